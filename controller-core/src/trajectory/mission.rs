//! A mission as the board flies it: a path, a heading mode and a time scale.

#[cfg(doc)]
use crate::trajectory::Trajectory;
use crate::trajectory::{HeadingMode, TrajectoryKind};

/// A mission as the board flies it: a path ([`TrajectoryKind`]), how its heading is formed
/// ([`HeadingMode`]) and how slowly it is flown (`time_scale` k ≥ 1: the desired state is
/// η_d(t/k), so velocities are divided by k and accelerations by k²). Validated by
/// [`Trajectory::new`]; crosses the link in `StartMission`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mission {
    /// The path's shape and parameters.
    pub path: TrajectoryKind,
    /// ψ_d: the paper's or the path's course.
    pub heading: HeadingMode,
    /// k ≥ 1 (1: the paper's speed).
    pub time_scale: f32,
}

impl Mission {
    /// `path` as the paper flies it: its own heading, k = 1.
    pub const fn paper(path: TrajectoryKind) -> Mission {
        Mission {
            path,
            heading: HeadingMode::Paper,
            time_scale: 1.0,
        }
    }
}

impl From<TrajectoryKind> for Mission {
    /// [`Mission::paper`].
    fn from(path: TrajectoryKind) -> Mission {
        Mission::paper(path)
    }
}
