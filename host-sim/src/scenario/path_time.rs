//! When a waypoint mission's reference passes its waypoints (docs/missions.md#the-run-and-the-path,
//! Choices 311–312): the time to the last waypoint is a waypoint mission's default `duration`,
//! and a run that ends before it (or long after it) says so.

use controller_core::readable::Readable;
use controller_core::{Trajectory, TrajectoryKind};

use super::validate::{invalid, MAX_DURATION};
use super::ScenarioError;

/// How far from the path's end (s) a run's end still counts as the end of the path: half the
/// tenth of a second to which `check` rounds the `duration` it pins (Choice 312).
pub const PATH_END_TOLERANCE: f64 = 0.05;

/// The times (s, at the trajectory's time scale) at which a waypoint mission's reference passes
/// each waypoint nearest ([`Route::passing`](controller_core::trajectory::Route::passing)):
/// the first at 0, the last at the path's end. Empty for the other kinds.
pub fn waypoint_times(trajectory: &Trajectory) -> Vec<f64> {
    let TrajectoryKind::Waypoints { speed, .. } = trajectory.kind() else {
        return Vec::new();
    };
    let (route, law) = (trajectory.route(), trajectory.time_law());
    let k = f64::from(trajectory.mission().time_scale);
    (0..route.waypoint_count())
        .map(|i| {
            let sigma = route.passing(i);
            let t = match law.is_set() {
                true => f64::from(law.time_at(route, sigma)),
                false => f64::from(sigma) / f64::from(speed),
            };
            t * k
        })
        .collect()
}

/// The time (s, at the trajectory's time scale) at which a waypoint mission's reference reaches
/// its last waypoint; `None` for the other kinds.
pub fn path_time(trajectory: &Trajectory) -> Option<f64> {
    waypoint_times(trajectory).last().copied()
}

/// The key that sets how long a waypoint path takes: `trajectory.speeds` with a time law,
/// else `trajectory.speed`.
fn pace_key(trajectory: &Trajectory) -> &'static str {
    match trajectory.time_law().is_set() {
        true => "trajectory.speeds",
        false => "trajectory.speed",
    }
}

/// A waypoint mission's default `duration` (Choice 312): its path's time, refused under the
/// key that sets the pace when it is longer than a run may be ([`MAX_DURATION`]).
pub(super) fn default_duration(trajectory: &Trajectory) -> Result<Option<f64>, ScenarioError> {
    let Some(t) = path_time(trajectory) else {
        return Ok(None);
    };
    if t > MAX_DURATION {
        return Err(too_long(trajectory, t, "the run's default duration"));
    }
    Ok(Some(t))
}

/// Refusal of a path that takes `time` s, longer than [`MAX_DURATION`], for `what`.
pub fn too_long(trajectory: &Trajectory, time: f64, what: &str) -> ScenarioError {
    invalid(
        pace_key(trajectory),
        format!(
            "the path takes {} s to its last waypoint ({what}), longer than the one day \
             ({MAX_DURATION} s) a run may last: fly it faster or split it into missions",
            Readable(time)
        ),
    )
}

/// What a run that ends at `run_end` (s) did to its waypoint path, when its end is not the
/// path's (beyond [`PATH_END_TOLERANCE`]): the waypoints it never reached, or how long before
/// it the path ended (the reference then goes on straight along the last leg). `None` when the
/// two ends meet, and for the other kinds (Choice 312).
pub fn run_note(trajectory: &Trajectory, run_end: f64) -> Option<String> {
    let times = waypoint_times(trajectory);
    let &last = times.last()?;
    if run_end < last - PATH_END_TOLERANCE {
        let missed: Vec<String> = times
            .iter()
            .enumerate()
            .filter(|(_, &t)| t > run_end + PATH_END_TOLERANCE)
            .map(|(i, _)| i.to_string())
            .collect();
        let which = match missed.len() {
            1 => format!("waypoint {} never reached", missed[0]),
            _ => format!("waypoints {} never reached", missed.join(", ")),
        };
        Some(format!(
            "the run ended at {run_end:.1} s, before its path (at {last:.1} s): {which}"
        ))
    } else if run_end > last + PATH_END_TOLERANCE {
        Some(format!(
            "the path ended at its last waypoint at {last:.1} s, {:.1} s before the run: the \
             reference went on straight past it",
            run_end - last
        ))
    } else {
        None
    }
}
