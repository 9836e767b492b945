//! `host-sim validate-preflight`: does the preflight's verdict hold? Missions checked, then
//! flown ([`crate::studies::validation`]).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, ValueEnum};

use super::common::check_run_count;
use super::json::print_json;
use super::Exit;
use crate::output::{atomic, OutputDir};
use crate::scenario::navigation::Preset;
use crate::sim::progress::{Progress, Unit};
use crate::studies::preflight::DEFAULT_MARGIN;
use crate::studies::validation::{self, Campaign, Measure, DEFAULT_RANDOM, TEAM_MOUNTINGS};

/// Which thruster mountings the matrix flies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mountings {
    /// The vertical × horizontal ones a team would build (8).
    Team,
    /// Every reversed-thruster mask of the AUV-150 layout (32).
    All,
}

/// `validate-preflight`: the six real paths under each mounting, and random missions, each
/// checked and flown; prints the false-feasible count and the conservativeness.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct ValidateArgs {
    #[arg(long, value_enum, default_value_t = Mountings::All)]
    pub mountings: Mountings,
    /// Random missions besides the matrix (at most host_sim::studies::montecarlo::MAX_RUNS
    /// without --allow-long-run).
    #[arg(long, default_value_t = DEFAULT_RANDOM)]
    pub random: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The navigation presets every mission is flown under (comma-separated).
    #[arg(long, value_delimiter = ',', value_parser = parse_preset, default_values = ["ideal", "survey"])]
    pub navigation: Vec<Preset>,
    /// Random missions also draw a thruster lag (0.05–0.3 s) and, on half, a Gauss–Markov
    /// current.
    #[arg(long)]
    pub disturbed: bool,
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
    #[arg(long)]
    pub json: bool,
    #[arg(long, default_value = "runs/validate-preflight")]
    pub out: PathBuf,
    /// Allow more than host_sim::studies::montecarlo::MAX_RUNS random missions.
    #[arg(long)]
    pub allow_long_run: bool,
}

/// `validate-preflight`: exit 0 when no mission was falsely feasible, 1 otherwise.
pub fn validate_preflight(args: &ValidateArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if !(args.margin > 0.0 && args.margin <= 1.0) {
        bail!(
            "--margin must be a fraction of the envelope in (0, 1], got {}",
            args.margin
        );
    }
    check_run_count("--random", args.random, args.allow_long_run)?;
    let campaign = Campaign {
        masks: match args.mountings {
            Mountings::Team => TEAM_MOUNTINGS.to_vec(),
            Mountings::All => validation::all_mountings(),
        },
        random: args.random,
        seed: args.seed,
        navigation: args.navigation.clone(),
        disturbed: args.disturbed,
    };
    let missions = campaign.missions()?;
    let dir = OutputDir::prepare(&args.out)?;
    let progress = Progress::counting(
        "validate-preflight",
        missions.len() as u64,
        Unit::Missions,
        !args.json,
    );
    let counter = progress.observer();
    let v = validation::validate(&missions, args.margin, Measure::Conservativeness, || {
        counter.add(1)
    })
    .map_err(|e| anyhow!(e))?;
    progress.finish();
    let md = v.markdown();
    let report = dir.claim("report.md")?;
    atomic::write(&report, md.as_bytes())
        .with_context(|| format!("writing {}", report.display()))?;
    if args.json {
        print_json(stdout, &v)?;
    } else {
        writeln!(stdout, "{md}")?;
        writeln!(stdout, "report: {}", report.display())?;
    }
    Ok(if v.partial {
        Exit::Interrupted
    } else if v.false_feasible > 0 {
        Exit::RunFailed
    } else {
        Exit::Success
    })
}

/// `--navigation`'s values: a preset's name.
pub(super) fn parse_preset(name: &str) -> Result<Preset, String> {
    Preset::ALL
        .into_iter()
        .find(|p| p.name() == name)
        .ok_or_else(|| format!("{name:?} is not one of ideal, survey, low-cost"))
}
