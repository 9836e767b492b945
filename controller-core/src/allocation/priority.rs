//! Which forces the allocator gives up first when a block cannot meet its demand
//! (docs/thrusters.md#allocation-blocks-and-the-axis-priority **Choice**).

use core::fmt;

use crate::axes::{ACTUATED, NAMES};

/// Which forces the allocator gives up first when a block cannot meet its demand
/// (docs/thrusters.md#allocation-blocks-and-the-axis-priority **Choice**), per row of τ = [X Y Z K M N] (the roll entries are not
/// used: roll is not actuated).
///
/// Within a block, the axis with the higher `rank` is met first (lexicographic); axes of
/// equal rank share the shortfall by weighted least squares with `weight`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisPriority {
    /// Priority of each axis; higher is more important.
    pub rank: [u8; 6],
    /// Least-squares weight of each axis (used between axes of equal rank); finite and > 0
    /// on the actuated axes. Forces are in N, moments in N m.
    pub weight: [f32; 6],
}

impl Default for AxisPriority {
    /// Pitch, depth, yaw, sway, surge (highest first); weights 1.
    fn default() -> Self {
        AxisPriority {
            //     X  Y  Z  K  M  N
            rank: [1, 2, 4, 0, 5, 3],
            weight: [1.0; 6],
        }
    }
}

impl AxisPriority {
    /// The first actuated axis whose weight is not finite and > 0, with the weight.
    pub fn invalid_weight(&self) -> Option<(usize, f32)> {
        ACTUATED
            .iter()
            .map(|&a| (a, self.weight[a]))
            .find(|&(_, w)| !(w.is_finite() && w > 0.0))
    }
}

impl fmt::Display for AxisPriority {
    /// The actuated axes from the highest rank down, e.g. `pitch > depth > yaw > sway > surge`
    /// (`=` between equal ranks).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut order = ACTUATED;
        // Insertion sort by rank, highest first (five entries).
        for i in 1..order.len() {
            let mut k = i;
            while k > 0 && self.rank[order[k]] > self.rank[order[k - 1]] {
                order.swap(k, k - 1);
                k -= 1;
            }
        }
        for (n, &a) in order.iter().enumerate() {
            if n > 0 {
                let sep = if self.rank[a] == self.rank[order[n - 1]] {
                    " = "
                } else {
                    " > "
                };
                f.write_str(sep)?;
            }
            f.write_str(NAMES[a])?;
        }
        Ok(())
    }
}
