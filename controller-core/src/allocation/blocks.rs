//! The blocks of the allocation (docs/thrusters.md#allocation-blocks-and-the-axis-priority): groups of thrusters that share no actuated
//! axis with any other group, each with the rule by which it shares a shortfall, found once at
//! configuration time from B and the axis priority.

use nalgebra::Matrix6x5;

use crate::allocation::box_solution::Segment;
use crate::allocation::error::AllocationError;
use crate::allocation::priority::AxisPriority;
use crate::axes::ACTUATED;
use crate::effectiveness::THRUSTERS;

/// How a block shares its shortfall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Rule {
    /// One thruster for one axis: clamp.
    Single,
    /// Axis `a` (row 0 of `g`) strictly above axis `b`: meet `a` within its reach, then `b`
    /// on the segment that achieves `a`.
    Lexicographic(Segment),
    /// Equal rank: weighted least squares, weights (w_a, w_b).
    LeastSquares([f32; 2]),
}

/// One block: up to two thrusters and as many axes. For a single block only index 0 is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Block {
    /// Thruster indices.
    pub(super) thrusters: [usize; 2],
    /// Rows of τ, `[a, b]`: for the lexicographic rule `a` is the higher priority.
    pub(super) axes: [usize; 2],
    /// g[r][c]: gain of block thruster c on axis r (entries of B).
    pub(super) g: [[f32; 2]; 2],
    pub(super) rule: Rule,
}

const EMPTY_BLOCK: Block = Block {
    thrusters: [0; 2],
    axes: [0; 2],
    g: [[0.0; 2]; 2],
    rule: Rule::Single,
};

/// The blocks of B (6×5) and how many there are (the rest of the array is unused). Refuses a
/// geometry whose 5×5 allocation is not block diagonal with blocks of at most two thrusters
/// ([`AllocationError::NotBlockDiagonal`]).
pub(super) fn split(
    b: &Matrix6x5<f32>,
    priority: &AxisPriority,
) -> Result<([Block; THRUSTERS], usize), AllocationError> {
    let group = components(b);
    let mut blocks = [EMPTY_BLOCK; THRUSTERS];
    let mut count = 0;
    for root in 0..THRUSTERS {
        let mut thrusters = [0usize; THRUSTERS];
        let mut n = 0;
        let mut rows = 0u8;
        for (t, &g) in group.iter().enumerate() {
            if g == root {
                thrusters[n] = t;
                n += 1;
                rows |= touches(b, t);
            }
        }
        if n == 0 {
            continue;
        }
        blocks[count] = block(b, &thrusters[..n], rows, priority)?;
        count += 1;
    }
    Ok((blocks, count))
}

/// The actuated rows thruster `t` touches, as bits over [`ACTUATED`] (exact zeros: the
/// AUV-150's layout has them).
fn touches(b: &Matrix6x5<f32>, t: usize) -> u8 {
    let mut m = 0u8;
    for (k, &row) in ACTUATED.iter().enumerate() {
        if b[(row, t)] != 0.0 {
            m |= 1 << k;
        }
    }
    m
}

/// Connected components: thrusters that share an actuated row belong together. Each
/// thruster's entry is the smallest thruster index of its component.
fn components(b: &Matrix6x5<f32>) -> [usize; THRUSTERS] {
    let mut group = [0usize; THRUSTERS];
    for (t, g) in group.iter_mut().enumerate() {
        *g = t;
    }
    for _ in 0..THRUSTERS {
        for t in 0..THRUSTERS {
            for u in 0..THRUSTERS {
                if touches(b, t) & touches(b, u) != 0 && group[u] < group[t] {
                    group[t] = group[u];
                }
            }
        }
    }
    group
}

/// The block of `thrusters` (one component), which touch the actuated `rows` (bits over
/// [`ACTUATED`]): one thruster for one axis, or two for two.
fn block(
    b: &Matrix6x5<f32>,
    thrusters: &[usize],
    rows: u8,
    priority: &AxisPriority,
) -> Result<Block, AllocationError> {
    let n = thrusters.len();
    let m = rows.count_ones() as usize;
    if n > 2 || m != n {
        return Err(AllocationError::NotBlockDiagonal {
            thrusters: n,
            axes: m,
        });
    }
    let mut axes = [0usize; 2];
    let mut k = 0;
    for (bit, &row) in ACTUATED.iter().enumerate() {
        if rows & (1 << bit) != 0 {
            axes[k] = row;
            k += 1;
        }
    }
    if n == 1 {
        Ok(Block {
            thrusters: [thrusters[0], thrusters[0]],
            axes: [axes[0], axes[0]],
            g: [[b[(axes[0], thrusters[0])], 0.0], [0.0, 0.0]],
            rule: Rule::Single,
        })
    } else {
        two_block(b, [thrusters[0], thrusters[1]], axes, priority)
    }
}

/// The two-thruster block of `thrusters` on `axes` (ascending rows): its gains, and its rule
/// from the priority.
fn two_block(
    b: &Matrix6x5<f32>,
    thrusters: [usize; 2],
    axes: [usize; 2],
    priority: &AxisPriority,
) -> Result<Block, AllocationError> {
    let [r0, r1] = axes;
    // Order the axes: the higher rank first (rows in ascending order on a tie).
    let axes = if priority.rank[r1] > priority.rank[r0] {
        [r1, r0]
    } else {
        [r0, r1]
    };
    let g = [
        [b[(axes[0], thrusters[0])], b[(axes[0], thrusters[1])]],
        [b[(axes[1], thrusters[0])], b[(axes[1], thrusters[1])]],
    ];
    let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
    if !(det.is_finite() && det != 0.0) {
        return Err(AllocationError::Singular);
    }
    let (mut thrusters, mut g) = (thrusters, g);
    let rule = if priority.rank[axes[0]] == priority.rank[axes[1]] {
        Rule::LeastSquares([priority.weight[axes[0]], priority.weight[axes[1]]])
    } else {
        // Choice 493: the thruster with the larger gain on the higher axis (p) is the block's
        // first, so the step indexes nothing by p. Every value the step forms from the pair is
        // a two-term sum or a product, which the order leaves bit for bit.
        if g[0][0].abs() < g[0][1].abs() {
            thrusters.swap(0, 1);
            g = [[g[0][1], g[0][0]], [g[1][1], g[1][0]]];
        }
        let ratio = g[0][1] / g[0][0];
        let alpha = g[1][1] - g[1][0] * ratio;
        Rule::Lexicographic(Segment {
            inv_gap: 1.0 / g[0][0],
            ratio,
            inv_alpha: 1.0 / alpha,
            // Set by the allocator, which knows the envelope (`Allocator::new`).
            reach: (0.0, 0.0),
        })
    };
    Ok(Block {
        thrusters,
        axes,
        g,
        rule,
    })
}
