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
use controller_core::{Controller, ControllerConfig, Table1Case, Trajectory};
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

/// Command kinds (the byte after `OP_COMMAND`, `% 6`).
pub const CMD_ARM: u8 = 0;
pub const CMD_DISARM: u8 = 1;
pub const CMD_START: u8 = 2;
pub const CMD_STOP: u8 = 3;
pub const CMD_CONFIG: u8 = 4;
/// A part of a mission upload: of a valid three-point mission, or from fuzz bytes.
pub const CMD_UPLOAD: u8 = 5;

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

/// Reads the input; missing bytes are 0.
struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
}

impl Bytes<'_> {
    fn more(&self) -> bool {
        self.at < self.data.len()
    }
    fn u8(&mut self) -> u8 {
        let b = self.peek_u8();
        self.at += 1;
        b
    }
    /// The next byte, without taking it.
    fn peek_u8(&self) -> u8 {
        self.data.get(self.at).copied().unwrap_or(0)
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | u64::from(self.u32()) << 32
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    fn take(&mut self, n: usize) -> &[u8] {
        let start = self.at.min(self.data.len());
        let end = (start + n).min(self.data.len());
        self.at = start + n;
        &self.data[start..end]
    }
}

/// How a frame the harness built was authenticated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Auth {
    /// No signature.
    Unsigned,
    /// Signed with the key, for the board, with this timestamp.
    Good(u64),
    /// Signed, but not in a way the board may accept (wrong key or direction).
    Forged,
}

/// A frame the harness built: its envelope and how it was signed.
type Known = Option<(Envelope, Auth)>;

/// What the board may have done: learnt only from the frames sent and the supervisor's public
/// counters and telemetry.
#[derive(Clone, Copy, Debug)]
struct Model {
    armed: bool,
    mission: bool,
    lockstep: bool,
    stale_periods: u8,
    latched: Option<FailSafeReason>,
    /// Disarmed since the latch (the next accepted `Arm` clears it).
    disarmed_since_latch: bool,
    last_seq: Option<u16>,
    last_timestamp: Option<u64>,
    /// Time the board counted since `last_timestamp` was accepted (timestamp units).
    counted: u64,
    /// Authentic frames refused as too far ahead.
    ahead: u32,
    /// Periods run since the last accepted state frame (`None`: none, or none since the
    /// mission started).
    periods_since_state: Option<u64>,
    /// Lock-step mission clock: the last accepted tick, and periods since.
    clock: Option<(u64, u64)>,
    /// Periods run since the mission started (a mission waits `stale_periods` for its first
    /// state).
    mission_periods: u64,
    /// An accepted `SetConfig` changed the controller's configuration since the last period:
    /// a rebuild, the period's long job (Choice 226).
    rebuilt: bool,
}

impl Model {
    fn new() -> Self {
        Model {
            armed: false,
            mission: false,
            lockstep: false,
            stale_periods: DEFAULT_STALE_PERIODS,
            latched: None,
            disarmed_since_latch: false,
            last_seq: None,
            last_timestamp: None,
            counted: 0,
            ahead: 0,
            periods_since_state: None,
            clock: None,
            mission_periods: 0,
            rebuilt: false,
        }
    }

    fn fresh(&self) -> bool {
        self.periods_since_state
            .is_some_and(|n| n <= u64::from(self.stale_periods))
    }

    /// A mission that has had no state yet, still within its `stale_periods` grace: running,
    /// thrusters off.
    fn waiting(&self) -> bool {
        self.periods_since_state.is_none() && self.mission_periods <= u64::from(self.stale_periods)
    }
}

/// The default controller (built once: `Controller::new` takes the bounds over the box).
fn controller() -> Controller {
    static C: std::sync::OnceLock<Controller> = std::sync::OnceLock::new();
    C.get_or_init(|| Controller::new(ControllerConfig::default()).expect("default config"))
        .clone()
}

/// The reference on the paper's 10 m circle at tick `k` (the vehicle exactly on it).
fn on_circle(k: u64) -> StateFrame {
    let d = Trajectory::table1(Table1Case::Circular10R).sample(k, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    StateFrame {
        t_ticks: k,
        eta: d.eta.into(),
        nu: nu.into(),
    }
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
    let mut input = Bytes { data, at: 0 };
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

/// The next sequence number: usually +1; sometimes a repeat, a step back or a jump.
fn next_seq(h: &mut Harness, input: &mut Bytes) -> u16 {
    let s = input.u8();
    let step = match s {
        0..=200 => 1,
        255 => input.u16(),
        _ => u16::from(s).wrapping_sub(228), // −27 ..= +26
    };
    h.seq = h.seq.wrapping_add(step);
    h.seq
}

/// A state frame: on the reference at the next tick of the mission clock (or the next after
/// `value`), at an arbitrary tick, and sometimes with one component replaced by arbitrary bits.
fn state_frame(h: &Harness, input: &mut Bytes) -> StateFrame {
    let mode = input.u8();
    let next = h.model.clock.map_or(0, |(t, _)| t + 1);
    let t = match mode % 4 {
        0 => next,
        1 => next.wrapping_add(u64::from(input.u8())),
        2 => next.wrapping_sub(u64::from(input.u8())),
        _ => input.u64(),
    };
    // The reference only depends on t mod its period; keep the sample finite for huge ticks.
    let mut s = on_circle(t % 1_000_000);
    s.t_ticks = t;
    if mode & 0x80 != 0 {
        let i = usize::from(input.u8() % 12);
        let v = input.f32();
        if i < 6 {
            s.eta[i] = v;
        } else {
            s.nu[i - 6] = v;
        }
    }
    s
}

/// A mission: [`path`]'s, with the tangent heading if bit 6 of its first byte is set and, if
/// bit 5 is, a time scale from the input (else 1) — so byte 0 is the paper's circle as before.
fn mission(input: &mut Bytes) -> MissionPlan {
    let kind = input.peek_u8();
    let path = path(input);
    MissionPlan {
        path,
        heading: if kind & 0x40 != 0 {
            Heading::Tangent
        } else {
            Heading::Paper
        },
        time_scale: if kind & 0x20 != 0 { input.f32() } else { 1.0 },
    }
}

fn path(input: &mut Bytes) -> MissionSpec {
    let kind = input.u8();
    if kind & 0x90 == 0x10 {
        // The uploaded mission, by its CRC (the board flies it only if it holds it verified).
        return MissionSpec::Waypoints {
            crc: three_points().crc(),
        };
    }
    if kind & 0x80 == 0 {
        return MissionSpec::Circle {
            radius: 10.0,
            omega: 0.1,
            depth: 5.0,
        };
    }
    let (a, b, c) = (input.f32(), input.f32(), input.f32());
    match kind % 4 {
        0 => MissionSpec::Circle {
            radius: a,
            omega: b,
            depth: c,
        },
        1 => MissionSpec::FigureEight {
            amplitude: a,
            omega: b,
            depth: c,
        },
        2 => MissionSpec::LawnMower {
            scale: a,
            omega: b,
            depth: c,
        },
        _ => MissionSpec::Helix {
            radius: a,
            omega: b,
            depth: c,
            depth_rate: input.f32(),
        },
    }
}

/// A config patch: each field present or not, with values from a few meaningful ones
/// (valid, at and beyond the limits) or arbitrary bits.
fn patch(input: &mut Bytes) -> ConfigPatch {
    let present = input.u8();
    let pick = |input: &mut Bytes, values: &[f32]| {
        let i = usize::from(input.u8()) % (values.len() + 1);
        values.get(i).copied().unwrap_or_else(|| input.f32())
    };
    ConfigPatch {
        rate_hz: (present & 1 != 0).then(|| {
            let values = [100, 50, 200, 201, 0, u32::MAX, 10];
            let i = usize::from(input.u8()) % (values.len() + 1);
            values.get(i).copied().unwrap_or_else(|| input.u32())
        }),
        robust: (present & 2 != 0).then(|| input.u8() & 1 == 1),
        delta_max: (present & 4 != 0).then(|| pick(input, &[1.0, 0.5, 0.0, -1.0, f32::NAN])),
        voltage_limit: (present & 8 != 0)
            .then(|| pick(input, &[SUPPLY, 12.0, SUPPLY + 0.5, 0.0, f32::INFINITY])),
        stale_periods: (present & 16 != 0).then(|| input.u8()),
        lockstep: (present & 32 != 0).then(|| input.u8() & 1 == 1),
        // Protocol 3's chain: any unit, any mask byte (a sixth thruster is refused); the
        // priority stays unset (no bit left in `present`; tests/thruster_chain.rs covers it).
        thrust_unit: (present & 64 != 0).then(|| {
            if input.u8() & 1 == 0 {
                ThrustUnit::Kgf
            } else {
                ThrustUnit::Newton
            }
        }),
        reversed_thrusters: (present & 128 != 0).then(|| input.u8()),
        priority: None,
    }
}

fn command(input: &mut Bytes) -> Command {
    match input.u8() % 6 {
        CMD_ARM => Command::Arm,
        CMD_DISARM => Command::Disarm,
        CMD_START => Command::StartMission(mission(input)),
        CMD_STOP => Command::StopMission,
        CMD_UPLOAD => Command::Upload(upload(input)),
        _ => Command::SetConfig(patch(input)),
    }
}

/// The valid upload the harness sends most: a three-point waypoint mission (one chunk).
pub fn three_points() -> MissionUpload {
    let points = controller_core::trajectory::WaypointList::new(&[
        [0.0, 10.0, 5.0],
        [60.0, 10.0, 5.0],
        [60.0, 60.0, 5.0],
    ])
    .expect("3 points");
    MissionUpload::of(&controller_core::Mission::paper(
        controller_core::TrajectoryKind::Waypoints {
            points,
            speed: 0.5,
            turn_radius: None,
            speeds: None,
            speed_change: None,
        },
    ))
    .expect("a waypoint path")
}

/// An upload part: the valid mission's `Begin` or chunk, or a header or chunk of fuzz bytes.
fn upload(input: &mut Bytes) -> UploadPart {
    let up = three_points();
    match input.u8() % 4 {
        0 => UploadPart::Begin(up.header()),
        1 => UploadPart::Chunk(up.chunk(input.u8() % 2)),
        2 => UploadPart::Begin(UploadHeader {
            points: input.u8(),
            speeds: (input.u8() & 1 == 1).then(|| input.u8()),
            speed: input.f32(),
            turn_radius: (input.u8() & 1 == 1).then(|| input.f32()),
            speed_change: (input.u8() & 1 == 1).then(|| input.f32()),
            heading: if input.u8() & 1 == 1 {
                Heading::Tangent
            } else {
                Heading::Paper
            },
            time_scale: input.f32(),
            crc: input.u32(),
        }),
        _ => {
            let index = input.u8();
            let mut words = [0.0; auv_link::upload::CHUNK_WORDS];
            for w in words.iter_mut().take(4) {
                *w = input.f32();
            }
            UploadPart::Chunk(UploadChunk { index, words })
        }
    }
}

/// The supervisor's settings a `SetConfig` may change.
fn settings(sup: &Supervisor) -> (ControllerConfig, u8, bool) {
    (
        *sup.controller().config(),
        sup.stale_periods(),
        sup.lockstep(),
    )
}

impl Harness {
    fn counters(&self) -> (u32, u32, u32, u32, u32, u32) {
        (
            self.sup.rx_frames(),
            self.sup.rx_stale(),
            self.sup.rx_errors(),
            self.sup.refused_commands(),
            self.sup.rx_auth_errors(),
            self.sup.rx_ahead(),
        )
    }

    /// A key holder's timestamp from 8 input bytes: the low 2 bits pick anywhere in 48 bits,
    /// around the lead past the harness's last stamp, around the ceiling, or at or below it.
    fn restarted_stamp(&self, raw: u64) -> u64 {
        let last = self.signer.timestamp();
        let r = raw >> 16;
        match raw & 3 {
            0 => r,
            1 => last + MAX_LEAD - (1 << 20) + r % (1 << 21),
            2 => CEILING - 8 + r % 16,
            _ => r % (last + 1),
        }
    }

    /// Builds the frame for `(seq, msg)`, signed as `how` says, sends it and checks what the
    /// supervisor did with it.
    fn send(&mut self, seq: u16, msg: Msg, how: u8, input: &mut Bytes) {
        let env = Envelope::new(seq, msg);
        let mut out = [0u8; MAX_FRAME];
        let signed = match how % 5 {
            SIGN_AS_EXPECTED => self.signing,
            SIGN_OTHER_WAY => !self.signing,
            _ => true,
        };
        let (n, auth) = if !signed {
            (encode(&env, &mut out), Auth::Unsigned)
        } else {
            match how % 5 {
                SIGN_WRONG_KEY => (
                    encode_signed(&env, &mut self.forger, &mut out),
                    Auth::Forged,
                ),
                SIGN_WRONG_DIRECTION => (
                    encode_signed(&env, &mut self.reflector, &mut out),
                    Auth::Forged,
                ),
                SIGN_RESTARTED => {
                    let mut restarted = Signer::new(&KEY, Direction::ToBoard);
                    restarted.advance_to(self.restarted_stamp(input.u64()));
                    let n = encode_signed(&env, &mut restarted, &mut out);
                    (n, Auth::Good(restarted.timestamp()))
                }
                _ => {
                    let n = encode_signed(&env, &mut self.signer, &mut out);
                    (n, Auth::Good(self.signer.timestamp()))
                }
            }
        };
        // Only a restarted signer at the last timestamp can fail to sign.
        let Ok(n) = n else { return };
        let frame = out[..n].to_vec();
        self.deliver(&frame, Some((env, auth)));
        if let (true, SIGN_RESTARTED, Auth::Good(t)) = (signed, how % 5, auth) {
            if self.signing && self.model.last_timestamp == Some(t) {
                self.stats.restarted_taken += 1;
            }
        }
        self.remember(frame, Some((env, auth)));
    }

    fn remember(&mut self, frame: Vec<u8>, known: Known) {
        if self.history.len() == 8 {
            self.history.remove(0);
        }
        self.history.push((frame, known));
    }

    /// Bytes the harness did not build as a frame (a corruption, raw bytes), split at the
    /// delimiters. A chunk equal to a frame sent earlier is that frame; otherwise it is what
    /// `decode_frame` says it is (signing off) or, signing on, a key holder's frame if it
    /// verifies with the key: libFuzzer learns a MAC from the comparison that checks it, so the
    /// fuzzer holds the key too (it wrote the signed `Arm` of timestamp 1 from raw bytes).
    fn raw(&mut self, bytes: &[u8]) {
        for chunk in bytes.split_inclusive(|&b| b == 0) {
            let mut body = chunk.strip_suffix(&[0]).unwrap_or(chunk).to_vec();
            let earlier = self
                .history
                .iter()
                .find(|(f, _)| f.as_slice() == chunk)
                .and_then(|(_, k)| *k);
            let known = earlier.or_else(|| {
                if self.signing {
                    let mut v = Verifier::new(&KEY, Direction::ToBoard);
                    let env = decode_frame_signed(&mut body, &mut v).ok()?;
                    Some((env, Auth::Good(v.last_timestamp()?)))
                } else {
                    decode_frame(&mut body).ok().map(|e| (e, Auth::Unsigned))
                }
            });
            self.deliver(chunk, known);
        }
    }

    /// Feeds `frame` to the board's end of the link and checks the supervisor's reaction
    /// against the model. `known`: the envelope and how it was signed, if it is a frame.
    fn deliver(&mut self, frame: &[u8], known: Known) {
        let before = self.counters();
        let settings_before = settings(&self.sup);
        board::receive(&mut self.sup, &mut self.link, frame);
        let after = self.counters();
        let d = |a: u32, b: u32| a.checked_sub(b).expect("counters never go down");
        let (accepted, stale, errors, refused, auth_errors, ahead) = (
            d(after.0, before.0),
            d(after.1, before.1),
            d(after.2, before.2),
            d(after.3, before.3),
            d(after.4, before.4),
            d(after.5, before.5),
        );
        let Some((env, auth)) = known else {
            assert_eq!(
                (accepted, stale, ahead),
                (0, 0, 0),
                "only a frame reaches the supervisor; only an authentic one is ahead"
            );
            assert_eq!(refused, 0);
            return;
        };
        self.stats.frames_sent += 1;
        assert_eq!(
            accepted + stale + errors,
            1,
            "a frame is counted once: {env:?}"
        );
        // A frame the harness built fails at the link only on authentication (or, signing off,
        // on a signature); an error without one is the supervisor's (telemetry to the board).
        let passed_link = accepted + stale == 1 || (errors == 1 && auth_errors == 0);
        // An authentic frame on a signed link: the timestamp rule decides, from the docs.
        let stamp = match (self.signing, auth) {
            (true, Auth::Good(t)) => {
                let m = &self.model;
                let replay = m.last_timestamp.is_some_and(|l| t <= l);
                let too_far = !replay
                    && (t > CEILING
                        || m.last_timestamp
                            .is_some_and(|l| t - l > MAX_LEAD + m.counted));
                assert_eq!(
                    ahead,
                    u32::from(too_far),
                    "stamp {t}, last {:?}, counted {}",
                    m.last_timestamp,
                    m.counted
                );
                assert_eq!(
                    passed_link,
                    !replay && !too_far,
                    "stamp {t}, last {:?}, counted {}",
                    m.last_timestamp,
                    m.counted
                );
                Some(t)
            }
            _ => {
                assert_eq!(ahead, 0, "only an authentic frame is ahead: {auth:?}");
                None
            }
        };
        self.model.ahead += ahead;
        self.stats.ahead += ahead;
        if passed_link {
            // It passed the link's checks: authentic as the board's mode requires.
            match (self.signing, stamp) {
                (false, _) => assert_eq!(auth, Auth::Unsigned, "signing off: {env:?}"),
                (true, Some(t)) => {
                    self.model.last_timestamp = Some(t);
                    self.model.counted = 0;
                    // As a navigation computer would: its next stamp goes above it.
                    self.signer.advance_to(t);
                }
                (true, None) => {
                    panic!("signing on, {auth:?} frame reached the supervisor: {env:?}")
                }
            }
        }
        if matches!(env.msg, Msg::Telemetry(_)) {
            assert_eq!(accepted + stale, 0, "telemetry to the board is an error");
        }
        if accepted == 0 {
            assert_eq!(refused, 0, "a dropped frame is not a command");
            assert_eq!(
                settings(&self.sup),
                settings_before,
                "a dropped frame changes nothing"
            );
            return;
        }
        self.stats.frames_accepted += 1;
        if let Some(last) = self.model.last_seq {
            let dist = env.seq.wrapping_sub(last);
            assert!(
                (1..=SEQ_WINDOW).contains(&dist),
                "seq {} accepted after {last}",
                env.seq
            );
        }
        self.model.last_seq = Some(env.seq);
        match env.msg {
            Msg::State(s) => {
                assert_eq!(refused, 0);
                if self.model.lockstep && self.model.mission {
                    if let Some((t, periods)) = self.model.clock {
                        assert!(
                            s.t_ticks > t && s.t_ticks - t <= periods,
                            "tick {} accepted after {t}, {periods} periods on",
                            s.t_ticks
                        );
                    }
                    self.model.clock = Some((s.t_ticks, 0));
                }
                self.model.periods_since_state = Some(0);
            }
            Msg::Command(c) => {
                let refused = refused == 1;
                if refused {
                    self.stats.refusals += 1;
                    assert!(self.sup.last_refusal().is_some());
                }
                self.command(&c, refused);
                if !refused && *self.sup.controller().config() != settings_before.0 {
                    self.model.rebuilt = true;
                }
                if refused || !matches!(c, Command::SetConfig(_)) {
                    assert_eq!(
                        settings(&self.sup),
                        settings_before,
                        "{c:?} changed settings"
                    );
                }
            }
            Msg::Telemetry(_) => unreachable!("checked above"),
        }
    }

    fn command(&mut self, c: &Command, refused: bool) {
        let m = &mut self.model;
        match c {
            Command::Arm => {
                if refused {
                    assert!(m.armed && m.latched.is_some(), "Arm refused: {m:?}");
                } else {
                    assert!(
                        !(m.armed && m.latched.is_some()),
                        "lone Arm accepted, latched"
                    );
                    if !m.armed {
                        if m.latched.is_some() {
                            assert!(m.disarmed_since_latch);
                            self.stats.rearms_after_latch += 1;
                        }
                        m.latched = None;
                        m.disarmed_since_latch = false;
                    }
                    m.armed = true;
                }
            }
            Command::Disarm | Command::StopMission => {
                assert!(!refused, "{c:?} refused");
                if matches!(c, Command::Disarm) {
                    m.armed = false;
                    m.disarmed_since_latch = m.latched.is_some();
                }
                m.mission = false;
            }
            Command::StartMission(_) => {
                if !refused {
                    assert!(
                        m.armed && m.latched.is_none() && !m.mission,
                        "StartMission accepted: {m:?}"
                    );
                    m.mission = true;
                    m.mission_periods = 0;
                    m.clock = None;
                    // A new mission counts from its start, in either pacing (Choice 227): a
                    // state from before it is not its state.
                    m.periods_since_state = None;
                }
            }
            Command::Upload(_) => {
                assert!(refused || !m.armed, "an upload part accepted armed");
            }
            Command::SetConfig(p) => {
                if !refused {
                    assert!(!m.armed, "SetConfig accepted armed");
                    if let Some(n) = p.stale_periods {
                        m.stale_periods = n;
                    }
                    if let Some(l) = p.lockstep {
                        m.lockstep = l;
                    }
                    assert_eq!(self.sup.stale_periods(), m.stale_periods, "whole patch");
                    assert_eq!(self.sup.lockstep(), m.lockstep, "whole patch");
                    let cfg = self.sup.controller().config();
                    assert!(p.rate_hz.is_none_or(|r| r == cfg.rate_hz), "whole patch");
                    assert!(
                        p.voltage_limit
                            .is_none_or(|v| v.to_bits() == cfg.voltage_limit.to_bits()),
                        "whole patch"
                    );
                    assert!(
                        cfg.voltage_limit <= SUPPLY,
                        "voltage limit above the supply"
                    );
                }
            }
        }
    }

    /// One control period, checked; returns its telemetry.
    fn period(&mut self, overrun: bool) -> Telemetry {
        let step = self.sup.step(overrun, &|| 0);
        let t: Telemetry = step.telemetry;
        self.stats.periods += 1;
        let limit = self.sup.controller().config().voltage_limit;
        for v in step.voltages {
            assert!(
                v.is_finite() && v.abs() <= limit,
                "voltage {v}, limit {limit}"
            );
        }
        let on = step.voltages.iter().any(|v| *v != 0.0);
        // A rebuild is the period's long job, and a period that ran one never flies.
        assert!(
            step.long_job || !self.model.rebuilt,
            "a rebuild not counted as the period's long job"
        );
        assert!(!(step.long_job && on), "a period with a long job flew");
        self.model.rebuilt = false;
        let m = self.model;
        let may_run = m.armed && m.mission && m.latched.is_none() && !overrun;
        let may_fly = may_run && m.fresh();
        if on {
            assert!(
                may_fly,
                "thrusters on {:?}, {t:?}, model {m:?}",
                step.voltages
            );
            assert_eq!(t.status, BoardStatus::Running);
            self.stats.periods_on += 1;
        } else if t.status == BoardStatus::Running {
            // Running with the thrusters off: a mission waiting for its first state.
            assert!(
                may_fly || (may_run && m.waiting()),
                "running, {t:?}, model {m:?}"
            );
        }
        match m.latched {
            Some(r) => {
                assert!(!on);
                assert_eq!(t.latched, Some(r), "the latched reason in every frame");
                let want = if m.armed {
                    BoardStatus::FailSafe(r)
                } else {
                    BoardStatus::Disarmed
                };
                assert_eq!(t.status, want);
            }
            None => match t.status {
                BoardStatus::FailSafe(r) => {
                    assert!(m.armed && m.mission, "fail-safe without a mission: {m:?}");
                    let want = if overrun {
                        FailSafeReason::Overrun
                    } else if !m.fresh() && !m.waiting() {
                        FailSafeReason::StaleState
                    } else {
                        FailSafeReason::ControllerFault
                    };
                    assert_eq!(r, want, "model {m:?}");
                    assert_eq!(t.latched, Some(r));
                    self.model.latched = Some(r);
                    self.stats.latches += 1;
                }
                status => {
                    assert_eq!(t.latched, None);
                    let want = match (m.armed, m.mission) {
                        (false, _) => BoardStatus::Disarmed,
                        (true, false) => BoardStatus::Armed,
                        (true, true) => BoardStatus::Running,
                    };
                    assert_eq!(status, want, "model {m:?}");
                }
            },
        }
        assert_eq!(t.rx_ahead, self.model.ahead, "frames refused as ahead");
        // The telemetry goes out: it always fits a frame and, signed, the board can always sign
        // it (this fuzz target once found a key holder's stamp at 2⁴⁸ − 1 leaving it none): the
        // navigation computer verifies it, and the stamp leaves at least RESERVE − periods.
        let env = self.sup.envelope(t);
        let frame = match self.link.encode(&env) {
            Ok(frame) => frame.to_vec(),
            Err(e) => panic!("telemetry does not encode: {e:?}, model {:?}", self.model),
        };
        assert!(frame.len() <= MAX_FRAME);
        if self.signing {
            let body = frame.strip_suffix(&[0]).expect("a delimited frame");
            let got = decode_frame_signed(&mut body.to_vec(), &mut self.nav);
            assert_eq!(
                got.map(|e| e.seq),
                Ok(env.seq),
                "the navigation end refused it"
            );
            let stamp = self.nav.last_timestamp().unwrap_or(0);
            let periods = u64::from(self.stats.periods);
            assert!(
                stamp <= CEILING + periods,
                "stamp {stamp}, {periods} periods"
            );
            assert!(MAX_TIMESTAMP - stamp >= auv_link::sign::RESERVE - periods);
        }
        // The period is over: the board counts it (its link's lead bound grows by as much).
        let rate = self.sup.rate_hz();
        self.link.period_passed(rate);
        let m = &mut self.model;
        m.counted += UNITS_PER_SECOND.div_ceil(u64::from(rate));
        m.periods_since_state = m.periods_since_state.map(|n| n + 1);
        m.mission_periods += 1;
        m.clock = m.clock.map(|(t, n)| (t, n + 1));
        t
    }
}
