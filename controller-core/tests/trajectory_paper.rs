//! The paper's missions as the paper states them (docs/missions.md#closed-form-paths, docs/simulator.md#table-1): the heading series
//! against the triangle and trapezoid waves they truncate (with the truncation bound), the
//! Table-1 names, sizes and spans, and K_d of Assumption 1 against the sampled ‖η̈_d‖.

use controller_core::trajectory::{Table1Case, Trajectory};
use std::f64::consts::PI;

#[path = "common/trajectories.rs"]
mod trajectories;
use trajectories::*;

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
