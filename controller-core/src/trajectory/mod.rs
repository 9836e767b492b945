//! Reference trajectories of the paper's missions: η_d(t), η̇_d(t), η̈_d(t).
//!
//! This module owns the desired state fed to the control law (ū = η̈_d − K₁e₁ − K₂e₂, Eq 17, with
//! e₁ = η − η_d and e₂ = η̇ − η̇_d, Eqs 12–13) and the bound K_d ≥ ‖η̈_d(t)‖ of Assumption 1
//! (Eq 19) that enters δ (Eq 29). The missions are the paper's "Simulation Results" section, as
//! cleaned up in docs/missions.md#closed-form-paths; all have φ_d = θ_d = 0 (and zero roll/pitch rates):
//!
//! | kind | x_d | y_d | z_d | ψ_d |
//! |---|---|---|---|---|
//! | circle | R sin ωt | R cos ωt | depth | ωt |
//! | figure-eight | A sin ωt | A cos(ωt/2) | depth | triangle series, base ω |
//! | lawn-mower | s(0.25t + 2.5 sin 2ωt) | 15s cos ωt | depth | trapezoid series, base ω |
//! | helix | R sin ωt | R cos ωt | depth + ż·t | ωt |
//!
//! The paper's values are ω = 0.1 (circle, figure-eight) and ω = 0.05 (lawn-mower, so that
//! 2ω = 0.1 in x_d), depth 5 m. The helix is ours (a circle that changes depth).
//!
//! **Choices** (docs/missions.md#closed-form-paths):
//! * The circle's printed "x_d = 10 sin(0.1)t" is read as R sin(0.1t) (a misplaced parenthesis:
//!   y_d = 10 cos(0.1t) beside it and the circular plot fix it).
//! * Both heading series use the prefactor 8/π (it makes the triangle and the trapezoid reach
//!   ±π, matching the paper's Fig. 5) and are truncated at N = [`Trajectory::SERIES_TERMS`] = 9.
//!   Every even-n term is identically zero in both series (for the lawn-mower,
//!   sin(3nπ/4) = −(−1)ⁿ sin(nπ/4), so sin(nπ/4) + sin(3nπ/4) = 2 sin(nπ/4) for odd n and 0 for
//!   even n), so only n = 1, 3, 5, 7, 9 are evaluated.
//! * All derivatives are analytic (term-by-term derivatives of the truncated series).
//!
//! **Time and precision** (docs/numerics.md#time-as-an-integer-tick-count): time is the integer tick count; no f32 `t` is ever
//! formed, and no f64 arithmetic runs per sample (docs/numerics.md#no-f64-on-the-control-step-from-the-elf). The tick count is split
//! once into whole seconds and a fraction ([`MissionTime`]); each base frequency turns it into a
//! phase in 2⁻³² turns by integer arithmetic ([`Frequency::phase`], exact to 3·2⁻³² turns at
//! any mission time); harmonics are n·θ as a wrapping integer product, so they are exact too.
//! One `sin_cos_turns` gives (sin θ, cos θ), the double-angle formulas (sin 2θ, cos 2θ), and the
//! heading series takes sin nθ, cos nθ for n = 3, 5, 7, 9 from the angle-addition recurrence:
//! one call per sample (two for the figure-eight's half phase) instead of one per harmonic.
//! Terms linear in t (lawn-mower surge advance, helix depth rate) use
//! [`MissionTime::linear`], the rate split into f32 parts at configuration so that rate·t is
//! rounded once. Positions that
//! grow with t (lawn-mower x_d, helix z_d) are f32 in the result, so they lose resolution as
//! they grow (≈ 8 mm at 90 km); see docs/numerics.md#positions.
//!
//! **Heading** ψ_d is returned wrapped to (−π, π]. For the circle and helix ψ_d = ωt grows
//! without bound and wraps once per revolution. The truncated lawn-mower series overshoots π
//! on its plateau (its maximum is ≈ 3.198 rad), so there too ψ_d jumps by 2π while the
//! heading itself is continuous; ψ̇_d and ψ̈_d are continuous everywhere. Consumers compare
//! headings modulo 2π (docs/law.md#structure wraps the yaw error).
//!
//! Every [`Trajectory::sample`] does a fixed amount of work (a `match` on the kind and, for the
//! series, a loop over a constant five harmonics), never allocates and never panics.
//!
//! **Files.** This file: [`Trajectory`] (validate, precompute, sample) and [`Desired`].
//! `paths/` the path kinds: [`TrajectoryKind`], declared with its dispatch from one list in
//! `paths/mod.rs`, and one file per kind (its parameters, the path at a sample, its minimum
//! speed and acceleration bound), so that a new closed-form kind is its file and one line of
//! the list; `heading.rs` [`HeadingMode`] and the tangent heading; `series.rs` the paper's
//! heading series; `phases.rs` a sample's phases and harmonics; `mission.rs` [`Mission`];
//! `table1.rs` [`Table1Case`]; `error.rs` [`TrajectoryError`] and the parameter ranges;
//! `limits.rs` the waypoint path's limits (a leaf: the refusals name them).

mod error;
mod heading;
mod limits;
mod mission;
mod paths;
mod phases;
mod series;
mod table1;

pub use error::{Parameter, ParameterRange, TrajectoryError};
pub use heading::HeadingMode;
pub use limits::{
    DEFAULT_SPEED_CHANGE, MAX_PARTS, MAX_SEGMENTS, MAX_SLOPE, MAX_SPEED, MAX_SPEED_CHANGE,
    MAX_TURN_DEGREES, MAX_WAYPOINTS, MIN_LEG, MIN_TURN_RADIUS, TURN_ACCEL,
};
pub use mission::Mission;
pub use paths::time_law::{SpeedList, TimeLaw};
pub use paths::waypoints::{turn_radius, PathPoint, Route, WaypointList};
// Every kind's parameter struct (declared by the list in `paths/mod.rs`) and `TrajectoryKind`.
pub use paths::*;
pub use table1::Table1Case;

use nalgebra::Vector6;

use crate::math;
use crate::phase::{Frequency, LinearRate, MissionTime};
use paths::PathKind;
use phases::tangent;
use phases::{Harmonics, Phases};
use series::{series_coefficients, ODD_TERMS};
use table1::{circle_kind, figure_eight_kind, lawn_mower_kind};

/// Desired state at one instant (earth frame, components [x y z φ θ ψ]).
///
/// `eta` = η_d (m, rad; ψ wrapped to (−π, π]), `eta_dot` = η̇_d (m/s and Euler-angle rates,
/// rad/s), `eta_ddot` = η̈_d (m/s², rad/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Desired {
    /// η_d = [x y z φ θ ψ].
    pub eta: Vector6<f32>,
    /// η̇_d.
    pub eta_dot: Vector6<f32>,
    /// η̈_d.
    pub eta_ddot: Vector6<f32>,
}

/// A validated mission with its precomputed constants; sample it with [`Trajectory::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trajectory {
    mission: Mission,
    /// ω/k (rad/s), for the amplitudes.
    omega: f32,
    /// ω/k as a turn rate, for θ (docs/numerics.md#time-as-an-integer-tick-count).
    theta: Frequency,
    /// ω/2k, the figure-eight's half phase (zero otherwise).
    half: Frequency,
    /// The linear rate over k: the lawn-mower's advance 0.25/k (per unit scale, m/s) or the
    /// helix's depth rate ż/k (m/s); zero otherwise.
    rate: f32,
    /// The linear position rate for the positions that grow with t
    /// ([`MissionTime::linear`]): the lawn-mower's 0.25·s/k (m/s) or the helix's ż/k.
    position_rate: LinearRate,
    /// `[a_n, a_n nω, a_n n²ω²]` for the odd harmonics (zero for circle/helix).
    psi: [[f32; 3]; ODD_TERMS],
    /// K_d of Assumption 1.
    accel_bound: f32,
    /// The smallest horizontal speed along the path (m/s), in closed form.
    min_speed: f32,
    /// The waypoint path's legs and blends ([`Route::EMPTY`] for the other kinds).
    route: Route,
    /// The waypoint path's time law ([`TimeLaw::EMPTY`]: constant speed, or another kind).
    law: TimeLaw,
}

impl Trajectory {
    /// N, the last harmonic of the heading series (docs/missions.md#closed-form-paths **Choice**: truncate at N = 9).
    pub const SERIES_TERMS: u32 = 9;
    /// The paper's ω for the circle and the figure-eight (rad/s).
    pub const PAPER_OMEGA: f32 = 0.1;
    /// The paper's ω for the lawn-mower (rad/s): y_d = 15 cos(0.05t), x_d uses 2ω = 0.1.
    pub const PAPER_LAWN_MOWER_OMEGA: f32 = 0.05;
    /// The paper's z_d (m).
    pub const PAPER_DEPTH: f32 = 5.0;
    /// Largest amplitude of any oscillating position term (R, A, 15 s), m. A sanity limit that
    /// keeps every output finite, not a feasibility check.
    pub const MAX_SIZE: f32 = 10_000.0;
    /// Largest |depth| (m).
    pub const MAX_DEPTH: f32 = 10_000.0;
    /// Largest ω (rad/s). A sanity limit; the vehicle cannot follow anything near it.
    pub const MAX_OMEGA: f32 = 10.0;
    /// Largest |depth_rate| of a helix (m/s).
    pub const MAX_DEPTH_RATE: f32 = 10.0;
    /// Largest time scale k (a mission flown 100 times slower than its path says).
    pub const MAX_TIME_SCALE: f32 = 100.0;
    /// Smallest horizontal speed (m/s) a tangent-heading mission may reach anywhere on its
    /// path (docs/missions.md#heading **Choice**): the course atan2(ẏ_d, ẋ_d) is undefined at zero
    /// speed and its derivatives grow as 1/speed², so [`Trajectory::new`] refuses a tangent
    /// mission whose closed-form minimum speed is lower, instead of holding a heading (which
    /// would need state in a stateless `update`). The shipped paths never stop.
    pub const MIN_TANGENT_SPEED: f32 = 0.02;

    /// An inert trajectory: the origin at the surface, held (η_d = 0, η̇_d = η̈_d = 0 at every
    /// t). Its mission (a circle of radius 0 and ω 0) is not one [`Trajectory::new`] accepts:
    /// it is what a trajectory holds before [`Trajectory::set`], and after a refused one.
    /// Every bit of it is zero (its time scale too), so that a board initialises one with a
    /// `memset` instead of copying 8.6 kB from flash.
    pub const EMPTY: Trajectory = Trajectory {
        mission: Mission {
            path: TrajectoryKind::Circle(Circle {
                radius: 0.0,
                omega: 0.0,
                depth: 0.0,
            }),
            heading: HeadingMode::Paper,
            time_scale: 0.0,
        },
        omega: 0.0,
        theta: Frequency::ZERO,
        half: Frequency::ZERO,
        rate: 0.0,
        position_rate: LinearRate::ZERO,
        psi: [[0.0; 3]; ODD_TERMS],
        accel_bound: 0.0,
        min_speed: 0.0,
        route: Route::EMPTY,
        law: TimeLaw::EMPTY,
    };

    /// Validates `mission` and precomputes the series coefficients, K_d and the minimum speed.
    /// A [`TrajectoryKind`] is the paper's mission ([`Mission::paper`]). A host convenience:
    /// `EMPTY` and then [`Trajectory::set`], returned by value (on the board, where a
    /// `Trajectory` of 32 waypoints is 8.6 kB, call `set` on one that stays in place).
    ///
    /// Checks, in field order: every parameter finite; radius/amplitude in (0, [`MAX_SIZE`]],
    /// lawn-mower scale in (0, [`MAX_SIZE`]/15]; omega in (0, [`MAX_OMEGA`]];
    /// |depth| ≤ [`MAX_DEPTH`]; |depth_rate| ≤ [`MAX_DEPTH_RATE`]; then time_scale in
    /// [1, [`MAX_TIME_SCALE`]]; then, for the tangent heading, a minimum horizontal speed
    /// ≥ [`MIN_TANGENT_SPEED`]. The error names the field.
    ///
    /// [`MAX_SIZE`]: Self::MAX_SIZE
    /// [`MAX_OMEGA`]: Self::MAX_OMEGA
    /// [`MAX_DEPTH`]: Self::MAX_DEPTH
    /// [`MAX_DEPTH_RATE`]: Self::MAX_DEPTH_RATE
    /// [`MAX_TIME_SCALE`]: Self::MAX_TIME_SCALE
    /// [`MIN_TANGENT_SPEED`]: Self::MIN_TANGENT_SPEED
    pub fn new(mission: impl Into<Mission>) -> Result<Self, TrajectoryError> {
        let mut t = Self::EMPTY;
        t.set(&mission.into())?;
        Ok(t)
    }

    /// [`Trajectory::new`] in place (Choice 180): validates `mission` and precomputes it into
    /// `self`, with no `Trajectory`, [`Route`] or [`TimeLaw`] on the stack (a waypoint path's
    /// route and time law are checked as they are built, once). The result is exactly
    /// [`Trajectory::new`]'s whatever `self` held before, and so is the error. After an error
    /// `self` samples as [`Trajectory::EMPTY`] (the origin held; never panics, finite).
    pub fn set(&mut self, mission: &Mission) -> Result<(), TrajectoryError> {
        let result = self.try_set(mission);
        if result.is_err() {
            self.make_inert();
        }
        result
    }

    /// [`Trajectory::set`] before its clean-up on an error.
    fn try_set(&mut self, mission: &Mission) -> Result<(), TrajectoryError> {
        mission.path.build_into(&mut self.route, &mut self.law)?;
        let k = mission.time_scale;
        if !k.is_finite() {
            return Err(TrajectoryError::NonFinite {
                parameter: "time_scale",
            });
        }
        if !(1.0..=Self::MAX_TIME_SCALE).contains(&k) {
            return Err(TrajectoryError::OutOfRange {
                parameter: "time_scale",
                value: k,
                min: 1.0,
                max: Self::MAX_TIME_SCALE,
            });
        }
        self.precompute(mission);
        if mission.heading == HeadingMode::Tangent
            && (self.min_speed.is_nan() || self.min_speed < Self::MIN_TANGENT_SPEED)
        {
            // A waypoint path's refusal names what sets its speed (Choice 315).
            return Err(match mission.path {
                TrajectoryKind::Waypoints { speeds, .. } => TrajectoryError::WaypointTooSlow {
                    min_speed: self.min_speed,
                    threshold: Self::MIN_TANGENT_SPEED,
                    part: speeds.and_then(|s| {
                        (0..s.as_slice().len())
                            .min_by(|&a, &b| s.as_slice()[a].total_cmp(&s.as_slice()[b]))
                    }),
                },
                _ => TrajectoryError::TooSlowForTangent {
                    min_speed: self.min_speed,
                    threshold: Self::MIN_TANGENT_SPEED,
                },
            });
        }
        Ok(())
    }

    /// Back to [`Trajectory::EMPTY`], every field.
    fn make_inert(&mut self) {
        // All zero bits (see `EMPTY`): a memset, not a copy of a constant from flash.
        *self = Self::EMPTY;
    }

    /// Precomputes the constants of an already validated mission into `self`, whose route and
    /// time law are already built (empty for the closed forms).
    fn precompute(&mut self, mission: &Mission) {
        let k = mission.time_scale as f64;
        let (omega, rate) = mission.path.rates();
        // η_d(t/k): every frequency and every linear rate over k (exact for k = 1).
        let omega_f64 = omega as f64 / k;
        let rate_f64 = rate as f64 / k;
        let omega = omega_f64 as f32;
        self.mission = *mission;
        self.omega = omega;
        self.theta = Frequency::from_rad_per_s(omega_f64);
        self.half = mission.path.half_frequency(omega_f64);
        self.rate = rate_f64 as f32;
        self.position_rate = mission.path.position_rate(rate_f64);
        self.psi = match mission.path.heading_series() {
            Some(series) => series_coefficients(series, omega),
            None => [[0.0; 3]; ODD_TERMS],
        };
        self.accel_bound = 0.0;
        // Assumption 1 (Eq 19): per component Σ |amplitude|·frequency² over its harmonics
        // (|sin|, |cos| ≤ 1), then the Euclidean norm over the components. Linear-in-t terms
        // (lawn-mower 0.25 s t, helix z) and the circle's ψ = ωt have no acceleration.
        if let TrajectoryKind::Waypoints { .. } = mission.path {
            if self.law.is_set() {
                // The time law's σ̇ is over k: its derivatives are evaluated per unit time.
                self.rate = (1.0 / k) as f32;
                self.position_rate = LinearRate::new(1.0 / k);
            }
            let (min_speed, accel) = paths::time_law::speed_and_accel_bound(
                &self.route,
                &self.law,
                self.rate,
                heading::TANGENT_BOUND_MARGIN,
            );
            self.min_speed = min_speed;
            self.accel_bound = sqrt_upper(accel);
            return;
        }
        self.min_speed = mission.path.min_speed(self);
        let heading_bound = match mission.heading {
            HeadingMode::Paper => {
                let mut series_bound = 0.0f32;
                for c in &self.psi {
                    series_bound += libm::fabsf(c[2]);
                }
                series_bound
            }
            HeadingMode::Tangent => self.tangent_accel_bound(),
        };
        let (x, y) = mission.path.accel(omega);
        self.accel_bound = sqrt_upper(x * x + y * y + heading_bound * heading_bound);
    }

    /// Circle of radius `radius` with the paper's ω = 0.1 rad/s and depth 5 m.
    pub fn circle(radius: f32) -> Result<Self, TrajectoryError> {
        Self::new(circle_kind(radius))
    }

    /// Figure-eight of amplitude `amplitude` (a 2A × 2A square) with the paper's ω = 0.1 rad/s
    /// and depth 5 m.
    pub fn figure_eight(amplitude: f32) -> Result<Self, TrajectoryError> {
        Self::new(figure_eight_kind(amplitude))
    }

    /// Lawn-mower of scale `scale` with the paper's ω = 0.05 rad/s and depth 5 m.
    pub fn lawn_mower(scale: f32) -> Result<Self, TrajectoryError> {
        Self::new(lawn_mower_kind(scale))
    }

    /// Helix: circle of radius `radius`, ω = 0.1 rad/s, starting at depth 5 m and descending at
    /// `depth_rate` m/s (negative rises).
    pub fn helix(radius: f32, depth_rate: f32) -> Result<Self, TrajectoryError> {
        Self::new(TrajectoryKind::Helix(Helix {
            radius,
            omega: Self::PAPER_OMEGA,
            depth: Self::PAPER_DEPTH,
            depth_rate,
        }))
    }

    /// One of the paper's Table-1 missions (always valid, so no `Result`).
    pub fn table1(case: Table1Case) -> Self {
        let mut t = Self::EMPTY;
        t.precompute(&Mission::paper(case.kind()));
        t
    }

    /// The mission's path: its shape and parameters.
    pub fn kind(&self) -> TrajectoryKind {
        self.mission.path
    }

    /// The mission: path, heading and time scale.
    pub fn mission(&self) -> Mission {
        self.mission
    }

    /// The smallest horizontal speed along the path at its time scale (m/s), in closed form.
    pub fn min_speed(&self) -> f32 {
        self.min_speed
    }

    /// The waypoint path's legs and blends ([`Route::EMPTY`] for the other kinds).
    pub fn route(&self) -> &Route {
        &self.route
    }

    /// The waypoint path's time law ([`TimeLaw::EMPTY`]: constant speed, or another kind).
    pub fn time_law(&self) -> &TimeLaw {
        &self.law
    }

    /// K_d of Assumption 1 (Eq 19): an upper bound on ‖η̈_d(t)‖ for all t.
    ///
    /// Computed from the amplitudes: for each component of η̈_d the sum of |amplitude|·(frequency)²
    /// over its harmonics, then the Euclidean norm over the components. For the circle this is
    /// √2·Rω² (the true maximum is Rω²); for the paper's figure-eight it is within 1 % of the true
    /// maximum (all the bounds are reached together at ωt = π/2). The tangent heading's term is
    /// the sampled bound of docs/missions.md#heading. All frequencies are over the time scale k, so
    /// K_d falls as 1/k². The square root is the backend's followed by one Newton step, which
    /// can only round up (AM–GM), so the bound holds with micromath's ≈ 6 % `sqrt` too.
    pub fn accel_bound(&self) -> f32 {
        self.accel_bound
    }

    /// η_d, η̇_d, η̈_d at t = `ticks` / `rate_hz` seconds since mission start.
    ///
    /// Phases come from the tick count in integer arithmetic (see the module doc), so the
    /// result at 100 h is as accurate as at 1 s. `rate_hz == 0` has no meaningful time: it returns the
    /// t = 0 sample. Never panics; every component is finite for every `ticks` and `rate_hz`
    /// (for absurd t the lawn-mower x_d and helix z_d are huge but finite).
    pub fn sample(&self, ticks: u64, rate_hz: u32) -> Desired {
        let (ticks, rate_hz) = if rate_hz == 0 {
            (0, 1)
        } else {
            (ticks, rate_hz)
        };
        let time = MissionTime::new(ticks, rate_hz);
        let theta = self.theta.phase(&time);
        let ph = Phases {
            half: self.half.phase(&time),
            h: Harmonics::of(theta),
            time,
        };
        let p = paths::planar(self, &ph);
        let (psi, rate, accel) = match self.mission.heading {
            HeadingMode::Tangent => tangent(&p),
            HeadingMode::Paper => paths::paper_heading(self, theta, &ph.h, &p),
        };
        // Each vector written once, in place (Choice 571: zeroed first, then filled, it was
        // written twice).
        Desired {
            eta: Vector6::new(p.x, p.y, p.z, 0.0, 0.0, psi),
            eta_dot: Vector6::new(p.d[0][0], p.d[0][1], p.z_dot, 0.0, 0.0, rate),
            eta_ddot: Vector6::new(p.d[1][0], p.d[1][1], p.z_ddot, 0.0, 0.0, accel),
        }
    }
}

/// √s rounded up: the correctly rounded root (every backend: this is configuration time), one
/// Newton step (never below √s, by AM–GM) and a few ulps of margin for the final rounding.
fn sqrt_upper(s: f32) -> f32 {
    let y = math::exact_sqrt(s);
    if y > 0.0 && y.is_finite() {
        0.5 * (y + s / y) * (1.0 + 4.0 * f32::EPSILON)
    } else {
        y
    }
}
