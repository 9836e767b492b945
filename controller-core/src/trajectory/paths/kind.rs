//! What every path kind answers ([`PathKind`]): its parameters and their ranges, the
//! constants [`Trajectory`] precomputes from them, and the path at a sample. One file of
//! `paths/` per kind implements it; the list in `paths/mod.rs` dispatches to them.

use crate::math;
use crate::phase::{Frequency, LinearRate};
use crate::trajectory::error::{Parameter, ParameterRange, TrajectoryError};
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::series::Series;
use crate::trajectory::Trajectory;

use super::{Route, TimeLaw};

/// ω (rad/s), in (0, [`Trajectory::MAX_OMEGA`]]: every closed form's base frequency.
pub(super) const OMEGA: Parameter = Parameter {
    name: "omega",
    range: ParameterRange::Positive(Trajectory::MAX_OMEGA),
};
/// z_d (m, positive down), in [−[`Trajectory::MAX_DEPTH`], [`Trajectory::MAX_DEPTH`]].
pub(super) const DEPTH: Parameter = Parameter {
    name: "depth",
    range: ParameterRange::Symmetric(Trajectory::MAX_DEPTH),
};

/// A path kind: the variant's parameters and its equations (docs/missions.md#closed-form-paths). Each method
/// answers one question [`Trajectory`] asks, at configuration (all but the last two) or per
/// sample ([`planar`](Self::planar), [`paper_heading`](Self::paper_heading): fixed work, no
/// panic, inlined into the one `match` of the dispatch, no vtable).
///
/// A new closed-form kind is a file of `paths/` with its parameter struct and this impl, and
/// one line in the list of `paths/mod.rs`.
pub(crate) trait PathKind {
    /// Visits each `f32` parameter, in field order, with its name and range (what
    /// [`check`](Self::check) enforces; the fuzzers and the docs read the same table). The
    /// waypoint path's points and options are checked as its route is built, and not visited.
    fn parameters(&mut self, visit: &mut dyn FnMut(&Parameter, &mut f32));

    /// Checks the parameters in field order (the error names the field), then builds the
    /// waypoint path's route and time law into `route` and `law` in place (Choice 180); a
    /// closed form leaves both empty (also after an error).
    fn build_into(&self, route: &mut Route, law: &mut TimeLaw) -> Result<(), TrajectoryError>
    where
        Self: Copy,
    {
        let mut copy = *self;
        let mut checked = Ok(());
        copy.parameters(&mut |p, v| {
            if checked.is_ok() {
                checked = p.check(*v);
            }
        });
        route.clear();
        law.clear();
        checked
    }

    /// The base frequency ω (rad/s) and the rate of the terms linear in t, before the time
    /// scale (0 where there is none).
    fn rates(&self) -> (f32, f32);

    /// The rate of the position that grows with t, from the linear rate over the time scale.
    fn position_rate(&self, rate: f64) -> LinearRate {
        LinearRate::new(rate)
    }

    /// The half phase's frequency from ω/k (the figure-eight's y_d); none by default.
    fn half_frequency(&self, _omega: f64) -> Frequency {
        Frequency::default()
    }

    /// The series that is the path's paper heading, if it is one (else ψ_d = ωt).
    fn heading_series(&self) -> Option<Series> {
        None
    }

    /// Σ |amplitude|·frequency² of ẍ_d and of ÿ_d (`omega` = ω/k): the path's part of K_d
    /// (Assumption 1). The terms linear in t have no acceleration.
    fn accel(&self, omega: f32) -> (f32, f32);

    /// The smallest horizontal speed √(ẋ_d² + ẏ_d²) over the path at `t`'s time scale (m/s).
    fn min_speed(&self, t: &Trajectory) -> f32;

    /// The phases at `a` (2⁻³² turns) along one period of the path's course, for the tangent
    /// heading's bound; `None` where the course turns at a constant rate.
    fn course_period_phases(&self, _a: u32) -> Option<Phases> {
        None
    }

    /// The path at the given phases: x_d, y_d and three derivatives each, z_d and ż_d
    /// (analytic; every frequency and rate is already over the time scale).
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar;

    /// The paper's ψ_d, ψ̇_d, ψ̈_d at phase θ (2⁻³² turns): the path's series if it has one,
    /// else ωt.
    #[inline(always)]
    fn paper_heading(
        &self,
        t: &Trajectory,
        theta: u32,
        h: &Harmonics,
        _p: &Planar,
    ) -> (f32, f32, f32) {
        match self.heading_series() {
            Some(_) => t.heading_series(h),
            None => (math::turns_to_radians(theta), t.omega, 0.0),
        }
    }
}

/// A closed-form kind: a [`PathKind`] with an example (valid, at the paper's scale: the
/// tests, the fuzzers, the golden vectors and the docs iterate
/// [`TrajectoryKind::EXAMPLES`](crate::TrajectoryKind::EXAMPLES)).
pub(crate) trait ClosedForm: PathKind + Copy {
    /// A valid mission of this kind, flown by both headings.
    const EXAMPLE: Self;
}

/// The serde defaults of the closed forms (the paper's values).
#[cfg(feature = "serde")]
pub(super) fn paper_omega() -> f32 {
    Trajectory::PAPER_OMEGA
}
#[cfg(feature = "serde")]
pub(super) fn paper_depth() -> f32 {
    Trajectory::PAPER_DEPTH
}
