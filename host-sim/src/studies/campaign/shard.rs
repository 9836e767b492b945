//! A shard's indices (**Choice 131**: i ≡ I (mod N), i < runs) and its bookkeeping of the runs
//! done, in memory that does not grow with the campaign (**Choice 244**): the indices are
//! iterated, never listed, and what is done is one bit a run of the shard, allocated only when a
//! rerun finds runs recorded (10⁹ runs: 125 MB; a fresh shard: nothing).

/// A shard: its index and the shard count, of a campaign of `runs` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub runs: u64,
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// How many runs the shard owns: the i < runs with i ≡ index (mod count).
    pub fn len(&self) -> u64 {
        if self.index >= self.runs || self.count == 0 {
            0
        } else {
            (self.runs - 1 - self.index) / self.count + 1
        }
    }

    /// True when the shard owns no run.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `k`-th run of the shard (k < [`Shard::len`]).
    pub fn run(&self, k: u64) -> u64 {
        self.index + k * self.count
    }

    /// Whether run `i` is the shard's.
    pub fn owns(&self, i: u64) -> bool {
        i < self.runs && self.count > 0 && i % self.count == self.index
    }
}

/// The runs of a shard recorded: one bit a run of the shard, allocated on the first insert.
#[derive(Clone, Debug)]
pub struct Done {
    shard: Shard,
    bits: Vec<u64>,
    count: u64,
}

impl Done {
    /// Nothing done yet (no memory).
    pub fn new(shard: Shard) -> Self {
        Done {
            shard,
            bits: Vec::new(),
            count: 0,
        }
    }

    /// Marks run `i` (the shard's) done; false if it was already, or is not the shard's.
    pub fn insert(&mut self, i: u64) -> bool {
        if !self.shard.owns(i) {
            return false;
        }
        if self.bits.is_empty() {
            self.bits = vec![0; self.shard.len().div_ceil(64) as usize];
        }
        let (word, bit) = Self::place(self.shard, i);
        let new = self.bits[word] & bit == 0;
        self.bits[word] |= bit;
        self.count += u64::from(new);
        new
    }

    /// Whether run `i` is done.
    pub fn contains(&self, i: u64) -> bool {
        if self.bits.is_empty() || !self.shard.owns(i) {
            return false;
        }
        let (word, bit) = Self::place(self.shard, i);
        self.bits[word] & bit != 0
    }

    /// Runs done.
    pub fn len(&self) -> u64 {
        self.count
    }

    /// True when no run is done.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Bytes of bookkeeping held.
    pub fn bytes(&self) -> usize {
        self.bits.capacity() * std::mem::size_of::<u64>()
    }

    fn place(shard: Shard, i: u64) -> (usize, u64) {
        let k = (i - shard.index) / shard.count;
        ((k / 64) as usize, 1 << (k % 64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form length and ownership against listing the indices.
    #[test]
    fn a_shard_owns_the_indices_congruent_to_it() {
        for runs in 1..40u64 {
            for count in 1..=runs {
                for index in 0..count {
                    let s = Shard { runs, index, count };
                    let listed: Vec<u64> = (0..runs).filter(|i| i % count == index).collect();
                    assert_eq!(s.len(), listed.len() as u64);
                    let made: Vec<u64> = (0..s.len()).map(|k| s.run(k)).collect();
                    assert_eq!(made, listed);
                    assert!((0..runs + 3).all(|i| s.owns(i) == listed.contains(&i)));
                }
            }
        }
        let s = Shard {
            runs: 1_000_000_000,
            index: 0,
            count: 1,
        };
        assert_eq!(s.len(), 1_000_000_000);
    }

    #[test]
    fn done_is_a_set_of_the_shards_runs_in_a_bit_each() {
        let s = Shard {
            runs: 1000,
            index: 2,
            count: 7,
        };
        let mut d = Done::new(s);
        assert_eq!(d.bytes(), 0);
        let mut reference = std::collections::BTreeSet::new();
        for i in (0..1000).rev().step_by(3) {
            assert_eq!(d.insert(i), s.owns(i) && reference.insert(i));
        }
        assert!(!d.insert(9), "recorded twice");
        assert_eq!(d.len(), reference.len() as u64);
        assert!((0..1100).all(|i| d.contains(i) == reference.contains(&i)));
        // 143 runs of the shard: three words.
        assert_eq!(d.bytes(), 3 * 8);
    }
}
