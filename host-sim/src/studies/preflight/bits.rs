//! A hash for keys that are bits already (**Choice 562**): the sweep's heels, sample keys and
//! kept samples, and the chatter term's kept crossings (Choice 556).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hasher for keys that are bits already (a heel's `f64` bits, the words of a sample's
/// key), in the manner of FxHash: each word is folded in by a rotate, an exclusive or and a
/// multiplication (**Choice 562**). The std's SipHash resists chosen keys, which these are
/// not, at several times the cost: it was ~4 % of `check` on a 32-point route, hashing a
/// heel per box corner. Only the speed of a lookup depends on the hash, never what it finds.
#[derive(Clone, Copy, Default)]
pub(super) struct BitsHasher(u64);

impl BitsHasher {
    /// FxHash's multiplier (an odd constant with well-spread bits).
    const K: u64 = 0x517c_c1b7_2722_0a95;

    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(Self::K);
    }
}

impl Hasher for BitsHasher {
    fn finish(&self) -> u64 {
        // The product's high bits are its best mixed; the table reads the low ones.
        self.0.rotate_left(26)
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, word: u64) {
        self.add(word);
    }

    fn write_usize(&mut self, word: usize) {
        self.add(word as u64);
    }
}

/// A hash map keyed by bits ([`BitsHasher`]).
pub(super) type BitsMap<K, V> = HashMap<K, V, BuildHasherDefault<BitsHasher>>;
