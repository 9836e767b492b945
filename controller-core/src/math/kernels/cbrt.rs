//! Cube root in f32, nearly correctly rounded, with one division and no loop.
//!
//! |x| = t·2^(3k) with t ∈ [1, 8) (subnormals scaled by 2²⁴ first). A first guess
//! y₀ = G(m)·∛2ʲ (t = m·2ʲ, m ∈ [1, 2), G the cubic minimax of ∛m, relative error 7.3e-5) is
//! cut to 12 significant bits, so that y₀³ splits exactly: y₀² is exact, its top and bottom
//! 12 bits times y₀ are exact, and the residual r = t − y₀³ is exact but for one rounding far
//! below its own size. One Halley step y = y₀ + y₀·r/(3t − 2r) then has a relative error near
//! (2⁻¹¹)³, and the result's only rounding at full weight is the last addition: ≤ 0.5 ulp
//! plus a few thousandths. Coefficients from `examples/kernel_constants.rs`.

// ∛m ≈ G0 + G1 m + G2 m² + G3 m³ on [1, 2].
const G0: f32 = f32::from_bits(0x3f0d_85d6); // 5.528234e-1
const G1: f32 = f32::from_bits(0x3f16_4d1f); // 5.871143e-1
const G2: f32 = f32::from_bits(0xbe26_e186); // −1.6296968e-1
const G3: f32 = f32::from_bits(0x3cbd_469f); // 2.3104964e-2
/// ∛(2ʲ), j = 0, 1, 2.
const CBRT_POW2: [f32; 3] = [
    1.0,
    f32::from_bits(0x3fa1_4518),
    f32::from_bits(0x3fcb_2ff5),
];
/// Keeps the top 12 significant bits of a normal f32.
const TOP12: u32 = 0xffff_f000;

/// ∛x for every f32 `x` (±0, ±∞ and NaN give themselves).
#[inline]
pub fn cbrt(x: f32) -> f32 {
    let bits = x.to_bits();
    let sign = bits & 0x8000_0000;
    let mut abs = bits & 0x7fff_ffff;
    if abs == 0 || abs >= 0x7f80_0000 {
        return x + x;
    }
    // Subnormal: |x|·2²⁴ is normal, and ∛(2²⁴) = 2⁸.
    let mut k_bias = 0i32;
    if abs < 0x0080_0000 {
        abs = (f32::from_bits(abs) * 16_777_216.0).to_bits();
        k_bias = -8;
    }
    let e = (abs >> 23) as i32 - 127;
    // e = 3k + j, j ∈ {0, 1, 2} (e + 300 > 0, so the division is a floor).
    let k = (e + 300) / 3 - 100;
    let j = (e - 3 * k) as u32;
    let mantissa = abs & 0x007f_ffff;
    let m = f32::from_bits(mantissa | 0x3f80_0000);
    let t = f32::from_bits(mantissa | ((127 + j) << 23));
    let guess = (((G3 * m + G2) * m + G1) * m + G0) * CBRT_POW2[j as usize];
    let y = f32::from_bits(guess.to_bits() & TOP12);
    // y³ = y²·y exactly as p_hi + p_lo; r = t − y³ (t − p_hi is a Sterbenz subtraction).
    let y2 = y * y;
    let y2_hi = f32::from_bits(y2.to_bits() & TOP12);
    let y2_lo = y2 - y2_hi;
    let r = (t - y2_hi * y) - y2_lo * y;
    let root = y + (y * r) / (3.0 * t - 2.0 * r);
    f32::from_bits((root.to_bits() as i32 + ((k + k_bias) << 23)) as u32 | sign)
}
