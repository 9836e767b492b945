//! What `pil` and `hil` share: their flags ([`LoopArgs`]), the scenarios with the flags
//! applied, the link key, and the runs themselves ([`fly`]: each scenario in SIL, then with the
//! board, compared).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use controller_core::{Table1Case, DEFAULT_V_LIMIT};

use super::common::{load, periods, report_incomplete, run_into, runs_exit, Incomplete};
use super::json::{print_json, Cases};
use super::Exit;
use crate::board::{self, BoardComparison, BoardInTheLoop, Mode, Pacing};
use crate::interrupt;
use crate::output::log::{sil_log_name, McapLog};
use crate::output::{self, atomic, sections, OutputDir, ReportRow};
use crate::scenario::{paper, LinkFaults, Scenario, TickRange};
use crate::sim::progress::Progress;
use crate::sim::{self, LocalController, Recording, RunResult};

/// What `pil` and `hil` share: the missions, the link faults and key, the outputs.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct LoopArgs {
    #[arg(long, conflicts_with = "table1")]
    pub scenario: Option<PathBuf>,
    /// The six Table-1 missions (with Δu).
    #[arg(long)]
    pub table1: bool,
    #[arg(long)]
    pub json: bool,
    /// Sign the link with this key file (`#` comment lines, then 64 hex digits; e.g.
    /// firmware/ci-test-link-key.hex): both ends refuse unsigned frames (`pil` starts the
    /// board with it; a real board has its own compiled in). Without it the link is unsigned.
    #[arg(long)]
    pub link_key_file: Option<PathBuf>,
    /// Override the scenario's duration (s); the scenario's limits apply to it.
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Drop the state frames of these ticks.
    #[arg(long, value_parser = TickRange::parse)]
    pub drop: Vec<TickRange>,
    /// Flip a byte in the state frames of these ticks.
    #[arg(long, value_parser = TickRange::parse)]
    pub corrupt: Vec<TickRange>,
    /// Send the state from `--delay-ticks` earlier during these ticks.
    #[arg(long, value_parser = TickRange::parse)]
    pub delay: Vec<TickRange>,
    #[arg(long, default_value_t = LinkFaults::DEFAULT_DELAY_TICKS)]
    pub delay_ticks: u64,
    /// Send nothing at all during these ticks.
    #[arg(long, value_parser = TickRange::parse)]
    pub silent: Vec<TickRange>,
    /// Lose this chunk of a waypoint mission's upload on its first sending (the runner resends
    /// it when the board's acknowledgement shows it missing); repeatable.
    #[arg(long)]
    pub lose_upload_chunk: Vec<u8>,
    /// Run beyond the step cap (see `run --help`).
    #[arg(long)]
    pub allow_long_run: bool,
}

pub(super) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The scenarios of a `pil` or `hil` run: the flags override the duration and add to each
/// scenario's [link_faults]; every check of the scenario (duration, step cap) applies to the
/// result.
pub(super) fn loop_scenarios(args: &LoopArgs) -> Result<Vec<Scenario>> {
    let base: Vec<Scenario> = match (&args.scenario, args.table1) {
        (Some(p), false) => vec![load(p, args.allow_long_run)?],
        (None, true) => Table1Case::ALL
            .iter()
            .map(|&case| paper::scenario(case, true))
            .collect::<Result<_, _>>()?,
        _ => bail!("give --scenario FILE or --table1"),
    };
    let mut scenarios = Vec::with_capacity(base.len());
    for s in &base {
        let changed = s.with(|c| {
            if let Some(d) = args.duration {
                c.duration = d;
            }
            c.allow_long_run |= args.allow_long_run;
            let f = &mut c.link_faults;
            f.drop.extend(args.drop.iter().copied());
            f.corrupt.extend(args.corrupt.iter().copied());
            f.delay.extend(args.delay.iter().copied());
            f.silent.extend(args.silent.iter().copied());
            f.lose_upload_chunks
                .extend(args.lose_upload_chunk.iter().copied());
            if !args.delay.is_empty() {
                f.delay_ticks = args.delay_ticks;
            }
            // Injected link faults are there to put the board in fail-safe.
            c.expect_faults |= !c.link_faults.is_empty();
        });
        scenarios.push(changed.with_context(|| match args.duration {
            Some(d) => format!("{} with --duration {d}", s.config().name),
            None => s.config().name.clone(),
        })?);
    }
    Ok(scenarios)
}

/// The link key of `--link-key-file`, if given.
pub(super) fn link_key(args: &LoopArgs) -> Result<Option<auv_link::sign::LinkKey>> {
    let Some(p) = &args.link_key_file else {
        return Ok(None);
    };
    let text = std::fs::read_to_string(p)
        .with_context(|| format!("reading the link key file {}", p.display()))?;
    Ok(Some(
        auv_link::sign::LinkKey::from_key_file(&text)
            .map_err(|e| anyhow!("{}: {e}", p.display()))?,
    ))
}

/// A board connected for one scenario, and the log of its emulator (kept whatever happens).
pub(super) struct Started {
    pub(super) board: BoardInTheLoop,
    pub(super) log: Option<(atomic::Pending, PathBuf)>,
}

/// How `pil` and `hil` take a board that did not start for the scenario `name`: a stop
/// requested during the set-up leaves the scenario unflown (`Ok(None)`); any other failure is
/// the command's error, named for the scenario (exit 2).
pub(super) fn not_started(name: &str, e: board::Error) -> Result<Option<Started>> {
    match e {
        board::Error::Interrupted { .. } => Ok(None),
        e => Err(anyhow!("{name}: {e}")),
    }
}

/// The runs of `pil` and `hil`: each scenario in SIL, then with the board `start` connects
/// (`None`: a stop was requested during its set-up), compared; the report, and how the command
/// ended. A run that loses its board keeps what it recorded (its CSV, its row in the report,
/// marked as having lost the board, with the reason) and is named on stderr (**Choice 72**);
/// a real-time run is compared with SIL but need not agree with it (**Choice 69**;
/// docs/board.md#pacing).
pub(super) fn fly(
    args: &LoopArgs,
    scenarios: &[Scenario],
    dir: &OutputDir,
    mode: Mode,
    stdout: &mut dyn Write,
    mut start: impl FnMut(&Scenario, &OutputDir) -> Result<Option<Started>>,
) -> Result<Exit> {
    let title = match mode {
        Mode::Pil => "AUV-150 processor in the loop (firmware in QEMU)",
        Mode::Hil => "AUV-150 hardware in the loop (board on a serial port)",
    };
    // Each scenario runs twice: SIL, then on the board.
    let progress = Progress::start(mode.name(), 2 * periods(scenarios), !args.json);
    let incomplete = Incomplete::default();
    let mut cases = Vec::new();
    let mut runs = Vec::new();
    let mut failed = false;
    // The scenarios an interrupt left unflown (before or during their set-up).
    let mut not_flown = Vec::new();
    for s in scenarios {
        if interrupt::requested() {
            not_flown.push(s.config().name.as_str());
            continue;
        }
        let Some(started) = start(s, dir)? else {
            // The set-up gave up waiting for the board because a stop was requested.
            not_flown.push(s.config().name.as_str());
            continue;
        };
        let (c, board_run, ok) = fly_one(s, started, dir, mode, &progress, &incomplete);
        failed |= !ok;
        cases.push(c);
        runs.push(board_run);
    }
    progress.finish();
    let mut notes = sections::board_vs_sil(&cases);
    if !not_flown.is_empty() {
        notes = format!(
            "**INTERRUPTED (PARTIAL)**: not flown: {}.\n\n{notes}",
            not_flown.join(", ")
        );
    }
    let rows: Vec<ReportRow> = runs.iter().map(|r| ReportRow::new(r, None)).collect();
    let mut incomplete = incomplete.into_inner();
    let report = output::write_plots_and_report(
        dir,
        title,
        &rows,
        "",
        &[],
        &notes,
        f64::from(DEFAULT_V_LIMIT),
        &mut incomplete,
    )?;
    report_incomplete(&incomplete);
    let exit = runs_exit(runs.iter(), !incomplete.is_empty(), failed);
    if args.json {
        let cases = Cases {
            cases,
            incomplete,
            preflight: Vec::new(),
            contract: None,
            contract_statistics: Vec::new(),
        };
        print_json(stdout, &cases)?;
    } else {
        print_board_runs(stdout, &notes, &cases)?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(exit)
}

/// One scenario in SIL, then with the board `started` for it; returns the comparison, the
/// board's run, and whether it passed (did not diverge or lose its board, and agreed with SIL
/// where it must).
fn fly_one(
    s: &Scenario,
    started: Started,
    dir: &OutputDir,
    mode: Mode,
    progress: &Progress,
    incomplete: &Incomplete,
) -> (BoardComparison, RunResult, bool) {
    let cfg = s.config();
    // SIL's flight log beside the board's (Choice 356, docs/logs.md#the-board-in-the-same-channels):
    // the two `diff` compares.
    let sil_name = sil_log_name(&cfg.name);
    let mut sil_log = dir
        .claim(&sil_name)
        .map_err(|e| format!("{e:#}"))
        .and_then(|p| McapLog::create(&p, s, "sil", None).map_err(|e| e.to_string()))
        .map_err(|e| incomplete.push(format!("{sil_name} was not written: {e}")))
        .ok();
    let sil_run = sim::fly(
        s,
        &mut LocalController::new(s),
        &mut (&mut sil_log, &mut progress.observer()),
        Recording::Plot,
    );
    if let Some(Err(e)) = sil_log.map(|l| l.finish(&sil_run)) {
        incomplete.push(e.to_string());
    }
    let Started { mut board, log } = started;
    let board_run = run_into(
        dir,
        s,
        &mut board,
        mode.source(),
        None,
        progress,
        incomplete,
    );
    let stats = board.finish();
    if let Some((log, log_path)) = log {
        if let Err(e) = log.commit() {
            incomplete.push(format!("{} was not written: {e}", log_path.display()));
        }
    }
    let summary = board_run.summary();
    let stopped = match (summary.diverged, summary.lost_board) {
        (Some(d), _) => Some((d.t, d.reason)),
        (None, Some(l)) => Some((l.t, l.reason)),
        (None, None) => None,
    };
    if let Some((t, reason)) = stopped {
        eprintln!(
            "host-sim: error: {} {}: stopped at t = {t:.2} s: {reason} (what was recorded is kept in {})",
            mode.name(),
            cfg.name,
            dir.path().display()
        );
    }
    let c = BoardComparison::new(&board_run, &sil_run, stats, mode);
    let interrupted = sil_run.interrupted() || board_run.interrupted();
    // Real time does not repeat SIL (the board's clock, the link's latency): compared,
    // not required to agree.
    let must_agree = c.pil.pacing == Pacing::Lockstep && cfg.link_faults.is_empty();
    let disagrees = must_agree && !interrupted && !c.agrees();
    let ok = !(board_run.diverged() || board_run.lost_board() || disagrees);
    (c, board_run, ok)
}

/// The text `pil` and `hil` print: the comparison with SIL, then every fail-safe entry and exit.
fn print_board_runs(stdout: &mut dyn Write, notes: &str, cases: &[BoardComparison]) -> Result<()> {
    writeln!(stdout, "{notes}")?;
    for c in cases {
        for e in &c.pil.failsafe_events {
            writeln!(
                stdout,
                "{}: fail-safe {} at t = {} s: {}",
                c.run.name,
                e.kind.as_str(),
                // As JSON writes it (3.0, not 3).
                serde_json::Value::from(e.t),
                e.reason
            )?;
        }
    }
    Ok(())
}
