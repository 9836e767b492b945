//! The math kernels on the target: the same bits as on the host (vectors from `build.rs`), and
//! each kernel's instructions per call beside libm's f32 functions (which evaluate sin, cos and
//! cbrt in soft-float f64 here, and sqrt in software), the backend's `sin_cos`, and the
//! trajectory's integer phase.

use core::f32::consts::{FRAC_PI_4, PI};
use core::hint::black_box;

use controller_core::math::{self, kernels};
use controller_core::phase::{Frequency, MissionTime};
use defmt::{error, info};

use crate::counter::Counter;

include!(concat!(env!("OUT_DIR"), "/kernel_golden.rs"));

/// Same bits, or both NaN (NaN payloads and signs may differ between libm on the host and the
/// FPU's default NaN).
fn same(a: f32, bits: u32) -> bool {
    let b = f32::from_bits(bits);
    a.to_bits() == bits || (a.is_nan() && b.is_nan())
}

/// Every kernel vector computed by the host gives the same bits here.
fn agree_with_host() -> bool {
    let mut bad = 0u32;
    let mut total = 0u32;
    let mut check = |name: &str, ok: bool, input: u32| {
        total += 1;
        if !ok {
            bad += 1;
            error!(
                "kernel {=str}: input {=u32:#x} differs from the host",
                name, input
            );
        }
    };
    for &(x, s, c) in &KERNEL_SIN_COS {
        let (ts, tc) = kernels::sin_cos(f32::from_bits(x));
        check("sin_cos", same(ts, s) && same(tc, c), x);
    }
    for &(p, s, c) in &KERNEL_SIN_COS_TURNS {
        let (ts, tc) = kernels::sin_cos_turns(p);
        check("sin_cos_turns", same(ts, s) && same(tc, c), p);
    }
    for &(y, x, a) in &KERNEL_ATAN2 {
        let t = kernels::atan2(f32::from_bits(y), f32::from_bits(x));
        check("atan2", same(t, a), y);
    }
    for &(x, r) in &KERNEL_CBRT {
        check("cbrt", same(kernels::cbrt(f32::from_bits(x)), r), x);
    }
    for &(x, r) in &KERNEL_SQRT {
        check(
            "sqrt (vsqrt.f32)",
            same(kernels::sqrt(f32::from_bits(x)), r),
            x,
        );
    }
    info!(
        "math kernels: {} of {} vectors agree with the host bit for bit",
        total - bad,
        total
    );
    bad == 0
}

/// `n` points evenly spread over [lo, hi].
fn spread<const N: usize>(lo: f32, hi: f32) -> [f32; N] {
    let mut out = [0.0; N];
    for (i, x) in out.iter_mut().enumerate() {
        *x = lo + (hi - lo) * (i as f32 + 0.5) / N as f32;
    }
    out
}

/// Largest and mean count of `f` over `inputs`, printed as one `kernel NAME on SET` line.
fn report<T: Copy, R>(counter: &Counter, name: &str, set: &str, inputs: &[T], f: impl Fn(T) -> R) {
    let (mut max, mut sum) = (0u32, 0u32);
    for &x in inputs {
        let n = counter.count(|| f(black_box(x)));
        max = max.max(n);
        sum += n;
    }
    info!(
        "kernel {=str} on {=str}: max={} mean={} instructions",
        name,
        set,
        max,
        sum / inputs.len() as u32
    );
}

/// The agreement check, then the counts. Returns false if a vector differs.
pub fn run(counter: &Counter) -> bool {
    let ok = agree_with_host();
    let small: [f32; 16] = spread(-FRAC_PI_4, FRAC_PI_4);
    let phase: [f32; 16] = spread(-PI, PI);
    let wide: [f32; 16] = spread(-1000.0, 1000.0);
    let huge: [f32; 4] = [1e4, -3.3e6, 7.1e17, 3e38];
    for (set, xs) in [
        ("|x| <= pi/4", &small[..]),
        ("[-pi, pi]", &phase[..]),
        ("[-1000, 1000]", &wide[..]),
        ("|x| >= 1e4", &huge[..]),
    ] {
        report(counter, "sin_cos (kernels)", set, xs, kernels::sin_cos);
        report(counter, "sinf + cosf (libm)", set, xs, |x| {
            (libm::sinf(x), libm::cosf(x))
        });
    }
    report(
        counter,
        "sin_cos (backend)",
        "[-pi, pi]",
        &phase,
        math::sin_cos,
    );
    let turns: [u32; 16] =
        core::array::from_fn(|i| (i as u32).wrapping_mul(0x1111_1111) ^ 0x9e37_79b9);
    report(
        counter,
        "sin_cos_turns (kernels)",
        "16 phases",
        &turns,
        kernels::sin_cos_turns,
    );
    let points: [(f32, f32); 16] = core::array::from_fn(|i| {
        let (s, c) = kernels::sin_cos(phase[i]);
        (3.0 * s, 3.0 * c)
    });
    let circle = "a circle";
    report(counter, "atan2 (kernels)", circle, &points, |(y, x)| {
        kernels::atan2(y, x)
    });
    report(counter, "atan2f (libm)", circle, &points, |(y, x)| {
        libm::atan2f(y, x)
    });
    // The tunnel thrusters' inverse map takes ∛w for w in about [−17, −2.4] at ±24 V.
    let w: [f32; 16] = spread(-17.0, -2.4);
    report(counter, "cbrt (kernels)", "[-17, -2.4]", &w, kernels::cbrt);
    report(counter, "cbrtf (libm)", "[-17, -2.4]", &w, libm::cbrtf);
    let s: [f32; 16] = spread(0.01, 1e4);
    report(
        counter,
        "sqrt (kernels, vsqrt.f32)",
        "[0.01, 1e4]",
        &s,
        kernels::sqrt,
    );
    report(counter, "sqrtf (libm)", "[0.01, 1e4]", &s, libm::sqrtf);
    // The trajectory's phase: mission time split by integer division, then ω·t modulo one
    // turn in fixed point (controller_core::phase).
    let ticks: [u64; 4] = [1_234, 86_400 * 100, 1 << 33, 6_999];
    let frequency = Frequency::from_rad_per_s(0.1);
    report(counter, "phase (integer)", "4 tick counts", &ticks, |k| {
        frequency.phase(&MissionTime::new(k, 100))
    });
    report(
        counter,
        "wrap_pi (math)",
        "[-1000, 1000]",
        &wide,
        math::wrap_pi,
    );
    ok
}
