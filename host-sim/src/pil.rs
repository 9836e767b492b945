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

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use auv_link::seq::SeqCheck;
use auv_link::sign::{AuthError, Direction, LinkKey, Signer, Verifier};
use auv_link::{
    encode, encode_signed, BoardStatus, Command as LinkCommand, ConfigPatch, Envelope,
    FrameDecoder, LinkError, MissionPlan, Msg, StateFrame, Telemetry, ThrustUnit,
    DEFAULT_STALE_PERIODS, MAX_FRAME, PROTOCOL_VERSION,
};
use serde::{Deserialize, Serialize};

use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;

use crate::config::LinkFaults;
use crate::record::{ControlStatus, RunResult, RunSummary};
use crate::scenario::Scenario;
use crate::sil::{ControlOut, ControlSource};

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
    /// Longest `update` the board measured, in instructions (`-icount shift=0`).
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

/// What a comparison is of: always `"pil"` (processor in the loop against SIL).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Pil,
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
    /// The comparison of a PIL run with the SIL run of the same scenario.
    pub fn new(pil_run: &RunResult, sil_run: &RunResult, stats: PilStats) -> Self {
        PilComparison {
            run: pil_run.summary(),
            mode: Mode::Pil,
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

/// The firmware in QEMU, on a socket.
pub struct BoardInTheLoop {
    child: Child,
    stream: TcpStream,
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
    log_path: PathBuf,
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
        let c = scenario.controller().config();
        // The link carries the geometry as the AUV-150 layout's reversed-thruster mask.
        let mounting = c.geometry.auv150_reversed().ok_or_else(|| {
            "the board's link carries the thruster geometry as the AUV-150 layout with some thrusters reversed; this scenario's geometry is another one, which PIL cannot fly".to_string()
        })?;
        let thrust_unit = ThrustUnit::from(c.thrust_unit);
        let listener = TcpListener::bind("127.0.0.1:0")
            .map_err(|e| format!("binding a loopback port: {e}"))?;
        let port = listener.local_addr().map_err(|e| e.to_string())?.port();
        let log_err = log.try_clone().map_err(|e| e.to_string())?;
        let mut qemu = Command::new("bash");
        qemu
            // Its own process group, so that ending it ends QEMU too (the runner starts QEMU
            // under `timeout`, two processes down).
            .process_group(0)
            .arg(runner)
            .arg(elf);
        if let Some(k) = key {
            // The QEMU image's provisioning (firmware::qemu::link_key); visible to this
            // machine's process list, which is acceptable for a simulator's key.
            let hex: String = k.bytes().iter().map(|b| format!("{b:02x}")).collect();
            qemu.arg("-append").arg(format!("link-key={hex}"));
        }
        let child = qemu
            .env("QEMU_SERIAL", format!("tcp:127.0.0.1:{port},nodelay=on"))
            .env("QEMU_TIMEOUT", "3600")
            .stdin(Stdio::null())
            .stdout(Stdio::from(log))
            .stderr(Stdio::from(log_err))
            .spawn()
            .map_err(|e| format!("starting QEMU through {}: {e}", runner.display()))?;
        listener.set_nonblocking(true).map_err(|e| e.to_string())?;
        let deadline = Instant::now() + Duration::from_secs(30);
        let stream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if Instant::now() > deadline {
                        return Err(format!(
                            "QEMU did not connect its UART within 30 s (see {})",
                            log_path.display()
                        ));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => return Err(format!("accepting QEMU's UART: {e}")),
            }
        };
        stream.set_nonblocking(false).map_err(|e| e.to_string())?;
        stream.set_nodelay(true).map_err(|e| e.to_string())?;
        stream
            .set_read_timeout(Some(Duration::from_secs(10)))
            .map_err(|e| e.to_string())?;
        let mut b = BoardInTheLoop {
            child,
            stream,
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
                ..PilStats::default()
            },
            log_path: log_path.to_path_buf(),
        };
        // Continue the board's numbering: a board that already heard a runner (this one
        // restarted) drops frames numbered at or before its last (auv_link::seq).
        let first = b.next_telemetry()?;
        if first.rx_frames > 0 {
            b.seq = first.last_rx_seq.wrapping_add(1);
        }
        let refused_before = first.refused_commands;
        b.send(Msg::Command(LinkCommand::SetConfig(ConfigPatch {
            rate_hz: Some(c.rate_hz),
            robust: Some(c.robust),
            delta_max: Some(c.delta_max),
            voltage_limit: Some(c.voltage_limit),
            stale_periods: Some(DEFAULT_STALE_PERIODS),
            lockstep: Some(true),
            thrust_unit: Some(thrust_unit),
            reversed_thrusters: Some(mounting),
            priority: Some(c.priority.into()),
        })))?;
        b.send(Msg::Command(LinkCommand::Arm))?;
        // Wait until the board reports itself armed: the configuration and arming took.
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let t = b.next_telemetry()?;
            if t.refused_commands > refused_before {
                return Err(format!(
                    "the board refused the set-up: {}",
                    t.last_refusal.map_or("(no reason)", |r| r.as_str())
                ));
            }
            if t.status == BoardStatus::Armed {
                if t.reversed_thrusters != mounting {
                    return Err(format!(
                        "the board flies thruster mounting {:#07b}, not the scenario's {mounting:#07b}",
                        t.reversed_thrusters
                    ));
                }
                b.check_unit(&t)?;
                break;
            }
            if Instant::now() > deadline {
                return Err(format!("board did not arm (status {:?})", t.status));
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
        self.stream.write_all(bytes).map_err(|e| {
            format!(
                "board link write failed: {e} (see {})",
                self.log_path.display()
            )
        })
    }

    /// The next telemetry frame from the board (frames of other kinds are ignored).
    fn next_telemetry(&mut self) -> Result<Telemetry, String> {
        let mut chunk = [0u8; 512];
        loop {
            if let Some(t) = self.pending.pop_front() {
                self.stats.telemetry_frames += 1;
                return Ok(t);
            }
            let n = self.stream.read(&mut chunk).map_err(|e| {
                format!(
                    "board link read failed: {e} (see {})",
                    self.log_path.display()
                )
            })?;
            if n == 0 {
                return Err(format!(
                    "QEMU closed the link (see {})",
                    self.log_path.display()
                ));
            }
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
                    Some(_) => self.stats.telemetry_refused += 1,
                }
            }
        }
    }

    /// The telemetry of the board's next control period (later than any seen before).
    fn next_period(&mut self) -> Result<Telemetry, String> {
        loop {
            let t = self.next_telemetry()?;
            if self.last_tick.is_none_or(|last| t.tick > last) {
                self.last_tick = Some(t.tick);
                return Ok(t);
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
        self.stats.worst_update_instructions =
            t.worst_update_ticks as u64 * INSTRUCTIONS_PER_TICK as u64;
    }

    fn stop_qemu(&mut self) {
        // SIGTERM to the whole process group (bash runner, timeout, QEMU, defmt-print).
        let _ = Command::new("kill")
            .arg("-TERM")
            .arg("--")
            .arg(format!("-{}", self.child.id()))
            .status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// Ends the QEMU process and returns the figures.
    pub fn finish(mut self) -> PilStats {
        self.stop_qemu();
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
        if !silent {
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
            if !dropped {
                let sent = if delayed {
                    let i = self
                        .history
                        .len()
                        .saturating_sub(1 + self.faults.delay_ticks as usize);
                    self.history[i]
                } else {
                    frame
                };
                // A corrupted frame is refused, and a delayed one holds an old state that the
                // board drops as off its mission clock: neither is answered.
                if !corrupt && !delayed {
                    expect_seq = Some(self.seq);
                }
                let n = self.encode(Msg::State(sent), &mut buf)?;
                if corrupt {
                    buf[n / 2] ^= 0x5A;
                }
                out.extend_from_slice(&buf[..n]);
                self.stats.state_frames_sent += 1;
            }
        }
        if !out.is_empty() {
            self.write(&out)?;
        }
        // The board's answer to this frame; if it timed out before the frame arrived (host
        // slower than the board's virtual clock), that timeout period is skipped. Without a
        // valid frame the answer is the board's next (timed-out) period.
        let t = loop {
            let t = self.next_period()?;
            match expect_seq {
                Some(seq) if t.last_state_seq != seq => continue,
                _ => break t,
            }
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
    use firmware::image::{Image, TARGET};
    root.join("target")
        .join(TARGET)
        .join("release")
        .join(Image::Qemu.bin())
}

/// Refuses an ELF that is not the QEMU flying image: the self-test image would run its checks
/// and exit, the STM32 image would wait for clocks QEMU does not have. The image says which it
/// is by the marker in its flash ([`firmware::image::Image::of_elf`]).
pub fn check_flying_image(elf: &Path) -> Result<(), String> {
    use firmware::image::{Image, TARGET};
    let bytes = std::fs::read(elf).map_err(|e| {
        format!(
            "firmware ELF {}: {e}; build it with `cargo build -p firmware --release --target {} --features qemu --bin {}`",
            elf.display(),
            TARGET,
            Image::Qemu.bin()
        )
    })?;
    match Image::of_elf(&bytes) {
        Some(Image::Qemu) => Ok(()),
        Some(other) => Err(format!(
            "{} is the `{}` image, not the QEMU flying image `{}` that PIL flies (see --elf)",
            elf.display(),
            other.bin(),
            Image::Qemu.bin()
        )),
        None => Err(format!(
            "{} is not an AUV-150 firmware image (no image marker; built before the images were binaries?); PIL flies `{}`",
            elf.display(),
            Image::Qemu.bin()
        )),
    }
}
