//! sin and cos in f32: the reduction of [`super::reduce`], then minimax polynomials on
//! [−π/4, π/4] evaluated in f32, with the reduced argument's low part as a first-order
//! correction.
//!
//! * sin r = r + r³ S(r²), S of degree 2: relative approximation error 3.8e-9 (0.06 of 2⁻²⁴);
//! * cos r = 1 − r²/2 + r⁴ C(r²), C of degree 2: 2.6e-10 (0.004 of 2⁻²⁴); 1 − r²/2 is formed
//!   with its rounding error recovered (Fast2Sum), so that only the final addition rounds at
//!   full weight.
//!
//! Coefficients from the Remez exchange of `examples/kernel_constants.rs`. Measured errors
//! (against f64, `tests/kernels.rs`) are in the module docs of [`super`].

use super::reduce::{self, Reduced};

// sin r = r + r³ (S0 + S1 r² + S2 r⁴).
const S0: f32 = f32::from_bits(0xbe2a_aaa3); // −1.6666655e-1
const S1: f32 = f32::from_bits(0x3c08_839d); // 8.33216e-3
const S2: f32 = f32::from_bits(0xb94c_a1f0); // −1.9515282e-4

// cos r = 1 − r²/2 + r⁴ (C0 + C1 r² + C2 r⁴).
const C0: f32 = f32::from_bits(0x3d2a_aaa7); // 4.1666653e-2
const C1: f32 = f32::from_bits(0xbab6_073c); // −1.3887654e-3
const C2: f32 = f32::from_bits(0x37cd_37b0); // 2.4463836e-5

/// sin(hi + lo) for |hi| ≤ π/4 (+ulps), |lo| ≤ ulp(hi): sin hi + lo·cos hi, cos hi ≈ 1 − hi²/2.
#[inline(always)]
fn sin_poly(hi: f32, lo: f32) -> f32 {
    let z = hi * hi;
    let p = S0 + z * (S1 + z * S2);
    hi + ((hi * z) * p + (lo - 0.5 * z * lo))
}

/// cos(hi + lo): cos hi − lo·sin hi, sin hi ≈ hi.
#[inline(always)]
fn cos_poly(hi: f32, lo: f32) -> f32 {
    let z = hi * hi;
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    // 1 − hz = w + ((1 − w) − hz) exactly (Fast2Sum: 1 ≥ hz).
    let tail = ((1.0 - w) - hz) + ((z * z) * (C0 + z * (C1 + z * C2)) - hi * lo);
    w + tail
}

/// (sin, cos) of a reduced argument.
#[inline(always)]
fn evaluate(r: Reduced) -> (f32, f32) {
    let s = sin_poly(r.hi, r.lo);
    let c = cos_poly(r.hi, r.lo);
    match r.quadrant & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// (sin x, cos x) for every f32 `x` (NaN for ±∞ and NaN; sin ±0 = ±0).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    if x == 0.0 {
        // The polynomial's tail is +0 for either zero, and −0 + +0 = +0: keep x's sign.
        return (x, 1.0);
    }
    evaluate(reduce::reduce(x))
}

/// sin x.
#[inline]
pub fn sin(x: f32) -> f32 {
    sin_cos(x).0
}

/// cos x.
#[inline]
pub fn cos(x: f32) -> f32 {
    sin_cos(x).1
}

/// (sin θ, cos θ) of θ = 2π·`phase`/2³², a phase in 2⁻³² turns, as an integer phase
/// accumulator gives it (θ exact modulo 2π; no floating-point reduction at all).
#[inline]
pub fn sin_cos_turns(phase: u32) -> (f32, f32) {
    evaluate(reduce::reduce_turns(phase))
}
