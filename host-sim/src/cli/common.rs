//! What the commands share: loading a scenario with the step cap, counting periods for the
//! progress, flying a run into its CSV, the preflight verdicts, and how a set of runs ends.

use std::io::Write;
use std::path::Path;
use std::sync::Mutex;

use anyhow::{anyhow, bail, Context, Result};

use super::json::{print_json, Cases};
use super::Exit;
use crate::interrupt;
use crate::output::log::{log_name, McapLog, Source};
use crate::output::{self, atomic, CsvStream, OutputDir, ReportRow};
use crate::scenario::{load_config, Scenario};
use crate::sim::progress::Progress;
use crate::sim::record::RunSummary;
use crate::sim::{self, ControlSource, LocalController, Recording, RunResult};
use crate::studies::montecarlo::MAX_RUNS;
use crate::studies::preflight::{self, CheckError, Preflight, DEFAULT_MARGIN};

/// Reads and validates a scenario file, with the step cap lifted if `allow_long_run`.
pub(super) fn load(path: &Path, allow_long_run: bool) -> Result<Scenario> {
    let ctx = || format!("scenario {}", path.display());
    let mut config = load_config(path).with_context(ctx)?;
    config.allow_long_run = allow_long_run;
    Scenario::new(config).with_context(ctx)
}

/// A command's count of runs (`--runs`, `--random`): at most [`MAX_RUNS`] unless
/// `allow_long_run` (the one cap of `monte-carlo` and `validate-preflight`, Choice 303).
pub(super) fn check_run_count(flag: &str, n: usize, allow_long_run: bool) -> Result<()> {
    if n > MAX_RUNS && !allow_long_run {
        bail!("{flag} {n} is more than {MAX_RUNS}; give --allow-long-run to run that many");
    }
    Ok(())
}

/// The control periods of `scenarios`, for [`Progress`].
pub(super) fn periods<'a>(scenarios: impl IntoIterator<Item = &'a Scenario>) -> u64 {
    scenarios.into_iter().map(|s| s.steps() + 1).sum()
}

/// Outputs that could not be written completely, collected from parallel runs.
#[derive(Default)]
pub(super) struct Incomplete(Mutex<Vec<String>>);

impl Incomplete {
    pub(super) fn push(&self, what: String) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(what);
    }
    pub(super) fn into_inner(self) -> Vec<String> {
        self.0.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// One run with the law from `control`, its CSV and its flight log (`source`: where the law
/// runs, `text`: the scenario file, attached) streamed into `dir` and its periods counted
/// into `progress`; an output that cannot be written completely goes to `incomplete` (the run
/// goes on: its metrics are still good).
pub(super) fn run_into(
    dir: &OutputDir,
    scenario: &Scenario,
    control: &mut dyn ControlSource,
    source: Source,
    text: Option<&str>,
    progress: &Progress,
    incomplete: &Incomplete,
) -> RunResult {
    let cfg = scenario.config();
    let name = output::csv_name(&cfg.name, cfg.controller.robust);
    let mut counter = progress.observer();
    let mut csv = dir
        .claim(&name)
        .and_then(|p| CsvStream::create(&p))
        .map_err(|e| incomplete.push(format!("{name} was not written: {e:#}")))
        .ok();
    let log_file = log_name(&cfg.name, cfg.controller.robust);
    let mut log = dir
        .claim(&log_file)
        .map_err(|e| format!("{e:#}"))
        .and_then(|p| McapLog::create(&p, scenario, source, text).map_err(|e| e.to_string()))
        .map_err(|e| incomplete.push(format!("{log_file} was not written: {e}")))
        .ok();
    if let Some(log) = log.as_mut() {
        log.upload(control.upload_rounds());
    }
    let run = sim::fly(
        scenario,
        control,
        &mut (&mut csv, (&mut log, &mut counter)),
        Recording::Plot,
    );
    if let Some(Err(e)) = csv.map(CsvStream::finish) {
        incomplete.push(e.to_string());
    }
    if let Some(Err(e)) = log.map(|l| l.finish(&run)) {
        incomplete.push(e.to_string());
    }
    run
}

/// [`run_into`] with the law on the host.
pub(super) fn sil_into(
    dir: &OutputDir,
    scenario: &Scenario,
    text: Option<&str>,
    progress: &Progress,
    incomplete: &Incomplete,
) -> RunResult {
    run_into(
        dir,
        scenario,
        &mut LocalController::new(scenario),
        "sil",
        text,
        progress,
        incomplete,
    )
}

/// Says once, on stderr, which outputs are incomplete.
pub(super) fn report_incomplete(incomplete: &[String]) {
    for i in incomplete {
        eprintln!("host-sim: error: {i}");
    }
}

/// Prints the runs of `rows` (JSON, or the table and the report's path) and says how the
/// command ended: by the runs of the controller each scenario configures (`with`), never by
/// its companion without Δu, which is there for comparison and reported beside it
/// (Choice 313).
pub(super) fn print_runs(
    stdout: &mut dyn Write,
    json: bool,
    rows: &[ReportRow],
    checks: &[Preflight],
    report: &Path,
    incomplete: Vec<String>,
) -> Result<Exit> {
    report_incomplete(&incomplete);
    let exit = runs_exit(rows.iter().map(|r| r.with), !incomplete.is_empty(), false);
    if json {
        let cases: Cases<RunSummary> = Cases {
            cases: runs(rows).map(RunResult::summary).collect(),
            incomplete,
            preflight: checks.to_vec(),
            contract: None,
            contract_statistics: Vec::new(),
        };
        print_json(stdout, &cases)?;
    } else {
        for c in checks {
            writeln!(stdout, "{c}")?;
        }
        writeln!(stdout, "{}", output::table_text(rows))?;
        let all: Vec<&RunResult> = runs(rows).collect();
        writeln!(stdout, "{}", output::chatter_table_text(&all))?;
        for r in rows {
            if let Some(c) = r.without.filter(|c| companion_differs(r.with, c)) {
                writeln!(
                    stdout,
                    "{}: the comparison run without Δu {} (reported, not the verdict: the exit \
                     code follows the run with the controller the scenario configures)",
                    c.name, c.outcome
                )?;
            }
        }
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(exit)
}

/// True when the companion without Δu ended otherwise than the run it accompanies (another
/// outcome, or faults where it had none): what the text output points out.
fn companion_differs(with: &RunResult, without: &RunResult) -> bool {
    std::mem::discriminant(&with.outcome) != std::mem::discriminant(&without.outcome)
        || with.faulted_unexpectedly() != without.faulted_unexpectedly()
}

/// The preflight checks of `scenarios` (in parallel), at the default margin; `None` when a
/// stop was requested before they were done ([`interrupted_before_runs`]).
pub(super) fn preflights<'a>(
    scenarios: impl IntoIterator<Item = &'a Scenario>,
) -> Result<Option<Vec<Preflight>>> {
    use rayon::prelude::*;
    let v: Vec<&Scenario> = scenarios.into_iter().collect();
    let checks: Result<Vec<Preflight>, (&Scenario, CheckError)> = v
        .par_iter()
        .map(|s| preflight::check(s, DEFAULT_MARGIN).map_err(|e| (*s, e)))
        .collect();
    match checks {
        Ok(c) => Ok(Some(c)),
        Err((_, CheckError::Interrupted)) => Ok(None),
        Err((s, e)) => Err(anyhow!("preflight of {}: {e}", s.config().name)),
    }
}

/// How a command ends when it is interrupted before its runs started (**Choice 120**): its
/// report says so and nothing else is written; the JSON has no cases; exit 130.
pub(super) fn interrupted_before_runs(
    dir: &OutputDir,
    title: &str,
    json: bool,
    stdout: &mut dyn Write,
) -> Result<Exit> {
    let what = "INTERRUPTED during the preflight check, before any run started: nothing was \
                simulated";
    let path = dir.claim("report.md")?;
    let text = format!("# {title} (PARTIAL)\n\n**{what}.**\n");
    atomic::write(&path, text.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("host-sim: {what}");
    if json {
        let cases: Cases<RunSummary> = Cases {
            cases: Vec::new(),
            incomplete: Vec::new(),
            preflight: Vec::new(),
            contract: None,
            contract_statistics: Vec::new(),
        };
        print_json(stdout, &cases)?;
    } else {
        writeln!(stdout, "{what}")?;
        writeln!(stdout, "report: {}", path.display())?;
    }
    Ok(Exit::Interrupted)
}

/// How a command with these runs ended ([`Exit::of`]); `failed`: another reason for exit 1.
pub(super) fn runs_exit<'a>(
    runs: impl Iterator<Item = &'a RunResult> + Clone,
    incomplete: bool,
    failed: bool,
) -> Exit {
    Exit::of(
        incomplete,
        runs.clone().any(RunResult::interrupted) || interrupt::requested(),
        failed || runs.clone().any(|r| r.diverged() || r.lost_board()),
        runs.clone().any(RunResult::faulted_unexpectedly),
        runs.clone().any(RunResult::missed_unexpectedly),
    )
}

/// Every run of the rows: with, then without Δu.
pub(super) fn runs<'a: 'r, 'r>(
    rows: &'r [ReportRow<'a>],
) -> impl Iterator<Item = &'a RunResult> + Clone + 'r {
    rows.iter()
        .flat_map(|r| std::iter::once(r.with).chain(r.without))
}
