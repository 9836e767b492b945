//! Building a trajectory in place (docs/missions.md#built-in-place, Choice 180): `Trajectory::set` over
//! whatever a trajectory held gives exactly what `Trajectory::new` gives (PartialEq over every
//! field, whole arrays included, so no segment or piece of an earlier path is left behind), the
//! same error for a refused mission, and a trajectory that samples as `Trajectory::EMPTY` (the
//! origin held) after a refusal.

use controller_core::trajectory::{Circle, Helix};
use controller_core::trajectory::{
    HeadingMode, Mission, SpeedList, Table1Case, Trajectory, TrajectoryError, TrajectoryKind,
    WaypointList, MAX_WAYPOINTS,
};

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

/// [`MAX_WAYPOINTS`] points on a zig-zag of gentle turns (30 m legs, 5 m across).
fn zigzag() -> Vec<[f32; 3]> {
    (0..MAX_WAYPOINTS)
        .map(|i| [30.0 * i as f32, if i % 2 == 0 { 0.0 } else { 5.0 }, 5.0])
        .collect()
}

/// Legs at 0.4, 0.5 or 0.6 m/s by turn, every turn at 0.3 m/s: changes on both ends of a leg.
fn speeds(parts: usize) -> SpeedList {
    let v: Vec<f32> = (0..parts)
        .map(|p| match p % 2 {
            1 => 0.3,
            _ => 0.4 + 0.1 * ((p / 2) % 3) as f32,
        })
        .collect();
    SpeedList::new(&v).expect("at most MAX_PARTS speeds")
}

fn waypoints(
    points: &[[f32; 3]],
    speed: f32,
    turn_radius: Option<f32>,
    profiled: bool,
    speed_change: Option<f32>,
) -> TrajectoryKind {
    TrajectoryKind::Waypoints {
        points: WaypointList::new(points).expect("at most MAX_WAYPOINTS points"),
        speed,
        turn_radius,
        speeds: profiled.then(|| speeds(2 * points.len() - 3)),
        speed_change,
    }
}

fn mission(path: TrajectoryKind, heading: HeadingMode, time_scale: f32) -> Mission {
    Mission {
        path,
        heading,
        time_scale,
    }
}

/// Every closed-form kind in both headings and at a time scale, and waypoint paths of 2, 6, 12
/// and 32 points, with and without a time law.
fn missions() -> Vec<Mission> {
    use HeadingMode::{Paper, Tangent};
    let mut m: Vec<Mission> = Table1Case::ALL
        .iter()
        .map(|c| Mission::paper(c.kind()))
        .collect();
    m.extend([
        mission(Table1Case::Circular10R.kind(), Tangent, 2.0),
        mission(Table1Case::FigureEight30x30.kind(), Tangent, 3.0),
        mission(Table1Case::LawnMower30x15.kind(), Tangent, 1.0),
        mission(
            TrajectoryKind::Helix(Helix {
                radius: 8.0,
                omega: 0.1,
                depth: 3.0,
                depth_rate: 0.05,
            }),
            Tangent,
            1.5,
        ),
        mission(
            TrajectoryKind::Helix(Helix {
                radius: 8.0,
                omega: 0.1,
                depth: 3.0,
                depth_rate: -0.05,
            }),
            Paper,
            1.0,
        ),
        mission(
            waypoints(&zigzag(), 0.3, None, true, Some(0.05)),
            Tangent,
            1.0,
        ),
        mission(
            with_speeds(
                waypoints(&survey(), 0.5, None, false, None),
                SpeedList::new(&survey_parts()).expect("21"),
            ),
            Tangent,
            1.0,
        ),
        mission(
            waypoints(&survey(), 0.5, Some(2.0), false, Some(0.1)),
            Paper,
            2.0,
        ),
        mission(
            waypoints(
                &[
                    [0.0, 0.0, 2.0],
                    [40.0, 0.0, 2.0],
                    [70.0, 25.0, 12.0],
                    [70.0, 60.0, 12.0],
                    [30.0, 80.0, 8.0],
                    [35.0, 120.0, 8.0],
                ],
                0.8,
                Some(3.0),
                true,
                Some(0.2),
            ),
            Tangent,
            1.5,
        ),
        mission(
            waypoints(&[[0.0, 0.0, 1.0], [10.0, 5.0, 3.0]], 0.5, None, false, None),
            Tangent,
            1.0,
        ),
        mission(
            waypoints(&zigzag()[..7], 0.3, None, false, None),
            Tangent,
            4.0,
        ),
    ]);
    m
}

/// Missions refused at each stage of `set`: the path's parameters, its points, its route's
/// fit, its time law, the time scale after a full route, the tangent heading's speed.
fn refused() -> Vec<Mission> {
    use HeadingMode::{Paper, Tangent};
    let a = [0.0, 0.0, 5.0];
    let b = [50.0, 0.0, 5.0];
    let mut short = speeds(2 * survey().len() - 3);
    let mut v = short.as_slice().to_vec();
    v.pop();
    short = SpeedList::new(&v).expect("fewer");
    let mut fast = survey_parts();
    fast[2] = 2.0;
    vec![
        mission(
            TrajectoryKind::Circle(Circle {
                radius: -1.0,
                omega: 0.1,
                depth: 5.0,
            }),
            Paper,
            1.0,
        ),
        mission(Table1Case::Circular10R.kind(), Paper, 0.5),
        mission(Table1Case::Circular10R.kind(), Paper, f32::NAN),
        mission(
            TrajectoryKind::Circle(Circle {
                radius: 0.1,
                omega: 0.1,
                depth: 5.0,
            }),
            Tangent,
            1.0,
        ),
        mission(waypoints(&[a, b], 0.0, None, false, None), Tangent, 1.0),
        mission(
            waypoints(&[a, b], 0.5, Some(-1.0), false, None),
            Tangent,
            1.0,
        ),
        mission(waypoints(&[a, b, b], 0.5, None, false, None), Tangent, 1.0),
        mission(waypoints(&[a], 0.5, None, false, None), Tangent, 1.0),
        mission(
            waypoints(&[a, [f32::NAN, 0.0, 5.0]], 0.5, None, false, None),
            Tangent,
            1.0,
        ),
        mission(
            waypoints(
                &[a, b, [50.0, 10.0, 5.0], [0.0, 10.0, 5.0]],
                0.5,
                Some(5.0),
                false,
                None,
            ),
            Tangent,
            1.0,
        ),
        mission(
            waypoints(
                &[a, b, [50.0 - 43.3, 25.0, 5.0]],
                0.5,
                Some(1.0),
                false,
                None,
            ),
            Tangent,
            1.0,
        ),
        mission(
            waypoints(&[a, b], 0.5, None, false, Some(0.0)),
            Tangent,
            1.0,
        ),
        mission(
            with_speeds(waypoints(&survey(), 0.5, None, false, None), short),
            Tangent,
            1.0,
        ),
        mission(
            with_speeds(
                waypoints(&survey(), 0.5, None, false, Some(0.05)),
                SpeedList::new(&fast).expect("21"),
            ),
            Tangent,
            1.0,
        ),
        mission(waypoints(&zigzag(), 0.3, None, true, None), Tangent, 200.0),
    ]
}

/// The survey's 21 parts: long legs fast, the short legs and the turns slow.
fn survey_parts() -> Vec<f32> {
    (0..21)
        .map(|p| match p {
            p if p % 2 == 1 => 0.3,
            p if (p / 2) % 2 == 0 => 0.9,
            _ => 0.3,
        })
        .collect()
}

fn with_speeds(path: TrajectoryKind, list: SpeedList) -> TrajectoryKind {
    match path {
        TrajectoryKind::Waypoints {
            points,
            speed,
            turn_radius,
            speed_change,
            ..
        } => TrajectoryKind::Waypoints {
            points,
            speed,
            turn_radius,
            speeds: Some(list),
            speed_change,
        },
        other => other,
    }
}

/// Every mission over every other one (more points then fewer and the reverse, a time law
/// then none, a waypoint path then a closed form): field for field what `new` gives.
#[test]
fn set_over_anything_equals_a_fresh_trajectory() {
    let missions = missions();
    let fresh: Vec<Trajectory> = missions
        .iter()
        .map(|m| Trajectory::new(*m).unwrap_or_else(|e| panic!("{m:?}: {e}")))
        .collect();
    // The waypoint missions do hold different numbers of segments and pieces.
    let segments: Vec<usize> = fresh.iter().map(|t| t.route().segment_count()).collect();
    assert!(segments.contains(&61) && segments.contains(&1) && segments.contains(&0));
    for (i, m) in missions.iter().enumerate() {
        let mut t = Trajectory::EMPTY;
        t.set(m).expect("valid");
        assert!(t == fresh[i], "EMPTY then set ≠ new for {m:?}");
        for (j, before) in fresh.iter().enumerate() {
            let mut t = *before;
            t.set(m).expect("valid");
            assert!(t == fresh[i], "set of mission {i} over mission {j} ≠ new");
        }
    }
}

/// A refused `set` gives `new`'s error, over a trajectory that held anything, and leaves a
/// trajectory that samples as `EMPTY`: the origin held, every component finite.
#[test]
fn a_refused_set_gives_new_s_error_and_an_inert_trajectory() {
    let before = missions();
    for m in refused() {
        let expected: TrajectoryError = Trajectory::new(m).expect_err("refused");
        for b in &before {
            let mut t = Trajectory::new(*b).expect("valid");
            assert_eq!(t.set(&m), Err(expected), "{m:?} over {b:?}");
            assert_eq!(t.route().segment_count(), 0);
            assert!(!t.time_law().is_set());
            for ticks in [0u64, 1, 1234, 1 << 40] {
                let d = t.sample(ticks, 100);
                assert_eq!(d, Trajectory::EMPTY.sample(ticks, 100));
                for v in [d.eta, d.eta_dot, d.eta_ddot] {
                    assert!(v.iter().all(|x| *x == 0.0), "{v:?}");
                }
            }
        }
    }
}

/// `EMPTY` holds the origin at the surface: zero position, rates and accelerations, K_d = 0.
#[test]
fn empty_holds_the_origin() {
    let t = Trajectory::EMPTY;
    assert_eq!(t.accel_bound(), 0.0);
    assert_eq!(t.route().segment_count(), 0);
    for ticks in [0u64, 7, 100_000, u64::MAX] {
        for rate in [0u32, 1, 100, 1000] {
            let d = t.sample(ticks, rate);
            for v in [d.eta, d.eta_dot, d.eta_ddot] {
                assert!(v.iter().all(|x| *x == 0.0), "{v:?}");
            }
        }
    }
}
