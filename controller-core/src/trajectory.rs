//! Reference trajectories of the paper's missions: η_d(t), η̇_d(t), η̈_d(t).
//!
//! This module owns the desired state fed to the control law (ū = η̈_d − K₁e₁ − K₂e₂, Eq 17, with
//! e₁ = η − η_d and e₂ = η̇ − η̇_d, Eqs 12–13) and the bound K_d ≥ ‖η̈_d(t)‖ of Assumption 1
//! (Eq 19) that enters δ (Eq 29). The missions are the paper's "Simulation Results" section, as
//! cleaned up in docs/design.md §6; all have φ_d = θ_d = 0 (and zero roll/pitch rates):
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
//! **Choices** (docs/design.md §6):
//! * The circle's printed "x_d = 10 sin(0.1)t" is read as R sin(0.1t) (a misplaced parenthesis:
//!   y_d = 10 cos(0.1t) beside it and the circular plot fix it).
//! * Both heading series use the prefactor 8/π (it makes the triangle and the trapezoid reach
//!   ±π, matching the paper's Fig. 5) and are truncated at N = [`Trajectory::SERIES_TERMS`] = 9.
//!   Every even-n term is identically zero in both series (for the lawn-mower,
//!   sin(3nπ/4) = −(−1)ⁿ sin(nπ/4), so sin(nπ/4) + sin(3nπ/4) = 2 sin(nπ/4) for odd n and 0 for
//!   even n), so only n = 1, 3, 5, 7, 9 are evaluated.
//! * All derivatives are analytic (term-by-term derivatives of the truncated series).
//!
//! **Time and precision** (docs/design.md §8): time is the integer tick count; no f32 `t` is ever
//! formed, and no f64 arithmetic runs per sample (docs/design.md §16). The tick count is split
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
//! they grow (≈ 8 mm at 90 km); see §8 "Position".
//!
//! **Heading** ψ_d is returned wrapped to (−π, π]. For the circle and helix ψ_d = ωt grows
//! without bound and wraps once per revolution. The truncated lawn-mower series overshoots π
//! on its plateau (its maximum is ≈ 3.198 rad), so there too ψ_d jumps by 2π while the
//! heading itself is continuous; ψ̇_d and ψ̈_d are continuous everywhere. Consumers compare
//! headings modulo 2π (docs/design.md §4 wraps the yaw error).
//!
//! Every [`Trajectory::sample`] does a fixed amount of work (a `match` on the kind and, for the
//! series, a loop over a constant five harmonics), never allocates and never panics.

use core::f32::consts::{FRAC_1_SQRT_2, PI};
use core::fmt;

use nalgebra::Vector6;

use crate::math;
use crate::phase::{Frequency, LinearRate, MissionTime};
use crate::readable::Readable;

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

/// Shape and parameters of a mission (the paper's "Simulation Results"; docs/design.md §6).
///
/// All frequencies ω are in rad/s and must be positive; sizes in metres; z is positive down (NED).
///
/// With the `serde` feature it is a table tagged by `kind` (`"circle"`, `"figure-eight"`,
/// `"lawn-mower"`, `"helix"`) with the fields by name; unknown fields are refused, and `omega`
/// and `depth` default to the paper's values ([`Trajectory::PAPER_OMEGA`], for the lawn-mower
/// [`Trajectory::PAPER_LAWN_MOWER_OMEGA`]; [`Trajectory::PAPER_DEPTH`]). This is the
/// `[trajectory]` table of host-sim's scenario files. Values are not validated there: build the
/// mission with [`Trajectory::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)
)]
pub enum TrajectoryKind {
    /// x = R sin ωt, y = R cos ωt, z = depth, ψ = ωt (paper: ω = 0.1; "10 sin(0.1)t" read as
    /// R sin 0.1t).
    Circle {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// x = A sin ωt, y = A cos(ωt/2), z = depth,
    /// ψ = (8/π) Σ_{n odd ≤ N} (−1)^((n−1)/2) sin(nωt)/n² (a triangle wave of amplitude π;
    /// paper: ω = 0.1, A = 15 or 20 for the 30×30 and 40×40 cases).
    FigureEight {
        /// A (m): x and y each span 2A.
        amplitude: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// x = s(0.25 t + 2.5 sin 2ωt), y = 15 s cos ωt, z = depth,
    /// ψ = (8/π) Σ_{n ≤ N} [sin(nπ/4) + sin(3nπ/4)] sin(nωt)/n² (a trapezoid of amplitude π;
    /// paper: ω = 0.05, so 2ω = 0.1; s = 1 is the paper's 30×15 case).
    LawnMower {
        /// s (dimensionless): loop height 30 s m, loop width ≈ 15.7 s m.
        scale: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_lawn_mower_omega"))]
        omega: f32,
        /// z_d (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
    },
    /// A circle whose depth changes linearly: z = depth + depth_rate·t (not in the paper).
    Helix {
        /// R (m).
        radius: f32,
        /// ω (rad/s).
        #[cfg_attr(feature = "serde", serde(default = "default_omega"))]
        omega: f32,
        /// z_d at t = 0 (m, positive down).
        #[cfg_attr(feature = "serde", serde(default = "default_depth"))]
        depth: f32,
        /// ż_d (m/s, positive = descending).
        depth_rate: f32,
    },
}

// The serde defaults of `TrajectoryKind` (the paper's values).
#[cfg(feature = "serde")]
fn default_omega() -> f32 {
    Trajectory::PAPER_OMEGA
}
#[cfg(feature = "serde")]
fn default_lawn_mower_omega() -> f32 {
    Trajectory::PAPER_LAWN_MOWER_OMEGA
}
#[cfg(feature = "serde")]
fn default_depth() -> f32 {
    Trajectory::PAPER_DEPTH
}

/// Why a [`TrajectoryKind`] was rejected by [`Trajectory::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrajectoryError {
    /// The parameter is NaN or infinite.
    NonFinite {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
    },
    /// A size or frequency that must be strictly positive is zero or negative.
    NotPositive {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
        /// The rejected value.
        value: f32,
    },
    /// The parameter lies outside [min, max] (for a positive parameter `min` is 0 and exclusive;
    /// values at or below it are reported as [`TrajectoryError::NotPositive`]).
    OutOfRange {
        /// Field name in [`TrajectoryKind`].
        parameter: &'static str,
        /// The rejected value.
        value: f32,
        /// Lower limit.
        min: f32,
        /// Upper limit.
        max: f32,
    },
    /// A tangent-heading mission whose horizontal speed falls below
    /// [`Trajectory::MIN_TANGENT_SPEED`] somewhere (the course is undefined at zero speed).
    TooSlowForTangent {
        /// The path's minimum horizontal speed at its time scale (m/s).
        min_speed: f32,
        /// [`Trajectory::MIN_TANGENT_SPEED`].
        threshold: f32,
    },
}

impl TrajectoryError {
    /// The rejected field of [`TrajectoryKind`] or [`Mission`], e.g. `"radius"` (a scenario's
    /// `trajectory.radius`), `"time_scale"` or `"heading"`.
    pub fn parameter(&self) -> &'static str {
        match *self {
            Self::NonFinite { parameter }
            | Self::NotPositive { parameter, .. }
            | Self::OutOfRange { parameter, .. } => parameter,
            Self::TooSlowForTangent { .. } => "heading",
        }
    }
}

impl fmt::Display for TrajectoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite { parameter } => write!(f, "trajectory {parameter} is not finite"),
            Self::NotPositive { parameter, value } => {
                write!(f, "trajectory {parameter} = {} must be > 0", Readable(value))
            }
            Self::OutOfRange {
                parameter,
                value,
                min,
                max,
            } => write!(
                f,
                "trajectory {parameter} = {} is outside [{}, {}]",
                Readable(value),
                Readable(min),
                Readable(max)
            ),
            Self::TooSlowForTangent {
                min_speed,
                threshold,
            } => write!(
                f,
                "tangent heading needs a horizontal speed of at least {threshold} m/s everywhere; this path slows to {min_speed} m/s (lower the time scale, or fly the paper's heading)"
            ),
        }
    }
}

/// The six missions of the paper's Table 1 (docs/design.md §6–7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Table1Case {
    /// Circle, R = 10 m.
    Circular10R,
    /// Circle, R = 20 m.
    Circular20R,
    /// Figure-eight in a 30 m × 30 m square, A = 15 m.
    FigureEight30x30,
    /// Figure-eight in a 40 m × 40 m square, A = 20 m.
    FigureEight40x40,
    /// Lawn-mower, loop 20 m high × ≈10 m wide, s = 2/3.
    LawnMower20x10,
    /// Lawn-mower, loop 30 m high × ≈15 m wide, s = 1 (the paper's printed equations).
    LawnMower30x15,
}

impl Table1Case {
    /// All six cases, in the order of the paper's Table 1.
    pub const ALL: [Self; 6] = [
        Self::Circular10R,
        Self::Circular20R,
        Self::FigureEight30x30,
        Self::FigureEight40x40,
        Self::LawnMower20x10,
        Self::LawnMower30x15,
    ];

    /// Stable name for logs and command lines, e.g. `"figure-eight-30x30"`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Circular10R => "circular-10R",
            Self::Circular20R => "circular-20R",
            Self::FigureEight30x30 => "figure-eight-30x30",
            Self::FigureEight40x40 => "figure-eight-40x40",
            Self::LawnMower20x10 => "lawn-mower-20x10",
            Self::LawnMower30x15 => "lawn-mower-30x15",
        }
    }

    /// The case whose [`name`](Self::name) is `name` (exact match).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The mission: paper frequencies (ω = 0.1, lawn-mower ω = 0.05) and depth 5 m, with the
    /// Table-1 sizes R = 10, 20; A = 15, 20; s = 2/3, 1.
    pub const fn kind(self) -> TrajectoryKind {
        match self {
            Self::Circular10R => circle_kind(10.0),
            Self::Circular20R => circle_kind(20.0),
            Self::FigureEight30x30 => figure_eight_kind(15.0),
            Self::FigureEight40x40 => figure_eight_kind(20.0),
            Self::LawnMower20x10 => lawn_mower_kind(2.0 / 3.0),
            Self::LawnMower30x15 => lawn_mower_kind(1.0),
        }
    }
}

const fn circle_kind(radius: f32) -> TrajectoryKind {
    TrajectoryKind::Circle {
        radius,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    }
}

const fn figure_eight_kind(amplitude: f32) -> TrajectoryKind {
    TrajectoryKind::FigureEight {
        amplitude,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    }
}

const fn lawn_mower_kind(scale: f32) -> TrajectoryKind {
    TrajectoryKind::LawnMower {
        scale,
        omega: Trajectory::PAPER_LAWN_MOWER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    }
}

/// Number of odd harmonics n = 1, 3, …, N evaluated by the heading series.
const ODD_TERMS: usize = (Trajectory::SERIES_TERMS as usize).div_ceil(2);

/// Heading-series shape: ψ = (8/π) Σ_{n odd ≤ N} sign_n sin(nθ)/n² · `gain`.
#[derive(Clone, Copy)]
enum Series {
    /// Figure-eight: sign_n = (−1)^((n−1)/2), gain 1.
    Triangle,
    /// Lawn-mower: sin(nπ/4) + sin(3nπ/4) = 2 sin(nπ/4) = √2·sign_n for odd n, with
    /// sign_n = +1 for n ≡ 1, 3 (mod 8) and −1 for n ≡ 5, 7 (mod 8); gain √2.
    Trapezoid,
}

/// Per-harmonic coefficients of ψ_d, ψ̇_d, ψ̈_d: for harmonic n (odd),
/// ψ = Σ a_n sin(nθ), ψ̇ = Σ a_n nω cos(nθ), ψ̈ = −Σ a_n n²ω² sin(nθ).
const fn series_coefficients(series: Series, omega: f32) -> [[f32; 3]; ODD_TERMS] {
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

/// How a mission's desired heading ψ_d is formed (docs/design.md §6, §9).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum HeadingMode {
    /// The paper's headings: ψ_d = ωt on the circle and the helix, the triangle and trapezoid
    /// series on the figure-eight and the lawn-mower. They make a torpedo vehicle crab.
    #[default]
    Paper,
    /// ψ_d follows the path's course χ_d = atan2(ẏ_d, ẋ_d), with ψ̇_d and ψ̈_d from the
    /// path's curvature (docs/design.md §9): ψ̇_d = N/D, ψ̈_d = (Ṅ − ψ̇_d Ḋ)/D with
    /// N = ẋ_d ÿ_d − ẏ_d ẍ_d, D = ẋ_d² + ẏ_d², Ṅ = ẋ_d y⃛_d − ẏ_d x⃛_d,
    /// Ḋ = 2(ẋ_d ẍ_d + ẏ_d ÿ_d). Defined where the horizontal speed √D is not zero:
    /// [`Trajectory::new`] refuses a tangent mission whose minimum speed is below
    /// [`Trajectory::MIN_TANGENT_SPEED`].
    Tangent,
}

impl HeadingMode {
    /// Both modes, the paper's first.
    pub const ALL: [HeadingMode; 2] = [HeadingMode::Paper, HeadingMode::Tangent];

    /// `"paper"` or `"tangent"`: the scenario files' `trajectory.heading`.
    pub const fn as_str(self) -> &'static str {
        match self {
            HeadingMode::Paper => "paper",
            HeadingMode::Tangent => "tangent",
        }
    }

    /// The mode whose [`as_str`](Self::as_str) is `name`.
    pub fn from_name(name: &str) -> Option<HeadingMode> {
        Self::ALL.into_iter().find(|m| m.as_str() == name)
    }
}

impl fmt::Display for HeadingMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A mission as the board flies it: a path ([`TrajectoryKind`]), how its heading is formed
/// ([`HeadingMode`]) and how slowly it is flown (`time_scale` k ≥ 1: the desired state is
/// η_d(t/k), so velocities are divided by k and accelerations by k²). Validated by
/// [`Trajectory::new`]; crosses the link in `StartMission`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mission {
    /// The path's shape and parameters.
    pub path: TrajectoryKind,
    /// ψ_d: the paper's or the path's course.
    pub heading: HeadingMode,
    /// k ≥ 1 (1: the paper's speed).
    pub time_scale: f32,
}

impl Mission {
    /// `path` as the paper flies it: its own heading, k = 1.
    pub const fn paper(path: TrajectoryKind) -> Mission {
        Mission {
            path,
            heading: HeadingMode::Paper,
            time_scale: 1.0,
        }
    }
}

impl From<TrajectoryKind> for Mission {
    /// [`Mission::paper`].
    fn from(path: TrajectoryKind) -> Mission {
        Mission::paper(path)
    }
}

/// A validated mission with its precomputed constants; sample it with [`Trajectory::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trajectory {
    mission: Mission,
    /// ω/k (rad/s), for the amplitudes.
    omega: f32,
    /// ω/k as a turn rate, for θ (docs/design.md §16).
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
}

/// The phases a sample needs, in 2⁻³² turns: θ = (ω/k)·t and, for the figure-eight, the half
/// phase; the first two harmonics of θ; the mission time for the terms linear in time.
#[derive(Clone, Copy)]
struct Phases {
    half: u32,
    h: Harmonics,
    time: MissionTime,
}

/// (sin θ, cos θ) from one exact-phase `sin_cos_turns`, and (sin 2θ, cos 2θ) from them by the
/// double-angle formulas: what the paths (x_d, y_d) and the heading series share.
#[derive(Clone, Copy)]
struct Harmonics {
    s1: f32,
    c1: f32,
    s2: f32,
    c2: f32,
}

impl Harmonics {
    #[inline]
    fn of(theta: u32) -> Harmonics {
        let (s1, c1) = math::sin_cos_turns(theta);
        Harmonics {
            s1,
            c1,
            s2: 2.0 * s1 * c1,
            c2: (c1 - s1) * (c1 + s1),
        }
    }
}

/// The horizontal path and its first three derivatives, and z_d, ż_d.
#[derive(Clone, Copy)]
struct Planar {
    x: f32,
    y: f32,
    z: f32,
    z_dot: f32,
    /// (ẋ, ẏ), (ẍ, ÿ), (x⃛, y⃛).
    d: [[f32; 2]; 3],
}

/// Samples per period of the path in the sampled bound on the tangent heading's |ψ̈_d|.
const TANGENT_BOUND_SAMPLES: u32 = 1024;
/// Margin on the sampled maximum of the tangent heading's |ψ̈_d| (docs/design.md §6 **Choice**).
const TANGENT_BOUND_MARGIN: f32 = 1.1;

impl Trajectory {
    /// N, the last harmonic of the heading series (docs/design.md §6 **Choice**: truncate at N = 9).
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
    /// path (docs/design.md §6 **Choice**): the course atan2(ẏ_d, ẋ_d) is undefined at zero
    /// speed and its derivatives grow as 1/speed², so [`Trajectory::new`] refuses a tangent
    /// mission whose closed-form minimum speed is lower, instead of holding a heading (which
    /// would need state in a stateless `update`). The shipped paths never stop.
    pub const MIN_TANGENT_SPEED: f32 = 0.02;

    /// Validates `mission` and precomputes the series coefficients, K_d and the minimum speed.
    /// A [`TrajectoryKind`] is the paper's mission ([`Mission::paper`]).
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
        let mission = mission.into();
        match mission.path {
            TrajectoryKind::Circle {
                radius,
                omega,
                depth,
            } => {
                positive("radius", radius, Self::MAX_SIZE)?;
                positive("omega", omega, Self::MAX_OMEGA)?;
                symmetric("depth", depth, Self::MAX_DEPTH)?;
            }
            TrajectoryKind::FigureEight {
                amplitude,
                omega,
                depth,
            } => {
                positive("amplitude", amplitude, Self::MAX_SIZE)?;
                positive("omega", omega, Self::MAX_OMEGA)?;
                symmetric("depth", depth, Self::MAX_DEPTH)?;
            }
            TrajectoryKind::LawnMower {
                scale,
                omega,
                depth,
            } => {
                positive("scale", scale, Self::MAX_SIZE / 15.0)?;
                positive("omega", omega, Self::MAX_OMEGA)?;
                symmetric("depth", depth, Self::MAX_DEPTH)?;
            }
            TrajectoryKind::Helix {
                radius,
                omega,
                depth,
                depth_rate,
            } => {
                positive("radius", radius, Self::MAX_SIZE)?;
                positive("omega", omega, Self::MAX_OMEGA)?;
                symmetric("depth", depth, Self::MAX_DEPTH)?;
                symmetric("depth_rate", depth_rate, Self::MAX_DEPTH_RATE)?;
            }
        }
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
        let t = Self::build(mission);
        if mission.heading == HeadingMode::Tangent
            && (t.min_speed.is_nan() || t.min_speed < Self::MIN_TANGENT_SPEED)
        {
            return Err(TrajectoryError::TooSlowForTangent {
                min_speed: t.min_speed,
                threshold: Self::MIN_TANGENT_SPEED,
            });
        }
        Ok(t)
    }

    /// Precomputes the constants of an already validated mission.
    fn build(mission: Mission) -> Self {
        let k = mission.time_scale as f64;
        let (omega, rate) = match mission.path {
            TrajectoryKind::Circle { omega, .. } | TrajectoryKind::FigureEight { omega, .. } => {
                (omega, 0.0)
            }
            TrajectoryKind::LawnMower { omega, .. } => (omega, LAWN_MOWER_ADVANCE),
            TrajectoryKind::Helix {
                omega, depth_rate, ..
            } => (omega, depth_rate),
        };
        // η_d(t/k): every frequency and every linear rate over k (exact for k = 1).
        let omega_f64 = omega as f64 / k;
        let rate_f64 = rate as f64 / k;
        let omega = omega_f64 as f32;
        let position_rate = match mission.path {
            TrajectoryKind::LawnMower { scale, .. } => LinearRate::new(rate_f64 * scale as f64),
            _ => LinearRate::new(rate_f64),
        };
        let half = match mission.path {
            TrajectoryKind::FigureEight { .. } => Frequency::from_rad_per_s(0.5 * omega_f64),
            _ => Frequency::default(),
        };
        let psi = match mission.path {
            TrajectoryKind::FigureEight { .. } => series_coefficients(Series::Triangle, omega),
            TrajectoryKind::LawnMower { .. } => series_coefficients(Series::Trapezoid, omega),
            TrajectoryKind::Circle { .. } | TrajectoryKind::Helix { .. } => [[0.0; 3]; ODD_TERMS],
        };
        let mut t = Self {
            mission,
            omega,
            theta: Frequency::from_rad_per_s(omega_f64),
            half,
            rate: rate_f64 as f32,
            position_rate,
            psi,
            accel_bound: 0.0,
            min_speed: 0.0,
        };
        t.min_speed = t.min_horizontal_speed();
        // Assumption 1 (Eq 19): per component Σ |amplitude|·frequency² over its harmonics
        // (|sin|, |cos| ≤ 1), then the Euclidean norm over the components. Linear-in-t terms
        // (lawn-mower 0.25 s t, helix z) and the circle's ψ = ωt have no acceleration.
        let heading_bound = match mission.heading {
            HeadingMode::Paper => {
                let mut series_bound = 0.0f32;
                for c in &psi {
                    series_bound += libm::fabsf(c[2]);
                }
                series_bound
            }
            HeadingMode::Tangent => t.tangent_accel_bound(),
        };
        let (x, y) = match mission.path {
            TrajectoryKind::Circle { radius, .. } | TrajectoryKind::Helix { radius, .. } => {
                (radius * omega * omega, radius * omega * omega)
            }
            TrajectoryKind::FigureEight { amplitude, .. } => {
                let half = 0.5 * omega;
                (amplitude * omega * omega, amplitude * half * half)
            }
            TrajectoryKind::LawnMower { scale, .. } => {
                let two = 2.0 * omega;
                (2.5 * scale * two * two, 15.0 * scale * omega * omega)
            }
        };
        t.accel_bound = sqrt_upper(x * x + y * y + heading_bound * heading_bound);
        t
    }

    /// The smallest horizontal speed √(ẋ_d² + ẏ_d²) over the path, in closed form (m/s):
    ///
    /// * circle, helix: Rω/k, constant;
    /// * figure-eight: ẋ = Aω cos θ, ẏ = −(Aω/2) sin(θ/2), so with s = sin²(θ/2) the speed² is
    ///   A²ω²[(1 − 2s)² + s/4], least at s = 15/32: Aω√31/16 ≈ 0.348 Aω;
    /// * lawn-mower: ẋ = s(a − b u), ẏ² = s² c u with u = sin²θ ∈ [0, 1], a = 0.25/k + 5ω,
    ///   b = 10ω, c = 225ω² (ω already over k): a convex quadratic in u, least at
    ///   u* = (2ab − c)/(2b²) clamped to [0, 1].
    fn min_horizontal_speed(&self) -> f32 {
        let w = self.omega;
        match self.mission.path {
            TrajectoryKind::Circle { radius, .. } | TrajectoryKind::Helix { radius, .. } => {
                radius * w
            }
            TrajectoryKind::FigureEight { amplitude, .. } => {
                amplitude * w * math::exact_sqrt(31.0) / 16.0
            }
            TrajectoryKind::LawnMower { scale, .. } => {
                let a = self.rate + 5.0 * w;
                let b = 10.0 * w;
                let c = 225.0 * w * w;
                let u = ((2.0 * a * b - c) / (2.0 * b * b)).clamp(0.0, 1.0);
                let f = (a - b * u) * (a - b * u) + c * u;
                scale * math::exact_sqrt(f)
            }
        }
    }

    /// An upper bound on the tangent heading's |ψ̈_d| (docs/design.md §6 **Choice**). On the
    /// circle and the helix ψ̈_d = 0 exactly (the course turns at the constant −ω/k). On the
    /// figure-eight and the lawn-mower ψ̈_d is periodic in the path's phase: its maximum over
    /// [`TANGENT_BOUND_SAMPLES`] phases of one period, times [`TANGENT_BOUND_MARGIN`] for
    /// the peak between samples. Fixed work, at configuration time only; the tests check the
    /// bound against whole missions sampled at the control rate.
    fn tangent_accel_bound(&self) -> f32 {
        let periodic = matches!(
            self.mission.path,
            TrajectoryKind::FigureEight { .. } | TrajectoryKind::LawnMower { .. }
        );
        if !periodic {
            return 0.0;
        }
        let mut max = 0.0f32;
        for j in 0..TANGENT_BOUND_SAMPLES {
            // One period: the figure-eight's y has the half phase (period 4π in θ), the
            // lawn-mower's derivatives have period 2π in θ.
            let a = j.wrapping_mul(u32::MAX / TANGENT_BOUND_SAMPLES + 1);
            let time = MissionTime::new(0, 1);
            let ph = match self.mission.path {
                TrajectoryKind::FigureEight { .. } => Phases {
                    half: a,
                    h: Harmonics::of(a.wrapping_mul(2)),
                    time,
                },
                _ => Phases {
                    half: 0,
                    h: Harmonics::of(a),
                    time,
                },
            };
            let (_, _, accel) = tangent(&self.planar(&ph));
            let accel = libm::fabsf(accel);
            if accel > max {
                max = accel;
            }
        }
        max * TANGENT_BOUND_MARGIN
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
        Self::new(TrajectoryKind::Helix {
            radius,
            omega: Self::PAPER_OMEGA,
            depth: Self::PAPER_DEPTH,
            depth_rate,
        })
    }

    /// One of the paper's Table-1 missions (always valid, so no `Result`).
    pub fn table1(case: Table1Case) -> Self {
        Self::build(Mission::paper(case.kind()))
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

    /// K_d of Assumption 1 (Eq 19): an upper bound on ‖η̈_d(t)‖ for all t.
    ///
    /// Computed from the amplitudes: for each component of η̈_d the sum of |amplitude|·(frequency)²
    /// over its harmonics, then the Euclidean norm over the components. For the circle this is
    /// √2·Rω² (the true maximum is Rω²); for the paper's figure-eight it is within 1 % of the true
    /// maximum (all the bounds are reached together at ωt = π/2). The tangent heading's term is
    /// the sampled bound of docs/design.md §6. All frequencies are over the time scale k, so
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
        let p = self.planar(&ph);
        let mut eta = Vector6::<f32>::zeros();
        let mut eta_dot = Vector6::<f32>::zeros();
        let mut eta_ddot = Vector6::<f32>::zeros();
        eta[0] = p.x;
        eta[1] = p.y;
        eta[2] = p.z;
        eta_dot[0] = p.d[0][0];
        eta_dot[1] = p.d[0][1];
        eta_dot[2] = p.z_dot;
        eta_ddot[0] = p.d[1][0];
        eta_ddot[1] = p.d[1][1];
        let (psi, rate, accel) = match (self.mission.heading, self.mission.path) {
            (HeadingMode::Tangent, _) => tangent(&p),
            (HeadingMode::Paper, TrajectoryKind::Circle { .. } | TrajectoryKind::Helix { .. }) => {
                (math::turns_to_radians(theta), self.omega, 0.0)
            }
            (HeadingMode::Paper, _) => self.heading_series(&ph.h),
        };
        eta[5] = psi;
        eta_dot[5] = rate;
        eta_ddot[5] = accel;
        Desired {
            eta,
            eta_dot,
            eta_ddot,
        }
    }

    /// The path at the given phases: x_d, y_d and three derivatives each, z_d and ż_d
    /// (analytic; every frequency and rate is already over the time scale).
    fn planar(&self, ph: &Phases) -> Planar {
        let omega = self.omega;
        match self.mission.path {
            TrajectoryKind::Circle { radius, depth, .. } => {
                let mut p = circle(radius, omega, &ph.h);
                p.z = depth;
                p
            }
            TrajectoryKind::Helix { radius, depth, .. } => {
                let mut p = circle(radius, omega, &ph.h);
                p.z = ph.time.linear(&self.position_rate, depth);
                p.z_dot = self.rate;
                p
            }
            TrajectoryKind::FigureEight {
                amplitude, depth, ..
            } => {
                let half = 0.5 * omega;
                let (s1, c1) = (ph.h.s1, ph.h.c1);
                let (sh, ch) = math::sin_cos_turns(ph.half);
                Planar {
                    x: amplitude * s1,
                    y: amplitude * ch,
                    z: depth,
                    z_dot: 0.0,
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
            TrajectoryKind::LawnMower { scale, depth, .. } => {
                let Harmonics { s1, c1, s2, c2 } = ph.h;
                let two = 2.0 * omega;
                let wave = 2.5 * scale * s2;
                let amp_y = 15.0 * scale;
                Planar {
                    x: ph.time.linear(&self.position_rate, wave),
                    y: amp_y * c1,
                    z: depth,
                    z_dot: 0.0,
                    d: [
                        [scale * (self.rate + 2.5 * two * c2), -amp_y * omega * s1],
                        [-2.5 * scale * two * two * s2, -amp_y * omega * omega * c1],
                        [
                            -2.5 * scale * two * two * two * c2,
                            amp_y * omega * omega * omega * s1,
                        ],
                    ],
                }
            }
        }
    }

    /// ψ_d, ψ̇_d, ψ̈_d from the precomputed odd-harmonic coefficients (fixed five terms).
    ///
    /// sin nθ and cos nθ for n = 3, 5, 7, 9 come from the angle-addition recurrence
    /// sin (n+2)θ = sin nθ cos 2θ + cos nθ sin 2θ, cos (n+2)θ = cos nθ cos 2θ − sin nθ sin 2θ,
    /// from the sample's [`Harmonics`] (one `sin_cos_turns` for the path and the series
    /// together, instead of one call per harmonic). Four steps of the recurrence add a few
    /// ulps (tests/trajectory.rs measures the series against f64).
    fn heading_series(&self, h: &Harmonics) -> (f32, f32, f32) {
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

/// The lawn-mower's advance, x_d = s(0.25 t + …): 0.25 m/s per unit scale.
const LAWN_MOWER_ADVANCE: f32 = 0.25;

/// The tangent heading of a path sample (see [`HeadingMode::Tangent`]): ψ_d = atan2(ẏ, ẋ),
/// ψ̇_d = N/D, ψ̈_d = (Ṅ − ψ̇_d Ḋ)/D. One `atan2` and one division.
#[inline]
fn tangent(p: &Planar) -> (f32, f32, f32) {
    let [[xd, yd], [xdd, ydd], [xddd, yddd]] = p.d;
    let d = xd * xd + yd * yd;
    let inv_d = 1.0 / d;
    let n = xd * ydd - yd * xdd;
    let n_dot = xd * yddd - yd * xddd;
    let d_dot = 2.0 * (xd * xdd + yd * ydd);
    let rate = n * inv_d;
    let accel = (n_dot - rate * d_dot) * inv_d;
    (math::atan2(yd, xd), rate, accel)
}

/// Circle part shared by the circle and the helix: x, y and their derivatives (z left 0).
fn circle(radius: f32, omega: f32, h: &Harmonics) -> Planar {
    let (s, c) = (h.s1, h.c1);
    Planar {
        x: radius * s,
        y: radius * c,
        z: 0.0,
        z_dot: 0.0,
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

/// `value` finite and in (0, max].
fn positive(parameter: &'static str, value: f32, max: f32) -> Result<(), TrajectoryError> {
    if !value.is_finite() {
        Err(TrajectoryError::NonFinite { parameter })
    } else if value <= 0.0 {
        Err(TrajectoryError::NotPositive { parameter, value })
    } else if value > max {
        Err(TrajectoryError::OutOfRange {
            parameter,
            value,
            min: 0.0,
            max,
        })
    } else {
        Ok(())
    }
}

/// `value` finite and in [−max, max].
fn symmetric(parameter: &'static str, value: f32, max: f32) -> Result<(), TrajectoryError> {
    if !value.is_finite() {
        Err(TrajectoryError::NonFinite { parameter })
    } else if !(-max..=max).contains(&value) {
        Err(TrajectoryError::OutOfRange {
            parameter,
            value,
            min: -max,
            max,
        })
    } else {
        Ok(())
    }
}
