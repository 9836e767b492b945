//! Frames: encoding, one-shot decoding and the streaming [`FrameDecoder`].
//!
//! COBS (Cheshire & Baker, 1999) is the [`cobs`] crate's; this module decides what it is applied
//! to (postcard ‖ CRC), what a frame may contain, and how errors are reported.

use crate::msg::{Envelope, PROTOCOL_VERSION};
use crate::sign::{AuthError, Signer, Verifier, SIGNATURE_LEN};
use core::fmt;

/// CRC-16/IBM-3740 (a.k.a. CRC-16/CCITT-FALSE): poly 0x1021, init 0xFFFF, no reflection,
/// no final XOR; check value ("123456789") 0x29B1.
pub(crate) const CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740);

/// Length of the CRC trailer (bytes, little-endian).
pub const CRC_LEN: usize = 2;

/// Worst-case length of the un-stuffed frame body: postcard(Envelope) ‖ signature ‖ CRC.
pub const MAX_BODY: usize = Envelope::MAX_SIZE + SIGNATURE_LEN + CRC_LEN;

/// Worst-case length of a complete frame on the wire: COBS of the body plus the `0x00`
/// delimiter. An `out` buffer of this size makes [`encode`] infallible, and a receiver never
/// needs more.
pub const MAX_FRAME: usize = cobs::max_encoding_length(MAX_BODY) + 1;

// COBS implementations differ only for data that ends in a run of 254 non-zero bytes (some
// append a final code byte 0x01, some do not). A body shorter than that never has such a run,
// so the wire form of every frame is the one COBS form, whatever the crate's choice.
const _: () = assert!(MAX_BODY < 254);

/// Why a frame was not encoded or not accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkError {
    /// More than `MAX_FRAME − 1` bytes without a delimiter: the bytes up to the next `0x00`
    /// are dropped.
    Overflow,
    /// Not a valid COBS encoding (a code byte runs past the end of the frame, or the frame
    /// holds a `0x00`).
    Cobs,
    /// The CRC does not match (or the frame is too short to hold one).
    Crc,
    /// The CRC matched but the body is not a postcard `Envelope` of this version (unknown
    /// variant, bad `Option`/`bool` tag, bytes missing or left over).
    Deserialize,
    /// The CRC matched but the sender speaks another protocol version.
    Version {
        /// The version byte received.
        got: u8,
    },
    /// [`encode`]: `out` is too short for this frame (`MAX_FRAME` bytes always suffice).
    BufferTooSmall,
    /// [`encode`]: postcard refused the message (cannot happen while `Envelope::MAX_SIZE` is
    /// right).
    Serialize,
    /// CRC, version and body are fine, but the frame's authentication is not
    /// ([`crate::sign`]): unsigned on a signed link, signed on an unsigned one, a replayed
    /// timestamp, a wrong direction, a bad MAC, or (the board's end) a timestamp too far
    /// ahead. From [`encode_signed`]: the signer's timestamp is exhausted.
    Auth(AuthError),
}

impl fmt::Display for LinkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinkError::Overflow => write!(f, "frame longer than {} bytes", MAX_FRAME - 1),
            LinkError::Cobs => f.write_str("invalid COBS encoding"),
            LinkError::Crc => f.write_str("CRC mismatch"),
            LinkError::Deserialize => f.write_str("malformed message"),
            LinkError::Version { got } => {
                write!(f, "protocol version {got}, expected {PROTOCOL_VERSION}")
            }
            LinkError::BufferTooSmall => f.write_str("output buffer too small for the frame"),
            LinkError::Serialize => f.write_str("message could not be serialized"),
            LinkError::Auth(e) => write!(f, "authentication: {e}"),
        }
    }
}

impl core::error::Error for LinkError {}

/// Encodes `env` as one complete unsigned frame, delimiter included, into `out`, and returns
/// the frame's length. Never panics; fails only if `out` is too short (`out.len() >= MAX_FRAME`
/// always suffices). The version field is sent as it is (use [`Envelope::new`] for the current
/// one).
pub fn encode(env: &Envelope, out: &mut [u8]) -> Result<usize, LinkError> {
    encode_with(env, None, out)
}

/// As [`encode`], with the signature trailer of [`crate::sign`] (the signer's next timestamp;
/// one is used even if `out` turns out too short). Fails also if the signer's timestamp is
/// exhausted.
pub fn encode_signed(
    env: &Envelope,
    signer: &mut Signer,
    out: &mut [u8],
) -> Result<usize, LinkError> {
    encode_with(env, Some(signer), out)
}

fn encode_with(
    env: &Envelope,
    signer: Option<&mut Signer>,
    out: &mut [u8],
) -> Result<usize, LinkError> {
    let mut body = [0u8; MAX_BODY];
    let mut n = postcard::to_slice(env, &mut body[..Envelope::MAX_SIZE])
        .map_err(|_| LinkError::Serialize)?
        .len();
    if let Some(signer) = signer {
        let trailer = signer.sign(&body[..n]).map_err(LinkError::Auth)?;
        body[n..n + SIGNATURE_LEN].copy_from_slice(&trailer);
        n += SIGNATURE_LEN;
    }
    let crc = CRC.checksum(&body[..n]).to_le_bytes();
    body[n..n + CRC_LEN].copy_from_slice(&crc);
    let len = cobs::try_encode(&body[..n + CRC_LEN], out).map_err(|_| LinkError::BufferTooSmall)?;
    *out.get_mut(len).ok_or(LinkError::BufferTooSmall)? = 0;
    Ok(len + 1)
}

/// Decodes one frame of an unsigned link, given without its `0x00` delimiter. The buffer is
/// used as scratch (COBS is undone in place). Checks, in order: length (≤ `MAX_FRAME − 1`, else
/// `Overflow`), COBS, CRC, version byte, then the postcard body, which must be followed by
/// nothing (a signature trailer is [`AuthError::SigningOff`]). Never panics.
pub fn decode_frame(frame: &mut [u8]) -> Result<Envelope, LinkError> {
    decode(frame, None)
}

/// As [`decode_frame`], on a signed link: the body must be followed by a signature trailer
/// that `verifier` accepts (direction, a newer timestamp, the MAC and, if bounded, a timestamp
/// not too far ahead; [`crate::sign`]).
pub fn decode_frame_signed(
    frame: &mut [u8],
    verifier: &mut Verifier,
) -> Result<Envelope, LinkError> {
    decode(frame, Some(verifier))
}

fn decode(frame: &mut [u8], verifier: Option<&mut Verifier>) -> Result<Envelope, LinkError> {
    if frame.len() > MAX_FRAME - 1 {
        return Err(LinkError::Overflow);
    }
    // An empty frame has no room for a CRC. A 0x00 can only come from a caller that did not
    // split at the delimiters: it is not COBS (the crate would stop at it and decode the rest
    // as the next frame's).
    if frame.is_empty() {
        return Err(LinkError::Crc);
    }
    if frame.contains(&0) {
        return Err(LinkError::Cobs);
    }
    let n = cobs::decode_in_place(frame).map_err(|_| LinkError::Cobs)?;
    let body = frame.get(..n).ok_or(LinkError::Cobs)?;
    let split = n.checked_sub(CRC_LEN).ok_or(LinkError::Crc)?;
    let (payload, crc) = body.split_at(split);
    if CRC.checksum(payload).to_le_bytes() != crc {
        return Err(LinkError::Crc);
    }
    match payload.first() {
        None => return Err(LinkError::Deserialize),
        Some(&v) if v != PROTOCOL_VERSION => return Err(LinkError::Version { got: v }),
        Some(_) => {}
    }
    let (env, rest) =
        postcard::take_from_bytes::<Envelope>(payload).map_err(|_| LinkError::Deserialize)?;
    let covered = &payload[..payload.len() - rest.len()];
    match (rest.len(), verifier) {
        (0, None) => Ok(env),
        (0, Some(_)) => Err(LinkError::Auth(AuthError::Unsigned)),
        (SIGNATURE_LEN, None) => Err(LinkError::Auth(AuthError::SigningOff)),
        (SIGNATURE_LEN, Some(v)) => {
            let trailer =
                <&[u8; SIGNATURE_LEN]>::try_from(rest).map_err(|_| LinkError::Deserialize)?;
            v.verify(covered, trailer).map_err(LinkError::Auth)?;
            Ok(env)
        }
        _ => Err(LinkError::Deserialize),
    }
}

/// Streaming receiver: feed it every received byte; it hands back a result each time a `0x00`
/// completes a frame.
///
/// Fixed memory (`MAX_FRAME − 1` bytes of buffer), no heap, never panics. `push` is O(1) except
/// on a delimiter that completes a frame, where [`decode_frame`] runs over at most
/// `MAX_FRAME − 1` bytes. Empty frames (consecutive delimiters) are ignored. After any error the
/// decoder starts afresh at the next delimiter.
#[derive(Clone, Debug)]
pub struct FrameDecoder {
    buf: [u8; MAX_FRAME - 1],
    len: usize,
    /// Dropping bytes until the next delimiter (after an overflow or [`resync`](Self::resync)).
    discarding: bool,
    frames: u32,
    errors: u32,
    /// Signing on: every frame must carry a signature this verifier accepts.
    verifier: Option<Verifier>,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    /// An empty decoder of an unsigned link ([`decode_frame`]); the first frame may start at the
    /// first byte.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; MAX_FRAME - 1],
            len: 0,
            discarding: false,
            frames: 0,
            errors: 0,
            verifier: None,
        }
    }

    /// An empty decoder of a signed link ([`decode_frame_signed`] with `verifier`).
    pub fn signed(verifier: Verifier) -> Self {
        FrameDecoder {
            verifier: Some(verifier),
            ..Self::new()
        }
    }

    /// The verifier of a signed link (`None`: signing off).
    pub const fn verifier(&self) -> Option<&Verifier> {
        self.verifier.as_ref()
    }

    /// The receiver's own time moved on by `units` (10 µs each): passed to a signed link's
    /// verifier ([`Verifier::elapse`]); nothing on an unsigned link.
    pub fn elapse(&mut self, units: u64) {
        if let Some(v) = &mut self.verifier {
            v.elapse(units);
        }
    }

    /// Takes one received byte. Returns `Some` when the byte completes a frame (a `0x00` after
    /// a non-empty frame) and when a frame overflows (`Err(Overflow)`, reported once, at the
    /// byte that overflows; the rest of that frame up to the next `0x00` is dropped).
    pub fn push(&mut self, byte: u8) -> Option<Result<Envelope, LinkError>> {
        if byte == 0 {
            let len = core::mem::take(&mut self.len);
            if core::mem::take(&mut self.discarding) || len == 0 {
                return None;
            }
            let result = match self.buf.get_mut(..len) {
                Some(frame) => decode(frame, self.verifier.as_mut()),
                None => Err(LinkError::Overflow),
            };
            return Some(self.count(result));
        }
        if self.discarding {
            return None;
        }
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = byte;
                self.len += 1;
                None
            }
            None => {
                self.len = 0;
                self.discarding = true;
                Some(self.count(Err(LinkError::Overflow)))
            }
        }
    }

    /// Pushes every byte of `bytes` and calls `on_frame` with each result, in order.
    pub fn push_slice(
        &mut self,
        bytes: &[u8],
        mut on_frame: impl FnMut(Result<Envelope, LinkError>),
    ) {
        for &b in bytes {
            if let Some(result) = self.push(b) {
                on_frame(result);
            }
        }
    }

    /// Drops the partial frame and every byte up to the next delimiter (call after a UART
    /// overrun or framing error: the frame in progress has lost bytes).
    pub fn resync(&mut self) {
        self.len = 0;
        self.discarding = true;
    }

    /// Frames accepted since creation (wrapping).
    pub const fn rx_frames(&self) -> u32 {
        self.frames
    }

    /// Errors reported since creation (wrapping): every `Err` that `push` returned.
    pub const fn rx_errors(&self) -> u32 {
        self.errors
    }

    fn count(&mut self, result: Result<Envelope, LinkError>) -> Result<Envelope, LinkError> {
        match result {
            Ok(_) => self.frames = self.frames.wrapping_add(1),
            Err(_) => self.errors = self.errors.wrapping_add(1),
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::{Command, Msg};

    #[test]
    fn crc_is_ccitt_false() {
        assert_eq!(CRC.checksum(b"123456789"), 0x29B1);
    }

    #[test]
    fn short_frames_are_errors_not_panics() {
        for frame in [&[][..], &[0x01], &[0x02, 0x05], &[0x01, 0x01, 0x01]] {
            let mut buf = [0u8; 4];
            buf[..frame.len()].copy_from_slice(frame);
            assert!(decode_frame(&mut buf[..frame.len()]).is_err());
        }
        // A valid CRC over an empty payload: no version byte.
        let crc = CRC.checksum(&[]).to_le_bytes();
        let mut buf = [0u8; 4];
        let n = cobs::try_encode(&crc, &mut buf).unwrap();
        assert_eq!(decode_frame(&mut buf[..n]), Err(LinkError::Deserialize));
    }

    #[test]
    fn a_zero_inside_a_frame_is_not_cobs() {
        // A valid frame followed by a 0x00 and more bytes, given as one frame: the COBS crate
        // alone would decode up to the 0x00 and accept it.
        let env = Envelope::new(9, Msg::Command(Command::Arm));
        let mut out = [0u8; MAX_FRAME + 2];
        let n = encode(&env, &mut out).unwrap();
        let mut copy = out;
        assert_eq!(decode_frame(&mut copy[..n - 1]), Ok(env));
        out[n] = 0x01;
        assert_eq!(decode_frame(&mut out[..n + 1]), Err(LinkError::Cobs));
        // Empty: no room for a CRC (as before the COBS crate).
        assert_eq!(decode_frame(&mut []), Err(LinkError::Crc));
    }

    #[test]
    fn trailing_bytes_are_rejected() {
        let env = Envelope::new(7, Msg::Command(Command::Disarm));
        let mut body = [0u8; MAX_BODY + 1];
        let n = postcard::to_slice(&env, &mut body).unwrap().len();
        body[n] = 0xAA; // one extra byte, covered by the CRC
        let crc = CRC.checksum(&body[..n + 1]).to_le_bytes();
        body[n + 1..n + 3].copy_from_slice(&crc);
        let mut frame = [0u8; MAX_FRAME + 1];
        let m = cobs::try_encode(&body[..n + 3], &mut frame).unwrap();
        assert_eq!(decode_frame(&mut frame[..m]), Err(LinkError::Deserialize));
    }

    #[test]
    fn encode_reports_short_output() {
        let env = Envelope::new(1, Msg::Command(Command::StopMission));
        let mut out = [0u8; MAX_FRAME];
        let n = encode(&env, &mut out).unwrap();
        for len in 0..n {
            assert_eq!(
                encode(&env, &mut out[..len]),
                Err(LinkError::BufferTooSmall),
                "len {len}"
            );
        }
        assert_eq!(encode(&env, &mut out[..n]), Ok(n));
    }

    #[test]
    fn resync_drops_the_partial_frame() {
        let env = Envelope::new(3, Msg::Command(Command::Arm));
        let mut out = [0u8; MAX_FRAME];
        let n = encode(&env, &mut out).unwrap();
        let mut dec = FrameDecoder::new();
        for &b in &out[..n / 2] {
            assert_eq!(dec.push(b), None);
        }
        dec.resync();
        for &b in &out[n / 2..n] {
            assert_eq!(dec.push(b), None);
        }
        let mut got = None;
        dec.push_slice(&out[..n], |r| got = Some(r));
        assert_eq!(got, Some(Ok(env)));
        assert_eq!((dec.rx_frames(), dec.rx_errors()), (1, 0));
    }

    #[test]
    fn display_names_the_problem() {
        extern crate std;
        use std::string::ToString;
        assert_eq!(
            LinkError::Version { got: 1 }.to_string(),
            "protocol version 1, expected 8"
        );
        assert_eq!(
            LinkError::Overflow.to_string(),
            std::format!("frame longer than {} bytes", MAX_FRAME - 1)
        );
    }
}
