//! Monte Carlo over the Table-3 box: each run draws Δp uniformly in [0, max] (held constant
//! over the run) and, if asked, a constant horizontal current of random direction and speed.
//! Deterministic per seed: run i uses a generator seeded from (seed, i), whatever the thread
//! scheduling.
//!
//! **What the draw replaces.** Δp replaces the base scenario's variation, so the base must
//! have none (`host-sim monte-carlo` refuses a scenario with its own `[variation]`, and its
//! default base is the paper's 10 m circle without its abs-sin profile); the drawn current
//! replaces the base's current, so with `--current` the base must have none. Everything else
//! (mission, controller, noise, lag, actuators, duration) is the base's.
//!
//! **Size.** At most [`MAX_RUNS`] runs unless overridden; before it starts the command prints
//! an [`estimate`] of the time. On an interrupt the runs in flight stop, the runs not started
//! are not run, and the [`Summary`] covers the runs completed, marked `partial`.

use controller_core::model::ParamVariation;
use controller_core::uncertainty::{ParamBox, VARIED_PARAMETERS};
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::Serialize;

use crate::interrupt;
use crate::plant::{CurrentModel, VariationProfile};
use crate::scenario::{Scenario, ScenarioError};
use crate::sim::progress::duration_text;
use crate::sim::{self, LocalController, Metrics, Observer, Recording};

/// Most runs of one Monte Carlo, and most random missions of `validate-preflight` (Choice
/// 303), without the explicit override (`--allow-long-run`).
pub const MAX_RUNS: usize = 10_000;

/// Simulated time of the calibration run of [`estimate`] (s), or the base's duration if
/// shorter.
pub const CALIBRATION_SECONDS: f64 = 2.0;

#[derive(Clone, Copy, Debug)]
pub struct MonteCarloOptions {
    pub runs: usize,
    pub seed: u64,
    /// Largest horizontal current speed to draw (m/s); None: no current.
    pub max_current: Option<f64>,
}

/// One drawn case.
#[derive(Clone, Debug, Serialize)]
pub struct Draw {
    pub run: usize,
    pub variation: [f64; VARIED_PARAMETERS],
    pub current: [f64; 3],
}

/// Percentiles of one metric over the runs.
#[derive(Clone, Debug, Serialize)]
pub struct MetricSummary {
    pub name: &'static str,
    pub p50: f64,
    pub p90: f64,
    pub p99: f64,
    pub max: f64,
    /// The run with the maximum.
    pub worst_run: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub base: String,
    /// Runs asked for.
    pub runs: usize,
    /// Runs completed (or diverged): the statistics cover these.
    pub done: usize,
    /// Interrupted before every run was done: the statistics cover `done` runs only.
    pub partial: bool,
    pub seed: u64,
    pub diverged: usize,
    /// Runs in which the controller was in fail-safe in some period.
    pub faulted: usize,
    /// What each run draws, and what of the base it replaces.
    pub draw: String,
    pub metrics: Vec<MetricSummary>,
    /// The draw with the largest path error, and its metrics.
    pub worst: Option<(Draw, Metrics)>,
}

fn draw(opts: &MonteCarloOptions, run: usize) -> Draw {
    let mut rng = rand::rngs::StdRng::seed_from_u64(
        opts.seed ^ (run as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
    );
    let mut f = [0.0; VARIED_PARAMETERS];
    for x in f.iter_mut() {
        *x = rng.random::<f64>();
    }
    let current = match opts.max_current {
        Some(vmax) => {
            let speed = vmax * rng.random::<f64>();
            let dir = std::f64::consts::TAU * rng.random::<f64>();
            [speed * dir.cos(), speed * dir.sin(), 0.0]
        }
        None => [0.0; 3],
    };
    Draw {
        run,
        variation: f,
        current,
    }
}

fn variation(d: &Draw) -> ParamVariation<f64> {
    ParamBox::table3().lerp(&d.variation)
}

/// Nearest-rank percentile of sorted values (NaN for none): the value of rank ⌈p·n/100⌉.
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p / 100.0) * sorted.len() as f64).ceil().max(1.0) as usize;
    sorted[rank.min(sorted.len()) - 1]
}

/// The plant steps a run of `s` takes (its control periods × RK4 steps per period).
fn plant_steps(s: &Scenario) -> f64 {
    (s.steps() * s.substeps() as u64).max(1) as f64
}

/// One calibration run of a base: [`CALIBRATION_SECONDS`] of it (or less), flown as the runs
/// go (metrics only) and timed; its time per plant step scaled to the base's whole duration.
pub struct Calibration {
    /// Simulated seconds the calibration flew.
    pub duration: f64,
    /// Its wall time, s.
    pub wall: f64,
    /// The estimated wall time of one whole run of the base on one thread, s.
    pub seconds_per_run: f64,
}

impl Calibration {
    /// Flies and times the calibration run of `base`.
    pub fn of(base: &Scenario) -> Result<Calibration, ScenarioError> {
        let short = base.with(|c| c.duration = c.duration.min(CALIBRATION_SECONDS))?;
        let t0 = Instant::now();
        sim::fly(
            &short,
            &mut LocalController::new(&short),
            &mut (),
            Recording::MetricsOnly,
        );
        let wall = t0.elapsed().as_secs_f64();
        Ok(Calibration {
            duration: short.config().duration,
            wall,
            seconds_per_run: wall / plant_steps(&short) * plant_steps(base),
        })
    }
}

/// How long `opts.runs` runs around `base` should take, as a sentence: a calibration run of
/// the base ([`CALIBRATION_SECONDS`] of simulated time) is timed, its time per plant step
/// scaled to every plant step of every run and divided by the threads (rayon's).
pub fn estimate(base: &Scenario, opts: &MonteCarloOptions) -> Result<String, ScenarioError> {
    let calibration = Calibration::of(base)?;
    let (short, wall) = (calibration.duration, calibration.wall);
    let threads = rayon::current_num_threads().max(1);
    let total = calibration.seconds_per_run * opts.runs as f64 / threads as f64;
    Ok(format!(
        "{} runs of {} ({} s, {} plant steps each): about {} on {threads} thread(s) (a {} s \
         calibration run took {:.3} s; scaled by plant steps)",
        opts.runs,
        base.config().name,
        base.config().duration,
        plant_steps(base),
        duration_text(total),
        short,
        wall
    ))
}

/// Runs `opts.runs` draws around `base` in parallel (the controller is `base`'s, built once);
/// each run's samples go to an `observer()` (progress) and are not kept
/// ([`Recording::MetricsOnly`]: the summary needs the metrics and fault counts only).
pub fn run<O: Observer>(
    base: &Scenario,
    opts: &MonteCarloOptions,
    observer: impl Fn() -> O + Sync,
) -> Result<Summary, ScenarioError> {
    let name = &base.config().name;
    type Done = Option<(Draw, Metrics, bool, bool)>;
    let results: Result<Vec<Done>, ScenarioError> = (0..opts.runs)
        .into_par_iter()
        .map(|i| {
            if interrupt::requested() {
                return Ok(None);
            }
            let d = draw(opts, i);
            let scenario = base.with(|cfg| {
                cfg.name = format!("{name}-mc{i}");
                cfg.variation = VariationProfile::Constant(variation(&d));
                if opts.max_current.is_some() {
                    cfg.current = CurrentModel::Constant(d.current);
                }
            })?;
            let r = sim::fly(
                &scenario,
                &mut LocalController::new(&scenario),
                &mut observer(),
                Recording::MetricsOnly,
            );
            if r.interrupted() {
                return Ok(None);
            }
            Ok(Some((d, r.metrics, r.diverged(), !r.faults.is_empty())))
        })
        .collect();
    let results: Vec<(Draw, Metrics, bool, bool)> = results?.into_iter().flatten().collect();
    let metrics = summaries(&results);
    let worst = results
        .iter()
        .max_by(|a, b| a.1.max_path.total_cmp(&b.1.max_path))
        .map(|(d, m, ..)| (d.clone(), *m));
    let draw = draw_text(opts);
    Ok(Summary {
        base: name.clone(),
        runs: opts.runs,
        done: results.len(),
        partial: results.len() < opts.runs,
        seed: opts.seed,
        diverged: results.iter().filter(|r| r.2).count(),
        faulted: results.iter().filter(|r| r.3).count(),
        draw,
        metrics,
        worst,
    })
}

/// The percentiles of every metric over the runs, and the run with each maximum.
fn summaries(results: &[(Draw, Metrics, bool, bool)]) -> Vec<MetricSummary> {
    Metrics::NAMES
        .iter()
        .enumerate()
        .map(|(k, &name)| {
            let mut v: Vec<(f64, usize)> = results
                .iter()
                .map(|(d, m, ..)| (m.values()[k], d.run))
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let sorted: Vec<f64> = v.iter().map(|x| x.0).collect();
            MetricSummary {
                name,
                p50: percentile(&sorted, 50.0),
                p90: percentile(&sorted, 90.0),
                p99: percentile(&sorted, 99.0),
                max: sorted.last().copied().unwrap_or(f64::NAN),
                worst_run: v.last().map_or(0, |x| x.1),
            }
        })
        .collect()
}

/// What each run draws, and what of the base it replaces.
fn draw_text(opts: &MonteCarloOptions) -> String {
    match opts.max_current {
        Some(v) => format!(
            "Δp uniform in the Table-3 box, constant over each run (replaces the base's \
             variation, which is none); a constant horizontal current of speed uniform in \
             [0, {v}] m/s and uniform direction (replaces the base's current, which is none)"
        ),
        None => "Δp uniform in the Table-3 box, constant over each run (replaces the base's \
                 variation, which is none); the base's own current"
            .to_string(),
    }
}

impl Summary {
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "# Monte Carlo over the Table-3 box{}\n\nbase scenario `{}`, {} runs, seed {}, diverged: {}, controller in fail-safe: {}\n\nEach run: {}.\n\n",
            if self.partial { " (PARTIAL)" } else { "" },
            self.base, self.runs, self.seed, self.diverged, self.faulted, self.draw
        );
        if self.partial {
            s += &format!(
                "**Partial: interrupted after {} of {} runs**; the statistics below cover those \
                 {} runs only.\n\n",
                self.done, self.runs, self.done
            );
        }
        s += "| metric | p50 | p90 | p99 | max | worst run |\n|---|---|---|---|---|---|\n";
        // No run done: no statistic (NaN), shown as `—` (Choice 129).
        let cell = |v: f64| {
            if v.is_nan() {
                "—".to_string()
            } else {
                format!("{v:.4}")
            }
        };
        for m in &self.metrics {
            let worst = if self.done == 0 {
                "—".to_string()
            } else {
                m.worst_run.to_string()
            };
            s += &format!(
                "| {} | {} | {} | {} | {} | {worst} |\n",
                m.name,
                cell(m.p50),
                cell(m.p90),
                cell(m.p99),
                cell(m.max)
            );
        }
        if let Some((d, m)) = &self.worst {
            let v = variation(d);
            s += &format!(
                "\nWorst path error {:.4} m in run {}: Δm = {:.2} kg, Δr_G = ({:.4}, {:.4}, {:.4}) m, ΔI = ({:.2}, {:.2}, {:.2}), Δ(−X_u̇) = {:.2}, Δ(−Y_v̇) = {:.2}, current = ({:.3}, {:.3}, {:.3}) m/s\n",
                m.max_path, d.run, v.mass, v.r_g[0], v.r_g[1], v.r_g[2], v.inertia[0], v.inertia[1], v.inertia[2], v.x_udot, v.y_vdot, d.current[0], d.current[1], d.current[2]
            );
        }
        s
    }
}
