//! Study-grade flight (Choice 400, docs/campaigns.md#study-grade-flight): one RK4 step per
//! control period agrees with the 1 ms RK4 within [`STUDY_PATH_TOLERANCE`] on the preflight
//! contract's missions and on the shipped real-circle campaign, with the same outcomes; and the
//! Gauss–Markov current (Choice 401) has its closed-form statistics at every step length.

use std::mem::discriminant;
use std::path::Path;

use host_sim::plant::{CurrentModel, OceanCurrent};
use host_sim::scenario::Scenario;
use host_sim::sim::{self, bound, LocalController, Recording, RunResult};
use host_sim::studies::campaign::{Campaign, PlantStep, STUDY_PATH_TOLERANCE};
use host_sim::studies::validation;

/// Saturated fraction (of the control periods) a study-grade run may differ by.
const SATURATED_TOLERANCE: f64 = 0.002;

fn fly(s: &Scenario) -> RunResult {
    sim::fly(
        s,
        &mut LocalController::new(s),
        &mut (),
        Recording::MetricsOnly,
    )
}

fn path_tolerance(reference: f64) -> f64 {
    STUDY_PATH_TOLERANCE.0 + STUDY_PATH_TOLERANCE.1 * reference
}

#[test]
fn study_grade_flight_agrees_with_the_1ms_rk4_on_the_contracts_missions() {
    // On the exact state: the plant step is what differs (the shipped real-circle campaign's
    // test below flies the real chain's default navigation).
    let campaign = validation::Campaign {
        navigation: vec![host_sim::scenario::navigation::Preset::Ideal],
        ..validation::Campaign::default()
    };
    let missions = campaign.missions().unwrap();
    assert_eq!(missions.len(), 392);
    let (mut near_bound, mut worst_near) = (0, 0.0f64);
    let mut failures = Vec::new();
    for i in 0..missions.len() {
        // No lag, and the vehicle's fastest and slowest thruster lags (0.05 s, 0.3 s).
        let lag = [None, Some(0.05), Some(0.3)][i % 3];
        let reference = missions
            .get(i)
            .unwrap()
            .with(|c| c.thruster_lag = lag)
            .unwrap();
        let study = reference
            .with(|c| PlantStep::ControlPeriod.apply(c))
            .unwrap();
        assert_eq!(study.substeps(), 1);
        let (a, b) = (fly(&reference), fly(&study));
        let name = &reference.config().name;
        let d = (a.metrics.max_path - b.metrics.max_path).abs();
        let ds = (a.metrics.saturated_fraction - b.metrics.saturated_fraction).abs();
        if d > path_tolerance(a.metrics.max_path) || ds > SATURATED_TOLERANCE {
            failures.push(format!(
                "{name} (lag {lag:?}): max path {} at 1 ms, {} at the period; saturated {} and {}",
                a.metrics.max_path,
                b.metrics.max_path,
                a.metrics.saturated_fraction,
                b.metrics.saturated_fraction
            ));
        }
        assert_eq!(discriminant(&a.outcome), discriminant(&b.outcome), "{name}");
        assert_eq!(bound::within_bound(&a), bound::within_bound(&b), "{name}");
        if a.metrics.max_path < 0.5 {
            near_bound += 1;
            worst_near = worst_near.max(d);
        }
    }
    println!("{near_bound} missions within 0.5 m: largest difference {worst_near:.2e} m");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The missions a verdict can turn on (within 10× the 0.05 m bound) are there, and agree far
    // inside the absolute tolerance.
    assert!(near_bound >= 20, "{near_bound} missions near the bound");
    assert!(worst_near <= STUDY_PATH_TOLERANCE.0, "{worst_near}");
}

fn shipped_campaign() -> Campaign {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("campaigns/real-circle.campaign.toml");
    Campaign::load(&file).unwrap()
}

#[test]
fn the_shipped_real_circle_campaign_flies_study_grade_and_agrees_with_the_1ms_rk4() {
    let study = shipped_campaign();
    assert_eq!(study.spec.plant_step, Some(PlantStep::ControlPeriod));
    let mut spec = study.spec.clone();
    spec.plant_step = None;
    let reference = Campaign::new(study.text.clone(), spec, study.bases.clone());
    assert_ne!(
        study.hash, reference.hash,
        "the step is part of the campaign's hash"
    );
    let max_path = host_sim::studies::campaign::METRIC_NAMES
        .iter()
        .position(|m| *m == "max_path")
        .unwrap();
    for i in 0..40 {
        let s = study.scenario(i, &study.draw(i)).unwrap();
        assert_eq!(s.substeps(), 1);
        let (a, b) = (reference.fly(i).unwrap(), study.fly(i).unwrap());
        assert_eq!(a.draw, b.draw);
        let (pa, pb) = (a.metrics[max_path], b.metrics[max_path]);
        assert!(
            (pa - pb).abs() <= path_tolerance(pa),
            "run {i}: {pa} vs {pb}"
        );
        assert_eq!(a.outcome, b.outcome, "run {i}");
    }
}

#[test]
fn a_campaign_without_the_key_keeps_each_bases_plant_step() {
    let study = shipped_campaign();
    let mut spec = study.spec.clone();
    spec.plant_step = None;
    let reference = Campaign::new(study.text.clone(), spec, study.bases.clone());
    let s = reference.scenario(0, &reference.draw(0)).unwrap();
    assert_eq!(s.config().plant_step, 0.001);
    // The canonical spec of a campaign without the key has no `plant_step`: the hashes of
    // campaigns written before it are unchanged.
    assert!(!serde_json::to_string(&reference.spec)
        .unwrap()
        .contains("plant_step"));
}

/// Sample variance and autocorrelation at `lags` (in steps) of axis `axis` of a Gauss–Markov
/// current of mean 0 stepped `n` times by `h`.
fn statistics(sigma: [f64; 3], tau: f64, h: f64, n: usize, lags: &[usize]) -> Vec<(f64, Vec<f64>)> {
    let mut c = OceanCurrent::new(&CurrentModel::GaussMarkov {
        mean: [0.0; 3],
        sigma,
        tau,
        seed: 11,
    });
    let mut xs = (0..3).map(|_| Vec::with_capacity(n)).collect::<Vec<_>>();
    for _ in 0..n {
        c.step(h);
        for (a, x) in xs.iter_mut().enumerate() {
            x.push(c.velocity()[a]);
        }
    }
    xs.iter()
        .map(|x| {
            let var = x.iter().map(|v| v * v).sum::<f64>() / n as f64;
            let rho = lags
                .iter()
                .map(|&l| {
                    let cov =
                        x.iter().zip(&x[l..]).map(|(a, b)| a * b).sum::<f64>() / (n - l) as f64;
                    cov / var
                })
                .collect();
            (var, rho)
        })
        .collect()
}

#[test]
fn the_gauss_markov_current_has_variance_sigma_squared_and_autocorrelation_exp_at_any_step() {
    let sigma = [0.1, 0.2, 0.05];
    // τ = 2 steps: the shortest correlation time a study-grade run accepts is one step, and
    // Euler–Maruyama gave σ²/(1 − h/2τ) = 4/3 σ² and ρ(h) = 1 − h/τ = 0.5 here (Choice 401).
    for (h, tau) in [(0.01, 0.02), (0.001, 0.02)] {
        let lags = [1, 2, 5];
        // 4·10⁴ correlation times: the variance estimate's relative spread is √(2/4·10⁴) ≈ 0.7 %.
        let n = (4e4 * tau / h) as usize;
        for (axis, (var, rho)) in statistics(sigma, tau, h, n, &lags).into_iter().enumerate() {
            let s2 = sigma[axis] * sigma[axis];
            assert!(
                (var / s2 - 1.0).abs() < 0.03,
                "h {h}, τ {tau}, axis {axis}: variance {var} against σ² = {s2}"
            );
            for (l, r) in lags.iter().zip(rho) {
                let expected = (-(*l as f64) * h / tau).exp();
                assert!(
                    (r - expected).abs() < 0.02,
                    "h {h}, τ {tau}, axis {axis}, lag {l}: ρ {r} against e^(−Δt/τ) = {expected}"
                );
            }
        }
    }
}
