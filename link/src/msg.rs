//! The messages and their worst-case postcard sizes.
//!
//! **Wire compatibility:** postcard writes fields in declaration order and enum variants by
//! their index (declaration order, from 0). Reordering, removing or retyping a field or variant
//! changes the protocol: bump [`PROTOCOL_VERSION`] and update the `MAX_SIZE` constants (the
//! `max_sizes_are_exact` test fails until they match).

use controller_core::effectiveness::THRUSTERS;
use serde::{Deserialize, Serialize};

use crate::heading::Heading;
use crate::refusal::Refusal;
use crate::upload::{UploadChunk, UploadPart, UploadStatus, CHUNK_WORDS};

/// The protocol version this crate speaks; sent as the first byte of every frame.
///
/// 2: sequence numbers checked ([`crate::seq`]), optional signature trailer
/// ([`crate::sign`]), and the telemetry's latched reason, refusals, drop counters, last
/// accepted sequence number and signing flag.
///
/// 3: `StartMission` carries a [`MissionPlan`] (heading, time scale); `SetConfig` the thrust
/// unit, the thruster mounting and the axis priority; `Telemetry` the unit and mounting the
/// board flies; refusals for an invalid time scale, tangent heading, mounting or priority.
///
/// 4: `Telemetry` counts the authentic frames refused for a timestamp too far ahead
/// ([`Telemetry::rx_ahead`], [`crate::sign::AuthError::Ahead`]).
///
/// 5: the chunked mission upload ([`crate::upload`]): `Command::Upload`, the waypoint path
/// named by its CRC (`MissionSpec::Waypoints`), the upload's acknowledgement in every
/// `Telemetry` ([`Telemetry::upload`]), and the upload's refusals.
///
/// 6: `Telemetry` carries the digest of the whole configuration the board flies
/// ([`Telemetry::config_digest`], [`ConfigPatch::digest`]), so that the navigation computer
/// confirms every field it set (Choice 228).
///
/// 7: `SetConfig` carries the state estimator's settings ([`ConfigPatch::estimator`],
/// [`EstimatorSettings`]), which the digest covers; the board computes the gains from them
/// while disarmed (Choice 361).
///
/// 8: `SetConfig` carries the law's settings ([`ConfigPatch::law`], [`LawSettings`]: K₁,
/// K₂, Q, β, μ, Theorem 3 or 4, the ‖b‖ bound, the pitch limit), which the digest covers; the
/// board validates them with the core's checks and applies them in its disarmed rebuild, so a
/// board flies the law the host's SIL flies (Choice 508). A whole `SetConfig` is now the
/// largest message.
pub const PROTOCOL_VERSION: u8 = 8;

// Worst-case postcard sizes of the primitives: u8 and bool are one byte, f32 is four bytes
// little-endian, u16/u32/u64 are unsigned LEB128 varints (7 bits per byte), `Option` is a
// one-byte tag plus the value, an enum is its variant index as a varint (one byte below 128)
// plus the variant's fields, and `[T; N]` is N times T with no length prefix.
const U8: usize = 1;
const BOOL: usize = 1;
const F32: usize = 4;
const fn varint(bits: usize) -> usize {
    bits.div_ceil(7)
}
const U16: usize = varint(16);
const U32: usize = varint(32);
const U64: usize = varint(64);
const TAG: usize = 1;
const fn option(n: usize) -> usize {
    1 + n
}
const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// One frame: protocol version, sequence number, message.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Envelope {
    /// [`PROTOCOL_VERSION`] of the sender. Receivers reject any other value
    /// ([`LinkError::Version`](crate::LinkError::Version)) without looking at the rest.
    pub version: u8,
    /// Sender's frame counter: +1 per frame sent, wrapping. Each direction has its own. A
    /// receiver accepts only frames newer than the last it accepted ([`crate::seq`]).
    pub seq: u16,
    /// The payload.
    pub msg: Msg,
}

impl Envelope {
    /// Worst-case postcard size of an `Envelope` (bytes).
    pub const MAX_SIZE: usize = U8 + U16 + Msg::MAX_SIZE;

    /// An envelope of the current [`PROTOCOL_VERSION`].
    pub const fn new(seq: u16, msg: Msg) -> Self {
        Envelope {
            version: PROTOCOL_VERSION,
            seq,
            msg,
        }
    }
}

/// What a frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Msg {
    /// Navigation computer → board: the vehicle state for the next control step.
    State(StateFrame),
    /// Navigation computer → board: an operator or mission command.
    Command(Command),
    /// Board → navigation computer: the board's report, one per control step (or fewer).
    Telemetry(Telemetry),
}

impl Msg {
    /// Worst-case postcard size of a `Msg` (bytes).
    pub const MAX_SIZE: usize = TAG
        + max(
            StateFrame::MAX_SIZE,
            max(Command::MAX_SIZE, Telemetry::MAX_SIZE),
        );
}

/// The navigation solution the controller runs on.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StateFrame {
    /// Navigation time in control ticks (time = `t_ticks / rate_hz`), the time η and ν hold at.
    pub t_ticks: u64,
    /// η = [x, y, z, φ, θ, ψ]: earth-fixed position (m, z positive down) and Euler angles (rad).
    pub eta: [f32; 6],
    /// ν = [u, v, w, p, q, r]: body-fixed linear (m/s) and angular (rad/s) velocity.
    pub nu: [f32; 6],
}

impl StateFrame {
    /// Worst-case postcard size of a `StateFrame` (bytes).
    pub const MAX_SIZE: usize = U64 + 12 * F32;
}

/// Commands to the board.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Allow the thrusters to run (no mission yet: [`BoardStatus::Armed`]).
    Arm,
    /// Thrusters off, mission dropped.
    Disarm,
    /// Start (or restart) a mission: the trajectory's t = 0 is the first control step after.
    StartMission(MissionPlan),
    /// End the mission; the board stays armed.
    StopMission,
    /// Change the fields that are `Some`; the others keep their values.
    SetConfig(ConfigPatch),
    // Protocol 5.
    /// A part of a waypoint mission's upload ([`crate::upload`]); refused while armed.
    Upload(UploadPart),
}

impl Command {
    /// Worst-case postcard size of a `Command` (bytes).
    pub const MAX_SIZE: usize = TAG
        + max(
            MissionPlan::MAX_SIZE,
            max(ConfigPatch::MAX_SIZE, UploadPart::MAX_SIZE),
        );

    /// One command of each variant, in wire order (`EXAMPLES[i]` is variant `i`): what the
    /// link's tests, the supervisor's fuzz generator and the board's tests iterate instead of
    /// counting the variants by hand. A new variant does not compile until
    /// [`wire_index`](Self::wire_index) gives it its index, and the link's tests fail until it
    /// has its example here (`no_command_variant_lacks_an_example`).
    pub const EXAMPLES: [Command; 6] = {
        let examples = [
            Command::Arm,
            Command::Disarm,
            Command::StartMission(MissionPlan::EXAMPLE),
            Command::StopMission,
            Command::SetConfig(ConfigPatch::EMPTY),
            Command::Upload(UploadPart::Chunk(UploadChunk {
                index: 0,
                words: [0.0; CHUNK_WORDS],
            })),
        ];
        let mut i = 0;
        while i < examples.len() {
            assert!(
                examples[i].wire_index() as usize == i,
                "EXAMPLES in wire order"
            );
            i += 1;
        }
        examples
    };

    /// The variant's index on the wire (postcard's enum tag: declaration order).
    pub const fn wire_index(&self) -> u8 {
        match self {
            Command::Arm => 0,
            Command::Disarm => 1,
            Command::StartMission(_) => 2,
            Command::StopMission => 3,
            Command::SetConfig(_) => 4,
            Command::Upload(_) => 5,
        }
    }
}

/// A mission as the board flies it: the wire form of `controller_core::Mission` — the path
/// ([`MissionSpec`]), how its heading is formed and how slowly it is flown (η_d(t/k),
/// k ≥ 1). Convert with `From` both ways ([`crate::mission`]); the receiver validates with
/// `controller_core::Trajectory::new`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MissionPlan {
    /// The path.
    pub path: MissionSpec,
    /// ψ_d: the paper's or the path's course.
    pub heading: Heading,
    /// k ≥ 1 (1: the paper's speed).
    pub time_scale: f32,
}

impl MissionPlan {
    /// Worst-case postcard size of a `MissionPlan` (bytes).
    pub const MAX_SIZE: usize = MissionSpec::MAX_SIZE + Heading::MAX_SIZE + F32;

    /// The paper's 10 m circle, its own heading, k = 1 (the example of
    /// [`Command::StartMission`] in [`Command::EXAMPLES`]; every path kind's example is
    /// `controller_core::TrajectoryKind::EXAMPLES`, through `From`).
    pub const EXAMPLE: MissionPlan = MissionPlan {
        path: MissionSpec::Circle {
            radius: 10.0,
            omega: 0.1,
            depth: 5.0,
        },
        heading: Heading::Paper,
        time_scale: 1.0,
    };
}

/// The wire form of `controller_core::ThrustUnit`, the unit Eqs 31–32 are read in (variant
/// order is the wire format).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ThrustUnit {
    /// Kilogram-force (the default).
    Kgf,
    /// Newtons.
    Newton,
}

impl ThrustUnit {
    /// Worst-case postcard size of a `ThrustUnit` (bytes).
    pub const MAX_SIZE: usize = TAG;
}

/// A mission trajectory and its parameters: the wire form of
/// [`controller_core::TrajectoryKind`], field for field. Convert with `From` both ways
/// ([`crate::mission`]); the receiver validates with `controller_core::Trajectory::new`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MissionSpec {
    /// x = R sin ωt, y = R cos ωt, z = depth, ψ = ωt.
    Circle {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        omega: f32,
        /// z_d (m, positive down).
        depth: f32,
    },
    /// Figure eight: x = A sin ωt, y = A cos(ωt/2), z = depth.
    FigureEight {
        /// A (m).
        amplitude: f32,
        /// ω (rad/s).
        omega: f32,
        /// z_d (m, positive down).
        depth: f32,
    },
    /// Lawn-mower pattern, scaled by s (s = 1: the paper's 30 × 15 case).
    LawnMower {
        /// s (dimensionless).
        scale: f32,
        /// ω (rad/s).
        omega: f32,
        /// z_d (m, positive down).
        depth: f32,
    },
    /// A circle whose depth changes linearly: z = depth + depth_rate·t.
    Helix {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        omega: f32,
        /// z_d at t = 0 (m, positive down).
        depth: f32,
        /// ż_d (m/s, positive = descending).
        depth_rate: f32,
    },
    // Protocol 5.
    /// The waypoint path the board holds from a mission upload ([`crate::upload`]) whose
    /// whole-mission CRC is `crc`: refused unless that upload is verified.
    Waypoints {
        /// [`crate::upload::mission_crc`] of the upload.
        crc: u32,
    },
}

impl MissionSpec {
    /// Worst-case postcard size of a `MissionSpec` (bytes).
    pub const MAX_SIZE: usize = TAG + 4 * F32;
}

/// Control periods a state frame stays valid on a board that was not told otherwise
/// ([`ConfigPatch::stale_periods`]): the third period without a fresh [`Msg::State`] fails
/// safe ([`FailSafeReason::StaleState`]).
pub const DEFAULT_STALE_PERIODS: u8 = 2;

/// A partial configuration change: `None` leaves a setting as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigPatch {
    /// Control-loop rate (Hz).
    pub rate_hz: Option<u32>,
    /// Add Δu (the robust term) or not.
    pub robust: Option<bool>,
    /// Clamp on δ.
    pub delta_max: Option<f32>,
    /// Thruster voltages are clamped to ±`voltage_limit` (V).
    pub voltage_limit: Option<f32>,
    /// Control periods without a fresh [`Msg::State`] before the board fails safe
    /// ([`FailSafeReason::StaleState`]); [`DEFAULT_STALE_PERIODS`] until set.
    pub stale_periods: Option<u8>,
    /// Lockstep: the board runs one control step per received [`Msg::State`] (simulation),
    /// instead of on its own timer.
    pub lockstep: Option<bool>,
    /// The thrust unit of Eqs 31–32 (refused while armed, like every law setting).
    pub thrust_unit: Option<ThrustUnit>,
    /// The thruster mounting, as the reversed-thruster mask of the AUV-150 layout
    /// (`controller_core::effectiveness::ThrusterGeometry::auv150`): bit i set ⇔ thruster i's
    /// positive thrust pushes against its reference axis (+x, +z, +z, +y, +y). Refused while
    /// armed, and with bits above the fifth ([`Refusal::InvalidMounting`]).
    pub reversed_thrusters: Option<u8>,
    /// Which forces the saturation-aware allocator gives up first. Refused while armed, and
    /// when the core refuses a weight ([`Refusal::InvalidPriority`]).
    pub priority: Option<AxisPriority>,
    // Protocol 7: appended field.
    /// The state estimator the law flies on and its noise settings (refused while armed, and
    /// when the core refuses a setting: [`Refusal::ControllerConfig`]).
    pub estimator: Option<EstimatorSettings>,
    // Protocol 8: appended field.
    /// The law's settings (refused while armed, and when the core refuses a setting or the
    /// configuration they make: Assumption 2 β̂ ≤ β, Theorem 2, the loop-rate rule;
    /// [`Refusal::ControllerConfig`]).
    pub law: Option<LawSettings>,
}

/// The wire form of the law's settings of `controller_core::ControllerConfig`, field for field
/// (docs/law.md): the gains of Eq (17), the Lyapunov weights of Theorem 3, β of Assumption 2
/// and Eq (29), the boundary layer μ of Eq (30), which robust law, which ‖b‖ bound enters δ,
/// and the pitch limit. Convert with [`LawSettings::of`] and [`LawSettings::apply`]
/// ([`crate::mission`]); the receiver validates the configuration they make with
/// `controller_core::Controller::new`'s checks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LawSettings {
    /// K₁ = diag(ω²ᵢ) of Eq (17), rows x y z φ θ ψ (roll must be 0).
    pub k1: [f32; 6],
    /// K₂ = diag(2ωᵢ) of Eq (17) (roll must be 0).
    pub k2: [f32; 6],
    /// Q = diag(q₁, q₂) of the per-axis Lyapunov equation (Theorem 3).
    pub q: [f32; 2],
    /// β of Assumption 2 and Eq (29).
    pub beta: f32,
    /// Boundary-layer width μ of Eq (30).
    pub mu: f32,
    /// Theorem 3 (Eq 26) or Theorem 4 (Eq 30).
    pub law: RobustLaw,
    /// Which bound on ‖b‖ enters δ (Eq 29).
    pub b_bound: BBound,
    /// |θ| beyond which the law faults (rad).
    pub pitch_limit: f32,
}

impl LawSettings {
    /// Worst-case postcard size of a `LawSettings` (bytes).
    pub const MAX_SIZE: usize =
        6 * F32 + 6 * F32 + 2 * F32 + F32 + F32 + RobustLaw::MAX_SIZE + BBound::MAX_SIZE + F32;
}

/// The wire form of `controller_core::law::RobustLaw` (variant order is the wire format).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RobustLaw {
    /// Theorem 3, Eq (26): Δu = −δ w/‖w‖.
    Discontinuous,
    /// Theorem 4, Eq (30): the boundary layer of width μ.
    BoundaryLayer,
}

impl RobustLaw {
    /// Worst-case postcard size of a `RobustLaw` (bytes).
    pub const MAX_SIZE: usize = TAG;
}

/// The wire form of `controller_core::BBound` (variant order is the wire format).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BBound {
    /// c_b · max(1, 1/|cos θ|) over the controlled rows (the default).
    ControlledRows,
    /// The literal ‖M̄⁻¹‖ bound.
    Literal,
}

impl BBound {
    /// Worst-case postcard size of a `BBound` (bytes).
    pub const MAX_SIZE: usize = TAG;
}

/// The wire form of `controller_core::EstimatorConfig` (docs/law.md#the-state-estimator):
/// whether the law flies on the estimate, and σₚ, σᵥ, σₐ per axis of η. The board computes
/// the filter's gains from them with the core's f32 code (Choice 361), so a board and the
/// host's SIL given the same settings fly the same gains, bit for bit. Convert with `From`
/// both ways ([`crate::mission`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EstimatorSettings {
    /// The per-axis steady-state Kalman filter is on (false: the law flies on the solution
    /// as told).
    pub kalman: bool,
    /// σₚ (m, rad).
    pub position_sigma: [f32; 6],
    /// σᵥ (m/s, rad/s).
    pub velocity_sigma: [f32; 6],
    /// σₐ (m/s², rad/s²).
    pub accel_sigma: [f32; 6],
}

impl EstimatorSettings {
    /// Worst-case postcard size of an `EstimatorSettings` (bytes).
    pub const MAX_SIZE: usize = BOOL + 18 * F32;
}

/// The wire form of `controller_core::allocation::AxisPriority`: per row of τ = [X Y Z K M N],
/// the rank (higher is met first) and the least-squares weight between axes of equal rank
/// (finite and > 0 on the actuated axes; the roll entries are carried and not used). Convert
/// with `From` both ways ([`crate::mission`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisPriority {
    /// Priority of each axis; higher is more important.
    pub rank: [u8; 6],
    /// Least-squares weight of each axis.
    pub weight: [f32; 6],
}

impl AxisPriority {
    /// Worst-case postcard size of an `AxisPriority` (bytes).
    pub const MAX_SIZE: usize = 6 * U8 + 6 * F32;
}

impl ConfigPatch {
    /// Worst-case postcard size of a `ConfigPatch` (bytes).
    pub const MAX_SIZE: usize = option(U32)
        + option(BOOL)
        + option(F32)
        + option(F32)
        + option(U8)
        + option(BOOL)
        + option(ThrustUnit::MAX_SIZE)
        + option(U8)
        + option(AxisPriority::MAX_SIZE)
        + option(EstimatorSettings::MAX_SIZE)
        + option(LawSettings::MAX_SIZE);

    /// The patch of the longest encoding: every field `Some`, every varint at its maximum,
    /// every f32 at its largest magnitude. Its `SetConfig` in an envelope with
    /// `seq = u16::MAX` is [`Envelope::MAX_SIZE`] bytes and, signed, the longest frame,
    /// `MAX_FRAME` (protocol 8; the link's tests check both).
    pub const LARGEST: ConfigPatch = ConfigPatch {
        rate_hz: Some(u32::MAX),
        robust: Some(true),
        delta_max: Some(f32::MAX),
        voltage_limit: Some(f32::MAX),
        stale_periods: Some(u8::MAX),
        lockstep: Some(true),
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(u8::MAX),
        priority: Some(AxisPriority {
            rank: [u8::MAX; 6],
            weight: [f32::MAX; 6],
        }),
        estimator: Some(EstimatorSettings {
            kalman: true,
            position_sigma: [f32::MAX; 6],
            velocity_sigma: [f32::MAX; 6],
            accel_sigma: [f32::MAX; 6],
        }),
        law: Some(LawSettings {
            k1: [f32::MAX; 6],
            k2: [f32::MAX; 6],
            q: [f32::MAX; 2],
            beta: f32::MAX,
            mu: f32::MAX,
            law: RobustLaw::BoundaryLayer,
            b_bound: BBound::Literal,
            pitch_limit: f32::MAX,
        }),
    };

    /// Changes nothing.
    pub const EMPTY: ConfigPatch = ConfigPatch {
        rate_hz: None,
        robust: None,
        delta_max: None,
        voltage_limit: None,
        stale_periods: None,
        lockstep: None,
        thrust_unit: None,
        reversed_thrusters: None,
        priority: None,
        estimator: None,
        law: None,
    };
}

/// [`Telemetry::reversed_thrusters`] of a board whose geometry is not the AUV-150 layout with
/// some thrusters reversed: every bit set, which no valid mask has (bits above the fifth).
pub const NOT_AUV150: u8 = u8::MAX;

/// The board's report.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Telemetry {
    /// Board control tick this report belongs to.
    pub tick: u64,
    /// What the board is doing.
    pub status: BoardStatus,
    /// Voltage per thruster (V), order [main, vert fore, vert aft, horz fore, horz aft].
    pub voltages: [f32; THRUSTERS],
    /// Achieved thrust per thruster (N), same order.
    pub thrusts: [f32; THRUSTERS],
    /// Commanded body force τ = [X Y Z K M N] (N, N m): what ideal actuators would apply
    /// (processor in the loop with ideal actuators).
    pub tau: [f32; 6],
    /// Bit i set: thruster i saturated.
    pub saturated: u8,
    /// δ(e, t) after the clamp.
    pub delta: f32,
    /// The δ clamp limited Δu this step.
    pub delta_clamped: bool,
    /// ‖w‖ = ‖BᵀPe‖.
    pub w_norm: f32,
    /// 0: no controller fault; otherwise the fault's code, [`controller_core::Fault::code`]
    /// (read it back with [`Telemetry::fault`]). A fault that latched the fail-safe is
    /// reported in every frame until the board is re-armed (with [`Telemetry::latched`]).
    pub controller_fault: u8,
    /// Control steps that missed their deadline since boot.
    pub loop_overruns: u32,
    /// Longest control update since boot, in the board's timer ticks (firmware-defined).
    pub worst_update_ticks: u32,
    /// Frames received and accepted since boot.
    pub rx_frames: u32,
    /// Frames received and rejected since boot (any [`LinkError`](crate::LinkError)).
    pub rx_errors: u32,
    /// `seq` of the last [`Msg::State`] the board accepted.
    pub last_state_seq: u16,
    // Protocol 2: appended fields.
    /// The latched fail-safe reason, in every frame from the period it latched until the board
    /// is re-armed (disarm, then arm): also while disarmed.
    pub latched: Option<FailSafeReason>,
    /// Commands refused since boot (each changed nothing).
    pub refused_commands: u32,
    /// Why the last refused command was refused (`None` before the first).
    pub last_refusal: Option<Refusal>,
    /// Frames dropped since boot as repeated, old or out of order: a sequence number that is
    /// not newer ([`crate::seq`]), or a lock-step state frame off the mission clock. They
    /// never restart the stale-state timer.
    pub rx_stale: u32,
    /// Frames refused since boot for their authentication ([`crate::sign`]; also counted in
    /// `rx_errors`).
    pub rx_auth_errors: u32,
    /// `seq` of the last frame (any message) the board accepted; a restarted navigation
    /// computer continues from the next number ([`crate::seq`]).
    pub last_rx_seq: u16,
    /// The board's link has signing on (it refuses unsigned frames).
    pub signing: bool,
    // Protocol 3: appended fields.
    /// The thrust unit the board reads Eqs 31–32 in.
    pub thrust_unit: ThrustUnit,
    /// The board's thruster mounting, as [`ConfigPatch::reversed_thrusters`]; [`NOT_AUV150`]
    /// for a board whose geometry is not the AUV-150 layout.
    pub reversed_thrusters: u8,
    // Protocol 4: appended fields.
    /// Authentic frames refused since boot because their timestamp ran too far ahead
    /// ([`crate::sign::AuthError::Ahead`]: above the board's ceiling, or beyond the lead it
    /// allows over the last accepted stamp; also counted in `rx_auth_errors` and `rx_errors`).
    /// A navigation computer whose clock jumped sees it rise, and the board fail safe.
    pub rx_ahead: u32,
    // Protocol 5: appended fields.
    /// What the board holds of a mission upload: the acknowledgement the sender resends by.
    pub upload: UploadStatus,
    // Protocol 6: appended fields.
    /// [`ConfigPatch::digest`] of the board's whole configuration
    /// ([`ConfigPatch::whole`]): a navigation computer that sent a whole patch confirms with it
    /// that the board flies every field it set ([`ConfigPatch::confirm`]).
    pub config_digest: u32,
}

impl Telemetry {
    /// The report of the longest encoding: every varint at its maximum, every f32 at its largest
    /// magnitude, every `Option` `Some`: the longest frame the board sends (the link's tests
    /// check its size, [`Telemetry::MAX_SIZE`]); the board's self-test times its encoding as the
    /// worst case. Since protocol 8 the longest message is a whole `SetConfig`
    /// ([`ConfigPatch::LARGEST`]).
    pub const LARGEST: Telemetry = Telemetry {
        tick: u64::MAX,
        status: BoardStatus::FailSafe(FailSafeReason::Overrun),
        voltages: [f32::MAX; THRUSTERS],
        thrusts: [f32::MIN; THRUSTERS],
        tau: [f32::MAX; 6],
        saturated: u8::MAX,
        delta: f32::MAX,
        delta_clamped: true,
        w_norm: f32::MAX,
        controller_fault: u8::MAX,
        loop_overruns: u32::MAX,
        worst_update_ticks: u32::MAX,
        rx_frames: u32::MAX,
        rx_errors: u32::MAX,
        last_state_seq: u16::MAX,
        latched: Some(FailSafeReason::Overrun),
        refused_commands: u32::MAX,
        last_refusal: Some(Refusal::ControllerConfig),
        rx_stale: u32::MAX,
        rx_auth_errors: u32::MAX,
        last_rx_seq: u16::MAX,
        signing: true,
        thrust_unit: ThrustUnit::Newton,
        reversed_thrusters: u8::MAX,
        rx_ahead: u32::MAX,
        upload: UploadStatus {
            crc: u32::MAX,
            chunks: u8::MAX,
            received: u32::MAX,
            verified: true,
        },
        config_digest: u32::MAX,
    };
}

impl Telemetry {
    /// Worst-case postcard size of a `Telemetry` (bytes).
    pub const MAX_SIZE: usize = U64
        + BoardStatus::MAX_SIZE
        + 5 * F32
        + 5 * F32
        + 6 * F32
        + U8
        + F32
        + BOOL
        + F32
        + U8
        + 4 * U32
        + U16
        + option(FailSafeReason::MAX_SIZE)
        + U32
        + option(Refusal::MAX_SIZE)
        + 2 * U32
        + U16
        + BOOL
        + ThrustUnit::MAX_SIZE
        + U8
        + U32
        + UploadStatus::MAX_SIZE
        + U32;

    /// The controller fault this report carries (`None`: no fault, or a code this crate does
    /// not know).
    pub fn fault(&self) -> Option<controller_core::Fault> {
        controller_core::Fault::from_code(self.controller_fault)
    }
}

/// What the board is doing. [`as_str`](Self::as_str) / `Display` name it for logs and
/// reports, e.g. `"running"`, `"fail-safe: stale state"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BoardStatus {
    /// Thrusters off; waiting for [`Command::Arm`].
    Disarmed,
    /// Armed, no mission: thrusters off.
    Armed,
    /// Flying a mission.
    Running,
    /// Thrusters forced off, for the reason given.
    FailSafe(FailSafeReason),
}

impl BoardStatus {
    /// Worst-case postcard size of a `BoardStatus` (bytes).
    pub const MAX_SIZE: usize = TAG + FailSafeReason::MAX_SIZE;
}

/// Why the board failed safe. The discriminant is the reason's byte on the wire (postcard's
/// variant index, declaration order); a test holds the two equal.
///
/// Disarming or stopping the mission is not a fail-safe (the board reports
/// [`BoardStatus::Disarmed`] / [`BoardStatus::Armed`]), so those have no reason here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum FailSafeReason {
    /// No fresh [`Msg::State`] within `stale_periods` control periods.
    StaleState = 0,
    /// The controller reported a fault (see [`Telemetry::controller_fault`]).
    ControllerFault = 1,
    /// The control loop overran its deadline.
    Overrun = 2,
}

impl FailSafeReason {
    /// Worst-case postcard size of a `FailSafeReason` (bytes).
    pub const MAX_SIZE: usize = TAG;
}

/// The names of the board's states, once: [`FailSafeReason::as_str`] and
/// [`BoardStatus::as_str`] (`"fail-safe: "` and the reason) both come from this list.
macro_rules! status_names {
    ($($reason:ident => $name:literal),+ $(,)?) => {
        impl FailSafeReason {
            /// Every reason, in wire order.
            pub const ALL: [FailSafeReason; [$(FailSafeReason::$reason),+].len()] =
                [$(FailSafeReason::$reason),+];

            /// Short name for logs and reports, e.g. `"stale state"`.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $(FailSafeReason::$reason => $name,)+
                }
            }
        }

        impl BoardStatus {
            /// Short name for logs and reports: `"disarmed"`, `"armed"`, `"running"`, or
            /// `"fail-safe: "` and the reason, e.g. `"fail-safe: stale state"`.
            pub const fn as_str(self) -> &'static str {
                match self {
                    BoardStatus::Disarmed => "disarmed",
                    BoardStatus::Armed => "armed",
                    BoardStatus::Running => "running",
                    $(BoardStatus::FailSafe(FailSafeReason::$reason) => {
                        concat!("fail-safe: ", $name)
                    })+
                }
            }
        }
    };
}

status_names! {
    StaleState => "stale state",
    ControllerFault => "controller fault",
    Overrun => "overrun",
}

impl core::fmt::Display for FailSafeReason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl core::fmt::Display for BoardStatus {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}
