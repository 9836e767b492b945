//! Saturation-aware thrust allocation: thrusts inside every thruster's [`Envelope`] that give
//! the commanded wrench where the thrusters can, and give up the least important force first
//! where they cannot (docs/design.md §9, §15).
//!
//! [`Allocator::new`] runs once at configuration time. It takes the exact allocation
//! ([`Allocation`]: B and B₅⁻¹), the envelope [T_min, T_max] of each thruster at the supply
//! limit, and the axis priority ([`AxisPriority`]), and splits the 5×5 allocation over
//! (X, Y, Z, M, N) into its blocks: groups of thrusters that share no actuated axis with any
//! other group. For the AUV-150 these are X ← main; (Z, M) ← the vertical pair; (Y, N) ← the
//! horizontal pair. **Choice** (§9): a geometry whose allocation is not block diagonal with
//! blocks of one or two thrusters is refused at configuration time
//! ([`AllocationError::NotBlockDiagonal`]); there is no general-geometry fallback.
//!
//! Per tick ([`Allocator::allocate`]), fixed work, no heap, no panic:
//!
//! 1. T = B₅⁻¹τ ([`Allocation::thrusts`]). A block whose thrusts are all inside their
//!    envelopes is *met*: it keeps exactly these thrusts, so a feasible demand gives exactly
//!    B₅⁻¹τ.
//! 2. Otherwise the block is solved exactly within its box, in closed form:
//!    * one thruster, one axis: the thrust clamped to its envelope;
//!    * two axes of different priority (**lexicographic**): the higher axis is clamped to the
//!      range it can reach over the box (so it is met exactly whenever it is feasible on its
//!      own), then the lower axis is optimised over the segment of the box that achieves it —
//!      on a segment the lower axis is linear in one parameter, so its optimum is one
//!      division and one clamp;
//!    * two axes of equal priority (**weighted least squares**): the minimum of
//!      w_a (τ_a − g_a·T)² + w_b (τ_b − g_b·T)² over the box, found among a fixed candidate
//!      set: the unconstrained optimum (already rejected in step 1), the optimum on each of
//!      the four edges (a one-dimensional quadratic, clamped) and the four corners. The cost
//!      is convex and the unconstrained optimum lies outside the box, so the box's optimum
//!      lies on its boundary, i.e. on an edge: the set contains it.
//! 3. Outputs ([`Allocated`]): the thrusts, the unallocated wrench τ − B·T of each block that
//!    was not met (zero for a met block and for the unactuated roll row), and per-thruster
//!    saturation bits: bit i is set when thruster i's block was not met and thruster i sits on
//!    a bound of its envelope (it is one of the thrusters that limit the block).
//!
//! The default [`AxisPriority`] is pitch, depth, yaw, sway, surge, highest first: the vertical
//! pair holds pitch before depth, the horizontal pair yaw before sway, and the main thruster
//! (surge) is alone in its block.

use core::fmt;

use nalgebra::Vector6;

use crate::allocation::{Allocation, AllocationError, ACTUATED_ROWS as ACTUATED};
use crate::effectiveness::THRUSTERS;
use crate::thruster::Envelope;

/// The rows of τ = [X Y Z K M N], by name, for [`AxisPriority`] and messages.
pub const AXIS_NAMES: [&str; 6] = ["surge", "sway", "depth", "roll", "pitch", "yaw"];

/// A thrust within this fraction of its envelope's width from a bound counts as on the bound
/// (for the saturation bits: the segment solution lands on a bound up to f32 rounding).
const ON_BOUND: f32 = 1.0e-4;

/// Which forces the allocator gives up first when a block cannot meet its demand
/// (docs/design.md §9 **Choice**), per row of τ = [X Y Z K M N] (the roll entries are not
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

/// One allocation step's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allocated {
    /// Thrust per thruster (N), thruster order, always inside the envelope.
    pub thrusts: [f32; THRUSTERS],
    /// Bit i set: thruster i's block was not met and thruster i is on a bound of its envelope.
    pub saturated: u8,
    /// τ − B·T over the rows of the blocks that were not met (N, N m); zero for met blocks and
    /// for the roll row.
    pub unallocated: [f32; 6],
}

/// How a block shares its shortfall.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    /// One thruster for one axis: clamp.
    Single,
    /// Axis `a` (row 0 of `g`) strictly above axis `b`: meet `a` within its reach, then `b`
    /// on the segment that achieves `a`.
    Lexicographic(Segment),
    /// Equal rank: weighted least squares, weights (w_a, w_b).
    LeastSquares([f32; 2]),
}

/// The constants of the lexicographic solution, precomputed. With `p` the thruster whose
/// gain on axis a is the larger in magnitude and `q` the other, the segment g_a·T = c is
/// T_p = (c − g_aq T_q)/g_ap, and along it τ_b = α T_q + β with α = g_bq − g_bp g_aq/g_ap
/// (= det G / g_ap ≠ 0) and β = g_bp c/g_ap.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    /// Index (0 or 1) of `p` within the block.
    p: usize,
    /// 1/g_ap.
    inv_gap: f32,
    /// g_aq/g_ap.
    ratio: f32,
    /// 1/α.
    inv_alpha: f32,
}

/// One block: up to two thrusters and as many axes. For a single block only index 0 is used.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Block {
    /// Thruster indices.
    thrusters: [usize; 2],
    /// Rows of τ, `[a, b]`: for the lexicographic rule `a` is the higher priority.
    axes: [usize; 2],
    /// g[r][c]: gain of block thruster c on axis r (entries of B).
    g: [[f32; 2]; 2],
    rule: Rule,
}

const EMPTY_BLOCK: Block = Block {
    thrusters: [0; 2],
    axes: [0; 2],
    g: [[0.0; 2]; 2],
    rule: Rule::Single,
};

/// The saturation-aware allocator of a validated geometry, envelope and priority (see the
/// module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allocator {
    allocation: Allocation,
    envelope: Envelope,
    blocks: [Block; THRUSTERS],
    count: usize,
}

impl Allocator {
    /// Splits `allocation` into blocks and precomputes each block's solution. Refuses a
    /// geometry whose 5×5 allocation is not block diagonal with blocks of at most two thrusters
    /// ([`AllocationError::NotBlockDiagonal`]), an envelope that is not finite with
    /// T_min < T_max, and an invalid weight.
    pub fn new(
        allocation: &Allocation,
        envelope: &Envelope,
        priority: &AxisPriority,
    ) -> Result<Allocator, AllocationError> {
        for i in 0..THRUSTERS {
            let (lo, hi) = (envelope.min[i], envelope.max[i]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(AllocationError::Envelope {
                    thruster: i,
                    min: lo,
                    max: hi,
                });
            }
        }
        if let Some((axis, weight)) = priority.invalid_weight() {
            return Err(AllocationError::Weight { axis, weight });
        }
        let b = allocation.matrix();
        // The actuated rows each thruster touches (exact zeros: the AUV-150's layout has them).
        let touches = |t: usize| -> u8 {
            let mut m = 0u8;
            for (k, &row) in ACTUATED.iter().enumerate() {
                if b[(row, t)] != 0.0 {
                    m |= 1 << k;
                }
            }
            m
        };
        // Connected components: thrusters that share an actuated row belong together.
        let mut group = [0usize; THRUSTERS];
        for (t, g) in group.iter_mut().enumerate() {
            *g = t;
        }
        for _ in 0..THRUSTERS {
            for t in 0..THRUSTERS {
                for u in 0..THRUSTERS {
                    if touches(t) & touches(u) != 0 && group[u] < group[t] {
                        group[t] = group[u];
                    }
                }
            }
        }
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
                    rows |= touches(t);
                }
            }
            if n == 0 {
                continue;
            }
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
            blocks[count] = if n == 1 {
                Block {
                    thrusters: [thrusters[0], thrusters[0]],
                    axes: [axes[0], axes[0]],
                    g: [[b[(axes[0], thrusters[0])], 0.0], [0.0, 0.0]],
                    rule: Rule::Single,
                }
            } else {
                two_block(&b, [thrusters[0], thrusters[1]], axes, priority)?
            };
            count += 1;
        }
        Ok(Allocator {
            allocation: *allocation,
            envelope: *envelope,
            blocks,
            count,
        })
    }

    /// The envelope the thrusts are kept in (N).
    pub fn envelope(&self) -> &Envelope {
        &self.envelope
    }

    /// The exact allocation underneath.
    pub fn allocation(&self) -> &Allocation {
        &self.allocation
    }

    /// Thrusts inside the envelope for the wrench `tau` = [X Y Z K M N] (N, N m); τ_K is
    /// ignored (see the module docs). Fixed work. A non-finite τ gives 0 N on every thruster
    /// with every saturation bit set and a zero unallocated part.
    pub fn allocate(&self, tau: &Vector6<f32>) -> Allocated {
        if !tau.iter().all(|x| x.is_finite()) {
            return Allocated {
                thrusts: [0.0; THRUSTERS],
                saturated: (1 << THRUSTERS) - 1,
                unallocated: [0.0; 6],
            };
        }
        let exact = self.allocation.thrusts(tau);
        let mut out = Allocated {
            thrusts: exact,
            saturated: 0,
            unallocated: [0.0; 6],
        };
        for block in &self.blocks[..self.count] {
            self.solve(block, tau, &exact, &mut out);
        }
        out
    }

    /// One block: keep B₅⁻¹τ if it fits, else solve within the box.
    fn solve(
        &self,
        block: &Block,
        tau: &Vector6<f32>,
        exact: &[f32; THRUSTERS],
        out: &mut Allocated,
    ) {
        let n = if block.rule == Rule::Single { 1 } else { 2 };
        let [i, j] = block.thrusters;
        let lo = [self.envelope.min[i], self.envelope.min[j]];
        let hi = [self.envelope.max[i], self.envelope.max[j]];
        let fits = (0..n).all(|c| {
            let t = exact[block.thrusters[c]];
            t >= lo[c] && t <= hi[c]
        });
        if fits {
            return;
        }
        let ta = tau[block.axes[0]];
        let tb = tau[block.axes[1]];
        let t = match block.rule {
            Rule::Single => [clamp(ta / block.g[0][0], lo[0], hi[0]), 0.0],
            Rule::Lexicographic(seg) => lexicographic(&block.g, &seg, ta, tb, lo, hi),
            Rule::LeastSquares(w) => least_squares(&block.g, w, ta, tb, lo, hi),
        };
        for c in 0..n {
            let k = block.thrusters[c];
            let v = clamp(t[c], lo[c], hi[c]);
            out.thrusts[k] = v;
            let tol = ON_BOUND * (hi[c] - lo[c]);
            if v - lo[c] <= tol || hi[c] - v <= tol {
                out.saturated |= 1 << k;
            }
        }
        let tk = [out.thrusts[i], out.thrusts[j]];
        for r in 0..n {
            let achieved = if n == 1 {
                block.g[0][0] * tk[0]
            } else {
                block.g[r][0] * tk[0] + block.g[r][1] * tk[1]
            };
            out.unallocated[block.axes[r]] = tau[block.axes[r]] - achieved;
        }
    }
}

/// The two-thruster block of `thrusters` on `axes` (ascending rows): its gains, and its rule
/// from the priority.
fn two_block(
    b: &nalgebra::Matrix6x5<f32>,
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
    let rule = if priority.rank[axes[0]] == priority.rank[axes[1]] {
        Rule::LeastSquares([priority.weight[axes[0]], priority.weight[axes[1]]])
    } else {
        let p = if g[0][0].abs() >= g[0][1].abs() { 0 } else { 1 };
        let q = 1 - p;
        let ratio = g[0][q] / g[0][p];
        let alpha = g[1][q] - g[1][p] * ratio;
        Rule::Lexicographic(Segment {
            p,
            inv_gap: 1.0 / g[0][p],
            ratio,
            inv_alpha: 1.0 / alpha,
        })
    };
    Ok(Block {
        thrusters,
        axes,
        g,
        rule,
    })
}

/// `x` in [lo, hi] (lo ≤ hi), without panicking: `f32::clamp` asserts lo ≤ hi. NaN stays NaN.
#[inline]
fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// The range of g·T over the box [lo, hi] (interval arithmetic on a sum of two products).
#[inline]
fn reach(g: [f32; 2], lo: [f32; 2], hi: [f32; 2]) -> (f32, f32) {
    let (mut a, mut b) = (0.0f32, 0.0f32);
    for c in 0..2 {
        let (x, y) = (g[c] * lo[c], g[c] * hi[c]);
        a += if x < y { x } else { y };
        b += if x < y { y } else { x };
    }
    (a, b)
}

/// Lexicographic solution of a two-thruster block (see [`Segment`]).
fn lexicographic(
    g: &[[f32; 2]; 2],
    seg: &Segment,
    ta: f32,
    tb: f32,
    lo: [f32; 2],
    hi: [f32; 2],
) -> [f32; 2] {
    let (p, q) = (seg.p, 1 - seg.p);
    let (r_lo, r_hi) = reach(g[0], lo, hi);
    let c = clamp(ta, r_lo, r_hi);
    // T_q such that T_p = (c − g_aq T_q)/g_ap lies in [lo_p, hi_p], and T_q in its own box.
    let (mut q_lo, mut q_hi) = (lo[q], hi[q]);
    if seg.ratio != 0.0 {
        // T_q = (c/g_ap − T_p)/ratio at the two ends of T_p's box.
        let base = c * seg.inv_gap;
        let e0 = (base - lo[p]) / seg.ratio;
        let e1 = (base - hi[p]) / seg.ratio;
        let (e_lo, e_hi) = if e0 < e1 { (e0, e1) } else { (e1, e0) };
        if e_lo > q_lo {
            q_lo = e_lo;
        }
        if e_hi < q_hi {
            q_hi = e_hi;
        }
    }
    if q_lo > q_hi {
        // Empty only by rounding (c is reachable): the segment is a point.
        let mid = 0.5 * (q_lo + q_hi);
        q_lo = mid;
        q_hi = mid;
    }
    // Along the segment τ_b = α T_q + β, β = g_bp c/g_ap.
    let beta = g[1][p] * c * seg.inv_gap;
    let tq = clamp((tb - beta) * seg.inv_alpha, q_lo, q_hi);
    let tp = (c - g[0][q] * tq) * seg.inv_gap;
    let mut t = [0.0f32; 2];
    t[p] = clamp(tp, lo[p], hi[p]);
    t[q] = tq;
    t
}

/// Weighted least squares over the box (see the module docs): the best of the four edge
/// optima and the four corners.
fn least_squares(
    g: &[[f32; 2]; 2],
    w: [f32; 2],
    ta: f32,
    tb: f32,
    lo: [f32; 2],
    hi: [f32; 2],
) -> [f32; 2] {
    let cost = |t: [f32; 2]| {
        let ra = ta - (g[0][0] * t[0] + g[0][1] * t[1]);
        let rb = tb - (g[1][0] * t[0] + g[1][1] * t[1]);
        w[0] * ra * ra + w[1] * rb * rb
    };
    // With T_fixed held at `v`, the best T_free (clamped): a one-dimensional quadratic.
    let edge = |free: usize, v: f32| -> [f32; 2] {
        let fixed = 1 - free;
        let ra = ta - g[0][fixed] * v;
        let rb = tb - g[1][fixed] * v;
        let num = w[0] * g[0][free] * ra + w[1] * g[1][free] * rb;
        let den = w[0] * g[0][free] * g[0][free] + w[1] * g[1][free] * g[1][free];
        let mut t = [0.0f32; 2];
        t[fixed] = v;
        t[free] = clamp(num / den, lo[free], hi[free]);
        t
    };
    let candidates = [
        edge(1, lo[0]),
        edge(1, hi[0]),
        edge(0, lo[1]),
        edge(0, hi[1]),
        [lo[0], lo[1]],
        [lo[0], hi[1]],
        [hi[0], lo[1]],
        [hi[0], hi[1]],
    ];
    let mut best = candidates[0];
    let mut best_cost = cost(best);
    for &c in &candidates[1..] {
        let k = cost(c);
        if k < best_cost {
            best = c;
            best_cost = k;
        }
    }
    best
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
            f.write_str(AXIS_NAMES[a])?;
        }
        Ok(())
    }
}
