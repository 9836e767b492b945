//! `host-sim tune`: a multi-objective study of the controller's gains over a fixed sample of
//! missions ([`crate::studies::tune`], docs/tune.md).
//!
//! ```text
//! host-sim tune [--missions M] [--duration D] [--population P] [--generations G]
//!               [--restarts R] [--seed S] [--margin M] [--shard I/N] [--json] --out DIR
//! host-sim tune --merge DIR… --out DIR
//! ```
//!
//! A shard (default the whole study, or the engine's index as `campaign run` takes it) runs
//! restarts r ≡ I (mod N) and writes `shard.json`; every run, and the merge of shard folders,
//! writes `report.md`, `front.csv`, `study.json`, `front.png` and `chosen.toml`. Exit 0, 130
//! interrupted (what was done is written, marked partial).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;

use super::campaign::RestartShards;
use super::json::print_json;
use super::Exit;
use crate::output::tune::{controller_block, front_csv, plot_front, report_markdown};
use crate::output::{atomic, OutputDir};
use crate::scenario::real_vehicle;
use crate::sim::progress::{Progress, Unit};
use crate::studies::preflight::DEFAULT_MARGIN;
use crate::studies::tune::{self, ShardResult, Spec, Study};

/// `tune`: NSGA-II over the gains, scored on a fixed sample of missions.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct TuneArgs {
    /// Random missions of the sample (each flown under ideal and survey navigation).
    #[arg(long, default_value_t = 8)]
    pub missions: usize,
    /// Each mission's duration at time scale 1 (s).
    #[arg(long, default_value_t = 30.0)]
    pub duration: f64,
    #[arg(long, default_value_t = 16)]
    pub population: usize,
    #[arg(long, default_value_t = 8)]
    pub generations: usize,
    /// NSGA-II restarts (the shards' unit).
    #[arg(long, default_value_t = 2)]
    pub restarts: u64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The preflight's margin (a fraction of the envelope in (0, 1]).
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
    #[command(flatten)]
    pub shards: RestartShards,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/tune")]
    pub out: PathBuf,
}

impl TuneArgs {
    /// The study these flags ask for.
    pub fn spec(&self) -> Result<Spec> {
        if !(self.margin > 0.0 && self.margin <= 1.0) {
            bail!(
                "--margin must be a fraction of the envelope in (0, 1], got {}",
                self.margin
            );
        }
        if !(self.duration > 0.0 && self.duration.is_finite()) {
            bail!("--duration must be a number of seconds > 0");
        }
        if self.missions == 0 || self.population < 2 || self.restarts == 0 {
            bail!("--missions and --restarts must be ≥ 1, --population ≥ 2");
        }
        Ok(Spec {
            seed: self.seed,
            missions: self.missions,
            duration: self.duration,
            margin: self.margin,
            population: self.population,
            generations: self.generations,
            restarts: self.restarts,
        })
    }
}

/// `tune`: a shard's study (or the merge of shards), its report and files.
pub fn tune(args: &TuneArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let dir = OutputDir::prepare(&args.out)?;
    let shards = if args.shards.merge.is_empty() {
        let shard = search(args)?;
        let text = serde_json::to_string_pretty(&shard)?;
        let path = dir.claim("shard.json")?;
        atomic::write(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        vec![shard]
    } else {
        args.shards.read_merged::<ShardResult>("tune")?
    };
    let interrupted = shards.iter().any(|s| s.restarts.iter().any(|r| r.partial));
    let study = tune::merge(&shards)?;
    let md = write_study(&study, &dir, "", "#")?;
    let report = dir.claim("report.md")?;
    atomic::write(&report, md.as_bytes())
        .with_context(|| format!("writing {}", report.display()))?;
    if args.json {
        print_json(stdout, &study)?;
    } else {
        writeln!(stdout, "{md}")?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(if interrupted {
        Exit::Interrupted
    } else {
        Exit::Success
    })
}

/// Writes a study's files into `dir`, each name prefixed by `prefix` (`chosen.toml`,
/// `front.csv`, `study.json`, `front.png`); returns the report's text (its title at
/// `heading` level), which links the plot.
pub fn write_study(study: &Study, dir: &OutputDir, prefix: &str, heading: &str) -> Result<String> {
    let write = |name: &str, bytes: &[u8]| -> Result<()> {
        let path = dir.claim(&format!("{prefix}{name}"))?;
        atomic::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
        Ok(())
    };
    let base = real_vehicle::real_scenarios()?.swap_remove(0);
    let block = match study.chosen {
        Some(i) => {
            let b = controller_block(&study.front[i], &base.config().controller)?;
            let scores = &study.front[i].scores;
            let head = format!(
                "# Chosen by `host-sim tune` (seed {}): p95 max path {:.4} m, reversals {:.2}/s, \
                 command TV {:.1} V/s, saturated {:.4}, time scale {:.3}\n",
                study.spec.seed,
                scores.p95[0],
                scores.p95[1],
                scores.p95[2],
                scores.p95[3],
                scores.p95[4]
            );
            write("chosen.toml", (head + &b).as_bytes())?;
            Some(b)
        }
        None => None,
    };
    write("front.csv", front_csv(study)?.as_bytes())?;
    write(
        "study.json",
        serde_json::to_string_pretty(study)?.as_bytes(),
    )?;
    let mut md = report_markdown(study, block.as_deref(), heading);
    md += &format!("\n![the Pareto front's projections]({prefix}front.png)\n");
    if let Err(e) = plot_front(&dir.claim(&format!("{prefix}front.png"))?, study) {
        md += &format!("\n(the plot could not be written: {e})\n");
    }
    Ok(md)
}

/// Runs this shard's restarts, with progress.
fn search(args: &TuneArgs) -> Result<ShardResult> {
    let spec = args.spec()?;
    let (i, n) = args.shards.resolve()?;
    let mine = crate::studies::campaign::Shard {
        runs: args.restarts,
        index: i,
        count: n,
    }
    .len();
    let progress = Progress::counting(
        "tune",
        mine * spec.evaluations_per_restart() as u64,
        Unit::Evaluations,
        !args.json,
    );
    let counter = progress.observer();
    let shard = tune::run_shard(&spec, i, n, &|| counter.add(1)).map_err(|e| anyhow!(e))?;
    progress.finish();
    Ok(shard)
}
