//! The helix (not in the paper; docs/missions.md#closed-form-paths **Choice**): the circle (`circle.rs`) with a
//! depth that changes linearly, z_d = depth + ż_d·t; ψ_d = ωt.

use super::circle::{self, Circle};
#[cfg(feature = "serde")]
use super::kind::{paper_depth, paper_omega};
use super::kind::{ClosedForm, PathKind};
use crate::trajectory::error::{Parameter, ParameterRange};
use crate::trajectory::phases::{Phases, Planar};
use crate::trajectory::Trajectory;

/// A circle whose depth changes linearly: z = depth + depth_rate·t (not in the paper).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Helix {
    /// R (m).
    pub radius: f32,
    /// ω (rad/s).
    #[cfg_attr(feature = "serde", serde(default = "paper_omega"))]
    pub omega: f32,
    /// z_d at t = 0 (m, positive down).
    #[cfg_attr(feature = "serde", serde(default = "paper_depth"))]
    pub depth: f32,
    /// ż_d (m/s, positive = descending).
    pub depth_rate: f32,
}

/// |ż_d| ≤ [`Trajectory::MAX_DEPTH_RATE`].
const DEPTH_RATE: Parameter = Parameter {
    name: "depth_rate",
    range: ParameterRange::Symmetric(Trajectory::MAX_DEPTH_RATE),
};

impl Helix {
    /// The circle it winds around (at its starting depth).
    fn circle(&self) -> Circle {
        Circle {
            radius: self.radius,
            omega: self.omega,
            depth: self.depth,
        }
    }
}

impl ClosedForm for Helix {
    /// The paper's 10 m circle, descending at 5 cm/s.
    const EXAMPLE: Helix = Helix {
        radius: 10.0,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
        depth_rate: 0.05,
    };
}

impl PathKind for Helix {
    /// The circle's, then ż_d.
    fn parameters(&mut self, visit: &mut dyn FnMut(&Parameter, &mut f32)) {
        let mut circle = self.circle();
        circle.parameters(visit);
        (self.radius, self.omega, self.depth) = (circle.radius, circle.omega, circle.depth);
        visit(&DEPTH_RATE, &mut self.depth_rate);
    }

    fn rates(&self) -> (f32, f32) {
        (self.omega, self.depth_rate)
    }

    fn accel(&self, omega: f32) -> (f32, f32) {
        self.circle().accel(omega)
    }

    fn min_speed(&self, t: &Trajectory) -> f32 {
        self.circle().min_speed(t)
    }

    /// The circle, z_d = depth + (ż/k)·t rounded once
    /// ([`MissionTime::linear`](crate::phase::MissionTime::linear)).
    #[inline]
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar {
        let mut p = circle::horizontal(self.radius, t.omega, &ph.h);
        p.z = ph.time.linear(&t.position_rate, self.depth);
        p.z_dot = t.rate;
        p
    }
}
