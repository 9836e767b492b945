//! Processor in the loop: the QEMU flying image flies the simulated vehicle through
//! `host-sim pil`. Seven checks: a short lawn-mower mission must equal SIL bit for bit, on an
//! unsigned and on a signed link (the public CI test key, [`CI_TEST_KEY`]); the real-chain
//! mission with a tuned law ([`TUNED_LAW`]: μ, K₁, K₂ other than the board's built-in ones,
//! protocol 8) must equal SIL bit for bit; a waypoint mission
//! uploaded over a link that loses one chunk ([`WAYPOINTS`]) must equal SIL bit for bit with
//! the chunk resent once; a short real-chain
//! mission (kgf, tangent heading, time scale > 1, the real actuator chain, the real vehicle's
//! mounting: [`REAL_CHAIN`]) must equal SIL bit for bit with the board reporting the
//! scenario's thrust unit and mounting; a link-fault case must enter and leave fail-safe
//! at its exact ticks and drop its delayed (old) state frames; and the worst case of a small
//! campaign (docs/campaigns.md#worst-cases), found in SIL, flown on the board from the merge's scenario
//! file, must equal the campaign's record bit for bit.

use std::path::{Path, PathBuf};
use std::process::Command;

use auv_link::FailSafeReason;
use auv_link::DEFAULT_STALE_PERIODS;
use controller_core::HeadingMode;
use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;
use host_sim::board::{BoardComparison, FailSafeEventKind};
use host_sim::cli::Cases;
use host_sim::output::log;
use xtask::ci::{Ci, HOST_PROFILE};

/// The key the signed runs use (workspace-relative): public, for tests only.
pub const CI_TEST_KEY: &str = "firmware/ci-test-link-key.hex";

/// The real-chain mission PIL flies (workspace-relative): one of the real-vehicle missions
/// (docs/ci.md#the-board-in-ci), chosen because its time scale is above 1, flown for
/// [`REAL_CHAIN_SECONDS`] only (CI time). The check reads it with host-sim's own loader and
/// refuses to run unless it is what the check claims to fly.
const REAL_CHAIN: &str = "host-sim/scenarios/real/figure-eight-30x30.toml";
/// Seconds of the real-chain mission: 300 periods, a few seconds of QEMU.
const REAL_CHAIN_SECONDS: &str = "3";

/// The law keys added to [`REAL_CHAIN`]'s `[controller]` for the tuned-law case (written to
/// the scratch folder as `pil-tuned-law.toml`): μ = 0.15 (the real-circle campaign's better
/// layer) and other K₁ (surge) and K₂ (yaw) than the paper's. The board boots on the paper's
/// law, so it flies these only if the link carries them (protocol 8, Choice 508): with μ alone
/// and no law on the link the board flew 0.015972 m against SIL's 0.016140 m.
const TUNED_LAW: &str =
    "mu = 0.15\nk1 = [5.0, 4.0, 4.0, 0.0, 4.0, 4.0]\nk2 = [4.0, 4.0, 4.0, 0.0, 4.0, 3.0]\n";

/// The waypoint mission PIL flies (workspace-relative, docs/ci.md#the-board-in-ci): uploaded in two
/// chunks, the second lost on its first sending ([`WAYPOINTS_LOST_CHUNK`]), so the board's
/// acknowledgement and the runner's resend are on the path; flown for its whole scenario
/// duration (a leg, a speed change, a turn and the next leg).
const WAYPOINTS: &str = "host-sim/scenarios/waypoints-short.toml";
/// The chunk of [`WAYPOINTS`]'s upload lost on its first sending.
const WAYPOINTS_LOST_CHUNK: &str = "1";

/// The link-fault case's silent ticks [from, to) and delayed ticks (see [`link_faults`]).
const SILENT: (u64, u64) = (300, 310);
const DELAY: (u64, u64) = (200, 202);

/// Builds the `host-sim` binary the checks run and returns its path. It is the very build of
/// the host tests (`cargo test --workspace --profile host`), so that host-sim is built once:
/// `cargo build -p host-sim` alone resolves features differently (no dev-dependencies) and
/// would build host-sim a second time.
pub fn build_host_sim(ci: &mut Ci) -> Option<PathBuf> {
    let args = ["test", "--workspace", "--profile", HOST_PROFILE, "--no-run"];
    let what = format!("cargo {}", args.join(" "));
    println!("{what}");
    match ci.cargo().args(args).status() {
        Ok(s) if s.success() => Some(ci.target_dir.join(HOST_PROFILE).join("host-sim")),
        other => {
            ci.fail(format!(
                "{what} failed ({other:?}); the compiler's errors are above"
            ));
            None
        }
    }
}

/// The PIL checks with the flying image `elf`. Each runs the `host-sim` binary with `--json`
/// and reads its report into host-sim's own types ([`Cases`]`<`[`BoardComparison`]`>`), so the
/// check and the report cannot disagree on a field.
pub fn checks(ci: &mut Ci, host_sim: &Path, elf: &Path) {
    ci.step(
        "processor in the loop: a short mission unsigned and signed, a short real-chain mission and the same with a tuned law (PIL must equal SIL), a link-fault case, and a campaign's worst case replayed on the board",
    );
    let pil = Pil { host_sim, elf };
    same_as_sil(ci, &pil);
    link_faults(ci, &pil);
    campaign_worst_case(ci, &pil);
}

/// `host-sim pil` with one image.
struct Pil<'a> {
    host_sim: &'a Path,
    elf: &'a Path,
}

impl Pil<'_> {
    /// Flies `args`; whether host-sim passed, and its one case.
    fn run(&self, ci: &mut Ci, name: &str, args: &[&str]) -> Option<(bool, BoardComparison)> {
        let out = ci.scratch().join(format!("pil-{name}"));
        // host-sim refuses an output folder it did not write (no manifest): start afresh.
        let _ = std::fs::remove_dir_all(&out);
        let mut cmd = Command::new(self.host_sim);
        cmd.current_dir(&ci.root)
            .arg("pil")
            .args(args)
            .arg("--elf")
            .arg(self.elf)
            .arg("--json")
            .arg("--out")
            .arg(&out);
        let shown = format!("{} pil {}", ci.rel(self.host_sim), args.join(" "));
        println!("{shown}");
        let output = match cmd.output() {
            Ok(o) => o,
            Err(e) => {
                ci.fail(format!("PIL {name}: running {shown}: {e}"));
                return None;
            }
        };
        // host-sim prints its report even when it exits 1 (PIL ≠ SIL, diverged, lost its board).
        match serde_json::from_slice::<Cases<BoardComparison>>(&output.stdout) {
            Ok(r) if r.cases.len() == 1 => {
                let case = r.cases.into_iter().next()?;
                Some((output.status.success(), case))
            }
            Ok(r) => {
                ci.fail(format!(
                    "PIL {name}: expected one case, got {}",
                    r.cases.len()
                ));
                None
            }
            Err(e) => {
                ci.fail(format!(
                    "PIL {name}: {shown} exited {} without a JSON report ({e}); its messages:\n{}",
                    output.status,
                    String::from_utf8_lossy(&output.stderr)
                ));
                None
            }
        }
    }
}

/// 1. PIL = SIL: the same f32 core on the same inputs, bit for bit, unsigned and signed
///    (signing changes what crosses the link, never what the board computes), and on the real
///    chain (the board gets the thrust unit, mounting and priority through SetConfig and the
///    heading and time scale through StartMission).
fn same_as_sil(ci: &mut Ci, pil: &Pil) {
    let short = [
        "--scenario",
        "host-sim/scenarios/lawn-mower-20x10.toml",
        "--duration",
        "10",
    ];
    let key = ci.root.join(CI_TEST_KEY);
    let key = key.to_string_lossy().into_owned();
    // Signed, the first half of the same mission (its PIL = SIL check is the same; CI time).
    let signed = [&short[..3], &["5", "--link-key-file", &key]].concat();
    let real = ["--scenario", REAL_CHAIN, "--duration", REAL_CHAIN_SECONDS];
    let real_chain = real_chain_scenario(ci);
    let tuned_file = tuned_law_scenario(ci);
    let tuned_path = tuned_file
        .as_ref()
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tuned = [
        "--scenario",
        tuned_path.as_str(),
        "--duration",
        REAL_CHAIN_SECONDS,
    ];
    let waypoints = [
        "--scenario",
        WAYPOINTS,
        "--lose-upload-chunk",
        WAYPOINTS_LOST_CHUNK,
    ];
    for (name, args, want_signed) in [
        ("short", &short[..], false),
        ("short-signed", &signed[..], true),
        ("real-chain", &real[..], false),
        ("tuned-law", &tuned[..], false),
        ("waypoints", &waypoints[..], false),
    ] {
        if name == "tuned-law" && tuned_file.is_none() {
            continue;
        }
        let want_chain = if name == "real-chain" {
            match &real_chain {
                Some(c) => Some(c),
                None => continue,
            }
        } else {
            None
        };
        let Some((ok, c)) = pil.run(ci, name, args) else {
            continue;
        };
        println!(
            "{name}: PIL max path {:.5} m, SIL {:.5} m, {:.0} frames/s, worst update {} instructions, signed {}, board auth errors {}, telemetry refused {}",
            c.run.metrics.max_path,
            c.sil_max_path,
            c.pil.frames_per_second,
            c.pil.worst_update_instructions,
            c.pil.signed,
            c.pil.board_rx_auth_errors,
            c.pil.telemetry_refused
        );
        whole_counts(ci, name, &c);
        bit_for_bit(ci, name, ok, &c);
        whole_flight(ci, pil, name, &c);
        if let Some((unit, mounting)) = want_chain {
            chain_taken(ci, name, unit, *mounting, &c);
        }
        clean_link(ci, name, want_signed, &c);
        if name == "waypoints" {
            upload_resent(ci, name, &c);
        }
    }
}

/// PIL = SIL on the whole flight, not only its metrics: `host-sim diff` finds the board's
/// flight log (its telemetry in the log's channels, source `pil`) the same as SIL's, every
/// series at every period (docs/logs.md#the-board-in-the-same-channels).
fn whole_flight(ci: &mut Ci, pil: &Pil, name: &str, c: &BoardComparison) {
    let out = ci.scratch().join(format!("pil-{name}"));
    let sil = out.join(log::sil_log_name(&c.run.name));
    let board = out.join(log::log_name(&c.run.name, c.run.robust));
    let output = Command::new(pil.host_sim)
        .arg("diff")
        .arg(&sil)
        .arg(&board)
        .arg("--out")
        .arg(ci.scratch().join(format!("pil-{name}-diff")))
        .output();
    match output {
        Ok(o) if o.status.success() => println!("{name}: diff of the flight logs: the same"),
        Ok(o) => ci.fail(format!(
            "PIL {name}: the board's flight log differs from SIL's (host-sim diff exited {}):\n{}{}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )),
        Err(e) => ci.fail(format!("PIL {name}: running host-sim diff: {e}")),
    }
}

/// The waypoint mission went up as an upload: its lost chunk was acknowledged as missing and
/// resent once, in a second round, and nothing else was resent.
fn upload_resent(ci: &mut Ci, name: &str, c: &BoardComparison) {
    let Some(u) = &c.pil.upload else {
        ci.fail(format!(
            "PIL {name}: the waypoint mission was flown without an upload"
        ));
        return;
    };
    println!(
        "{name}: upload CRC {:#010x}, {} chunks, {} frames, {} bytes, {} rounds, {} resent, {:.3} s",
        u.crc, u.chunks, u.frames, u.bytes, u.rounds, u.resent, u.seconds
    );
    if u.chunks < 2 || u.rounds != 2 || u.resent != 1 {
        ci.fail(format!(
            "PIL {name}: upload of {} chunks took {} rounds and resent {} chunks; with chunk {WAYPOINTS_LOST_CHUNK} lost once it must take 2 rounds and resend 1",
            u.chunks, u.rounds, u.resent
        ));
    }
}

/// The board's worst `update` must be whole SysTick counts (instructions under `-icount`).
fn whole_counts(ci: &mut Ci, name: &str, c: &BoardComparison) {
    if !c
        .pil
        .worst_update_instructions
        .is_multiple_of(u64::from(INSTRUCTIONS_PER_TICK))
    {
        ci.fail(format!(
            "PIL {name}: worst update {} instructions is not a whole number of SysTick counts ({INSTRUCTIONS_PER_TICK} each)",
            c.pil.worst_update_instructions
        ));
    }
}

/// PIL's max path error equals SIL's bit for bit, and host-sim passed.
fn bit_for_bit(ci: &mut Ci, name: &str, ok: bool, c: &BoardComparison) {
    if !ok || c.run.metrics.max_path.to_bits() != c.sil_max_path.to_bits() {
        ci.fail(format!(
            "PIL {name}: PIL max path {} m is not SIL's {} m bit for bit (host-sim {}); the board and SIL run the same f32 core on the same state frames, so look for a change in what crosses the link or in the firmware's period",
            c.run.metrics.max_path,
            c.sil_max_path,
            if ok { "passed its 1 mm check" } else { "failed" }
        ));
    }
}

/// The board flew the scenario's thrust unit and mounting (its SetConfig took).
fn chain_taken(ci: &mut Ci, name: &str, unit: &str, mounting: u8, c: &BoardComparison) {
    println!(
        "{name}: board flew thrust unit {:?}, reversed-thruster mask {:?}; peak |V| {:.2} V, saturated {:.1} % of periods",
        c.pil.board_thrust_unit,
        c.pil.board_reversed_thrusters,
        c.run.metrics.peak_voltage,
        100.0 * c.run.metrics.saturated_fraction
    );
    if c.pil.board_thrust_unit.as_deref() != Some(unit)
        || c.pil.board_reversed_thrusters != Some(mounting)
    {
        ci.fail(format!(
            "PIL {name}: the board reported thrust unit {:?} and mounting {:?}; the scenario flies {unit} and {mounting:#07b} (SetConfig did not take)",
            c.pil.board_thrust_unit, c.pil.board_reversed_thrusters
        ));
    }
}

/// The link was signed as asked, with no receive error, dropped frame or refusal at either end.
fn clean_link(ci: &mut Ci, name: &str, want_signed: bool, c: &BoardComparison) {
    let clean = c.pil.board_rx_errors == 0
        && c.pil.board_rx_stale == 0
        && c.pil.board_refused_commands == 0
        && c.pil.telemetry_refused == 0;
    if c.pil.signed != want_signed || !clean {
        ci.fail(format!(
            "PIL {name}: expected a {} link with no receive error, dropped frame or refusal at either end; got signed {}, board rx errors {}, dropped {}, refused {} ({:?}), telemetry refused {}",
            if want_signed { "signed" } else { "unsigned" },
            c.pil.signed,
            c.pil.board_rx_errors,
            c.pil.board_rx_stale,
            c.pil.board_refused_commands,
            c.pil.board_last_refusal,
            c.pil.telemetry_refused
        ));
    }
}

/// 2. Link faults: drop, corruption and a short delay stay within the stale limit; the delayed
///    frames hold old states, which the board drops (off its mission clock) and counts; silence
///    from tick SILENT.0 is fail-safe (stale state) once DEFAULT_STALE_PERIODS periods have
///    passed without a frame, and the re-arm (and restart of the mission) on the first healthy
///    frame (SILENT.1) ends it.
fn link_faults(ci: &mut Ci, pil: &Pil) {
    let silent = format!("{}..{}", SILENT.0, SILENT.1);
    let delay = format!("{}..{}", DELAY.0, DELAY.1);
    let args = [
        "--scenario",
        "host-sim/scenarios/circular-10R.toml",
        "--duration",
        "8",
        "--drop",
        "100..101",
        "--corrupt",
        "150..152",
        "--delay",
        &delay,
        "--silent",
        &silent,
    ];
    let Some((ok, c)) = pil.run(ci, "faults", &args) else {
        return;
    };
    let ev = &c.pil.failsafe_events;
    println!(
        "fail-safe events: {:?}, board rx_errors {}",
        ev.iter()
            .map(|e| (e.kind.as_str(), e.tick, e.reason.as_str()))
            .collect::<Vec<_>>(),
        c.pil.board_rx_errors
    );
    whole_counts(ci, "link-fault case", &c);
    let enter = SILENT.0 + u64::from(DEFAULT_STALE_PERIODS);
    let as_expected = matches!(
        &ev[..],
        [a, b] if a.kind == FailSafeEventKind::Enter && a.tick == enter
            && a.reason == FailSafeReason::StaleState.as_str()
            && b.kind == FailSafeEventKind::Exit && b.tick == SILENT.1
    );
    if !ok || !as_expected {
        ci.fail(format!(
            "PIL link-fault case: expected fail-safe (stale state) entered at tick {enter} (silent from {}, stale after {DEFAULT_STALE_PERIODS} periods) and left at {} (re-armed on the first healthy frame), nothing else; got {ev:?}{}",
            SILENT.0,
            SILENT.1,
            if ok { "" } else { " and host-sim failed" }
        ));
    }
    if c.pil.board_rx_errors < 2 {
        ci.fail(format!(
            "PIL link-fault case: the board counted {} receive errors; the two corrupted frames must be counted",
            c.pil.board_rx_errors
        ));
    }
    if u64::from(c.pil.board_rx_stale) != DELAY.1 - DELAY.0 {
        ci.fail(format!(
            "PIL link-fault case: the board dropped {} frames as old; the {} delayed state frames (ticks {delay}) must be dropped, and nothing else",
            c.pil.board_rx_stale,
            DELAY.1 - DELAY.0
        ));
    }
}

/// The CI's small campaign (docs/campaigns.md#worst-cases), run and merged here.
const CAMPAIGN: &str = "host-sim/campaigns/ci-small.campaign.toml";

/// Runs the CI's small campaign in one shard and merges it, in the scratch folder; the merged
/// report's folder, or `None` (and a CI failure).
fn run_campaign(ci: &mut Ci, host_sim: &Path) -> Option<PathBuf> {
    let dir = ci.scratch().join("campaign");
    let _ = std::fs::remove_dir_all(&dir);
    let (shard, report) = (dir.join("shard"), dir.join("report"));
    let run = |args: &[&std::ffi::OsStr]| {
        Command::new(host_sim)
            .current_dir(&ci.root)
            .args(args)
            .output()
            .map_err(|e| e.to_string())
            .and_then(|o| match o.status.success() {
                true => Ok(()),
                false => Err(String::from_utf8_lossy(&o.stderr).into_owned()),
            })
    };
    let os = |s: &str| std::ffi::OsString::from(s);
    let made = run(&[
        &os("campaign"),
        &os("run"),
        &os(CAMPAIGN),
        &os("--shard"),
        &os("0/1"),
        &os("--out"),
        shard.as_os_str(),
    ])
    .and_then(|()| {
        run(&[
            &os("campaign"),
            &os("merge"),
            shard.as_os_str(),
            &os("--out"),
            report.as_os_str(),
        ])
    });
    match made {
        Ok(()) => Some(report),
        Err(e) => {
            ci.fail(format!(
                "PIL campaign worst case: the campaign {CAMPAIGN}: {e}"
            ));
            None
        }
    }
}

/// 5. A worst case found in SIL, replayed on the board: the small campaign is run (one shard)
///    and merged, and the merge's `worst-max_path.toml` is flown through `pil` as its report
///    prints it. The board's max path error must equal the campaign's record of that run bit
///    for bit (and SIL's).
fn campaign_worst_case(ci: &mut Ci, pil: &Pil) {
    let Some(report) = run_campaign(ci, pil.host_sim) else {
        return;
    };
    let records = match host_sim::output::campaign::read_records(
        &report.join(host_sim::output::campaign::RECORDS),
        false,
    ) {
        Ok(r) => r,
        Err(e) => {
            ci.fail(format!("PIL campaign worst case: {e:#}"));
            return;
        }
    };
    // The worst max path error: the largest, the first run with it (records in index order).
    let metric = host_sim::studies::campaign::METRIC_NAMES
        .iter()
        .position(|m| *m == "max_path")
        .unwrap_or(3);
    let worst = records.iter().filter(|r| !r.metrics[metric].is_nan()).fold(
        None::<&host_sim::studies::campaign::Record>,
        |w, r| match w {
            Some(w) if w.metrics[metric] >= r.metrics[metric] => Some(w),
            _ => Some(r),
        },
    );
    let Some(worst) = worst else {
        ci.fail("PIL campaign worst case: the merged campaign has no records");
        return;
    };
    let file = report.join(host_sim::output::campaign::worst_file("max_path"));
    let file = file.to_string_lossy().into_owned();
    // A worst case may well miss its bound (host-sim then exits 4): what is checked is that
    // the board flies the campaign's run, to the bit.
    let Some((_, c)) = pil.run(ci, "campaign-worst", &["--scenario", &file]) else {
        return;
    };
    let recorded = worst.metrics[metric];
    println!(
        "campaign worst case (run {}): PIL max path {} m, SIL {} m, the campaign's record {recorded} m",
        worst.index, c.run.metrics.max_path, c.sil_max_path
    );
    if c.run.metrics.max_path.to_bits() != c.sil_max_path.to_bits()
        || c.run.metrics.max_path.to_bits() != recorded.to_bits()
    {
        ci.fail(format!(
            "PIL campaign worst case: the board flew run {} to a max path of {} m, SIL {} m, the campaign recorded {recorded} m: all three must be the same bits (the worst case's scenario file replays the run)",
            worst.index, c.run.metrics.max_path, c.sil_max_path
        ));
    }
}

/// The real-chain scenario's thrust unit name and reversed-thruster mask, after checking that
/// it is a real-chain mission as [`REAL_CHAIN`] says (kgf, tangent heading, time scale > 1,
/// the real actuator chain); `None` (and a CI failure) otherwise.
/// [`REAL_CHAIN`] with [`TUNED_LAW`] in its `[controller]`, written to the scratch folder.
fn tuned_law_scenario(ci: &mut Ci) -> Option<PathBuf> {
    let text = match std::fs::read_to_string(ci.root.join(REAL_CHAIN)) {
        Ok(t) if t.contains("\n[controller]\n") => t,
        other => {
            ci.fail(format!(
                "PIL tuned-law: {REAL_CHAIN} must have a [controller] table to add the law to ({:?})",
                other.err()
            ));
            return None;
        }
    };
    let tuned = text.replacen(
        "\n[controller]\n",
        &format!("\n[controller]\n{TUNED_LAW}"),
        1,
    );
    let path = ci.scratch().join("pil-tuned-law.toml");
    match std::fs::write(&path, tuned) {
        Ok(()) => Some(path),
        Err(e) => {
            ci.fail(format!("PIL tuned-law: writing {}: {e}", path.display()));
            None
        }
    }
}

fn real_chain_scenario(ci: &mut Ci) -> Option<(&'static str, u8)> {
    let path = ci.root.join(REAL_CHAIN);
    let s = match host_sim::scenario::load_scenario(&path) {
        Ok(s) => s,
        Err(e) => {
            // The whole chain: an unreadable file's reason is the error's source.
            ci.fail(format!(
                "PIL real-chain: {REAL_CHAIN}: {:#}",
                anyhow::Error::from(e)
            ));
            return None;
        }
    };
    let cfg = s.config();
    let mission = s.trajectory().mission();
    let controller = s.controller().config();
    let unit = controller.thrust_unit;
    let mounting = controller.geometry.auv150_reversed();
    let real = unit == controller_core::ThrustUnit::Kgf
        && mission.heading == HeadingMode::Tangent
        && mission.time_scale > 1.0
        && !cfg.ideal_actuators;
    match mounting {
        Some(m) if real => {
            println!(
                "real-chain mission {REAL_CHAIN}: thrust unit {}, heading {}, time scale {}, ideal actuators {}, reversed-thruster mask {m:#07b}",
                unit.as_str(),
                mission.heading.as_str(),
                mission.time_scale,
                cfg.ideal_actuators
            );
            Some((unit.as_str(), m))
        }
        _ => {
            ci.fail(format!(
                "PIL real-chain: {REAL_CHAIN} must be a real-chain mission of the AUV-150 layout (kgf, tangent heading, time scale > 1, ideal_actuators = false); it has {}, {}, {}, ideal actuators {}, mounting {mounting:?}",
                unit.as_str(),
                mission.heading.as_str(),
                mission.time_scale,
                cfg.ideal_actuators
            ));
            None
        }
    }
}
