//! The comparison of docs/law.md#the-state-estimator: the real AUV-150 on circular-10R with the
//! shipped campaign's white `[noise]` (5 mm, 1 mrad; 2 mm/s, 0.5 mrad/s), flown with nothing,
//! μ = 0.3 alone, the estimator alone, and both; per run the max path error, the saturated
//! share, the peak voltage, and per thruster the voltage's sign reversals per second through a
//! ±0.5 V band and its total variation per second.
//!
//! `cargo run --profile host -p host-sim --example estimator_comparison [-- SCENARIO [ACCEL_SIGMA …]]`
//! (extra arguments: the linear axes' σₐ values to sweep, the angular ones a fifth of it;
//! `NOISE=0` flies the exact state instead, `SEED=n` another noise seed, `LAG=s` a first-order
//! thruster lag, `CURRENT=σ` a Gauss–Markov current of σ m/s horizontally, τ 60 s).

use std::path::Path;

use controller_core::effectiveness::THRUSTERS;
use controller_core::EstimatorKind;
use host_sim::plant::CurrentModel;
use host_sim::scenario::{load_config, Scenario, SensorNoise, SimConfig};
use host_sim::sim::{fly, LocalController, Recording};

#[path = "../tests/common/chatter.rs"]
mod chatter;

use chatter::Chatter;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .cloned()
        .unwrap_or_else(|| "host-sim/scenarios/real/circular-10R.toml".into());
    let sweep: Vec<f32> = args[1.min(args.len())..]
        .iter()
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let base = base_config(Path::new(&path))?;
    let mut cases: Vec<(String, f32, Option<f32>)> = vec![
        ("nothing".into(), base.controller.mu, None),
        ("mu = 0.3".into(), 0.3, None),
    ];
    let default_sa = base.controller.estimator.accel_sigma[0];
    let sas = if sweep.is_empty() {
        vec![default_sa]
    } else {
        sweep
    };
    for sa in sas {
        cases.push((format!("estimator (σa {sa})"), base.controller.mu, Some(sa)));
        cases.push((format!("both (σa {sa})"), 0.3, Some(sa)));
    }
    println!("| case | max path (mm) | saturated (%) | peak V | reversals/s vf/va/hf/ha (main) | TV V/s vf/va/hf/ha (main) | outcome |");
    println!("|---|---|---|---|---|---|---|");
    for (name, mu, sa) in cases {
        let mut cfg = base.clone();
        cfg.controller.mu = mu;
        if let Some(sa) = sa {
            cfg.controller.estimator.kind = EstimatorKind::Kalman;
            cfg.controller.estimator.accel_sigma = [sa, sa, sa, sa / 5.0, sa / 5.0, sa / 5.0];
        }
        println!("| {name} | {} |", row(cfg)?);
    }
    Ok(())
}

/// The scenario at `path` with the campaign's noise and what the environment asks for.
fn base_config(path: &Path) -> anyhow::Result<SimConfig> {
    let mut base = load_config(path)?;
    let env = |name: &str| std::env::var(name).ok();
    // NOISE=0: the exact state (what the estimator costs on a perfect solution).
    let noisy = env("NOISE").is_none_or(|v| v != "0");
    base.noise = noisy.then_some(SensorNoise {
        eta_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
        nu_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
        seed: env("SEED").map_or(Ok(1), |s| s.parse())?,
    });
    // LAG=s: first-order thruster lag; CURRENT=σ: a Gauss–Markov current (m/s, τ 60 s).
    if let Some(lag) = env("LAG") {
        base.thruster_lag = Some(lag.parse()?);
    }
    if let Some(sigma) = env("CURRENT") {
        let sigma: f64 = sigma.parse()?;
        base.current = CurrentModel::GaussMarkov {
            mean: [0.0; 3],
            sigma: [sigma, sigma, sigma / 4.0],
            tau: 60.0,
            seed: 7,
        };
    }
    Ok(base)
}

/// One run's cells after the case's name.
fn row(cfg: SimConfig) -> anyhow::Result<String> {
    let scenario = Scenario::new(cfg)?;
    let mut chatter = Chatter::default();
    let r = fly(
        &scenario,
        &mut LocalController::new(&scenario),
        &mut chatter,
        Recording::MetricsOnly,
    );
    let per_s = |x: &[f64; THRUSTERS]| -> String {
        let o = [1, 2, 3, 4, 0];
        o.iter()
            .map(|&i| format!("{:.1}", x[i]))
            .collect::<Vec<_>>()
            .join(" / ")
    };
    Ok(format!(
        "{:.1} | {:.1} | {:.1} | {} | {} | {:?}",
        r.metrics.max_path * 1e3,
        r.metrics.saturated_fraction * 100.0,
        r.metrics.peak_voltage,
        per_s(&chatter.reversals_per_s()),
        per_s(&chatter.variation_per_s()),
        r.outcome
    ))
}
