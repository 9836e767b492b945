//! Frame authentication, in the manner of MAVLink 2 message signing.
//!
//! The CRC only detects noise: any peer that can compute it can arm the board and command
//! thrust. With signing on, each frame carries a 13-byte signature trailer after the postcard
//! bytes (and before the CRC, which covers it too):
//!
//! ```text
//! body:      postcard(Envelope) ‖ link id (1) ‖ timestamp (6, LE) ‖ MAC (6) ‖ CRC-16 (2)
//! MAC:       the first 6 bytes of HMAC-SHA-256(key, postcard(Envelope) ‖ link id ‖ timestamp)
//! ```
//!
//! - **Key:** 32 secret bytes ([`LinkKey`]), the same at both ends, provisioned in each end's
//!   configuration and never sent on the link (firmware/README.md says how a team makes and
//!   stores one). Its [`fingerprint`](LinkKey::fingerprint) may be logged to check that both
//!   ends hold the same key.
//! - **Link id:** the direction ([`Direction`]): a frame signed for one direction does not
//!   verify in the other, so a board's own frames cannot be reflected back to it.
//! - **Timestamp:** 48 bits, strictly increasing per direction: the receiver refuses any
//!   timestamp not above the last one it accepted (replay protection, checked before the MAC
//!   is computed, committed only after it matched). As in MAVLink the sender may use time —
//!   `host-sim` uses 10 µs units since 2015-01-01 UTC ([`UNITS_PER_SECOND`]), MAVLink's, so
//!   that a restarted host still counts upwards — or a counter: the board has no clock, and
//!   stamps each frame with one more than the larger of its previous stamp and the last stamp
//!   it accepted from the navigation computer ([`Signer::advance_to`]), so after a reset its
//!   stamps rise above everything it sent before as soon as it has heard one signed frame.
//! - **How far ahead (the board's end, [`Verifier::bounded`]):** because the board follows its
//!   peer's stamps, a key holder that stamped a frame at 2⁴⁸ − 1 would leave it nothing to sign
//!   with until it reset. So the board also refuses an authentic frame ([`AuthError::Ahead`])
//!   whose timestamp is above [`CEILING`] (2⁴⁸ − 2⁴⁰: its telemetry can always be signed for
//!   another 2⁴⁰ frames, 174 years at 200 Hz), or more than [`MAX_LEAD`] (10 minutes) ahead of
//!   the last one it accepted plus the time it counted since ([`Verifier::elapse`]): a
//!   navigation computer stamping its clock across any silence the board lived through is
//!   accepted, a clock that jumps ahead of the board's count by more than 10 minutes is not.
//!   The first frame after a reset is bounded by the ceiling only (the board cannot know where
//!   its peer's clock is). docs/link.md#how-far-ahead-a-stamp-may-run, Choices 95–96.
//! - **MAC:** HMAC-SHA-256 (the `hmac` and `sha2` crates: no_std, no heap), truncated to 48
//!   bits as MAVLink does, compared in constant time. A forger's chance per attempt is 2⁻⁴⁸.
//!
//! **Policy:** a receiver with signing on refuses unsigned frames and frames whose link id,
//! timestamp or MAC is wrong ([`AuthError`]); a receiver with signing off refuses signed frames
//! (a half-configured link fails loudly at both ends instead of running half-protected).
//!
//! **Limits (as MAVLink's):** signing authenticates, it does not encrypt. The receiver keeps the
//! last timestamp in RAM only: after it resets, the first validly signed frame is accepted
//! whatever its timestamp (up to the board's [`CEILING`]), so a recording of earlier signed
//! traffic could be replayed into a board that has just reset and not yet heard its navigation
//! computer. The sequence numbers ([`crate::seq`]) and the lock-step mission clock limit what
//! such a replay can do, but do not prevent it; a persisted timestamp floor would.

use core::fmt;

use hmac::{Hmac, KeyInit, Mac};
use sha2::{Digest, Sha256};

/// Length of a [`LinkKey`] (bytes).
pub const KEY_LEN: usize = 32;
/// Length of the timestamp in the trailer (bytes): 48 bits.
pub const TIMESTAMP_LEN: usize = 6;
/// Length of the truncated MAC (bytes): 48 bits, as MAVLink 2.
pub const MAC_LEN: usize = 6;
/// Length of the signature trailer: link id, timestamp, MAC.
pub const SIGNATURE_LEN: usize = 1 + TIMESTAMP_LEN + MAC_LEN;
/// Largest timestamp: 2⁴⁸ − 1.
pub const MAX_TIMESTAMP: u64 = (1 << (8 * TIMESTAMP_LEN)) - 1;
/// Timestamp units per second: MAVLink's 10 µs.
pub const UNITS_PER_SECOND: u64 = 100_000;
/// **Choice 95:** the stamps a [bounded](Verifier::bounded) receiver keeps for its own signer:
/// 2⁴⁰, 174 years of frames at 200 Hz (the board's fastest loop) counted one by one, or 127
/// days of MAVLink time.
pub const RESERVE: u64 = 1 << 40;
/// **Choice 95:** the highest timestamp a [bounded](Verifier::bounded) receiver accepts,
/// `MAX_TIMESTAMP − RESERVE`, so that a board that follows its peer's stamps can sign another
/// [`RESERVE`] frames whatever its peer sent. In MAVLink time it is November 2103; a peer
/// stamping its clock never meets it before then.
pub const CEILING: u64 = MAX_TIMESTAMP - RESERVE;
/// **Choice 96:** how far a [bounded](Verifier::bounded) receiver lets a timestamp run ahead of
/// the last one it accepted plus the time it counted since ([`Verifier::elapse`]): 10 minutes
/// (6·10⁷ units, 60 000 frames at 100 Hz). It covers what the board's count does not see — a
/// navigation computer's clock stepped forward at its boot, the board held by a debugger, a
/// processor-in-the-loop board whose emulated clock lags the host's while a reply is awaited
/// (at most the host's reply timeout, seconds) — and is the longest a frame accepted from a
/// wrong clock can lock its peer's later frames out as replays.
pub const MAX_LEAD: u64 = 10 * 60 * UNITS_PER_SECOND;

/// HMAC-SHA-256's block: keys up to this length are zero-padded to it (RFC 2104).
const BLOCK_LEN: usize = 64;

/// The link id byte of a signature: which way the frame travels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Direction {
    /// Navigation computer (or host-sim) → board.
    ToBoard = 0,
    /// Board → navigation computer.
    FromBoard = 1,
}

/// A 32-byte secret shared by the board and its navigation computer.
///
/// `Debug` shows the fingerprint, never the key.
#[derive(Clone, PartialEq, Eq)]
pub struct LinkKey([u8; KEY_LEN]);

/// Why a text is not a key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeyError {
    /// Not 64 hexadecimal digits (after trimming white space).
    Length {
        /// Characters found.
        got: usize,
    },
    /// A character that is not a hexadecimal digit, at this index (0-based, after trimming).
    NotHex {
        /// Its index.
        at: usize,
    },
}

impl fmt::Display for KeyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KeyError::Length { got } => write!(
                f,
                "a link key is {} hexadecimal digits ({KEY_LEN} bytes), got {got} characters",
                2 * KEY_LEN
            ),
            KeyError::NotHex { at } => {
                write!(f, "a link key is hexadecimal; character {at} is not")
            }
        }
    }
}

impl core::error::Error for KeyError {}

impl LinkKey {
    /// A key from its bytes.
    pub const fn new(bytes: [u8; KEY_LEN]) -> Self {
        LinkKey(bytes)
    }

    /// A key from 64 hexadecimal digits (either case; surrounding white space ignored), the
    /// form of `AUV150_LINK_KEY` and of key files.
    pub fn from_hex(text: &str) -> Result<Self, KeyError> {
        let text = text.trim().as_bytes();
        if text.len() != 2 * KEY_LEN {
            return Err(KeyError::Length { got: text.len() });
        }
        let mut key = [0u8; KEY_LEN];
        for (i, byte) in key.iter_mut().enumerate() {
            let hi = hex_digit(text[2 * i]).ok_or(KeyError::NotHex { at: 2 * i })?;
            let lo = hex_digit(text[2 * i + 1]).ok_or(KeyError::NotHex { at: 2 * i + 1 })?;
            *byte = hi << 4 | lo;
        }
        Ok(LinkKey(key))
    }

    /// A key from a key file's text: lines starting with `#` and blank lines are comments, and
    /// the one line left is the key in hexadecimal ([`from_hex`](Self::from_hex)).
    pub fn from_key_file(text: &str) -> Result<Self, KeyError> {
        let mut lines = text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'));
        match (lines.next(), lines.next()) {
            (Some(key), None) => LinkKey::from_hex(key),
            (None, _) => Err(KeyError::Length { got: 0 }),
            (Some(key), Some(more)) => Err(KeyError::Length {
                got: key.len() + more.len(),
            }),
        }
    }

    /// The key's bytes.
    pub const fn bytes(&self) -> &[u8; KEY_LEN] {
        &self.0
    }

    /// The first 4 bytes of SHA-256(key), big-endian: a public name for the key, to log at
    /// both ends and compare. It reveals nothing usable about the key.
    pub fn fingerprint(&self) -> u32 {
        let h = Sha256::digest(self.0);
        u32::from_be_bytes([h[0], h[1], h[2], h[3]])
    }

    /// HMAC-SHA-256 keyed with this key (the key's pads hashed once, here; each frame then
    /// clones the state).
    fn mac(&self) -> Hmac<Sha256> {
        let mut block = [0u8; BLOCK_LEN];
        block[..KEY_LEN].copy_from_slice(&self.0);
        <Hmac<Sha256> as KeyInit>::new(&block.into())
    }
}

impl fmt::Debug for LinkKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "LinkKey(fingerprint {:08x})", self.fingerprint())
    }
}

fn hex_digit(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// Why a frame's authentication failed (or why a frame could not be signed).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AuthError {
    /// Signing is on, and the frame carries no signature.
    Unsigned,
    /// Signing is off at this end, and the frame carries a signature.
    SigningOff,
    /// The signature's link id is not this receiver's direction.
    WrongDirection {
        /// The link id byte received.
        got: u8,
    },
    /// The timestamp is not above the last one accepted: a replay, or frames out of order.
    Replay,
    /// The MAC does not match: wrong key, or the frame was altered.
    BadMac,
    /// [`encode_signed`](crate::encode_signed): the sender's timestamp reached
    /// [`MAX_TIMESTAMP`]; a new key is due.
    TimestampExhausted,
    /// A [bounded](Verifier::bounded) receiver: the frame is authentic, but its timestamp is
    /// above [`CEILING`] or more than [`MAX_LEAD`] ahead of the last one accepted plus the time
    /// counted since (a peer's clock that jumped, or a stamp near 2⁴⁸).
    Ahead,
}

impl fmt::Display for AuthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AuthError::Unsigned => f.write_str("unsigned frame, signing is on"),
            AuthError::SigningOff => f.write_str("signed frame, signing is off at this end"),
            AuthError::WrongDirection { got } => {
                write!(f, "signature for link id {got}, not this direction")
            }
            AuthError::Replay => f.write_str("signature timestamp not newer (replay)"),
            AuthError::BadMac => f.write_str("bad signature"),
            AuthError::TimestampExhausted => f.write_str("signing timestamp exhausted"),
            AuthError::Ahead => f.write_str("signature timestamp too far ahead"),
        }
    }
}

/// The sending end of a signed direction: the keyed MAC, the direction and the last timestamp
/// used.
#[derive(Clone)]
pub struct Signer {
    mac: Hmac<Sha256>,
    direction: Direction,
    timestamp: u64,
}

impl Signer {
    /// A signer whose first frame gets timestamp 1 (unless [`advance_to`](Self::advance_to)
    /// moves it on).
    pub fn new(key: &LinkKey, direction: Direction) -> Self {
        Signer {
            mac: key.mac(),
            direction,
            timestamp: 0,
        }
    }

    /// The next frame's timestamp will be above `t` (and above every earlier one): never moves
    /// backwards. Values above [`MAX_TIMESTAMP`] count as `MAX_TIMESTAMP`.
    pub fn advance_to(&mut self, t: u64) {
        self.timestamp = self.timestamp.max(t.min(MAX_TIMESTAMP));
    }

    /// The timestamp of the last frame signed (0 before the first).
    pub const fn timestamp(&self) -> u64 {
        self.timestamp
    }

    /// The direction this signer signs for.
    pub const fn direction(&self) -> Direction {
        self.direction
    }

    /// The trailer for `covered` (the frame's postcard bytes), with the next timestamp.
    pub(crate) fn sign(&mut self, covered: &[u8]) -> Result<[u8; SIGNATURE_LEN], AuthError> {
        if self.timestamp >= MAX_TIMESTAMP {
            return Err(AuthError::TimestampExhausted);
        }
        self.timestamp += 1;
        let mut trailer = [0u8; SIGNATURE_LEN];
        trailer[0] = self.direction as u8;
        trailer[1..1 + TIMESTAMP_LEN].copy_from_slice(&self.timestamp.to_le_bytes()[..6]);
        let tag = tag(self.mac.clone(), covered, &trailer[..1 + TIMESTAMP_LEN]);
        trailer[1 + TIMESTAMP_LEN..].copy_from_slice(&tag[..MAC_LEN]);
        Ok(trailer)
    }
}

/// The receiving end of a signed direction: the keyed MAC, the direction expected, the last
/// timestamp accepted and, if bounded, the time counted since.
#[derive(Clone)]
pub struct Verifier {
    mac: Hmac<Sha256>,
    direction: Direction,
    last: Option<u64>,
    /// The board's end: the ceiling and the lead bound apply.
    bounded: bool,
    /// Time counted since `last` was accepted (or since creation), in timestamp units.
    counted: u64,
}

impl Verifier {
    /// A verifier that has accepted nothing yet: the first valid frame's timestamp may be any,
    /// and each later one any above the last (MAVLink's rule; the navigation computer's end,
    /// which stamps with its own clock and does not follow the board's stamps).
    pub fn new(key: &LinkKey, direction: Direction) -> Self {
        Verifier {
            mac: key.mac(),
            direction,
            last: None,
            bounded: false,
            counted: 0,
        }
    }

    /// A verifier for an end that follows its peer's stamps (the board): as [`new`](Self::new),
    /// and an authentic frame is also refused ([`AuthError::Ahead`]) if its timestamp is above
    /// [`CEILING`] or, after the first, more than [`MAX_LEAD`] above the last one accepted
    /// plus the time counted since ([`elapse`](Self::elapse)). Choices 95–96.
    pub fn bounded(key: &LinkKey, direction: Direction) -> Self {
        Verifier {
            bounded: true,
            ..Self::new(key, direction)
        }
    }

    /// The timestamp of the last frame accepted.
    pub const fn last_timestamp(&self) -> Option<u64> {
        self.last
    }

    /// The receiver's own time moved on by `units` (10 µs each): a bounded verifier lets the
    /// next timestamp run ahead of the last one accepted by as much more (the board calls it
    /// once per control period). Counts from the last accepted frame.
    pub fn elapse(&mut self, units: u64) {
        self.counted = self.counted.saturating_add(units);
    }

    /// The highest timestamp this verifier accepts now.
    pub fn limit(&self) -> u64 {
        match (self.bounded, self.last) {
            (false, _) => MAX_TIMESTAMP,
            (true, None) => CEILING,
            (true, Some(last)) => last
                .saturating_add(MAX_LEAD)
                .saturating_add(self.counted)
                .min(CEILING),
        }
    }

    /// Checks `trailer` against `covered` (the frame's postcard bytes): link id, then the
    /// timestamp against the last accepted, then the MAC, then (bounded) how far ahead the
    /// timestamp is. Remembers the timestamp only if all pass, so only authentic frames are
    /// counted as too far ahead.
    pub(crate) fn verify(
        &mut self,
        covered: &[u8],
        trailer: &[u8; SIGNATURE_LEN],
    ) -> Result<(), AuthError> {
        if trailer[0] != self.direction as u8 {
            return Err(AuthError::WrongDirection { got: trailer[0] });
        }
        let mut ts = [0u8; 8];
        ts[..TIMESTAMP_LEN].copy_from_slice(&trailer[1..1 + TIMESTAMP_LEN]);
        let ts = u64::from_le_bytes(ts);
        if self.last.is_some_and(|last| ts <= last) {
            return Err(AuthError::Replay);
        }
        let mut mac = self.mac.clone();
        mac.update(covered);
        mac.update(&trailer[..1 + TIMESTAMP_LEN]);
        mac.verify_truncated_left(&trailer[1 + TIMESTAMP_LEN..])
            .map_err(|_| AuthError::BadMac)?;
        if ts > self.limit() {
            return Err(AuthError::Ahead);
        }
        self.last = Some(ts);
        self.counted = 0;
        Ok(())
    }
}

impl fmt::Debug for Signer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Signer")
            .field("direction", &self.direction)
            .field("timestamp", &self.timestamp)
            .finish_non_exhaustive()
    }
}

impl fmt::Debug for Verifier {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Verifier")
            .field("direction", &self.direction)
            .field("last", &self.last)
            .field("bounded", &self.bounded)
            .field("counted", &self.counted)
            .finish_non_exhaustive()
    }
}

fn tag(mut mac: Hmac<Sha256>, covered: &[u8], id_and_time: &[u8]) -> [u8; 32] {
    mac.update(covered);
    mac.update(id_and_time);
    mac.finalize().into_bytes().into()
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::format;
    use std::string::ToString;

    /// RFC 4231 test case 2: key "Jefe", data "what do ya want for nothing?".
    #[test]
    fn the_mac_is_hmac_sha256_with_the_key_zero_padded() {
        let mut key = [0u8; KEY_LEN];
        key[..4].copy_from_slice(b"Jefe");
        let k = LinkKey::new(key);
        let mut mac = k.mac();
        mac.update(b"what do ya want for nothing?");
        let out: [u8; 32] = mac.finalize().into_bytes().into();
        // RFC 4231 §4.3, HMAC-SHA-256. Zero bytes appended to a short key do not change HMAC
        // (RFC 2104 pads the key with zeros to the block length).
        let want = [
            0x5b, 0xdc, 0xc1, 0x46, 0xbf, 0x60, 0x75, 0x4e, 0x6a, 0x04, 0x24, 0x26, 0x08, 0x95,
            0x75, 0xc7, 0x5a, 0x00, 0x3f, 0x08, 0x9d, 0x27, 0x39, 0x83, 0x9d, 0xec, 0x58, 0xb9,
            0x64, 0xec, 0x38, 0x43,
        ];
        assert_eq!(out, want);
    }

    #[test]
    fn keys_parse_from_hex_and_say_what_is_wrong() {
        let hex = "000102030405060708090a0b0c0d0e0f101112131415161718191A1B1C1D1E1F";
        let k = LinkKey::from_hex(&format!("  {hex}\n")).unwrap();
        let want: [u8; 32] = core::array::from_fn(|i| i as u8);
        assert_eq!(k.bytes(), &want);
        assert_eq!(
            LinkKey::from_hex(&hex[..62]),
            Err(KeyError::Length { got: 62 })
        );
        let mut bad = hex.to_string();
        bad.replace_range(10..11, "g");
        assert_eq!(LinkKey::from_hex(&bad), Err(KeyError::NotHex { at: 10 }));
    }

    #[test]
    fn key_files_have_comments_and_one_key_line() {
        let hex = "ab".repeat(KEY_LEN);
        let file = format!("# a comment\n\n  {hex}  \n# another\n");
        assert_eq!(
            LinkKey::from_key_file(&file),
            Ok(LinkKey::new([0xAB; KEY_LEN]))
        );
        assert!(LinkKey::from_key_file("# only a comment\n").is_err());
        assert!(LinkKey::from_key_file(&format!("{hex}\n{hex}\n")).is_err());
    }

    #[test]
    fn debug_never_shows_the_key() {
        let k = LinkKey::new([0xAB; KEY_LEN]);
        let shown = format!("{k:?}");
        assert!(!shown.contains("ab") && !shown.contains("AB") && !shown.contains("171"));
        assert!(shown.contains(&format!("{:08x}", k.fingerprint())));
    }

    #[test]
    fn sign_then_verify_then_every_refusal() {
        let key = LinkKey::new([7; KEY_LEN]);
        let mut tx = Signer::new(&key, Direction::ToBoard);
        let mut rx = Verifier::new(&key, Direction::ToBoard);
        let t1 = tx.sign(b"hello").unwrap();
        let t2 = tx.sign(b"hello").unwrap();
        assert_eq!(tx.timestamp(), 2);
        assert_eq!(rx.verify(b"hello", &t2), Ok(()));
        assert_eq!(rx.last_timestamp(), Some(2));
        assert_eq!(rx.verify(b"hello", &t2), Err(AuthError::Replay));
        assert_eq!(rx.verify(b"hello", &t1), Err(AuthError::Replay));
        let t3 = tx.sign(b"hello").unwrap();
        assert_eq!(rx.verify(b"hellO", &t3), Err(AuthError::BadMac));
        // A failed MAC does not move the timestamp on: the genuine frame still verifies.
        assert_eq!(rx.verify(b"hello", &t3), Ok(()));
        let mut other = Verifier::new(&key, Direction::FromBoard);
        let t4 = tx.sign(b"x").unwrap();
        assert_eq!(
            other.verify(b"x", &t4),
            Err(AuthError::WrongDirection { got: 0 })
        );
        let mut wrong_key = Verifier::new(&LinkKey::new([8; KEY_LEN]), Direction::ToBoard);
        assert_eq!(wrong_key.verify(b"x", &t4), Err(AuthError::BadMac));
        tx.advance_to(MAX_TIMESTAMP);
        assert_eq!(tx.sign(b"x"), Err(AuthError::TimestampExhausted));
    }

    #[test]
    fn advance_never_moves_back() {
        let mut tx = Signer::new(&LinkKey::new([1; KEY_LEN]), Direction::FromBoard);
        tx.advance_to(1000);
        tx.advance_to(10);
        assert_eq!(tx.timestamp(), 1000);
        let t = tx.sign(b"").unwrap();
        assert_eq!(&t[1..7], &1001u64.to_le_bytes()[..6]);
        assert_eq!(t[0], Direction::FromBoard as u8);
    }
}
