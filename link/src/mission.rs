//! The one conversion between the link's wire types and the core's, both ways:
//! [`MissionSpec`] ↔ [`TrajectoryKind`], [`MissionPlan`] ↔ [`Mission`], [`Heading`] ↔
//! [`HeadingMode`], and the wire [`ThrustUnit`] and [`AxisPriority`] ↔ the core's. The board
//! (`Command::StartMission` → trajectory, `SetConfig` → configuration) and the host
//! (scenario → `StartMission`, `SetConfig`) both use it, so the two ends cannot disagree on a
//! field.
//!
//! The conversion is field for field and loses nothing: every `f32` keeps its bits (NaN
//! payloads included). It does not validate: the receiver builds the trajectory with
//! [`controller_core::Trajectory::new`], which rejects what cannot be flown.
//!
//! `MissionSpec` stays its own type because its layout *is* the wire format (variant order and
//! field order fix the postcard bytes; see [`crate::msg`]), while `TrajectoryKind` may grow
//! without a protocol change. A kind added to the core fails to compile here until the link
//! carries it, or is listed as one that does not fit one frame: the waypoint path
//! (docs/design.md §27) is up to 32 points, so core → wire is a `TryFrom` that refuses it
//! ([`NotOneFrame`]) until the chunked mission upload carries it.

use controller_core::{HeadingMode, Mission, TrajectoryKind};

use crate::msg::{AxisPriority, Heading, MissionPlan, MissionSpec, ThrustUnit};

/// Both `From` impls from one list of variants and fields, so the two directions cannot drift
/// apart. A variant or field missing from the list is a compile error (non-exhaustive match,
/// or a pattern that does not mention a field).
macro_rules! field_for_field {
    ($($variant:ident { $($field:ident),+ $(,)? }),+ ; not one frame: $($big:ident),+ $(,)?) => {
        impl TryFrom<TrajectoryKind> for MissionSpec {
            type Error = NotOneFrame;
            fn try_from(kind: TrajectoryKind) -> Result<Self, NotOneFrame> {
                match kind {
                    $(TrajectoryKind::$variant { $($field),+ } => Ok(MissionSpec::$variant { $($field),+ }),)+
                    $(TrajectoryKind::$big { .. } => Err(NotOneFrame),)+
                }
            }
        }

        impl From<MissionSpec> for TrajectoryKind {
            fn from(spec: MissionSpec) -> Self {
                match spec {
                    $(MissionSpec::$variant { $($field),+ } => TrajectoryKind::$variant { $($field),+ },)+
                }
            }
        }
    };
}

field_for_field! {
    Circle { radius, omega, depth },
    FigureEight { amplitude, omega, depth },
    LawnMower { scale, omega, depth },
    Helix { radius, omega, depth, depth_rate };
    not one frame: Waypoints,
}

/// A path that does not fit one `StartMission` frame (the waypoint path, docs/design.md §27):
/// it is flown in SIL until the chunked mission upload carries it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotOneFrame;

impl core::fmt::Display for NotOneFrame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("a waypoint mission does not fit one StartMission frame (no mission upload yet: fly it in SIL)")
    }
}

/// Both `From` impls of a field-less enum pair from one list of variants.
macro_rules! variant_for_variant {
    ($wire:ident, $core:ty, $($variant:ident),+ $(,)?) => {
        impl From<$core> for $wire {
            fn from(v: $core) -> Self {
                match v {
                    $(<$core>::$variant => $wire::$variant,)+
                }
            }
        }

        impl From<$wire> for $core {
            fn from(v: $wire) -> Self {
                match v {
                    $($wire::$variant => <$core>::$variant,)+
                }
            }
        }
    };
}

variant_for_variant!(Heading, HeadingMode, Paper, Tangent);
variant_for_variant!(ThrustUnit, controller_core::ThrustUnit, Kgf, Newton);

impl TryFrom<Mission> for MissionPlan {
    type Error = NotOneFrame;
    fn try_from(m: Mission) -> Result<Self, NotOneFrame> {
        Ok(MissionPlan {
            path: m.path.try_into()?,
            heading: m.heading.into(),
            time_scale: m.time_scale,
        })
    }
}

impl From<MissionPlan> for Mission {
    fn from(m: MissionPlan) -> Self {
        Mission {
            path: m.path.into(),
            heading: m.heading.into(),
            time_scale: m.time_scale,
        }
    }
}

impl TryFrom<TrajectoryKind> for MissionPlan {
    type Error = NotOneFrame;
    /// The paper's mission on this path ([`Mission::paper`]).
    fn try_from(kind: TrajectoryKind) -> Result<Self, NotOneFrame> {
        Mission::paper(kind).try_into()
    }
}

impl From<MissionSpec> for MissionPlan {
    /// The paper's mission on this path ([`Mission::paper`]).
    fn from(path: MissionSpec) -> Self {
        MissionPlan {
            path,
            heading: HeadingMode::Paper.into(),
            time_scale: 1.0,
        }
    }
}

impl From<controller_core::allocation::AxisPriority> for AxisPriority {
    fn from(p: controller_core::allocation::AxisPriority) -> Self {
        let controller_core::allocation::AxisPriority { rank, weight } = p;
        AxisPriority { rank, weight }
    }
}

impl From<AxisPriority> for controller_core::allocation::AxisPriority {
    fn from(p: AxisPriority) -> Self {
        let AxisPriority { rank, weight } = p;
        controller_core::allocation::AxisPriority { rank, weight }
    }
}
