//! Long missions (docs/law.md#the-sampled-f32-loop): the sampled x_d, y_d, ψ_d against an f64 evaluation of
//! the paper's literal formulas written here, over the paper's 70 s and after 100 hours (the
//! phase reduction: an f32 time would be off by centimetres).

use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower};
use controller_core::trajectory::{Trajectory, TrajectoryKind};
use std::f64::consts::PI;

#[path = "common/trajectories.rs"]
mod trajectories;
use trajectories::*;

// ---------------------------------------------------------------------------------------------
// Long missions: phase reduction.
// ---------------------------------------------------------------------------------------------

/// The paper's formulas in f64, written independently of the module (all n ≤ 9 for the
/// lawn-mower, with the literal sin(nπ/4) + sin(3nπ/4)). ω is the f32 parameter widened to f64
/// (0.1f32 = 0.100000001490…; the 1.5e-9 difference would be 5e-4 rad after 100 h).
fn reference(kind: TrajectoryKind, t: f64) -> (f64, f64, f64) {
    match kind {
        TrajectoryKind::Circle(Circle { radius, omega, .. })
        | TrajectoryKind::Helix(Helix { radius, omega, .. }) => {
            let (r, w) = (radius as f64, omega as f64);
            (r * (w * t).sin(), r * (w * t).cos(), wrap(w * t))
        }
        TrajectoryKind::FigureEight(FigureEight {
            amplitude, omega, ..
        }) => {
            let (a, w) = (amplitude as f64, omega as f64);
            let psi: f64 = (1..=9)
                .step_by(2)
                .map(|n| {
                    let n = n as f64;
                    let sign = if ((n as i32 - 1) / 2) % 2 == 0 {
                        1.0
                    } else {
                        -1.0
                    };
                    sign * (n * w * t).sin() / (n * n)
                })
                .sum::<f64>()
                * 8.0
                / PI;
            (a * (w * t).sin(), a * (0.5 * w * t).cos(), wrap(psi))
        }
        TrajectoryKind::LawnMower(LawnMower { scale, omega, .. }) => {
            let (s, w) = (scale as f64, omega as f64);
            let psi: f64 = (1..=9)
                .map(|n| {
                    let n = n as f64;
                    ((n * PI / 4.0).sin() + (3.0 * n * PI / 4.0).sin()) * (n * w * t).sin()
                        / (n * n)
                })
                .sum::<f64>()
                * 8.0
                / PI;
            (
                s * (0.25 * t + 2.5 * (2.0 * w * t).sin()),
                15.0 * s * (w * t).cos(),
                wrap(psi),
            )
        }
        TrajectoryKind::Waypoints { .. } => {
            unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
        }
    }
}

/// Position/heading tolerance against the f64 reference: 1e-4 with libm (measured 8.4e-6 m and
/// 2.0e-6 rad, the same at 100 h as in the first 70 s); with micromath its sin/cos error times
/// the amplitude, 2e-3·A (measured 1.1e-3·A, e.g. 2.2e-2 m for R = 20) and [`SERIES_TOL`] for ψ
/// (measured 4.1e-3 rad).
fn reference_tol(kind: TrajectoryKind) -> (f64, f64) {
    if !MICROMATH {
        return (1e-4, 1e-4);
    }
    let amp = match kind {
        TrajectoryKind::Circle(Circle { radius, .. })
        | TrajectoryKind::Helix(Helix { radius, .. }) => radius,
        TrajectoryKind::FigureEight(FigureEight { amplitude, .. }) => amplitude,
        TrajectoryKind::LawnMower(LawnMower { scale, .. }) => 15.0 * scale,
        TrajectoryKind::Waypoints { .. } => {
            unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
        }
    } as f64;
    (2e-3 * amp, SERIES_TOL)
}

/// Checks x, y, ψ at `ticks` + 0..span (100 Hz) against the reference; returns the worst errors.
fn check_against_reference(traj: &Trajectory, first_tick: u64, span: u64) -> (f64, f64) {
    let kind = traj.kind();
    let (pos_tol, psi_tol) = reference_tol(kind);
    let mut worst = (0.0f64, 0.0f64);
    for k in (first_tick..first_tick + span).step_by(13) {
        let d = traj.sample(k, 100);
        let t = k as f64 / 100.0;
        let (x, y, psi) = reference(kind, t);
        // x of the lawn-mower grows with t (90 km after 100 h): allow the f32 spacing there.
        let spacing = (x.abs() as f32).to_bits();
        let ulp = (f32::from_bits(spacing + 1) - f32::from_bits(spacing)) as f64;
        let ex = (d.eta[0] as f64 - x).abs();
        let ey = (d.eta[1] as f64 - y).abs();
        let ep = wrap(d.eta[5] as f64 - psi).abs();
        worst = (worst.0.max(ex.max(ey)), worst.1.max(ep));
        assert!(ex <= pos_tol + ulp, "t={t}: x {} vs {x}", d.eta[0]);
        assert!(ey <= pos_tol, "t={t}: y {} vs {y}", d.eta[1]);
        assert!(ep <= psi_tol, "t={t}: ψ {} vs {psi}", d.eta[5]);
    }
    worst
}

#[test]
fn matches_f64_reference_over_a_mission() {
    for (name, traj) in all_trajectories() {
        let w = check_against_reference(&traj, 0, 7_000); // the paper's 70 s
        eprintln!(
            "{name} 0–70 s: worst position {:.1e} m, ψ {:.1e} rad",
            w.0, w.1
        );
    }
}

#[test]
fn matches_f64_reference_after_100_hours() {
    let ticks_100h = 100 * 3600 * 100u64;
    for (name, traj) in all_trajectories() {
        let w = check_against_reference(&traj, ticks_100h, 20_000);
        eprintln!(
            "{name} 100 h: worst position {:.1e} m, ψ {:.1e} rad",
            w.0, w.1
        );
    }
    // The same evaluation with an f32 time (what the module must not do) is off by centimetres
    // for the 10 m circle: this is what the test above would catch.
    let mut naive_worst = 0.0f64;
    for k in (ticks_100h..ticks_100h + 20_000).step_by(13) {
        let t32 = k as f32 / 100.0;
        let x32 = 10.0 * (0.1f32 * t32).sin();
        naive_worst = naive_worst.max(
            (x32 as f64 - reference(Trajectory::circle(10.0).unwrap().kind(), k as f64 / 100.0).0)
                .abs(),
        );
    }
    eprintln!("naive f32 time after 100 h: worst x error {naive_worst:.1e} m");
    assert!(naive_worst > 1e-3);
}
