//! The runner's end of the board link ([`Link`]): frames out, numbered and signed if the link
//! is; telemetry in, decoded, verified and checked for sequence order; every wait bounded by
//! the reply timeout, with silence told from noise (**Choice 64**, docs/board.md#hardware-in-the-loop).

use std::collections::VecDeque;
use std::io;
use std::time::{Duration, Instant};

use auv_link::seq::SeqCheck;
use auv_link::sign::{AuthError, Direction, LinkKey, Signer, Verifier};
use auv_link::{
    encode, encode_signed, Envelope, FrameDecoder, LinkError, Msg, Telemetry, MAX_FRAME,
    PROTOCOL_VERSION,
};

use super::error::Error;
use super::frames::mavlink_time;
use super::transport::Transport;
use crate::interrupt;

/// The longest single read: the runner checks its deadlines at least this often.
const READ_SLICE: Duration = Duration::from_millis(100);
/// Telemetry frames [`Link::acknowledged`] waits for the board to take a frame (a lost frame is
/// never acknowledged: the wait ends on what the board says).
const ACK_FRAMES: u32 = 5;
/// The longest [`Link::acknowledged`] waits, whatever telemetry keeps coming.
const ACK_WAIT: Duration = Duration::from_secs(30);

/// The link to the board over a byte transport.
pub(super) struct Link {
    stream: Box<dyn Transport>,
    /// Where to look when the link fails (QEMU's log, or the serial port).
    context: String,
    decoder: FrameDecoder,
    /// Signing on: signs every frame sent.
    signer: Option<Signer>,
    /// The number of this end's next frame.
    seq: u16,
    /// The board's telemetry numbers.
    telemetry_seq: SeqCheck,
    /// Telemetry decoded but not yet taken.
    pending: VecDeque<Telemetry>,
    /// No valid telemetry for this long is an error.
    reply_timeout: Duration,
    read_timeout: Duration,
    /// When valid telemetry last arrived, and what came since (bytes, refused frames).
    heard: Instant,
    noise_bytes: u64,
    noise_refused: u64,
    /// Telemetry frames taken, and refused (undecodable, badly signed, out of sequence).
    telemetry_frames: u64,
    telemetry_refused: u64,
}

impl Link {
    /// The link over `stream`, signed with `key` if given; `context` is where to look when it
    /// fails.
    pub(super) fn new(
        stream: Box<dyn Transport>,
        context: String,
        key: Option<&LinkKey>,
        reply_timeout: Duration,
    ) -> Self {
        let mut decoder = match key {
            Some(k) => FrameDecoder::signed(Verifier::new(k, Direction::FromBoard)),
            None => FrameDecoder::new(),
        };
        // Joined mid-stream: what precedes the first delimiter is no frame (Choice 490).
        if stream.joins_mid_stream() {
            decoder.resync();
        }
        Link {
            stream,
            context,
            decoder,
            signer: key.map(|k| Signer::new(k, Direction::ToBoard)),
            seq: 0,
            telemetry_seq: SeqCheck::new(),
            pending: VecDeque::new(),
            reply_timeout,
            read_timeout: Duration::ZERO,
            heard: Instant::now(),
            noise_bytes: 0,
            noise_refused: 0,
            telemetry_frames: 0,
            telemetry_refused: 0,
        }
    }

    /// This end signs its frames (and the board's are verified).
    pub(super) fn signed(&self) -> bool {
        self.signer.is_some()
    }

    /// The number the next frame takes.
    pub(super) fn next_seq(&self) -> u16 {
        self.seq
    }

    /// The number of the last frame numbered.
    pub(super) fn last_seq(&self) -> u16 {
        self.seq.wrapping_sub(1)
    }

    /// Numbers this end's frames after `seq`, the board's last (a board that already heard a
    /// runner drops frames numbered at or before its last: `auv_link::seq`).
    pub(super) fn number_after(&mut self, seq: u16) {
        self.seq = seq.wrapping_add(1);
    }

    /// Numbers a frame that is never sent (lost on the way, on purpose).
    pub(super) fn skip(&mut self) {
        self.seq = self.seq.wrapping_add(1);
    }

    /// Telemetry frames taken and refused so far.
    pub(super) fn telemetry_counts(&self) -> (u64, u64) {
        (self.telemetry_frames, self.telemetry_refused)
    }

    /// When the last telemetry frame was taken.
    pub(super) fn heard(&self) -> Instant {
        self.heard
    }

    /// Numbers (and signs) `msg` and appends its frame to `out`; returns the frame's length.
    pub(super) fn append(&mut self, msg: Msg, out: &mut Vec<u8>) -> Result<usize, Error> {
        let mut buf = [0u8; MAX_FRAME];
        let env = Envelope {
            version: PROTOCOL_VERSION,
            seq: self.seq,
            msg,
        };
        self.seq = self.seq.wrapping_add(1);
        let n = match &mut self.signer {
            None => encode(&env, &mut buf),
            Some(signer) => {
                signer.advance_to(mavlink_time());
                encode_signed(&env, signer, &mut buf)
            }
        }
        .map_err(Error::Encode)?;
        out.extend_from_slice(&buf[..n]);
        Ok(n)
    }

    /// Sends `msg` in a frame of its own.
    pub(super) fn send(&mut self, msg: Msg) -> Result<(), Error> {
        let mut out = Vec::with_capacity(MAX_FRAME);
        self.append(msg, &mut out)?;
        self.write(&out)
    }

    /// Writes frames.
    pub(super) fn write(&mut self, bytes: &[u8]) -> Result<(), Error> {
        self.stream
            .write_frame(bytes)
            .map_err(|e| self.lost(e, "write"))
    }

    /// The error for a link that failed under a read or a write.
    fn lost(&self, io: io::Error, op: &'static str) -> Error {
        use io::ErrorKind;
        // EIO: a tty whose other end (a pty's master, a USB adapter) is gone.
        const EIO: i32 = 5;
        let gone = io.raw_os_error() == Some(EIO)
            || matches!(
                io.kind(),
                ErrorKind::UnexpectedEof | ErrorKind::BrokenPipe | ErrorKind::ConnectionReset
            );
        let context = self.context.clone();
        if gone {
            Error::LinkGone { io, context }
        } else {
            Error::LinkIo { op, io, context }
        }
    }

    /// Why no valid telemetry came for the reply timeout: nothing at all, or only noise.
    fn silence(&self) -> Error {
        let (waited, context) = (self.reply_timeout, self.context.clone());
        if self.noise_bytes == 0 {
            Error::Silent { waited, context }
        } else {
            Error::Noise {
                waited,
                bytes: self.noise_bytes,
                refused: self.noise_refused,
                context,
            }
        }
    }

    /// The next telemetry frame from the board (frames of other kinds are ignored).
    pub(super) fn next_telemetry(&mut self) -> Result<Telemetry, Error> {
        loop {
            if let Some(t) = self.poll_telemetry(None)? {
                return Ok(t);
            }
        }
    }

    /// The board's telemetry once it has taken frame `last` (or after [`ACK_FRAMES`] telemetry
    /// frames, if `last` was lost).
    pub(super) fn acknowledged(&mut self, last: u16) -> Result<Telemetry, Error> {
        let deadline = Instant::now() + ACK_WAIT;
        let mut frames = 0;
        loop {
            let t = self.next_telemetry()?;
            frames += 1;
            if t.last_rx_seq == last || frames >= ACK_FRAMES || Instant::now() > deadline {
                return Ok(t);
            }
        }
    }

    /// The next telemetry frame, or `None` once `until` has passed without one. No valid
    /// telemetry for the reply timeout is an error ([`Error::Silent`], [`Error::Noise`]),
    /// whatever `until` says.
    pub(super) fn poll_telemetry(
        &mut self,
        until: Option<Instant>,
    ) -> Result<Option<Telemetry>, Error> {
        let mut chunk = [0u8; 512];
        loop {
            if let Some(t) = self.pending.pop_front() {
                self.telemetry_frames += 1;
                self.heard = Instant::now();
                self.noise_bytes = 0;
                self.noise_refused = 0;
                return Ok(Some(t));
            }
            // The set-up and a lock-step period may wait up to the reply timeout (an hour):
            // a stop request ends the wait (Choice 120).
            if interrupt::requested() {
                return Err(Error::Interrupted {
                    waiting_for: "the board",
                });
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
            let n = self.read(wait.max(Duration::from_millis(1)), &mut chunk)?;
            for &b in &chunk[..n] {
                self.take(b)?;
            }
        }
    }

    /// Reads what came within `wait`.
    fn read(&mut self, wait: Duration, chunk: &mut [u8]) -> Result<usize, Error> {
        if wait != self.read_timeout {
            self.stream
                .set_read_timeout(wait)
                .map_err(|e| self.lost(e, "set-up"))?;
            self.read_timeout = wait;
        }
        let n = self
            .stream
            .read_some(chunk)
            .map_err(|e| self.lost(e, "read"))?;
        self.noise_bytes += n as u64;
        Ok(n)
    }

    /// Takes one received byte: a telemetry frame it completes is pending.
    fn take(&mut self, b: u8) -> Result<(), Error> {
        match self.decoder.push(b) {
            None => {}
            Some(Ok(Envelope {
                seq,
                msg: Msg::Telemetry(t),
                ..
            })) if self.telemetry_seq.accept(seq) => self.pending.push_back(t),
            // The two ends disagree on signing: nothing will ever be accepted.
            Some(Err(LinkError::Auth(error @ (AuthError::SigningOff | AuthError::Unsigned)))) => {
                return Err(Error::Signing { error });
            }
            // Undecodable, badly signed, out of sequence, or not telemetry.
            Some(_) => {
                self.telemetry_refused += 1;
                self.noise_refused += 1;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A transport that hands out `bytes` once, then nothing.
    struct Script {
        bytes: VecDeque<u8>,
        mid_stream: bool,
    }

    impl Transport for Script {
        fn read_some(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = buf.len().min(self.bytes.len());
            for (slot, b) in buf.iter_mut().zip(self.bytes.drain(..n)) {
                *slot = b;
            }
            Ok(n)
        }
        fn write_frame(&mut self, _: &[u8]) -> io::Result<()> {
            Ok(())
        }
        fn set_read_timeout(&mut self, _: Duration) -> io::Result<()> {
            Ok(())
        }
        fn joins_mid_stream(&self) -> bool {
            self.mid_stream
        }
    }

    fn frame(seq: u16) -> Vec<u8> {
        let env = Envelope {
            version: PROTOCOL_VERSION,
            seq,
            msg: Msg::Telemetry(Telemetry::LARGEST),
        };
        let mut buf = [0u8; MAX_FRAME];
        let n = encode(&env, &mut buf).expect("a telemetry frame fits");
        buf[..n].to_vec()
    }

    fn link(bytes: Vec<u8>, mid_stream: bool) -> Link {
        let stream = Script {
            bytes: bytes.into(),
            mid_stream,
        };
        Link::new(
            Box::new(stream),
            String::new(),
            None,
            Duration::from_secs(1),
        )
    }

    /// A serial port opened while the board talks starts inside a frame: its tail is not a
    /// refused frame (the HIL lock-step over QEMU's pty counted one, now and then, in CI).
    #[test]
    fn a_serial_line_joined_mid_frame_refuses_nothing() {
        let first = frame(7);
        let mut bytes = first[first.len() / 2..].to_vec();
        bytes.extend(frame(8));
        bytes.extend(frame(9));
        let mut l = link(bytes, true);
        assert_eq!(l.next_telemetry().ok().map(|_| ()), Some(()));
        assert_eq!(l.next_telemetry().ok().map(|_| ()), Some(()));
        assert_eq!(l.telemetry_counts(), (2, 0));
    }

    /// A socket starts at a frame's first byte: that frame is taken, and a broken one refused.
    #[test]
    fn a_socket_takes_its_first_frame_and_refuses_a_broken_one() {
        let mut bytes = frame(1);
        let second = frame(2);
        bytes.extend(&second[second.len() / 2..]);
        bytes.extend(frame(3));
        let mut l = link(bytes, false);
        assert!(l.next_telemetry().is_ok());
        assert!(l.next_telemetry().is_ok());
        assert_eq!(l.telemetry_counts(), (2, 1));
    }
}
