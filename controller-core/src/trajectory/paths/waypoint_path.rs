//! The waypoint path as a [`PathKind`] (docs/missions.md#waypoint-paths): the fields of a
//! [`TrajectoryKind::Waypoints`](crate::TrajectoryKind::Waypoints), borrowed, checked and built
//! into the trajectory's route and time law in place, and flown along them.

use super::kind::PathKind;
use super::time_law::{self, SpeedList, TimeLaw};
use super::waypoints::{self, turn_radius, Route, WaypointList};
use crate::trajectory::error::{positive, Parameter, TrajectoryError};
use crate::trajectory::limits::{
    DEFAULT_SPEED_CHANGE, MAX_SPEED, MAX_SPEED_CHANGE, MIN_TURN_RADIUS,
};
use crate::trajectory::phases::{tangent, Harmonics, Phases, Planar};
use crate::trajectory::{Trajectory, TrajectoryKind};

/// `speed` as written (an f64) narrowed to the f32 it flies as, refused when an f32 cannot
/// hold it (Choice 315): 1e39 is not "not finite", 1e-300 is not 0.
#[cfg(feature = "serde")]
pub(crate) fn narrow_speed<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    narrow("speed", <f64 as serde::Deserialize>::deserialize(d)?)
}

/// `turn_radius` as [`narrow_speed`] reads `speed`.
#[cfg(feature = "serde")]
pub(crate) fn narrow_turn_radius<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<f32>, D::Error> {
    narrow_option("turn_radius", d)
}

/// `speed_change` as [`narrow_speed`] reads `speed`.
#[cfg(feature = "serde")]
pub(crate) fn narrow_speed_change<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<f32>, D::Error> {
    narrow_option("speed_change", d)
}

#[cfg(feature = "serde")]
fn narrow_option<'de, D: serde::Deserializer<'de>>(
    key: &str,
    d: D,
) -> Result<Option<f32>, D::Error> {
    match <Option<f64> as serde::Deserialize>::deserialize(d)? {
        Some(v) => narrow(key, v).map(Some),
        None => Ok(None),
    }
}

#[cfg(feature = "serde")]
fn narrow<E: serde::de::Error>(key: &str, v: f64) -> Result<f32, E> {
    let n = v as f32;
    let w = crate::readable::Readable(v);
    if v.is_finite() && !n.is_finite() {
        Err(E::custom(format_args!(
            "{key} = {w} is beyond the largest f32 (3.4e38) the path is flown in"
        )))
    } else if v != 0.0 && n == 0.0 {
        Err(E::custom(format_args!(
            "{key} = {w} is below the smallest f32 (1.2e-38) the path is flown in: it would read as 0"
        )))
    } else {
        Ok(n)
    }
}

/// The fields of a [`TrajectoryKind::Waypoints`], borrowed (no copy of its lists).
#[derive(Clone, Copy)]
pub(super) struct WaypointPath<'a> {
    pub(super) points: &'a WaypointList,
    pub(super) speed: f32,
    pub(super) turn_radius: Option<f32>,
    pub(super) speeds: Option<&'a SpeedList>,
    pub(super) speed_change: Option<f32>,
}

/// The waypoint path of [`TrajectoryKind::EXAMPLES`]: three points, two legs and the 90° turn
/// between them, at 0.5 m/s.
pub(super) const EXAMPLE: TrajectoryKind = TrajectoryKind::Waypoints {
    points: WaypointList::from_array([[0.0, 10.0, 5.0], [60.0, 10.0, 5.0], [60.0, 60.0, 5.0]]),
    speed: 0.5,
    turn_radius: None,
    speeds: None,
    speed_change: None,
};

impl PathKind for WaypointPath<'_> {
    /// None: the points and the options are checked as the route is built.
    fn parameters(&mut self, _visit: &mut dyn FnMut(&Parameter, &mut f32)) {}

    /// Checks the path's parameters and builds its route and time law in place (Choice 180:
    /// validation is the build, nothing is built twice or on the stack): speed in
    /// (0, [`MAX_SPEED`]], a configured turn radius in [[`MIN_TURN_RADIUS`],
    /// [`Trajectory::MAX_SIZE`]] (Choice 310), then the
    /// points ([`Route::build_into`]), then the time law if there is one
    /// ([`TimeLaw::build_into`]; else [`TimeLaw::EMPTY`], with `speed_change` still checked if
    /// given). After an error the route and the law are unspecified but safe to sample.
    fn build_into(&self, route: &mut Route, law: &mut TimeLaw) -> Result<(), TrajectoryError> {
        positive("speed", self.speed, MAX_SPEED)?;
        if let Some(r) = self.turn_radius {
            positive("turn_radius", r, Trajectory::MAX_SIZE)?;
            // The floor a corner may have (Choice 310): every blend then turns the heading at
            // most at speed/MIN_TURN_RADIUS and lasts at least MIN_TURN_RADIUS/speed.
            if r < MIN_TURN_RADIUS {
                return Err(TrajectoryError::OutOfRange {
                    parameter: "turn_radius",
                    value: r,
                    min: MIN_TURN_RADIUS,
                    max: Trajectory::MAX_SIZE,
                });
            }
        }
        route.build_into(self.points, turn_radius(self.speed, self.turn_radius))?;
        match self.speeds {
            Some(s) => law.build_into(route, s, self.speed_change.unwrap_or(DEFAULT_SPEED_CHANGE)),
            None => {
                law.clear();
                match self.speed_change {
                    Some(a) => positive("speed_change", a, MAX_SPEED_CHANGE),
                    None => Ok(()),
                }
            }
        }
    }

    /// No angular frequency; the path speed σ̇.
    fn rates(&self) -> (f32, f32) {
        (0.0, self.speed)
    }

    /// None in closed form: its bound is its route's ([`waypoints::bounds`], in
    /// [`Trajectory`]'s precompute).
    fn accel(&self, _omega: f32) -> (f32, f32) {
        (0.0, 0.0)
    }

    /// Its route's, sampled ([`waypoints::bounds`]).
    fn min_speed(&self, t: &Trajectory) -> f32 {
        waypoints::bounds(&t.route).0 * t.rate
    }

    /// Along the route, at constant speed or by the time law. Inlined into the dispatch, so
    /// that the borrowed fields it does not read are never formed on the tick path.
    #[inline(always)]
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar {
        match t.law.is_set() {
            true => time_law::timed(&t.route, &t.law, &ph.time, &t.position_rate, t.rate),
            false => waypoints::planar(&t.route, &ph.time, &t.position_rate, t.rate),
        }
    }

    /// The waypoint path has no heading of its own in the paper: its "paper" heading is its
    /// course, as the tangent heading (Choice 154).
    #[inline(always)]
    fn paper_heading(
        &self,
        _t: &Trajectory,
        _theta: u32,
        _h: &Harmonics,
        p: &Planar,
    ) -> (f32, f32, f32) {
        tangent(p)
    }
}
