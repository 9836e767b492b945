//! `host-sim`: software-in-the-loop runs of the AUV-150 controller against the 6-DOF plant.
//!
//! ```text
//! host-sim                                   # = host-sim table1
//! host-sim table1 [--json] [--out DIR]
//! host-sim run --scenario FILE.toml [--json] [--out DIR]
//! host-sim monte-carlo --runs N --seed S [--scenario FILE] [--current V] [--json] [--out DIR]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use host_sim::config::{LinkFaults, TickRange};
use host_sim::montecarlo::{self, MonteCarloOptions};
use host_sim::output::{self, ReportRow};
use host_sim::pil::BoardInTheLoop;
use host_sim::record::{Outcome, RunResult};
use host_sim::{scenario, sil, table1};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser)]
#[command(
    name = "host-sim",
    version,
    about = "AUV-150 robust controller: software-in-the-loop simulator"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// The paper's six Table-1 missions with and without Δu, side by side with the paper.
    Table1 {
        /// Print one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
        /// Report folder (CSV, PNG, report.md).
        #[arg(long, default_value = "runs/table1")]
        out: PathBuf,
    },
    /// One scenario from a TOML file (and its companion without Δu, for comparison).
    Run {
        #[arg(long)]
        scenario: PathBuf,
        #[arg(long)]
        json: bool,
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Processor in the loop: the firmware ELF in QEMU flies the simulated vehicle over a
    /// loopback socket, lock-stepped; compared with SIL. Link faults by tick range (A..B).
    Pil {
        #[arg(long, conflicts_with = "table1")]
        scenario: Option<PathBuf>,
        /// The six Table-1 missions (with Δu).
        #[arg(long)]
        table1: bool,
        #[arg(long)]
        json: bool,
        #[arg(long, default_value = "runs/pil")]
        out: PathBuf,
        /// Firmware ELF: the QEMU flying image [default:
        /// target/thumbv7em-none-eabihf/release/firmware-qemu].
        #[arg(long)]
        elf: Option<PathBuf>,
        /// Override the scenario's duration (s).
        #[arg(long)]
        duration: Option<f64>,
        /// Drop the state frames of these ticks.
        #[arg(long, value_parser = TickRange::parse)]
        drop: Vec<TickRange>,
        /// Flip a byte in the state frames of these ticks.
        #[arg(long, value_parser = TickRange::parse)]
        corrupt: Vec<TickRange>,
        /// Send the state from `--delay-ticks` earlier during these ticks.
        #[arg(long, value_parser = TickRange::parse)]
        delay: Vec<TickRange>,
        #[arg(long, default_value_t = 5)]
        delay_ticks: u64,
        /// Send nothing at all during these ticks.
        #[arg(long, value_parser = TickRange::parse)]
        silent: Vec<TickRange>,
    },
    /// Draws the Table-3 parameters uniformly in their box, runs in parallel, reports
    /// percentiles and the worst case. Deterministic per seed.
    MonteCarlo {
        #[arg(long)]
        runs: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Base scenario (default: circular-10R).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Also draw a constant horizontal current of up to this speed (m/s).
        #[arg(long)]
        current: Option<f64>,
        #[arg(long)]
        json: bool,
        #[arg(long, default_value = "runs/monte-carlo")]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command.unwrap_or(Command::Table1 {
        json: false,
        out: PathBuf::from("runs/table1"),
    }) {
        Command::Table1 { json, out } => cmd_table1(json, &out),
        Command::Run {
            scenario,
            json,
            out,
        } => cmd_run(&scenario, json, out),
        Command::Pil {
            scenario,
            table1,
            json,
            out,
            elf,
            duration,
            drop,
            corrupt,
            delay,
            delay_ticks,
            silent,
        } => cmd_pil(
            scenario,
            table1,
            json,
            &out,
            elf,
            duration,
            LinkFaults {
                drop,
                corrupt,
                delay,
                delay_ticks,
                silent,
            },
        ),
        Command::MonteCarlo {
            runs,
            seed,
            scenario,
            current,
            json,
            out,
        } => cmd_monte_carlo(runs, seed, scenario, current, json, &out),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("host-sim: error: {e:#}");
            ExitCode::from(2)
        }
    }
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

/// Writes CSVs, plots and the report for pairs of (with Δu, without Δu) runs.
fn write_outputs(
    out: &Path,
    title: &str,
    pairs: &[(RunResult, Option<RunResult>)],
    notes: &str,
    voltage_limit: f64,
) -> Result<PathBuf> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut plots = Vec::new();
    for (with, without) in pairs {
        output::write_csv(&out.join(format!("{}-with.csv", with.name)), with)?;
        if let Some(w) = without {
            output::write_csv(&out.join(format!("{}-without.csv", w.name)), w)?;
        }
        plots.extend(output::plot_case_with_limit(
            out,
            with,
            without.as_ref(),
            voltage_limit,
        )?);
    }
    let rows: Vec<ReportRow> = pairs
        .iter()
        .map(|(with, without)| ReportRow {
            with,
            without: without.as_ref(),
            paper: output::paper_table1(&with.name),
        })
        .collect();
    output::write_report(out, title, &rows, &plots, notes)
}

fn json_cases(runs: &[&RunResult]) -> serde_json::Value {
    let cases: Vec<serde_json::Value> = runs
        .iter()
        .map(|r| {
            let m = &r.metrics;
            let mut v = serde_json::json!({
                "case": r.name,
                "robust": r.robust,
                "max_x": m.max_x, "max_y": m.max_y, "max_z": m.max_z,
                "max_path": m.max_path, "rms_path": m.rms_path,
                "max_roll": m.max_roll, "max_pitch": m.max_pitch, "max_yaw": m.max_yaw,
                "peak_voltage": m.peak_voltage, "saturated_fraction": m.saturated_fraction,
            });
            if let Outcome::Diverged { t, reason } = &r.outcome {
                v["diverged"] = serde_json::json!({ "t": t, "reason": reason });
            }
            v
        })
        .collect();
    serde_json::json!({ "cases": cases })
}

fn exit_for(runs: &[&RunResult]) -> ExitCode {
    if runs
        .iter()
        .any(|r| matches!(r.outcome, Outcome::Diverged { .. }))
    {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn cmd_table1(json: bool, out: &Path) -> Result<ExitCode> {
    let pb = progress(12, "Table 1", json);
    let pairs = table1::run_all(|| pb.inc(1))?;
    pb.finish_and_clear();
    let all: Vec<&RunResult> = pairs.iter().flat_map(|(a, b)| [a, b]).collect();
    let wrapped: Vec<(RunResult, Option<RunResult>)> = pairs
        .iter()
        .map(|(a, b)| (a.clone(), Some(b.clone())))
        .collect();
    let report = write_outputs(
        out,
        "AUV-150 Table 1 reproduction (software in the loop)",
        &wrapped,
        table1::NOTES,
        output::DEFAULT_VOLTAGE_LIMIT,
    )?;
    if json {
        println!("{}", json_cases(&all));
    } else {
        let rows: Vec<ReportRow> = pairs
            .iter()
            .map(|(with, without)| ReportRow {
                with,
                without: Some(without),
                paper: output::paper_table1(&with.name),
            })
            .collect();
        println!("{}", output::table_text(&rows));
        println!("report: {}", report.display());
    }
    Ok(exit_for(&all))
}

fn cmd_run(path: &Path, json: bool, out: Option<PathBuf>) -> Result<ExitCode> {
    let cfg =
        scenario::load_scenario(path).with_context(|| format!("scenario {}", path.display()))?;
    let out = out.unwrap_or_else(|| PathBuf::from("runs").join(&cfg.name));
    let mut companion = None;
    if cfg.controller.robust {
        let mut c = cfg.clone();
        c.controller.robust = false;
        companion = Some(c);
    }
    let pb = progress(1 + companion.is_some() as usize, &cfg.name, json);
    let main_run = sil::run(&cfg).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    pb.inc(1);
    let without = match companion {
        Some(c) => Some(sil::run(&c).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?),
        None => None,
    };
    pb.finish_and_clear();
    let pairs = vec![(main_run, without)];
    let report = write_outputs(
        &out,
        &format!("AUV-150 scenario {}", pairs[0].0.name),
        &pairs,
        "",
        cfg.controller.voltage_limit as f64,
    )?;
    let all: Vec<&RunResult> = pairs
        .iter()
        .flat_map(|(a, b)| std::iter::once(a).chain(b.as_ref()))
        .collect();
    if json {
        println!("{}", json_cases(&all));
    } else {
        let rows = [ReportRow {
            with: &pairs[0].0,
            without: pairs[0].1.as_ref(),
            paper: output::paper_table1(&pairs[0].0.name),
        }];
        println!("{}", output::table_text(&rows));
        println!("report: {}", report.display());
    }
    Ok(exit_for(&all))
}

fn cmd_monte_carlo(
    runs: usize,
    seed: u64,
    scenario_path: Option<PathBuf>,
    current: Option<f64>,
    json: bool,
    out: &Path,
) -> Result<ExitCode> {
    if runs == 0 {
        bail!("--runs must be at least 1");
    }
    if let Some(c) = current {
        if !(c.is_finite() && c >= 0.0) {
            bail!("--current must be a finite speed ≥ 0 m/s, got {c}");
        }
    }
    let base = match &scenario_path {
        Some(p) => {
            scenario::load_scenario(p).with_context(|| format!("scenario {}", p.display()))?
        }
        None => scenario::table1_scenario(controller_core::Table1Case::Circular10R, true),
    };
    let pb = progress(runs, "Monte Carlo", json);
    let summary = montecarlo::run(
        &base,
        &MonteCarloOptions {
            runs,
            seed,
            max_current: current,
        },
        || pb.inc(1),
    )?;
    pb.finish_and_clear();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let md = summary.markdown();
    let report = out.join("report.md");
    std::fs::write(&report, &md).with_context(|| format!("writing {}", report.display()))?;
    if json {
        println!(
            "{}",
            serde_json::to_string(&summary).context("serialising the summary")?
        );
    } else {
        println!("{md}");
        println!("report: {}", report.display());
    }
    Ok(if summary.diverged > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn cmd_pil(
    scenario_path: Option<PathBuf>,
    table1_cases: bool,
    json: bool,
    out: &Path,
    elf: Option<PathBuf>,
    duration: Option<f64>,
    faults: LinkFaults,
) -> Result<ExitCode> {
    let mut configs = Vec::new();
    match (&scenario_path, table1_cases) {
        (Some(p), false) => configs
            .push(scenario::load_scenario(p).with_context(|| format!("scenario {}", p.display()))?),
        (None, true) => {
            for case in controller_core::Table1Case::ALL {
                configs.push(scenario::table1_scenario(case, true));
            }
        }
        _ => bail!("give --scenario FILE or --table1"),
    }
    if let Some(d) = duration {
        if !(d.is_finite() && d > 0.0) {
            bail!("--duration must be > 0 s, got {d}");
        }
        for c in &mut configs {
            c.duration = d;
        }
    }
    // Flags add to the scenario's [link_faults].
    for c in &mut configs {
        let f = &mut c.link_faults;
        f.drop.extend(faults.drop.iter().copied());
        f.corrupt.extend(faults.corrupt.iter().copied());
        f.delay.extend(faults.delay.iter().copied());
        f.silent.extend(faults.silent.iter().copied());
        if !faults.delay.is_empty() {
            f.delay_ticks = faults.delay_ticks;
        }
    }
    let root = workspace_root();
    let elf = elf.unwrap_or_else(|| host_sim::pil::default_elf(&root));
    let runner = root.join("scripts/qemu-run.sh");
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let pb = progress(configs.len(), "PIL", json);
    let mut cases = Vec::new();
    let mut pairs = Vec::new();
    let mut failed = false;
    for cfg in &configs {
        let sil_run = sil::run(cfg).map_err(|e| anyhow::anyhow!("{}: {e}", cfg.name))?;
        let log = out.join(format!("{}-qemu.log", cfg.name));
        let mut board = BoardInTheLoop::start(&elf, &runner, cfg, cfg.link_faults.clone(), &log)
            .map_err(|e| anyhow::anyhow!("{}: {e}", cfg.name))?;
        let pil_run =
            sil::run_with(cfg, &mut board).map_err(|e| anyhow::anyhow!("{}: {e}", cfg.name))?;
        let stats = board.finish();
        pb.inc(1);
        let diff = pil_run.metrics.max_path - sil_run.metrics.max_path;
        if matches!(pil_run.outcome, Outcome::Diverged { .. })
            || (cfg.link_faults.is_empty() && diff.abs() > 1e-3)
        {
            failed = true;
        }
        let mut v = json_cases(&[&pil_run])["cases"][0].clone();
        v["mode"] = serde_json::json!("pil");
        v["sil_max_path"] = serde_json::json!(sil_run.metrics.max_path);
        v["pil_minus_sil_max_path"] = serde_json::json!(diff);
        v["pil"] = serde_json::to_value(&stats).context("serialising PIL stats")?;
        cases.push(v);
        pairs.push((pil_run, None));
    }
    pb.finish_and_clear();
    let mut notes = String::from("## Processor in the loop vs software in the loop\n\n| case | PIL max path (m) | SIL max path (m) | PIL − SIL (m) | frames/s | worst update (instructions) | fail-safe events | re-arms |\n|---|---|---|---|---|---|---|---|\n");
    for c in &cases {
        notes += &format!(
            "| {} | {:.5} | {:.5} | {:+.2e} | {:.0} | {} | {} | {} |\n",
            c["case"].as_str().unwrap_or("?"),
            c["max_path"].as_f64().unwrap_or(f64::NAN),
            c["sil_max_path"].as_f64().unwrap_or(f64::NAN),
            c["pil_minus_sil_max_path"].as_f64().unwrap_or(f64::NAN),
            c["pil"]["frames_per_second"].as_f64().unwrap_or(f64::NAN),
            c["pil"]["worst_update_instructions"],
            c["pil"]["failsafe_events"]
                .as_array()
                .map_or(0, |a| a.len()),
            c["pil"]["rearms"],
        );
    }
    let report = write_outputs(
        out,
        "AUV-150 processor in the loop (firmware in QEMU)",
        &pairs,
        &notes,
        output::DEFAULT_VOLTAGE_LIMIT,
    )?;
    if json {
        println!("{}", serde_json::json!({ "cases": cases }));
    } else {
        println!("{notes}");
        for c in &cases {
            for e in c["pil"]["failsafe_events"].as_array().into_iter().flatten() {
                println!(
                    "{}: fail-safe {} at t = {} s: {}",
                    c["case"].as_str().unwrap_or("?"),
                    e["kind"].as_str().unwrap_or("?"),
                    e["t"],
                    e["reason"].as_str().unwrap_or("?")
                );
            }
        }
        println!("report: {}", report.display());
    }
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}
