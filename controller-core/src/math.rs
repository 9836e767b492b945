//! Scalar math backend for the f32 control path.
//!
//! Every transcendental call of the f32 law goes through this module so that one cargo feature
//! decides what runs on the board:
//!
//! * default — the core's own f32-only [`kernels`]: sin/cos within 0.82 ulp over every f32,
//!   cbrt within 0.51 ulp, atan2 within 1.5 ulp, and the FPU's `vsqrt.f32` (exact); no f64
//!   anywhere, so nothing on the control step is a soft-float call on the Cortex-M4F
//!   (docs/numerics.md#the-math-backends, the board default on evidence: accuracy, Table 1, instruction counts);
//! * feature `libm-math` — [`libm`]: correctly rounded to an ulp or two; its `sinf`, `cosf` and
//!   `cbrtf` evaluate in f64 (soft-float calls on the Cortex-M4F) and its `sqrtf` is a software
//!   loop there (kept to measure against);
//! * feature `micromath` — micromath's fast approximations for `sin`, `cos`, `sqrt` and
//!   `atan2` (the product design names micromath). Measured here (`tests/math_backend.rs`):
//!   sin/cos absolute error ≈ 1e-3, `sqrt` relative error up to ≈ 6 % (√2 → 1.5).
//!
//! If several are enabled (features add up in a workspace), micromath wins over libm, and libm
//! over the kernels. `cbrt` is libm's with `libm-math` and the kernels' otherwise (micromath
//! has no `cbrt`); `floor` is always libm (exact, integer operations).
//!
//! Call these functions by path (`math::sqrt(x)`), never as methods: a method call `x.sqrt()`
//! resolves to std on the host and to a trait method on the target, which is exactly the
//! silent backend switch this module exists to prevent.

use core::f32::consts::{PI, TAU};

pub mod kernels;

/// Name of the backend compiled in, for logs and benchmarks.
pub const BACKEND: &str = if cfg!(feature = "micromath") {
    "micromath"
} else if cfg!(feature = "libm-math") {
    "libm"
} else {
    "kernels"
};

/// sin(x).
#[inline]
pub fn sin(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).sin().0
    }
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::sin(x)
    }
    #[cfg(all(feature = "libm-math", not(feature = "micromath")))]
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
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::cos(x)
    }
    #[cfg(all(feature = "libm-math", not(feature = "micromath")))]
    {
        libm::cosf(x)
    }
}

/// (sin x, cos x) (the kernels reduce x once for both).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::sin_cos(x)
    }
    #[cfg(any(feature = "micromath", feature = "libm-math"))]
    {
        (sin(x), cos(x))
    }
}

/// atan2(y, x), the angle of the point (x, y) in [−π, π] (the tangent heading's course,
/// docs/missions.md#heading).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(y).atan2(micromath::F32(x)).0
    }
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::atan2(y, x)
    }
    #[cfg(all(feature = "libm-math", not(feature = "micromath")))]
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
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::sqrt(x)
    }
    #[cfg(all(feature = "libm-math", not(feature = "micromath")))]
    {
        libm::sqrtf(x)
    }
}

/// Correctly rounded √x in every backend, for what is reported or feeds a cancellation, where
/// micromath's ≈ 6 % error is not acceptable: the inverse thrust maps, the trajectory's K_d and
/// minimum speed (docs/numerics.md#the-math-backends, Choice 30). It is [`kernels::sqrt`]: the
/// FPU's `vsqrt.f32` on the M4F (≈ 9 instructions where libm's `sqrtf`, a software loop there,
/// took ≈ 53: Choice 520), libm's `sqrtf` on the host; both correctly rounded, so the bits are
/// libm's on every target.
#[inline]
pub fn exact_sqrt(x: f32) -> f32 {
    kernels::sqrt(x)
}

/// ∛x (libm's with `libm-math`, the kernels' otherwise).
#[inline]
pub fn cbrt(x: f32) -> f32 {
    #[cfg(not(feature = "libm-math"))]
    {
        kernels::cbrt(x)
    }
    #[cfg(feature = "libm-math")]
    {
        libm::cbrtf(x)
    }
}

/// Σ xᵢ·0: ±0 when every xᵢ is finite, NaN otherwise: a finiteness check in two
/// instructions a value where a test and branch each take four (Choice 524; the controller's
/// output and estimate, the estimator's solution and state, Choice 527).
#[inline]
pub(crate) fn times_zero<const N: usize>(x: &[f32; N]) -> f32 {
    let mut zero = 0.0f32;
    for v in x {
        zero += v * 0.0;
    }
    zero
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
/// Used for the yaw component of e₁ (docs/law.md#structure, **Choice**) and for trajectory phases.
/// Non-finite input gives NaN (the caller checks finiteness). Fossen's `ssa` (smallest signed
/// angle, which returns [−π, π) where this returns (−π, π]) and MATLAB's `wrapToPi`.
#[doc(alias("ssa", "wrapToPi"))]
#[inline]
pub fn wrap_pi(x: f32) -> f32 {
    // r ∈ [−π, π) up to rounding; map −π to +π to make the interval (−π, π].
    let r = x - TAU * kernels::floor((x + PI) / TAU);
    if r <= -PI {
        r + TAU
    } else if r > PI {
        r - TAU
    } else {
        r
    }
}

/// (sin θ, cos θ) of θ = 2π·`phase`/2³², a phase in 2⁻³² turns ([`crate::phase`]): the
/// kernels reduce it by integer arithmetic (θ exact modulo 2π); libm and micromath take it as
/// [`turns_to_radians`].
#[inline]
pub fn sin_cos_turns(phase: u32) -> (f32, f32) {
    #[cfg(not(any(feature = "micromath", feature = "libm-math")))]
    {
        kernels::sin_cos_turns(phase)
    }
    #[cfg(any(feature = "micromath", feature = "libm-math"))]
    {
        sin_cos(turns_to_radians(phase))
    }
}

/// A phase in 2⁻³² turns as an angle in (−π, π] (rad): the phase read as a signed turn
/// fraction, one rounding to f32.
#[inline]
pub fn turns_to_radians(phase: u32) -> f32 {
    const RAD_PER_UNIT: f32 = TAU / 4_294_967_296.0;
    if phase == 1 << 31 {
        PI
    } else {
        (phase as i32) as f32 * RAD_PER_UNIT
    }
}
