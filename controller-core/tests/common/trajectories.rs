//! What the trajectory tests share: the missions they fly (`TrajectoryKind::EXAMPLES`' closed
//! forms, the Table-1 missions and a few off the paper's values), sampling at a time in seconds,
//! and the backend's tolerances.

#![allow(dead_code)]

use controller_core::trajectory::{Desired, Table1Case, Trajectory, TrajectoryKind};
use controller_core::trajectory::{FigureEight, LawnMower};
use std::f64::consts::{PI, TAU};

pub const MICROMATH: bool = cfg!(feature = "micromath");

/// Wraps to (−π, π] in f64.
pub fn wrap(x: f64) -> f64 {
    let r = x - TAU * ((x + PI) / TAU).floor();
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// Every closed form of `TrajectoryKind::EXAMPLES` (a new kind is flown here without a line),
/// the six Table-1 missions, a faster-descending helix and two non-paper frequencies/depths.
pub fn all_trajectories() -> Vec<(String, Trajectory)> {
    let mut v: Vec<(String, Trajectory)> = TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .map(|k| {
            let t = Trajectory::new(k).expect("every example is a valid mission");
            (format!("{} (example)", k.name()), t)
        })
        .collect();
    v.extend(
        Table1Case::ALL
            .iter()
            .map(|c| (c.name().to_string(), Trajectory::table1(*c))),
    );
    v.push(("helix".into(), Trajectory::helix(10.0, 0.2).unwrap()));
    v.push((
        "figure-eight-fast".into(),
        Trajectory::new(TrajectoryKind::FigureEight(FigureEight {
            amplitude: 7.0,
            omega: 0.3,
            depth: 12.0,
        }))
        .unwrap(),
    ));
    v.push((
        "lawn-mower-slow-descending".into(),
        Trajectory::new(TrajectoryKind::LawnMower(LawnMower {
            scale: 0.5,
            omega: 0.02,
            depth: 40.0,
        }))
        .unwrap(),
    ));
    v
}

pub fn to_f64(v: &nalgebra::Vector6<f32>) -> [f64; 6] {
    core::array::from_fn(|i| v[i] as f64)
}

/// 1 MHz: a tick is a microsecond, so t = k µs exactly.
pub const FD_RATE: u32 = 1_000_000;

/// Absolute tolerance on a quantity of unit amplitude from one sin/cos: libm — f32 rounding plus
/// the half-microsecond tick rounding (≤ 1e-6); micromath — its documented ≤ 2e-3 sin/cos error
/// (measured 1.1e-3 here).
pub const UNIT_TOL: f64 = if MICROMATH { 2.5e-3 } else { 2e-6 };

pub fn at_seconds(traj: &Trajectory, t: f64) -> Desired {
    traj.sample((t * FD_RATE as f64).round() as u64, FD_RATE)
}

pub fn assert_close(what: &str, got: f32, want: f64, tol: f64) {
    assert!(
        (got as f64 - want).abs() <= tol,
        "{what}: got {got}, want {want} (tol {tol})"
    );
}

pub fn assert_angle(what: &str, got: f32, want: f64, tol: f64) {
    assert!(
        wrap(got as f64 - want).abs() <= tol,
        "{what}: got {got}, want {want} mod 2π (tol {tol})"
    );
}

/// Extra tolerance for the f32 evaluation of the 5-term heading series.
///
/// libm: measured 2e-6 rad. micromath: each sin is off by ≤ 2e-3, weighted by (8/π)|c_n|/n², so
/// the series is off by ≤ 2e-3·(8/π)·√2·Σ_{odd n≤9} 1/n² = 8.5e-3 rad for the lawn-mower
/// (6.0e-3 for the figure-eight); measured 4.0e-3.
pub const SERIES_TOL: f64 = if MICROMATH { 8.5e-3 } else { 5e-6 };
