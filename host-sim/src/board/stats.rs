//! The link and board figures of one run with a board in the loop: frames, the board's own
//! counters as its telemetry reports them, fail-safe entries and exits, a mission upload's
//! cost, real-time timing.

use auv_link::Telemetry;
use firmware_images::qemu_clock::INSTRUCTIONS_PER_TICK;
use serde::{Deserialize, Serialize};

use super::error::unit_name;
use super::pacing::{Pacing, RealTimeStats};

/// Whether the board entered or left fail-safe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FailSafeEventKind {
    Enter,
    Exit,
}

/// A change of the board's fail-safe state, as reported by its telemetry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FailSafeEvent {
    /// Control tick (the simulator's period) of the change.
    pub tick: u64,
    /// Its time (s).
    pub t: f64,
    /// "enter" or "exit".
    pub kind: FailSafeEventKind,
    /// Enter: the reason's name ([`auv_link::FailSafeReason::as_str`], e.g. `"stale state"`); exit: the
    /// status the board left fail-safe for, as its Rust name (e.g. `"Running"`).
    pub reason: String,
}

/// Link and board figures of one run with a board in the loop (PIL or HIL).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BoardStats {
    pub state_frames_sent: u64,
    pub telemetry_frames: u64,
    pub wall_seconds: f64,
    /// State frames per wall-clock second.
    pub frames_per_second: f64,
    /// Longest `update` the board measured, in instructions (`-icount shift=0`): meaningful
    /// for the QEMU image under `-icount` only (PIL; HIL lock-step against QEMU's pty), else
    /// see [`BoardStats::worst_update_board_ticks`].
    pub worst_update_instructions: u64,
    pub board_rx_errors: u32,
    pub board_loop_overruns: u32,
    pub rearms: u32,
    pub failsafe_events: Vec<FailSafeEvent>,
    /// The waypoint mission's upload, if it had one.
    #[serde(default)]
    pub upload: Option<UploadStats>,
    /// The link was signed (both ends).
    #[serde(default)]
    pub signed: bool,
    /// Frames the board dropped as repeated, old or off its mission clock (its `rx_stale`).
    #[serde(default)]
    pub board_rx_stale: u32,
    /// Frames the board refused for their authentication (its `rx_auth_errors`).
    #[serde(default)]
    pub board_rx_auth_errors: u32,
    /// Of those, authentic frames stamped too far ahead (its `rx_ahead`: this end's clock
    /// jumped ahead of the board's count, auv_link::sign).
    #[serde(default)]
    pub board_rx_ahead: u32,
    /// Commands the board refused, and the last reason ([`auv_link::Refusal::as_str`]).
    #[serde(default)]
    pub board_refused_commands: u32,
    #[serde(default)]
    pub board_last_refusal: Option<String>,
    /// Telemetry frames this end refused: undecodable, badly signed, or out of sequence.
    #[serde(default)]
    pub telemetry_refused: u64,
    /// The thrust unit of Eqs 31–32 the board reported flying (`"kgf"` or `"newton"`), and
    /// its thruster mounting as the reversed-thruster mask (`Telemetry::reversed_thrusters`).
    #[serde(default)]
    pub board_thrust_unit: Option<String>,
    #[serde(default)]
    pub board_reversed_thrusters: Option<u8>,
    /// The longest `update` in the board's own timer unit (QEMU: SysTick counts of
    /// `INSTRUCTIONS_PER_TICK` instructions; the STM32: CPU cycles at 168 MHz).
    #[serde(default)]
    pub worst_update_board_ticks: u64,
    /// What carried the link: `"tcp"` (PIL) or the serial port and its baud rate.
    #[serde(default)]
    pub link: String,
    /// How the run was paced.
    #[serde(default)]
    pub pacing: Pacing,
    /// The timing of a real-time run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub realtime: Option<RealTimeStats>,
}

/// What a mission upload cost on the link (upload.rs).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct UploadStats {
    /// The mission's CRC (`StartMission` names it).
    pub crc: u32,
    /// Chunks of the mission.
    pub chunks: u32,
    /// Frames sent (the `Begin`, every chunk, every resend).
    pub frames: u32,
    /// Their bytes on the wire.
    pub bytes: u64,
    /// Rounds until the board verified it (1: nothing lost).
    pub rounds: u32,
    /// Chunks sent again.
    pub resent: u32,
    /// Wall-clock time from the `Begin` to the board's verification (s).
    pub seconds: f64,
    /// Each round as it went (the flight log's `/board/upload`, Choice 382).
    #[serde(skip)]
    pub round_log: Vec<crate::sim::UploadRound>,
}

impl BoardStats {
    /// The board's own counters, as telemetry frame `t` reports them.
    pub(super) fn reported(&mut self, t: &Telemetry) {
        self.board_rx_errors = t.rx_errors;
        self.board_rx_stale = t.rx_stale;
        self.board_rx_auth_errors = t.rx_auth_errors;
        self.board_rx_ahead = t.rx_ahead;
        self.board_refused_commands = t.refused_commands;
        self.board_last_refusal = t.last_refusal.map(|r| r.as_str().to_string());
        self.board_loop_overruns = t.loop_overruns;
        self.board_thrust_unit = Some(unit_name(t.thrust_unit).to_string());
        self.board_reversed_thrusters = Some(t.reversed_thrusters);
        self.worst_update_board_ticks = u64::from(t.worst_update_ticks);
        self.worst_update_instructions = t.worst_update_ticks as u64 * INSTRUCTIONS_PER_TICK as u64;
    }
}

impl FailSafeEventKind {
    /// `"enter"` or `"exit"` (as in the JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            FailSafeEventKind::Enter => "enter",
            FailSafeEventKind::Exit => "exit",
        }
    }
}
