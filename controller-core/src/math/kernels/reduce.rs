//! Argument reduction for sin and cos: x = q·π/2 + r with |r| ≤ π/4 (to a few ulps), r
//! returned as an unevaluated sum hi + lo of two f32 (|lo| ≤ ulp(hi)), in f32 and integer
//! arithmetic only.
//!
//! * |x| ≤ π/4: nothing to do.
//! * |x| < [`CODY_WAITE_LIMIT`]: Cody–Waite. q = round(|x|·2/π) < 2¹⁰ and π/2 = C₁ + C₂ + C₃ +
//!   C₄, where C₁…C₃ have 14 significant bits, so q·Cᵢ is exact in f32; |x| − q·C₁ is exact
//!   (Sterbenz); the next two subtractions are made exact with TwoSum; C₄ (24 bits) and the
//!   rounding errors go into `lo`. The four parts carry 75 bits of π/2 (the rest is 1e-23),
//!   enough for the f32 arguments closest to a multiple of π/2 in this range.
//! * larger finite |x|: Payne–Hanek in integers. |x| = m·2ᵉ with m a 24-bit integer; only a
//!   96-bit window of the bits of 2/π matters (those before it make multiples of 4 quarter
//!   turns, those after it less than 2⁻⁷⁰): m times the window gives the quadrant and a 94-bit
//!   fraction of a quarter turn, which times π/4 in 64-bit fixed point gives r.
//! * ±∞ and NaN: NaN.
//!
//! All constants are from `examples/kernel_constants.rs`, which derives them from π computed
//! by Machin's formula.

/// Below this |x|, Cody–Waite (q ≤ 1019 < 2¹⁰, so q·Cᵢ is exact); from it, Payne–Hanek.
pub const CODY_WAITE_LIMIT: f32 = 1600.0;

/// x = `quadrant`·π/2 + (`hi` + `lo`) (quadrant modulo 4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduced {
    /// q mod 4.
    pub quadrant: u32,
    /// r, rounded to f32 (|hi| ≤ π/4 + a few ulps).
    pub hi: f32,
    /// r − hi, to f32 (|lo| ≤ ulp(hi)).
    pub lo: f32,
}

impl Reduced {
    /// The reduction of −x from that of x.
    #[inline]
    fn negate(self) -> Reduced {
        Reduced {
            quadrant: self.quadrant.wrapping_neg() & 3,
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

/// π/4 rounded up to f32 (0x3f490fdb = 0.785398185 > π/4): |x| at or below it needs no
/// reduction.
const PIO4_F32_BITS: u32 = 0x3f49_0fdb;
/// 2/π rounded to f32 (only q = round(|x|·2/π) depends on it: a q off by one near a half
/// quarter turn leaves |r| a few ulps above π/4, which the polynomials cover).
const FRAC_2_PI: f32 = core::f32::consts::FRAC_2_PI;

// π/2 = PIO2_1 + PIO2_2 + PIO2_3 + PIO2_4 + 1.06e-23 (examples/kernel_constants.rs).
/// Part 1 of π/2 (14 significant bits): 1.5708008.
const PIO2_1: f32 = f32::from_bits(0x3fc9_1000);
/// Part 2 of π/2 (14 significant bits): −4.454516e-6.
const PIO2_2: f32 = f32::from_bits(0xb695_7800);
/// Part 3 of π/2 (14 significant bits): 6.077272e-11.
const PIO2_3: f32 = f32::from_bits(0x2e85_a400);
/// Part 4 of π/2 (24 bits): −1.7151245e-15.
const PIO2_4: f32 = f32::from_bits(0xa6f7_2ced);

/// 2/π, bits 1…224 after the binary point, most significant first, after one zero word (so
/// that a window may start up to 32 bits before bit 1).
const TWO_OVER_PI: [u32; 8] = [
    0,
    0xa2f9_836e,
    0x4e44_1529,
    0xfc27_57d1,
    0xf534_ddc0,
    0xdb62_9599,
    0x3c43_9041,
    0xfe51_63ab,
];
/// π/4 · 2⁶⁴, rounded.
const PIO4_FIX: u64 = 0xc90f_daa2_2168_c235;
/// π/2 · 2³¹, rounded (one 2⁻³² turn is 2π·2⁻³² = π/2 · 2⁻³⁰).
const PIO2_Q31: u32 = 0xc90f_daa2;

/// The reduction of `x` (see the module docs). Fixed work per range; no loop.
#[inline]
pub fn reduce(x: f32) -> Reduced {
    let ax = x.abs();
    let r = if ax.to_bits() <= PIO4_F32_BITS {
        Reduced {
            quadrant: 0,
            hi: ax,
            lo: 0.0,
        }
    } else if ax < CODY_WAITE_LIMIT {
        cody_waite(ax)
    } else if ax.is_finite() {
        payne_hanek(ax)
    } else {
        Reduced {
            quadrant: 0,
            hi: f32::NAN,
            lo: 0.0,
        }
    };
    if x.is_sign_negative() {
        r.negate()
    } else {
        r
    }
}

/// TwoSum (Knuth): s = fl(a + b) and the exact error a + b − s, for any a, b.
#[inline(always)]
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// Cody–Waite for π/4 < `ax` < [`CODY_WAITE_LIMIT`].
#[inline]
fn cody_waite(ax: f32) -> Reduced {
    let q = (ax * FRAC_2_PI + 0.5) as u32;
    let fq = q as f32;
    // Exact: q·C₁ has ≤ 24 bits, and |x| − q·C₁ is a Sterbenz subtraction.
    let t = ax - fq * PIO2_1;
    let (u, eu) = two_sum(t, -(fq * PIO2_2));
    let (hi, eh) = two_sum(u, -(fq * PIO2_3));
    let lo = (eu + eh) - fq * PIO2_4;
    let r_hi = hi + lo;
    Reduced {
        quadrant: q & 3,
        hi: r_hi,
        lo: lo - (r_hi - hi),
    }
}

/// 2ᵏ as f32, for −126 ≤ k ≤ 127.
#[inline(always)]
fn pow2(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

/// `v` · 2^(`scale` − 40) as hi + lo: hi from the top 24 of its 64 bits, lo from the next 32
/// (`v` has its top bit at 63 or 62).
#[inline(always)]
fn split_fixed(v: u64, scale: i32) -> (f32, f32) {
    let s = pow2(scale);
    let hi = ((v >> 40) as u32) as f32 * s;
    let lo = ((v >> 8) as u32) as f32 * (pow2(-32) * s);
    (hi, lo)
}

/// Payne–Hanek for finite `ax` > π/4 (used from [`CODY_WAITE_LIMIT`] on; correct from π/4).
#[doc(hidden)]
pub fn payne_hanek(ax: f32) -> Reduced {
    let bits = ax.to_bits();
    // ax = m·2^e (normal: ax > π/4).
    let e = (bits >> 23) as i32 - 150;
    let m = ((bits & 0x007f_ffff) | 0x0080_0000) as u64;
    // Bits i ≤ e − 2 of 2/π add multiples of 4 quarter turns: the window starts at bit
    // i₀ = e − 1, which is bit p = i₀ − 1 + 32 of the padded table (e ≥ −24, so p ≥ 5;
    // e ≤ 104, so the window ends by bit 230 < 256).
    let p = (e + 30) as u32;
    let (w, s) = ((p / 32) as usize, p % 32);
    let word = |i: usize| {
        let pair = ((TWO_OVER_PI[w + i] as u64) << 32) | TWO_OVER_PI[w + i + 1] as u64;
        ((pair << s) >> 32) & 0xffff_ffff
    };
    let (w0, w1, w2) = (word(0), word(1), word(2));
    // m·window = x·(2/π)·2⁹⁴ modulo 4·2⁹⁴ (plus less than 2⁻⁷⁰ quarter turns).
    let full = (((m * w0) as u128) << 64)
        .wrapping_add(((m * w1) as u128) << 32)
        .wrapping_add((m * w2) as u128);
    let mut quadrant = ((full >> 94) as u32) & 3;
    let frac = full & ((1u128 << 94) - 1);
    // Round to the nearest quadrant: fraction in [−1/2, 1/2) of a quarter turn.
    let negative = frac >= 1u128 << 93;
    let mag = if negative {
        quadrant += 1;
        (1u128 << 94) - frac
    } else {
        frac
    };
    if mag == 0 {
        return Reduced {
            quadrant: quadrant & 3,
            hi: 0.0,
            lo: 0.0,
        };
    }
    // r = mag·2⁻⁹⁴·π/2: normalise mag to 64 bits, times π/4 in 0.64 fixed point.
    let lz = mag.leading_zeros() as i32; // ≥ 34
    let top = ((mag << lz) >> 64) as u64;
    let v = mul_hi_64(top, PIO4_FIX);
    // r = v·2^(−29 − lz) = (v·2⁻⁴⁰)·2^(11 − lz).
    let (hi, lo) = split_fixed(v, 11 - lz);
    let r = Reduced {
        quadrant: quadrant & 3,
        hi,
        lo,
    };
    if negative {
        Reduced {
            hi: -r.hi,
            lo: -r.lo,
            ..r
        }
    } else {
        r
    }
}

/// ⌊a·b / 2⁶⁴⌋, from 32-bit partial products (no 128-bit multiplication routine).
#[inline(always)]
fn mul_hi_64(a: u64, b: u64) -> u64 {
    const LOW: u64 = 0xffff_ffff;
    let (a1, a0) = (a >> 32, a & LOW);
    let (b1, b0) = (b >> 32, b & LOW);
    let (hh, hl, lh, ll) = (a1 * b1, a1 * b0, a0 * b1, a0 * b0);
    let carry = ((ll >> 32) + (hl & LOW) + (lh & LOW)) >> 32;
    hh + (hl >> 32) + (lh >> 32) + carry
}

/// The reduction of the angle 2π·`phase`/2³² (a phase in 2⁻³² turns): the quadrant from the top
/// bits, the rest times π/2·2⁻³⁰ in integers. Exact but for the 2⁻³³ relative error of π/2·2³¹.
#[inline]
pub fn reduce_turns(phase: u32) -> Reduced {
    let quadrant = phase.wrapping_add(1 << 29) >> 30;
    let rem = phase.wrapping_sub(quadrant << 30) as i32; // [−2²⁹, 2²⁹)
    let prod = rem as i64 * PIO2_Q31 as i64; // r·2⁶¹
    let mag = prod.unsigned_abs();
    if mag == 0 {
        return Reduced {
            quadrant,
            hi: 0.0,
            lo: 0.0,
        };
    }
    let lz = mag.leading_zeros() as i32; // ≥ 3
                                         // r = (mag << lz)·2^(−61 − lz) = ((mag << lz)·2⁻⁴⁰)·2^(−21 − lz).
    let (hi, lo) = split_fixed(mag << lz, -21 - lz);
    if prod < 0 {
        Reduced {
            quadrant,
            hi: -hi,
            lo: -lo,
        }
    } else {
        Reduced { quadrant, hi, lo }
    }
}
