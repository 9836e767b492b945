//! The waypoint path (docs/missions.md#waypoint-paths): legs joined by septic blends, flown at a constant
//! path speed.
//!
//! Every expected value is independent of the module's arithmetic: finite differences of the
//! sampled path and of the desired state, one-sided limits at every knot (C³), the waypoints'
//! own lines and distances measured by dense sampling in f64, the curvature computed here from
//! p′ and p″, and the refusals' reasons.

use controller_core::trajectory::{
    HeadingMode, Mission, Route, Trajectory, TrajectoryError, TrajectoryKind, WaypointList,
    MAX_TURN_DEGREES, MAX_WAYPOINTS,
};

const MICROMATH: bool = cfg!(feature = "micromath");

/// A 200 m × 100 m lawn-mower at 5 m depth, lines 20 m apart (12 points, ten 90° turns).
fn survey() -> Vec<[f32; 3]> {
    let mut p = Vec::new();
    for line in 0..6 {
        let y = 20.0 * line as f32;
        let (a, b) = if line % 2 == 0 {
            (0.0, 200.0)
        } else {
            (200.0, 0.0)
        };
        p.push([a, y, 5.0]);
        p.push([b, y, 5.0]);
    }
    p
}

/// A descending inspection with turns of several angles and a depth change on a leg.
fn inspection() -> Vec<[f32; 3]> {
    vec![
        [0.0, 0.0, 2.0],
        [40.0, 0.0, 2.0],
        [70.0, 25.0, 12.0],
        [70.0, 60.0, 12.0],
        [30.0, 80.0, 8.0],
        [35.0, 120.0, 8.0],
    ]
}

fn kind(points: &[[f32; 3]], speed: f32, turn_radius: Option<f32>) -> TrajectoryKind {
    TrajectoryKind::Waypoints {
        points: WaypointList::new(points).expect("≤ 32 points"),
        speed,
        turn_radius,
        speeds: None,
        speed_change: None,
    }
}

fn tangent(points: &[[f32; 3]], speed: f32, turn_radius: Option<f32>) -> Trajectory {
    Trajectory::new(Mission {
        path: kind(points, speed, turn_radius),
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    })
    .expect("a valid waypoint mission")
}

fn f64s(v: [f32; 3]) -> [f64; 3] {
    v.map(f64::from)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// p and its three derivatives in f64 at σ rounded to f32.
fn at(route: &Route, sigma: f64) -> [[f64; 3]; 4] {
    let pp = route.at(sigma as f32);
    [f64s(pp.p), f64s(pp.d[0]), f64s(pp.d[1]), f64s(pp.d[2])]
}

/// σ as the route sees it (f32).
fn f32_sigma(sigma: f64) -> f64 {
    sigma as f32 as f64
}

fn missions() -> Vec<(&'static str, Trajectory)> {
    vec![
        ("survey", tangent(&survey(), 0.5, None)),
        ("inspection", tangent(&inspection(), 0.4, Some(2.0))),
    ]
}

/// Each derivative of p(σ) against the central difference of the one below it, everywhere
/// along the path (h = 5 mm; the f32 position's rounding at 200 m, 1.5e-5 m, over 2h is 1.5e-3
/// of the unit tangent, so positions are differenced with h = 5 cm).
#[test]
fn path_derivatives_match_finite_differences() {
    for (name, tr) in missions() {
        let route = tr.route();
        let len = route.length() as f64;
        let mut peak = [0.0f64; 4];
        let mut worst = [0.0f64; 4];
        let steps = 4000;
        for i in 1..steps {
            let s = len * i as f64 / steps as f64;
            for order in 1..4 {
                let h = if order == 1 { 0.05 } else { 0.005 };
                let (lo, hi, mid) = (at(route, s - h), at(route, s + h), at(route, s));
                for c in 0..3 {
                    // The step σ actually took in f32 (ulp 1.2e-4 at 1.3 km).
                    let step = f32_sigma(s + h) - f32_sigma(s - h);
                    let fd = (hi[order - 1][c] - lo[order - 1][c]) / step;
                    worst[order] = worst[order].max((fd - mid[order][c]).abs());
                    peak[order] = peak[order].max(mid[order][c].abs());
                }
            }
        }
        for order in 1..4 {
            assert!(peak[order] > 0.0, "{name}: derivative {order} is zero");
            assert!(
                worst[order] <= 2e-3 * peak[order],
                "{name}: derivative {order} off its finite difference by {} (peak {})",
                worst[order],
                peak[order]
            );
        }
    }
}

/// At every knot (a leg meeting a blend) p, p′, p″ and p‴ have the same limit from both sides:
/// the jump across ±δ (δ = 1 mm) is below 1 % of the derivative's peak over the path, where a
/// missing order of continuity would jump by its whole size (a tangent turning: 1; a curvature
/// starting: 1/R).
#[test]
fn the_path_is_c3_at_every_knot() {
    for (name, tr) in missions() {
        let route = tr.route();
        let mut peak = [0.0f64; 4];
        let steps = 4000;
        for i in 0..=steps {
            let v = at(route, route.length() as f64 * i as f64 / steps as f64);
            for order in 1..4 {
                peak[order] = peak[order].max(norm(v[order]));
            }
        }
        assert!(route.segment_count() >= 3, "{name}");
        let delta = 1e-3;
        for i in 1..route.segment_count() {
            let s0 = route.segment_start(i) as f64;
            let (before, after) = (at(route, s0 - delta), at(route, s0 + delta));
            for order in 0..4 {
                let jump = norm([0, 1, 2].map(|c| after[order][c] - before[order][c]));
                let allowed = match order {
                    // Position: the path moves 2δ at unit speed.
                    0 => 2.0 * delta * 1.01 + 1e-4,
                    _ => 1e-2 * peak[order],
                };
                assert!(
                    jump <= allowed,
                    "{name}: knot {i} at σ = {s0}: derivative {order} jumps by {jump} (allowed {allowed})"
                );
            }
        }
    }
}

/// The desired state's η̇_d, η̈_d and ψ̇_d, ψ̈_d against central differences of the sampled η_d and
/// η̇_d at 1 kHz over the whole mission and beyond its end (the straight continuation).
#[test]
fn desired_state_derivatives_match_finite_differences() {
    const RATE: u32 = 1000;
    for (name, tr) in missions() {
        let speed = match tr.kind() {
            TrajectoryKind::Waypoints { speed, .. } => speed as f64,
            _ => unreachable!(),
        };
        let end = (tr.route().length() as f64 / speed + 20.0) * RATE as f64;
        let h = 20u64; // 20 ms
        let dt = 2.0 * h as f64 / RATE as f64;
        let mut worst = [[0.0f64; 6]; 2];
        let mut peak = [[0.0f64; 6]; 2];
        for k in (h..end as u64).step_by(997) {
            let (lo, mid, hi) = (
                tr.sample(k - h, RATE),
                tr.sample(k, RATE),
                tr.sample(k + h, RATE),
            );
            for c in [0, 1, 2, 5] {
                let mut de = hi.eta[c] as f64 - lo.eta[c] as f64;
                if c == 5 {
                    de = (de + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI;
                }
                let fd = [de / dt, (hi.eta_dot[c] as f64 - lo.eta_dot[c] as f64) / dt];
                let got = [mid.eta_dot[c] as f64, mid.eta_ddot[c] as f64];
                for o in 0..2 {
                    worst[o][c] = worst[o][c].max((fd[o] - got[o]).abs());
                    peak[o][c] = peak[o][c].max(got[o].abs());
                }
            }
        }
        // Rounding of f32 positions (~1.5e-5 m at 200 m) over 40 ms: 4e-4 m/s; truncation
        // h²/6·|x⁗| is far below. micromath's atan2 (≈ 1e-3 rad) dominates ψ there.
        let psi_tol = if MICROMATH { 0.1 } else { 2e-3 };
        for c in [0, 1, 2, 5] {
            for o in 0..2 {
                let tol = if c == 5 && o == 0 {
                    psi_tol
                } else {
                    1e-3 + 2e-3 * peak[o][c]
                };
                assert!(
                    worst[o][c] <= tol,
                    "{name}: component {c}, derivative {}: off by {} (peak {}, tol {tol})",
                    o + 1,
                    worst[o][c],
                    peak[o][c]
                );
            }
        }
        assert!(peak[1][5] > 0.0, "{name}: the heading never turns");
    }
}

/// The path starts on the first waypoint, ends on the last, keeps to the legs' lines outside
/// the blends, and passes each inner waypoint at its stated distance (5/16)·a·sin(Δ/2), measured
/// here by dense sampling.
#[test]
fn passes_each_waypoint_within_its_stated_distance() {
    for (name, pts) in [("survey", survey()), ("inspection", inspection())] {
        let tr = match name {
            "survey" => tangent(&pts, 0.5, None),
            _ => tangent(&pts, 0.4, Some(2.0)),
        };
        let route = tr.route();
        let len = route.length() as f64;
        let first = at(route, 0.0)[0];
        let last = at(route, len)[0];
        assert!(
            norm([0, 1, 2].map(|c| first[c] - pts[0][c] as f64)) < 1e-4,
            "{name}"
        );
        let n = pts.len() - 1;
        assert!(
            norm([0, 1, 2].map(|c| last[c] - pts[n][c] as f64)) < 1e-3,
            "{name}"
        );
        let steps = 200_000;
        let mut closest = vec![f64::INFINITY; pts.len()];
        for i in 0..=steps {
            let p = at(route, len * i as f64 / steps as f64)[0];
            for (j, w) in pts.iter().enumerate() {
                let d = norm([0, 1, 2].map(|c| p[c] - w[c] as f64));
                closest[j] = closest[j].min(d);
            }
        }
        let mut worst = 0.0f64;
        for (j, &closest) in closest.iter().enumerate().take(n).skip(1) {
            let stated = route.miss(j) as f64;
            assert!(stated > 0.0, "{name}: waypoint {j}");
            // Sampling step ≤ len/steps ≈ 6 mm: the closest sample is within 3 mm.
            assert!(
                (closest - stated).abs() <= 5e-3,
                "{name}: waypoint {j} passed at {closest} m, stated {stated} m"
            );
            worst = worst.max(stated);
        }
        println!("{name}: largest stated miss {worst:.3} m");
    }
}

/// The curvature |p′ × p″|/|p′|³, computed here, never exceeds 1/turn_radius; on each blend its
/// peak is the closed form (15/8)·sin(Δ/2)/(a·cos²(Δ/2)); the parameter speed |p′| is ≤ 1 and
/// cos(Δ/2) at the middle of a blend.
#[test]
fn curvature_stays_within_the_turn_radius() {
    for (name, tr, radius) in [
        ("survey", tangent(&survey(), 0.5, None), 2.5),
        ("inspection", tangent(&inspection(), 0.4, Some(2.0)), 2.0),
        ("inspection-r5", tangent(&inspection(), 0.4, Some(5.0)), 5.0),
    ] {
        let route = tr.route();
        let len = route.length() as f64;
        let steps = 100_000;
        let mut kmax = 0.0f64;
        let mut vmax = 0.0f64;
        for i in 0..=steps {
            let v = at(route, len * i as f64 / steps as f64);
            let (d1, d2) = (v[1], v[2]);
            let cross = [
                d1[1] * d2[2] - d1[2] * d2[1],
                d1[2] * d2[0] - d1[0] * d2[2],
                d1[0] * d2[1] - d1[1] * d2[0],
            ];
            kmax = kmax.max(norm(cross) / norm(d1).powi(3));
            vmax = vmax.max(norm(d1));
        }
        assert!(
            kmax <= (1.0 + 1e-3) / radius,
            "{name}: κ {kmax} > 1/{radius}"
        );
        assert!(
            kmax >= 0.5 / radius,
            "{name}: κ {kmax}: the blends are needlessly wide"
        );
        assert!(vmax <= 1.0 + 1e-6, "{name}: parameter speed {vmax}");
        // The closed forms at the middle of each blend (u = ½: σ = start + a).
        let n = match tr.kind() {
            TrajectoryKind::Waypoints { points, .. } => points.as_slice().len(),
            _ => unreachable!(),
        };
        let mut blend = 0;
        for i in 0..route.segment_count() {
            let s0 = route.segment_start(i) as f64;
            // A blend is the segment that starts a cut before its waypoint: find it by its
            // middle's speed below 1.
            let next = if i + 1 < route.segment_count() {
                route.segment_start(i + 1) as f64
            } else {
                len
            };
            let mid = at(route, 0.5 * (s0 + next));
            if norm(mid[1]) > 1.0 - 1e-6 {
                continue;
            }
            blend += 1;
            let (a, turn) = (route.cut(blend) as f64, route.turn(blend) as f64);
            assert!(
                ((next - s0) - 2.0 * a).abs() < 1e-3,
                "{name}: blend {blend} length"
            );
            let speed = norm(mid[1]);
            assert!(
                (speed - (0.5 * turn).cos()).abs() < 1e-5,
                "{name}: blend {blend} speed"
            );
            let mut peak = 0.0f64;
            for j in 0..=2000 {
                let v = at(route, s0 + (next - s0) * j as f64 / 2000.0);
                let c = v[1][0] * v[2][1] - v[1][1] * v[2][0];
                let c3 = norm([
                    v[1][1] * v[2][2] - v[1][2] * v[2][1],
                    v[1][2] * v[2][0] - v[1][0] * v[2][2],
                    c,
                ]);
                peak = peak.max(c3 / norm(v[1]).powi(3));
            }
            let closed = route.peak_curvature(blend) as f64;
            assert!(
                (peak - closed).abs() <= 1e-3 * closed,
                "{name}: blend {blend}: sampled peak κ {peak}, closed form {closed}"
            );
        }
        assert_eq!(blend, n - 2, "{name}: one blend per inner waypoint");
    }
}

/// K_d (Assumption 1) bounds ‖η̈_d‖ at every control period of the mission, and η_d is finite
/// at any tick.
#[test]
fn the_acceleration_bound_holds_and_samples_are_finite() {
    for (name, tr) in missions() {
        let kd = tr.accel_bound() as f64;
        let end = (tr.route().length() / 0.4 + 30.0) as u64 * 100;
        let mut worst = 0.0f64;
        for k in 0..end {
            let d = tr.sample(k, 100);
            let a: f64 = d
                .eta_ddot
                .iter()
                .map(|x| (*x as f64).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(a);
        }
        assert!(
            worst > 0.0 && worst <= kd,
            "{name}: ‖η̈_d‖ {worst} vs K_d {kd}"
        );
        for k in [0, 1, u64::MAX / 3, u64::MAX] {
            let d = tr.sample(k, 100);
            assert!(
                d.eta.iter().chain(d.eta_dot.iter()).all(|x| x.is_finite()),
                "{name}"
            );
        }
    }
}

fn refusal(points: &[[f32; 3]], speed: f32, turn_radius: Option<f32>) -> TrajectoryError {
    Trajectory::new(kind(points, speed, turn_radius)).expect_err("refused")
}

#[test]
fn what_cannot_be_flown_is_refused_with_its_reason() {
    let a = [0.0, 0.0, 5.0];
    let b = [50.0, 0.0, 5.0];
    // Repeated point.
    assert_eq!(
        refusal(&[a, b, b, [50.0, 50.0, 5.0]], 0.5, None),
        TrajectoryError::RepeatedWaypoint { index: 2 }
    );
    // A turn sharper than the limit: 150° at b.
    let back = [50.0 - 50.0 * 0.866, 25.0, 5.0];
    match refusal(&[a, b, back], 0.5, Some(1.0)) {
        TrajectoryError::TurnTooSharp { index: 1, degrees } => {
            assert!((degrees - 150.0).abs() < 0.1 && degrees > MAX_TURN_DEGREES)
        }
        e => panic!("{e:?}"),
    }
    // A 90° turn whose cut (2.65 R) does not fit a 10 m leg at R = 5 m.
    match refusal(&[a, b, [50.0, 10.0, 5.0], [0.0, 10.0, 5.0]], 0.5, Some(5.0)) {
        TrajectoryError::LegTooShort { leg: 1, needs, has } => {
            assert!((has - 10.0).abs() < 1e-4);
            let cut = 5.0 * 15.0 / 8.0 * (0.5f32).sqrt() / 0.5;
            assert!((needs - 2.0 * cut).abs() < 1e-3, "{needs}");
        }
        e => panic!("{e:?}"),
    }
    // Too steep a leg.
    assert!(matches!(
        refusal(&[a, [5.0, 0.0, 20.0]], 0.5, None),
        TrajectoryError::TooSteep { leg: 0, .. }
    ));
    // Too few points, too many points.
    assert_eq!(
        refusal(&[a], 0.5, None),
        TrajectoryError::WaypointCount { count: 1 }
    );
    let many: Vec<[f32; 3]> = (0..=MAX_WAYPOINTS).map(|i| [i as f32, 0.0, 0.0]).collect();
    assert_eq!(
        WaypointList::new(&many),
        Err(TrajectoryError::WaypointCount {
            count: MAX_WAYPOINTS + 1
        })
    );
    // MAX_WAYPOINTS is accepted (a zig-zag of gentle turns).
    let zigzag: Vec<[f32; 3]> = (0..MAX_WAYPOINTS)
        .map(|i| [30.0 * i as f32, if i % 2 == 0 { 0.0 } else { 5.0 }, 5.0])
        .collect();
    assert!(Trajectory::new(kind(&zigzag, 0.3, None)).is_ok());
    // Non-finite, non-positive speed, and every waypoint error names `points`.
    let nan = refusal(&[a, [f32::NAN, 0.0, 5.0]], 0.5, None);
    assert!(
        matches!(nan, TrajectoryError::PointNotFinite { index: 1, axis: 0 }),
        "{nan:?}"
    );
    assert_eq!(nan.parameter(), "points");
    assert_eq!(refusal(&[a, b], 0.0, None).parameter(), "speed");
    assert_eq!(refusal(&[a, b], 0.5, Some(-1.0)).parameter(), "turn_radius");
    assert_eq!(refusal(&[a, b, b], 0.5, None).parameter(), "points");
    // The messages say what to change.
    let msg = refusal(&[a, b, [50.0, 10.0, 5.0], [0.0, 10.0, 5.0]], 0.5, Some(5.0)).to_string();
    assert!(
        msg.contains("leg 1") && msg.contains("turn_radius"),
        "{msg}"
    );
}

/// The default turn radius is speed²/0.1 m/s² (at least 1 m); the paper heading of a waypoint
/// path is its course, as the tangent heading.
#[test]
fn default_radius_and_heading() {
    assert_eq!(controller_core::trajectory::turn_radius(0.5, None), 2.5);
    assert_eq!(controller_core::trajectory::turn_radius(0.2, None), 1.0);
    assert_eq!(
        controller_core::trajectory::turn_radius(0.5, Some(7.0)),
        7.0
    );
    let k = kind(&survey(), 0.5, None);
    let paper = Trajectory::new(k).expect("valid");
    let tan = tangent(&survey(), 0.5, None);
    for t in [0, 12345, 99999, 300000] {
        assert_eq!(paper.sample(t, 100), tan.sample(t, 100));
    }
}

// ---------------------------------------------------------------------------------------------
// The time law: a speed per leg and turn.

/// The survey with fast legs and slow turns: 21 parts (11 legs, 10 turns).
fn profiled(speeds: &[f32], speed_change: Option<f32>) -> Result<Trajectory, TrajectoryError> {
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        ..
    } = kind(&survey(), 0.5, None)
    else {
        unreachable!()
    };
    Trajectory::new(Mission {
        path: TrajectoryKind::Waypoints {
            points,
            speed,
            turn_radius,
            speeds: Some(controller_core::trajectory::SpeedList::new(speeds).expect("≤ 61")),
            speed_change,
        },
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    })
}

fn survey_speeds() -> Vec<f32> {
    // Long legs fast, the 20 m legs between two turns and the turns slow.
    (0..21)
        .map(|p| match p {
            p if p % 2 == 1 => 0.3,
            p if (p / 2) % 2 == 0 => 0.9,
            _ => 0.3,
        })
        .collect()
}

/// With a time law: η̇_d, η̈_d, ψ̇_d, ψ̈_d against central differences, K_d holds, the speed on
/// each cruise is the part's, and the path's end is reached at the law's duration.
#[test]
fn a_time_law_is_smooth_and_flies_each_part_at_its_speed() {
    const RATE: u32 = 1000;
    let tr = profiled(&survey_speeds(), Some(0.05)).expect("valid");
    let law = tr.time_law();
    assert!(law.is_set());
    let end = law.duration() as f64;
    let (h, dt) = (20u64, 0.04);
    let mut worst = [0.0f64; 4];
    let mut jump = 0.0f64;
    let kd = tr.accel_bound() as f64;
    let mut peak_acc = 0.0f64;
    for k in (h..((end + 30.0) * RATE as f64) as u64).step_by(499) {
        let (lo, mid, hi) = (
            tr.sample(k - h, RATE),
            tr.sample(k, RATE),
            tr.sample(k + h, RATE),
        );
        for (n, c) in [0usize, 1].into_iter().enumerate() {
            let fd_v = (hi.eta[c] as f64 - lo.eta[c] as f64) / dt;
            let fd_a = (hi.eta_dot[c] as f64 - lo.eta_dot[c] as f64) / dt;
            worst[n] = worst[n].max((fd_v - mid.eta_dot[c] as f64).abs());
            worst[2 + n] = worst[2 + n].max((fd_a - mid.eta_ddot[c] as f64).abs());
        }
        let next = tr.sample(k + 1, RATE);
        for c in [0, 1, 5] {
            jump = jump.max((next.eta_ddot[c] - mid.eta_ddot[c]).abs() as f64);
        }
        let a: f64 = mid
            .eta_ddot
            .iter()
            .map(|x| (*x as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        peak_acc = peak_acc.max(a);
    }
    assert!(worst.iter().all(|&w| w < 3e-3), "{worst:?}");
    // σ̈ continuous: η̈ moves by little in one 1 ms tick (a step in σ̈ of A = 0.05 would show).
    assert!(jump < 5e-3, "η̈ jumps by {jump} in a tick");
    assert!(peak_acc <= kd, "‖η̈‖ {peak_acc} > K_d {kd}");
    // The end: the last waypoint at the law's duration.
    let d = tr.sample((end * RATE as f64).round() as u64, RATE);
    assert!(
        (d.eta[0] - 0.0).abs() < 2e-3 && (d.eta[1] - 100.0).abs() < 2e-3,
        "{:?}",
        d.eta
    );
    // Mid-leg 0 (100 m along it) at 0.9 m/s, mid-turn 1 at 0.3·cos 45° m/s.
    let route = tr.route();
    let speed_at = |sigma: f64| {
        // The first time the path reaches σ, found by sampling (independent of the pieces).
        let mut k = 0u64;
        loop {
            let s = tr.sample(k, 100);
            let p = route.at(sigma as f32).p;
            if ((s.eta[0] - p[0]).powi(2) + (s.eta[1] - p[1]).powi(2)).sqrt() < 0.01 {
                return (s.eta_dot[0].powi(2) + s.eta_dot[1].powi(2)).sqrt();
            }
            k += 1;
            assert!(k < 400_000, "σ = {sigma} never reached");
        }
    };
    assert!((speed_at(100.0) - 0.9).abs() < 1e-3);
    let turn_mid = route.segment_start(1) as f64 + route.cut(1) as f64;
    assert!((speed_at(turn_mid) - 0.3 * 0.5f32.sqrt()).abs() < 2e-3);
    // The duration: at least Σ length/speed over the parts (instant changes), at most that plus
    // one change's duration, (15/8)·0.6/0.05 = 22.5 s, per change (ten of them).
    let instant: f64 = (0..route.segment_count())
        .map(|i| route.segment_length(i) as f64 / survey_speeds()[route.segment_part(i)] as f64)
        .sum();
    assert!(
        end >= instant && end <= instant + 10.0 * 22.5,
        "{end} vs {instant}"
    );
}

#[test]
fn a_time_law_that_cannot_be_flown_is_refused() {
    let mut speeds = survey_speeds();
    speeds.pop();
    assert_eq!(
        profiled(&speeds, None).expect_err("20 of 21"),
        TrajectoryError::SpeedCount {
            count: 20,
            expected: 21
        }
    );
    // The 6.7 m leg between two turns (part 2) at 2 m/s, turns at 0.3: the changes need more.
    let mut speeds = survey_speeds();
    speeds[2] = 2.0;
    match profiled(&speeds, Some(0.05)).expect_err("too short") {
        TrajectoryError::SpeedChangeTooLong {
            part: 2,
            needs,
            has,
        } => {
            assert!(
                needs > has && (has - (20.0 - 2.0 * 6.629)).abs() < 0.01,
                "{needs} {has}"
            )
        }
        e => panic!("{e:?}"),
    }
    assert_eq!(
        profiled(&survey_speeds(), Some(0.0))
            .expect_err("A = 0")
            .parameter(),
        "speed_change"
    );
    let mut speeds = survey_speeds();
    speeds[3] = -1.0;
    assert_eq!(
        profiled(&speeds, None).expect_err("v < 0").parameter(),
        "speeds"
    );
}
