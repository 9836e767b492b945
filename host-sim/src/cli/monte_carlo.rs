//! `host-sim monte-carlo`: draws over the Table-3 box, in parallel.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use controller_core::readable::Readable;
use controller_core::Table1Case;

use super::common::{check_run_count, load};
use super::Exit;
use crate::output::{atomic, OutputDir};
use crate::plant::{CurrentModel, VariationProfile};
use crate::scenario::{paper, Scenario, MAX_CURRENT_SPEED};
use crate::sim::progress::Progress;
use crate::studies::montecarlo::{self, MonteCarloOptions};

/// `monte-carlo`: draws the Table-3 parameters uniformly in their box, runs in parallel,
/// reports percentiles and the worst case. Deterministic per seed.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct MonteCarloArgs {
    /// How many runs (at most host_sim::studies::montecarlo::MAX_RUNS without --allow-long-run).
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
    /// Allow more than host_sim::studies::montecarlo::MAX_RUNS runs, and runs beyond the step cap.
    #[arg(long)]
    pub allow_long_run: bool,
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
    check_run_count("--runs", args.runs, args.allow_long_run)?;
    if let Some(c) = args.current {
        if !(c.is_finite() && (0.0..=MAX_CURRENT_SPEED).contains(&c)) {
            bail!(
                "--current must be a finite speed in [0, {MAX_CURRENT_SPEED}] m/s (a current the \
                 vehicle could meet: host_sim::scenario::MAX_CURRENT_SPEED), got {}",
                Readable(c)
            );
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
        // Monte Carlo reports its runs' spread, not a verdict per run (campaigns have bounds).
        false,
    ))
}
