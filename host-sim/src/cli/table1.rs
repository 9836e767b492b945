//! `host-sim table1` (and `host-sim` without a command): the paper's Table 1, then the real
//! vehicle.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use clap::Args;
use controller_core::DEFAULT_V_LIMIT;

use super::common::{
    interrupted_before_runs, periods, preflights, report_incomplete, runs_exit, sil_into,
    Incomplete,
};
use super::json::{print_json, Cases};
use super::Exit;
use crate::output::waypoint_plot::mission_plots;
use crate::output::{self, sections, OutputDir, RealRow, ReportRow};
use crate::scenario::real_vehicle;
use crate::scenario::Scenario;
use crate::sim::progress::{Progress, Unit};
use crate::sim::record::RunSummary;
use crate::sim::RunResult;
use crate::studies::contract_statistics::{self, PresetStatistics};
use crate::studies::preflight::{Preflight, DEFAULT_MARGIN};
use crate::studies::table1 as paper_table1;
use crate::studies::tune;
use crate::studies::validation::{self, Campaign, Measure, Validation, TEAM_MOUNTINGS};

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
    /// The preflight's validation campaign the report gives its two numbers from: the real
    /// paths under every mounting and 200 random missions (`full`, docs/real-vehicle.md#the-preflights-contract), the
    /// eight mountings a team would build and no random missions (`team`), or none.
    #[arg(long, value_enum, default_value_t = ContractRun::Full)]
    pub contract: ContractRun,
    /// The main job's small fixed-seed gain-tuning study (docs/tune.md#in-the-main-job,
    /// [`MAIN_JOB_TUNE`](crate::studies::tune::MAIN_JOB_TUNE)): its Pareto front and chosen point
    /// in the report (`tune-*` files), or none.
    #[arg(long, value_enum, default_value_t = TuneRun::Main)]
    pub tune: TuneRun,
}

/// Whether `table1` runs the main job's tuning study.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TuneRun {
    Main,
    None,
}

/// How much of the preflight's validation campaign `table1` flies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ContractRun {
    Full,
    Team,
    None,
}

impl ContractRun {
    fn campaign(self) -> Option<Campaign> {
        match self {
            ContractRun::Full => Some(Campaign::default()),
            ContractRun::Team => Some(Campaign {
                masks: TEAM_MOUNTINGS.to_vec(),
                random: 0,
                ..Campaign::default()
            }),
            ContractRun::None => None,
        }
    }
}

impl Default for Table1Args {
    /// What `host-sim` without a command runs.
    fn default() -> Self {
        Table1Args {
            json: false,
            out: PathBuf::from(DEFAULT_TABLE1_OUT),
            contract: ContractRun::Full,
            tune: TuneRun::Main,
        }
    }
}

/// `table1`: the paper's Table 1 (ideal actuators), then the real vehicle: the missions of
/// `scenarios/real/` (the paper's paths, then the waypoint surveys) and the paper's six through
/// the real chain, with their preflight verdicts.
pub fn table1(args: &Table1Args, stdout: &mut dyn Write) -> Result<Exit> {
    let jobs = paper_table1::jobs()?;
    let mut real_jobs = real_vehicle::real_scenarios()?;
    let chain_jobs = real_vehicle::paper_real_chain_scenarios(&real_jobs)?;
    // The waypoint surveys fly in the same table, after the paper's paths (no chain twin).
    real_jobs.extend(real_vehicle::waypoint_scenarios()?);
    let dir = OutputDir::prepare(&args.out)?;
    // The paper's missions' verdicts (the Table-1 cases, with Δu: the same mission as the
    // real-chain runs), then the real ones.
    let title = "AUV-150 Table 1 reproduction (software in the loop)";
    let Some(checks) = preflights(chain_jobs.iter().chain(&real_jobs))? else {
        return interrupted_before_runs(&dir, title, args.json, stdout);
    };
    let all: Vec<&Scenario> = jobs.iter().chain(&real_jobs).chain(&chain_jobs).collect();
    let incomplete = Incomplete::default();
    let results = fly_all(&all, &dir, &incomplete, args.json);
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
    let (contract, statistics) = contract_and_statistics(args, &dir)?;
    let mut sections = real_sections(
        &real_rows,
        &checks,
        real_runs.iter().chain(chain_runs),
        contract.as_ref().map(|(_, v)| v),
    ) + statistics.as_ref().map_or("", |(_, md)| md.as_str());
    sections += &main_job_tune(args, &dir)?;
    let mut incomplete = incomplete.into_inner();
    let report = write_report(
        &dir,
        title,
        &rows,
        &sections,
        (&real_jobs, real_runs),
        &mut incomplete,
    )?;
    report_incomplete(&incomplete);
    // The paper's missions through the real chain are expected to fail: they show what an
    // infeasible verdict means, and do not make the command fail.
    let broken = contract.as_ref().is_some_and(|(_, v)| v.false_feasible > 0)
        || statistics
            .as_ref()
            .is_some_and(|(st, _)| st.iter().any(PresetStatistics::broken));
    let exit = runs_exit(
        paper_runs.iter().chain(real_runs),
        !incomplete.is_empty(),
        broken,
    );
    if args.json {
        let cases: Cases<RunSummary> = Cases {
            cases: results.iter().map(RunResult::summary).collect(),
            incomplete,
            preflight: checks,
            contract: contract.map(|(c, v)| v.summary(&c)),
            contract_statistics: statistics.map(|(st, _)| st).unwrap_or_default(),
        };
        print_json(stdout, &cases)?;
    } else {
        print_text(
            stdout,
            &rows,
            &checks,
            &real_rows,
            contract.as_ref().map(|(_, v)| v),
            statistics.as_ref().map_or(&[][..], |(st, _)| &st[..]),
            &report,
        )?;
    }
    Ok(exit)
}

/// The contract `args` asks for (none with `--contract none`) and its statistics per preset.
#[allow(clippy::type_complexity)]
fn contract_and_statistics(
    args: &Table1Args,
    dir: &OutputDir,
) -> Result<(
    Option<(Campaign, Validation)>,
    Option<(Vec<PresetStatistics>, String)>,
)> {
    let contract = match args.contract.campaign() {
        Some(campaign) => Some(contract(&campaign, args.json)?),
        None => None,
    };
    let statistics = match &contract {
        Some((campaign, v)) => Some(statistics(campaign, v, dir, args.json)?),
        None => None,
    };
    Ok((contract, statistics))
}

/// The plots of every run (the paper's rows, then the real missions without a companion), the
/// waypoint missions' path over the waypoints and speed over time after their own
/// (docs/simulator.md#plots-of-a-waypoint-mission, Choice 173), and `report.md`; returns its path.
fn write_report(
    dir: &OutputDir,
    title: &str,
    rows: &[ReportRow],
    sections: &str,
    (real_jobs, real_runs): (&[Scenario], &[RunResult]),
    incomplete: &mut Vec<String>,
) -> Result<PathBuf> {
    let real_plots: Vec<ReportRow> = real_runs.iter().map(|r| ReportRow::new(r, None)).collect();
    let mut extra = Vec::new();
    for (scenario, run) in real_jobs.iter().zip(real_runs) {
        let files = mission_plots(dir, scenario, run, incomplete)?;
        extra.extend(files.into_iter().map(|f| (run.name.clone(), f)));
    }
    output::write_plots_and_report_with(
        dir,
        title,
        rows,
        sections,
        &real_plots,
        &extra,
        &paper_table1::notes(),
        f64::from(DEFAULT_V_LIMIT),
        incomplete,
    )
}

/// The report's sections after the paper's table: the real vehicle's table, the preflight
/// verdicts (and any that did not hold) and the contract's campaign.
fn real_sections<'a>(
    real_rows: &[RealRow],
    checks: &[Preflight],
    real_runs: impl IntoIterator<Item = &'a RunResult>,
    contract: Option<&Validation>,
) -> String {
    format!(
        "{}\n{}\n{}\n\n{}\n{}",
        sections::REAL_NOTES,
        output::real_table_markdown(real_rows),
        output::report::real_table_legend(),
        sections::preflight(checks, real_runs),
        contract.map_or(String::new(), Validation::markdown),
    )
}

/// Every run of `all` in parallel, each CSV streamed into `dir`, with the progress (a bar
/// unless `json`).
fn fly_all(
    all: &[&Scenario],
    dir: &OutputDir,
    incomplete: &Incomplete,
    json: bool,
) -> Vec<RunResult> {
    use rayon::prelude::*;
    let progress = Progress::start("Table 1", periods(all.iter().copied()), !json);
    let results = all
        .par_iter()
        .map(|s| sil_into(dir, s, None, &progress, incomplete))
        .collect();
    progress.finish();
    results
}

/// The preflight's validation campaign `campaign`, with its progress (a bar unless `json`).
fn contract(campaign: &Campaign, json: bool) -> Result<(Campaign, Validation)> {
    let missions = campaign.missions()?;
    let progress = Progress::counting(
        "preflight contract",
        missions.len() as u64,
        Unit::Missions,
        !json,
    );
    let counter = progress.observer();
    let v = validation::validate(&missions, DEFAULT_MARGIN, Measure::Conservativeness, || {
        counter.add(1)
    })
    .map_err(|e| anyhow!(e))?;
    progress.finish();
    Ok((campaign.clone(), v))
}

/// The contract's statistics per preset of `campaign` (docs/search.md#the-contract-in-the-main-jobs-report,
/// Choices 471–472): the sampled figures from its flights `v`, the adversarial ones from a
/// small fixed-seed search per preset, each falsifying mission written into `dir`; the
/// figures and the report's section.
fn statistics(
    campaign: &Campaign,
    v: &Validation,
    dir: &OutputDir,
    json: bool,
) -> Result<(Vec<PresetStatistics>, String)> {
    let presets = &campaign.navigation;
    let progress = Progress::counting(
        "preflight contract, searched",
        (presets.len() * contract_statistics::SEARCH_BUDGET) as u64,
        Unit::Evaluations,
        !json,
    );
    let counter = progress.observer();
    let start = std::time::Instant::now();
    let mut stats = Vec::new();
    let mut written = Vec::new();
    for &preset in presets {
        let restart =
            contract_statistics::search(preset, &|| counter.add(1)).map_err(|e| anyhow!(e))?;
        let files = super::falsify::write_falsifying(
            &contract_statistics::search_spec(preset),
            std::slice::from_ref(&restart),
            dir,
        )?;
        written.extend(files.into_iter().map(|w| w.file));
        stats.push(PresetStatistics::of(preset, v, Some(&restart)));
    }
    progress.finish();
    let md = contract_statistics::markdown(&stats, start.elapsed().as_secs_f64(), &written);
    Ok((stats, md))
}

/// The main job's tuning study (Choice 447), its files as `tune-*`; its report section (none
/// with `--tune none`).
fn main_job_tune(args: &Table1Args, dir: &OutputDir) -> Result<String> {
    if args.tune != TuneRun::Main {
        return Ok(String::new());
    }
    let json = args.json;
    let spec = tune::MAIN_JOB_TUNE;
    let progress = Progress::counting(
        "gain tuning",
        spec.restarts * spec.evaluations_per_restart() as u64,
        Unit::Evaluations,
        !json,
    );
    let counter = progress.observer();
    let shard = tune::run_shard(&spec, 0, 1, &|| counter.add(1)).map_err(|e| anyhow!(e))?;
    progress.finish();
    let study = tune::merge(&[shard])?;
    super::tune::write_study(&study, dir, "tune-", "\n##")
}

/// The text `table1` prints: the paper's table, the real vehicle's verdicts and table, the
/// preflight contract's two numbers, the report's path.
fn print_text(
    stdout: &mut dyn Write,
    rows: &[ReportRow],
    checks: &[Preflight],
    real_rows: &[RealRow],
    contract: Option<&Validation>,
    statistics: &[PresetStatistics],
    report: &Path,
) -> Result<()> {
    writeln!(stdout, "{}", output::table_text(rows))?;
    writeln!(
        stdout,
        "The real vehicle: the missions of scenarios/real/ and the paper's through the real chain (kgf, ±24 V)"
    )?;
    for c in checks {
        writeln!(stdout, "{c}")?;
    }
    writeln!(stdout)?;
    write!(stdout, "{}", output::real_table_text(real_rows))?;
    writeln!(stdout, "{}\n", output::report::real_table_legend())?;
    if let Some(v) = contract {
        writeln!(stdout, "{}\n", v.headline())?;
    }
    for p in statistics {
        writeln!(
            stdout,
            "contract on {}: {}",
            p.navigation.name(),
            p.counts.sentence()
        )?;
    }
    writeln!(stdout, "report: {}", report.display())?;
    Ok(())
}
