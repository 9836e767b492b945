//! The one conversion between the link's wire type [`MissionSpec`] and the core's
//! [`TrajectoryKind`], both ways. The board (`Command::StartMission` → trajectory) and the
//! host (scenario → `StartMission`) both use it, so the two ends cannot disagree on a field.
//!
//! The conversion is field for field and loses nothing: every `f32` keeps its bits (NaN
//! payloads included). It does not validate: the receiver builds the trajectory with
//! [`controller_core::Trajectory::new`], which rejects what cannot be flown.
//!
//! `MissionSpec` stays its own type because its layout *is* the wire format (variant order and
//! field order fix the postcard bytes; see [`crate::msg`]), while `TrajectoryKind` may grow
//! without a protocol change. A kind added to the core fails to compile here until the link
//! carries it.

use controller_core::TrajectoryKind;

use crate::msg::MissionSpec;

/// Both `From` impls from one list of variants and fields, so the two directions cannot drift
/// apart. A variant or field missing from the list is a compile error (non-exhaustive match,
/// or a pattern that does not mention a field).
macro_rules! field_for_field {
    ($($variant:ident { $($field:ident),+ $(,)? }),+ $(,)?) => {
        impl From<TrajectoryKind> for MissionSpec {
            fn from(kind: TrajectoryKind) -> Self {
                match kind {
                    $(TrajectoryKind::$variant { $($field),+ } => MissionSpec::$variant { $($field),+ },)+
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
    Helix { radius, omega, depth, depth_rate },
}
