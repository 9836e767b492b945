//! The saturation-aware allocator the board flies: thrusts inside every thruster's
//! [`ThrustEnvelope`] that give the commanded wrench where the thrusters can, and give up the
//! least important force first where they cannot (docs/thrusters.md#allocation-blocks-and-the-axis-priority, docs/thrusters.md#the-chain-end-to-end).
//!
//! [`Allocator::new`] runs once at configuration time. It takes the geometric allocation
//! ([`PseudoInverse`]: B and B₅⁻¹), the envelope [T_min, T_max] of each thruster at the supply
//! limit, and the axis priority ([`AxisPriority`]), and splits the 5×5 allocation over
//! (X, Y, Z, M, N) into its blocks (`blocks.rs`): groups of thrusters that share no actuated
//! axis with any other group. For the AUV-150 these are X ← main; (Z, M) ← the vertical pair;
//! (Y, N) ← the horizontal pair. **Choice** (docs/thrusters.md#allocation-blocks-and-the-axis-priority): a geometry whose allocation is not block
//! diagonal with blocks of one or two thrusters is refused at configuration time
//! ([`AllocationError::NotBlockDiagonal`]); there is no general-geometry fallback.
//!
//! Per tick ([`Allocator::allocate`]), fixed work, no heap, no panic:
//!
//! 1. T = B₅⁻¹τ ([`PseudoInverse::thrusts`]). A block whose thrusts are all inside their
//!    envelopes is *met*: it keeps exactly these thrusts, so a feasible demand gives exactly
//!    B₅⁻¹τ.
//! 2. Otherwise the block is solved exactly within its box, in closed form
//!    (`box_solution.rs`):
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

use nalgebra::Vector6;

use crate::allocation::blocks::{self, Block, Rule};
use crate::allocation::box_solution::{clamp, least_squares, lexicographic, reach};
use crate::allocation::error::AllocationError;
use crate::allocation::priority::AxisPriority;
use crate::allocation::pseudo_inverse::PseudoInverse;
use crate::axes::ROLL;
use crate::effectiveness::THRUSTERS;
use crate::math::times_zero;
use crate::thruster::ThrustEnvelope;

/// A thrust within this fraction of its envelope's width from a bound counts as on the bound
/// (for the saturation bits: the segment solution lands on a bound up to f32 rounding).
const ON_BOUND: f32 = 1.0e-4;

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

/// The saturation-aware allocator of a validated geometry, envelope and priority (see the
/// module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Allocator {
    pseudo_inverse: PseudoInverse,
    envelope: ThrustEnvelope,
    blocks: [Block; THRUSTERS],
    count: usize,
    /// B's roll row K (not actuated, so in no block; zero for the AUV-150's layout).
    roll: [f32; THRUSTERS],
}

impl Allocator {
    /// Splits `pseudo_inverse` into blocks and precomputes each block's solution. Refuses a
    /// geometry whose 5×5 allocation is not block diagonal with blocks of at most two thrusters
    /// ([`AllocationError::NotBlockDiagonal`]), an envelope that is not finite with
    /// T_min < T_max, and an invalid weight.
    pub fn new(
        pseudo_inverse: &PseudoInverse,
        envelope: &ThrustEnvelope,
        priority: &AxisPriority,
    ) -> Result<Allocator, AllocationError> {
        for i in 0..THRUSTERS {
            let (lo, hi) = (envelope.min[i], envelope.max[i]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(AllocationError::ThrustEnvelope {
                    thruster: i,
                    min: lo,
                    max: hi,
                });
            }
        }
        if let Some((axis, weight)) = priority.invalid_weight() {
            return Err(AllocationError::Weight { axis, weight });
        }
        let b = pseudo_inverse.matrix();
        let (mut blocks, count) = blocks::split(&b, priority)?;
        // The higher axis's reach over each lexicographic block's box, once (Choice 573).
        for block in &mut blocks[..count] {
            let [i, j] = block.thrusters;
            if let Rule::Lexicographic(seg) = &mut block.rule {
                let lo = [envelope.min[i], envelope.min[j]];
                let hi = [envelope.max[i], envelope.max[j]];
                seg.reach = reach(block.g[0], lo, hi);
            }
        }
        Ok(Allocator {
            pseudo_inverse: *pseudo_inverse,
            envelope: *envelope,
            blocks,
            count,
            roll: core::array::from_fn(|t| b[(ROLL, t)]),
        })
    }

    /// The envelope the thrusts are kept in (N).
    pub fn envelope(&self) -> &ThrustEnvelope {
        &self.envelope
    }

    /// The geometric allocation underneath.
    pub fn pseudo_inverse(&self) -> &PseudoInverse {
        &self.pseudo_inverse
    }

    /// Thrusts inside the envelope for the wrench `tau` = [X Y Z K M N] (N, N m); τ_K is
    /// ignored (see the module docs). Fixed work. A non-finite τ gives 0 N on every thruster
    /// with every saturation bit set and a zero unallocated part.
    pub fn allocate(&self, tau: &Vector6<f32>) -> Allocated {
        // Σ τᵢ·0 is NaN exactly when some τᵢ is not finite (Choice 524).
        if times_zero(&(*tau).into()) != 0.0 {
            return Allocated {
                thrusts: [0.0; THRUSTERS],
                saturated: (1 << THRUSTERS) - 1,
                unallocated: [0.0; 6],
            };
        }
        let exact = self.pseudo_inverse.thrusts(tau);
        let mut out = Allocated {
            thrusts: exact,
            saturated: 0,
            unallocated: [0.0; 6],
        };
        // Each rule on its own fixed-size path (Choice 573): no loop over a block's size.
        for block in &self.blocks[..self.count] {
            match block.rule {
                Rule::Single => self.solve_single(block, tau, &mut out),
                Rule::Lexicographic(seg) => {
                    self.solve_pair(block, tau, &mut out, |g, ta, tb, lo, hi| {
                        lexicographic(g, &seg, ta, tb, lo, hi)
                    })
                }
                Rule::LeastSquares(w) => {
                    self.solve_pair(block, tau, &mut out, |g, ta, tb, lo, hi| {
                        least_squares(g, w, ta, tb, lo, hi)
                    })
                }
            }
        }
        out
    }

    /// The wrench B·T (N, N·m) that `thrusts` (N) give, all six rows: each actuated row from
    /// its block's gains, the roll row whole (14 products on the AUV-150's layout where the
    /// dense B·T makes 30). The bits of [`PseudoInverse::wrench`]: a row's products outside its
    /// block are with exact zeros of B, and the others are summed in thruster order, as the
    /// dense product sums them (Choice 522).
    #[inline]
    pub fn wrench(&self, thrusts: &[f32; THRUSTERS]) -> Vector6<f32> {
        let t = thrusts;
        let r = &self.roll;
        let mut w = Vector6::zeros();
        w[ROLL] = r[0] * t[0] + r[1] * t[1] + r[2] * t[2] + r[3] * t[3] + r[4] * t[4];
        for block in &self.blocks[..self.count] {
            let [i, j] = block.thrusters;
            let g = &block.g;
            if block.rule == Rule::Single {
                w[block.axes[0]] = g[0][0] * t[i];
            } else {
                w[block.axes[0]] = g[0][0] * t[i] + g[0][1] * t[j];
                w[block.axes[1]] = g[1][0] * t[i] + g[1][1] * t[j];
            }
        }
        w
    }

    /// A one-thruster block: keep B₅⁻¹τ if it fits, else clamp τ_a/g to the envelope.
    #[inline(always)]
    fn solve_single(&self, block: &Block, tau: &Vector6<f32>, out: &mut Allocated) {
        let i = block.thrusters[0];
        let (lo, hi) = (self.envelope.min[i], self.envelope.max[i]);
        let t = out.thrusts[i];
        if t >= lo && t <= hi {
            return;
        }
        let a = block.axes[0];
        let ta = tau[a];
        let g = block.g[0][0];
        let v = clamp(ta / g, lo, hi);
        out.thrusts[i] = v;
        out.saturated |= on_bound(v, lo, hi) << i;
        out.unallocated[a] = ta - g * v;
    }

    /// A two-thruster block: keep B₅⁻¹τ if both fit, else `within` the box (its rule).
    #[inline(always)]
    fn solve_pair(
        &self,
        block: &Block,
        tau: &Vector6<f32>,
        out: &mut Allocated,
        within: impl FnOnce(&[[f32; 2]; 2], f32, f32, [f32; 2], [f32; 2]) -> [f32; 2],
    ) {
        let [i, j] = block.thrusters;
        let lo = [self.envelope.min[i], self.envelope.min[j]];
        let hi = [self.envelope.max[i], self.envelope.max[j]];
        let (ti, tj) = (out.thrusts[i], out.thrusts[j]);
        if ti >= lo[0] && ti <= hi[0] && tj >= lo[1] && tj <= hi[1] {
            return;
        }
        let [a, b] = block.axes;
        let (ta, tb) = (tau[a], tau[b]);
        let g = &block.g;
        // Both rules return thrusts inside the box (lexicographic clamps each, least squares
        // picks among clamped candidates), so no clamp follows.
        let v = within(g, ta, tb, lo, hi);
        out.thrusts[i] = v[0];
        out.thrusts[j] = v[1];
        out.saturated |= (on_bound(v[0], lo[0], hi[0]) << i) | (on_bound(v[1], lo[1], hi[1]) << j);
        out.unallocated[a] = ta - (g[0][0] * v[0] + g[0][1] * v[1]);
        out.unallocated[b] = tb - (g[1][0] * v[0] + g[1][1] * v[1]);
    }
}

/// 1 when `v` lies within [`ON_BOUND`] of the envelope's width from `lo` or `hi`, else 0.
#[inline(always)]
fn on_bound(v: f32, lo: f32, hi: f32) -> u8 {
    let tol = ON_BOUND * (hi - lo);
    // Both tests, without a branch between them.
    u8::from(v - lo <= tol) | u8::from(hi - v <= tol)
}
