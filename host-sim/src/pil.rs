//! Processor in the loop: the firmware ELF runs in QEMU (`mps2-an386`) with its UART0 — the
//! navigation link — on a loopback TCP socket; the simulator plays the vehicle and its
//! navigation computer.
//!
//! Set-up: the runner waits for the board's first telemetry and numbers its own frames from the
//! board's `last_rx_seq` on (a restarted runner is heard again: `auv_link::seq`), then sends
//! `SetConfig { lockstep, rate, Δu on/off, δ_max, voltage limit, stale periods, thrust unit,
//! thruster mounting, axis priority }` from the scenario's validated controller and `Arm`,
//! and waits for the board to report itself armed with that thrust unit and mounting (a
//! refused command is reported with the board's reason); then `StartMission` with the
//! scenario's validated mission (path, heading, time scale) and the first state frame. Every
//! telemetry frame must name the thrust unit the plant reads the voltages in, or the run
//! stops (docs/design.md §9). In lock-step the board runs
//! one control period per state frame and takes the frame's `t_ticks` as mission time (on its
//! mission clock), so the result does not depend on host speed.
//!
//! Signing ([`auv_link::sign`]): with a key, QEMU is started with `-append link-key=…` (the
//! QEMU image's configuration; the key never crosses the link), the runner signs every frame
//! (timestamps: 10 µs units since 2015-01-01 UTC, as MAVLink) and refuses telemetry that is not
//! signed by the board. Telemetry frames are also checked for sequence order. Each period the simulator sends a state frame from
//! the plant and applies the returned telemetry (voltages, or τ for ideal actuators) through
//! the same actuator chain as SIL ([`crate::sil::run_with`]).
//!
//! Link faults ([`LinkFaults`]) drop, corrupt, delay or silence state frames over tick ranges.
//! The board must go to fail-safe within its stale-state limit; a delayed frame is an old state
//! the board drops (off its mission clock). Once the link is healthy again the simulator
//! re-arms it (disarm, arm, and start the mission again where it is, since disarming drops it)
//! and it must resume. Every fail-safe entry and exit is recorded.
//!
//! Hardware in the loop (`host-sim hil`) is the same runner over another byte transport
//! ([`crate::transport`]): a serial device instead of QEMU's socket ([`BoardInTheLoop::over_serial`]).
//! It paces the run one of two ways ([`Pacing`], docs/design.md §21): lock-step, exactly the
//! protocol above; or real time, where the board runs on its own timer (`lockstep = false`)
//! and the host sends each state frame at its wall-clock period and flies the plant on the
//! newest telemetry it has when the next period is due ([`RealTimeStats`]).
//!
//! Every wait is bounded: no valid telemetry for the reply timeout (10 s for PIL,
//! `hil --reply-timeout`) ends the run with a message that says whether the board sent
//! nothing (not powered, not wired, wrong port) or only bytes that did not decode (a wrong
//! baud rate or key); a link that closes or a port that goes away ends it at once.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::Child;
use std::time::{Duration, Instant};

use auv_link::seq::SeqCheck;
use auv_link::sign::{AuthError, Direction, LinkKey, Signer, Verifier};
use auv_link::{
    encode, encode_signed, BoardStatus, Command as LinkCommand, ConfigPatch, Envelope,
    FrameDecoder, LinkError, MissionPlan, Msg, StateFrame, Telemetry, ThrustUnit,
    DEFAULT_STALE_PERIODS, MAX_FRAME, PROTOCOL_VERSION,
};
use serde::{Deserialize, Serialize};

use firmware_images::qemu_clock::INSTRUCTIONS_PER_TICK;

use crate::config::LinkFaults;
use crate::pacing::{board_edge, RealTime, PHASE_FRAMES};
pub use crate::pacing::{Pacing, RealTimeStats};
use crate::qemu::{spawn_qemu, stop_group};
use crate::record::{ControlStatus, RunResult, RunSummary};
use crate::scenario::Scenario;
use crate::sil::{ControlOut, ControlSource};
use crate::transport::{Serial, Transport};

/// How long PIL waits for valid telemetry before it gives up on QEMU (an idle QEMU under
/// `-icount` on a loaded host is slow; the board itself answers every period).
pub const PIL_REPLY_TIMEOUT: Duration = Duration::from_secs(10);

/// Board periods real time's period 0 waits for an answer that took all it sent (Choice 83),
/// before it takes the newest telemetry.
const K0_PATIENCE: u32 = 10;

/// The longest single read: the runner checks its deadlines at least this often.
const READ_SLICE: Duration = Duration::from_millis(100);

/// Largest |PIL − SIL| of the max path error (m) that a fault-free PIL run may show: 1 mm.
/// PIL equals SIL bit for bit today (the same f32 core, the same state frames); this is the
/// margin the `pil` command (exit 1 beyond it) and CI hold it to.
pub const PIL_SIL_TOLERANCE: f64 = 1e-3;

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

/// Link and board figures of one PIL run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PilStats {
    pub state_frames_sent: u64,
    pub telemetry_frames: u64,
    pub wall_seconds: f64,
    /// State frames per wall-clock second.
    pub frames_per_second: f64,
    /// Longest `update` the board measured, in instructions (`-icount shift=0`): meaningful
    /// for the QEMU image under `-icount` only (PIL; HIL lock-step against QEMU's pty), else
    /// see [`PilStats::worst_update_board_ticks`].
    pub worst_update_instructions: u64,
    pub board_rx_errors: u32,
    pub board_loop_overruns: u32,
    pub rearms: u32,
    pub failsafe_events: Vec<FailSafeEvent>,
    /// The link was signed (both ends).
    #[serde(default)]
    pub signed: bool,
    /// Frames the board dropped as repeated, old or off its mission clock (its `rx_stale`).
    #[serde(default)]
    pub board_rx_stale: u32,
    /// Frames the board refused for their authentication (its `rx_auth_errors`).
    #[serde(default)]
    pub board_rx_auth_errors: u32,
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

impl FailSafeEventKind {
    /// `"enter"` or `"exit"` (as in the JSON).
    pub fn as_str(self) -> &'static str {
        match self {
            FailSafeEventKind::Enter => "enter",
            FailSafeEventKind::Exit => "exit",
        }
    }
}

/// What a comparison is of: `"pil"` (processor in the loop, QEMU on a socket) or `"hil"`
/// (the board on a serial port), against SIL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Pil,
    Hil,
}

/// One PIL run compared with SIL: an entry of `host-sim pil --json`'s `cases` (read it back
/// with `serde_json::from_str::<Cases<PilComparison>>`). The PIL run's summary, its SIL twin's
/// max path error and the difference, and the board and link figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PilComparison {
    /// The PIL run (`case`, `robust`, metrics, `diverged`).
    #[serde(flatten)]
    pub run: RunSummary,
    pub mode: Mode,
    /// Max path error of the same scenario in SIL (m).
    pub sil_max_path: f64,
    /// PIL − SIL max path error (m).
    pub pil_minus_sil_max_path: f64,
    /// The board's and the link's figures.
    pub pil: PilStats,
}

impl PilComparison {
    /// The comparison of a PIL (or HIL: `mode`) run with the SIL run of the same scenario.
    pub fn new(pil_run: &RunResult, sil_run: &RunResult, stats: PilStats, mode: Mode) -> Self {
        PilComparison {
            run: pil_run.summary(),
            mode,
            sil_max_path: sil_run.metrics.max_path,
            pil_minus_sil_max_path: pil_run.metrics.max_path - sil_run.metrics.max_path,
            pil: stats,
        }
    }

    /// PIL and SIL agree: |PIL − SIL| of the max path error within [`PIL_SIL_TOLERANCE`] (a NaN
    /// difference does not agree).
    pub fn agrees(&self) -> bool {
        self.pil_minus_sil_max_path.abs() <= PIL_SIL_TOLERANCE
    }
}

/// A board in the loop: the firmware in QEMU on a socket (PIL), or a board on a serial port
/// (HIL; the board may be QEMU's on a pty).
pub struct BoardInTheLoop {
    /// QEMU, when this runner started it (ended with the run).
    child: Option<Child>,
    stream: Box<dyn Transport>,
    pacing: Pacing,
    /// Real-time pacing's clock and figures.
    rt: Option<RealTime>,
    /// No valid telemetry for this long ends the run.
    reply_timeout: Duration,
    /// When valid telemetry last arrived, and what came since (bytes, refused frames).
    heard: Instant,
    noise_bytes: u64,
    noise_refused: u64,
    read_timeout: Duration,
    /// The newest telemetry (real time: what the thrusters apply when a reply is late).
    latest: Option<Telemetry>,
    decoder: FrameDecoder,
    /// Signing on: signs every frame sent.
    signer: Option<Signer>,
    /// The board's telemetry numbers.
    telemetry_seq: SeqCheck,
    seq: u16,
    rate_hz: u32,
    faults: LinkFaults,
    mission: MissionPlan,
    /// The thrust unit the plant reads the board's voltages in: every telemetry frame must
    /// report it.
    thrust_unit: ThrustUnit,
    started: bool,
    /// The last `delay_ticks + 1` state frames (what a delayed frame is taken from).
    history: std::collections::VecDeque<StateFrame>,
    pending: std::collections::VecDeque<Telemetry>,
    last_tick: Option<u64>,
    last_status: Option<BoardStatus>,
    needs_rearm: bool,
    t0: Instant,
    pub stats: PilStats,
    /// Where to look when the link fails (QEMU's log, or the serial port).
    context: String,
}

impl BoardInTheLoop {
    /// Starts QEMU with `elf` (the QEMU flying image), waits for its UART to connect, and
    /// configures and arms the board with `scenario`'s validated controller (its mission is
    /// sent with the first state frame); with `key`, the board and this end sign the link.
    /// `runner` is `scripts/qemu-run.sh`; QEMU's decoded log goes to `log` (opened by the
    /// caller, who decides where and how it is written), which messages call `log_path`.
    pub fn start(
        elf: &Path,
        runner: &Path,
        scenario: &Scenario,
        faults: LinkFaults,
        log: std::fs::File,
        log_path: &Path,
        key: Option<&LinkKey>,
    ) -> Result<Self, String> {
        check_flying_image(elf)?;
        let listener = TcpListener::bind("127.0.0.1:0")
            .map_err(|e| format!("binding a loopback port: {e}"))?;
        let port = listener.local_addr().map_err(|e| e.to_string())?.port();
        let mut child = spawn_qemu(
            elf,
            runner,
            &format!("tcp:127.0.0.1:{port},nodelay=on"),
            Pacing::Lockstep,
            log,
            key,
        )?;
        listener.set_nonblocking(true).map_err(|e| e.to_string())?;
        let deadline = Instant::now() + Duration::from_secs(30);
        let stream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if Instant::now() > deadline {
                        stop_group(&mut child);
                        return Err(format!(
                            "QEMU did not connect its UART within 30 s (see {})",
                            log_path.display()
                        ));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => {
                    stop_group(&mut child);
                    return Err(format!("accepting QEMU's UART: {e}"));
                }
            }
        };
        stream.set_nonblocking(false).map_err(|e| e.to_string())?;
        stream.set_nodelay(true).map_err(|e| e.to_string())?;
        Self::connect(
            Box::new(stream),
            Some(child),
            "tcp".to_string(),
            format!("see {}", log_path.display()),
            scenario,
            faults,
            Pacing::Lockstep,
            PIL_REPLY_TIMEOUT,
            key,
        )
    }

    /// Hardware in the loop: the board on the serial device `port` at `baud` (a USB-serial
    /// adapter, or QEMU's `-serial pty`), configured and armed as [`BoardInTheLoop::start`]
    /// does, paced by `pacing`. No valid telemetry for `reply_timeout` ends the set-up or the
    /// run with a message that says what came instead.
    pub fn over_serial(
        port: &str,
        baud: u32,
        scenario: &Scenario,
        faults: LinkFaults,
        pacing: Pacing,
        reply_timeout: Duration,
        key: Option<&LinkKey>,
    ) -> Result<Self, String> {
        let serial = Serial::open(port, baud)?;
        Self::connect(
            Box::new(serial),
            None,
            format!("{port} at {baud} baud"),
            format!("serial port {port} at {baud} baud"),
            scenario,
            faults,
            pacing,
            reply_timeout,
            key,
        )
    }

    /// The set-up over an open transport (module docs): the first telemetry, then disarm,
    /// the configuration and arming, until the board reports itself armed.
    ///
    /// **Choice 65** (docs/design.md §21): disarm first (a bench board may still be armed
    /// from a run before, and refuses a configuration while armed), and take `Armed` only
    /// from telemetry whose `last_rx_seq` is the `Arm`'s.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        stream: Box<dyn Transport>,
        child: Option<Child>,
        link: String,
        context: String,
        scenario: &Scenario,
        faults: LinkFaults,
        pacing: Pacing,
        reply_timeout: Duration,
        key: Option<&LinkKey>,
    ) -> Result<Self, String> {
        let c = scenario.controller().config();
        // The link carries the geometry as the AUV-150 layout's reversed-thruster mask.
        let mounting = c.geometry.auv150_reversed().ok_or_else(|| {
            "the board's link carries the thruster geometry as the AUV-150 layout with some thrusters reversed; this scenario's geometry is another one, which PIL cannot fly".to_string()
        })?;
        let thrust_unit = ThrustUnit::from(c.thrust_unit);
        let mut b = BoardInTheLoop {
            child,
            stream,
            pacing,
            rt: (pacing == Pacing::Realtime).then(|| RealTime::new(c.rate_hz)),
            reply_timeout,
            heard: Instant::now(),
            noise_bytes: 0,
            noise_refused: 0,
            read_timeout: Duration::ZERO,
            latest: None,
            decoder: match key {
                Some(k) => FrameDecoder::signed(Verifier::new(k, Direction::FromBoard)),
                None => FrameDecoder::new(),
            },
            signer: key.map(|k| Signer::new(k, Direction::ToBoard)),
            telemetry_seq: SeqCheck::new(),
            seq: 0,
            rate_hz: c.rate_hz,
            faults,
            mission: MissionPlan::from(scenario.trajectory().mission()),
            thrust_unit,
            started: false,
            history: std::collections::VecDeque::new(),
            pending: std::collections::VecDeque::new(),
            last_tick: None,
            last_status: None,
            needs_rearm: false,
            t0: Instant::now(),
            stats: PilStats {
                signed: key.is_some(),
                link,
                pacing,
                ..PilStats::default()
            },
            context,
        };
        // Continue the board's numbering: a board that already heard a runner (this one
        // restarted) drops frames numbered at or before its last (auv_link::seq).
        let first = b.next_telemetry()?;
        if first.rx_frames > 0 {
            b.seq = first.last_rx_seq.wrapping_add(1);
        }
        let refused_before = first.refused_commands;
        // A board that flew before (a bench board between runs) may still be armed, and
        // refuses a configuration while armed: disarm it first (a fresh board is disarmed
        // already; disarming is never refused).
        b.send(Msg::Command(LinkCommand::Disarm))?;
        b.send(Msg::Command(LinkCommand::SetConfig(ConfigPatch {
            rate_hz: Some(c.rate_hz),
            robust: Some(c.robust),
            delta_max: Some(c.delta_max),
            voltage_limit: Some(c.voltage_limit),
            stale_periods: Some(DEFAULT_STALE_PERIODS),
            lockstep: Some(pacing == Pacing::Lockstep),
            thrust_unit: Some(thrust_unit),
            reversed_thrusters: Some(mounting),
            priority: Some(c.priority.into()),
        })))?;
        let arm_seq = b.seq;
        b.send(Msg::Command(LinkCommand::Arm))?;
        // Wait until the board reports itself armed after it took the arming (an earlier
        // frame of a board that was armed before says nothing of this set-up).
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let t = b.next_telemetry()?;
            if t.refused_commands > refused_before {
                return Err(format!(
                    "the board refused the set-up: {}",
                    t.last_refusal.map_or("(no reason)", |r| r.as_str())
                ));
            }
            if t.status == BoardStatus::Armed && t.last_rx_seq == arm_seq {
                if t.reversed_thrusters != mounting {
                    return Err(format!(
                        "the board flies thruster mounting {:#07b}, not the scenario's {mounting:#07b}",
                        t.reversed_thrusters
                    ));
                }
                b.check_unit(&t)?;
                b.latest = Some(t);
                break;
            }
            if Instant::now() > deadline {
                return Err(format!("board did not arm (status {:?})", t.status));
            }
        }
        if b.rt.is_some() {
            // Real time: the board's period phase, from the frames it sends armed at the
            // mission's rate (Choice 78).
            let mut arrivals = Vec::with_capacity(PHASE_FRAMES);
            for _ in 0..PHASE_FRAMES {
                b.latest = Some(b.next_telemetry()?);
                arrivals.push(b.heard);
            }
            if let Some(rt) = &mut b.rt {
                rt.edge = board_edge(&arrivals, rt.period);
            }
        }
        b.t0 = Instant::now();
        Ok(b)
    }

    /// The board reports the thrust unit the plant reads its voltages in.
    fn check_unit(&self, t: &Telemetry) -> Result<(), String> {
        if t.thrust_unit == self.thrust_unit {
            Ok(())
        } else {
            Err(format!(
                "the board reports thrust unit {}, but the plant reads its voltages in {} (tick {})",
                unit_name(t.thrust_unit),
                unit_name(self.thrust_unit),
                t.tick
            ))
        }
    }

    fn send(&mut self, msg: Msg) -> Result<(), String> {
        let mut buf = [0u8; MAX_FRAME];
        let n = self.encode(msg, &mut buf)?;
        self.write(&buf[..n])
    }

    fn encode(&mut self, msg: Msg, buf: &mut [u8; MAX_FRAME]) -> Result<usize, String> {
        let env = Envelope {
            version: PROTOCOL_VERSION,
            seq: self.seq,
            msg,
        };
        self.seq = self.seq.wrapping_add(1);
        match &mut self.signer {
            None => encode(&env, buf),
            Some(signer) => {
                signer.advance_to(mavlink_time());
                encode_signed(&env, signer, buf)
            }
        }
        .map_err(|e| format!("encoding: {e}"))
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.stream
            .write_frame(bytes)
            .map_err(|e| self.lost(&e, "write"))
    }

    /// The message for a link that failed under a read or a write.
    fn lost(&self, e: &std::io::Error, op: &str) -> String {
        use std::io::ErrorKind;
        // EIO: a tty whose other end (a pty's master, a USB adapter) is gone.
        const EIO: i32 = 5;
        let gone = e.raw_os_error() == Some(EIO)
            || matches!(
                e.kind(),
                ErrorKind::UnexpectedEof | ErrorKind::BrokenPipe | ErrorKind::ConnectionReset
            );
        if gone {
            format!(
                "the board's link went away ({e}): the port was unplugged, the board lost power, or its emulator ended ({})",
                self.context
            )
        } else {
            format!("board link {op} failed: {e} ({})", self.context)
        }
    }

    /// Why no valid telemetry came for the reply timeout.
    fn silence(&self) -> String {
        let t = self.reply_timeout.as_secs_f64();
        if self.noise_bytes == 0 {
            format!(
                "no telemetry from the board for {t:.1} s: it sent nothing ({}); is it powered, flashed with its flying image and wired (its TX to this end's RX, a common ground), and is this the right port?",
                self.context
            )
        } else {
            format!(
                "no valid telemetry from the board for {t:.1} s: {} bytes came, and {} frames that did not decode ({}); a wrong baud rate (--baud; the STM32 board's is 460800), a wrong or missing link key (--link-key-file), or another device on this port",
                self.noise_bytes, self.noise_refused, self.context
            )
        }
    }

    /// The next telemetry frame from the board (frames of other kinds are ignored).
    fn next_telemetry(&mut self) -> Result<Telemetry, String> {
        loop {
            if let Some(t) = self.poll_telemetry(None)? {
                return Ok(t);
            }
        }
    }

    /// The next telemetry frame, or `None` once `until` has passed without one. No valid
    /// telemetry for the reply timeout is an error ([`BoardInTheLoop::silence`]), whatever
    /// `until` says (**Choice 64**, docs/design.md §21: every wait bounded, silence told from
    /// noise).
    fn poll_telemetry(&mut self, until: Option<Instant>) -> Result<Option<Telemetry>, String> {
        let mut chunk = [0u8; 512];
        loop {
            if let Some(t) = self.pending.pop_front() {
                self.stats.telemetry_frames += 1;
                self.heard = Instant::now();
                self.noise_bytes = 0;
                self.noise_refused = 0;
                if let Some(rt) = &mut self.rt {
                    rt.arrived(self.heard);
                }
                return Ok(Some(t));
            }
            let now = Instant::now();
            let silent_until = self.heard + self.reply_timeout;
            if now >= silent_until {
                return Err(self.silence());
            }
            let mut wait = READ_SLICE.min(silent_until - now);
            if let Some(u) = until {
                if now >= u {
                    return Ok(None);
                }
                wait = wait.min(u - now);
            }
            let wait = wait.max(Duration::from_millis(1));
            if wait != self.read_timeout {
                self.stream
                    .set_read_timeout(wait)
                    .map_err(|e| self.lost(&e, "set-up"))?;
                self.read_timeout = wait;
            }
            let n = self
                .stream
                .read_some(&mut chunk)
                .map_err(|e| self.lost(&e, "read"))?;
            self.noise_bytes += n as u64;
            for &b in &chunk[..n] {
                match self.decoder.push(b) {
                    None => {}
                    Some(Ok(Envelope {
                        seq,
                        msg: Msg::Telemetry(t),
                        ..
                    })) if self.telemetry_seq.accept(seq) => self.pending.push_back(t),
                    // The two ends disagree on signing: nothing will ever be accepted.
                    Some(Err(LinkError::Auth(
                        e @ (AuthError::SigningOff | AuthError::Unsigned),
                    ))) => {
                        return Err(format!(
                            "the board's telemetry is {} but this end has signing {}: {e}; give the board and host-sim the same key (--link-key-file), or neither",
                            if e == AuthError::SigningOff { "signed" } else { "unsigned" },
                            on_off(self.signer.is_some())
                        ));
                    }
                    // Undecodable, badly signed, out of sequence, or not telemetry.
                    Some(_) => {
                        self.stats.telemetry_refused += 1;
                        self.noise_refused += 1;
                    }
                }
            }
        }
    }

    /// Appends this period's state frame to `out` — `frame`, or with a delay fault the one
    /// from `delay_ticks` earlier, with a corruption fault a byte flipped — and returns the
    /// sequence number the board's answer will name (none for a frame the board will refuse
    /// or drop).
    fn encode_state(
        &mut self,
        frame: StateFrame,
        corrupt: bool,
        delayed: bool,
        out: &mut Vec<u8>,
    ) -> Result<Option<u16>, String> {
        let mut buf = [0u8; MAX_FRAME];
        let sent = if delayed {
            let i = self
                .history
                .len()
                .saturating_sub(1 + self.faults.delay_ticks as usize);
            self.history[i]
        } else {
            frame
        };
        // A corrupted frame is refused, and a delayed one holds an old state that the board
        // drops as off its mission clock: neither is answered.
        let expect = (!corrupt && !delayed).then_some(self.seq);
        let n = self.encode(Msg::State(sent), &mut buf)?;
        if corrupt {
            buf[n / 2] ^= 0x5A;
        }
        out.extend_from_slice(&buf[..n]);
        self.stats.state_frames_sent += 1;
        Ok(expect)
    }

    /// The telemetry of the board's next control period (later than any seen before).
    fn next_period(&mut self) -> Result<Telemetry, String> {
        loop {
            if let Some(t) = self.poll_period(None)? {
                return Ok(t);
            }
        }
    }

    /// [`BoardInTheLoop::next_period`], or `None` once `until` has passed; in real time,
    /// counts the board's periods missing between two telemetry frames.
    fn poll_period(&mut self, until: Option<Instant>) -> Result<Option<Telemetry>, String> {
        loop {
            let Some(t) = self.poll_telemetry(until)? else {
                return Ok(None);
            };
            if self.last_tick.is_none_or(|last| t.tick > last) {
                if let (Some(rt), Some(last)) = (&mut self.rt, self.last_tick) {
                    rt.stats.board_missed_periods += t.tick - last - 1;
                }
                self.last_tick = Some(t.tick);
                self.latest = Some(t);
                return Ok(Some(t));
            }
        }
    }

    /// Real time: the board's output for state frame `expect_seq` if it arrives before
    /// period `k + 1` is due, else the newest output the board sent (a late frame: the
    /// thrusters hold what the board last commanded, as they would on the vehicle). Period 0
    /// waits for its answer, and the run's wall clock starts then.
    /// **Choice 66**, docs/design.md §21.
    fn realtime_reply(
        &mut self,
        k: u64,
        expect_seq: Option<u16>,
        last_sent: Option<u16>,
    ) -> Result<Telemetry, String> {
        if k == 0 {
            // The answer is the first telemetry that names the first state frame from a
            // period in which the board had also taken the rest of what period 0 sent (the
            // `StartMission` after it): when the two straddle one of the board's boundaries,
            // the board's first answer names the state but is still `armed`, and flying on it
            // would count a period with the thrusters off. After `K0_PATIENCE` board periods
            // without such an answer (the frames were lost or damaged on the line), the newest
            // telemetry is the answer: the mission goes on, and what the board did shows in
            // the run's faults — never an unbounded wait while telemetry keeps coming.
            let mut periods = 0;
            // The mission starts with the board's answer to its first state frame (bounded by
            // the reply timeout), so period 0 does not fly on a reply from before the mission
            // ran. The board sends telemetry just after its period boundary: the run's clock
            // starts half a period after the boundary that answer followed, so that the host's
            // periods fall between the board's — a frame then waits half a period for the
            // board, and its answer has half a period to come back. (Started on the answer
            // itself, every frame arrived just after a boundary and was answered just after
            // the next period was due: every frame late.) The boundary is the set-up's
            // estimate (Choice 78), not the answer's arrival: a first answer delayed by a few
            // ms put every later frame just after the board's boundary. The clocks drift
            // apart over a run; the figures show it.
            loop {
                let t = self.next_period()?;
                let heard = self.heard;
                if let Some(rt) = &mut self.rt {
                    rt.answered(t.last_state_seq, heard);
                }
                periods += 1;
                let took_all = last_sent.is_none_or(|seq| t.last_rx_seq == seq);
                let names_state = expect_seq.is_none_or(|seq| t.last_state_seq == seq);
                if (names_state && took_all) || periods > K0_PATIENCE {
                    if let Some(rt) = &mut self.rt {
                        rt.origin = Some(rt.origin_after(heard));
                    }
                    return Ok(t);
                }
            }
        }
        let due = match &mut self.rt {
            Some(rt) => rt.due(k + 1),
            None => Instant::now(),
        };
        loop {
            match self.poll_period(Some(due))? {
                Some(t) => {
                    let heard = self.heard;
                    if let Some(rt) = &mut self.rt {
                        rt.answered(t.last_state_seq, heard);
                    }
                    if expect_seq.is_some_and(|seq| t.last_state_seq == seq) {
                        return Ok(t);
                    }
                }
                None => {
                    if let (Some(rt), Some(_)) = (&mut self.rt, expect_seq) {
                        rt.stats.late_frames += 1;
                    }
                    return self
                        .latest
                        .ok_or_else(|| "no telemetry from the board yet".to_string());
                }
            }
        }
    }

    fn note_status(&mut self, t: &Telemetry, k: u64) {
        let was_fail = matches!(self.last_status, Some(BoardStatus::FailSafe(_)));
        let is_fail = matches!(t.status, BoardStatus::FailSafe(_));
        let time = k as f64 / self.rate_hz as f64;
        if let (BoardStatus::FailSafe(reason), false) = (t.status, was_fail) {
            self.stats.failsafe_events.push(FailSafeEvent {
                tick: k,
                t: time,
                kind: FailSafeEventKind::Enter,
                reason: reason.as_str().to_string(),
            });
            self.needs_rearm = true;
        } else if was_fail && !is_fail {
            self.stats.failsafe_events.push(FailSafeEvent {
                tick: k,
                t: time,
                kind: FailSafeEventKind::Exit,
                reason: format!("{:?}", t.status),
            });
        }
        self.last_status = Some(t.status);
        self.stats.board_rx_errors = t.rx_errors;
        self.stats.board_rx_stale = t.rx_stale;
        self.stats.board_rx_auth_errors = t.rx_auth_errors;
        self.stats.board_refused_commands = t.refused_commands;
        self.stats.board_last_refusal = t.last_refusal.map(|r| r.as_str().to_string());
        self.stats.board_loop_overruns = t.loop_overruns;
        self.stats.board_thrust_unit = Some(unit_name(t.thrust_unit).to_string());
        self.stats.board_reversed_thrusters = Some(t.reversed_thrusters);
        self.stats.worst_update_board_ticks = u64::from(t.worst_update_ticks);
        self.stats.worst_update_instructions =
            t.worst_update_ticks as u64 * INSTRUCTIONS_PER_TICK as u64;
    }

    fn stop_qemu(&mut self) {
        if let Some(child) = &mut self.child {
            stop_group(child);
        }
    }

    /// Ends the QEMU process (if this runner started one) and returns the figures.
    pub fn finish(mut self) -> PilStats {
        self.stop_qemu();
        if let Some(rt) = &mut self.rt {
            self.stats.realtime = Some(rt.finish());
        }
        let wall = self.t0.elapsed().as_secs_f64();
        self.stats.wall_seconds = wall;
        self.stats.frames_per_second = if wall > 0.0 {
            self.stats.state_frames_sent as f64 / wall
        } else {
            0.0
        };
        std::mem::take(&mut self.stats)
    }
}

impl Drop for BoardInTheLoop {
    fn drop(&mut self) {
        self.stop_qemu();
    }
}

impl ControlSource for BoardInTheLoop {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, String> {
        if let Some(rt) = &mut self.rt {
            rt.pace(k);
        }
        let frame = StateFrame {
            t_ticks: k,
            eta: *eta,
            nu: *nu,
        };
        self.history.push_back(frame);
        if self.history.len() > (self.faults.delay_ticks as usize).saturating_add(1) {
            self.history.pop_front();
        }
        let silent = LinkFaults::any(&self.faults.silent, k);
        let dropped = LinkFaults::any(&self.faults.drop, k);
        let corrupt = LinkFaults::any(&self.faults.corrupt, k);
        let delayed = LinkFaults::any(&self.faults.delay, k);
        let healthy = !(silent || dropped || corrupt || delayed);
        let mut expect_seq = None;
        let mut out = Vec::with_capacity(4 * MAX_FRAME);
        let mut buf = [0u8; MAX_FRAME];
        // Lock-step: commands, then the state frame (a mission's first state frame sets its
        // clock; an earlier one is not on it). Real time: the state first, so that a mission
        // (re)started in this period has a state when the board's next period comes
        // (Choice 68, docs/design.md §21).
        let state_first = self.pacing == Pacing::Realtime;
        if !silent {
            if state_first && !dropped {
                expect_seq = self.encode_state(frame, corrupt, delayed, &mut out)?;
            }
            if self.needs_rearm && healthy {
                // Recovery: the link is good again; re-arm (the fail-safe latches until
                // then) and start the mission again, since disarming dropped it. Its first
                // state frame below sets the board's mission clock to this tick.
                for c in [
                    LinkCommand::Disarm,
                    LinkCommand::Arm,
                    LinkCommand::StartMission(self.mission),
                ] {
                    let n = self.encode(Msg::Command(c), &mut buf)?;
                    out.extend_from_slice(&buf[..n]);
                }
                self.needs_rearm = false;
                self.stats.rearms += 1;
            }
            if !self.started {
                let n = self.encode(
                    Msg::Command(LinkCommand::StartMission(self.mission)),
                    &mut buf,
                )?;
                out.extend_from_slice(&buf[..n]);
                self.started = true;
            }
            if !state_first && !dropped {
                expect_seq = self.encode_state(frame, corrupt, delayed, &mut out)?;
            }
        }
        // The last frame this period sent (real time's period 0 waits until the board took it).
        let last_sent = (!out.is_empty()).then(|| self.seq.wrapping_sub(1));
        if !out.is_empty() {
            self.write(&out)?;
        }
        if let (Some(rt), Some(seq)) = (&mut self.rt, expect_seq) {
            rt.sent(seq);
        }
        let t = match self.pacing {
            // The board's answer to this frame; if it timed out before the frame arrived
            // (host slower than the board's virtual clock), that timeout period is skipped.
            // Without a valid frame the answer is the board's next (timed-out) period.
            Pacing::Lockstep => loop {
                let t = self.next_period()?;
                match expect_seq {
                    Some(seq) if t.last_state_seq != seq => continue,
                    _ => break t,
                }
            },
            Pacing::Realtime => self.realtime_reply(k, expect_seq, last_sent)?,
        };
        self.note_status(&t, k);
        self.check_unit(&t)?;
        Ok(ControlOut {
            status: ControlStatus::Board(t.status),
            tau: t.tau,
            voltage: t.voltages,
            saturated: t.saturated,
            delta: t.delta,
            delta_clamped: t.delta_clamped,
            w_norm: t.w_norm,
        })
    }
}

/// The core's name of a wire thrust unit (`"kgf"`, `"newton"`: the scenario key's values).
fn unit_name(u: ThrustUnit) -> &'static str {
    controller_core::ThrustUnit::from(u).as_str()
}

fn on_off(b: bool) -> &'static str {
    if b {
        "on"
    } else {
        "off"
    }
}

/// MAVLink 2's signing time: 10 µs units since 2015-01-01 00:00 UTC (1 420 070 400 s after the
/// Unix epoch), so that a restarted runner still counts upwards.
pub fn mavlink_time() -> u64 {
    const EPOCH_2015: u64 = 1_420_070_400;
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| {
            d.as_secs().saturating_sub(EPOCH_2015) * 100_000 + u64::from(d.subsec_micros() / 10)
        })
}

/// The QEMU flying image as `cargo build -p firmware --release --target thumbv7em-none-eabihf
/// --features qemu --bin firmware-qemu` (or `cargo xtask firmware`) leaves it under `root`.
pub fn default_elf(root: &Path) -> PathBuf {
    use firmware_images::image::{Image, TARGET};
    root.join("target")
        .join(TARGET)
        .join("release")
        .join(Image::Qemu.bin())
}

/// Refuses an ELF that is not the QEMU flying image: the self-test image would run its checks
/// and exit, the STM32 image would wait for clocks QEMU does not have. The image says which it
/// is by the marker in its flash ([`firmware_images::image::Image::of_elf`]).
pub fn check_flying_image(elf: &Path) -> Result<(), String> {
    use firmware_images::image::{Image, TARGET};
    let bytes = std::fs::read(elf).map_err(|e| {
        format!(
            "firmware ELF {}: {e}; build it with `cargo build -p firmware --release --target {} --features qemu --bin {}`",
            elf.display(),
            TARGET,
            Image::Qemu.bin()
        )
    })?;
    let flying: Vec<&str> = Image::ALL
        .iter()
        .filter(|i| i.flies_in_qemu())
        .map(|i| i.bin())
        .collect();
    let flying = flying.join("` or `");
    match Image::of_elf(&bytes) {
        Some(image) if image.flies_in_qemu() => Ok(()),
        Some(other) => Err(format!(
            "{} is the `{}` image, not a flying image that runs in QEMU (`{flying}`) as the board in the loop (see --elf)",
            elf.display(),
            other.bin(),
        )),
        None => Err(format!(
            "{} is not an AUV-150 firmware image (no image marker; built before the images were binaries?); the board in the loop is `{flying}`",
            elf.display(),
        )),
    }
}
