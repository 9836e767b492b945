//! Integration tests of `controller_core::trajectory` (docs/missions.md#closed-form-paths, docs/law.md#the-sampled-f32-loop): derivatives
//! against finite differences and the closed-form values of the paper's missions (the heading
//! series, Table 1 and K_d: `trajectory_paper.rs`; long missions: `trajectory_long.rs`;
//! robustness and refusals: `trajectory_robust.rs`).
//!
//! Every assertion checks a fact that does not come from the module's own arithmetic: finite
//! differences of the sampled η_d, closed-form values of the paper's missions, the exact triangle
//! and trapezoid waves the heading series approximate (with the series' truncation bound), the
//! Table-1 sizes, and an f64 evaluation of the paper's literal formulas written here.
//!
//! Tolerances depend on the math backend: libm's sin/cos are correct to an ulp; micromath's have
//! an absolute error of ≈ 1e-3 (up to 2e-3 documented). The numbers measured with each backend
//! are given at each tolerance.

use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower};
use controller_core::trajectory::{Table1Case, Trajectory, TrajectoryKind};
use std::f64::consts::PI;

#[path = "common/trajectories.rs"]
mod trajectories;
use trajectories::*;

// ---------------------------------------------------------------------------------------------
// Derivatives against finite differences.
// ---------------------------------------------------------------------------------------------

/// Half-step h of the central differences: h·ω = 0.005 for the mission's base frequency ω
/// (h = 0.05 s at the paper's ω = 0.1).
///
/// Central-difference error = truncation |f‴|h²/6 + rounding ε/h. Truncation: a harmonic of
/// frequency ν is differentiated with relative error (νh)²/6, ≤ (9 × 0.005)²/6 = 3.4e-4 for the
/// fastest heading harmonic (n = 9; 2ω for the lawn-mower's x is 1.7e-5). Rounding: the f32 η
/// is off by ε ≈ 1e-6·A (phase rounded to 2.4e-7 rad, n·θ to a few 1e-6 rad, plus the ulp of the
/// value), so ε/h ≈ 1e-6·A/(0.005/ω) = 2e-4 of A·ω. The same two terms apply to η̈ from η̇.
/// Hence a libm tolerance of 1e-3 of each component's peak derivative (≈ 2× the sum).
fn fd_half_step(kind: TrajectoryKind) -> u64 {
    let omega = match kind {
        TrajectoryKind::Circle(Circle { omega, .. })
        | TrajectoryKind::Helix(Helix { omega, .. })
        | TrajectoryKind::FigureEight(FigureEight { omega, .. })
        | TrajectoryKind::LawnMower(LawnMower { omega, .. }) => omega as f64,
        TrajectoryKind::Waypoints { .. } => {
            unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
        }
    };
    (0.005 / omega * FD_RATE as f64).round() as u64
}

/// Times (s) at which the derivatives are checked (≥ h ≤ 0.25 s, ≤ 200 s so that the lawn-mower's
/// growing x stays where f32 resolves 4e-6 m).
const FD_TIMES: [f64; 10] = [
    0.3, 3.7, 12.5, 15.707_963, 31.4, 47.1, 60.0, 88.8, 125.0, 199.9,
];

/// Relative tolerance of the finite-difference checks (of the component's peak |derivative|).
///
/// Measured worst case: libm 8.4e-5 (η̇) / 1.4e-4 (η̈); micromath 1.3e-2 / 1.3e-2 —
/// micromath's piecewise-parabolic sin is not the integral of its cos, so the derivative of the
/// sampled η_d and the analytic η̇_d disagree by about a percent of the peak (tolerance 4e-2).
const FD_REL: f64 = if MICROMATH { 4e-2 } else { 1e-3 };

fn unwrapped_diff(a: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
    let mut d: [f64; 6] = core::array::from_fn(|i| a[i] - b[i]);
    d[5] = wrap(d[5]);
    d
}

#[test]
fn derivatives_match_central_finite_differences() {
    let mut worst = (0.0f64, 0.0f64);
    for (name, traj) in all_trajectories() {
        let h = fd_half_step(traj.kind());
        let mut rows = Vec::new(); // (analytic η̇, fd η̇, analytic η̈, fd η̈)
        for &t in &FD_TIMES {
            let k = (t * FD_RATE as f64).round() as u64;
            let mid = traj.sample(k, FD_RATE);
            let lo = traj.sample(k - h, FD_RATE);
            let hi = traj.sample(k + h, FD_RATE);
            let two_h = 2.0 * h as f64 / FD_RATE as f64;
            let d1 = unwrapped_diff(&to_f64(&hi.eta), &to_f64(&lo.eta)).map(|d| d / two_h);
            let d2: [f64; 6] =
                core::array::from_fn(|i| (hi.eta_dot[i] as f64 - lo.eta_dot[i] as f64) / two_h);
            rows.push((to_f64(&mid.eta_dot), d1, to_f64(&mid.eta_ddot), d2));
        }
        for c in 0..6 {
            let peak1 = rows.iter().map(|r| r.1[c].abs()).fold(0.0, f64::max);
            let peak2 = rows.iter().map(|r| r.3[c].abs()).fold(0.0, f64::max);
            for (t, r) in FD_TIMES.iter().zip(&rows) {
                let e1 = (r.0[c] - r.1[c]).abs();
                let e2 = (r.2[c] - r.3[c]).abs();
                let tol1 = FD_REL * peak1 + 1e-6;
                let tol2 = FD_REL * peak2 + 1e-6;
                if peak1 > 0.0 {
                    worst.0 = worst.0.max(e1 / peak1);
                }
                if peak2 > 0.0 {
                    worst.1 = worst.1.max(e2 / peak2);
                }
                assert!(
                    e1 <= tol1,
                    "{name} t={t} component {c}: η̇ analytic {} vs fd {} (tol {tol1})",
                    r.0[c],
                    r.1[c]
                );
                assert!(
                    e2 <= tol2,
                    "{name} t={t} component {c}: η̈ analytic {} vs fd {} (tol {tol2})",
                    r.2[c],
                    r.3[c]
                );
            }
        }
    }
    eprintln!(
        "finite differences, worst error / peak: η̇ {:.2e}, η̈ {:.2e}",
        worst.0, worst.1
    );
}

// ---------------------------------------------------------------------------------------------
// Closed-form values of the paper's missions.
// ---------------------------------------------------------------------------------------------

#[test]
fn circle_paper_values() {
    let r = 10.0;
    let traj = Trajectory::circle(10.0).unwrap();
    let tol = r * UNIT_TOL;
    // t = 0: x = 0, y = R, z = 5, ψ = 0; ẋ = Rω = 1, ẏ = 0, ψ̇ = ω; ẍ = 0, ÿ = −Rω² = −0.1.
    let d = traj.sample(0, 100);
    assert_close("x(0)", d.eta[0], 0.0, tol);
    assert_close("y(0)", d.eta[1], 10.0, tol);
    assert_close("z(0)", d.eta[2], 5.0, 0.0);
    assert_close("ψ(0)", d.eta[5], 0.0, 1e-7);
    assert_close("ẋ(0)", d.eta_dot[0], 1.0, 0.1 * tol);
    assert_close("ẏ(0)", d.eta_dot[1], 0.0, 0.1 * tol);
    assert_close("ψ̇", d.eta_dot[5], 0.1, 1e-8);
    assert_close("ẍ(0)", d.eta_ddot[0], 0.0, 0.01 * tol);
    assert_close("ÿ(0)", d.eta_ddot[1], -0.1, 0.01 * tol);
    // t = 5π s (ωt = π/2): x = R, y = 0, ψ = π/2.
    let d = at_seconds(&traj, 5.0 * PI);
    assert_close("x(5π)", d.eta[0], 10.0, tol);
    assert_close("y(5π)", d.eta[1], 0.0, tol);
    assert_close("ψ(5π)", d.eta[5], PI / 2.0, 1e-6);
    // t = 10π s (ωt = π): x = 0, y = −R, ψ = ±π (wrapped, so compare mod 2π).
    let d = at_seconds(&traj, 10.0 * PI);
    assert_close("x(10π)", d.eta[0], 0.0, tol);
    assert_close("y(10π)", d.eta[1], -10.0, tol);
    assert_angle("ψ(10π)", d.eta[5], PI, 1e-6);
    // t = 15π s (ωt = 3π/2): ψ = 3π/2 is returned wrapped as −π/2.
    let d = at_seconds(&traj, 15.0 * PI);
    assert_close("x(15π)", d.eta[0], -10.0, tol);
    assert_close("ψ(15π)", d.eta[5], -PI / 2.0, 1e-6);
}

#[test]
fn figure_eight_and_lawn_mower_paper_values() {
    // Figure-eight A = 15, ω = 0.1: x(0) = 0, y(0) = A, ψ(0) = 0; at ωt = π/2 (t = 5π):
    // x = A, y = A cos(π/4).
    let f8 = Trajectory::figure_eight(15.0).unwrap();
    let d = f8.sample(0, 100);
    assert_close("f8 x(0)", d.eta[0], 0.0, 15.0 * UNIT_TOL);
    assert_close("f8 y(0)", d.eta[1], 15.0, 15.0 * UNIT_TOL);
    assert_close("f8 ψ(0)", d.eta[5], 0.0, 10.0 * UNIT_TOL);
    assert_close("f8 ẋ(0)", d.eta_dot[0], 1.5, 1.5 * UNIT_TOL);
    let d = at_seconds(&f8, 5.0 * PI);
    assert_close("f8 x(5π)", d.eta[0], 15.0, 15.0 * UNIT_TOL);
    assert_close(
        "f8 y(5π)",
        d.eta[1],
        15.0 * (PI / 4.0).cos(),
        15.0 * UNIT_TOL,
    );
    // Lawn-mower s = 1, ω = 0.05: x(0) = 0, y(0) = 15, ψ(0) = 0, ẋ(0) = 0.25 + 2.5·0.1 = 0.5,
    // ẏ(0) = 0; at t = 20π (ωt = π): x = 0.25·20π, y = −15.
    let lm = Trajectory::lawn_mower(1.0).unwrap();
    let d = lm.sample(0, 100);
    assert_close("lm x(0)", d.eta[0], 0.0, 2.5 * UNIT_TOL);
    assert_close("lm y(0)", d.eta[1], 15.0, 15.0 * UNIT_TOL);
    assert_close("lm ψ(0)", d.eta[5], 0.0, 10.0 * UNIT_TOL);
    assert_close("lm ẋ(0)", d.eta_dot[0], 0.5, 0.25 * UNIT_TOL);
    assert_close("lm ẏ(0)", d.eta_dot[1], 0.0, 0.75 * UNIT_TOL);
    let d = at_seconds(&lm, 20.0 * PI);
    assert_close("lm x(20π)", d.eta[0], 5.0 * PI, 2.5 * UNIT_TOL + 1e-5);
    assert_close("lm y(20π)", d.eta[1], -15.0, 15.0 * UNIT_TOL);
    // Every mission: z = 5, φ = θ = 0 with zero rates and accelerations.
    for (name, traj) in all_trajectories() {
        for t in [0.0, 1.0, 33.0, 70.0] {
            let d = at_seconds(&traj, t);
            for c in [3, 4] {
                assert_eq!(d.eta[c], 0.0, "{name}");
                assert_eq!(d.eta_dot[c], 0.0, "{name}");
                assert_eq!(d.eta_ddot[c], 0.0, "{name}");
            }
            // z = depth with zero rate, except for the helix (tested below).
            let depth = match traj.kind() {
                TrajectoryKind::Circle(Circle { depth, .. })
                | TrajectoryKind::FigureEight(FigureEight { depth, .. })
                | TrajectoryKind::LawnMower(LawnMower { depth, .. }) => Some(depth),
                TrajectoryKind::Helix(_) => None,
                TrajectoryKind::Waypoints { .. } => {
                    unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
                }
            };
            if let Some(depth) = depth {
                assert_eq!(d.eta[2], depth, "{name}");
                assert_eq!(d.eta_dot[2], 0.0, "{name}");
                assert_eq!(d.eta_ddot[2], 0.0, "{name}");
            }
        }
    }
    for case in Table1Case::ALL {
        assert_eq!(Trajectory::table1(case).sample(4321, 100).eta[2], 5.0);
    }
}

#[test]
fn helix_depth_is_linear_in_time() {
    let traj = Trajectory::helix(10.0, 0.2).unwrap();
    for t in [0.0, 1.0, 100.0, 3600.0] {
        let d = at_seconds(&traj, t);
        // z = 5 + 0.2 t, exact up to the f32 rounding of the result.
        assert_close("helix z", d.eta[2], 5.0 + 0.2 * t, 1e-6 * (5.0 + 0.2 * t));
        assert_close("helix ż", d.eta_dot[2], 0.2, 1e-7);
        assert_eq!(d.eta_ddot[2], 0.0);
    }
    // Same x, y, ψ as the circle of the same radius.
    let c = Trajectory::circle(10.0).unwrap();
    for k in [0u64, 12_345, 7_000_000] {
        let (a, b) = (traj.sample(k, 100), c.sample(k, 100));
        for i in [0, 1, 5] {
            assert_eq!(a.eta[i], b.eta[i]);
            assert_eq!(a.eta_dot[i], b.eta_dot[i]);
            assert_eq!(a.eta_ddot[i], b.eta_ddot[i]);
        }
    }
}
