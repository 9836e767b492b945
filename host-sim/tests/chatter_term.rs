//! The preflight's chatter term (docs/real-vehicle.md#the-chatter-term, Choices 500–504):
//! its prediction against flights (the closed forms it rests on are its unit tests).

use controller_core::effectiveness::THRUSTER_NAMES;
use controller_core::EstimatorKind;
use host_sim::scenario::navigation::Preset;
use host_sim::scenario::{Scenario, SensorNoise};
use host_sim::sim::{self, LocalController, Recording, RunResult};
use host_sim::studies::preflight::chatter::{self, Chatter, ChatterPrediction};
use host_sim::studies::validation::Campaign;

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

/// The shipped circle on the shipped campaign's white `[noise]` (5 mm, 1 mrad; 2 mm/s,
/// 0.5 mrad/s) on the exact state, flown as told (no estimator).
fn white_noise_circle() -> Scenario {
    real("real-circular-10R")
        .with(|c| {
            c.navigation = None;
            c.controller.estimator.kind = EstimatorKind::Off;
            c.noise = Some(SensorNoise {
                eta_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
                nu_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
                seed: 1,
            });
        })
        .unwrap()
}

/// The shipped campaign's white `[noise]` (5 mm, 1 mrad; 2 mm/s, 0.5 mrad/s) flown as told
/// (no estimator) reverses the thrusters tens of times a second (docs/real-vehicle.md#chatter):
/// the term predicts at least what flies, beyond the bound, at every time scale, and names
/// the navigation the mission would need.
#[test]
fn white_noise_flown_as_told_is_refused_at_every_scale() {
    let s = white_noise_circle();
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

/// The contract's `random` disturbed random missions (seed 1) on `survey`, cut to `duration` s.
fn disturbed_on_survey(random: usize, duration: f64) -> Vec<Scenario> {
    let campaign = Campaign {
        masks: Vec::new(),
        random,
        seed: 1,
        navigation: vec![Preset::Survey],
        disturbed: true,
    };
    let all = campaign.missions().unwrap();
    (0..all.len())
        .map(|i| all.get(i).unwrap().with(|c| c.duration = duration).unwrap())
        .collect()
}

/// The search's decision (Choice 516) stops a pass over the flight once a partial sum is past
/// the bound; it answers what the full prediction answers, at every scale and noise fraction
/// asked: on the shipped circle (at its own scale 1.31, where it fits), the white noise flown as told (refused at
/// every scale), and the tuning sample's disturbed missions on `survey` (a Gauss–Markov
/// current on half: several current corners, the first past the bound stops the decision).
/// And the prediction a finished decision keeps is the fresh one, bit for bit.
#[test]
fn the_stopping_decision_answers_what_the_full_prediction_answers() {
    let white = white_noise_circle();
    let mut missions = vec![real("real-circular-10R"), white];
    missions.extend(disturbed_on_survey(4, 20.0));
    let (mut stopped, mut kept) = (0, 0);
    for s in &missions {
        let name = &s.config().name;
        let deciding = Chatter::new(s).unwrap().unwrap();
        for (k, noise) in [
            (1.0, 1.0),
            (1.25, 1.0),
            (1.7, 1.0),
            (3.1, 1.0),
            (8.0, 1.0),
            (1.0, 0.5),
            (1.0, 0.1),
            (1.0, 0.0),
        ] {
            let full = Chatter::new(s).unwrap().unwrap().at(k, noise).unwrap();
            let fits = deciding.fits_with(k, noise).unwrap();
            assert_eq!(fits, full.fits(), "{name} at {k}, noise {noise}");
            // A decision that fits flew the whole flight and kept it.
            let again = deciding.at(k, noise).unwrap();
            assert_eq!(again, full, "{name} at {k}, noise {noise}");
            match fits {
                true => kept += 1,
                false => stopped += 1,
            }
        }
    }
    // Both answers were given.
    assert!(stopped > 5 && kept > 5, "{stopped} refused, {kept} fit");
}

/// The refusal's score takes the chatter term at the slowest scale with the mean thrust held
/// still between the reference's samples (Choice 560): within 3 % of the full pass at that
/// scale (the mean moves by one sample's step over 500 periods there), on the white noise flown
/// as told (refused at every scale) and two of the tuning sample's disturbed missions on
/// `survey` (several current corners).
#[test]
fn the_held_slowest_pass_is_within_a_few_per_cent_of_the_full_one() {
    let mut missions = vec![white_noise_circle().with(|c| c.duration = 10.0).unwrap()];
    missions.extend(disturbed_on_survey(2, 5.0));
    let k = f64::from(controller_core::Trajectory::MAX_TIME_SCALE);
    for s in &missions {
        let name = &s.config().name;
        let model = Chatter::new(s).unwrap().unwrap();
        let held = model.slowest_held().unwrap();
        let full = model.at(k, 1.0).unwrap();
        assert_eq!(held.time_scale, full.time_scale);
        let close = |a: f64, b: f64| (a - b).abs() <= 0.03 * b.abs().max(1e-9);
        for (h, f) in held.thrusters.iter().zip(&full.thrusters) {
            for (what, held, full) in [
                ("reversals", h.reversals_per_s, f.reversals_per_s),
                ("TV", h.command_tv, f.command_tv),
            ] {
                assert!(
                    close(held, full),
                    "{name} {}: {what} held {held} full {full}",
                    f.thruster
                );
            }
        }
    }
}
