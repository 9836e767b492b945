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
//! carries it. The waypoint path (docs/missions.md#waypoint-paths) is up to 32 points: it travels as a
//! mission upload ([`crate::upload`]) and `StartMission` names it by the upload's CRC
//! ([`MissionSpec::Waypoints`]), so core → wire computes that CRC, and wire → core needs the
//! board's [`UploadBuffer`] ([`MissionPlan::resolve`]; without it, [`Uploaded`]).

use controller_core::{trajectory, HeadingMode, Mission, TrajectoryKind};

use crate::heading::Heading;
use crate::msg::{
    AxisPriority, BBound, EstimatorSettings, LawSettings, MissionPlan, MissionSpec, RobustLaw,
    ThrustUnit,
};
use crate::refusal::Refusal;
use crate::upload::{MissionUpload, UploadBuffer};

/// Both conversions from one list of variants and fields, so the two directions cannot drift
/// apart. A variant or field missing from the list is a compile error (non-exhaustive match,
/// or a pattern that does not mention a field).
macro_rules! field_for_field {
    ($($variant:ident { $($field:ident),+ $(,)? }),+ ; uploaded: $big:ident) => {
        impl From<TrajectoryKind> for MissionSpec {
            fn from(kind: TrajectoryKind) -> Self {
                match kind {
                    $(TrajectoryKind::$variant(trajectory::$variant { $($field),+ }) => MissionSpec::$variant { $($field),+ },)+
                    // A bare path is the paper's mission (k = 1); `MissionPlan::from(Mission)`
                    // names the mission's own upload.
                    path @ TrajectoryKind::$big { .. } => MissionSpec::$big {
                        crc: MissionUpload::of(&Mission::paper(path)).map_or(0, |u| u.crc()),
                    },
                }
            }
        }

        impl TryFrom<MissionSpec> for TrajectoryKind {
            type Error = Uploaded;
            fn try_from(spec: MissionSpec) -> Result<Self, Uploaded> {
                match spec {
                    $(MissionSpec::$variant { $($field),+ } => Ok(TrajectoryKind::$variant(trajectory::$variant { $($field),+ })),)+
                    MissionSpec::$big { crc } => Err(Uploaded { crc }),
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
    uploaded: Waypoints
}

/// A wire path that names a mission upload (the waypoint path, by its CRC): only the board
/// that holds the upload can turn it into a path ([`MissionPlan::resolve`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Uploaded {
    /// The upload's CRC.
    pub crc: u32,
}

impl core::fmt::Display for Uploaded {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "the path is the mission upload of CRC {:#010x}, which only its board holds",
            self.crc
        )
    }
}

impl MissionPlan {
    /// The mission: a closed-form path field for field; an uploaded one from `upload`, if it
    /// holds that upload verified and the plan's heading and time scale are the upload's
    /// ([`UploadBuffer::mission`]; else [`Refusal::NoUpload`]).
    pub fn resolve(&self, upload: &UploadBuffer) -> Result<Mission, Refusal> {
        match TrajectoryKind::try_from(self.path) {
            Ok(path) => Ok(Mission {
                path,
                heading: self.heading.into(),
                time_scale: self.time_scale,
            }),
            Err(Uploaded { crc }) => {
                let m = upload.mission(crc)?;
                let same = Heading::from(m.heading) == self.heading
                    && m.time_scale.to_bits() == self.time_scale.to_bits();
                if same {
                    Ok(m)
                } else {
                    Err(Refusal::NoUpload)
                }
            }
        }
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
variant_for_variant!(
    RobustLaw,
    controller_core::law::RobustLaw,
    Discontinuous,
    BoundaryLayer
);
variant_for_variant!(BBound, controller_core::BBound, ControlledRows, Literal);

impl From<Mission> for MissionPlan {
    /// A waypoint path is named by the CRC of this mission's upload (its heading and time
    /// scale included).
    fn from(m: Mission) -> Self {
        MissionPlan {
            path: match MissionUpload::of(&m) {
                Some(u) => MissionSpec::Waypoints { crc: u.crc() },
                None => m.path.into(),
            },
            heading: m.heading.into(),
            time_scale: m.time_scale,
        }
    }
}

impl TryFrom<MissionPlan> for Mission {
    type Error = Uploaded;
    /// A mission on a closed-form path ([`Uploaded`] for an uploaded one: see
    /// [`MissionPlan::resolve`]).
    fn try_from(m: MissionPlan) -> Result<Self, Uploaded> {
        Ok(Mission {
            path: m.path.try_into()?,
            heading: m.heading.into(),
            time_scale: m.time_scale,
        })
    }
}

impl From<TrajectoryKind> for MissionPlan {
    /// The paper's mission on this path ([`Mission::paper`]).
    fn from(kind: TrajectoryKind) -> Self {
        Mission::paper(kind).into()
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

impl From<controller_core::EstimatorConfig> for EstimatorSettings {
    fn from(e: controller_core::EstimatorConfig) -> Self {
        let controller_core::EstimatorConfig {
            kind,
            position_sigma,
            velocity_sigma,
            accel_sigma,
            // Not on the wire: every board flies the core's DISTURBANCE_TIME (Choice 510).
            disturbance_time: _,
        } = e;
        EstimatorSettings {
            kalman: kind == controller_core::EstimatorKind::Kalman,
            position_sigma,
            velocity_sigma,
            accel_sigma,
        }
    }
}

impl From<EstimatorSettings> for controller_core::EstimatorConfig {
    fn from(e: EstimatorSettings) -> Self {
        let EstimatorSettings {
            kalman,
            position_sigma,
            velocity_sigma,
            accel_sigma,
        } = e;
        controller_core::EstimatorConfig {
            kind: if kalman {
                controller_core::EstimatorKind::Kalman
            } else {
                controller_core::EstimatorKind::Off
            },
            position_sigma,
            velocity_sigma,
            accel_sigma,
            disturbance_time: controller_core::estimator::DISTURBANCE_TIME,
        }
    }
}

impl LawSettings {
    /// The law's settings of `c`, field for field (every `f32` keeps its bits).
    pub fn of(c: &controller_core::ControllerConfig) -> Self {
        // Every field named, so that a law setting added to the core is a compile error here
        // until the link carries it or says why not.
        let controller_core::ControllerConfig {
            k1,
            k2,
            q,
            beta,
            mu,
            law,
            b_bound,
            pitch_limit,
            // Carried by `ConfigPatch`'s own fields (protocols 1–7).
            robust: _,
            delta_max: _,
            rate_hz: _,
            voltage_limit: _,
            thrust_unit: _,
            priority: _,
            estimator: _,
            // The mounting crosses as `ConfigPatch::reversed_thrusters`; the positions, the
            // nominal model and its box are the vehicle's, built into the board (Choices 49,
            // 225, 363).
            geometry: _,
            params: _,
            uncertainty: _,
        } = *c;
        LawSettings {
            k1,
            k2,
            q,
            beta,
            mu,
            law: law.into(),
            b_bound: b_bound.into(),
            pitch_limit,
        }
    }

    /// `c` with these law settings; the rest of `c` unchanged. Does not validate (the
    /// receiver builds the controller, which does).
    pub fn apply(self, c: &mut controller_core::ControllerConfig) {
        let LawSettings {
            k1,
            k2,
            q,
            beta,
            mu,
            law,
            b_bound,
            pitch_limit,
        } = self;
        c.k1 = k1;
        c.k2 = k2;
        c.q = q;
        c.beta = beta;
        c.mu = mu;
        c.law = law.into();
        c.b_bound = b_bound.into();
        c.pitch_limit = pitch_limit;
    }
}
