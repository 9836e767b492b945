//! The circle (docs/missions.md#closed-form-paths): x_d = R sin ωt, y_d = R cos ωt, z_d = depth, ψ_d = ωt
//! (paper: ω = 0.1). **Choice** (docs/missions.md#closed-form-paths): the printed "x_d = 10 sin(0.1)t" is read as R sin(0.1t)
//! (a misplaced parenthesis: y_d = 10 cos(0.1t) beside it and the circular plot fix it).

#[cfg(feature = "serde")]
use super::kind::{paper_depth, paper_omega};
use super::kind::{ClosedForm, PathKind, DEPTH, OMEGA};
use crate::trajectory::error::{Parameter, ParameterRange};
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::Trajectory;

/// x = R sin ωt, y = R cos ωt, z = depth, ψ = ωt (paper: ω = 0.1; "10 sin(0.1)t" read as
/// R sin 0.1t).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Circle {
    /// R (m).
    pub radius: f32,
    /// ω (rad/s).
    #[cfg_attr(feature = "serde", serde(default = "paper_omega"))]
    pub omega: f32,
    /// z_d (m, positive down).
    #[cfg_attr(feature = "serde", serde(default = "paper_depth"))]
    pub depth: f32,
}

/// R in (0, [`Trajectory::MAX_SIZE`]].
const RADIUS: Parameter = Parameter {
    name: "radius",
    range: ParameterRange::Positive(Trajectory::MAX_SIZE),
};

impl ClosedForm for Circle {
    /// The paper's 10 m circle.
    const EXAMPLE: Circle = Circle {
        radius: 10.0,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    };
}

impl PathKind for Circle {
    fn parameters(&mut self, visit: &mut dyn FnMut(&Parameter, &mut f32)) {
        visit(&RADIUS, &mut self.radius);
        visit(&OMEGA, &mut self.omega);
        visit(&DEPTH, &mut self.depth);
    }

    fn rates(&self) -> (f32, f32) {
        (self.omega, 0.0)
    }

    /// Σ |amplitude|·frequency² of ẍ_d and of ÿ_d: Rω² each.
    fn accel(&self, omega: f32) -> (f32, f32) {
        let r = self.radius;
        (r * omega * omega, r * omega * omega)
    }

    /// The horizontal speed, constant: Rω/k.
    fn min_speed(&self, t: &Trajectory) -> f32 {
        self.radius * t.omega
    }

    #[inline]
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar {
        let mut p = horizontal(self.radius, t.omega, &ph.h);
        p.z = self.depth;
        p
    }
}

/// x_d, y_d and their derivatives (z_d left 0): the circle, and the helix around it.
#[inline]
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
