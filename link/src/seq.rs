//! Sequence numbers: which frame is newer than which, with wrap-around.
//!
//! Each direction of the link numbers its frames with [`Envelope::seq`](crate::Envelope::seq),
//! +1 per frame sent, wrapping from 65 535 to 0. A receiver accepts a frame only if its number
//! is *newer* than the last one it accepted, in serial-number arithmetic (RFC 1982, with
//! `SERIAL_BITS` = 16): `s` is newer than `last` when the forward distance
//! `d = (s − last) mod 2¹⁶` is in `1..=SEQ_WINDOW`.
//!
//! - `d = 0`: the same frame again (a repeat, e.g. a recorded frame re-sent) — refused.
//! - `d > SEQ_WINDOW`: behind `last` (an old or reordered frame: RFC 1982 calls anything with
//!   `d > 2¹⁵` "less than"), or so far ahead that no frame between could have been lost
//!   in flight — refused.
//!
//! **Choice (the window):** [`SEQ_WINDOW`] = 1024 frames. RFC 1982 allows a window of up to
//! 2¹⁵ − 1; ours is smaller so that a frame from long ago that wraps round (or a restarted peer
//! whose numbering starts again) is refused, while a sender may still lose 1023 frames in a row
//! (10 s of a 100 Hz link, longer than any stale-state limit the board accepts) and be heard
//! again. A peer whose frames are refused because it restarted or lost more than that
//! resynchronises by reading the board's [`Telemetry::last_rx_seq`](crate::Telemetry) and
//! continuing from the next number (`host-sim pil` does so at connect).
//!
//! The receiver's first frame (after its own reset) is accepted whatever its number.

/// Largest forward distance `(seq − last) mod 2¹⁶` at which a frame counts as newer.
pub const SEQ_WINDOW: u16 = 1024;

// RFC 1982 defines "greater than" only for distances below 2^(SERIAL_BITS − 1).
const _: () = assert!(SEQ_WINDOW >= 1 && SEQ_WINDOW < 1 << 15);

/// True if `seq` is newer than `last`: `(seq − last) mod 2¹⁶` in `1..=SEQ_WINDOW`.
pub const fn is_newer(seq: u16, last: u16) -> bool {
    let d = seq.wrapping_sub(last);
    d >= 1 && d <= SEQ_WINDOW
}

/// A receiver's view of one direction's sequence numbers: the last number it accepted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SeqCheck {
    last: Option<u16>,
}

impl SeqCheck {
    /// Nothing accepted yet: the first frame is accepted whatever its number.
    pub const fn new() -> Self {
        SeqCheck { last: None }
    }

    /// True if [`accept`](Self::accept) would accept `seq` (checks only).
    pub const fn admits(&self, seq: u16) -> bool {
        match self.last {
            None => true,
            Some(last) => is_newer(seq, last),
        }
    }

    /// Accepts `seq` (and remembers it) if it is newer than the last accepted one
    /// ([`is_newer`]); otherwise leaves the state as it was and returns false.
    pub fn accept(&mut self, seq: u16) -> bool {
        let ok = self.admits(seq);
        if ok {
            self.last = Some(seq);
        }
        ok
    }

    /// The last accepted number (`None` before the first).
    pub const fn last(&self) -> Option<u16> {
        self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newer_is_rfc1982_within_the_window() {
        // Plain order.
        assert!(is_newer(1, 0));
        assert!(is_newer(100, 3));
        assert!(!is_newer(3, 3));
        assert!(!is_newer(2, 3));
        // Wrap-around: 0 follows 65535, 5 is 6 ahead of 65535.
        assert!(is_newer(0, u16::MAX));
        assert!(is_newer(5, u16::MAX));
        assert!(!is_newer(u16::MAX, 0));
        // The window's edges.
        assert!(is_newer(SEQ_WINDOW, 0));
        assert!(!is_newer(SEQ_WINDOW + 1, 0));
        assert!(is_newer(SEQ_WINDOW.wrapping_sub(10), u16::MAX - 9));
        assert!(!is_newer(SEQ_WINDOW.wrapping_sub(9), u16::MAX - 9));
    }

    #[test]
    fn every_distance_by_brute_force() {
        for last in [0u16, 1, 1000, 32767, 32768, 65000, u16::MAX] {
            for d in 0..=u16::MAX {
                let seq = last.wrapping_add(d);
                assert_eq!(
                    is_newer(seq, last),
                    (1..=u32::from(SEQ_WINDOW)).contains(&u32::from(d)),
                    "last {last}, seq {seq}"
                );
            }
        }
    }

    #[test]
    fn the_check_accepts_first_then_only_newer() {
        let mut c = SeqCheck::new();
        assert!(c.accept(40_000));
        assert!(!c.accept(40_000), "repeat");
        assert!(!c.accept(39_999), "older");
        assert!(c.accept(40_002), "one lost in between");
        assert_eq!(c.last(), Some(40_002));
        assert!(!c.accept(40_002 + SEQ_WINDOW + 1), "beyond the window");
        assert_eq!(c.last(), Some(40_002), "a refusal changes nothing");
    }
}
