//! Why the board refused a command: [`Refusal`], reported in every telemetry frame as
//! [`Telemetry::last_refusal`](crate::Telemetry::last_refusal) next to the count
//! [`Telemetry::refused_commands`](crate::Telemetry::refused_commands).
//!
//! A refused command changes nothing on the board (a `SetConfig` is validated whole, then
//! applied whole or not at all). Which command is refused in which state is the state table of
//! firmware/README.md.

/// Why a command was refused. The discriminant is the reason's byte on the wire (postcard's
/// variant index, declaration order); a test holds the two equal. [`as_str`](Self::as_str) /
/// `Display` name it for logs and reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Refusal {
    /// `StartMission` while disarmed: arm first.
    NotArmed = 0,
    /// `SetConfig` while armed: nothing that the loop or the fail-safe depends on changes in
    /// flight; disarm first.
    WhileArmed = 1,
    /// `Arm` or `StartMission` while a fail-safe is latched: only disarm, then arm, clears it.
    Latched = 2,
    /// `StartMission` while a mission runs: stop it first (the trajectory is never swapped in
    /// flight).
    MissionRunning = 3,
    /// `StartMission` with parameters the core refuses (`controller_core::Trajectory::new`).
    InvalidMission = 4,
    /// `SetConfig` with `voltage_limit` above the board's supply voltage.
    VoltageAboveSupply = 5,
    /// `SetConfig` with `rate_hz` above the board's maximum loop rate.
    RateTooHigh = 6,
    /// `SetConfig` whose stale-state limit is 0 periods, or longer than the board's limit in
    /// time at the resulting loop rate.
    StaleLimit = 7,
    /// `SetConfig` whose resulting controller configuration the core refuses
    /// (`controller_core::Controller::new`: e.g. the loop-rate rule, or δ_max ≤ 0).
    ControllerConfig = 8,
    // Protocol 3.
    /// `StartMission` whose time scale the core refuses (`controller_core::Trajectory::new`:
    /// k must be finite and in [1, `Trajectory::MAX_TIME_SCALE`]).
    InvalidTimeScale = 9,
    /// `StartMission` with the tangent heading on a path (at its time scale) whose horizontal
    /// speed falls below `Trajectory::MIN_TANGENT_SPEED`: the course is undefined there.
    TangentTooSlow = 10,
    /// `SetConfig` whose reversed-thruster mask has a bit above the fifth (there are five
    /// thrusters).
    InvalidMounting = 11,
    /// `SetConfig` whose axis priority the core refuses (a weight of an actuated axis that is
    /// not finite and > 0).
    InvalidPriority = 12,
    // Protocol 5.
    /// `Upload` whose `Begin` has counts the board cannot hold (fewer than 2 or more than
    /// `MAX_WAYPOINTS` points, more than `MAX_PARTS` speeds), or a chunk with no upload begun
    /// or an index past its last.
    InvalidUpload = 13,
    /// The last chunk of an upload completed a mission that does not match its CRC: every
    /// chunk is dropped, to be sent again.
    UploadCrc = 14,
    /// `StartMission` of an uploaded path with no verified upload of that CRC, or with a
    /// heading or time scale other than the upload's.
    NoUpload = 15,
}

impl Refusal {
    /// Worst-case postcard size of a `Refusal` (bytes).
    pub const MAX_SIZE: usize = 1;
}

/// The names, once: [`Refusal::as_str`], [`Refusal::ALL`] and [`Refusal::from_name`] come from
/// this list. A name never contains a comma (the state table of firmware/README.md lists them
/// in comma-separated cells).
macro_rules! refusal_names {
    ($($reason:ident => $name:literal),+ $(,)?) => {
        impl Refusal {
            /// Every reason, in wire order.
            pub const ALL: [Refusal; [$(Refusal::$reason),+].len()] = [$(Refusal::$reason),+];

            /// Short name for logs and reports, e.g. `"fail-safe latched"`.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $(Refusal::$reason => $name,)+
                }
            }
        }
    };
}

refusal_names! {
    NotArmed => "not armed",
    WhileArmed => "while armed",
    Latched => "fail-safe latched",
    MissionRunning => "mission running",
    InvalidMission => "invalid mission",
    VoltageAboveSupply => "voltage above supply",
    RateTooHigh => "rate too high",
    StaleLimit => "stale limit out of range",
    ControllerConfig => "controller config invalid",
    InvalidTimeScale => "invalid time scale",
    TangentTooSlow => "too slow for tangent heading",
    InvalidMounting => "invalid thruster mounting",
    InvalidPriority => "invalid axis priority",
    InvalidUpload => "invalid upload",
    UploadCrc => "upload CRC mismatch",
    NoUpload => "no such upload",
}

impl Refusal {
    /// The reason named `name` ([`as_str`](Self::as_str)), if any.
    pub fn from_name(name: &str) -> Option<Refusal> {
        Refusal::ALL.into_iter().find(|r| r.as_str() == name)
    }
}

impl core::fmt::Display for Refusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}
