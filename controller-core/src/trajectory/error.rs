//! Why a mission is refused ([`TrajectoryError`]), and the ranges a path kind's parameters
//! are checked against ([`Parameter`], [`ParameterRange`]).

use core::fmt;

use crate::readable::Readable;
use crate::trajectory::limits::{
    MAX_COORDINATE, MAX_SLOPE, MAX_SPEED, MAX_TURN_DEGREES, MAX_WAYPOINTS, MIN_LEG,
};

/// Why a [`TrajectoryKind`](crate::TrajectoryKind) was rejected by [`Trajectory::new`](crate::Trajectory::new).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrajectoryError {
    /// The parameter is NaN or infinite.
    NonFinite {
        /// Field name in [`TrajectoryKind`](crate::TrajectoryKind).
        parameter: &'static str,
    },
    /// A size or frequency that must be strictly positive is zero or negative.
    NotPositive {
        /// Field name in [`TrajectoryKind`](crate::TrajectoryKind).
        parameter: &'static str,
        /// The rejected value.
        value: f32,
    },
    /// The parameter lies outside [min, max] (for a positive parameter `min` is 0 and exclusive;
    /// values at or below it are reported as [`TrajectoryError::NotPositive`]).
    OutOfRange {
        /// Field name in [`TrajectoryKind`](crate::TrajectoryKind).
        parameter: &'static str,
        /// The rejected value.
        value: f32,
        /// Lower limit.
        min: f32,
        /// Upper limit.
        max: f32,
    },
    /// A tangent-heading mission whose horizontal speed falls below
    /// [`Trajectory::MIN_TANGENT_SPEED`](crate::Trajectory::MIN_TANGENT_SPEED) somewhere (the course is undefined at zero speed).
    TooSlowForTangent {
        /// The path's minimum horizontal speed at its time scale (m/s).
        min_speed: f32,
        /// [`Trajectory::MIN_TANGENT_SPEED`](crate::Trajectory::MIN_TANGENT_SPEED).
        threshold: f32,
    },
    /// A waypoint path with fewer than 2 or more than [`MAX_WAYPOINTS`] points.
    WaypointCount {
        /// How many points were given.
        count: usize,
    },
    /// Two consecutive waypoints closer than [`MIN_LEG`]: one point repeated.
    RepeatedWaypoint {
        /// The second of the two (0-based).
        index: usize,
    },
    /// A turn sharper than [`MAX_TURN_DEGREES`] at a waypoint.
    TurnTooSharp {
        /// The waypoint (0-based).
        index: usize,
        /// Its turn angle (degrees).
        degrees: f32,
    },
    /// A leg too short for the blends of the turns at its two ends (at this turn radius).
    LegTooShort {
        /// The leg (0-based: leg i joins points i and i + 1).
        leg: usize,
        /// The cut distances of its two turns, added (m).
        needs: f32,
        /// Its length (m).
        has: f32,
    },
    /// A time law whose speed count is not the path's parts (2n − 3: each leg and each turn).
    SpeedCount {
        /// How many speeds were given.
        count: usize,
        /// How many the path has.
        expected: usize,
    },
    /// A part of the path too short for the speed changes at its two ends.
    SpeedChangeTooLong {
        /// The part (2j: leg j, 2j − 1: the turn at waypoint j).
        part: usize,
        /// The path the changes need (m).
        needs: f32,
        /// The part's length (m).
        has: f32,
    },
    /// A leg steeper than [`MAX_SLOPE`] (|Δz| over its horizontal length).
    TooSteep {
        /// The leg (0-based).
        leg: usize,
        /// Its slope.
        slope: f32,
    },
    /// A waypoint's coordinate that is NaN or infinite (Choice 315).
    PointNotFinite {
        /// The waypoint (0-based).
        index: usize,
        /// The coordinate: 0 x, 1 y, 2 z.
        axis: usize,
    },
    /// A speed of the time law that is NaN or infinite (Choice 315).
    SpeedNotFinite {
        /// The part (2j: leg j, 2j − 1: the turn at waypoint j).
        part: usize,
    },
    /// A waypoint's coordinate beyond ±[`MAX_COORDINATE`] (Choice 315).
    BadPoint {
        /// The waypoint (0-based).
        index: usize,
        /// The coordinate: 0 x, 1 y, 2 z.
        axis: usize,
        /// The rejected value.
        value: f32,
    },
    /// A speed of the time law outside (0, [`MAX_SPEED`]] (Choice 315).
    BadSpeed {
        /// The part (2j: leg j, 2j − 1: the turn at waypoint j).
        part: usize,
        /// The rejected value.
        value: f32,
    },
    /// A waypoint path whose horizontal speed falls below
    /// [`Trajectory::MIN_TANGENT_SPEED`](crate::Trajectory::MIN_TANGENT_SPEED) somewhere: its
    /// course (its heading, Choice 154) is undefined at zero speed (Choice 315).
    WaypointTooSlow {
        /// The path's minimum horizontal speed at its time scale (m/s).
        min_speed: f32,
        /// [`Trajectory::MIN_TANGENT_SPEED`](crate::Trajectory::MIN_TANGENT_SPEED).
        threshold: f32,
        /// The slowest part of its time law (`None`: flown at `speed`).
        part: Option<usize>,
    },
}

impl TrajectoryError {
    /// The messages that name a waypoint or a part (Choice 315).
    fn fmt_named(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::PointNotFinite { index, axis } => write!(
                f,
                "waypoint {index}'s {} is not finite",
                ["x", "y", "z"][axis.min(2)]
            ),
            Self::SpeedNotFinite { part } => {
                write!(f, "speeds[{part}] ({}) is not finite", PartName(part))
            }
            Self::BadPoint { index, axis, value } => write!(
                f,
                "waypoint {index}'s {} = {} m is outside [{}, {}]",
                ["x", "y", "z"][axis.min(2)],
                Readable(value),
                Readable(-MAX_COORDINATE),
                Readable(MAX_COORDINATE)
            ),
            Self::BadSpeed { part, value } => write!(
                f,
                "speeds[{part}] ({}) = {} m/s is outside (0, {}]",
                PartName(part),
                Readable(value),
                MAX_SPEED
            ),
            Self::WaypointTooSlow {
                min_speed,
                threshold,
                part,
            } => {
                write!(
                    f,
                    "the path's course (its heading) needs a horizontal speed of at least {threshold} m/s everywhere; this path slows to {} m/s",
                    Readable(min_speed)
                )?;
                match part {
                    Some(p) => write!(f, " on speeds[{p}] ({}): raise it", PartName(p)),
                    None => f.write_str(": raise speed or lower the time scale"),
                }
            }
            _ => Ok(()),
        }
    }
}

impl TrajectoryError {
    /// This refusal of a number read from a file as `written` (an f64 that an f32 cannot hold:
    /// beyond ±3.4e38, or below 1.2e-38 and so read as 0), with the number as written
    /// (Choice 315).
    #[cfg(feature = "serde")]
    pub(crate) fn narrowed(self, written: f64) -> NarrowedError {
        NarrowedError {
            error: self,
            written,
        }
    }
}

/// A [`TrajectoryError`] about a number as written in a file ([`TrajectoryError::narrowed`]).
#[cfg(feature = "serde")]
pub(crate) struct NarrowedError {
    error: TrajectoryError,
    written: f64,
}

#[cfg(feature = "serde")]
impl fmt::Display for NarrowedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let w = Readable(self.written);
        match self.error {
            TrajectoryError::BadPoint { index, axis, .. } => write!(
                f,
                "waypoint {index}'s {} = {w} m is outside [{}, {}]",
                ["x", "y", "z"][axis.min(2)],
                Readable(-MAX_COORDINATE),
                Readable(MAX_COORDINATE)
            ),
            TrajectoryError::BadSpeed { part, .. } => write!(
                f,
                "speeds[{part}] ({}) = {w} m/s is outside (0, {}]{}",
                PartName(part),
                MAX_SPEED,
                match self.written.abs() < 1.0 {
                    true => " (below the smallest f32, it would read as 0)",
                    false => "",
                }
            ),
            e => write!(f, "{e} (written {w})"),
        }
    }
}

/// `leg j` or `the turn at waypoint j` for part p (2j, 2j − 1).
struct PartName(usize);

impl fmt::Display for PartName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 % 2 {
            0 => write!(f, "leg {}", self.0 / 2),
            _ => write!(f, "the turn at waypoint {}", self.0.div_ceil(2)),
        }
    }
}

impl TrajectoryError {
    /// The rejected field of [`TrajectoryKind`](crate::TrajectoryKind) or [`Mission`](crate::Mission), e.g. `"radius"` (a scenario's
    /// `trajectory.radius`), `"time_scale"` or `"heading"`.
    pub fn parameter(&self) -> &'static str {
        match *self {
            Self::NonFinite { parameter }
            | Self::NotPositive { parameter, .. }
            | Self::OutOfRange { parameter, .. } => parameter,
            Self::TooSlowForTangent { .. } => "heading",
            Self::WaypointCount { .. }
            | Self::RepeatedWaypoint { .. }
            | Self::TurnTooSharp { .. }
            | Self::LegTooShort { .. }
            | Self::TooSteep { .. }
            | Self::BadPoint { .. }
            | Self::PointNotFinite { .. } => "points",
            Self::SpeedCount { .. }
            | Self::SpeedChangeTooLong { .. }
            | Self::BadSpeed { .. }
            | Self::SpeedNotFinite { .. } => "speeds",
            Self::WaypointTooSlow { part: Some(_), .. } => "speeds",
            Self::WaypointTooSlow { part: None, .. } => "speed",
        }
    }
}

impl fmt::Display for TrajectoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite { parameter } => write!(f, "trajectory {parameter} is not finite"),
            Self::NotPositive { parameter, value } => {
                write!(f, "trajectory {parameter} = {} must be > 0", Readable(value))
            }
            Self::OutOfRange {
                parameter,
                value,
                min,
                max,
            } => write!(
                f,
                "trajectory {parameter} = {} is outside [{}, {}]",
                Readable(value),
                Readable(min),
                Readable(max)
            ),
            Self::TooSlowForTangent {
                min_speed,
                threshold,
            } => write!(
                f,
                "tangent heading needs a horizontal speed of at least {threshold} m/s everywhere; this path slows to {min_speed} m/s (lower the time scale, or fly the paper's heading)"
            ),
            Self::WaypointCount { count } => write!(
                f,
                "a waypoint path needs 2 to {} points; this one has {count}",
                MAX_WAYPOINTS
            ),
            Self::RepeatedWaypoint { index } => write!(
                f,
                "waypoint {index} repeats waypoint {} (closer than {} m)",
                index - 1,
                MIN_LEG
            ),
            Self::TurnTooSharp { index, degrees } => write!(
                f,
                "the turn at waypoint {index} is {}°, sharper than the {}° the path allows (add a waypoint to split it)",
                Readable(degrees),
                MAX_TURN_DEGREES
            ),
            Self::LegTooShort { leg, needs, has } => write!(
                f,
                "leg {leg} (waypoints {leg} to {}) is {} m long but its turns need {} m at this turn radius (lower turn_radius or speed, or space the waypoints)",
                leg + 1,
                Readable(has),
                Readable(needs)
            ),
            Self::SpeedCount { count, expected } => write!(
                f,
                "the time law has {count} speeds; this path has {expected} parts (each leg and each turn, in path order)"
            ),
            Self::SpeedChangeTooLong { part, needs, has } => write!(
                f,
                "part {part} of the path is {} m long but its speed changes need {} m (lower its speed, or raise speed_change)",
                Readable(has),
                Readable(needs)
            ),
            Self::PointNotFinite { .. }
            | Self::SpeedNotFinite { .. }
            | Self::BadPoint { .. }
            | Self::BadSpeed { .. }
            | Self::WaypointTooSlow { .. } => self.fmt_named(f),
            Self::TooSteep { leg, slope } => write!(
                f,
                "leg {leg} (waypoints {leg} to {}) climbs or dives at slope {}, steeper than {} (the heading needs horizontal motion)",
                leg + 1,
                Readable(slope),
                MAX_SLOPE
            ),
        }
    }
}

/// A parameter of a closed-form path kind: its field's name and the values
/// [`Trajectory::new`](crate::Trajectory::new) accepts
/// ([`TrajectoryKind::parameters`](crate::TrajectoryKind::parameters) lists them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameter {
    /// The field's name, as scenario files spell it and [`TrajectoryError::parameter`] names it.
    pub name: &'static str,
    /// The values accepted.
    pub range: ParameterRange,
}

/// The values a [`Parameter`] accepts (every one finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParameterRange {
    /// (0, max]: a size or a frequency.
    Positive(f32),
    /// [−max, max]: a depth or a rate of either sign.
    Symmetric(f32),
}

impl Parameter {
    /// The largest magnitude accepted.
    pub const fn max(&self) -> f32 {
        match self.range {
            ParameterRange::Positive(max) | ParameterRange::Symmetric(max) => max,
        }
    }

    /// `value` finite and in range; the error names the parameter.
    pub fn check(&self, value: f32) -> Result<(), TrajectoryError> {
        match self.range {
            ParameterRange::Positive(max) => positive(self.name, value, max),
            ParameterRange::Symmetric(max) => symmetric(self.name, value, max),
        }
    }
}

/// `value` finite and in (0, max].
pub(super) fn positive(
    parameter: &'static str,
    value: f32,
    max: f32,
) -> Result<(), TrajectoryError> {
    if !value.is_finite() {
        Err(TrajectoryError::NonFinite { parameter })
    } else if value <= 0.0 {
        Err(TrajectoryError::NotPositive { parameter, value })
    } else if value > max {
        Err(TrajectoryError::OutOfRange {
            parameter,
            value,
            min: 0.0,
            max,
        })
    } else {
        Ok(())
    }
}

/// `value` finite and in [−max, max].
pub(super) fn symmetric(
    parameter: &'static str,
    value: f32,
    max: f32,
) -> Result<(), TrajectoryError> {
    if !value.is_finite() {
        Err(TrajectoryError::NonFinite { parameter })
    } else if !(-max..=max).contains(&value) {
        Err(TrajectoryError::OutOfRange {
            parameter,
            value,
            min: -max,
            max,
        })
    } else {
        Ok(())
    }
}
