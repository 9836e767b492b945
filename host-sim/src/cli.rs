//! The `host-sim` commands as library functions: each takes its arguments ([`clap::Args`], so
//! the binary only parses and dispatches) and a writer for what it prints on stdout, writes its
//! outputs, and returns how it ended ([`Exit`]). Errors (bad input, I/O) are `Err`: the binary
//! prints them once and exits 2.
//!
//! ```text
//! host-sim                                   # = host-sim table1
//! host-sim table1 [--json] [--out DIR]
//! host-sim run --scenario FILE.toml [--json] [--out DIR] [--allow-long-run]
//! host-sim pil (--scenario FILE | --table1) [--duration S] [--drop A..B …] [--link-key-file F] [--json] [--out DIR]
//! host-sim hil --port PATH [--baud N] [--pacing lockstep|realtime] [--reply-timeout S] (--scenario FILE | --table1) [the pil flags] [--json] [--out DIR]
//! host-sim monte-carlo --runs N --seed S [--scenario FILE] [--current V] [--json] [--out DIR]
//! host-sim check --scenario FILE.toml [--margin 0.8] [--json]
//! ```
//!
//! `check` is the preflight feasibility check ([`crate::preflight`]): it simulates nothing, and
//! exits 0 when the mission is feasible at its time scale, 1 when it is not (the verdict says
//! whether a time scale helps), 2 on bad input. `run` and `table1` print the same verdict for
//! each mission, one line each, and put it in the report; they never refuse to run.
//!
//! `--json` prints one JSON object, `{"cases": [...]}` of [`RunSummary`] (table1, run) or of
//! [`PilComparison`] (pil, hil), or the Monte Carlo [`Summary`](crate::montecarlo::Summary); its
//! keys come out sorted.
//!
//! Every command, before it computes anything: validates its input (scenario, flags, the step
//! cap), checks and prepares the output folder ([`OutputDir::prepare`]: a folder, not a symlink,
//! writable; the previous run's files removed), and for `pil` checks the firmware image. Then
//! the runs stream their CSVs ([`CsvStream`]) and show progress ([`Progress`]), and the plots
//! and the report follow. An output that cannot be written completely (a full disk) is named
//! on stderr, in the report and in the JSON (`incomplete`), once, and the command exits 2; the
//! other outputs are still written.
//!
//! # Exit codes
//!
//! | code | meaning |
//! |---|---|
//! | 0 | every run completed, the controller never in fail-safe unless expected (and PIL agreed with SIL) |
//! | 1 | a run diverged (or lost its board), or PIL disagreed with SIL; `check`: the mission is infeasible |
//! | 2 | bad input (scenario, flags, output folder, firmware image) or an I/O error; or an output could not be written completely |
//! | 3 | a run had the controller in fail-safe (thrusters off) for some periods and its scenario does not say `expect_faults = true` |
//! | 130 | interrupted (Ctrl-C, SIGTERM): what was done is written and marked partial |
//!
//! When several apply, the first of 2, 130, 1, 3 is the exit code. In `pil`, a run with link
//! faults injected (flags or `[link_faults]`) expects the board's fail-safe. In `table1`, the
//! paper's missions flown through the real chain are there to show what happens when the
//! preflight says infeasible: their divergence and faults are reported, not an exit code.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use controller_core::{Table1Case, DEFAULT_V_LIMIT};
use serde::Serialize;

use crate::config::{CurrentModel, LinkFaults, TickRange, VariationProfile};
use crate::interrupt;
use crate::montecarlo::{self, MonteCarloOptions, MAX_RUNS};
use crate::output::{self, atomic, CsvStream, OutputDir, RealRow, ReportRow};
use crate::paper;
use crate::pil::{BoardInTheLoop, Mode, Pacing, PilComparison};
use crate::preflight::{self, Preflight, DEFAULT_MARGIN};
use crate::progress::Progress;
use crate::real;
use crate::record::{Cases, RunResult, RunSummary};
use crate::scenario::{load_config, Scenario};
use crate::sil::{self, ControlSource, LocalController};

/// How a command ended, as the process's exit code (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Every run completed, no unexpected controller fault (and PIL agreed with SIL): exit 0.
    Success,
    /// A run diverged, or PIL disagreed with SIL: exit 1 (the outputs are written).
    RunFailed,
    /// An output could not be written completely (named on stderr and in the report): exit 2.
    OutputIncomplete,
    /// The controller was in fail-safe in some period of a run that does not expect faults:
    /// exit 3 (the outputs are written).
    Faulted,
    /// Interrupted (Ctrl-C, SIGTERM); what was done is written, marked partial: exit 130.
    Interrupted,
    /// `check`: the mission is not feasible at its time scale: exit 1.
    Infeasible,
}

impl Exit {
    /// The process exit code (0, 1, 2, 3 or 130; 2 is also the binary's for an `Err`).
    pub fn code(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::RunFailed | Exit::Infeasible => 1,
            Exit::OutputIncomplete => 2,
            Exit::Faulted => 3,
            Exit::Interrupted => 130,
        }
    }

    /// The exit of a command from what happened, in the order of precedence 2, 130, 1, 3.
    fn of(incomplete: bool, interrupted: bool, failed: bool, faulted: bool) -> Self {
        if incomplete {
            Exit::OutputIncomplete
        } else if interrupted {
            Exit::Interrupted
        } else if failed {
            Exit::RunFailed
        } else if faulted {
            Exit::Faulted
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
    /// Run a scenario beyond the step cap (host_sim::scenario::MAX_CONTROL_PERIODS,
    /// MAX_PLANT_STEPS: one day at 100 Hz and 1 ms).
    #[arg(long)]
    pub allow_long_run: bool,
}

/// `check`: the preflight feasibility check of one scenario (nothing is simulated).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct CheckArgs {
    #[arg(long)]
    pub scenario: PathBuf,
    /// Print one JSON object (the check's [`Preflight`]) instead of the text.
    #[arg(long)]
    pub json: bool,
    /// Fraction of each thruster's envelope the reference may use, in (0, 1]; the rest is left
    /// to the feedback.
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
}

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
    /// Run beyond the step cap (see `run --help`).
    #[arg(long)]
    pub allow_long_run: bool,
}

/// `pil`: processor in the loop. The firmware ELF in QEMU flies the simulated vehicle over a
/// loopback socket, lock-stepped; compared with SIL. Link faults by tick range (A..B).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct PilArgs {
    #[command(flatten)]
    pub common: LoopArgs,
    #[arg(long, default_value = "runs/pil")]
    pub out: PathBuf,
    /// Firmware ELF: a flying image that runs in QEMU, `firmware-qemu` or
    /// `firmware-stm32f405-emulator` [default: target/thumbv7em-none-eabihf/release/firmware-qemu].
    #[arg(long)]
    pub elf: Option<PathBuf>,
}

/// The STM32 board's link baud rate (`firmware::serial::LINK_BAUD`), `hil`'s default.
pub const DEFAULT_HIL_BAUD: u32 = firmware::serial::LINK_BAUD;

/// `hil`'s default reply timeout (s): a board answers every period (10 ms at 100 Hz).
pub const DEFAULT_HIL_REPLY_TIMEOUT: f64 = 5.0;

/// `hil`: hardware in the loop. The board on a serial port (a USB-serial adapter, or QEMU's
/// `-serial pty`) flies the simulated vehicle; compared with SIL. Link faults as `pil`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct HilArgs {
    /// The serial device of the board's link (e.g. /dev/ttyUSB0, or QEMU's /dev/pts/N).
    #[arg(long)]
    pub port: String,
    /// Baud rate (8N1, no flow control); the default is the STM32 board's.
    #[arg(long, default_value_t = DEFAULT_HIL_BAUD)]
    pub baud: u32,
    /// lockstep: the board runs a period per state frame (as PIL; equals SIL); realtime: the
    /// board runs on its own timer and the host flies the plant in wall-clock time.
    #[arg(long, value_enum, default_value_t = Pacing::Lockstep)]
    pub pacing: Pacing,
    /// Seconds without valid telemetry after which the run stops (a silent or garbled link).
    #[arg(long, default_value_t = DEFAULT_HIL_REPLY_TIMEOUT)]
    pub reply_timeout: f64,
    #[command(flatten)]
    pub common: LoopArgs,
    #[arg(long, default_value = "runs/hil")]
    pub out: PathBuf,
}

/// `monte-carlo`: draws the Table-3 parameters uniformly in their box, runs in parallel,
/// reports percentiles and the worst case. Deterministic per seed.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct MonteCarloArgs {
    /// How many runs (at most host_sim::montecarlo::MAX_RUNS without --allow-long-run).
    #[arg(long)]
    pub runs: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Base scenario (default: circular-10R).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Also draw a constant horizontal current of up to this speed (m/s).
    #[arg(long, allow_negative_numbers = true)]
    pub current: Option<f64>,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/monte-carlo")]
    pub out: PathBuf,
    /// Allow more than host_sim::montecarlo::MAX_RUNS runs, and runs beyond the step cap.
    #[arg(long)]
    pub allow_long_run: bool,
}

/// One JSON line: the value through `serde_json::Value`, so the keys come out sorted.
fn print_json(stdout: &mut dyn Write, value: &impl Serialize) -> Result<()> {
    let v = serde_json::to_value(value).context("serialising the JSON output")?;
    writeln!(stdout, "{v}").context("writing stdout")
}

/// Reads and validates a scenario file, with the step cap lifted if `allow_long_run`.
fn load(path: &Path, allow_long_run: bool) -> Result<Scenario> {
    let ctx = || format!("scenario {}", path.display());
    let mut config = load_config(path).with_context(ctx)?;
    config.allow_long_run = allow_long_run;
    Scenario::new(config).with_context(ctx)
}

/// The control periods of `scenarios`, for [`Progress`].
fn periods<'a>(scenarios: impl IntoIterator<Item = &'a Scenario>) -> u64 {
    scenarios.into_iter().map(|s| s.steps() + 1).sum()
}

/// Outputs that could not be written completely, collected from parallel runs.
#[derive(Default)]
struct Incomplete(Mutex<Vec<String>>);

impl Incomplete {
    fn push(&self, what: String) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(what);
    }
    fn into_inner(self) -> Vec<String> {
        self.0.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// One run with the law from `source`, its CSV streamed into `dir` and its periods counted
/// into `progress`; a CSV that cannot be written completely goes to `incomplete` (the run goes
/// on: its metrics are still good).
fn run_into(
    dir: &OutputDir,
    scenario: &Scenario,
    source: &mut dyn ControlSource,
    progress: &Progress,
    incomplete: &Incomplete,
) -> RunResult {
    let cfg = scenario.config();
    let name = output::csv_name(&cfg.name, cfg.controller.robust);
    let mut counter = progress.observer();
    match dir.claim(&name).and_then(|p| CsvStream::create(&p)) {
        Ok(mut csv) => {
            let run = sil::run_observed(scenario, source, &mut (&mut csv, &mut counter));
            if let Err(e) = csv.finish() {
                incomplete.push(e.to_string());
            }
            run
        }
        Err(e) => {
            incomplete.push(format!("{name} was not written: {e:#}"));
            sil::run_observed(scenario, source, &mut counter)
        }
    }
}

/// [`run_into`] with the law on the host.
fn sil_into(
    dir: &OutputDir,
    scenario: &Scenario,
    progress: &Progress,
    incomplete: &Incomplete,
) -> RunResult {
    run_into(
        dir,
        scenario,
        &mut LocalController::new(scenario),
        progress,
        incomplete,
    )
}

/// Says once, on stderr, which outputs are incomplete.
fn report_incomplete(incomplete: &[String]) {
    for i in incomplete {
        eprintln!("host-sim: error: {i}");
    }
}

/// Prints the runs of `rows` (JSON, or the table and the report's path) and says how the
/// command ended.
fn print_runs(
    stdout: &mut dyn Write,
    json: bool,
    rows: &[ReportRow],
    checks: &[Preflight],
    report: &Path,
    incomplete: Vec<String>,
) -> Result<Exit> {
    report_incomplete(&incomplete);
    let exit = runs_exit(runs(rows), !incomplete.is_empty(), false);
    if json {
        let cases: Cases<RunSummary> = Cases {
            cases: runs(rows).map(RunResult::summary).collect(),
            incomplete,
            preflight: checks.to_vec(),
        };
        print_json(stdout, &cases)?;
    } else {
        for c in checks {
            writeln!(stdout, "{c}")?;
        }
        writeln!(stdout, "{}", output::table_text(rows))?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(exit)
}

/// The preflight checks of `scenarios` (in parallel), at the default margin.
fn preflights<'a>(scenarios: impl IntoIterator<Item = &'a Scenario>) -> Result<Vec<Preflight>> {
    use rayon::prelude::*;
    let v: Vec<&Scenario> = scenarios.into_iter().collect();
    v.par_iter()
        .map(|s| {
            preflight::check(s, DEFAULT_MARGIN)
                .map_err(|e| anyhow!("preflight of {}: {e}", s.config().name))
        })
        .collect()
}

/// The report section of preflight verdicts: one line each.
fn preflight_section(checks: &[Preflight]) -> String {
    let mut s = format!(
        "## Preflight (docs/design.md §9)\n\nWhether the real thrusters can fly each mission \
         (`host-sim check --scenario FILE`): the force the reference needs at every corner of \
         the parameter box, through the board's allocator, against {:.0} % of each thruster's \
         envelope.\n\n",
        100.0 * DEFAULT_MARGIN
    );
    for c in checks {
        s.push_str(&format!("- {}\n", c.to_string().replace('|', "\\|")));
    }
    s
}

/// How a command with these runs ended ([`Exit::of`]); `failed`: another reason for exit 1.
fn runs_exit<'a>(
    runs: impl Iterator<Item = &'a RunResult> + Clone,
    incomplete: bool,
    failed: bool,
) -> Exit {
    Exit::of(
        incomplete,
        runs.clone().any(RunResult::interrupted) || interrupt::requested(),
        failed || runs.clone().any(RunResult::diverged),
        runs.clone().any(RunResult::faulted_unexpectedly),
    )
}

/// Every run of the rows: with, then without Δu.
fn runs<'a: 'r, 'r>(rows: &'r [ReportRow<'a>]) -> impl Iterator<Item = &'a RunResult> + Clone + 'r {
    rows.iter()
        .flat_map(|r| std::iter::once(r.with).chain(r.without))
}

/// What the report says about the real-vehicle table.
const REAL_NOTES: &str = "\
## The real vehicle (docs/design.md §9)

The missions of `scenarios/real/` fly the Table-1 paths as a vehicle team would: heading along
the course, the Table-3 payload trimmed to neutral buoyancy, Eqs 31–32 in kgf, and the real
actuator chain (the board's voltages, clamped at ±24 V, turned back into thrust by Eqs 31–32),
each at the time scale the preflight check proposes. Below them, the paper's own six missions
(its headings, untrimmed payload, time scale 1) through the same real chain: what the preflight
calls infeasible, flown anyway.
";

/// `table1`: the paper's Table 1 (ideal actuators), then the real vehicle: the missions of
/// `scenarios/real/` and the paper's six through the real chain, with their preflight verdicts.
pub fn table1(args: &Table1Args, stdout: &mut dyn Write) -> Result<Exit> {
    use rayon::prelude::*;
    let jobs = paper::jobs()?;
    let real_jobs = real::real_scenarios()?;
    let chain_jobs = real::paper_real_chain_scenarios(&real_jobs)?;
    let dir = OutputDir::prepare(&args.out)?;
    // The paper's missions' verdicts (the Table-1 cases, with Δu: the same mission as the
    // real-chain runs), then the real ones.
    let checks = preflights(chain_jobs.iter().chain(&real_jobs))?;
    let all: Vec<&Scenario> = jobs.iter().chain(&real_jobs).chain(&chain_jobs).collect();
    let progress = Progress::start("Table 1", periods(all.iter().copied()), !args.json);
    let incomplete = Incomplete::default();
    let results: Vec<RunResult> = all
        .par_iter()
        .map(|s| sil_into(&dir, s, &progress, &incomplete))
        .collect();
    progress.finish();
    let (paper_runs, rest) = results.split_at(jobs.len());
    let (real_runs, chain_runs) = rest.split_at(real_jobs.len());
    let rows: Vec<ReportRow> = paper_runs
        .chunks(2)
        .map(|pair| ReportRow::new(&pair[0], pair.get(1)))
        .collect();
    let (chain_checks, real_checks) = checks.split_at(chain_jobs.len());
    let real_rows: Vec<RealRow> = real_runs
        .iter()
        .zip(real_checks)
        .chain(chain_runs.iter().zip(chain_checks))
        .map(|(run, preflight)| RealRow { run, preflight })
        .collect();
    let sections = format!(
        "{REAL_NOTES}\n{}\n{}\n\n{}",
        output::real_table_markdown(&real_rows),
        output::report::real_table_legend(),
        preflight_section(&checks)
    );
    let real_plots: Vec<ReportRow> = real_runs.iter().map(|r| ReportRow::new(r, None)).collect();
    let mut incomplete = incomplete.into_inner();
    let report = output::write_plots_and_report(
        &dir,
        "AUV-150 Table 1 reproduction (software in the loop)",
        &rows,
        &sections,
        &real_plots,
        paper::NOTES,
        f64::from(DEFAULT_V_LIMIT),
        &mut incomplete,
    )?;
    report_incomplete(&incomplete);
    // The paper's missions through the real chain are expected to fail: they show what an
    // infeasible verdict means, and do not make the command fail.
    let exit = runs_exit(
        paper_runs.iter().chain(real_runs),
        !incomplete.is_empty(),
        false,
    );
    if args.json {
        let cases: Cases<RunSummary> = Cases {
            cases: results.iter().map(RunResult::summary).collect(),
            incomplete,
            preflight: checks,
        };
        print_json(stdout, &cases)?;
    } else {
        writeln!(stdout, "{}", output::table_text(&rows))?;
        writeln!(
            stdout,
            "The real vehicle: the missions of scenarios/real/ and the paper's through the real chain (kgf, ±24 V)"
        )?;
        for c in &checks {
            writeln!(stdout, "{c}")?;
        }
        writeln!(stdout)?;
        write!(stdout, "{}", output::real_table_text(&real_rows))?;
        writeln!(stdout, "{}\n", output::report::real_table_legend())?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(exit)
}

/// `check`: the preflight check of one scenario; exit 0 feasible, 1 infeasible.
pub fn check(args: &CheckArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if !(args.margin > 0.0 && args.margin <= 1.0) {
        bail!(
            "--margin must be a fraction of the envelope in (0, 1], got {}",
            args.margin
        );
    }
    let scenario = load(&args.scenario, false)?;
    let p = preflight::check(&scenario, args.margin).map_err(|e| anyhow!(e))?;
    if args.json {
        print_json(stdout, &p)?;
    } else {
        writeln!(stdout, "{p}")?;
        writeln!(stdout, "{}", preflight_table(&p))?;
    }
    Ok(if p.feasible() {
        Exit::Success
    } else {
        Exit::Infeasible
    })
}

/// The per-thruster part of `check`'s text.
fn preflight_table(p: &Preflight) -> String {
    let mut s = format!(
        "thrust unit {}, heading {}, trimmed {}, time scale {}, margin {:.0} %\n",
        p.thrust_unit,
        p.heading,
        p.trimmed,
        p.time_scale,
        100.0 * p.margin
    );
    s.push_str(&format!(
        "{:<10} {:>18} {:>22} {:>22} {:>8}\n",
        "thruster", "envelope (N)", "min demand (N) at t", "max demand (N) at t", "usage"
    ));
    for t in &p.thrusters {
        s.push_str(&format!(
            "{:<10} {:>18} {:>22} {:>22} {:>6.0} %\n",
            t.thruster,
            format!("[{:.1}, {:.1}]", t.envelope[0], t.envelope[1]),
            format!("{:.1} at {:.2} s", t.min, t.t_min),
            format!("{:.1} at {:.2} s", t.max, t.t_max),
            100.0 * t.usage
        ));
    }
    if let Some(k) = p.smallest_time_scale {
        s.push_str(&format!(
            "smallest feasible time scale: {k} (the same path then takes {:.1} s)\n",
            p.duration * k / p.time_scale
        ));
    }
    s
}

/// `run`.
pub fn run(args: &RunArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let scenario = load(&args.scenario, args.allow_long_run)?;
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
    let dir = OutputDir::prepare(&out)?;
    // The verdict of the mission as the scenario flies it (with Δu: the check does not depend
    // on the law).
    let checks = preflights(std::iter::once(&scenario))?;
    let progress = Progress::start(
        &cfg.name,
        periods(std::iter::once(&scenario).chain(&companion)),
        !args.json,
    );
    let incomplete = Incomplete::default();
    let with = sil_into(&dir, &scenario, &progress, &incomplete);
    // A run interrupted is not followed by its companion (nothing would be done of it).
    let without = companion
        .as_ref()
        .filter(|_| !interrupt::requested())
        .map(|c| sil_into(&dir, c, &progress, &incomplete));
    progress.finish();
    let rows = [ReportRow::new(&with, without.as_ref())];
    let mut incomplete = incomplete.into_inner();
    let report = output::write_plots_and_report(
        &dir,
        &format!("AUV-150 scenario {}", with.name),
        &rows,
        &preflight_section(&checks),
        &[],
        "",
        f64::from(cfg.controller.voltage_limit),
        &mut incomplete,
    )?;
    print_runs(stdout, args.json, &rows, &checks, &report, incomplete)
}

/// The base scenario of `monte-carlo`: the file's, which must leave to the draw what the draw
/// replaces, or the paper's circle of 10 m radius without its Table-3 profile.
fn monte_carlo_base(args: &MonteCarloArgs) -> Result<Scenario> {
    let Some(path) = &args.scenario else {
        return Ok(paper::scenario(Table1Case::Circular10R, true)?
            .with(|c| c.variation = VariationProfile::None)?);
    };
    let base = load(path, args.allow_long_run)?;
    let cfg = base.config();
    if cfg.variation != VariationProfile::None {
        bail!(
            "scenario {}: monte-carlo draws the plant's Δp itself (uniform in the Table-3 box, \
             constant over each run) and would replace the scenario's own [variation]; remove \
             the [variation] table (or set profile = \"none\") to run it",
            path.display()
        );
    }
    if args.current.is_some() && cfg.current != CurrentModel::None {
        bail!(
            "scenario {}: --current draws a constant current for each run and would replace the \
             scenario's own [current]; remove one of the two",
            path.display()
        );
    }
    Ok(base)
}

/// `monte-carlo`.
pub fn monte_carlo(args: &MonteCarloArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if args.runs == 0 {
        bail!("--runs must be at least 1");
    }
    if args.runs > MAX_RUNS && !args.allow_long_run {
        bail!(
            "--runs {} is more than {MAX_RUNS}; give --allow-long-run to run that many",
            args.runs
        );
    }
    if let Some(c) = args.current {
        if !(c.is_finite() && c >= 0.0) {
            bail!("--current must be a finite speed ≥ 0 m/s, got {c}");
        }
    }
    let base = monte_carlo_base(args)?;
    let dir = OutputDir::prepare(&args.out)?;
    let opts = MonteCarloOptions {
        runs: args.runs,
        seed: args.seed,
        max_current: args.current,
    };
    eprintln!(
        "host-sim: monte-carlo: {}",
        montecarlo::estimate(&base, &opts)?
    );
    let progress = Progress::start(
        "Monte Carlo",
        args.runs as u64 * (base.steps() + 1),
        !args.json,
    );
    let summary = montecarlo::run(&base, &opts, || progress.observer())?;
    progress.finish();
    let md = summary.markdown();
    let report = dir.claim("report.md")?;
    atomic::write(&report, md.as_bytes())
        .with_context(|| format!("writing {}", report.display()))?;
    if args.json {
        let text = serde_json::to_string(&summary).context("serialising the summary")?;
        writeln!(stdout, "{text}")?;
    } else {
        writeln!(stdout, "{md}")?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(Exit::of(
        false,
        summary.partial,
        summary.diverged > 0,
        summary.faulted > 0 && !base.config().expect_faults,
    ))
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The scenarios of a `pil` or `hil` run: the flags override the duration and add to each
/// scenario's [link_faults]; every check of the scenario (duration, step cap) applies to the
/// result.
fn loop_scenarios(args: &LoopArgs) -> Result<Vec<Scenario>> {
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
fn link_key(args: &LoopArgs) -> Result<Option<auv_link::sign::LinkKey>> {
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
struct Started {
    board: BoardInTheLoop,
    log: Option<(atomic::Pending, PathBuf)>,
}

/// `pil`. Exits 1 if a run diverged, or if a run without link faults differs from SIL by more
/// than [`PIL_SIL_TOLERANCE`](crate::pil::PIL_SIL_TOLERANCE).
pub fn pil(args: &PilArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let scenarios = loop_scenarios(&args.common)?;
    let root = workspace_root();
    let elf = args
        .elf
        .clone()
        .unwrap_or_else(|| crate::pil::default_elf(&root));
    crate::pil::check_flying_image(&elf).map_err(|e| anyhow!(e))?;
    let runner = root.join(firmware::qemu_runner::SCRIPT);
    let key = link_key(&args.common)?;
    let dir = OutputDir::prepare(&args.out)?;
    fly(
        &args.common,
        &scenarios,
        &dir,
        Mode::Pil,
        stdout,
        |s: &Scenario, dir: &OutputDir| {
            let cfg = s.config();
            let log_path = dir.claim(&format!("{}-qemu.log", cfg.name))?;
            let (log, log_file) = atomic::Pending::create(&log_path)
                .with_context(|| format!("writing {}", log_path.display()))?;
            match BoardInTheLoop::start(
                &elf,
                &runner,
                s,
                cfg.link_faults.clone(),
                log_file,
                &log_path,
                key.as_ref(),
            ) {
                Ok(board) => Ok(Started {
                    board,
                    log: Some((log, log_path)),
                }),
                Err(e) => {
                    // Keep QEMU's log: it says why.
                    let _ = log.commit();
                    bail!("{}: {e}", cfg.name);
                }
            }
        },
    )
}

/// `hil`. Exits 1 if a run diverged or lost its board, or if a lock-step run without link
/// faults differs from SIL by more than [`PIL_SIL_TOLERANCE`](crate::pil::PIL_SIL_TOLERANCE);
/// 2 if the port cannot be opened or the board never answers the set-up.
pub fn hil(args: &HilArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if !(args.reply_timeout.is_finite() && args.reply_timeout > 0.0 && args.reply_timeout <= 3600.0)
    {
        bail!(
            "--reply-timeout must be a time in (0, 3600] s, got {}",
            args.reply_timeout
        );
    }
    if args.baud == 0 {
        bail!("--baud must be a positive baud rate");
    }
    let scenarios = loop_scenarios(&args.common)?;
    let key = link_key(&args.common)?;
    let dir = OutputDir::prepare(&args.out)?;
    let timeout = std::time::Duration::from_secs_f64(args.reply_timeout);
    fly(
        &args.common,
        &scenarios,
        &dir,
        Mode::Hil,
        stdout,
        |s: &Scenario, _: &OutputDir| {
            let cfg = s.config();
            BoardInTheLoop::over_serial(
                &args.port,
                args.baud,
                s,
                cfg.link_faults.clone(),
                args.pacing,
                timeout,
                key.as_ref(),
            )
            .map(|board| Started { board, log: None })
            .map_err(|e| anyhow!("{}: {e}", cfg.name))
        },
    )
}

/// The runs of `pil` and `hil`: each scenario in SIL, then with the board `start` connects,
/// compared; the report, and how the command ended. A run that loses its board keeps what it
/// recorded (its CSV, its row in the report, marked diverged with the reason) and is named on
/// stderr (**Choice 72**); a real-time run is compared with SIL but need not agree with it
/// (**Choice 69**; docs/design.md §21).
fn fly(
    args: &LoopArgs,
    scenarios: &[Scenario],
    dir: &OutputDir,
    mode: Mode,
    stdout: &mut dyn Write,
    mut start: impl FnMut(&Scenario, &OutputDir) -> Result<Started>,
) -> Result<Exit> {
    let (name, title) = match mode {
        Mode::Pil => ("PIL", "AUV-150 processor in the loop (firmware in QEMU)"),
        Mode::Hil => (
            "HIL",
            "AUV-150 hardware in the loop (board on a serial port)",
        ),
    };
    // Each scenario runs twice: SIL, then on the board.
    let progress = Progress::start(name, 2 * periods(scenarios), !args.json);
    let incomplete = Incomplete::default();
    let mut cases = Vec::new();
    let mut runs = Vec::new();
    let mut failed = false;
    for s in scenarios {
        if interrupt::requested() {
            break;
        }
        let cfg = s.config();
        let sil_run = sil::run_observed(s, &mut LocalController::new(s), &mut progress.observer());
        let Started { mut board, log } = start(s, dir)?;
        let board_run = run_into(dir, s, &mut board, &progress, &incomplete);
        let stats = board.finish();
        if let Some((log, log_path)) = log {
            if let Err(e) = log.commit() {
                incomplete.push(format!("{} was not written: {e}", log_path.display()));
            }
        }
        if let Some(d) = board_run.summary().diverged {
            eprintln!(
                "host-sim: error: {name} {}: stopped at t = {:.2} s: {} (what was recorded is kept in {})",
                cfg.name,
                d.t,
                d.reason,
                dir.path().display()
            );
        }
        let c = PilComparison::new(&board_run, &sil_run, stats, mode);
        let interrupted = sil_run.interrupted() || board_run.interrupted();
        // Real time does not repeat SIL (the board's clock, the link's latency): compared,
        // not required to agree.
        let must_agree = c.pil.pacing == Pacing::Lockstep && cfg.link_faults.is_empty();
        failed |= board_run.diverged() || (must_agree && !interrupted && !c.agrees());
        cases.push(c);
        runs.push(board_run);
    }
    progress.finish();
    let notes = pil_notes(&cases);
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
        print_json(
            stdout,
            &Cases {
                cases,
                incomplete,
                preflight: Vec::new(),
            },
        )?;
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
    Ok(exit)
}

/// The report's PIL-vs-SIL section (HIL's too), and the timing of real-time runs.
fn pil_notes(cases: &[PilComparison]) -> String {
    let mut notes = String::from(
        "## Board in the loop vs software in the loop\n\n\
         | case | link | pacing | board max path (m) | SIL max path (m) | board − SIL (m) | frames/s | \
         worst update (PIL: instructions; HIL: board timer ticks) | fail-safe events | re-arms | signed | board drops (old / auth) | \
         board refusals |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cases {
        notes += &format!(
            "| {} | {} | {} | {:.5} | {:.5} | {:+.2e} | {:.0} | {} | {} | {} | {} | {} / {} | {} |\n",
            c.run.name,
            c.pil.link,
            c.pil.pacing.as_str(),
            c.run.metrics.max_path,
            c.sil_max_path,
            c.pil_minus_sil_max_path,
            c.pil.frames_per_second,
            match c.mode {
                Mode::Pil => c.pil.worst_update_instructions,
                // The board's own unit: QEMU's SysTick counts, the STM32's CPU cycles.
                Mode::Hil => c.pil.worst_update_board_ticks,
            },
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
    let realtime: Vec<_> = cases
        .iter()
        .filter_map(|c| c.pil.realtime.as_ref().map(|r| (c, r)))
        .collect();
    if !realtime.is_empty() {
        notes += "\n### Real-time pacing (docs/design.md §21)\n\n";
        for (c, r) in realtime {
            notes += &format!("- {}: {r}\n", c.run.name);
        }
    }
    notes
}
