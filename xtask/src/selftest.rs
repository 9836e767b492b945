//! The QEMU self-test with each math backend, compared with its log snapshot, its per-stage
//! instruction counts against `firmware::budget`, and the failure injection that proves each
//! kind of failure is visible.

use controller_core::{EstimatorStage, Stage};
use firmware::budget;
use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;
use firmware::qemu_runner::TIMED_OUT;

use crate::images::{Backend, Built, Variant};
use crate::qemu_run;
use crate::snapshot;
use xtask::ci::Ci;

/// Seconds a self-test run may take (it needs about one on an idle machine).
const SELFTEST_TIMEOUT_S: u32 = 120;
/// Seconds before a failure-injection run counts as hung: the injections act before the
/// self-test's work, so this only bounds the `hang` case.
const INJECTION_TIMEOUT_S: u32 = 15;
/// Seconds the `hang` injection is given before the runner stops it (its timeout is the
/// expected outcome, so a short one suffices).
const HANG_TIMEOUT_S: u32 = 5;

/// `-append inject=<kind>` and the line (substring) that shows that failure in the log.
const INJECTIONS: [(&str, &str); 4] = [
    ("wrong", "ERROR injected wrong answer"),
    ("panic", "ERROR panic: "),
    ("hardfault", "ERROR HardFault at pc"),
    ("hang", "TIMEOUT"),
];

pub fn run(ci: &mut Ci, built: &Built) {
    for v in Variant::SELFTEST {
        let Some(elf) = built.elf(v) else { continue };
        let backend = v.backend.name();
        ci.step(&format!("self-test in QEMU, {backend} backend"));
        let run = match qemu_run::run(
            ci,
            elf,
            &[],
            SELFTEST_TIMEOUT_S,
            &format!("selftest-{backend}"),
        ) {
            Ok(r) => r,
            Err(e) => {
                ci.fail(e);
                continue;
            }
        };
        print!("{}", run.log);
        if run.status != Some(0) {
            ci.fail(format!(
                "self-test ({backend}) exited {:?}, not 0 (its log: {})",
                run.status,
                ci.rel(&run.log_path)
            ));
        }
        check_instruction_counts(ci, backend, &run.log);
        check_stage_budgets(ci, backend, &run.log);
        check_signing_budget(ci, backend, &run.log);
        check_stack_budget(ci, backend, &run.log);
        compare_log(ci, backend, &run.log);
        if v.backend == Backend::DEFAULT {
            inject_failures(ci, elf);
        }
    }
}

/// The lines whose counts are one call timed in whole SysTick counts (`INSTRUCTIONS_PER_TICK`
/// instructions each): `Controller::new` and `update instructions: max=N mean=N`. The per-call
/// lines of the cost module (`stage …`, `step …`, `kernel …`) average 40 calls and are exact to
/// one instruction instead.
fn is_systick_count(line: &str) -> bool {
    line.contains("Controller::new") || line.contains("update instructions:")
}

/// Instructions signing adds to the largest telemetry frame the board sends (the self-test's
/// `signing instructions per frame: sign=N`): the measured count plus ≈ 20 % headroom. Twice
/// per period the board signs or verifies one frame: together ≈ half an `update`.
pub const SIGN_INSTRUCTION_BUDGET: u64 = 12_000;
/// Instructions signing adds to receiving a state frame (`verify=N`), likewise.
pub const VERIFY_INSTRUCTION_BUDGET: u64 = 10_000;

/// The self-test's `signing instructions per frame: sign=N verify=M` against the budgets.
fn check_signing_budget(ci: &mut Ci, backend: &str, log: &str) {
    let count = |key: &str| {
        log.lines()
            .find(|l| l.contains("signing instructions per frame:"))
            .and_then(|l| l.split_whitespace().find_map(|t| t.strip_prefix(key)))
            .and_then(|n| n.parse::<u64>().ok())
    };
    match (count("sign="), count("verify=")) {
        (Some(sign), Some(verify)) => {
            println!(
                "{backend}: signing adds {sign} instructions to a telemetry frame (budget {SIGN_INSTRUCTION_BUDGET}) and {verify} to a state frame (budget {VERIFY_INSTRUCTION_BUDGET})"
            );
            if sign > SIGN_INSTRUCTION_BUDGET || verify > VERIFY_INSTRUCTION_BUDGET {
                ci.fail(format!(
                    "self-test ({backend}): signing costs sign={sign} verify={verify} instructions per frame, over the budgets {SIGN_INSTRUCTION_BUDGET} / {VERIFY_INSTRUCTION_BUDGET} (xtask/src/selftest.rs)"
                ));
            }
        }
        _ => ci.fail(format!(
            "self-test ({backend}): no `signing instructions per frame: sign=N verify=M` line in its log"
        )),
    }
}

/// The self-test's `stack high-water mark: N bytes`.
fn stack_high_water(log: &str) -> Option<u32> {
    log.lines()
        .find_map(|l| l.split_once("stack high-water mark:"))
        .and_then(|(_, rest)| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

/// The stack's high-water mark against [`budget::STACK_BUDGET_BYTES`].
fn check_stack_budget(ci: &mut Ci, backend: &str, log: &str) {
    match stack_high_water(log) {
        Some(bytes) => {
            println!(
                "{backend}: stack high-water mark {bytes} B (budget {} B)",
                budget::STACK_BUDGET_BYTES
            );
            if bytes > budget::STACK_BUDGET_BYTES {
                ci.fail(format!(
                    "self-test ({backend}): the stack reached {bytes} B, over its budget of {} B (firmware/src/budget.rs)",
                    budget::STACK_BUDGET_BYTES
                ));
            }
        }
        None => ci.fail(format!(
            "self-test ({backend}): no `stack high-water mark: N bytes` line in its log"
        )),
    }
}

/// The SysTick-timed counts must be whole numbers of counts, and the `update` line must be
/// there (its budget is checked on the target).
fn check_instruction_counts(ci: &mut Ci, backend: &str, log: &str) {
    if !log.contains("update instructions: max=") {
        ci.fail(format!(
            "self-test ({backend}): no `update instructions: max=` line in its log"
        ));
        return;
    }
    let counts: Vec<u64> = log
        .lines()
        .filter(|l| is_systick_count(l))
        // The counts: `~N` and `max=N mean=N` (not the `2^9` of the box corners).
        .flat_map(|l| l.split_whitespace())
        .filter_map(|t| {
            t.trim_start_matches(|c: char| !c.is_ascii_digit())
                .parse::<u64>()
                .ok()
        })
        .collect();
    if let Some(n) = counts
        .iter()
        .find(|&&n| !n.is_multiple_of(u64::from(INSTRUCTIONS_PER_TICK)))
    {
        ci.fail(format!(
            "self-test ({backend}): {n} instructions is not a whole number of SysTick counts ({INSTRUCTIONS_PER_TICK} instructions each, firmware::qemu_clock): is the runner's -icount shift the one the firmware assumes?"
        ));
    }
    let show = |f: &dyn Fn(u64) -> u64| {
        counts
            .iter()
            .map(|&n| f(n).to_string())
            .collect::<Vec<_>>()
            .join(" / ")
    };
    println!(
        "{backend}: instructions of Controller::new / update max / update mean: {} = {} SysTick counts of {INSTRUCTIONS_PER_TICK}",
        show(&|n| n),
        show(&|n| n / u64::from(INSTRUCTIONS_PER_TICK))
    );
}

/// `max=N` of the log line that starts (after the level) with `prefix`, e.g. `stage law:`.
fn max_of(log: &str, prefix: &str) -> Option<u32> {
    log.lines()
        .filter_map(|l| l.split_once("  ").map(|(_, rest)| rest.trim_start()))
        .find_map(|rest| rest.strip_prefix(prefix))
        .and_then(|rest| rest.trim_start().strip_prefix("max="))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

/// Every stage of `update` (`controller_core::Stage`) and of the estimator
/// (`controller_core::EstimatorStage`) must have its `stage NAME: max=N` line, within its
/// budget in `firmware::budget`.
fn check_stage_budgets(ci: &mut Ci, backend: &str, log: &str) {
    let Some(budget) = budget::for_backend(backend) else {
        ci.fail(format!(
            "self-test ({backend}): no budget for this backend in firmware/src/budget.rs"
        ));
        return;
    };
    let mut shown = Vec::new();
    let law = Stage::ALL.map(|s| (s.name(), budget.stage(s)));
    let estimator = EstimatorStage::ALL.map(|s| (s.name(), budget.estimator_stage(s)));
    for (name, limit) in law.into_iter().chain(estimator) {
        match max_of(log, &format!("stage {name}:")) {
            None => ci.fail(format!(
                "self-test ({backend}): no `stage {name}: max=N` line in its log"
            )),
            Some(n) if n > limit => ci.fail(format!(
                "self-test ({backend}): stage {name} takes {n} instructions, over its budget of {limit} (firmware/src/budget.rs; raise it there only with the reason)"
            )),
            Some(n) => shown.push(format!("{name} {n}/{limit}")),
        }
    }
    println!(
        "{backend}: stage instructions / budget: {}",
        shown.join(", ")
    );
}

fn compare_log(ci: &mut Ci, backend: &str, log: &str) {
    let rel = snapshot::selftest_log(backend);
    let path = ci.root.join(&rel);
    if ci.bless {
        match std::fs::write(&path, log) {
            Ok(()) => println!("blessed {rel}"),
            Err(e) => ci.fail(format!("writing {rel}: {e}")),
        }
        return;
    }
    let snap = match std::fs::read_to_string(&path) {
        Ok(s) => s,
        Err(e) => {
            ci.fail(format!(
                "reading {rel}: {e} (cargo xtask selftest --bless writes it)"
            ));
            return;
        }
    };
    let d = snapshot::diff(&snapshot::normalise(&snap), &snapshot::normalise(log));
    if !d.is_empty() {
        ci.fail(format!(
            "self-test log ({backend}) differs from {rel} (- snapshot, + this run; numbers on instruction and stack lines are not compared):\n      {}\n    if the change is intended: cargo xtask selftest --bless, then review and commit the snapshot",
            d.join("\n      ")
        ));
    }
}

/// Each injected failure must make the self-test fail, visibly: a non-zero exit and its line
/// in the log.
fn inject_failures(ci: &mut Ci, elf: &std::path::Path) {
    ci.step("failure injection: each must fail visibly");
    for (kind, evidence) in INJECTIONS {
        let timeout = if kind == "hang" {
            HANG_TIMEOUT_S
        } else {
            INJECTION_TIMEOUT_S
        };
        let arg = format!("inject={kind}");
        let run = match qemu_run::run(
            ci,
            elf,
            &["-append", &arg],
            timeout,
            &format!("inject-{kind}"),
        ) {
            Ok(r) => r,
            Err(e) => {
                ci.fail(e);
                continue;
            }
        };
        let shown = run.log.lines().find(|l| l.contains(evidence));
        println!(
            "inject={kind} → exit {:?}: {}",
            run.status,
            shown.unwrap_or("(no evidence line)")
        );
        let failed = match kind {
            "hang" => run.status == Some(TIMED_OUT),
            _ => matches!(run.status, Some(s) if s != 0 && s != TIMED_OUT),
        };
        if !failed || shown.is_none() {
            ci.fail(format!(
                "inject={kind} did not fail visibly: exit {:?}, expected {} and a line with `{evidence}` (log: {})",
                run.status,
                if kind == "hang" { "the runner's timeout (124)" } else { "a failure exit" },
                ci.rel(&run.log_path)
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOG: &str = "INFO  update instructions: max=35200 mean=26120\n\
                       INFO  stage law: max=1004 mean=996 instructions\n\
                       INFO    circular-10R: [7592, 3412, 1004, 66, 7072] = update 19186 instructions";

    #[test]
    fn a_stage_count_is_read_from_its_own_line_only() {
        assert_eq!(max_of(LOG, "stage law:"), Some(1004));
        assert_eq!(max_of(LOG, "stage trajectory:"), None);
        assert_eq!(max_of(LOG, "update instructions:"), Some(35200));
    }

    #[test]
    fn the_stack_high_water_mark_is_read_from_its_line() {
        let log = "INFO  stage law: max=1004 mean=996 instructions\n\
                   INFO  stack high-water mark: 92612 bytes\n\
                   INFO  self-test passed";
        assert_eq!(stack_high_water(log), Some(92612));
        const {
            assert!(
                92_612 > budget::STACK_BUDGET_BYTES,
                "the 32-point capacity's stack, trajectories by value, is refused"
            )
        };
        assert_eq!(stack_high_water(LOG), None);
    }

    #[test]
    fn only_single_call_lines_are_whole_systick_counts() {
        let lines: Vec<&str> = LOG.lines().filter(|l| is_systick_count(l)).collect();
        assert_eq!(lines.len(), 1);
        assert!(lines[0].contains("update instructions"));
    }
}
