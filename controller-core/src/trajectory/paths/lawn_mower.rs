//! The lawn-mower (docs/missions.md#closed-form-paths): x_d = s(0.25 t + 2.5 sin 2ωt), y_d = 15 s cos ωt,
//! z_d = depth, ψ_d the trapezoid series of base ω (`series.rs`; paper: ω = 0.05, so 2ω = 0.1
//! in x_d; s = 1 is the paper's 30×15 case).

use crate::math;
use crate::trajectory::error::{positive, symmetric, TrajectoryError};
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::Trajectory;

/// The lawn-mower's advance, x_d = s(0.25 t + …): 0.25 m/s per unit scale.
pub(super) const ADVANCE: f32 = 0.25;

/// s in (0, [`Trajectory::MAX_SIZE`]/15] (y_d's amplitude is 15 s), ω in
/// (0, [`Trajectory::MAX_OMEGA`]], |depth| ≤ [`Trajectory::MAX_DEPTH`].
pub(super) fn check(scale: f32, omega: f32, depth: f32) -> Result<(), TrajectoryError> {
    positive("scale", scale, Trajectory::MAX_SIZE / 15.0)?;
    positive("omega", omega, Trajectory::MAX_OMEGA)?;
    symmetric("depth", depth, Trajectory::MAX_DEPTH)
}

/// The path at a sample: the advance s·(0.25/k)·t rounded once
/// ([`MissionTime::linear`](crate::phase::MissionTime::linear)) plus the wave.
#[inline]
pub(super) fn planar(scale: f32, depth: f32, t: &Trajectory, ph: &Phases) -> Planar {
    let omega = t.omega;
    let Harmonics { s1, c1, s2, c2 } = ph.h;
    let two = 2.0 * omega;
    let wave = 2.5 * scale * s2;
    let amp_y = 15.0 * scale;
    Planar {
        x: ph.time.linear(&t.position_rate, wave),
        y: amp_y * c1,
        z: depth,
        z_dot: 0.0,
        z_ddot: 0.0,
        d: [
            [scale * (t.rate + 2.5 * two * c2), -amp_y * omega * s1],
            [-2.5 * scale * two * two * s2, -amp_y * omega * omega * c1],
            [
                -2.5 * scale * two * two * two * c2,
                amp_y * omega * omega * omega * s1,
            ],
        ],
    }
}

/// ẋ = s(a − b u), ẏ² = s² c u with u = sin²θ ∈ [0, 1], a = 0.25/k + 5ω, b = 10ω,
/// c = 225ω² (`rate` = 0.25/k, `omega` = ω/k): a convex quadratic in u, least at
/// u* = (2ab − c)/(2b²) clamped to [0, 1].
pub(super) fn min_speed(scale: f32, rate: f32, omega: f32) -> f32 {
    let w = omega;
    let a = rate + 5.0 * w;
    let b = 10.0 * w;
    let c = 225.0 * w * w;
    let u = ((2.0 * a * b - c) / (2.0 * b * b)).clamp(0.0, 1.0);
    let f = (a - b * u) * (a - b * u) + c * u;
    scale * math::exact_sqrt(f)
}

/// Σ |amplitude|·frequency² of ẍ_d (2.5 s (2ω)²) and of ÿ_d (15 s ω²).
pub(super) fn accel(scale: f32, omega: f32) -> (f32, f32) {
    let two = 2.0 * omega;
    (2.5 * scale * two * two, 15.0 * scale * omega * omega)
}
