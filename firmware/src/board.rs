//! What the firmware needs from a board, and one control period over it.
//!
//! A board provides five thruster PWM channels (`embedded_hal::pwm::SetDutyCycle`), the
//! navigation link (`embedded_io` serial), a period timer and a free-running tick counter.
//! [`period`] is the whole loop body; it is the same on every board.

use auv_link::sign::{Direction, LinkKey, Signer, Verifier, UNITS_PER_SECOND};
use auv_link::{encode, encode_signed, Envelope, FrameDecoder, LinkError, MAX_FRAME};
use controller_core::effectiveness::THRUSTERS;
use embedded_hal::pwm::SetDutyCycle;
use embedded_io::{Read, ReadReady, Write};

use crate::pwm;
use crate::supervisor::{Step, Supervisor};

/// A thruster board.
pub trait Board {
    type Thruster: SetDutyCycle;
    type Link: Read + Write + ReadReady;

    /// H-bridge supply voltage V_s (V).
    fn supply_voltage(&self) -> f32;
    /// The five thruster channels, order [main, vert fore, vert aft, horz fore, horz aft].
    fn thrusters(&mut self) -> &mut [Self::Thruster; THRUSTERS];
    /// The navigation link.
    fn link(&mut self) -> &mut Self::Link;
    /// Sets the control-loop rate (Hz).
    fn set_rate(&mut self, hz: u32);
    /// True if a period boundary passed since the last call (non-blocking; clears the flag).
    fn period_elapsed(&mut self) -> bool;
    /// Blocks until the next period boundary. Returns true if that boundary had already passed
    /// when called: the previous period overran.
    fn wait_period(&mut self) -> bool {
        let overrun = self.period_elapsed();
        if !overrun {
            while !self.period_elapsed() {}
        }
        overrun
    }
    /// A free-running up-counting timer, for timing `update` (board-specific unit).
    fn now(&self) -> u32;
    /// Feeds the watchdog (boards without one do nothing).
    fn feed_watchdog(&mut self) {}
}

/// Bytes the board reads from its link at a time.
const READ_CHUNK: usize = 64;

/// The board's end of the link: the streaming decoder (with the verifier if signing is on),
/// one frame of transmit space, the signer if signing is on, and the last read's bytes not yet
/// decoded.
pub struct LinkBuffers {
    pub decoder: FrameDecoder,
    pub tx: [u8; MAX_FRAME],
    signer: Option<Signer>,
    /// The last read, and how far it is decoded: the bytes after a frame whose command ran the
    /// period's long job wait here for the next period ([`pump`], Choice 226).
    rx: [u8; READ_CHUNK],
    rx_next: usize,
    rx_end: usize,
}

impl LinkBuffers {
    /// An unsigned link: unsigned frames in and out; signed frames are refused.
    pub fn new() -> Self {
        LinkBuffers {
            decoder: FrameDecoder::new(),
            tx: [0; MAX_FRAME],
            signer: None,
            rx: [0; READ_CHUNK],
            rx_next: 0,
            rx_end: 0,
        }
    }

    /// A signed link with `key` (auv_link::sign): only frames the navigation computer signed
    /// with it are accepted — none stamped too far ahead (`Verifier::bounded`, Choices 95–96)
    /// — and telemetry is signed with it.
    pub fn signed(key: &LinkKey) -> Self {
        LinkBuffers {
            signer: Some(Signer::new(key, Direction::FromBoard)),
            decoder: FrameDecoder::signed(Verifier::bounded(key, Direction::ToBoard)),
            ..Self::new()
        }
    }

    /// A signed link if `key` is given, else an unsigned one.
    pub fn with_key(key: Option<&LinkKey>) -> Self {
        key.map_or_else(Self::new, Self::signed)
    }

    /// Signing is on.
    pub fn signing(&self) -> bool {
        self.signer.is_some()
    }

    /// Encodes `env` into `tx` (signed if signing is on) and returns the frame. The board has
    /// no clock: its timestamp stays above the last one it accepted from the navigation
    /// computer, and above its own previous one (auv_link::sign).
    pub fn encode(&mut self, env: &Envelope) -> Result<&[u8], LinkError> {
        let n = match &mut self.signer {
            None => encode(env, &mut self.tx)?,
            Some(signer) => {
                if let Some(t) = self.decoder.verifier().and_then(|v| v.last_timestamp()) {
                    signer.advance_to(t);
                }
                encode_signed(env, signer, &mut self.tx)?
            }
        };
        Ok(&self.tx[..n])
    }

    /// A control period at `rate_hz` ended: the verifier counts its length (rounded up to the
    /// timestamp's 10 µs), so that a navigation computer stamping its clock across a silence
    /// the board lived through is not refused as too far ahead (Choice 96).
    pub fn period_passed(&mut self, rate_hz: u32) {
        let units = UNITS_PER_SECOND.div_ceil(u64::from(rate_hz.max(1)));
        self.decoder.elapse(units);
    }

    /// One received byte to the decoder, and what it completes to the supervisor.
    fn push(&mut self, sup: &mut Supervisor, b: u8) {
        match self.decoder.push(b) {
            Some(Ok(env)) => sup.on_envelope(&env),
            Some(Err(e)) => sup.on_link_error(&e),
            None => {}
        }
    }

    /// Decodes what is left of the last read, up to its end or until the period's long job
    /// ran; true if the period may read more.
    fn decode_held(&mut self, sup: &mut Supervisor) -> bool {
        while self.rx_next < self.rx_end {
            if sup.built_this_period() {
                return false;
            }
            let b = self.rx[self.rx_next];
            self.rx_next += 1;
            self.push(sup, b);
        }
        !sup.built_this_period()
    }
}

impl Default for LinkBuffers {
    fn default() -> Self {
        Self::new()
    }
}

/// Feeds received bytes to the decoder and each result to the supervisor: frames to
/// [`Supervisor::on_envelope`], errors to [`Supervisor::on_link_error`]. All of them (the
/// tests' and the self-test's way in; the loop reads through [`pump`]).
pub fn receive(sup: &mut Supervisor, bufs: &mut LinkBuffers, bytes: &[u8]) {
    for &b in bytes {
        bufs.push(sup, b);
    }
}

/// Reads whatever bytes are waiting (without blocking) into the supervisor, until the
/// period's long job ran.
///
/// **Choice 226:** a build (the controller's, or a waypoint trajectory's) is the period's one
/// long job. Once it ran, no further byte is decoded in the period: the rest of the read waits
/// in [`LinkBuffers`] (and the rest of the link in its queue) for the next period, which
/// starts after the job's overrun was counted where it happened ([`period`]). So a `SetConfig`,
/// `Arm`, `StartMission` and state frame sent together never fly in the period that rebuilt
/// the controller, a flood of configurations costs one rebuild per period, and the watchdog
/// is fed after at most one long job.
///
/// A read error means the byte stream is broken at that point (a UART line error: overrun,
/// framing, noise, or bytes dropped on a full queue, see [`crate::serial`]): the frame in
/// progress has lost bytes, so the decoder is resynchronised (it drops everything up to the
/// next delimiter) and the loss is counted as one receive error.
pub fn pump<L: Read + ReadReady>(link: &mut L, sup: &mut Supervisor, bufs: &mut LinkBuffers) {
    // What the last read left after a long job first.
    if !bufs.decode_held(sup) {
        return;
    }
    // Bounded: at most 16 reads per period, so a flooding link cannot stall the loop.
    for _ in 0..16 {
        match link.read_ready() {
            Ok(true) => {}
            _ => return,
        }
        match link.read(&mut bufs.rx) {
            Ok(0) => return,
            Ok(n) => (bufs.rx_next, bufs.rx_end) = (0, n),
            Err(_) => {
                bufs.decoder.resync();
                sup.on_rx_error();
                continue;
            }
        };
        if !bufs.decode_held(sup) {
            return;
        }
    }
}

/// Applies voltages to the thrusters (neutral duty for 0 V).
pub fn drive<B: Board>(board: &mut B, voltages: &[f32; THRUSTERS]) {
    let vs = board.supply_voltage();
    for (ch, v) in board.thrusters().iter_mut().zip(voltages.iter()) {
        // A PWM channel error leaves that channel as it was; there is nothing better to do
        // from here, and the next period retries.
        let _ = pwm::set_voltage(ch, *v, vs);
    }
}

/// One control period: wait for the period (or, in lock-step, for a state frame), read the
/// link, run the supervisor, drive the thrusters, send telemetry, feed the watchdog.
pub fn period<B: Board>(board: &mut B, sup: &mut Supervisor, bufs: &mut LinkBuffers) -> Step {
    let overrun = if sup.lockstep() {
        // Paced by state frames (processor in the loop): poll the link until a state frame
        // arrives. A silent link still ends the wait after one period, so the stale-state
        // fail-safe acts as it would on the timer.
        let _ = board.period_elapsed();
        while !sup.state_fresh() {
            pump(board.link(), sup, bufs);
            if board.period_elapsed() {
                break;
            }
        }
        false
    } else {
        board.wait_period()
    };
    pump(board.link(), sup, bufs);
    let step = {
        let now = || board.now();
        sup.step(overrun, &now)
    };
    drive(board, &step.voltages);
    let env = sup.envelope(step.telemetry);
    if let Ok(frame) = bufs.encode(&env) {
        let _ = board.link().write_all(frame);
    }
    bufs.period_passed(sup.rate_hz());
    if step.long_job && board.period_elapsed() {
        // The boundary passed during this period's long job, in a period that did not fly:
        // the overrun is counted here, where the work was, and the next period starts on the
        // next boundary instead of latching a mission started meanwhile (Choice 226). The link
        // counts the period the job took.
        sup.long_job_overran();
        bufs.period_passed(sup.rate_hz());
    }
    board.feed_watchdog();
    step
}
