//! The missions a torpedo vehicle flies (docs/missions.md#heading): the tangent heading
//! ψ_d = atan2(ẏ_d, ẋ_d) and the time scale η_d(t/k), on every kind of path.
//!
//! Every expected value is independent of `trajectory.rs`: finite differences of the sampled
//! η_d over whole missions, the paths' derivatives written here in f64 from the paper's
//! formulas (so the course and its derivatives are computed here, not by the module), the
//! unscaled mission sampled at t/k, and the closed-form minimum speeds checked against a
//! dense sampling.

use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower};
use controller_core::trajectory::{
    HeadingMode, Mission, Trajectory, TrajectoryError, TrajectoryKind,
};
use std::f64::consts::{PI, TAU};

const MICROMATH: bool = cfg!(feature = "micromath");

fn wrap(x: f64) -> f64 {
    let r = x - TAU * ((x + PI) / TAU).floor();
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

fn paths() -> Vec<(&'static str, TrajectoryKind)> {
    vec![
        (
            "circle-10",
            TrajectoryKind::Circle(Circle {
                radius: 10.0,
                omega: 0.1,
                depth: 5.0,
            }),
        ),
        (
            "figure-eight-20",
            TrajectoryKind::FigureEight(FigureEight {
                amplitude: 20.0,
                omega: 0.1,
                depth: 5.0,
            }),
        ),
        (
            "lawn-mower-1",
            TrajectoryKind::LawnMower(LawnMower {
                scale: 1.0,
                omega: 0.05,
                depth: 5.0,
            }),
        ),
        (
            "lawn-mower-fast",
            TrajectoryKind::LawnMower(LawnMower {
                scale: 0.5,
                omega: 0.12,
                depth: 5.0,
            }),
        ),
        (
            "helix",
            TrajectoryKind::Helix(Helix {
                radius: 15.0,
                omega: 0.1,
                depth: 5.0,
                depth_rate: 0.1,
            }),
        ),
    ]
}

fn missions() -> Vec<(String, Mission)> {
    let mut v = Vec::new();
    for (name, path) in paths() {
        for heading in HeadingMode::ALL {
            for k in [1.0f32, 2.5, 4.0] {
                v.push((
                    format!("{name} {heading} k={k}"),
                    Mission {
                        path,
                        heading,
                        time_scale: k,
                    },
                ));
            }
        }
    }
    v
}

/// The path's (x, y, z) and first three derivatives of x and y at time t of the *unscaled*
/// path, written here from the paper's formulas in f64: [[x, ẋ, ẍ, x⃛], [y, …]], z, ż.
fn path_f64(kind: TrajectoryKind, t: f64) -> ([[f64; 4]; 2], f64, f64) {
    match kind {
        TrajectoryKind::Circle(Circle {
            radius,
            omega,
            depth,
        })
        | TrajectoryKind::Helix(Helix {
            radius,
            omega,
            depth,
            ..
        }) => {
            let (r, w) = (radius as f64, omega as f64);
            let (s, c) = (w * t).sin_cos();
            let rate = match kind {
                TrajectoryKind::Helix(Helix { depth_rate, .. }) => depth_rate as f64,
                _ => 0.0,
            };
            (
                [
                    [r * s, r * w * c, -r * w * w * s, -r * w * w * w * c],
                    [r * c, -r * w * s, -r * w * w * c, r * w * w * w * s],
                ],
                depth as f64 + rate * t,
                rate,
            )
        }
        TrajectoryKind::FigureEight(FigureEight {
            amplitude,
            omega,
            depth,
        }) => {
            let (a, w) = (amplitude as f64, omega as f64);
            let h = 0.5 * w;
            let (s, c) = (w * t).sin_cos();
            let (sh, ch) = (h * t).sin_cos();
            (
                [
                    [a * s, a * w * c, -a * w * w * s, -a * w * w * w * c],
                    [a * ch, -a * h * sh, -a * h * h * ch, a * h * h * h * sh],
                ],
                depth as f64,
                0.0,
            )
        }
        TrajectoryKind::LawnMower(LawnMower {
            scale,
            omega,
            depth,
        }) => {
            let (sc, w) = (scale as f64, omega as f64);
            let w2 = 2.0 * w;
            let (s2, c2) = (w2 * t).sin_cos();
            let (s1, c1) = (w * t).sin_cos();
            let ay = 15.0 * sc;
            (
                [
                    [
                        sc * (0.25 * t + 2.5 * s2),
                        sc * (0.25 + 2.5 * w2 * c2),
                        -2.5 * sc * w2 * w2 * s2,
                        -2.5 * sc * w2 * w2 * w2 * c2,
                    ],
                    [ay * c1, -ay * w * s1, -ay * w * w * c1, ay * w * w * w * s1],
                ],
                depth as f64,
                0.0,
            )
        }
        TrajectoryKind::Waypoints { .. } => {
            unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
        }
    }
}

/// The tangent heading of the unscaled path, from `path_f64`: (ψ, ψ̇, ψ̈) by the formulas of
/// docs/missions.md#heading, evaluated here.
fn course_f64(kind: TrajectoryKind, t: f64) -> (f64, f64, f64) {
    let ([[_, xd, xdd, xddd], [_, yd, ydd, yddd]], _, _) = path_f64(kind, t);
    let d = xd * xd + yd * yd;
    let n = xd * ydd - yd * xdd;
    let n_dot = xd * yddd - yd * xddd;
    let d_dot = 2.0 * (xd * xdd + yd * ydd);
    (yd.atan2(xd), n / d, (n_dot * d - n * d_dot) / (d * d))
}

fn base_omega(kind: TrajectoryKind) -> f64 {
    match kind {
        TrajectoryKind::Circle(Circle { omega, .. })
        | TrajectoryKind::Helix(Helix { omega, .. })
        | TrajectoryKind::FigureEight(FigureEight { omega, .. })
        | TrajectoryKind::LawnMower(LawnMower { omega, .. }) => omega as f64,
        TrajectoryKind::Waypoints { .. } => {
            unreachable!("the closed-form kinds only (waypoints: tests/waypoints.rs)")
        }
    }
}

/// One period of the path (s, unscaled): the figure-eight's y has half the frequency.
fn period(kind: TrajectoryKind) -> f64 {
    match kind {
        TrajectoryKind::FigureEight(FigureEight { omega, .. }) => 4.0 * PI / omega as f64,
        _ => TAU / base_omega(kind),
    }
}

/// Samples at 1 kHz over one whole period of the scaled mission.
const RATE: u32 = 1000;

/// η_d against the unscaled path sampled at t/k, over a whole period: positions equal,
/// velocities over k, accelerations over k²; the tangent heading equal to the course
/// computed here.
#[test]
fn time_scale_and_tangent_heading_match_the_path_at_t_over_k() {
    // libm: f32 rounding of values ~20 m and of the phase; micromath: its 1e-3 sin/cos.
    let (pos_tol, ang_tol) = if MICROMATH {
        (8e-2, 2e-2)
    } else {
        (2e-4, 2e-4)
    };
    for (name, m) in missions() {
        let tr = Trajectory::new(m).unwrap_or_else(|e| panic!("{name}: {e}"));
        let k = m.time_scale as f64;
        let span = (period(m.path) * k * RATE as f64) as u64;
        let mut worst = [0.0f64; 3];
        for tick in (0..span).step_by(97) {
            let t = tick as f64 / RATE as f64;
            let d = tr.sample(tick, RATE);
            let (p, z, z_dot) = path_f64(m.path, t / k);
            for (i, pi) in p.iter().enumerate() {
                let e0 = (d.eta[i] as f64 - pi[0]).abs();
                let e1 = (d.eta_dot[i] as f64 - pi[1] / k).abs();
                let e2 = (d.eta_ddot[i] as f64 - pi[2] / (k * k)).abs();
                assert!(
                    e0 <= pos_tol * (1.0 + pi[0].abs()),
                    "{name} t={t}: η[{i}] {} vs {}",
                    d.eta[i],
                    pi[0]
                );
                assert!(
                    e1 <= pos_tol,
                    "{name} t={t}: η̇[{i}] {} vs {}",
                    d.eta_dot[i],
                    pi[1] / k
                );
                assert!(
                    e2 <= pos_tol,
                    "{name} t={t}: η̈[{i}] {} vs {}",
                    d.eta_ddot[i],
                    pi[2] / (k * k)
                );
                worst[0] = worst[0].max(e0);
            }
            assert!(
                (d.eta[2] as f64 - z).abs() <= pos_tol * (1.0 + z.abs()),
                "{name} t={t}: z"
            );
            assert!(
                (d.eta_dot[2] as f64 - z_dot / k).abs() <= 1e-7,
                "{name} t={t}: ż"
            );
            if m.heading == HeadingMode::Tangent {
                let (psi, rate, accel) = course_f64(m.path, t / k);
                let ep = wrap(d.eta[5] as f64 - psi).abs();
                let er = (d.eta_dot[5] as f64 - rate / k).abs();
                let ea = (d.eta_ddot[5] as f64 - accel / (k * k)).abs();
                // The heading's derivatives scale with the path's turn rate: relative to ω.
                let w = base_omega(m.path) / k;
                assert!(ep <= ang_tol, "{name} t={t}: ψ {} vs {psi}", d.eta[5]);
                assert!(
                    er <= ang_tol * w * 10.0,
                    "{name} t={t}: ψ̇ {} vs {}",
                    d.eta_dot[5],
                    rate / k
                );
                assert!(
                    ea <= ang_tol * w * w * 100.0,
                    "{name} t={t}: ψ̈ {} vs {}",
                    d.eta_ddot[5],
                    accel / (k * k)
                );
                worst[1] = worst[1].max(ep);
                worst[2] = worst[2].max(ea);
            }
        }
        eprintln!(
            "{name}: worst position {:.1e} m, ψ {:.1e} rad, ψ̈ {:.1e} rad/s²",
            worst[0], worst[1], worst[2]
        );
    }
}

/// ψ̇_d and ψ̈_d (and every other derivative) against central finite differences of the
/// sampled mission, every 0.25 s (scaled) over a whole period.
#[test]
fn derivatives_match_finite_differences_over_whole_missions() {
    const FD_RATE: u32 = 1_000_000;
    let rel = if MICROMATH { 4e-2 } else { 2e-3 };
    for (name, m) in missions() {
        let tr = Trajectory::new(m).unwrap();
        let k = m.time_scale as f64;
        // h·(ω/k) = 0.002.
        let h = (0.002 * k / base_omega(m.path) * FD_RATE as f64).round() as u64;
        let two_h = 2.0 * h as f64 / FD_RATE as f64;
        let span = period(m.path) * k;
        let mut rows = Vec::new();
        let mut t = 0.25 + two_h;
        while t < span {
            let tick = (t * FD_RATE as f64).round() as u64;
            let lo = tr.sample(tick - h, FD_RATE);
            let mid = tr.sample(tick, FD_RATE);
            let hi = tr.sample(tick + h, FD_RATE);
            let d1: [f64; 6] = std::array::from_fn(|i| {
                let d = hi.eta[i] as f64 - lo.eta[i] as f64;
                (if i == 5 { wrap(d) } else { d }) / two_h
            });
            let d2: [f64; 6] =
                std::array::from_fn(|i| (hi.eta_dot[i] as f64 - lo.eta_dot[i] as f64) / two_h);
            rows.push((t, mid, d1, d2));
            t += 0.25 * k;
        }
        for c in [0usize, 1, 2, 5] {
            let peak1 = rows.iter().map(|r| r.2[c].abs()).fold(0.0, f64::max);
            let peak2 = rows.iter().map(|r| r.3[c].abs()).fold(0.0, f64::max);
            for (t, mid, d1, d2) in &rows {
                let e1 = (mid.eta_dot[c] as f64 - d1[c]).abs();
                let e2 = (mid.eta_ddot[c] as f64 - d2[c]).abs();
                // Under micromath, ψ_d itself is micromath's atan2, whose error (a few mrad,
                // not smooth) makes its difference quotient over 2h no derivative of anything;
                // ψ̇_d is checked against the f64 course in
                // `time_scale_and_tangent_heading_match_the_path_at_t_over_k`, and ψ̈_d here.
                let heading_from_micromath_atan2 = MICROMATH && c == 5;
                assert!(
                    heading_from_micromath_atan2 || e1 <= rel * peak1 + 1e-6,
                    "{name} t={t} [{c}]: η̇ {} vs fd {}",
                    mid.eta_dot[c],
                    d1[c]
                );
                assert!(
                    e2 <= rel * peak2 + 1e-6,
                    "{name} t={t} [{c}]: η̈ {} vs fd {}",
                    mid.eta_ddot[c],
                    d2[c]
                );
            }
        }
    }
}

/// K_d (Assumption 1) bounds ‖η̈_d‖ over whole missions at the control rate, also with the
/// tangent heading's sampled term and the time scale, and is not wildly loose.
#[test]
fn accel_bound_holds_for_tangent_and_scaled_missions() {
    for (name, m) in missions() {
        let tr = Trajectory::new(m).unwrap();
        let span = (period(m.path) * m.time_scale as f64 * 1000.0) as u64;
        let mut peak = 0.0f64;
        for tick in 0..span {
            let a = tr.sample(tick, 1000).eta_ddot;
            peak = peak.max(a.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt());
        }
        let bound = tr.accel_bound() as f64;
        eprintln!("{name}: max ‖η̈_d‖ = {peak:.5}, K_d = {bound:.5}");
        assert!(bound >= peak, "{name}: K_d {bound} < sampled max {peak}");
        assert!(bound <= 3.0 * peak, "{name}: K_d {bound} > 3 × {peak}");
        // K_d falls with 1/k² (every term is an acceleration).
        if m.time_scale > 1.0 {
            let one = Trajectory::new(Mission {
                time_scale: 1.0,
                ..m
            })
            .unwrap()
            .accel_bound() as f64;
            let k2 = (m.time_scale as f64).powi(2);
            assert!(
                (bound * k2 / one - 1.0).abs() < 1e-3,
                "{name}: K_d·k² {} vs {one}",
                bound * k2
            );
        }
    }
}

/// The closed-form minimum horizontal speed against a dense sampling of the mission.
#[test]
fn minimum_speed_in_closed_form() {
    for (name, m) in missions() {
        let tr = Trajectory::new(m).unwrap();
        let span = (period(m.path) * m.time_scale as f64 * 1000.0) as u64;
        let mut min = f64::INFINITY;
        for tick in (0..span).step_by(7) {
            let v = tr.sample(tick, 1000).eta_dot;
            min = min.min((v[0] as f64).hypot(v[1] as f64));
        }
        let closed = tr.min_speed() as f64;
        let tol = if MICROMATH { 5e-2 } else { 1e-3 };
        assert!(
            closed <= min * (1.0 + tol),
            "{name}: closed form {closed} > sampled {min}"
        );
        assert!(
            closed >= min * (1.0 - tol),
            "{name}: closed form {closed} ≪ sampled {min}"
        );
    }
    // The figure-eight's is Aω√31/16.
    let f8 = Trajectory::new(paths()[1].1).unwrap();
    assert!((f8.min_speed() as f64 - 20.0 * 0.1 * 31f64.sqrt() / 16.0).abs() < 1e-5);
}

#[test]
fn circle_course_turns_at_minus_omega_over_k() {
    let m = Mission {
        path: paths()[0].1,
        heading: HeadingMode::Tangent,
        time_scale: 2.0,
    };
    let tr = Trajectory::new(m).unwrap();
    for tick in [0u64, 1234, 99_999] {
        let d = tr.sample(tick, 100);
        assert!((d.eta_dot[5] + 0.05).abs() < 1e-6, "{}", d.eta_dot[5]);
        assert!(d.eta_ddot[5].abs() < 1e-6);
        // The course at t = 0 is north (the circle starts at (0, R) moving along +x).
    }
    assert!(tr.sample(0, 100).eta[5].abs() < 1e-6);
}

#[test]
fn refusals_name_the_field() {
    let path = paths()[2].1;
    for (k, want) in [
        (0.5f32, "time_scale"),
        (f32::NAN, "time_scale"),
        (101.0, "time_scale"),
    ] {
        let err = Trajectory::new(Mission {
            path,
            heading: HeadingMode::Paper,
            time_scale: k,
        })
        .expect_err("invalid time scale");
        assert_eq!(err.parameter(), want, "{k}: {err}");
    }
    // The paper's lawn-mower (s = 1) slows to 0.5 m/s; at k = 30 that is 0.0167 m/s, below the
    // 0.02 m/s a tangent heading needs, while the paper's heading flies it.
    let slow = Mission {
        path,
        heading: HeadingMode::Tangent,
        time_scale: 30.0,
    };
    let err = Trajectory::new(slow).expect_err("too slow for a course");
    assert_eq!(err.parameter(), "heading");
    match err {
        TrajectoryError::TooSlowForTangent {
            min_speed,
            threshold,
        } => {
            assert!((min_speed - 0.5 / 30.0).abs() < 1e-4, "{min_speed}");
            assert_eq!(threshold, Trajectory::MIN_TANGENT_SPEED);
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("tangent heading"), "{err}");
    assert!(Trajectory::new(Mission {
        heading: HeadingMode::Paper,
        ..slow
    })
    .is_ok());
    assert!(Trajectory::new(Mission {
        time_scale: 20.0,
        ..slow
    })
    .is_ok());
    assert_eq!(
        HeadingMode::from_name("tangent"),
        Some(HeadingMode::Tangent)
    );
    assert_eq!(HeadingMode::default().as_str(), "paper");
}
