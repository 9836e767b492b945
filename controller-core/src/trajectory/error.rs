//! Why a mission is refused ([`TrajectoryError`]), and the two range checks every path kind's
//! parameters go through.

use core::fmt;

use crate::readable::Readable;

#[cfg(doc)]
use crate::trajectory::{Mission, Trajectory, TrajectoryKind};

/// Why a [`TrajectoryKind`] was rejected by [`Trajectory::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrajectoryError {
    /// The parameter is NaN or infinite.
    NonFinite {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
    },
    /// A size or frequency that must be strictly positive is zero or negative.
    NotPositive {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
        /// The rejected value.
        value: f32,
    },
    /// The parameter lies outside [min, max] (for a positive parameter `min` is 0 and exclusive;
    /// values at or below it are reported as [`TrajectoryError::NotPositive`]).
    OutOfRange {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
        /// The rejected value.
        value: f32,
        /// Lower limit.
        min: f32,
        /// Upper limit.
        max: f32,
    },
    /// A tangent-heading mission whose horizontal speed falls below
    /// [`Trajectory::MIN_TANGENT_SPEED`] somewhere (the course is undefined at zero speed).
    TooSlowForTangent {
        /// The path's minimum horizontal speed at its time scale (m/s).
        min_speed: f32,
        /// [`Trajectory::MIN_TANGENT_SPEED`].
        threshold: f32,
    },
}

impl TrajectoryError {
    /// The rejected field of [`TrajectoryKind`] or [`Mission`], e.g. `"radius"` (a scenario's
    /// `trajectory.radius`), `"time_scale"` or `"heading"`.
    pub fn parameter(&self) -> &'static str {
        match *self {
            Self::NonFinite { parameter }
            | Self::NotPositive { parameter, .. }
            | Self::OutOfRange { parameter, .. } => parameter,
            Self::TooSlowForTangent { .. } => "heading",
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
