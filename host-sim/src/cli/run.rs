//! `host-sim run`: one scenario file, and its companion without Δu.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::common::{
    interrupted_before_runs, load, periods, preflights, print_runs, sil_into, Incomplete,
};
use super::Exit;
use crate::interrupt;
use crate::output::waypoint_plot::mission_plots;
use crate::output::{self, figures, sections, OutputDir, ReportRow};
use crate::sim::progress::Progress;
use crate::sim::RunResult;

/// `run`: one scenario from a TOML file (and its companion without Δu, for comparison). The
/// exit code follows the run of the controller the scenario configures; the companion is
/// reported beside it, not as the verdict (Choice 313).
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
    let title = format!("AUV-150 scenario {}", cfg.name);
    let Some(checks) = preflights(std::iter::once(&scenario))? else {
        return interrupted_before_runs(&dir, &title, args.json, stdout);
    };
    let progress = Progress::start(
        &cfg.name,
        periods(std::iter::once(&scenario).chain(&companion)),
        !args.json,
    );
    let incomplete = Incomplete::default();
    // The scenario file as written, attached to the flight logs (docs/logs.md#metadata).
    let text = std::fs::read_to_string(&args.scenario).ok();
    let with = sil_into(&dir, &scenario, text.as_deref(), &progress, &incomplete);
    // A run interrupted is not followed by its companion (nothing would be done of it).
    let without = companion
        .as_ref()
        .filter(|_| !interrupt::requested())
        .map(|c| sil_into(&dir, c, text.as_deref(), &progress, &incomplete));
    progress.finish();
    let rows = [ReportRow::new(&with, without.as_ref())];
    let mut incomplete = incomplete.into_inner();
    // A waypoint mission's path over its waypoints and speed over time (docs/simulator.md#plots-of-a-waypoint-mission).
    let mut extra: Vec<(String, PathBuf)> = mission_plots(&dir, &scenario, &with, &mut incomplete)?
        .into_iter()
        .map(|f| (with.name.clone(), f))
        .collect();
    extra.extend(commands_plot(&dir, &with, &mut incomplete)?);
    let runs: Vec<&RunResult> = std::iter::once(&with).chain(&without).collect();
    let sections = format!(
        "{}\n{}",
        output::chatter_section(&runs),
        sections::preflight(&checks, runs.iter().copied())
    );
    let report = output::write_plots_and_report_with(
        &dir,
        &title,
        &rows,
        &sections,
        &[],
        &extra,
        "",
        f64::from(cfg.controller.voltage_limit),
        &mut incomplete,
    )?;
    if let Some([lat, lon, alt]) = cfg.origin {
        // The flown path on a map (docs/missions.md#plans-from-qgroundcontrol): the run with Δu, its plotted samples.
        let origin = crate::scenario::plan::Origin { lat, lon, alt };
        let path: Vec<[f64; 3]> = with
            .samples
            .iter()
            .map(|s| [s.eta[0], s.eta[1], s.eta[2]])
            .collect();
        let file = dir.claim(&format!("{}-flown.geojson", cfg.name))?;
        std::fs::write(
            &file,
            crate::scenario::plan::geojson_line(&origin, &cfg.name, &path),
        )
        .with_context(|| format!("cannot write {}", file.display()))?;
    }
    print_runs(stdout, args.json, &rows, &checks, &report, incomplete)
}

/// The run's commands zoomed in, where a person sees the chatter (docs/real-vehicle.md#chatter):
/// the file for the report's list of the run's plots, or nothing and why in `incomplete`.
fn commands_plot(
    dir: &OutputDir,
    with: &RunResult,
    incomplete: &mut Vec<String>,
) -> Result<Option<(String, PathBuf)>> {
    dir.claim(&figures::commands_plot_name(&with.name))?;
    Ok(match figures::plot_commands(dir.path(), with) {
        Ok(file) => Some((with.name.clone(), file)),
        Err(e) => {
            incomplete.push(format!("commands plot of {}: {e:#}", with.name));
            None
        }
    })
}
