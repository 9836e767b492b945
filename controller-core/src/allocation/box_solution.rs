//! One block's thrusts within its box [T_min, T_max], in closed form, when B₅⁻¹τ does not fit
//! (docs/thrusters.md#allocation-blocks-and-the-axis-priority): the clamp, the lexicographic solution on a segment, and the weighted
//! least squares over the box's edges and corners ([`super::Allocator`] says when each applies).

/// The constants of the lexicographic solution, precomputed. With `p` the thruster whose
/// gain on axis a is the larger in magnitude, the block's first (Choice 493), and `q` the other, the segment g_a·T = c is
/// T_p = (c − g_aq T_q)/g_ap, and along it τ_b = α T_q + β with α = g_bq − g_bp g_aq/g_ap
/// (= det G / g_ap ≠ 0) and β = g_bp c/g_ap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Segment {
    /// 1/g_ap.
    pub(super) inv_gap: f32,
    /// g_aq/g_ap.
    pub(super) ratio: f32,
    /// 1/α.
    pub(super) inv_alpha: f32,
    /// The range of g_a·T over the box, ([`reach`] of the block's higher axis), formed once
    /// with the allocator from its envelope (Choice 573).
    pub(super) reach: (f32, f32),
}

/// `x` in [lo, hi] (lo ≤ hi), without panicking: `f32::clamp` asserts lo ≤ hi. NaN stays NaN.
#[inline]
pub(super) fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
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
pub(super) fn reach(g: [f32; 2], lo: [f32; 2], hi: [f32; 2]) -> (f32, f32) {
    let (mut a, mut b) = (0.0f32, 0.0f32);
    for c in 0..2 {
        let (x, y) = (g[c] * lo[c], g[c] * hi[c]);
        a += if x < y { x } else { y };
        b += if x < y { y } else { x };
    }
    (a, b)
}

/// Lexicographic solution of a two-thruster block (see [`Segment`]); both thrusts inside the
/// box.
pub(super) fn lexicographic(
    g: &[[f32; 2]; 2],
    seg: &Segment,
    ta: f32,
    tb: f32,
    lo: [f32; 2],
    hi: [f32; 2],
) -> [f32; 2] {
    // p is the block's first thruster (Choice 493).
    let (p, q) = (0, 1);
    // reach(g[0], lo, hi), formed with the allocator.
    let (r_lo, r_hi) = seg.reach;
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
        // Empty only by rounding (c is reachable): the segment is a point, kept in T_q's box
        // (so that every thrust this returns is inside the box).
        let mid = clamp(0.5 * (q_lo + q_hi), lo[q], hi[q]);
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
/// optima and the four corners, each inside the box.
pub(super) fn least_squares(
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
