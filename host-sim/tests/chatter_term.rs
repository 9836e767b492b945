//! The preflight's chatter term (docs/real-vehicle.md#the-chatter-term, Choices 500–504):
//! its prediction against flights (the closed forms it rests on are its unit tests).

use controller_core::effectiveness::THRUSTER_NAMES;
use controller_core::EstimatorKind;
use host_sim::scenario::{Scenario, SensorNoise};
use host_sim::sim::{self, LocalController, Recording, RunResult};
use host_sim::studies::preflight::chatter::{self, ChatterPrediction};

mod common;

use common::real_mission as real;

fn predicted(s: &Scenario) -> ChatterPrediction {
    chatter::chatter(s)
        .unwrap()
        .expect("a real-chain scenario has a bound")
}

fn fly(s: &Scenario) -> RunResult {
    sim::fly(
        s,
        &mut LocalController::new(s),
        &mut (),
        Recording::MetricsOnly,
    )
}

/// On its default survey navigation (the estimator on), the real 10 m circle as shipped: every
/// thruster reverses no more often than the term predicts, and the predicted command total
/// variation is the flown one within a factor 2 either way (the term's expectation, not a
/// bound: it binds only on noise the estimator does not filter).
#[test]
fn a_survey_flight_reverses_no_more_than_predicted() {
    let s = real("real-circular-10R");
    let p = predicted(&s);
    let run = fly(&s);
    for (j, name) in THRUSTER_NAMES.iter().enumerate() {
        let flown = run.metrics.chatter.0[j];
        let pred = &p.thrusters[j];
        eprintln!(
            "{name}: flown {:.2} /s, {:.1} V/s; predicted {:.2} /s (expected {:.2}), {:.1} V/s",
            flown.reversals_per_s,
            flown.command_tv,
            pred.reversals_per_s,
            pred.expected_reversals_per_s,
            pred.command_tv
        );
        assert!(
            flown.reversals_per_s <= pred.reversals_per_s,
            "{name}: flown {} reversals/s > predicted {}",
            flown.reversals_per_s,
            pred.reversals_per_s
        );
        let ratio = pred.command_tv / flown.command_tv.max(1e-9);
        assert!(
            flown.command_tv < 1.0 || (0.5..2.0).contains(&ratio),
            "{name}: TV flown {} V/s, predicted {}",
            flown.command_tv,
            pred.command_tv
        );
    }
}

/// The shipped campaign's white `[noise]` (5 mm, 1 mrad; 2 mm/s, 0.5 mrad/s) flown as told
/// (no estimator) reverses the thrusters tens of times a second (docs/real-vehicle.md#chatter):
/// the term predicts at least what flies, beyond the bound, at every time scale, and names
/// the navigation the mission would need.
#[test]
fn white_noise_flown_as_told_is_refused_at_every_scale() {
    let s = real("real-circular-10R")
        .with(|c| {
            c.navigation = None;
            c.controller.estimator.kind = EstimatorKind::Off;
            c.noise = Some(SensorNoise {
                eta_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
                nu_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
                seed: 1,
            });
        })
        .unwrap();
    let p = predicted(&s);
    let run = fly(&s);
    let (worst, _) = p.worst_reversals();
    assert!(!p.fits(), "{}", p.describe());
    assert!(p.smallest_time_scale.is_none(), "{}", p.describe());
    assert!(p.needs.is_some(), "{}", p.describe());
    assert!(
        run.metrics.reversals_per_s <= worst,
        "flown {} reversals/s > predicted {worst}",
        run.metrics.reversals_per_s
    );
    assert!(run.metrics.reversals_per_s > p.max_reversals_per_s);
}
