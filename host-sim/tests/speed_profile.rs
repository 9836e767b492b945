//! The speed profile of a waypoint mission (docs/design.md §27): `check`'s proposal beats the
//! uniform time scale, and flown as pinned it stays within the real vehicle's bound.

use controller_core::trajectory::SpeedList;
use controller_core::TrajectoryKind;
use host_sim::scenario::real_vehicle;
use host_sim::sim::{self, bound};
use host_sim::studies::preflight::profile;
use host_sim::studies::preflight::DEFAULT_MARGIN;

/// The shipped survey's vehicle on a short path: a 90 m leg, a 90° turn, a 20 m leg, a 90° turn,
/// a 90 m leg back (constant speed 0.5 m/s; five parts... three legs and two turns).
fn short_survey() -> host_sim::scenario::Scenario {
    let base = real_vehicle::waypoint_scenarios().unwrap().remove(0);
    base.with(|c| {
        let points = controller_core::WaypointList::new(&[
            [0.0, 0.0, 5.0],
            [90.0, 0.0, 5.0],
            [90.0, 20.0, 5.0],
            [0.0, 20.0, 5.0],
        ])
        .unwrap();
        c.trajectory = TrajectoryKind::Waypoints {
            points,
            speed: 0.5,
            turn_radius: None,
            speeds: None,
            speed_change: None,
        };
        c.duration = 400.0;
    })
    .unwrap()
}

#[test]
fn the_profile_beats_the_uniform_scale_and_flies_within_the_bound() {
    let s = short_survey();
    let p = profile::propose(&s, DEFAULT_MARGIN)
        .unwrap()
        .expect("a waypoint mission");
    assert_eq!(p.speeds.len(), 5);
    // Legs faster than turns, and faster than the slowest part (the uniform speed).
    assert!(
        p.speeds[0] > p.speeds[1] && p.speeds[4] > p.speeds[3],
        "{:?}",
        p.speeds
    );
    assert!(p.total_time < p.uniform_time, "{p:?}");
    // The times add up to the total (each part's from the flown law).
    let sum: f64 = p.parts.iter().map(|t| t.time).sum();
    assert!(
        (sum - p.total_time).abs() < 1e-3 * p.total_time,
        "{sum} vs {}",
        p.total_time
    );
    // Flown as pinned: within the real vehicle's bound.
    let speeds: Vec<f32> = p.speeds.iter().map(|&v| v as f32).collect();
    let pinned = s
        .with(|c| {
            if let TrajectoryKind::Waypoints {
                speeds: ref mut sp,
                speed_change: ref mut a,
                ..
            } = c.trajectory
            {
                *sp = Some(SpeedList::new(&speeds).unwrap());
                *a = Some(p.speed_change as f32);
            }
            c.duration = p.total_time;
        })
        .unwrap();
    let run = sim::run(&pinned);
    assert!(bound::within_bound(&run), "{:?}", run.metrics);
    assert!(!run.missed(), "{}", run.outcome);
}
