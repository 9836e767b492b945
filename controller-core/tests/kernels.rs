//! Accuracy of the f32 kernels (`controller_core::math::kernels`) against the host's f64 libm
//! (an independent implementation with its own constants and its own argument reduction), in
//! ulps of the f32 result, beside libm's and micromath's f32 functions on the same inputs.
//!
//! The normal suite sweeps every range densely and stratified (every binade, the points
//! closest to the multiples of π/2, the special values). The `#[ignore]`d `exhaustive_*` tests
//! run every f32 input (every 2⁻³² turn for `sin_cos_turns`); run them once after a change of
//! a kernel:
//!
//! ```text
//! cargo test -p controller-core --release --test kernels -- --ignored --nocapture
//! ```
//!
//! The asserted bounds are the exhaustive measurements, so a sweep that finds a larger error
//! fails.

use controller_core::math::kernels;

/// Error of `got` against the exact value `want`, in ulps of f32 at `want`.
fn ulps(got: f32, want: f64) -> f64 {
    if want.is_nan() || got.is_nan() {
        return if want.is_nan() && got.is_nan() {
            0.0
        } else {
            f64::INFINITY
        };
    }
    if want.is_infinite() || got.is_infinite() {
        return if got as f64 == want {
            0.0
        } else {
            f64::INFINITY
        };
    }
    let e = if want == 0.0 {
        -126
    } else {
        (((want.abs().to_bits() >> 52) & 0x7ff) as i32 - 1023).max(-126)
    };
    let ulp = f64::from_bits(((e - 23 + 1023) as u64) << 52);
    (got as f64 - want).abs() / ulp
}

/// Largest error over the inputs, and the input where it occurs.
#[derive(Clone, Copy, Debug)]
struct Worst<T> {
    ulps: f64,
    at: T,
}

impl<T: Copy> Worst<T> {
    fn new(at: T) -> Self {
        Worst { ulps: 0.0, at }
    }
    fn add(&mut self, ulps: f64, at: T) {
        if ulps > self.ulps {
            self.ulps = ulps;
            self.at = at;
        }
    }
    fn merge(mut self, o: Self) -> Self {
        self.add(o.ulps, o.at);
        self
    }
}

/// Every `stride`-th bit pattern in `lo..=hi` (and `hi` itself).
fn strided(lo: u32, hi: u32, stride: u32) -> impl Iterator<Item = u32> {
    (lo..=hi)
        .step_by(stride as usize)
        .chain(std::iter::once(hi))
}

/// `f` over `lo..=hi` (bit patterns, every one) on two threads.
fn par_worst<T: Copy + Send + Sync>(
    lo: u64,
    hi: u64,
    at0: T,
    f: impl Fn(u64) -> (f64, T) + Sync,
) -> Worst<T> {
    let mid = lo + (hi - lo) / 2;
    let run = |a: u64, b: u64| {
        let mut w = Worst::new(at0);
        for i in a..=b {
            let (u, at) = f(i);
            w.add(u, at);
        }
        w
    };
    let run = &run;
    std::thread::scope(|s| {
        let h = s.spawn(move || run(lo, mid));
        let w = run(mid + 1, hi);
        w.merge(h.join().expect("sweep thread"))
    })
}

/// [`par_worst`] for two errors at once (sin and cos).
fn par_worst2<T: Copy + Send + Sync + Default>(
    lo: u64,
    hi: u64,
    f: impl Fn(u64) -> ([f64; 2], T) + Sync,
) -> [Worst<T>; 2] {
    let mid = lo + (hi - lo) / 2;
    let run = |a: u64, b: u64| {
        let mut w = [Worst::new(T::default()); 2];
        for i in a..=b {
            let (u, at) = f(i);
            w[0].add(u[0], at);
            w[1].add(u[1], at);
        }
        w
    };
    let run = &run;
    std::thread::scope(|s| {
        let h = s.spawn(move || run(lo, mid));
        let [a, b] = run(mid + 1, hi);
        let [c, d] = h.join().expect("sweep thread");
        [a.merge(c), b.merge(d)]
    })
}

// ---------------------------------------------------------------------------------------------
// sin and cos

/// (sin, cos) errors of an f32 sin/cos at x, against f64.
fn sin_cos_error(f: impl Fn(f32) -> (f32, f32), x: f32) -> (f64, f64) {
    let (s, c) = f(x);
    let xd = x as f64;
    (ulps(s, xd.sin()), ulps(c, xd.cos()))
}

/// The f32 inputs of one range of the sweep.
struct Range {
    name: &'static str,
    inputs: Vec<f32>,
}

/// π/4 as an f32 bit pattern (the largest f32 below or at which no reduction is needed).
const PIO4_BITS: u32 = 0x3f49_0fdb;

/// The stratified sin/cos sweep.
fn sin_cos_ranges() -> Vec<Range> {
    let cw_limit = kernels_cw_limit();
    let reduced: Vec<f32> = strided(0, PIO4_BITS, 251)
        .map(f32::from_bits)
        .flat_map(|x| [x, -x])
        .collect();
    let cody_waite: Vec<f32> = strided(PIO4_BITS + 1, cw_limit.to_bits() - 1, 61)
        .map(f32::from_bits)
        .flat_map(|x| [x, -x])
        .collect();
    // The f32 closest to each multiple of π/2 below 2^20, and 64 ulps either side (cancellation).
    let mut near = Vec::new();
    for k in 1..(1u32 << 20) {
        if k > 4096 && k % 251 != 0 {
            continue;
        }
        let x = (k as f64 * std::f64::consts::FRAC_PI_2) as f32;
        let b = x.to_bits();
        near.extend((b - 64..=b + 64).map(f32::from_bits));
    }
    let payne_hanek: Vec<f32> = strided(cw_limit.to_bits(), f32::MAX.to_bits(), 1021)
        .map(f32::from_bits)
        .flat_map(|x| [x, -x])
        .collect();
    let special = vec![
        0.0,
        -0.0,
        f32::MIN_POSITIVE,
        1e-45,
        -1e-45,
        1e-30,
        f32::MAX,
        -f32::MAX,
        std::f32::consts::FRAC_PI_4,
        std::f32::consts::FRAC_PI_2,
        std::f32::consts::PI,
        -std::f32::consts::PI,
    ];
    vec![
        Range {
            name: "|x| <= pi/4 (no reduction)",
            inputs: reduced,
        },
        Range {
            name: "pi/4 < |x| < 1600 (Cody-Waite)",
            inputs: cody_waite,
        },
        Range {
            name: "64 ulp around k*pi/2, k < 2^20",
            inputs: near,
        },
        Range {
            name: "|x| >= 1600 (Payne-Hanek)",
            inputs: payne_hanek,
        },
        Range {
            name: "special values",
            inputs: special,
        },
    ]
}

fn kernels_cw_limit() -> f32 {
    kernels::reduce::CODY_WAITE_LIMIT
}

/// The backends compared: ours, libm's f32 functions, micromath's.
/// A named f32 (sin, cos).
type SinCos = (&'static str, fn(f32) -> (f32, f32));

fn sin_cos_impls() -> [SinCos; 3] {
    [
        ("kernels", kernels::sin_cos),
        ("libm", |x| (libm::sinf(x), libm::cosf(x))),
        ("micromath", |x| {
            let m = micromath::F32(x);
            (m.sin().0, m.cos().0)
        }),
    ]
}

/// Measured with `exhaustive_sin_cos_every_f32` (every f32): the largest errors of the kernel.
const SIN_MAX_ULPS: f64 = 1.0;
const COS_MAX_ULPS: f64 = 1.0;

#[test]
fn sin_cos_within_their_bounds_over_every_range_beside_libm_and_micromath() {
    for range in sin_cos_ranges() {
        for (name, f) in sin_cos_impls() {
            let (mut ws, mut wc) = (Worst::new(0.0f32), Worst::new(0.0f32));
            for &x in &range.inputs {
                let (es, ec) = sin_cos_error(f, x);
                ws.add(es, x);
                wc.add(ec, x);
            }
            println!(
                "{:<34} {name:<10} sin {:>10.3} ulp (x = {:e}), cos {:>10.3} ulp (x = {:e})  [{} inputs]",
                range.name,
                ws.ulps,
                ws.at,
                wc.ulps,
                wc.at,
                range.inputs.len()
            );
            if name == "kernels" {
                assert!(ws.ulps <= SIN_MAX_ULPS, "{}: sin {ws:?}", range.name);
                assert!(wc.ulps <= COS_MAX_ULPS, "{}: cos {wc:?}", range.name);
            }
        }
    }
}

#[test]
fn sin_cos_of_non_finite_is_nan_and_the_signs_are_odd_and_even() {
    for x in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
        let (s, c) = kernels::sin_cos(x);
        assert!(s.is_nan() && c.is_nan(), "{x}");
    }
    for x in [0.3f32, 2.0, 100.0, 1e4, 3e38] {
        let (s, c) = kernels::sin_cos(x);
        let (sn, cn) = kernels::sin_cos(-x);
        assert_eq!((sn.to_bits(), cn.to_bits()), ((-s).to_bits(), c.to_bits()));
    }
    assert_eq!(kernels::sin(-0.0).to_bits(), (-0.0f32).to_bits());
    assert_eq!(kernels::cos(0.0), 1.0);
}

#[test]
fn the_two_reductions_agree_where_both_apply() {
    // Payne–Hanek is valid from π/4; Cody–Waite is used below 1600. Both must give the same
    // sin/cos to the polynomials' accuracy (a defect in either table shows here).
    use kernels::reduce::{payne_hanek, reduce};
    for b in strided(PIO4_BITS + 1, kernels_cw_limit().to_bits() - 1, 4099) {
        let x = f32::from_bits(b);
        let (cw, ph) = (reduce(x), payne_hanek(x));
        assert_eq!(cw.quadrant, ph.quadrant, "{x}");
        let (r_cw, r_ph) = (cw.hi as f64 + cw.lo as f64, ph.hi as f64 + ph.lo as f64);
        assert!(
            (r_cw - r_ph).abs() <= 1e-14 * r_cw.abs().max(1e-9),
            "{x}: {r_cw} vs {r_ph}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// sin_cos_turns

/// sin(2π·a) in f64 for an exactly represented a, folded to |a| ≤ 1/4 by exact identities
/// first (sin(2π(½ − a)) = sin 2πa), so that the f64 argument is accurate near every zero.
fn sin_turns_f64(a: f64) -> f64 {
    let mut a = a - a.round();
    if a > 0.25 {
        a = 0.5 - a;
    } else if a < -0.25 {
        a = -0.5 - a;
    }
    (std::f64::consts::TAU * a).sin()
}

fn turns_error(p: u32) -> (f64, f64) {
    let (s, c) = kernels::sin_cos_turns(p);
    let a = p as f64 / 4_294_967_296.0;
    (ulps(s, sin_turns_f64(a)), ulps(c, sin_turns_f64(a + 0.25)))
}

/// Measured with `exhaustive_sin_cos_turns_every_phase`.
const TURNS_SIN_MAX_ULPS: f64 = 1.0;
const TURNS_COS_MAX_ULPS: f64 = 1.0;

#[test]
fn sin_cos_turns_within_its_bounds() {
    let mut phases: Vec<u32> = strided(0, u32::MAX, 4099).collect();
    for q in 0..4u32 {
        let b = q << 30;
        phases.extend((0..2048u32).flat_map(|d| [b.wrapping_add(d), b.wrapping_sub(d)]));
    }
    let (mut ws, mut wc) = (Worst::new(0u32), Worst::new(0u32));
    for &p in &phases {
        let (es, ec) = turns_error(p);
        ws.add(es, p);
        wc.add(ec, p);
    }
    println!(
        "sin_cos_turns: sin {:.3} ulp (phase {:#x}), cos {:.3} ulp (phase {:#x}) [{} phases]",
        ws.ulps,
        ws.at,
        wc.ulps,
        wc.at,
        phases.len()
    );
    assert!(ws.ulps <= TURNS_SIN_MAX_ULPS, "{ws:?}");
    assert!(wc.ulps <= TURNS_COS_MAX_ULPS, "{wc:?}");
    // Quarter turns are exact.
    assert_eq!(kernels::sin_cos_turns(0), (0.0, 1.0));
    assert_eq!(kernels::sin_cos_turns(1 << 30), (1.0, 0.0));
    assert_eq!(kernels::sin_cos_turns(1 << 31), (0.0, -1.0));
    assert_eq!(kernels::sin_cos_turns(3 << 30), (-1.0, 0.0));
}

// ---------------------------------------------------------------------------------------------
// atan2

/// xorshift64*: deterministic inputs.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// A random finite f32 with exponent in [−e, e] and a random sign.
    fn f32_within(&mut self, e: i32) -> f32 {
        let r = self.next();
        let exp = (r % (2 * e as u64 + 1)) as i32 - e;
        let mantissa = ((r >> 8) as u32) & 0x007f_ffff;
        let sign = ((r >> 40) as u32 & 1) << 31;
        f32::from_bits(sign | (((exp + 127) as u32) << 23) | mantissa)
    }
}

/// A named f32 function of two arguments.
type Binary = (&'static str, fn(f32, f32) -> f32);

fn atan2_impls() -> [Binary; 3] {
    [
        ("kernels", kernels::atan2),
        ("libm", libm::atan2f),
        ("micromath", |y, x| {
            micromath::F32(y).atan2(micromath::F32(x)).0
        }),
    ]
}

/// Measured with `exhaustive_atan2_every_y_at_x_plus_minus_one` and the random sweep.
const ATAN2_MAX_ULPS: f64 = 1.6;

#[test]
fn atan2_within_its_bound_beside_libm_and_micromath() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let pairs: Vec<(f32, f32)> = (0..500_000)
        .map(|_| (rng.f32_within(40), rng.f32_within(40)))
        .chain(strided(0, 0x7f7f_ffff, 2039).flat_map(|b| {
            let y = f32::from_bits(b);
            [(y, 1.0), (y, -1.0), (-y, 1.0), (1.0, y), (-1.0, -y)]
        }))
        .collect();
    for (name, f) in atan2_impls() {
        let mut w = Worst::new((0.0f32, 0.0f32));
        for &(y, x) in &pairs {
            w.add(ulps(f(y, x), (y as f64).atan2(x as f64)), (y, x));
        }
        println!(
            "atan2 {name:<10} {:>10.3} ulp at (y, x) = ({:e}, {:e})  [{} pairs]",
            w.ulps,
            w.at.0,
            w.at.1,
            pairs.len()
        );
        if name == "kernels" {
            assert!(w.ulps <= ATAN2_MAX_ULPS, "{w:?}");
        }
    }
}

#[test]
fn atan2_special_values_are_ieee_754s() {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let inf = f32::INFINITY;
    let cases: [(f32, f32, f32); 16] = [
        (0.0, 0.0, 0.0),
        (-0.0, 0.0, -0.0),
        (0.0, -0.0, PI),
        (-0.0, -0.0, -PI),
        (0.0, -1.0, PI),
        (-0.0, -1.0, -PI),
        (1.0, 0.0, FRAC_PI_2),
        (-1.0, -0.0, -FRAC_PI_2),
        (inf, inf, FRAC_PI_4),
        (-inf, inf, -FRAC_PI_4),
        (inf, -inf, 3.0 * FRAC_PI_4),
        (-inf, -inf, -3.0 * FRAC_PI_4),
        (1.0, inf, 0.0),
        (1.0, -inf, PI),
        (-1.0, -inf, -PI),
        (inf, 1.0, FRAC_PI_2),
    ];
    for (y, x, want) in cases {
        let got = kernels::atan2(y, x);
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "atan2({y}, {x}) = {got}, want {want}"
        );
    }
    assert!(kernels::atan2(f32::NAN, 1.0).is_nan());
    assert!(kernels::atan2(0.0, f32::NAN).is_nan());
}

// ---------------------------------------------------------------------------------------------
// cbrt and sqrt

/// A named f32 function of one argument.
type Unary = (&'static str, fn(f32) -> f32);

fn cbrt_impls() -> [Unary; 2] {
    [("kernels", kernels::cbrt), ("libm", libm::cbrtf)]
}

/// Measured with `exhaustive_cbrt_every_f32`.
const CBRT_MAX_ULPS: f64 = 0.51;

#[test]
fn cbrt_within_its_bound_beside_libm() {
    for (name, f) in cbrt_impls() {
        let mut w = Worst::new(0.0f32);
        for b in strided(0, 0x7f7f_ffff, 251) {
            let x = f32::from_bits(b);
            w.add(ulps(f(x), (x as f64).cbrt()), x);
        }
        println!("cbrt {name:<10} {:.4} ulp at {:e}", w.ulps, w.at);
        if name == "kernels" {
            assert!(w.ulps <= CBRT_MAX_ULPS, "{w:?}");
        }
    }
}

#[test]
fn cbrt_of_a_cube_is_exact_and_the_special_values_pass_through() {
    for k in 1..=255u32 {
        let c = (k * k * k) as f32; // < 2^24: exact
        assert_eq!(kernels::cbrt(c), k as f32, "∛{c}");
        assert_eq!(kernels::cbrt(-c), -(k as f32));
        // Scaled by 2^(3j): exact too, across the whole exponent range.
        for j in [-40i32, -20, 20, 30] {
            let s = 2f32.powi(3 * j);
            assert_eq!(
                kernels::cbrt(c * s),
                k as f32 * 2f32.powi(j),
                "∛({c}·2^{})",
                3 * j
            );
        }
    }
    assert_eq!(kernels::cbrt(0.0).to_bits(), 0.0f32.to_bits());
    assert_eq!(kernels::cbrt(-0.0).to_bits(), (-0.0f32).to_bits());
    assert_eq!(kernels::cbrt(f32::INFINITY), f32::INFINITY);
    assert_eq!(kernels::cbrt(f32::NEG_INFINITY), f32::NEG_INFINITY);
    assert!(kernels::cbrt(f32::NAN).is_nan());
}

#[test]
fn sqrt_is_correctly_rounded() {
    // The f64 square root of an f32, rounded to f32, is the correctly rounded f32 root
    // (53 ≥ 2·24 + 2, so the double rounding is innocuous).
    for b in strided(0, 0x7f80_0000, 257) {
        let x = f32::from_bits(b);
        assert_eq!(
            kernels::sqrt(x).to_bits(),
            ((x as f64).sqrt() as f32).to_bits(),
            "{x}"
        );
    }
    assert!(kernels::sqrt(-1.0).is_nan());
    assert_eq!(kernels::sqrt(-0.0).to_bits(), (-0.0f32).to_bits());
}

// ---------------------------------------------------------------------------------------------
// Exhaustive (run once after a change: see the module docs).

#[test]
#[ignore = "exhaustive: every f32, minutes"]
fn exhaustive_sin_cos_every_f32() {
    let [s, c] = par_worst2(0, u32::MAX as u64, |b| {
        let x = f32::from_bits(b as u32);
        let (es, ec) = sin_cos_error(kernels::sin_cos, x);
        ([es, ec], x)
    });
    println!(
        "every f32: sin {:.4} ulp at {:e}, cos {:.4} ulp at {:e}",
        s.ulps, s.at, c.ulps, c.at
    );
    assert!(s.ulps <= SIN_MAX_ULPS && c.ulps <= COS_MAX_ULPS);
}

#[test]
#[ignore = "exhaustive: every phase, minutes"]
fn exhaustive_sin_cos_turns_every_phase() {
    let [s, c] = par_worst2(0, u32::MAX as u64, |p| {
        let (es, ec) = turns_error(p as u32);
        ([es, ec], p as u32)
    });
    println!(
        "every phase: sin {:.4} ulp at {:#x}, cos {:.4} ulp at {:#x}",
        s.ulps, s.at, c.ulps, c.at
    );
    assert!(s.ulps <= TURNS_SIN_MAX_ULPS && c.ulps <= TURNS_COS_MAX_ULPS);
}

#[test]
#[ignore = "exhaustive: every y at x = ±1, minutes"]
fn exhaustive_atan2_every_y_at_x_plus_minus_one() {
    for x in [1.0f32, -1.0] {
        let w = par_worst(0, u32::MAX as u64, 0.0f32, |b| {
            let y = f32::from_bits(b as u32);
            (ulps(kernels::atan2(y, x), (y as f64).atan2(x as f64)), y)
        });
        println!(
            "every y, x = {x}: atan2 {:.4} ulp at y = {:e}",
            w.ulps, w.at
        );
        assert!(w.ulps <= ATAN2_MAX_ULPS);
    }
}

#[test]
#[ignore = "exhaustive: every f32, minutes"]
fn exhaustive_cbrt_every_f32() {
    let w = par_worst(0, 0x7f7f_ffff, 0.0f32, |b| {
        let x = f32::from_bits(b as u32);
        (ulps(kernels::cbrt(x), (x as f64).cbrt()), x)
    });
    println!("every f32: cbrt {:.4} ulp at {:e}", w.ulps, w.at);
    assert!(w.ulps <= CBRT_MAX_ULPS);
}

/// Whether `kernels::floor(x)` is ⌊x⌋ bit for bit (the host's f64 floor of the same value, exact
/// in f32: a whole number below 2²⁴ or x itself), NaN for NaN.
fn floor_is_exact(b: u32) -> bool {
    let x = f32::from_bits(b);
    let got = kernels::floor(x);
    if x.is_nan() {
        return got.is_nan();
    }
    got.to_bits() == ((x as f64).floor() as f32).to_bits()
}

#[test]
fn floor_is_exact_on_every_sign_and_binade_and_next_to_every_small_whole_number() {
    let strided_ok = strided(0, u32::MAX, 997).all(floor_is_exact);
    // Every f32 within 8 ulps of each whole number up to 2¹⁶ (±), where truncation and floor
    // part; ±0, ±∞, NaN and the edges of the integral range 2²³.
    let near_whole = (0..=65_536u32).flat_map(|n| {
        let b = (n as f32).to_bits();
        (b.saturating_sub(8)..=b + 8).flat_map(|m| [m, m | 0x8000_0000])
    });
    let edges = [
        0.0f32,
        -0.0,
        0.5,
        -0.5,
        8_388_607.5,
        -8_388_607.5,
        8_388_608.0,
    ]
    .into_iter()
    .chain([
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        f32::MIN,
        f32::MAX,
    ])
    .map(f32::to_bits);
    let bad: Vec<u32> = near_whole
        .chain(edges)
        .filter(|&b| !floor_is_exact(b))
        .collect();
    assert!(
        strided_ok && bad.is_empty(),
        "{:?}",
        &bad[..bad.len().min(8)]
    );
}

#[test]
#[ignore = "exhaustive: every f32, seconds"]
fn exhaustive_floor_every_f32() {
    let bad = (0..=u32::MAX).filter(|&b| !floor_is_exact(b)).count();
    assert_eq!(bad, 0);
}
