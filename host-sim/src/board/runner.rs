//! [`BoardInTheLoop`]: a board in the loop, started (QEMU on a loopback socket, or a board on
//! a serial port), set up, flown one control period at a time as the closed loop's
//! [`ControlSource`], and ended. It composes the parts that own the state: the link
//! (`link.rs`), the link faults (`faults.rs`), the session (`session.rs`: set-up, mission,
//! re-arm), the periods and their pacing (`period.rs`), and the figures (`stats.rs`).

use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::time::{Duration, Instant};

use auv_link::sign::LinkKey;
use auv_link::{Msg, StateFrame, MAX_FRAME};

use super::emulator::{spawn_qemu, wait_for_qemu, Qemu};
use super::error::Error;
use super::faults::{Faults, PeriodFaults};
use super::image::check_flying_image;
use super::link::Link;
use super::pacing::Pacing;
use super::period::Periods;
use super::session::Session;
use super::stats::BoardStats;
use super::transport::{Serial, Transport};
use crate::scenario::{LinkFaults, Scenario};
use crate::sim::{BoardReport, ControlOut, ControlSource, ControlStatus, LinkCounters, Stop};

/// How long PIL waits for valid telemetry before it gives up on QEMU (an idle QEMU under
/// `-icount` on a loaded host is slow; the board itself answers every period).
pub const PIL_REPLY_TIMEOUT: Duration = Duration::from_secs(10);

/// An open byte transport to a board, and how to name it in figures and messages.
struct Wire {
    stream: Box<dyn Transport>,
    /// QEMU, when this runner started it.
    qemu: Option<Qemu>,
    /// What carried the link: `"tcp"` (PIL) or the serial port and its baud rate.
    link: String,
    /// Where to look when the link fails (QEMU's log, or the serial port).
    context: String,
}

/// A board in the loop: the firmware in QEMU on a socket (PIL), or a board on a serial port
/// (HIL; the board may be QEMU's on a pty).
pub struct BoardInTheLoop {
    /// QEMU, when this runner started it (ended with the run).
    qemu: Option<Qemu>,
    link: Link,
    faults: Faults,
    session: Session,
    periods: Periods,
    stats: BoardStats,
    /// When the run started (after the set-up).
    t0: Instant,
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
    ) -> Result<Self, Error> {
        check_flying_image(elf)?;
        let listener =
            TcpListener::bind("127.0.0.1:0").map_err(socket("binding a loopback port"))?;
        let port = listener
            .local_addr()
            .map_err(socket("reading the loopback port's address"))?
            .port();
        let qemu = spawn_qemu(
            elf,
            runner,
            &format!("tcp:127.0.0.1:{port},nodelay=on"),
            Pacing::Lockstep,
            log,
            key,
        )?;
        listener
            .set_nonblocking(true)
            .map_err(socket("waiting on the loopback port"))?;
        let stream = accept(&listener, log_path)?;
        stream
            .set_nonblocking(false)
            .and_then(|()| stream.set_nodelay(true))
            .map_err(socket("setting up QEMU's UART socket"))?;
        let wire = Wire {
            stream: Box::new(stream),
            qemu: Some(qemu),
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
    /// run with an error that says what came instead ([`Error::Silent`], [`Error::Noise`]).
    pub fn over_serial(
        port: &str,
        baud: u32,
        scenario: &Scenario,
        faults: LinkFaults,
        pacing: Pacing,
        reply_timeout: Duration,
        key: Option<&LinkKey>,
    ) -> Result<Self, Error> {
        let serial = Serial::open(port, baud)?;
        let wire = Wire {
            stream: Box::new(serial),
            qemu: None,
            link: format!("{port} at {baud} baud"),
            context: format!("serial port {port} at {baud} baud"),
        };
        Self::connect(wire, scenario, faults, pacing, reply_timeout, key)
    }

    /// The set-up over an open transport (module docs of [`crate::board`]): the session's
    /// (first telemetry, disarm, configuration, upload, arming, until the board reports itself
    /// armed); in real time, the board's period phase. A failed set-up ends QEMU (dropped).
    fn connect(
        wire: Wire,
        scenario: &Scenario,
        faults: LinkFaults,
        pacing: Pacing,
        reply_timeout: Duration,
        key: Option<&LinkKey>,
    ) -> Result<Self, Error> {
        let mut session = Session::new(scenario, pacing)?;
        let faults = Faults::new(faults);
        let mut link = Link::new(wire.stream, wire.context, key, reply_timeout);
        let set_up = session.set_up(&mut link, faults.lost_upload_chunks())?;
        let mut stats = BoardStats {
            signed: link.signed(),
            link: wire.link,
            pacing,
            ..BoardStats::default()
        };
        if let Some((upload, verified)) = set_up.upload {
            stats.upload = Some(upload);
            stats.board_last_refusal = verified.last_refusal.map(|r| r.as_str().to_string());
        }
        let rate_hz = scenario.controller().config().rate_hz;
        let mut periods = Periods::new(pacing, rate_hz, set_up.armed);
        periods.find_phase(&mut link)?;
        Ok(BoardInTheLoop {
            qemu: wire.qemu,
            link,
            faults,
            session,
            periods,
            stats,
            t0: Instant::now(),
        })
    }

    /// Ends the QEMU process (if this runner started one) and returns the figures.
    pub fn finish(mut self) -> BoardStats {
        if let Some(qemu) = &mut self.qemu {
            qemu.stop();
        }
        let mut stats = std::mem::take(&mut self.stats);
        stats.realtime = self.periods.finish();
        (stats.telemetry_frames, stats.telemetry_refused) = self.link.telemetry_counts();
        let wall = self.t0.elapsed().as_secs_f64();
        stats.wall_seconds = wall;
        stats.frames_per_second = if wall > 0.0 {
            stats.state_frames_sent as f64 / wall
        } else {
            0.0
        };
        stats
    }

    /// Period `k`: its frames to the board, the board's answer, and what it says.
    fn period(&mut self, k: u64, frame: StateFrame) -> Result<ControlOut, Error> {
        self.periods.pace(k);
        let (expect_seq, last_sent) = self.send_period(k, frame)?;
        let t = self
            .periods
            .reply(&mut self.link, k, expect_seq, last_sent)?;
        if let Some(event) = self.session.note(&t, k) {
            self.stats.failsafe_events.push(event);
        }
        self.stats.reported(&t);
        self.session.check_unit(&t)?;
        let (telemetry_frames, telemetry_refused) = self.link.telemetry_counts();
        let board = BoardReport {
            status: t.status,
            board_tick: t.tick,
            last_refusal: t.last_refusal,
            counters: LinkCounters {
                state_frames_sent: self.stats.state_frames_sent,
                telemetry_frames,
                telemetry_refused,
                rearms: self.stats.rearms,
                rx_frames: t.rx_frames,
                rx_errors: t.rx_errors,
                rx_stale: t.rx_stale,
                rx_auth_errors: t.rx_auth_errors,
                rx_ahead: t.rx_ahead,
                refused_commands: t.refused_commands,
                loop_overruns: t.loop_overruns,
                worst_update_ticks: t.worst_update_ticks,
            },
        };
        Ok(ControlOut {
            status: ControlStatus::Board(t.status),
            tau: t.tau,
            voltage: t.voltages,
            thrust: None,
            saturated: t.saturated,
            delta: t.delta,
            delta_clamped: t.delta_clamped,
            w_norm: t.w_norm,
            eta_d: None,
            board: Some(board),
        })
    }

    /// Sends period `k`'s frames: the state frame (unless the link faults drop, corrupt,
    /// delay or silence it) and the session's commands. Returns the sequence number the
    /// board's answer will name (none for a frame the board will refuse or drop) and the last
    /// frame sent.
    fn send_period(
        &mut self,
        k: u64,
        frame: StateFrame,
    ) -> Result<(Option<u16>, Option<u16>), Error> {
        let f = self.faults.period(k, frame);
        let mut expect_seq = None;
        let mut out = Vec::with_capacity(4 * MAX_FRAME);
        // Lock-step: commands, then the state frame (a mission's first state frame sets its
        // clock; an earlier one is not on it). Real time: the state first, so that a mission
        // (re)started in this period has a state when the board's next period comes
        // (Choice 68, docs/board.md#pacing).
        let state_first = self.periods.pacing() == Pacing::Realtime;
        if !f.silent {
            if state_first && !f.dropped {
                expect_seq = self.append_state(&f, &mut out)?;
            }
            let (commands, rearm) = self.session.commands(f.healthy());
            for c in commands {
                self.link.append(Msg::Command(c), &mut out)?;
            }
            self.stats.rearms += u32::from(rearm);
            if !state_first && !f.dropped {
                expect_seq = self.append_state(&f, &mut out)?;
            }
        }
        // The last frame this period sent (real time's period 0 waits until the board took it).
        let last_sent = (!out.is_empty()).then(|| self.link.last_seq());
        if !out.is_empty() {
            self.link.write(&out)?;
        }
        if let Some(seq) = expect_seq {
            self.periods.sent(seq);
        }
        Ok((expect_seq, last_sent))
    }

    /// Appends the period's state frame, as its faults make it, to `out`; returns the
    /// sequence number the board's answer will name (none for a frame it refuses or drops).
    fn append_state(&mut self, f: &PeriodFaults, out: &mut Vec<u8>) -> Result<Option<u16>, Error> {
        let expect = f.answered().then_some(self.link.next_seq());
        let start = out.len();
        self.link.append(Msg::State(f.state), out)?;
        f.damage(&mut out[start..]);
        self.stats.state_frames_sent += 1;
        Ok(expect)
    }
}

impl ControlSource for BoardInTheLoop {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, Stop> {
        let frame = StateFrame {
            t_ticks: k,
            eta: *eta,
            nu: *nu,
        };
        self.period(k, frame).map_err(Stop::from)
    }

    fn upload_rounds(&self) -> &[crate::sim::UploadRound] {
        self.stats.upload.as_ref().map_or(&[], |u| &u.round_log)
    }
}

/// The error of the loopback socket's step `op`.
fn socket(op: &'static str) -> impl FnOnce(std::io::Error) -> Error {
    move |io| Error::QemuIo { op, io }
}

/// QEMU's UART connection to `listener` ([`wait_for_qemu`]: its log at `log_path` says why
/// not).
fn accept(listener: &TcpListener, log_path: &Path) -> Result<TcpStream, Error> {
    wait_for_qemu(
        |waited| Error::QemuNoUart {
            waited,
            log: log_path.to_path_buf(),
        },
        || match listener.accept() {
            Ok((s, _)) => Ok(Some(s)),
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Ok(None),
            Err(io) => Err(Error::QemuIo {
                op: "accepting QEMU's UART",
                io,
            }),
        },
    )
}
