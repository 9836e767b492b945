//! The preflight's path-error budget (docs/real-vehicle.md#the-path-error-budget, Choices
//! 420–424): checked against closed forms and against flights, each test a few seconds.

use controller_core::TrajectoryKind;
use host_sim::scenario::navigation::{NavigationModel, Preset};
use host_sim::scenario::Scenario;
use host_sim::sim::{self, LocalController, Recording};
use host_sim::studies::preflight::path_budget::{self, PathBudget};

mod common;

use common::real_mission as real;

fn budget(s: &Scenario) -> PathBudget {
    path_budget::budget(s)
        .unwrap()
        .expect("a real-chain scenario has a bound")
}

/// The thrusters' lag τ_L adds τ_L·(the reference's jerk) to the acceleration the law does not
/// explain; on a circle of radius R at ω the jerk on x is Rω³ at its largest, so the
/// mismatch with the lag is within the mismatch without it of τ_L·Rω³ (triangle inequality),
/// and grows by it when τ_L·Rω³ dominates.
#[test]
fn thruster_lag_term_on_a_circle_is_tau_r_omega_cubed() {
    let base = real("real-circular-10R");
    let TrajectoryKind::Circle(c) = base.config().trajectory else {
        panic!("a circle");
    };
    let (r, w) = (f64::from(c.radius), f64::from(c.omega));
    let without = budget(&base).mismatch[0];
    for lag in [0.1, 0.3] {
        let s = base.with(|c| c.thruster_lag = Some(lag)).unwrap();
        let with = budget(&s).mismatch[0];
        let jerk = lag * r * w.powi(3);
        // The sampled jerk (a difference over 0.05 s of path) is within (ω·0.05)²/6 of it.
        let tol = without + jerk * 0.01;
        assert!(
            (with - jerk).abs() <= tol,
            "lag {lag}: mismatch {with} vs τRω³ = {jerk} ± {tol}"
        );
    }
}

/// On the exact state the budget has no navigation term at all, and its lag alone fits:
/// the ideal preset's verdicts are the force check's.
#[test]
fn ideal_navigation_has_no_navigation_term() {
    let s = real("real-circular-10R")
        .with(|c| {
            c.navigation = None;
            c.controller.estimator.kind = controller_core::EstimatorKind::Off;
        })
        .unwrap();
    let b = budget(&s);
    assert_eq!(b.noise, [0.0; 3], "{b:?}");
    assert!(b.fits(), "{}", b.describe());
    assert!(b.total < 0.1 * b.bound, "{}", b.describe());
}

/// Without fixes the dead reckoning drifts: the navigation term of the same mission grows
/// with its duration, and with fixes restored it does not.
#[test]
fn without_fixes_the_navigation_term_grows_with_the_flight() {
    let base = real("real-lawn-mower-20x10");
    let at = |preset: Preset, duration: f64| {
        let s = base
            .with(|c| {
                c.navigation = NavigationModel::preset(preset, 7);
                c.duration = duration;
            })
            .unwrap();
        budget(&s).noise_sigma[0]
    };
    let (short, long) = (at(Preset::LowCost, 20.0), at(Preset::LowCost, 60.0));
    assert!(long > 1.5 * short, "low-cost drift: {short} → {long}");
    let (short, long) = (at(Preset::Survey, 20.0), at(Preset::Survey, 60.0));
    assert!(
        long < 1.1 * short,
        "survey is held by its fixes: {short} → {long}"
    );
}

/// Flown on the survey preset (the real chain's default) at the scale the budget fits, the
/// shipped missions stay inside their budget — and the budget is not loose beyond 3× the
/// error flown.
#[test]
fn flown_survey_missions_stay_inside_the_budget() {
    for name in ["real-circular-10R", "real-lawn-mower-20x10"] {
        let s = real(name);
        let b = budget(&s);
        let k = b.smallest_time_scale.expect("fits at some scale");
        let span = s.config().duration / f64::from(s.config().time_scale);
        let flown = s
            .with(|c| {
                c.time_scale = k as f32;
                c.duration = span * k;
            })
            .unwrap();
        let at = budget(&flown);
        let run = sim::fly(
            &flown,
            &mut LocalController::new(&flown),
            &mut (),
            Recording::MetricsOnly,
        );
        let measured = run.metrics.max_path;
        assert!(
            measured <= at.total,
            "{name} at k = {k}: flew {measured} m, budget {}",
            at.describe()
        );
        let ratio = at.total / measured;
        assert!(
            ratio < 3.0,
            "{name}: budget {} is {ratio}× the flight",
            at.total
        );
        eprintln!(
            "{name} at k = {k}: flew {measured:.4} m, budget {:.4} m ({ratio:.2}×)",
            at.total
        );
    }
}
