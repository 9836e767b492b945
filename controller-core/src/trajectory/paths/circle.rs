//! The circle (docs/missions.md#closed-form-paths): x_d = R sin ωt, y_d = R cos ωt, z_d = depth, ψ_d = ωt
//! (paper: ω = 0.1). **Choice** (docs/missions.md#closed-form-paths): the printed "x_d = 10 sin(0.1)t" is read as R sin(0.1t)
//! (a misplaced parenthesis: y_d = 10 cos(0.1t) beside it and the circular plot fix it).

use crate::trajectory::error::{positive, symmetric, TrajectoryError};
use crate::trajectory::phases::{Harmonics, Planar};
use crate::trajectory::Trajectory;

/// R in (0, [`Trajectory::MAX_SIZE`]], ω in (0, [`Trajectory::MAX_OMEGA`]],
/// |depth| ≤ [`Trajectory::MAX_DEPTH`].
pub(super) fn check(radius: f32, omega: f32, depth: f32) -> Result<(), TrajectoryError> {
    positive("radius", radius, Trajectory::MAX_SIZE)?;
    positive("omega", omega, Trajectory::MAX_OMEGA)?;
    symmetric("depth", depth, Trajectory::MAX_DEPTH)
}

/// The path at a sample (`omega` is ω/k).
#[inline]
pub(super) fn planar(radius: f32, depth: f32, omega: f32, h: &Harmonics) -> Planar {
    let mut p = horizontal(radius, omega, h);
    p.z = depth;
    p
}

/// x_d, y_d and their derivatives (z_d left 0): the circle, and the helix around it.
pub(super) fn horizontal(radius: f32, omega: f32, h: &Harmonics) -> Planar {
    let (s, c) = (h.s1, h.c1);
    Planar {
        x: radius * s,
        y: radius * c,
        z: 0.0,
        z_dot: 0.0,
        z_ddot: 0.0,
        d: [
            [radius * omega * c, -radius * omega * s],
            [-radius * omega * omega * s, -radius * omega * omega * c],
            [
                -radius * omega * omega * omega * c,
                radius * omega * omega * omega * s,
            ],
        ],
    }
}

/// The horizontal speed, constant: Rω/k.
pub(super) fn min_speed(radius: f32, omega: f32) -> f32 {
    radius * omega
}

/// Σ |amplitude|·frequency² of ẍ_d and of ÿ_d: Rω² each.
pub(super) fn accel(radius: f32, omega: f32) -> (f32, f32) {
    (radius * omega * omega, radius * omega * omega)
}
