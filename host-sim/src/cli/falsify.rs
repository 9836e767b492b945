//! `host-sim falsify`: search for a mission the preflight calls feasible that flies outside its
//! bound ([`crate::studies::falsify`], docs/search.md).
//!
//! ```text
//! host-sim falsify [--budget B] [--restarts R] [--seed S] [--margin M] [--duration D]
//!                  [--reach contract|realities] [--navigation PRESET] [--refused graded|flat]
//!                  [--shard I/N] [--json]
//!                  --out DIR
//! host-sim falsify --merge DIR… --out DIR
//! ```
//!
//! A shard (default the whole search, or the engine's index as `campaign run` takes it) runs
//! restarts r ≡ I (mod N) of both methods and writes `shard.json`; every run, and the merge of
//! shard folders, writes `report.md`, `robustness.png` and each falsifying mission as a
//! scenario file. Exit 1 when a false feasible was found, 0 when none, 130 interrupted.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;

use super::campaign::RestartShards;
use super::json::print_json;
use super::Exit;
use crate::output::falsify::{plot_robustness, report_markdown, Written};
use crate::output::{atomic, OutputDir};
use crate::scenario::file::ScenarioFile;
use crate::scenario::navigation::Preset;
use crate::sim::progress::{Progress, Unit};
use crate::studies::falsify::{self, Refused, Restart, ShardResult, Spec};
use crate::studies::mission_space::Reach;
use crate::studies::preflight::DEFAULT_MARGIN;

/// `falsify`: cross-entropy search and random search at the same budget for a false feasible.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct FalsifyArgs {
    /// Evaluations (each a preflight check and a flight) per restart of each method.
    #[arg(long, default_value_t = 200)]
    pub budget: usize,
    /// Restarts of each method (the shards' unit).
    #[arg(long, default_value_t = 4)]
    pub restarts: u64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The preflight's margin (a fraction of the envelope in (0, 1]; 1.0 weakens it).
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
    /// Each candidate's duration at time scale 1 (s).
    #[arg(long, default_value_t = crate::studies::validation::CONTRACT_DURATION)]
    pub duration: f64,
    /// Which mission space: the contract's draws, or those and the realities a team writes.
    #[arg(long, value_enum, default_value_t = Reach::Realities)]
    pub reach: Reach,
    /// Every candidate told its state through this navigation preset (ideal, survey,
    /// low-cost); default: the contract's exact state, or a drawn preset for the realities.
    #[arg(long, value_parser = super::validate::parse_preset)]
    pub navigation: Option<Preset>,
    /// What a candidate the preflight refuses scores for the search: graded (how far its check
    /// is from feasible, above every flown robustness) or flat (+∞, the search learns nothing
    /// from it).
    #[arg(long, value_enum, default_value_t = Refused::Graded)]
    pub refused: Refused,
    #[command(flatten)]
    pub shards: RestartShards,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/falsify")]
    pub out: PathBuf,
}

/// `falsify`: a shard's search (or the merge of shards), its report and files.
pub fn falsify(args: &FalsifyArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let dir = OutputDir::prepare(&args.out)?;
    let (spec, restarts, missing, seconds) = if args.shards.merge.is_empty() {
        let shard = search(args)?;
        let text = serde_json::to_string_pretty(&shard)?;
        let path = dir.claim("shard.json")?;
        atomic::write(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        let missing: Vec<String> = shard
            .restarts
            .iter()
            .filter(|r| r.partial)
            .map(|r| format!("{} restart {} (interrupted)", r.method.name(), r.index))
            .collect();
        let (spec, seconds) = (shard.spec, shard.seconds);
        let mut restarts = shard.restarts;
        restarts.sort_by_key(|r| (r.method == falsify::Method::Random, r.index));
        (spec, restarts, missing, seconds)
    } else {
        let shards = args.shards.read_merged::<ShardResult>("falsify")?;
        let (spec, restarts, missing) = falsify::merge(&shards)?;
        let seconds = shards.iter().map(|s| s.seconds).sum();
        (spec, restarts, missing, seconds)
    };
    let written = write_falsifying(&spec, &restarts, &dir)?;
    let plot = dir.claim("robustness.png")?;
    let mut md = report_markdown(&spec, &restarts, &missing, &written, seconds);
    if let Err(e) = plot_robustness(&plot, &restarts) {
        md += &format!("\n(the plot could not be written: {e})\n");
    }
    let report = dir.claim("report.md")?;
    atomic::write(&report, md.as_bytes())
        .with_context(|| format!("writing {}", report.display()))?;
    let found = restarts.iter().any(|r| r.first_falsified.is_some());
    if args.json {
        print_json(stdout, &restarts)?;
    } else {
        writeln!(stdout, "{md}")?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(if restarts.iter().any(|r| r.partial) {
        Exit::Interrupted
    } else if found {
        Exit::RunFailed
    } else {
        Exit::Success
    })
}

/// Runs this shard's restarts, with progress.
fn search(args: &FalsifyArgs) -> Result<ShardResult> {
    if !(args.margin > 0.0 && args.margin <= 1.0) {
        bail!(
            "--margin must be a fraction of the envelope in (0, 1], got {}",
            args.margin
        );
    }
    if !(args.duration > 0.0 && args.duration.is_finite()) || args.budget == 0 {
        bail!("--duration must be > 0 s and --budget ≥ 1");
    }
    let (i, n) = args.shards.resolve()?;
    let spec = Spec {
        reach: args.reach,
        margin: args.margin,
        duration: args.duration,
        seed: args.seed,
        budget: args.budget,
        restarts: args.restarts,
        navigation: args.navigation,
        refused: args.refused,
    };
    let mine = crate::studies::campaign::Shard {
        runs: args.restarts,
        index: i,
        count: n,
    }
    .len();
    let progress = Progress::counting(
        "falsify",
        mine * 2 * args.budget as u64,
        Unit::Evaluations,
        !args.json,
    );
    let counter = progress.observer();
    let shard = falsify::run_shard(&spec, i, n, &|| counter.add(1)).map_err(|e| anyhow!(e))?;
    progress.finish();
    Ok(shard)
}

/// Each restart's worst candidate that is a false feasible, as a scenario file at its
/// proposed scale (the one writer, [`ScenarioFile`]).
pub(super) fn write_falsifying(
    spec: &Spec,
    restarts: &[Restart],
    dir: &OutputDir,
) -> Result<Vec<Written>> {
    let setup = spec.setup()?;
    let mut out = Vec::new();
    for (k, r) in restarts.iter().enumerate() {
        let Some(w) = r.worst.as_ref().filter(|w| w.falsified) else {
            continue;
        };
        let name = format!(
            "falsified-{}-r{}{}",
            r.method.name(),
            r.index,
            spec.navigation
                .map_or(String::new(), |p| format!("-{}", p.name()))
        );
        let Some(s) = falsify::flown_mission(&setup, &w.x, &name).map_err(|e| anyhow!(e))? else {
            continue;
        };
        let file = ScenarioFile::try_from(s.config())?;
        let header = format!(
            "# Found by `host-sim falsify` ({} restart {}, seed {}, margin {}): the preflight \
             proposed time scale {} and the flight\n# missed its bound (robustness {:.4}). \
             `host-sim run --scenario` on this file flies it bit for bit.\n",
            r.method.name(),
            r.index,
            spec.seed,
            spec.margin,
            w.proposed.unwrap_or(f64::NAN),
            w.robustness().unwrap_or(f64::NAN),
        );
        let text = header + &file.to_toml()?;
        let fname = format!("{name}.toml");
        let path = dir.claim(&fname)?;
        atomic::write(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        out.push(Written {
            file: path.display().to_string(),
            restart: k,
        });
    }
    Ok(out)
}
