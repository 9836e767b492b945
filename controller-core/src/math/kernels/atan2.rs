//! atan2 in f32: t = min(|x|, |y|)/max(|x|, |y|) ∈ [0, 1] (one division), then
//!
//! * t < 7/16: atan t = t − t³ A(t²);
//! * 7/16 ≤ t < 11/16: atan t = atan(1/2) + atan u, u = (2t − 1)/(2 + t) ∈ [−0.052, 0.14];
//! * t ≥ 11/16: atan t = π/4 + atan u, u = (t − 1)/(t + 1) ∈ [−0.19, 0];
//!
//! (2t − 1 and t − 1 are exact, Sterbenz), with A the degree-4 minimax polynomial of
//! (u − atan u)/u³ on |u| ≤ 7/16 (relative approximation error 1.2e-9, 0.02 of 2⁻²⁴). The
//! octant (|y| > |x|) and the half plane (x < 0, also x = −0) fold into one base angle
//! C ∈ {0, atan ½, π/4, π/2 ∓ …, π − …} held as hi + lo, so the result is
//! C_hi + (C_lo ± atan u), rounded once at full weight; its sign is y's.
//!
//! IEEE 754 / C99 special values: NaN → NaN; atan2(±0, +0) = ±0, atan2(±0, −0) = ±π;
//! atan2(±∞, +∞) = ±π/4, atan2(±∞, −∞) = ±3π/4; atan2(±y, ±0) = ±π/2 for y ≠ 0.
//! Coefficients and base angles from `examples/kernel_constants.rs`.

// atan u = u − u³ (A0 + A1 u² + … + A4 u⁸).
const A0: f32 = f32::from_bits(0x3eaa_aaa1); // 3.3333305e-1
const A1: f32 = f32::from_bits(0xbe4c_c6df); // −1.9997738e-1
const A2: f32 = f32::from_bits(0x3e11_b5ff); // 1.4229582e-1
const A3: f32 = f32::from_bits(0xbdd6_da09); // −1.0490806e-1
const A4: f32 = f32::from_bits(0x3d6e_59ab); // 5.8190983e-2

/// An angle as hi + lo.
type Angle = (f32, f32);

const ZERO: Angle = (0.0, 0.0);
const ATAN_HALF: Angle = (f32::from_bits(0x3eed_6338), f32::from_bits(0x31ac_376a));
const PIO4: Angle = (f32::from_bits(0x3f49_0fdb), f32::from_bits(0xb2bb_bd2e));
const PIO2_MINUS_ATAN_HALF: Angle = (f32::from_bits(0x3f8d_b70d), f32::from_bits(0xb351_441c));
const PIO2: Angle = (f32::from_bits(0x3fc9_0fdb), f32::from_bits(0xb33b_bd2e));
const PI_MINUS_ATAN_HALF: Angle = (f32::from_bits(0x402b_6374), f32::from_bits(0xb3c6_80a5));
const THREE_PIO4: Angle = (f32::from_bits(0x4016_cbe4), f32::from_bits(0xb1cc_de2e));
const PIO2_PLUS_ATAN_HALF: Angle = (f32::from_bits(0x4002_3454), f32::from_bits(0x33ac_e4df));
const PI: Angle = (f32::from_bits(0x4049_0fdb), f32::from_bits(0xb3bb_bd2e));

/// Base angle C and the sign of atan u in C ± atan u, by [half plane·2 + octant][interval]:
/// x ≥ 0, |y| ≤ |x|: C = base; x ≥ 0, |y| > |x|: π/2 − base; x < 0, |y| ≤ |x|: π − base;
/// x < 0, |y| > |x|: π/2 + base. (π/2 − π/4 = π/4 and π/2 + π/4 = π − π/4 = 3π/4.)
const BASES: [([Angle; 3], f32); 4] = [
    ([ZERO, ATAN_HALF, PIO4], 1.0),
    ([PIO2, PIO2_MINUS_ATAN_HALF, PIO4], -1.0),
    ([PI, PI_MINUS_ATAN_HALF, THREE_PIO4], -1.0),
    ([PIO2, PIO2_PLUS_ATAN_HALF, THREE_PIO4], 1.0),
];

/// The angle of the point (x, y), in [−π, π], for every f32 pair (see the module docs).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    if x.is_nan() || y.is_nan() {
        return x + y;
    }
    let (ax, ay) = (x.abs(), y.abs());
    let swapped = ay > ax;
    let (num, den) = if swapped { (ax, ay) } else { (ay, ax) };
    let t = if num == 0.0 {
        0.0 // also 0/0
    } else if num == f32::INFINITY {
        1.0 // ∞/∞ (den ≥ num)
    } else {
        num / den
    };
    let (interval, u) = if t < 0.4375 {
        (0, t)
    } else if t < 0.6875 {
        (1, (2.0 * t - 1.0) / (2.0 + t))
    } else {
        (2, (t - 1.0) / (t + 1.0))
    };
    let z = u * u;
    let atan_u = u - (u * z) * (A0 + z * (A1 + z * (A2 + z * (A3 + z * A4))));
    let half_plane = if x.is_sign_negative() { 2 } else { 0 };
    let (bases, sign) = BASES[half_plane + swapped as usize];
    let (c_hi, c_lo) = bases[interval];
    let a = c_hi + (c_lo + sign * atan_u);
    a.copysign(y)
}
