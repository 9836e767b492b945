//! The core's own f32 math kernels: f32 and integer arithmetic only, no f64 anywhere (every
//! f64 operation is a soft-float call on the Cortex-M4F), fixed work, every f32 input handled.
//!
//! | kernel | method | max error vs f64 (`tests/kernels.rs`) |
//! |---|---|---|
//! | [`sin_cos`], [`sin`], [`cos`] | Cody–Waite by π/2 below 1600, Payne–Hanek above; minimax on [−π/4, π/4] | see below |
//! | [`sin_cos_turns`] | phase in 2⁻³² turns: integer reduction, the same polynomials | see below |
//! | [`atan2`] | one division to [0, 1], three intervals, minimax of degree 9 | see below |
//! | [`cbrt`] | exponent ÷ 3, cubic guess, exact residual, one Halley step | see below |
//! | [`sqrt`] | `vsqrt.f32` on the target, libm on the host: correctly rounded | 0 ulp |
//! | [`floor`] | the FPU's truncation to an integer, one less when above | 0 ulp (exact) |
//!
//! Errors in ulps of the f32 result, measured against the host's f64 functions of the same f32
//! inputs (the stratified sweeps of `tests/kernels.rs`, every range and binade): sin 0.81 ulp,
//! cos 0.82 ulp over the whole f32 range (0.72 / 0.74 on |x| ≤ π/4), `sin_cos_turns` 0.82 /
//! 0.83, atan2 1.37, cbrt 0.51. The tests assert sin/cos ≤ 1 ulp, atan2 ≤ 1.6, cbrt ≤ 0.51;
//! their `#[ignore]`d exhaustive variants run every f32 input.
//!
//! Host and target run the same f32 operations in the same order (Rust never contracts
//! a·b + c into a fused multiply-add), so they give the same bits; the self-test checks that
//! on the target against vectors from the host.
//!
//! Which backend `crate::math::sin` etc. use is the `kernels` feature's choice (see
//! [`crate::math`]); these functions are always available, for measurements and for code that
//! must not depend on the backend.

mod atan2;
mod cbrt;
mod floor;
#[doc(hidden)]
pub mod reduce;
mod sin_cos;
mod sqrt;

pub use atan2::atan2;
pub use cbrt::cbrt;
pub use floor::floor;
pub use sin_cos::{cos, sin, sin_cos, sin_cos_turns};
pub use sqrt::sqrt;
