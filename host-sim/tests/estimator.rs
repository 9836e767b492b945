//! The board's state estimator in the simulator (docs/law.md#the-state-estimator): a scenario
//! turns it on in `[controller]`, its settings are checked under their keys, and on the real
//! vehicle told a noisy solution it stops the thrusters' chatter that the law given the solution
//! as told has, within the path bound.

mod common;

use std::path::Path;

use controller_core::EstimatorKind;
use host_sim::scenario::{load_config, Scenario, SensorNoise, SimConfig};
use host_sim::sim::{fly, LocalController, Outcome, Recording};

use common::chatter::Chatter;
use common::{circle_with, invalid_key};

#[test]
fn the_estimator_is_turned_on_in_the_controller_table_and_its_settings_named_when_wrong() {
    let on = host_sim::scenario::parse_scenario(&circle_with(
        "[controller]\nestimator = \"kalman\"\nestimator_accel_sigma = [0.1, 0.1, 0.1, 0.02, 0.02, 0.02]\n",
    ))
    .unwrap();
    let e = on.config().controller.estimator;
    assert_eq!(e.kind, EstimatorKind::Kalman);
    assert_eq!(e.accel_sigma[3], 0.02);
    for (key, value) in [
        (
            "estimator_position_sigma",
            "[0.005, 0.005, 0.005, 0.001, 0, 0.001]",
        ),
        (
            "estimator_velocity_sigma",
            "[0.002, 0.002, 0.002, 0.0005, -1, 0.0005]",
        ),
        (
            "estimator_accel_sigma",
            "[0.02, 0.02, 0.02, 0.004, nan, 0.004]",
        ),
    ] {
        let text = format!("[controller]\nestimator = \"kalman\"\n{key} = {value}\n");
        let (got, message) = invalid_key(&circle_with(&text));
        assert_eq!(got, format!("controller.{key}[4]"), "{message}");
    }
}

/// The real circle with the shipped campaign's white `[noise]`.
fn noisy_real_circle() -> SimConfig {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut c = load_config(&root.join("scenarios/real/circular-10R.toml")).unwrap();
    // The exact state with white noise, told as is: the real chain's default (survey, the
    // estimator on: docs/navigation.md#the-default) pinned off.
    c.navigation = None;
    c.controller.estimator = controller_core::EstimatorConfig::default();
    c.noise = Some(SensorNoise {
        eta_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
        nu_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
        seed: 1,
    });
    c
}

/// Max path error (m), saturated share, and the worst thruster's reversals per second and
/// voltage total variation per second.
fn fly_chatter(config: SimConfig) -> (f64, f64, f64, f64) {
    let scenario = Scenario::new(config).unwrap();
    let mut chatter = Chatter::default();
    let r = fly(
        &scenario,
        &mut LocalController::new(&scenario),
        &mut chatter,
        Recording::MetricsOnly,
    );
    // The chatter bound in `[bound]` may call the run missed (the law told the raw solution
    // is); what this comparison needs is a flight that ran to its end.
    assert!(
        matches!(r.outcome, Outcome::Completed | Outcome::Missed { .. }),
        "{:?}",
        r.outcome
    );
    let worst = |x: [f64; 5]| x.into_iter().fold(0.0, f64::max);
    (
        r.metrics.max_path,
        r.metrics.saturated_fraction,
        worst(chatter.reversals_per_s()),
        worst(chatter.variation_per_s()),
    )
}

/// Issue 28's bound: within 5 cm, ≤ 1 % saturated, ≤ 2 reversals per second per thruster
/// through ±0.5 V and ≤ 100 V/s of total variation. The law told the solution as is breaks
/// the chatter limits by an order of magnitude; on the estimate it keeps all four.
#[test]
fn on_a_noisy_solution_the_estimator_keeps_the_real_circle_within_the_chatter_bound() {
    let (_, _, reversals, variation) = fly_chatter(noisy_real_circle());
    assert!(
        reversals > 20.0 && variation > 500.0,
        "{reversals} /s, {variation} V/s"
    );

    let mut c = noisy_real_circle();
    c.controller.estimator.kind = EstimatorKind::Kalman;
    let (path, saturated, reversals, variation) = fly_chatter(c);
    assert!(path < 0.05, "max path {path} m");
    assert!(saturated <= 0.01, "saturated {saturated}");
    assert!(reversals <= 2.0, "{reversals} reversals/s");
    assert!(variation <= 100.0, "{variation} V/s");
}
