//! What the runner hears from the board: telemetry frames, decoded (and verified, if the link
//! is signed) and checked for sequence order, every wait bounded by the reply timeout
//! (**Choice 64**), the board's status and counters noted.

use std::time::{Duration, Instant};

use auv_link::sign::AuthError;
use auv_link::{BoardStatus, Envelope, LinkError, Msg, Telemetry, ThrustUnit};
use firmware_images::qemu_clock::INSTRUCTIONS_PER_TICK;

use super::runner::BoardInTheLoop;
use super::stats::{FailSafeEvent, FailSafeEventKind};
use crate::interrupt;

/// The longest single read: the runner checks its deadlines at least this often.
const READ_SLICE: Duration = Duration::from_millis(100);

impl BoardInTheLoop {
    /// The board reports the thrust unit the plant reads its voltages in.
    pub(super) fn check_unit(&self, t: &Telemetry) -> Result<(), String> {
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

    /// The message for a link that failed under a read or a write.
    pub(super) fn lost(&self, e: &std::io::Error, op: &str) -> String {
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
    pub(super) fn next_telemetry(&mut self) -> Result<Telemetry, String> {
        loop {
            if let Some(t) = self.poll_telemetry(None)? {
                return Ok(t);
            }
        }
    }

    /// The next telemetry frame, or `None` once `until` has passed without one. No valid
    /// telemetry for the reply timeout is an error ([`BoardInTheLoop::silence`]), whatever
    /// `until` says (**Choice 64**, docs/board.md#hardware-in-the-loop: every wait bounded, silence told from
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
            // The set-up and a lock-step period may wait up to the reply timeout (an hour):
            // a stop request ends the wait (Choice 120).
            if interrupt::requested() {
                return Err("interrupted while waiting for the board".to_string());
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

    /// The telemetry of the board's next control period (later than any seen before).
    pub(super) fn next_period(&mut self) -> Result<Telemetry, String> {
        loop {
            if let Some(t) = self.poll_period(None)? {
                return Ok(t);
            }
        }
    }

    /// [`BoardInTheLoop::next_period`], or `None` once `until` has passed; in real time,
    /// counts the board's periods missing between two telemetry frames.
    pub(super) fn poll_period(
        &mut self,
        until: Option<Instant>,
    ) -> Result<Option<Telemetry>, String> {
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

    pub(super) fn note_status(&mut self, t: &Telemetry, k: u64) {
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
        self.stats.board_rx_ahead = t.rx_ahead;
        self.stats.board_refused_commands = t.refused_commands;
        self.stats.board_last_refusal = t.last_refusal.map(|r| r.as_str().to_string());
        self.stats.board_loop_overruns = t.loop_overruns;
        self.stats.board_thrust_unit = Some(unit_name(t.thrust_unit).to_string());
        self.stats.board_reversed_thrusters = Some(t.reversed_thrusters);
        self.stats.worst_update_board_ticks = u64::from(t.worst_update_ticks);
        self.stats.worst_update_instructions =
            t.worst_update_ticks as u64 * INSTRUCTIONS_PER_TICK as u64;
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
