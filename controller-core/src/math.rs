//! Scalar math backend for the f32 control path.
//!
//! Every transcendental call of the f32 law goes through this module so that one cargo feature
//! decides what runs on the board:
//!
//! * default — [`libm`]: correctly rounded to an ulp or two; its `sinf`, `cosf` and `cbrtf`
//!   evaluate in f64 (soft-float calls on the Cortex-M4F) and its `sqrtf` is a software loop
//!   there;
//! * feature `kernels` — the core's own f32-only [`kernels`]: sin/cos within 0.82 ulp over
//!   every f32, cbrt within 0.51 ulp, atan2 within 1.5 ulp, and the FPU's `vsqrt.f32` (exact);
//!   no f64 anywhere;
//! * feature `micromath` — micromath's fast approximations for `sin`, `cos`, `sqrt` and
//!   `atan2` (the product design names micromath). Measured here (`tests/math_backend.rs`):
//!   sin/cos absolute error ≈ 1e-3, `sqrt` relative error up to ≈ 6 % (√2 → 1.5).
//!
//! If several are enabled (features add up in a workspace), micromath wins over kernels, and
//! kernels over libm. Making the kernels the default is one line: `default = ["kernels"]` in
//! `controller-core/Cargo.toml`. `cbrt` is the kernels' with `kernels` and libm's otherwise
//! (micromath has no `cbrt`); `floor` is always libm (exact, integer operations).
//!
//! Call these functions by path (`math::sqrt(x)`), never as methods: a method call `x.sqrt()`
//! resolves to std on the host and to a trait method on the target, which is exactly the
//! silent backend switch this module exists to prevent.

use core::f32::consts::{PI, TAU};

pub mod kernels;

/// Name of the backend compiled in, for logs and benchmarks.
pub const BACKEND: &str = if cfg!(feature = "micromath") {
    "micromath"
} else if cfg!(feature = "kernels") {
    "kernels"
} else {
    "libm"
};

/// sin(x).
#[inline]
pub fn sin(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).sin().0
    }
    #[cfg(all(feature = "kernels", not(feature = "micromath")))]
    {
        kernels::sin(x)
    }
    #[cfg(not(any(feature = "micromath", feature = "kernels")))]
    {
        libm::sinf(x)
    }
}

/// cos(x).
#[inline]
pub fn cos(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).cos().0
    }
    #[cfg(all(feature = "kernels", not(feature = "micromath")))]
    {
        kernels::cos(x)
    }
    #[cfg(not(any(feature = "micromath", feature = "kernels")))]
    {
        libm::cosf(x)
    }
}

/// (sin x, cos x) (the kernels reduce x once for both).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    #[cfg(all(feature = "kernels", not(feature = "micromath")))]
    {
        kernels::sin_cos(x)
    }
    #[cfg(not(all(feature = "kernels", not(feature = "micromath"))))]
    {
        (sin(x), cos(x))
    }
}

/// atan2(y, x), the angle of the point (x, y) in [−π, π] (the tangent heading's course,
/// docs/design.md §6).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(y).atan2(micromath::F32(x)).0
    }
    #[cfg(all(feature = "kernels", not(feature = "micromath")))]
    {
        kernels::atan2(y, x)
    }
    #[cfg(not(any(feature = "micromath", feature = "kernels")))]
    {
        libm::atan2f(y, x)
    }
}

/// √x for x ≥ 0 (NaN for x < 0 in every backend).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).sqrt().0
    }
    #[cfg(all(feature = "kernels", not(feature = "micromath")))]
    {
        kernels::sqrt(x)
    }
    #[cfg(not(any(feature = "micromath", feature = "kernels")))]
    {
        libm::sqrtf(x)
    }
}

/// Correctly rounded √x in every backend (libm's `sqrtf`, one `vsqrt.f32` on the M4F), for
/// what is computed once at configuration time or reported, where micromath's ≈ 6 % error is
/// not acceptable: the inverse thrust maps, the trajectory's K_d and minimum speed
/// (docs/design.md §17, Choice 30).
#[inline]
pub fn exact_sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// ∛x (the kernels' with `kernels`, libm's otherwise).
#[inline]
pub fn cbrt(x: f32) -> f32 {
    #[cfg(feature = "kernels")]
    {
        kernels::cbrt(x)
    }
    #[cfg(not(feature = "kernels"))]
    {
        libm::cbrtf(x)
    }
}

/// Euclidean norm of a slice of fixed length, through the backend's `sqrt`.
#[inline]
pub fn norm<const N: usize>(v: &[f32; N]) -> f32 {
    let mut s = 0.0f32;
    for x in v {
        s += x * x;
    }
    sqrt(s)
}

/// Wraps an angle to (−π, π] with a fixed amount of work (no loop).
///
/// Used for the yaw component of e₁ (docs/design.md §4, **Choice**) and for trajectory phases.
/// Non-finite input gives NaN (the caller checks finiteness). Fossen's `ssa` (smallest signed
/// angle, which returns [−π, π) where this returns (−π, π]) and MATLAB's `wrapToPi`.
#[doc(alias("ssa", "wrapToPi"))]
#[inline]
pub fn wrap_pi(x: f32) -> f32 {
    // r ∈ [−π, π) up to rounding; map −π to +π to make the interval (−π, π].
    let r = x - TAU * libm::floorf((x + PI) / TAU);
    if r <= -PI {
        r + TAU
    } else if r > PI {
        r - TAU
    } else {
        r
    }
}

/// Reduces the phase ω·t, with t = `ticks` / `rate_hz` seconds, to [0, 2π] (up to one rounding
/// either side; callers wrap before sin/cos) in f64 before it
/// becomes f32 (docs/design.md §8, "Time"): an f32 `t` would lose a millisecond per tick after a few
/// hours, and ω·t in f32 loses the phase itself. Fixed work (one floor, no loop).
#[inline]
pub fn phase(omega: f32, ticks: u64, rate_hz: u32) -> f32 {
    phase_f64(omega as f64, ticks, rate_hz)
}

/// [`phase`] for a frequency given in f64 (a mission's ω/k, docs/design.md §6: the time scale
/// divides the frequency once, at configuration time, not the time on every tick).
#[inline]
pub fn phase_f64(omega: f64, ticks: u64, rate_hz: u32) -> f32 {
    let t = ticks as f64 / rate_hz as f64;
    let p = omega * t;
    let r = p - core::f64::consts::TAU * libm::floor(p / core::f64::consts::TAU);
    r as f32
}

/// Seconds since mission start as f64 (for terms linear in t, such as the lawn-mower's surge
/// advance or the helix depth rate, which must not be computed from an f32 time).
#[inline]
pub fn seconds(ticks: u64, rate_hz: u32) -> f64 {
    ticks as f64 / rate_hz as f64
}
