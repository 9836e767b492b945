//! Integration tests of `controller_core::trajectory` (docs/missions.md#closed-form-paths, docs/law.md#the-sampled-f32-loop).
//!
//! Every assertion checks a fact that does not come from the module's own arithmetic: finite
//! differences of the sampled η_d, closed-form values of the paper's missions, the exact triangle
//! and trapezoid waves the heading series approximate (with the series' truncation bound), the
//! Table-1 sizes, and an f64 evaluation of the paper's literal formulas written here.
//!
//! Tolerances depend on the math backend: libm's sin/cos are correct to an ulp; micromath's have
//! an absolute error of ≈ 1e-3 (up to 2e-3 documented). The numbers measured with each backend
//! are given at each tolerance.

use controller_core::trajectory::{
    Desired, Table1Case, Trajectory, TrajectoryError, TrajectoryKind,
};
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};

const MICROMATH: bool = cfg!(feature = "micromath");

/// Wraps to (−π, π] in f64.
fn wrap(x: f64) -> f64 {
    let r = x - TAU * ((x + PI) / TAU).floor();
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// The six Table-1 missions plus a helix and two non-paper frequencies/depths.
fn all_trajectories() -> Vec<(String, Trajectory)> {
    let mut v: Vec<(String, Trajectory)> = Table1Case::ALL
        .iter()
        .map(|c| (c.name().to_string(), Trajectory::table1(*c)))
        .collect();
    v.push(("helix".into(), Trajectory::helix(10.0, 0.2).unwrap()));
    v.push((
        "figure-eight-fast".into(),
        Trajectory::new(TrajectoryKind::FigureEight {
            amplitude: 7.0,
            omega: 0.3,
            depth: 12.0,
        })
        .unwrap(),
    ));
    v.push((
        "lawn-mower-slow-descending".into(),
        Trajectory::new(TrajectoryKind::LawnMower {
            scale: 0.5,
            omega: 0.02,
            depth: 40.0,
        })
        .unwrap(),
    ));
    v
}

fn to_f64(v: &nalgebra::Vector6<f32>) -> [f64; 6] {
    core::array::from_fn(|i| v[i] as f64)
}

// ---------------------------------------------------------------------------------------------
// Derivatives against finite differences.
// ---------------------------------------------------------------------------------------------

/// 1 MHz: a tick is a microsecond, so t = k µs exactly.
const FD_RATE: u32 = 1_000_000;
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
        TrajectoryKind::Circle { omega, .. }
        | TrajectoryKind::Helix { omega, .. }
        | TrajectoryKind::FigureEight { omega, .. }
        | TrajectoryKind::LawnMower { omega, .. } => omega as f64,
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

/// Absolute tolerance on a quantity of unit amplitude from one sin/cos: libm — f32 rounding plus
/// the half-microsecond tick rounding (≤ 1e-6); micromath — its documented ≤ 2e-3 sin/cos error
/// (measured 1.1e-3 here).
const UNIT_TOL: f64 = if MICROMATH { 2.5e-3 } else { 2e-6 };

fn at_seconds(traj: &Trajectory, t: f64) -> Desired {
    traj.sample((t * FD_RATE as f64).round() as u64, FD_RATE)
}

fn assert_close(what: &str, got: f32, want: f64, tol: f64) {
    assert!(
        (got as f64 - want).abs() <= tol,
        "{what}: got {got}, want {want} (tol {tol})"
    );
}

fn assert_angle(what: &str, got: f32, want: f64, tol: f64) {
    assert!(
        wrap(got as f64 - want).abs() <= tol,
        "{what}: got {got}, want {want} mod 2π (tol {tol})"
    );
}

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
                TrajectoryKind::Circle { depth, .. }
                | TrajectoryKind::FigureEight { depth, .. }
                | TrajectoryKind::LawnMower { depth, .. } => Some(depth),
                TrajectoryKind::Helix { .. } => None,
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

// ---------------------------------------------------------------------------------------------
// Heading series against the waves they truncate.
// ---------------------------------------------------------------------------------------------

/// Σ_{n odd > 9} 1/n² = π²/8 − (1 + 1/9 + 1/25 + 1/49 + 1/81).
fn odd_tail() -> f64 {
    PI * PI / 8.0
        - [1.0f64, 3.0, 5.0, 7.0, 9.0]
            .iter()
            .map(|n| 1.0 / (n * n))
            .sum::<f64>()
}

/// The triangle wave of amplitude π: 2x on [−π/2, π/2], 2(π − x) on [π/2, 3π/2].
fn triangle(x: f64) -> f64 {
    let x = wrap(x);
    if x > PI / 2.0 {
        2.0 * (PI - x)
    } else if x < -PI / 2.0 {
        -2.0 * (PI + x)
    } else {
        2.0 * x
    }
}

/// The trapezoid of amplitude π with ramps of width π/4: odd, 4x on [0, π/4], π on
/// [π/4, 3π/4], 4(π − x) on [3π/4, π].
fn trapezoid(x: f64) -> f64 {
    let x = wrap(x);
    let a = x.abs();
    let v = if a < PI / 4.0 {
        4.0 * a
    } else if a <= 3.0 * PI / 4.0 {
        PI
    } else {
        4.0 * (PI - a)
    };
    v.copysign(x)
}

/// Extra tolerance for the f32 evaluation of the 5-term heading series.
///
/// libm: measured 2e-6 rad. micromath: each sin is off by ≤ 2e-3, weighted by (8/π)|c_n|/n², so
/// the series is off by ≤ 2e-3·(8/π)·√2·Σ_{odd n≤9} 1/n² = 8.5e-3 rad for the lawn-mower
/// (6.0e-3 for the figure-eight); measured 4.0e-3.
const SERIES_TOL: f64 = if MICROMATH { 8.5e-3 } else { 5e-6 };

#[test]
fn figure_eight_heading_is_truncated_triangle_wave() {
    // Truncation error of (8/π)Σ(−1)^k sin(nx)/n² at N = 9: |·| ≤ (8/π)Σ_{odd n>9} 1/n² ≈ 0.127.
    let tail = 8.0 / PI * odd_tail();
    assert!((tail - 0.1269).abs() < 1e-3);
    let traj = Trajectory::figure_eight(15.0).unwrap();
    // Peak at ωt = π/2: every term is positive there, so π − ψ is the whole (positive) tail.
    let d = at_seconds(&traj, 5.0 * PI);
    let gap = PI - d.eta[5] as f64;
    assert!(
        gap >= -SERIES_TOL && gap <= tail + SERIES_TOL,
        "ψ peak {} vs π (tail bound {tail})",
        d.eta[5]
    );
    // Heading rate is zero at the peak (every cos(nπ/2) = 0 for odd n); each of the five cos
    // terms carries weight (8/π)ω/n, Σ = 0.46, times the backend's cos error.
    assert_close("ψ̇ at the peak", d.eta_dot[5], 0.0, 0.5 * UNIT_TOL + 1e-6);
    // Everywhere over one period, within the tail bound of the exact triangle.
    let mut worst = 0.0f64;
    for k in (0..63_000u64).step_by(7) {
        let d = traj.sample(k, 1000); // 1 ms ticks, one ψ period is 20π ≈ 62.8 s
        let t = k as f64 / 1000.0;
        let err = wrap(d.eta[5] as f64 - triangle(0.1f32 as f64 * t)).abs();
        worst = worst.max(err);
        assert!(err <= tail + SERIES_TOL, "t={t}: ψ {} err {err}", d.eta[5]);
    }
    eprintln!("figure-eight ψ vs triangle: worst {worst:.4} (tail bound {tail:.4})");
}

#[test]
fn lawn_mower_heading_is_truncated_trapezoid() {
    // sin(nπ/4) + sin(3nπ/4) = 2 sin(nπ/4): zero for even n and of size √2 for odd n, so the
    // truncation error is ≤ (8/π)·√2·Σ_{odd n>9} 1/n² ≈ 0.180.
    let tail = 8.0 / PI * 2f64.sqrt() * odd_tail();
    assert!((tail - 0.1795).abs() < 1e-3);
    for scale in [2.0 / 3.0, 1.0] {
        let traj = Trajectory::lawn_mower(scale).unwrap();
        // Middle of the plateau, ωt = π/2 (t = 10π): the infinite series gives exactly π.
        let d = at_seconds(&traj, 10.0 * PI);
        assert_angle("ψ plateau", d.eta[5], PI, tail + SERIES_TOL);
        // And −π on the lower plateau, ωt = 3π/2.
        let d = at_seconds(&traj, 30.0 * PI);
        assert_angle("ψ lower plateau", d.eta[5], -PI, tail + SERIES_TOL);
        let mut worst = 0.0f64;
        for k in (0..126_000u64).step_by(11) {
            let d = traj.sample(k, 1000); // one ψ period is 40π ≈ 125.7 s
            let t = k as f64 / 1000.0;
            let err = wrap(d.eta[5] as f64 - trapezoid(0.05f32 as f64 * t)).abs();
            worst = worst.max(err);
            assert!(err <= tail + SERIES_TOL, "t={t}: ψ {} err {err}", d.eta[5]);
            assert!(d.eta[5] > -std::f32::consts::PI && d.eta[5] <= std::f32::consts::PI);
        }
        eprintln!("lawn-mower ψ vs trapezoid: worst {worst:.4} (tail bound {tail:.4})");
    }
}

// ---------------------------------------------------------------------------------------------
// Table 1.
// ---------------------------------------------------------------------------------------------

/// Min and max of x and y over `seconds`, sampled every 5 ms.
fn extent(traj: &Trajectory, seconds: f64) -> ([f64; 2], [f64; 2]) {
    let mut x = [f64::INFINITY, f64::NEG_INFINITY];
    let mut y = x;
    for k in (0..=(seconds * 1000.0) as u64).step_by(5) {
        let d = traj.sample(k, 1000);
        let (px, py) = (d.eta[0] as f64, d.eta[1] as f64);
        x = [x[0].min(px), x[1].max(px)];
        y = [y[0].min(py), y[1].max(py)];
    }
    (x, y)
}

#[test]
fn table1_names_and_sizes() {
    let names: Vec<&str> = Table1Case::ALL.iter().map(|c| c.name()).collect();
    assert_eq!(
        names,
        [
            "circular-10R",
            "circular-20R",
            "figure-eight-30x30",
            "figure-eight-40x40",
            "lawn-mower-20x10",
            "lawn-mower-30x15",
        ]
    );
    for case in Table1Case::ALL {
        assert_eq!(Table1Case::from_name(case.name()), Some(case));
        // table1 is the validated constructor's result.
        assert_eq!(
            Trajectory::table1(case),
            Trajectory::new(case.kind()).unwrap()
        );
        assert_eq!(Trajectory::table1(case).kind(), case.kind());
    }
    assert_eq!(Table1Case::from_name("circular"), None);
    assert_eq!(
        Trajectory::table1(Table1Case::Circular20R),
        Trajectory::circle(20.0).unwrap()
    );
    assert_eq!(
        Trajectory::table1(Table1Case::FigureEight40x40),
        Trajectory::figure_eight(20.0).unwrap()
    );
    assert_eq!(
        Trajectory::table1(Table1Case::LawnMower30x15),
        Trajectory::lawn_mower(1.0).unwrap()
    );
}

#[test]
fn table1_spans() {
    // Sampling every 5 ms misses an extremum by at most A(1 − cos(ω·2.5 ms)) < 1e-6 m.
    let rel = if MICROMATH { 3e-3 } else { 1e-5 };
    let span = |r: [f64; 2]| r[1] - r[0];
    for (case, radius) in [
        (Table1Case::Circular10R, 10.0),
        (Table1Case::Circular20R, 20.0),
    ] {
        let (x, y) = extent(&Trajectory::table1(case), 63.0); // one revolution 20π s
        for (axis, r) in [("x", x), ("y", y)] {
            assert!(
                (r[0] + radius).abs() <= rel * radius && (r[1] - radius).abs() <= rel * radius,
                "{} {axis} range {r:?}",
                case.name()
            );
        }
    }
    for (case, side) in [
        (Table1Case::FigureEight30x30, 30.0),
        (Table1Case::FigureEight40x40, 40.0),
    ] {
        let (x, y) = extent(&Trajectory::table1(case), 126.0); // y period 40π s
        assert!(
            (span(x) - side).abs() <= rel * side,
            "{} x {x:?}",
            case.name()
        );
        assert!(
            (span(y) - side).abs() <= rel * side,
            "{} y {y:?}",
            case.name()
        );
        // Centred on the origin.
        assert!((x[0] + x[1]).abs() <= rel * side && (y[0] + y[1]).abs() <= rel * side);
    }
    for (case, height, width) in [
        (Table1Case::LawnMower20x10, 20.0, 10.0),
        (Table1Case::LawnMower30x15, 30.0, 15.0),
    ] {
        let traj = Trajectory::table1(case);
        let (_, y) = extent(&traj, 126.0); // y period 40π s
        assert!(
            (span(y) - height).abs() <= rel * height,
            "{} y {y:?}",
            case.name()
        );
        // One loop: y goes from its maximum (t = 0) to its minimum (ωt = π, t = 20π s); the x
        // advance over it is the loop width, 0.25·s·20π = 5πs ≈ 10.47 / 15.71, i.e. the paper's
        // "20×10" / "30×15" to within 5 %.
        let x0 = traj.sample(0, 1000).eta[0] as f64;
        let x1 = at_seconds(&traj, 20.0 * PI).eta[0] as f64;
        let w = x1 - x0;
        assert!(
            (w - width).abs() <= 0.06 * width,
            "{} width {w}",
            case.name()
        );
        // y really is extremal at both ends.
        assert_close(
            "y max",
            traj.sample(0, 1000).eta[1],
            height / 2.0,
            rel * height,
        );
        assert_close(
            "y min",
            at_seconds(&traj, 20.0 * PI).eta[1],
            -height / 2.0,
            rel * height,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Assumption 1 (K_d).
// ---------------------------------------------------------------------------------------------

#[test]
fn accel_bound_bounds_and_is_useful() {
    for (name, traj) in all_trajectories() {
        // 130 s covers every ψ and y period of the paper's missions (≤ 40π s); the slow
        // lawn-mower needs 100π s.
        let seconds = if name.ends_with("-descending") {
            315.0
        } else {
            130.0
        };
        let mut peak = 0.0f64;
        for k in (0..(seconds * 1000.0) as u64).step_by(3) {
            let a = to_f64(&traj.sample(k, 1000).eta_ddot);
            peak = peak.max(a.iter().map(|v| v * v).sum::<f64>().sqrt());
        }
        let bound = traj.accel_bound() as f64;
        eprintln!(
            "{name}: max ‖η̈_d‖ = {peak:.5}, K_d = {bound:.5}, ratio {:.3}",
            bound / peak
        );
        assert!(bound >= peak, "{name}: K_d {bound} < sampled max {peak}");
        assert!(
            bound <= 3.0 * peak,
            "{name}: K_d {bound} > 3 × sampled max {peak}"
        );
    }
    // Circle: the bound is √2·Rω² (x and y amplitudes Rω² summed in quadrature) and the true
    // maximum Rω² = 0.1 for R = 10, ω = 0.1.
    let k = Trajectory::circle(10.0).unwrap().accel_bound() as f64;
    assert!((0.1..=0.1 * 2f64.sqrt() * 1.001).contains(&k), "{k}");
}

// ---------------------------------------------------------------------------------------------
// Long missions: phase reduction.
// ---------------------------------------------------------------------------------------------

/// The paper's formulas in f64, written independently of the module (all n ≤ 9 for the
/// lawn-mower, with the literal sin(nπ/4) + sin(3nπ/4)). ω is the f32 parameter widened to f64
/// (0.1f32 = 0.100000001490…; the 1.5e-9 difference would be 5e-4 rad after 100 h).
fn reference(kind: TrajectoryKind, t: f64) -> (f64, f64, f64) {
    match kind {
        TrajectoryKind::Circle { radius, omega, .. }
        | TrajectoryKind::Helix { radius, omega, .. } => {
            let (r, w) = (radius as f64, omega as f64);
            (r * (w * t).sin(), r * (w * t).cos(), wrap(w * t))
        }
        TrajectoryKind::FigureEight {
            amplitude, omega, ..
        } => {
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
        TrajectoryKind::LawnMower { scale, omega, .. } => {
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
        TrajectoryKind::Circle { radius, .. } | TrajectoryKind::Helix { radius, .. } => radius,
        TrajectoryKind::FigureEight { amplitude, .. } => amplitude,
        TrajectoryKind::LawnMower { scale, .. } => 15.0 * scale,
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

fn any_kind() -> impl Strategy<Value = TrajectoryKind> {
    let size = 1e-3f32..=Trajectory::MAX_SIZE;
    let omega = 1e-6f32..=Trajectory::MAX_OMEGA;
    let depth = -Trajectory::MAX_DEPTH..=Trajectory::MAX_DEPTH;
    let rate = -Trajectory::MAX_DEPTH_RATE..=Trajectory::MAX_DEPTH_RATE;
    prop_oneof![
        (size.clone(), omega.clone(), depth.clone()).prop_map(|(radius, omega, depth)| {
            TrajectoryKind::Circle {
                radius,
                omega,
                depth,
            }
        }),
        (size.clone(), omega.clone(), depth.clone()).prop_map(|(amplitude, omega, depth)| {
            TrajectoryKind::FigureEight {
                amplitude,
                omega,
                depth,
            }
        }),
        (
            1e-3f32..=Trajectory::MAX_SIZE / 15.0,
            omega.clone(),
            depth.clone()
        )
            .prop_map(|(scale, omega, depth)| TrajectoryKind::LawnMower {
                scale,
                omega,
                depth,
            }),
        (size, omega, depth, rate).prop_map(|(radius, omega, depth, depth_rate)| {
            TrajectoryKind::Helix {
                radius,
                omega,
                depth,
                depth_rate,
            }
        }),
    ]
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
        TrajectoryKind::Circle {
            radius: m,
            omega: Trajectory::MAX_OMEGA,
            depth: -Trajectory::MAX_DEPTH,
        },
        TrajectoryKind::FigureEight {
            amplitude: m,
            omega: Trajectory::MAX_OMEGA,
            depth: Trajectory::MAX_DEPTH,
        },
        TrajectoryKind::LawnMower {
            scale: m / 15.0,
            omega: Trajectory::MAX_OMEGA,
            depth: 0.0,
        },
        TrajectoryKind::Helix {
            radius: m,
            omega: Trajectory::MAX_OMEGA,
            depth: Trajectory::MAX_DEPTH,
            depth_rate: Trajectory::MAX_DEPTH_RATE,
        },
        TrajectoryKind::Helix {
            radius: 1e-3,
            omega: f32::MIN_POSITIVE,
            depth: 0.0,
            depth_rate: -Trajectory::MAX_DEPTH_RATE,
        },
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
        Trajectory::new(TrajectoryKind::Circle {
            radius: 10.0,
            omega,
            depth,
        })
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
    let lawn = Trajectory::new(TrajectoryKind::LawnMower {
        scale: 1.0,
        omega: 0.0,
        depth: 5.0,
    });
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
