//! The path kinds as data: [`TrajectoryKind`], the shape and parameters of a mission, and how
//! host-sim's scenario files spell it (the `serde` feature). Each kind's equations are its own
//! file in `paths/`.

#[cfg(any(doc, feature = "serde"))]
use crate::trajectory::Trajectory;
use crate::trajectory::{SpeedList, WaypointList};
#[cfg(doc)]
use crate::trajectory::{DEFAULT_SPEED_CHANGE, TURN_ACCEL};

/// Shape and parameters of a mission (the paper's "Simulation Results"; docs/missions.md#closed-form-paths).
///
/// All frequencies ω are in rad/s and must be positive; sizes in metres; z is positive down (NED).
///
/// With the `serde` feature it is a table tagged by `kind` (`"circle"`, `"figure-eight"`,
/// `"lawn-mower"`, `"helix"`) with the fields by name; unknown fields are refused, and `omega`
/// and `depth` default to the paper's values ([`Trajectory::PAPER_OMEGA`], for the lawn-mower
/// [`Trajectory::PAPER_LAWN_MOWER_OMEGA`]; [`Trajectory::PAPER_DEPTH`]). This is the
/// `[trajectory]` table of host-sim's scenario files. Values are not validated there: build the
/// mission with [`Trajectory::new`].
// The waypoint list is ~390 bytes beside the closed forms' 16: no heap on the board (no `Box`),
// and a mission is copied at configuration only (`Trajectory::set`), never per sample.
#[allow(clippy::large_enum_variant)]
// The tag in declaration order (Circle = 0), so that `Trajectory::EMPTY`, a circle of zeros, is
// all zero bits (a board zeroes it instead of copying it from flash).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)
)]
pub enum TrajectoryKind {
    /// x = R sin ωt, y = R cos ωt, z = depth, ψ = ωt (paper: ω = 0.1; "10 sin(0.1)t" read as
    /// R sin 0.1t).
    Circle {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// x = A sin ωt, y = A cos(ωt/2), z = depth,
    /// ψ = (8/π) Σ_{n odd ≤ N} (−1)^((n−1)/2) sin(nωt)/n² (a triangle wave of amplitude π;
    /// paper: ω = 0.1, A = 15 or 20 for the 30×30 and 40×40 cases).
    FigureEight {
        /// A (m): x and y each span 2A.
        amplitude: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// x = s(0.25 t + 2.5 sin 2ωt), y = 15 s cos ωt, z = depth,
    /// ψ = (8/π) Σ_{n ≤ N} [sin(nπ/4) + sin(3nπ/4)] sin(nωt)/n² (a trapezoid of amplitude π;
    /// paper: ω = 0.05, so 2ω = 0.1; s = 1 is the paper's 30×15 case).
    LawnMower {
        /// s (dimensionless): loop height 30 s m, loop width ≈ 15.7 s m.
        scale: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_lawn_mower_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// A circle whose depth changes linearly: z = depth + depth_rate·t (not in the paper).
    Helix {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d at t = 0 (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
        /// ż_d (m/s, positive = descending).
        depth_rate: f32,
    },
    /// Straight legs through the waypoints, each corner turned on a septic blend, flown at
    /// `speed` along the path (not in the paper; docs/missions.md#waypoint-paths).
    Waypoints {
        /// The points in the mission frame (m, z positive down): `points = [[x, y, z], …]`.
        points: WaypointList,
        /// σ̇, the path speed on the legs (m/s; slower in the turns).
        speed: f32,
        /// The smallest radius of a turn (m); `None`: speed²/[`TURN_ACCEL`] (Choice 151).
        #[cfg_attr(feature = "serde", serde(default))]
        turn_radius: Option<f32>,
        /// The time law: a speed per leg and turn in path order (m/s; Choice 156), the
        /// profile `host-sim check` proposes; `None`: `speed` everywhere.
        #[cfg_attr(feature = "serde", serde(default))]
        speeds: Option<SpeedList>,
        /// The largest |σ̈| of a change of speed (m/s²); `None`: [`DEFAULT_SPEED_CHANGE`].
        #[cfg_attr(feature = "serde", serde(default))]
        speed_change: Option<f32>,
    },
}

// The serde defaults of `TrajectoryKind` (the paper's values).
#[cfg(feature = "serde")]
fn default_omega() -> f32 {
    Trajectory::PAPER_OMEGA
}
#[cfg(feature = "serde")]
fn default_lawn_mower_omega() -> f32 {
    Trajectory::PAPER_LAWN_MOWER_OMEGA
}
#[cfg(feature = "serde")]
fn default_depth() -> f32 {
    Trajectory::PAPER_DEPTH
}
