//! The tangent heading on a waypoint corner in closed form (docs/missions.md#the-corner-radius,
//! Choices 310, 314), against the heading computed here from the path's own tangent
//! (atan2 of p′) and its finite differences, densely sampled; and the floor of `turn_radius`
//! (issue 29 item 1: a corner of 1e-6 m passed both checks and flew with a π/2 yaw error).

use controller_core::trajectory::{
    Route, TrajectoryError, WaypointList, MAX_SPEED, MIN_TURN_RADIUS,
};
use controller_core::{HeadingMode, Mission, Trajectory, TrajectoryKind};

fn corner(points: &[[f32; 3]], turn_radius: Option<f32>) -> Result<Trajectory, TrajectoryError> {
    Trajectory::new(Mission {
        path: TrajectoryKind::Waypoints {
            points: WaypointList::new(points).unwrap(),
            speed: 0.5,
            turn_radius,
            speeds: None,
            speed_change: None,
        },
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    })
}

/// A corner of `degrees` at (40, 0, 5), legs of 40 m, the second climbing by `dz` m.
fn turn(degrees: f32, dz: f32) -> Vec<[f32; 3]> {
    let a = degrees.to_radians();
    vec![
        [0.0, 0.0, 5.0],
        [40.0, 0.0, 5.0],
        [40.0 + 40.0 * a.cos(), 40.0 * a.sin(), 5.0 + dz],
    ]
}

/// The blends' segment indices.
fn blends(route: &Route) -> Vec<usize> {
    (0..route.segment_count())
        .filter(|&i| route.segment_part(i) % 2 == 1)
        .collect()
}

/// ψ at `local` on segment `i` from the path's tangent, computed here (f64 of the f32
/// tangent; the local parameter, not σ, so that its rounding is the local one).
fn heading(route: &Route, i: usize, local: f64) -> f64 {
    let d = route.at_local(Some(i), local as f32).d[0];
    f64::from(d[1]).atan2(f64::from(d[0]))
}

fn unwrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
}

/// ψ′ and ψ″ at `local` on segment `i` by central differences of step h.
fn differences(route: &Route, i: usize, local: f64, h: f64) -> (f64, f64) {
    let (m, c, p) = (
        heading(route, i, local - h),
        heading(route, i, local),
        heading(route, i, local + h),
    );
    let (dm, dp) = (unwrap(c - m), unwrap(p - c));
    ((dp + dm) / (2.0 * h), (dp - dm) / (h * h))
}

const CASES: [(f32, f32, f32); 7] = [
    (30.0, 0.0, 1.0),
    (90.0, 0.0, 1.0),
    (90.0, 0.0, 2.5),
    (120.0, 0.0, 1.0),
    (60.0, 20.0, 1.5),
    (100.0, -30.0, 1.0),
    (-75.0, 10.0, 2.0),
];

/// The closed forms of ψ′ and ψ″ are the derivatives of the heading of the path's tangent;
/// the rate's bound holds everywhere on the blend and is tight (within 2× of the sampled peak;
/// exact for a level corner); the peaks found give the sampled extremes of ψ″.
#[test]
fn the_blend_heading_in_closed_form_matches_the_tangents_heading() {
    for (degrees, dz, radius) in CASES {
        let t = corner(&turn(degrees, dz), Some(radius)).unwrap();
        let route = t.route();
        for i in blends(route) {
            let len = f64::from(route.segment_length(i));
            let h = len / 100.0;
            let (mut rate, mut accel) = (0.0f64, 0.0f64);
            let (mut hi, mut lo) = (f64::NEG_INFINITY, f64::INFINITY);
            for j in 1..400 {
                let local = len * f64::from(j) / 400.0;
                let (d1, d2) = differences(route, i, local, h);
                let (c1, c2) = route.heading_derivatives(i, local as f32);
                let peak2 = f64::from(route.peak_heading_accel(i));
                assert!(
                    (f64::from(c1) - d1).abs() < 2e-3 * f64::from(route.peak_heading_rate(i)),
                    "{degrees}° dz {dz} R {radius} u {}: ψ′ {c1} vs {d1}",
                    local / len
                );
                assert!(
                    (f64::from(c2) - d2).abs() < 2e-2 * peak2,
                    "{degrees}° dz {dz} R {radius} u {}: ψ″ {c2} vs {d2}",
                    local / len
                );
                rate = rate.max(d1.abs());
                accel = accel.max(d2.abs());
                hi = hi.max(f64::from(c2));
                lo = lo.min(f64::from(c2));
            }
            let (rate_bound, accel_bound) = (
                f64::from(route.peak_heading_rate(i)),
                f64::from(route.peak_heading_accel(i)),
            );
            assert!(
                rate <= rate_bound * 1.001,
                "{degrees}°: {rate} > {rate_bound}"
            );
            assert!(
                rate_bound <= 2.0 * rate,
                "{degrees}°: {rate_bound} ≫ {rate}"
            );
            assert!(
                accel <= accel_bound * 1.02,
                "{degrees}°: {accel} > {accel_bound}"
            );
            assert!(
                accel_bound <= 1.02 * accel,
                "{degrees}°: {accel_bound} > {accel}"
            );
            // The corner rule: |ψ′| ≤ 1/R, so the heading turns at most at speed/R.
            assert!(
                rate <= 1.0 / f64::from(radius) * 1.001,
                "{degrees}°: {rate}"
            );
            let [up, down] = route.heading_accel_peaks(i);
            let at = |l: f32| f64::from(route.heading_derivatives(i, l).1);
            assert!(
                at(up) >= hi - 1e-4 * hi.abs(),
                "{degrees}°: {} < {hi}",
                at(up)
            );
            assert!(
                at(down) <= lo + 1e-4 * lo.abs(),
                "{degrees}°: {} > {lo}",
                at(down)
            );
        }
    }
}

/// For a level corner the rate bound is the closed form (15/8)·tan(Δ/2)/a, at the middle.
#[test]
fn a_level_corners_peak_rate_is_its_closed_form() {
    for degrees in [20.0f32, 90.0, 120.0] {
        let t = corner(&turn(degrees, 0.0), Some(1.0)).unwrap();
        let route = t.route();
        let a = f64::from(route.cut(1));
        let expected = 15.0 / 8.0 * (f64::from(degrees).to_radians() / 2.0).tan() / a;
        let i = blends(route)[0];
        let got = f64::from(route.peak_heading_rate(i));
        assert!((got - expected).abs() < 1e-5 * expected, "{got} {expected}");
        let middle = f64::from(
            route
                .heading_derivatives(i, route.segment_length(i) / 2.0)
                .0,
        );
        assert!(
            (middle.abs() - expected).abs() < 1e-4 * expected,
            "{middle}"
        );
    }
}

/// Issue 29 item 1: `turn_radius = 1e-6` (or 1e-9, 1e-30, and anything under the 1 m floor)
/// was accepted; it is refused naming `turn_radius` and the floor, and the floor flies.
#[test]
fn a_turn_radius_under_the_floor_is_refused() {
    for r in [1e-30f32, 1e-9, 1e-6, 1e-3, 0.5, 0.999] {
        match corner(&turn(90.0, 0.0), Some(r)) {
            Err(e @ TrajectoryError::OutOfRange { min, .. }) => {
                assert_eq!(e.parameter(), "turn_radius");
                assert_eq!(min, MIN_TURN_RADIUS);
            }
            other => panic!("{r}: {other:?}"),
        }
    }
    let t = corner(&turn(90.0, 0.0), Some(MIN_TURN_RADIUS)).unwrap();
    // At the floor the blend is at least R long, so at the fastest path speed it lasts at
    // least R/MAX_SPEED = 0.1 s, and its heading turns at most at MAX_SPEED/R.
    let route = t.route();
    let i = blends(route)[0];
    assert!(route.segment_length(i) >= MIN_TURN_RADIUS);
    assert!(route.peak_heading_rate(i) * MAX_SPEED <= MAX_SPEED / MIN_TURN_RADIUS * 1.0001);
}
