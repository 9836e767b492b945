//! Monte Carlo over the Table-3 box: each run draws Δp uniformly in [0, max] (held constant
//! over the run) and, if asked, a constant horizontal current of random direction and speed.
//! Deterministic per seed: run i uses a generator seeded from (seed, i), whatever the thread
//! scheduling.

use controller_core::model::ParamVariation;
use controller_core::uncertainty::{ParamBox, VARIED_PARAMETERS};
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::Serialize;

use crate::config::{CurrentModel, VariationProfile};
use crate::record::Metrics;
use crate::scenario::{Scenario, ScenarioError};
use crate::sil;

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
    pub runs: usize,
    pub seed: u64,
    pub diverged: usize,
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

/// Nearest-rank percentile of sorted values.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p / 100.0) * sorted.len() as f64).ceil().max(1.0) as usize;
    sorted[rank.min(sorted.len()) - 1]
}

/// Runs `opts.runs` draws around `base` in parallel (the controller is `base`'s, built once).
pub fn run(
    base: &Scenario,
    opts: &MonteCarloOptions,
    on_done: impl Fn() + Sync,
) -> Result<Summary, ScenarioError> {
    let name = &base.config().name;
    let results: Result<Vec<(Draw, Metrics, bool)>, ScenarioError> = (0..opts.runs)
        .into_par_iter()
        .map(|i| {
            let d = draw(opts, i);
            let scenario = base.with(|cfg| {
                cfg.name = format!("{name}-mc{i}");
                cfg.variation = VariationProfile::Constant(variation(&d));
                if opts.max_current.is_some() {
                    cfg.current = CurrentModel::Constant(d.current);
                }
            })?;
            let r = sil::run(&scenario);
            on_done();
            let diverged = r.diverged();
            Ok((d, r.metrics, diverged))
        })
        .collect();
    let results = results?;
    type Getter = (&'static str, fn(&Metrics) -> f64);
    let getters: [Getter; 10] = [
        ("max_x", |m| m.max_x),
        ("max_y", |m| m.max_y),
        ("max_z", |m| m.max_z),
        ("max_path", |m| m.max_path),
        ("rms_path", |m| m.rms_path),
        ("max_roll", |m| m.max_roll),
        ("max_pitch", |m| m.max_pitch),
        ("max_yaw", |m| m.max_yaw),
        ("peak_voltage", |m| m.peak_voltage),
        ("saturated_fraction", |m| m.saturated_fraction),
    ];
    let metrics = getters
        .iter()
        .map(|(name, get)| {
            let mut v: Vec<(f64, usize)> =
                results.iter().map(|(d, m, _)| (get(m), d.run)).collect();
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
        .collect();
    let worst = results
        .iter()
        .max_by(|a, b| a.1.max_path.total_cmp(&b.1.max_path))
        .map(|(d, m, _)| (d.clone(), *m));
    Ok(Summary {
        base: name.clone(),
        runs: opts.runs,
        seed: opts.seed,
        diverged: results.iter().filter(|r| r.2).count(),
        metrics,
        worst,
    })
}

impl Summary {
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "# Monte Carlo over the Table-3 box\n\nbase scenario `{}`, {} runs, seed {}, diverged: {}\n\n| metric | p50 | p90 | p99 | max | worst run |\n|---|---|---|---|---|---|\n",
            self.base, self.runs, self.seed, self.diverged
        );
        for m in &self.metrics {
            s += &format!(
                "| {} | {:.4} | {:.4} | {:.4} | {:.4} | {} |\n",
                m.name, m.p50, m.p90, m.p99, m.max, m.worst_run
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
