//! What the supervisor's fuzz target (`fuzz/fuzz_targets/supervisor.rs`) and its stable
//! proptest twin (`firmware/tests/supervisor_fuzz.rs`) share, as source (both `#[path]`-include
//! this file): the reading of arbitrary bytes as a sequence of link events and control periods,
//! the navigation computer (and its forgers) that turn them into real frames, an independent
//! model of what the board may accept, and the invariants checked after every event.
//!
//! Input layout: byte 0 bit 0 turns the board's signing on; then ops until the input ends, each
//! an op byte (`b % OPS`, the `OP_*` constants) and its arguments (missing bytes read as 0):
//!
//! | op | event |
//! |----|-------|
//! | `OP_STATE` | a state frame: seq step `s` (1 byte: `s = 0` → +1, else `s − 128` as i8-ish, or a 2-byte jump when `s = 255`), tick mode, value, perturbation |
//! | `OP_COMMAND` | a command: kind, then its arguments (missions and patches from fuzz bytes, biased to valid ones) |
//! | `OP_TELEMETRY` | a telemetry frame sent to the board (the wrong direction) |
//! | `OP_PERIOD` | one control period; bit 0 of the argument: the previous period overran |
//! | `OP_REPLAY` | an earlier frame (of the last 8) sent again, byte for byte |
//! | `OP_CORRUPT` | an earlier frame with one bit flipped |
//! | `OP_RAW` | up to 64 raw bytes (length byte), then a delimiter |
//! | `OP_PERIODS` | up to 16 control periods in a row |
//!
//! Every frame the harness builds is signed one of five ways (an argument byte): as the board
//! expects (signed with the key if signing is on, else unsigned), the other way, with a wrong
//! key, for the wrong direction (a reflected board frame), or by a restarted signer (a key
//! holder) with a timestamp from the input: anywhere in 48 bits, around the lead the board
//! allows past the harness's last stamp, around the board's ceiling, or old.
//!
//! Invariants (the issue's, and what they imply), checked against the [`Model`], which learns
//! only from what the harness sent and from the supervisor's public counters:
//! - **No panic**, and every period's voltages are finite and within `voltage_limit`.
//! - **Only in-order, authentic frames reach the supervisor:** a frame the supervisor accepts
//!   (`rx_frames` + 1) has a sequence number newer than the last accepted one (RFC 1982 within
//!   [`SEQ_WINDOW`]); with signing on, every frame that reaches the supervisor at all (accepted
//!   or dropped as stale) was signed with the key, for this direction, with a timestamp above
//!   every earlier one; with signing off, none was signed. In lock-step, an accepted state frame
//!   during a mission is on the mission clock (its tick rises by 1 ..= the periods run since the
//!   last one). Every frame the harness built is counted exactly once (accepted, stale or error).
//! - **Timestamps (Choices 95–96):** with signing on, an authentic frame reaches the
//!   supervisor exactly when its timestamp is above the last accepted, at most
//!   [`CEILING`], and (after the first) at most [`MAX_LEAD`] plus the time the board counted
//!   since (one period length per period) above the last accepted; an authentic frame refused
//!   for being ahead is counted in `rx_ahead` (and telemetry reports the count), nothing else
//!   is. **The board can always sign:** every period's telemetry encodes, and, signed, the
//!   navigation computer's end verifies it and its stamp is at most `CEILING` + the periods run,
//!   so whatever a key holder sent, the board has at least `RESERVE` − periods stamps left
//!   (174 years at 200 Hz).
//! - **Thrusters off unless armed with a fresh, in-order state:** a period with any voltage ≠ 0
//!   (or reported `Running`) needs the model armed, with a mission, nothing latched, no overrun,
//!   and an accepted state frame at most `stale_periods` periods old, accepted since the
//!   mission started.
//! - **A latched fail-safe never clears without disarm + arm:** once a period reports
//!   `FailSafe(r)`, every telemetry frame reports `latched = r` and no thrust, and a lone `Arm`
//!   is refused, until an accepted `Disarm` followed by an accepted `Arm`.
//! - **Commands do what the state table says, or nothing:** a refused `SetConfig` changes no
//!   setting (atomic), an accepted one happened disarmed; an accepted `StartMission` happened
//!   armed, unlatched and without a mission; `Disarm` and `StopMission` are never refused and
//!   drop the mission; a refused `Arm` happened only armed and latched.

#![allow(dead_code)]

use auv_link::seq::SEQ_WINDOW;
use auv_link::sign::{
    Direction, LinkKey, Signer, Verifier, CEILING, MAX_LEAD, MAX_TIMESTAMP, UNITS_PER_SECOND,
};
use auv_link::{
    decode_frame, decode_frame_signed, encode, encode_signed, BoardStatus, Command, ConfigPatch,
    Envelope, FailSafeReason, Heading, MissionPlan, MissionSpec, MissionUpload, Msg, StateFrame,
    Telemetry, ThrustUnit, UploadChunk, UploadHeader, UploadPart, DEFAULT_STALE_PERIODS, MAX_FRAME,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Table1Case, Trajectory, TrajectoryKind};
use firmware::board::{self, LinkBuffers};
use firmware::supervisor::{BoardInfo, Supervisor};

pub const OP_STATE: u8 = 0;
pub const OP_COMMAND: u8 = 1;
pub const OP_TELEMETRY: u8 = 2;
pub const OP_PERIOD: u8 = 3;
pub const OP_REPLAY: u8 = 4;
pub const OP_CORRUPT: u8 = 5;
pub const OP_RAW: u8 = 6;
pub const OP_PERIODS: u8 = 7;
/// Number of ops (`op byte % OPS`).
pub const OPS: u8 = 8;

/// Command kinds (the byte after `OP_COMMAND`, `% Command::EXAMPLES.len()`): each command's
/// wire index, its place in [`Command::EXAMPLES`].
pub const CMD_ARM: u8 = Command::Arm.wire_index();
pub const CMD_DISARM: u8 = Command::Disarm.wire_index();
pub const CMD_START: u8 = Command::StartMission(MissionPlan::EXAMPLE).wire_index();
pub const CMD_STOP: u8 = Command::StopMission.wire_index();
pub const CMD_CONFIG: u8 = Command::SetConfig(ConfigPatch::EMPTY).wire_index();
/// A part of a mission upload: of a valid three-point mission, or from fuzz bytes.
pub const CMD_UPLOAD: u8 = Command::Upload(UploadPart::Chunk(UploadChunk {
    index: 0,
    words: [0.0; auv_link::upload::CHUNK_WORDS],
}))
.wire_index();

/// How a frame is signed (the signing byte, `% 5`).
pub const SIGN_AS_EXPECTED: u8 = 0;
pub const SIGN_OTHER_WAY: u8 = 1;
pub const SIGN_WRONG_KEY: u8 = 2;
pub const SIGN_WRONG_DIRECTION: u8 = 3;
pub const SIGN_RESTARTED: u8 = 4;

/// The board's supply (V), as the boards state it.
pub const SUPPLY: f32 = controller_core::DEFAULT_V_LIMIT;
/// The link key of the signed runs, and a forger's.
pub const KEY: LinkKey = LinkKey::new([0x5C; 32]);
pub const WRONG_KEY: LinkKey = LinkKey::new([0x5D; 32]);

/// What one run did, so that tests can check the invariants were not vacuous.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    pub frames_sent: u32,
    pub frames_accepted: u32,
    pub periods: u32,
    pub periods_on: u32,
    pub latches: u32,
    pub rearms_after_latch: u32,
    pub refusals: u32,
    /// Authentic frames refused as too far ahead.
    pub ahead: u32,
    /// Frames of a restarted signer (a key holder's own stamp) that passed the link.
    pub restarted_taken: u32,
}

#[path = "supervisor_ops/inputs.rs"]
mod inputs;
#[path = "supervisor_ops/link.rs"]
mod link;
#[path = "supervisor_ops/model.rs"]
mod model;

// Not every includer uploads.
#[allow(unused_imports)]
pub use inputs::three_points;
use inputs::{command, next_seq, state_frame, Bytes};
use link::Known;
use model::{settings, Model};

/// The default controller (built once: `Controller::new` takes the bounds over the box).
fn controller() -> Controller {
    static C: std::sync::OnceLock<Controller> = std::sync::OnceLock::new();
    C.get_or_init(|| Controller::new(ControllerConfig::default()).expect("default config"))
        .clone()
}

struct Harness {
    sup: Supervisor,
    link: LinkBuffers,
    signing: bool,
    seq: u16,
    signer: Signer,
    forger: Signer,
    reflector: Signer,
    /// The navigation computer's end of the board's telemetry.
    nav: Verifier,
    /// The last frames sent, and what each is (for replays).
    history: Vec<(Vec<u8>, Known)>,
    model: Model,
    stats: Stats,
}

/// Runs the input through a fresh supervisor and checks every invariant (module docs); panics
/// on a violation. Returns what the run did.
pub fn run(data: &[u8]) -> Stats {
    let mut input = Bytes::new(data);
    let signing = input.u8() & 1 == 1;
    let mut h = Harness {
        sup: Supervisor::new(
            controller(),
            BoardInfo {
                supply_voltage: SUPPLY,
                signing,
            },
        ),
        link: if signing {
            LinkBuffers::signed(&KEY)
        } else {
            LinkBuffers::new()
        },
        signing,
        seq: 0,
        signer: Signer::new(&KEY, Direction::ToBoard),
        forger: Signer::new(&WRONG_KEY, Direction::ToBoard),
        reflector: Signer::new(&KEY, Direction::FromBoard),
        nav: Verifier::new(&KEY, Direction::FromBoard),
        history: Vec::new(),
        model: Model::new(),
        stats: Stats::default(),
    };
    // Bounded work per input whatever its length.
    let mut ops = 0;
    while input.more() && ops < 512 {
        ops += 1;
        match input.u8() % OPS {
            OP_STATE => {
                let seq = next_seq(&mut h, &mut input);
                let s = state_frame(&h, &mut input);
                let how = input.u8();
                h.send(seq, Msg::State(s), how, &mut input);
            }
            OP_COMMAND => {
                let seq = next_seq(&mut h, &mut input);
                let c = command(&mut input);
                let how = input.u8();
                h.send(seq, Msg::Command(c), how, &mut input);
            }
            OP_TELEMETRY => {
                let seq = next_seq(&mut h, &mut input);
                let how = input.u8();
                let t = h.period(false);
                h.send(seq, Msg::Telemetry(t), how, &mut input);
            }
            OP_PERIOD => {
                let overrun = input.u8() & 1 == 1;
                h.period(overrun);
            }
            OP_PERIODS => {
                for _ in 0..=(input.u8() % 16) {
                    h.period(false);
                }
            }
            OP_REPLAY => {
                if !h.history.is_empty() {
                    let i = usize::from(input.u8()) % h.history.len();
                    let (frame, known) = h.history[i].clone();
                    h.deliver(&frame, known);
                    h.remember(frame, known);
                }
            }
            OP_CORRUPT => {
                if !h.history.is_empty() {
                    let i = usize::from(input.u8()) % h.history.len();
                    let mut frame = h.history[i].0.clone();
                    // Not the delimiter: every delivery ends with one, so the decoder is
                    // aligned on frames when the next one starts.
                    let bit = usize::from(input.u16()) % (8 * (frame.len() - 1));
                    frame[bit / 8] ^= 1 << (bit % 8);
                    h.raw(&frame);
                }
            }
            _ => {
                let n = usize::from(input.u8() % 65);
                let mut bytes = input.take(n).to_vec();
                bytes.push(0);
                h.raw(&bytes);
            }
        }
    }
    h.stats
}
