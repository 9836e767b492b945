//! Robustness of the trajectories: every output finite for any valid mission, tick and rate,
//! extreme ticks and parameters, a zero rate, the refusals naming their parameter, and the same
//! instant at different rates.

use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower, ParameterRange};
use controller_core::trajectory::{
    Desired, Table1Case, Trajectory, TrajectoryError, TrajectoryKind,
};
use proptest::prelude::*;

#[path = "common/trajectories.rs"]
mod trajectories;
use trajectories::*;

// ---------------------------------------------------------------------------------------------
// Robustness.
// ---------------------------------------------------------------------------------------------

fn assert_finite(d: &Desired) -> Result<(), TestCaseError> {
    for v in [d.eta, d.eta_dot, d.eta_ddot] {
        for (i, x) in v.iter().enumerate() {
            prop_assert!(x.is_finite(), "component {i} = {x}");
        }
    }
    let psi = d.eta[5];
    prop_assert!(
        psi > -std::f32::consts::PI && psi <= std::f32::consts::PI,
        "ψ {psi}"
    );
    Ok(())
}

/// A valid closed form of every kind of `TrajectoryKind::EXAMPLES`: each parameter anywhere in
/// its range (a positive one from 10⁻⁷ of its largest value up).
fn any_kind() -> impl Strategy<Value = TrajectoryKind> {
    let closed: Vec<TrajectoryKind> = TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .collect();
    let n = closed.len();
    (0..n, prop::collection::vec(0.0f32..=1.0, 8)).prop_map(move |(i, u)| {
        let mut kind = closed[i];
        let mut u = u.into_iter();
        kind.parameters(&mut |p, value| {
            let x = u.next().unwrap_or(0.5);
            *value = match p.range {
                ParameterRange::Positive(max) => max * (1e-7 + (1.0 - 1e-7) * x),
                ParameterRange::Symmetric(max) => max * (2.0 * x - 1.0),
            };
        });
        kind
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn every_output_is_finite(kind in any_kind(), ticks in any::<u64>(), rate_hz in any::<u32>()) {
        let traj = Trajectory::new(kind);
        prop_assert!(traj.is_ok(), "{kind:?} rejected: {traj:?}");
        let traj = traj.unwrap();
        assert_finite(&traj.sample(ticks, rate_hz))?;
        prop_assert!(traj.accel_bound().is_finite() && traj.accel_bound() > 0.0);
    }

    #[test]
    fn table1_outputs_are_finite(case in 0usize..6, ticks in any::<u64>(), rate_hz in any::<u32>()) {
        assert_finite(&Trajectory::table1(Table1Case::ALL[case]).sample(ticks, rate_hz))?;
    }
}

#[test]
fn extreme_ticks_and_parameters_stay_finite() {
    let m = Trajectory::MAX_SIZE;
    let kinds = [
        TrajectoryKind::Circle(Circle {
            radius: m,
            omega: Trajectory::MAX_OMEGA,
            depth: -Trajectory::MAX_DEPTH,
        }),
        TrajectoryKind::FigureEight(FigureEight {
            amplitude: m,
            omega: Trajectory::MAX_OMEGA,
            depth: Trajectory::MAX_DEPTH,
        }),
        TrajectoryKind::LawnMower(LawnMower {
            scale: m / 15.0,
            omega: Trajectory::MAX_OMEGA,
            depth: 0.0,
        }),
        TrajectoryKind::Helix(Helix {
            radius: m,
            omega: Trajectory::MAX_OMEGA,
            depth: Trajectory::MAX_DEPTH,
            depth_rate: Trajectory::MAX_DEPTH_RATE,
        }),
        TrajectoryKind::Helix(Helix {
            radius: 1e-3,
            omega: f32::MIN_POSITIVE,
            depth: 0.0,
            depth_rate: -Trajectory::MAX_DEPTH_RATE,
        }),
    ];
    for kind in kinds {
        let traj = Trajectory::new(kind).unwrap();
        for (ticks, rate) in [
            (u64::MAX, 1),
            (u64::MAX, u32::MAX),
            (0, 0),
            (u64::MAX, 0),
            (1, u32::MAX),
        ] {
            assert_finite(&traj.sample(ticks, rate)).unwrap();
        }
    }
}

#[test]
fn zero_rate_gives_the_start_sample() {
    for (_, traj) in all_trajectories() {
        assert_eq!(traj.sample(123_456_789, 0), traj.sample(0, 1));
        assert_eq!(traj.sample(0, 0), traj.sample(0, 100));
    }
}

#[test]
fn constructor_errors_name_the_parameter() {
    use TrajectoryError::*;
    assert_eq!(
        Trajectory::circle(-1.0),
        Err(NotPositive {
            parameter: "radius",
            value: -1.0
        })
    );
    assert_eq!(
        Trajectory::circle(f32::NAN),
        Err(NonFinite {
            parameter: "radius"
        })
    );
    assert_eq!(
        Trajectory::figure_eight(f32::INFINITY),
        Err(NonFinite {
            parameter: "amplitude"
        })
    );
    assert_eq!(
        Trajectory::figure_eight(0.0),
        Err(NotPositive {
            parameter: "amplitude",
            value: 0.0
        })
    );
    assert!(matches!(
        Trajectory::lawn_mower(1000.0),
        Err(OutOfRange { parameter: "scale", value, .. }) if value == 1000.0
    ));
    assert_eq!(
        Trajectory::helix(10.0, f32::NAN),
        Err(NonFinite {
            parameter: "depth_rate"
        })
    );
    assert!(matches!(
        Trajectory::helix(10.0, 50.0),
        Err(OutOfRange {
            parameter: "depth_rate",
            ..
        })
    ));
    assert!(matches!(
        Trajectory::circle(20_000.0),
        Err(OutOfRange { parameter: "radius", max, .. }) if max == Trajectory::MAX_SIZE
    ));
    let circle = |omega, depth| {
        Trajectory::new(TrajectoryKind::Circle(Circle {
            radius: 10.0,
            omega,
            depth,
        }))
    };
    assert_eq!(
        circle(0.0, 5.0),
        Err(NotPositive {
            parameter: "omega",
            value: 0.0
        })
    );
    assert_eq!(
        circle(-0.1, 5.0),
        Err(NotPositive {
            parameter: "omega",
            value: -0.1
        })
    );
    assert_eq!(circle(f32::NAN, 5.0), Err(NonFinite { parameter: "omega" }));
    assert!(matches!(
        circle(100.0, 5.0),
        Err(OutOfRange {
            parameter: "omega",
            ..
        })
    ));
    assert_eq!(
        circle(0.1, f32::NEG_INFINITY),
        Err(NonFinite { parameter: "depth" })
    );
    assert!(matches!(
        circle(0.1, 1e6),
        Err(OutOfRange {
            parameter: "depth",
            ..
        })
    ));
    let lawn = Trajectory::new(TrajectoryKind::LawnMower(LawnMower {
        scale: 1.0,
        omega: 0.0,
        depth: 5.0,
    }));
    assert_eq!(
        lawn,
        Err(NotPositive {
            parameter: "omega",
            value: 0.0
        })
    );
    // The message names the parameter too.
    let msg = format!("{}", Trajectory::circle(f32::NAN).unwrap_err());
    assert!(msg.contains("radius"), "{msg}");
}

#[test]
fn same_instant_at_different_rates_is_identical() {
    // t = k/100 s = 10k/1000 s = 10_000k/1_000_000 s: the sample depends on t only.
    for (_, traj) in all_trajectories() {
        for k in [0u64, 1, 777, 360_000, 36_000_000] {
            let a = traj.sample(k, 100);
            assert_eq!(a, traj.sample(10 * k, 1000));
            assert_eq!(a, traj.sample(10_000 * k, 1_000_000));
        }
    }
}
