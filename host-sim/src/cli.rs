//! The `host-sim` commands as library functions: each takes its arguments ([`clap::Args`], so
//! the binary only parses and dispatches) and a writer for what it prints on stdout, writes its
//! outputs, and returns how it ended ([`Exit`]). Errors (bad input, I/O) are `Err`: the binary
//! prints them and exits 2.
//!
//! ```text
//! host-sim                                   # = host-sim table1
//! host-sim table1 [--json] [--out DIR]
//! host-sim run --scenario FILE.toml [--json] [--out DIR]
//! host-sim pil (--scenario FILE | --table1) [--duration S] [--drop A..B …] [--link-key-file F] [--json] [--out DIR]
//! host-sim monte-carlo --runs N --seed S [--scenario FILE] [--current V] [--json] [--out DIR]
//! ```
//!
//! `--json` prints one JSON object, `{"cases": [...]}` of [`RunSummary`] (table1, run) or of
//! [`PilComparison`] (pil), or the Monte Carlo [`Summary`](crate::montecarlo::Summary); its
//! keys come out sorted.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use controller_core::{Table1Case, DEFAULT_V_LIMIT};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use crate::config::{LinkFaults, TickRange};
use crate::montecarlo::{self, MonteCarloOptions};
use crate::output::{self, ReportRow};
use crate::paper;
use crate::pil::{BoardInTheLoop, PilComparison};
use crate::record::{Cases, RunResult, RunSummary};
use crate::scenario::{load_scenario, Scenario};
use crate::sil;

/// How a command ended, as the process's exit code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Every run completed (and PIL agreed with SIL): exit 0.
    Success,
    /// A run diverged, or PIL disagreed with SIL: exit 1 (the outputs are written).
    RunFailed,
}

impl Exit {
    /// The process exit code (0 or 1; 2 is the binary's for an `Err`).
    pub fn code(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::RunFailed => 1,
        }
    }

    fn failed_if(failed: bool) -> Self {
        if failed {
            Exit::RunFailed
        } else {
            Exit::Success
        }
    }
}

/// Default report folder of `table1`.
pub const DEFAULT_TABLE1_OUT: &str = "runs/table1";

/// `table1`: the paper's six Table-1 missions with and without Δu, side by side with the paper.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct Table1Args {
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Report folder (CSV, PNG, report.md).
    #[arg(long, default_value = DEFAULT_TABLE1_OUT)]
    pub out: PathBuf,
}

impl Default for Table1Args {
    /// What `host-sim` without a command runs.
    fn default() -> Self {
        Table1Args {
            json: false,
            out: PathBuf::from(DEFAULT_TABLE1_OUT),
        }
    }
}

/// `run`: one scenario from a TOML file (and its companion without Δu, for comparison).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RunArgs {
    #[arg(long)]
    pub scenario: PathBuf,
    #[arg(long)]
    pub json: bool,
    /// Report folder; default `runs/<scenario name>`.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `pil`: processor in the loop. The firmware ELF in QEMU flies the simulated vehicle over a
/// loopback socket, lock-stepped; compared with SIL. Link faults by tick range (A..B).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct PilArgs {
    #[arg(long, conflicts_with = "table1")]
    pub scenario: Option<PathBuf>,
    /// The six Table-1 missions (with Δu).
    #[arg(long)]
    pub table1: bool,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/pil")]
    pub out: PathBuf,
    /// Firmware ELF: the QEMU flying image [default:
    /// target/thumbv7em-none-eabihf/release/firmware-qemu].
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Sign the link with this key file (`#` comment lines, then 64 hex digits; e.g.
    /// firmware/ci-test-link-key.hex): the board is started with it, and both ends refuse
    /// unsigned frames. Without it the link is unsigned.
    #[arg(long)]
    pub link_key_file: Option<PathBuf>,
    /// Override the scenario's duration (s).
    #[arg(long)]
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
}

/// `monte-carlo`: draws the Table-3 parameters uniformly in their box, runs in parallel,
/// reports percentiles and the worst case. Deterministic per seed.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct MonteCarloArgs {
    #[arg(long)]
    pub runs: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Base scenario (default: circular-10R).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Also draw a constant horizontal current of up to this speed (m/s).
    #[arg(long)]
    pub current: Option<f64>,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/monte-carlo")]
    pub out: PathBuf,
}

fn progress(n: usize, what: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(n as u64);
    pb.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} runs, {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// One JSON line: the value through `serde_json::Value`, so the keys come out sorted.
fn print_json(stdout: &mut dyn Write, value: &impl Serialize) -> Result<()> {
    let v = serde_json::to_value(value).context("serialising the JSON output")?;
    writeln!(stdout, "{v}").context("writing stdout")
}

fn load(path: &Path) -> Result<Scenario> {
    load_scenario(path).with_context(|| format!("scenario {}", path.display()))
}

/// Prints the runs of `rows` (JSON, or the table and the report's path) and says whether one
/// diverged.
fn print_runs(
    stdout: &mut dyn Write,
    json: bool,
    rows: &[ReportRow],
    report: &Path,
) -> Result<Exit> {
    if json {
        let cases: Cases<RunSummary> = Cases {
            cases: runs(rows).map(RunResult::summary).collect(),
        };
        print_json(stdout, &cases)?;
    } else {
        writeln!(stdout, "{}", output::table_text(rows))?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(Exit::failed_if(runs(rows).any(RunResult::diverged)))
}

/// Every run of the rows: with, then without Δu.
fn runs<'a: 'r, 'r>(rows: &'r [ReportRow<'a>]) -> impl Iterator<Item = &'a RunResult> + 'r {
    rows.iter()
        .flat_map(|r| std::iter::once(r.with).chain(r.without))
}

/// `table1`.
pub fn table1(args: &Table1Args, stdout: &mut dyn Write) -> Result<Exit> {
    let pb = progress(12, "Table 1", args.json);
    let pairs = paper::run_all(|| pb.inc(1))?;
    pb.finish_and_clear();
    let rows: Vec<ReportRow> = pairs
        .iter()
        .map(|(with, without)| ReportRow::new(with, Some(without)))
        .collect();
    let report = output::write_all(
        &args.out,
        "AUV-150 Table 1 reproduction (software in the loop)",
        &rows,
        paper::NOTES,
        f64::from(DEFAULT_V_LIMIT),
    )?;
    print_runs(stdout, args.json, &rows, &report)
}

/// `run`.
pub fn run(args: &RunArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let scenario = load(&args.scenario)?;
    let cfg = scenario.config();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(&cfg.name));
    let companion = if cfg.controller.robust {
        Some(
            scenario
                .with(|c| c.controller.robust = false)
                .with_context(|| format!("scenario {} without Δu", args.scenario.display()))?,
        )
    } else {
        None
    };
    let pb = progress(1 + companion.is_some() as usize, &cfg.name, args.json);
    let with = sil::run(&scenario);
    pb.inc(1);
    let without = companion.as_ref().map(sil::run);
    pb.finish_and_clear();
    let rows = [ReportRow::new(&with, without.as_ref())];
    let report = output::write_all(
        &out,
        &format!("AUV-150 scenario {}", with.name),
        &rows,
        "",
        f64::from(cfg.controller.voltage_limit),
    )?;
    print_runs(stdout, args.json, &rows, &report)
}

/// `monte-carlo`.
pub fn monte_carlo(args: &MonteCarloArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if args.runs == 0 {
        bail!("--runs must be at least 1");
    }
    if let Some(c) = args.current {
        if !(c.is_finite() && c >= 0.0) {
            bail!("--current must be a finite speed ≥ 0 m/s, got {c}");
        }
    }
    let base = match &args.scenario {
        Some(p) => load(p)?,
        None => paper::scenario(Table1Case::Circular10R, true)?,
    };
    let pb = progress(args.runs, "Monte Carlo", args.json);
    let summary = montecarlo::run(
        &base,
        &MonteCarloOptions {
            runs: args.runs,
            seed: args.seed,
            max_current: args.current,
        },
        || pb.inc(1),
    )?;
    pb.finish_and_clear();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let md = summary.markdown();
    let report = args.out.join("report.md");
    std::fs::write(&report, &md).with_context(|| format!("writing {}", report.display()))?;
    if args.json {
        let text = serde_json::to_string(&summary).context("serialising the summary")?;
        writeln!(stdout, "{text}")?;
    } else {
        writeln!(stdout, "{md}")?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(Exit::failed_if(summary.diverged > 0))
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `pil`. Exits 1 if a run diverged, or if a run without link faults differs from SIL by more
/// than [`PIL_SIL_TOLERANCE`](crate::pil::PIL_SIL_TOLERANCE).
pub fn pil(args: &PilArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let base: Vec<Scenario> = match (&args.scenario, args.table1) {
        (Some(p), false) => vec![load(p)?],
        (None, true) => Table1Case::ALL
            .iter()
            .map(|&case| paper::scenario(case, true))
            .collect::<Result<_, _>>()?,
        _ => bail!("give --scenario FILE or --table1"),
    };
    // The flags override the duration and add to the scenario's [link_faults].
    let mut scenarios = Vec::with_capacity(base.len());
    for s in &base {
        let changed = s.with(|c| {
            if let Some(d) = args.duration {
                c.duration = d;
            }
            let f = &mut c.link_faults;
            f.drop.extend(args.drop.iter().copied());
            f.corrupt.extend(args.corrupt.iter().copied());
            f.delay.extend(args.delay.iter().copied());
            f.silent.extend(args.silent.iter().copied());
            if !args.delay.is_empty() {
                f.delay_ticks = args.delay_ticks;
            }
        });
        scenarios.push(changed.with_context(|| match args.duration {
            Some(d) => format!("{} with --duration {d}", s.config().name),
            None => s.config().name.clone(),
        })?);
    }
    let root = workspace_root();
    let elf = args
        .elf
        .clone()
        .unwrap_or_else(|| crate::pil::default_elf(&root));
    let runner = root.join("scripts/qemu-run.sh");
    let key = match &args.link_key_file {
        None => None,
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("reading the link key file {}", p.display()))?;
            Some(
                auv_link::sign::LinkKey::from_key_file(&text)
                    .map_err(|e| anyhow!("{}: {e}", p.display()))?,
            )
        }
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let pb = progress(scenarios.len(), "PIL", args.json);
    let mut cases = Vec::new();
    let mut runs = Vec::new();
    let mut failed = false;
    for s in &scenarios {
        let cfg = s.config();
        let sil_run = sil::run(s);
        let log = args.out.join(format!("{}-qemu.log", cfg.name));
        let mut board = BoardInTheLoop::start(
            &elf,
            &runner,
            cfg,
            cfg.link_faults.clone(),
            &log,
            key.as_ref(),
        )
        .map_err(|e| anyhow!("{}: {e}", cfg.name))?;
        let pil_run = sil::run_with(s, &mut board);
        let stats = board.finish();
        pb.inc(1);
        let c = PilComparison::new(&pil_run, &sil_run, stats);
        failed |= pil_run.diverged() || (cfg.link_faults.is_empty() && !c.agrees());
        cases.push(c);
        runs.push(pil_run);
    }
    pb.finish_and_clear();
    let notes = pil_notes(&cases);
    let rows: Vec<ReportRow> = runs.iter().map(|r| ReportRow::new(r, None)).collect();
    let report = output::write_all(
        &args.out,
        "AUV-150 processor in the loop (firmware in QEMU)",
        &rows,
        &notes,
        f64::from(DEFAULT_V_LIMIT),
    )?;
    if args.json {
        print_json(stdout, &Cases { cases })?;
    } else {
        writeln!(stdout, "{notes}")?;
        for c in &cases {
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
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(Exit::failed_if(failed))
}

/// The report's PIL-vs-SIL section.
fn pil_notes(cases: &[PilComparison]) -> String {
    let mut notes = String::from(
        "## Processor in the loop vs software in the loop\n\n\
         | case | PIL max path (m) | SIL max path (m) | PIL − SIL (m) | frames/s | worst update \
         (instructions) | fail-safe events | re-arms | signed | board drops (old / auth) | \
         board refusals |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cases {
        notes += &format!(
            "| {} | {:.5} | {:.5} | {:+.2e} | {:.0} | {} | {} | {} | {} | {} / {} | {} |\n",
            c.run.name,
            c.run.metrics.max_path,
            c.sil_max_path,
            c.pil_minus_sil_max_path,
            c.pil.frames_per_second,
            c.pil.worst_update_instructions,
            c.pil.failsafe_events.len(),
            c.pil.rearms,
            if c.pil.signed { "yes" } else { "no" },
            c.pil.board_rx_stale,
            c.pil.board_rx_auth_errors,
            match &c.pil.board_last_refusal {
                Some(r) => format!("{} (last: {r})", c.pil.board_refused_commands),
                None => c.pil.board_refused_commands.to_string(),
            },
        );
    }
    notes
}
