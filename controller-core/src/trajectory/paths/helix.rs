//! The helix (not in the paper; docs/missions.md#closed-form-paths **Choice**): the circle (`circle.rs`) with a
//! depth that changes linearly, z_d = depth + ż_d·t; ψ_d = ωt.

use super::circle;
use crate::trajectory::error::{symmetric, TrajectoryError};
use crate::trajectory::phases::{Phases, Planar};
use crate::trajectory::Trajectory;

/// The circle's checks, then |depth_rate| ≤ [`Trajectory::MAX_DEPTH_RATE`].
pub(super) fn check(
    radius: f32,
    omega: f32,
    depth: f32,
    depth_rate: f32,
) -> Result<(), TrajectoryError> {
    circle::check(radius, omega, depth)?;
    symmetric("depth_rate", depth_rate, Trajectory::MAX_DEPTH_RATE)
}

/// The path at a sample: the circle, z_d = depth + (ż/k)·t rounded once
/// ([`MissionTime::linear`](crate::phase::MissionTime::linear)).
#[inline]
pub(super) fn planar(radius: f32, depth: f32, t: &Trajectory, ph: &Phases) -> Planar {
    let mut p = circle::horizontal(radius, t.omega, &ph.h);
    p.z = ph.time.linear(&t.position_rate, depth);
    p.z_dot = t.rate;
    p
}
