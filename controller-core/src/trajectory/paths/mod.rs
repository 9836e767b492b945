//! The path kinds, one file each: its parameter checks, the path and its derivatives at a
//! sample, its smallest horizontal speed and its acceleration bound, in closed form
//! (docs/missions.md#closed-form-paths). The functions here answer each question for any [`TrajectoryKind`]
//! with one `match`: a new path kind is its file, its variant of [`TrajectoryKind`] and one
//! arm in each of them.

mod circle;
mod figure_eight;
mod helix;
mod lawn_mower;
pub(super) mod time_law;
pub(super) mod waypoints;

use crate::math;
use crate::phase::{Frequency, LinearRate, MissionTime};
use crate::trajectory::error::TrajectoryError;
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::series::Series;
use crate::trajectory::{Route, TimeLaw, Trajectory, TrajectoryKind};

/// The path's parameters, checked in field order (the error names the field), and the waypoint
/// path's route and time law built into `route` and `law` in place as they are checked
/// (Choice 180); for the other kinds both are left empty.
pub(super) fn build_into(
    path: &TrajectoryKind,
    route: &mut Route,
    law: &mut TimeLaw,
) -> Result<(), TrajectoryError> {
    let checked = match *path {
        TrajectoryKind::Circle {
            radius,
            omega,
            depth,
        } => circle::check(radius, omega, depth),
        TrajectoryKind::FigureEight {
            amplitude,
            omega,
            depth,
        } => figure_eight::check(amplitude, omega, depth),
        TrajectoryKind::LawnMower {
            scale,
            omega,
            depth,
        } => lawn_mower::check(scale, omega, depth),
        TrajectoryKind::Helix {
            radius,
            omega,
            depth,
            depth_rate,
        } => helix::check(radius, omega, depth, depth_rate),
        TrajectoryKind::Waypoints {
            ref points,
            speed,
            turn_radius,
            ref speeds,
            speed_change,
        } => {
            let path = time_law::Waypoints {
                points,
                speed,
                turn_radius,
                speeds: speeds.as_ref(),
                speed_change,
            };
            return time_law::build_into(&path, route, law);
        }
    };
    route.clear();
    law.clear();
    checked
}

/// The base frequency ω (rad/s) and the rate of the terms linear in t, before the time scale:
/// the lawn-mower's advance (per unit scale, m/s), the helix's depth rate (m/s), else 0.
pub(super) fn rates(path: &TrajectoryKind) -> (f32, f32) {
    match *path {
        TrajectoryKind::Circle { omega, .. } | TrajectoryKind::FigureEight { omega, .. } => {
            (omega, 0.0)
        }
        TrajectoryKind::LawnMower { omega, .. } => (omega, lawn_mower::ADVANCE),
        TrajectoryKind::Helix {
            omega, depth_rate, ..
        } => (omega, depth_rate),
        TrajectoryKind::Waypoints { speed, .. } => (0.0, speed),
    }
}

/// The rate of the position that grows with t, from the linear rate over the time scale: the
/// lawn-mower's times its scale, the helix's as it is.
pub(super) fn position_rate(path: &TrajectoryKind, rate: f64) -> LinearRate {
    match *path {
        TrajectoryKind::LawnMower { scale, .. } => LinearRate::new(rate * scale as f64),
        _ => LinearRate::new(rate),
    }
}

/// The half phase's frequency from ω/k: ω/2k on the figure-eight (its y_d), none elsewhere.
pub(super) fn half_frequency(path: &TrajectoryKind, omega: f64) -> Frequency {
    match *path {
        TrajectoryKind::FigureEight { .. } => Frequency::from_rad_per_s(0.5 * omega),
        _ => Frequency::default(),
    }
}

/// The series that is the path's paper heading, if it is one (ψ_d = ωt otherwise).
pub(super) fn heading_series(path: &TrajectoryKind) -> Option<Series> {
    match *path {
        TrajectoryKind::FigureEight { .. } => Some(Series::Triangle),
        TrajectoryKind::LawnMower { .. } => Some(Series::Trapezoid),
        TrajectoryKind::Circle { .. }
        | TrajectoryKind::Helix { .. }
        | TrajectoryKind::Waypoints { .. } => None,
    }
}

/// Σ |amplitude|·frequency² of ẍ_d and of ÿ_d (`omega` = ω/k): the path's part of K_d
/// (Assumption 1). The terms linear in t have no acceleration. The waypoint path's bound is
/// its route's ([`waypoints::bounds`], in [`Trajectory`]'s precompute), not a sum of amplitudes.
pub(super) fn accel(path: &TrajectoryKind, omega: f32) -> (f32, f32) {
    match *path {
        TrajectoryKind::Circle { radius, .. } | TrajectoryKind::Helix { radius, .. } => {
            circle::accel(radius, omega)
        }
        TrajectoryKind::FigureEight { amplitude, .. } => figure_eight::accel(amplitude, omega),
        TrajectoryKind::LawnMower { scale, .. } => lawn_mower::accel(scale, omega),
        TrajectoryKind::Waypoints { .. } => (0.0, 0.0),
    }
}

/// The smallest horizontal speed √(ẋ_d² + ẏ_d²) over the path, in closed form (m/s); the
/// waypoint path's is its route's, sampled ([`waypoints::bounds`]).
pub(super) fn min_speed(t: &Trajectory) -> f32 {
    let w = t.omega;
    match t.mission.path {
        TrajectoryKind::Circle { radius, .. } | TrajectoryKind::Helix { radius, .. } => {
            circle::min_speed(radius, w)
        }
        TrajectoryKind::FigureEight { amplitude, .. } => figure_eight::min_speed(amplitude, w),
        TrajectoryKind::LawnMower { scale, .. } => lawn_mower::min_speed(scale, t.rate, w),
        TrajectoryKind::Waypoints { .. } => waypoints::bounds(&t.route).0 * t.rate,
    }
}

/// The phases at `a` (2⁻³² turns) along one period of the path's course, for the tangent
/// heading's bound: the figure-eight's y_d has the half phase (period 4π in θ), the
/// lawn-mower's derivatives have period 2π in θ. `None` where the course turns at a constant
/// rate (the circle and the helix).
pub(super) fn course_period_phases(path: &TrajectoryKind, a: u32) -> Option<Phases> {
    let time = MissionTime::new(0, 1);
    match *path {
        TrajectoryKind::FigureEight { .. } => Some(Phases {
            half: a,
            h: Harmonics::of(a.wrapping_mul(2)),
            time,
        }),
        TrajectoryKind::LawnMower { .. } => Some(Phases {
            half: 0,
            h: Harmonics::of(a),
            time,
        }),
        TrajectoryKind::Circle { .. }
        | TrajectoryKind::Helix { .. }
        | TrajectoryKind::Waypoints { .. } => None,
    }
}

/// The path at the given phases: x_d, y_d and three derivatives each, z_d and ż_d
/// (analytic; every frequency and rate is already over the time scale).
#[inline]
pub(super) fn planar(t: &Trajectory, ph: &Phases) -> Planar {
    match t.mission.path {
        TrajectoryKind::Circle { radius, depth, .. } => {
            circle::planar(radius, depth, t.omega, &ph.h)
        }
        TrajectoryKind::Helix { radius, depth, .. } => helix::planar(radius, depth, t, ph),
        TrajectoryKind::FigureEight {
            amplitude, depth, ..
        } => figure_eight::planar(amplitude, depth, t.omega, ph),
        TrajectoryKind::LawnMower { scale, depth, .. } => lawn_mower::planar(scale, depth, t, ph),
        TrajectoryKind::Waypoints { .. } => match t.law.is_set() {
            true => time_law::timed(&t.route, &t.law, &ph.time, &t.position_rate, t.rate),
            false => waypoints::planar(&t.route, &ph.time, &t.position_rate, t.rate),
        },
    }
}

/// The paper's ψ_d, ψ̇_d, ψ̈_d at phase θ (2⁻³² turns): ωt on the circle and the helix, the
/// path's series on the figure-eight and the lawn-mower. The waypoint path has no heading of
/// its own in the paper: its "paper" heading is its course, as the tangent heading (Choice 154).
#[inline]
pub(super) fn paper_heading(
    t: &Trajectory,
    theta: u32,
    h: &Harmonics,
    p: &Planar,
) -> (f32, f32, f32) {
    match t.mission.path {
        TrajectoryKind::Circle { .. } | TrajectoryKind::Helix { .. } => {
            (math::turns_to_radians(theta), t.omega, 0.0)
        }
        TrajectoryKind::FigureEight { .. } | TrajectoryKind::LawnMower { .. } => {
            t.heading_series(h)
        }
        TrajectoryKind::Waypoints { .. } => crate::trajectory::phases::tangent(p),
    }
}
