//! [`BoardInTheLoop`]: a board in the loop, started (QEMU on a loopback socket, or a board on
//! a serial port), set up (configured, armed, its period phase found in real time) and ended.
//! What it sends is `send.rs`'s, what it hears `receive.rs`'s, one control period `period.rs`'s.

use std::collections::VecDeque;
use std::net::TcpListener;
use std::path::Path;
use std::process::Child;
use std::time::{Duration, Instant};

use auv_link::seq::SeqCheck;
use auv_link::sign::{Direction, LinkKey, Signer, Verifier};
use auv_link::{
    BoardStatus, Command as LinkCommand, ConfigPatch, FrameDecoder, MissionPlan, MissionUpload,
    Msg, StateFrame, Telemetry, ThrustUnit, DEFAULT_STALE_PERIODS,
};
use controller_core::ControllerConfig;

use super::emulator::{spawn_qemu, stop_group};
use super::image::check_flying_image;
use super::pacing::{board_edge, Pacing, RealTime, PHASE_FRAMES};
use super::stats::BoardStats;
use super::transport::{Serial, Transport};
use crate::interrupt;
use crate::scenario::{LinkFaults, Scenario};

/// How long PIL waits for valid telemetry before it gives up on QEMU (an idle QEMU under
/// `-icount` on a loaded host is slow; the board itself answers every period).
pub const PIL_REPLY_TIMEOUT: Duration = Duration::from_secs(10);

/// An open byte transport to a board, and how to name it in figures and messages.
struct Wire {
    stream: Box<dyn Transport>,
    /// QEMU, when this runner started it.
    child: Option<Child>,
    /// What carried the link: `"tcp"` (PIL) or the serial port and its baud rate.
    link: String,
    /// Where to look when the link fails (QEMU's log, or the serial port).
    context: String,
}

/// A board in the loop: the firmware in QEMU on a socket (PIL), or a board on a serial port
/// (HIL; the board may be QEMU's on a pty).
pub struct BoardInTheLoop {
    /// QEMU, when this runner started it (ended with the run).
    pub(super) child: Option<Child>,
    pub(super) stream: Box<dyn Transport>,
    pub(super) pacing: Pacing,
    /// Real-time pacing's clock and figures.
    pub(super) rt: Option<RealTime>,
    /// No valid telemetry for this long ends the run.
    pub(super) reply_timeout: Duration,
    /// When valid telemetry last arrived, and what came since (bytes, refused frames).
    pub(super) heard: Instant,
    pub(super) noise_bytes: u64,
    pub(super) noise_refused: u64,
    pub(super) read_timeout: Duration,
    /// The newest telemetry (real time: what the thrusters apply when a reply is late).
    pub(super) latest: Option<Telemetry>,
    pub(super) decoder: FrameDecoder,
    /// Signing on: signs every frame sent.
    pub(super) signer: Option<Signer>,
    /// The board's telemetry numbers.
    pub(super) telemetry_seq: SeqCheck,
    pub(super) seq: u16,
    pub(super) rate_hz: u32,
    pub(super) faults: LinkFaults,
    pub(super) mission: MissionPlan,
    /// The thrust unit the plant reads the board's voltages in: every telemetry frame must
    /// report it.
    pub(super) thrust_unit: ThrustUnit,
    pub(super) started: bool,
    /// The last `delay_ticks + 1` state frames (what a delayed frame is taken from).
    pub(super) history: VecDeque<StateFrame>,
    pub(super) pending: VecDeque<Telemetry>,
    pub(super) last_tick: Option<u64>,
    pub(super) last_status: Option<BoardStatus>,
    pub(super) needs_rearm: bool,
    pub(super) t0: Instant,
    pub(super) stats: BoardStats,
    /// Where to look when the link fails (QEMU's log, or the serial port).
    pub(super) context: String,
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
                    if interrupt::requested() {
                        stop_group(&mut child);
                        return Err("interrupted while waiting for QEMU".to_string());
                    }
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
        let wire = Wire {
            stream: Box::new(stream),
            child: Some(child),
            link: "tcp".to_string(),
            context: format!("see {}", log_path.display()),
        };
        Self::connect(
            wire,
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
        let wire = Wire {
            stream: Box::new(serial),
            child: None,
            link: format!("{port} at {baud} baud"),
            context: format!("serial port {port} at {baud} baud"),
        };
        Self::connect(wire, scenario, faults, pacing, reply_timeout, key)
    }

    /// The set-up over an open transport (module docs of [`crate::board`]): the first
    /// telemetry, then disarm, the configuration and arming, until the board reports itself
    /// armed; in real time, the board's period phase.
    fn connect(
        wire: Wire,
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
        let mission = MissionPlan::from(scenario.trajectory().mission());
        let upload = MissionUpload::of(&scenario.trajectory().mission());
        let lose = faults.lose_upload_chunks.clone();
        let mut b = Self::new(wire, scenario, faults, pacing, reply_timeout, key, mission);
        let (arm_seq, refused_before) = b.configure(c, mounting, upload.as_ref(), &lose)?;
        b.wait_armed(arm_seq, refused_before, mounting)?;
        if b.rt.is_some() {
            b.find_phase()?;
        }
        b.t0 = Instant::now();
        Ok(b)
    }

    /// The runner over `wire`, before the set-up.
    fn new(
        wire: Wire,
        scenario: &Scenario,
        faults: LinkFaults,
        pacing: Pacing,
        reply_timeout: Duration,
        key: Option<&LinkKey>,
        mission: MissionPlan,
    ) -> Self {
        let c = scenario.controller().config();
        BoardInTheLoop {
            child: wire.child,
            stream: wire.stream,
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
            mission,
            thrust_unit: ThrustUnit::from(c.thrust_unit),
            started: false,
            history: VecDeque::new(),
            pending: VecDeque::new(),
            last_tick: None,
            last_status: None,
            needs_rearm: false,
            t0: Instant::now(),
            stats: BoardStats {
                signed: key.is_some(),
                link: wire.link,
                pacing,
                ..BoardStats::default()
            },
            context: wire.context,
        }
    }

    /// Numbers this end's frames after the board's last, disarms, configures and arms;
    /// returns the `Arm`'s sequence number and the board's refusals before the set-up.
    ///
    /// **Choice 65** (docs/board.md#hardware-in-the-loop): disarm first (a bench board may still be armed
    /// from a run before, and refuses a configuration while armed).
    fn configure(
        &mut self,
        c: &ControllerConfig,
        mounting: u8,
        upload: Option<&MissionUpload>,
        lose: &[u8],
    ) -> Result<(u16, u32), String> {
        // Continue the board's numbering: a board that already heard a runner (this one
        // restarted) drops frames numbered at or before its last (auv_link::seq).
        let first = self.next_telemetry()?;
        if first.rx_frames > 0 {
            self.seq = first.last_rx_seq.wrapping_add(1);
        }
        // A board that flew before (a bench board between runs) may still be armed, and
        // refuses a configuration while armed: disarm it first (a fresh board is disarmed
        // already; disarming is never refused).
        self.send(Msg::Command(LinkCommand::Disarm))?;
        self.send(Msg::Command(LinkCommand::SetConfig(ConfigPatch {
            rate_hz: Some(c.rate_hz),
            robust: Some(c.robust),
            delta_max: Some(c.delta_max),
            voltage_limit: Some(c.voltage_limit),
            stale_periods: Some(DEFAULT_STALE_PERIODS),
            lockstep: Some(self.pacing == Pacing::Lockstep),
            thrust_unit: Some(self.thrust_unit),
            reversed_thrusters: Some(mounting),
            priority: Some(c.priority.into()),
        })))?;
        // A waypoint mission travels as an upload, taken only while disarmed (upload.rs),
        // once the board has taken the configuration (its refusals are the set-up's, those
        // of a lossy upload the upload's own).
        let mut refused = first.refused_commands;
        if let Some(up) = upload {
            let config_seq = self.seq.wrapping_sub(1);
            let t = self.acknowledged(config_seq)?;
            if t.refused_commands > refused {
                return Err(format!(
                    "the board refused the set-up: {}",
                    t.last_refusal.map_or("(no reason)", |r| r.as_str())
                ));
            }
            refused = self.upload(up, lose)?;
        }
        let arm_seq = self.seq;
        self.send(Msg::Command(LinkCommand::Arm))?;
        Ok((arm_seq, refused))
    }

    /// Waits until the board reports itself armed with the scenario's mounting and unit.
    ///
    /// **Choice 65**: `Armed` counts only from telemetry whose `last_rx_seq` is the `Arm`'s
    /// (an earlier frame of a board that was armed before says nothing of this set-up).
    fn wait_armed(
        &mut self,
        arm_seq: u16,
        refused_before: u32,
        mounting: u8,
    ) -> Result<(), String> {
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let t = self.next_telemetry()?;
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
                self.check_unit(&t)?;
                self.latest = Some(t);
                return Ok(());
            }
            if Instant::now() > deadline {
                return Err(format!("board did not arm (status {:?})", t.status));
            }
        }
    }

    /// Real time: the board's period phase, from the frames it sends armed at the mission's
    /// rate (**Choice 78**).
    fn find_phase(&mut self) -> Result<(), String> {
        let mut arrivals = Vec::with_capacity(PHASE_FRAMES);
        for _ in 0..PHASE_FRAMES {
            self.latest = Some(self.next_telemetry()?);
            arrivals.push(self.heard);
        }
        if let Some(rt) = &mut self.rt {
            rt.edge = board_edge(&arrivals, rt.period);
        }
        Ok(())
    }

    fn stop_qemu(&mut self) {
        if let Some(child) = &mut self.child {
            stop_group(child);
        }
    }

    /// Ends the QEMU process (if this runner started one) and returns the figures.
    pub fn finish(mut self) -> BoardStats {
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
