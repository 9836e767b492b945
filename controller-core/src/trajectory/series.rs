//! The paper's heading series (docs/missions.md#closed-form-paths **Choice**: prefactor 8/π, truncated at
//! N = [`Trajectory::SERIES_TERMS`] = 9): the figure-eight's triangle and the lawn-mower's
//! trapezoid, as per-harmonic coefficients computed once and summed per sample over the odd
//! harmonics (the even ones are identically zero in both).

use core::f32::consts::{FRAC_1_SQRT_2, PI};

use crate::math;
use crate::trajectory::phases::Harmonics;
use crate::trajectory::Trajectory;

/// Number of odd harmonics n = 1, 3, …, N evaluated by the heading series.
pub(super) const ODD_TERMS: usize = (Trajectory::SERIES_TERMS as usize).div_ceil(2);

/// Heading-series shape: ψ = (8/π) Σ_{n odd ≤ N} sign_n sin(nθ)/n² · `gain`.
#[derive(Clone, Copy)]
pub(super) enum Series {
    /// Figure-eight: sign_n = (−1)^((n−1)/2), gain 1.
    Triangle,
    /// Lawn-mower: sin(nπ/4) + sin(3nπ/4) = 2 sin(nπ/4) = √2·sign_n for odd n, with
    /// sign_n = +1 for n ≡ 1, 3 (mod 8) and −1 for n ≡ 5, 7 (mod 8); gain √2.
    Trapezoid,
}

/// Per-harmonic coefficients of ψ_d, ψ̇_d, ψ̈_d: for harmonic n (odd),
/// ψ = Σ a_n sin(nθ), ψ̇ = Σ a_n nω cos(nθ), ψ̈ = −Σ a_n n²ω² sin(nθ).
pub(super) const fn series_coefficients(series: Series, omega: f32) -> [[f32; 3]; ODD_TERMS] {
    let mut out = [[0.0; 3]; ODD_TERMS];
    let mut i = 0;
    while i < ODD_TERMS {
        let n = 2 * i as u32 + 1;
        let (sign, gain) = match series {
            Series::Triangle => (if i % 2 == 0 { 1.0 } else { -1.0 }, 1.0),
            Series::Trapezoid => (
                if n % 8 == 1 || n % 8 == 3 { 1.0 } else { -1.0 },
                2.0 * FRAC_1_SQRT_2,
            ),
        };
        let nf = n as f32;
        let a = 8.0 / PI * gain * sign / (nf * nf);
        out[i] = [a, a * nf * omega, a * nf * nf * omega * omega];
        i += 1;
    }
    out
}

impl Trajectory {
    /// ψ_d, ψ̇_d, ψ̈_d from the precomputed odd-harmonic coefficients (fixed five terms).
    ///
    /// sin nθ and cos nθ for n = 3, 5, 7, 9 come from the angle-addition recurrence
    /// sin (n+2)θ = sin nθ cos 2θ + cos nθ sin 2θ, cos (n+2)θ = cos nθ cos 2θ − sin nθ sin 2θ,
    /// from the sample's [`Harmonics`] (one `sin_cos_turns` for the path and the series
    /// together, instead of one call per harmonic). Four steps of the recurrence add a few
    /// ulps (tests/trajectory.rs measures the series against f64).
    pub(super) fn heading_series(&self, h: &Harmonics) -> (f32, f32, f32) {
        let (s2, c2) = (h.s2, h.c2);
        let (mut s, mut co) = (h.s1, h.c1);
        let (mut psi, mut rate, mut accel) = (0.0f32, 0.0f32, 0.0f32);
        for c in &self.psi {
            psi += c[0] * s;
            rate += c[1] * co;
            accel -= c[2] * s;
            let next = (s * c2 + co * s2, co * c2 - s * s2);
            s = next.0;
            co = next.1;
        }
        (math::wrap_pi(psi), rate, accel)
    }
}
