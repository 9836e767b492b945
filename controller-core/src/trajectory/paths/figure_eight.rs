//! The figure-eight (docs/missions.md#closed-form-paths): x_d = A sin ωt, y_d = A cos(ωt/2), z_d = depth,
//! ψ_d the triangle series of base ω (`series.rs`; paper: ω = 0.1, A = 15 or 20 for the
//! 30×30 and 40×40 cases).

use crate::math;
use crate::trajectory::error::{positive, symmetric, TrajectoryError};
use crate::trajectory::phases::{Phases, Planar};
use crate::trajectory::Trajectory;

/// A in (0, [`Trajectory::MAX_SIZE`]], ω in (0, [`Trajectory::MAX_OMEGA`]],
/// |depth| ≤ [`Trajectory::MAX_DEPTH`].
pub(super) fn check(amplitude: f32, omega: f32, depth: f32) -> Result<(), TrajectoryError> {
    positive("amplitude", amplitude, Trajectory::MAX_SIZE)?;
    positive("omega", omega, Trajectory::MAX_OMEGA)?;
    symmetric("depth", depth, Trajectory::MAX_DEPTH)
}

/// The path at a sample (`omega` is ω/k; y_d runs on the half phase).
#[inline]
pub(super) fn planar(amplitude: f32, depth: f32, omega: f32, ph: &Phases) -> Planar {
    let half = 0.5 * omega;
    let (s1, c1) = (ph.h.s1, ph.h.c1);
    let (sh, ch) = math::sin_cos_turns(ph.half);
    Planar {
        x: amplitude * s1,
        y: amplitude * ch,
        z: depth,
        z_dot: 0.0,
        z_ddot: 0.0,
        d: [
            [amplitude * omega * c1, -amplitude * half * sh],
            [
                -amplitude * omega * omega * s1,
                -amplitude * half * half * ch,
            ],
            [
                -amplitude * omega * omega * omega * c1,
                amplitude * half * half * half * sh,
            ],
        ],
    }
}

/// ẋ = Aω cos θ, ẏ = −(Aω/2) sin(θ/2), so with s = sin²(θ/2) the speed² is
/// A²ω²[(1 − 2s)² + s/4], least at s = 15/32: Aω√31/16 ≈ 0.348 Aω.
pub(super) fn min_speed(amplitude: f32, omega: f32) -> f32 {
    amplitude * omega * math::exact_sqrt(31.0) / 16.0
}

/// Σ |amplitude|·frequency² of ẍ_d (Aω²) and of ÿ_d (A(ω/2)²).
pub(super) fn accel(amplitude: f32, omega: f32) -> (f32, f32) {
    let half = 0.5 * omega;
    (amplitude * omega * omega, amplitude * half * half)
}
