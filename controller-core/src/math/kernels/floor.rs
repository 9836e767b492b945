//! ⌊x⌋ in f32 by the FPU's integer conversions (**Choice 513**): libm's `floorf` is integer
//! bit manipulation, about 45 instructions a call on the Cortex-M4F, which has no `vrintm`.
//! ⌊x⌋ is exact, so every correct floor gives the same bits: `tests/kernels.rs` checks this
//! one against libm's on every f32 input.

/// 2²³: every f32 of at least this magnitude is an integer.
const INTEGRAL: f32 = 8_388_608.0;

/// ⌊x⌋ for every f32 `x` (±0, ±∞ and NaN returned as they are).
///
/// Below 2²³ in magnitude, `x as i32` truncates toward zero exactly (`vcvt.s32.f32`) and
/// converting it back is exact; the truncation is ⌊x⌋ unless it is above x (x negative and
/// not whole), then ⌊x⌋ is one less. x = −0 keeps its sign (the truncation, +0, is not
/// above it, so it is returned with x's sign; every other whole result is not zero or
/// has x's sign already).
// The negated compare is the point: it is true for NaN too, which returns as it is.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline]
pub fn floor(x: f32) -> f32 {
    if !(x.abs() < INTEGRAL) {
        return x;
    }
    let t = (x as i32) as f32;
    if t > x {
        t - 1.0
    } else if t == 0.0 {
        // +0 from the conversion: ⌊x⌋ of x ∈ [0, 1) is +0, of −0 is −0.
        x * 0.0
    } else {
        t
    }
}
