//! Preflight feasibility (docs/design.md §9 "Preflight"): before any simulation, can the real
//! thrusters fly this scenario's mission, and if not, why not and how slowly could they?
//!
//! For the mission's reference η_d, η̇_d, η̈_d (the path the scenario flies, sampled every
//! [`SAMPLE_PERIOD`] of the path's own time), the body force the vehicle needs is Eq (1) solved
//! for τ ([`Plant::required_force`]) with ν = J⁻¹η̇_d and ν̇ = J⁻¹(η̈_d − J̇ν), at **every corner
//! of the controller's parameter box** (Table 3 by default: 2⁹ plants, trimmed if the scenario
//! is) and under **the configured current** (constant: that velocity; Gauss–Markov: every
//! corner of mean ± [`GAUSS_MARKOV_SIGMAS`]·σ). Each τ goes through **the board's own
//! allocator** ([`controller_core::allocation::Allocator`], the scenario's geometry, unit and
//! axis priority) built on the envelope shrunk to the margin (default [`DEFAULT_MARGIN`] = 80 %
//! of [T_min, T_max]): the mission is feasible when every block of every τ is met, i.e. every
//! thruster's demand B₅⁻¹τ lies inside the margin envelope. The rest of the envelope is left to
//! the feedback (the tracking and robust terms of the law), which this check does not model.
//!
//! **Time scale.** With k the time scale, η̇_d scales as 1/k and η̈_d (and with it every
//! velocity-squared term: Coriolis, damping) as 1/k², so the check is run at any k from the
//! path sampled once at k = 1. At k = ∞ (`1/k = 0`) only g(η) and the current's drag remain:
//! a mission infeasible there is **statically infeasible** — payload weight or CG moment beyond
//! what the thrusters can hold at zero speed, which no time scale cures. Otherwise the smallest
//! feasible k in [1, [`Trajectory::MAX_TIME_SCALE`]] is found by doubling, then bisection to a
//! relative [`TIME_SCALE_TOLERANCE`], and rounded up to [`TIME_SCALE_STEP`]. Without current,
//! each thrust is A/k² + G with G (the static demand) inside the box, so feasibility is
//! monotone in k and the bisection is exact; with a current it is an approximation (the drag
//! of the current does not scale). The proposed scale flies the same path: the scenario's
//! duration D covers the path up to D/k_scenario, which at scale k takes D·k/k_scenario.
//!
//! **Choices** (docs/design.md §9): the box is the controller's `uncertainty` box (what the
//! law is certified for, not only the scenario's own variation profile, so one check covers
//! every payload in it); the margin is 80 %; the path is sampled at 20 Hz of its own time;
//! Gauss–Markov currents are taken at ±3σ.

use std::fmt;

use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};
use controller_core::kinematics::{self, Attitude};
use controller_core::model::VehicleParams;
use controller_core::readable::Readable;
use controller_core::thruster::ThrustEnvelope;
use controller_core::{allocation::Allocator, axes::NAMES as AXIS_NAMES};
use controller_core::{Mission, Trajectory};
use nalgebra::{Vector3, Vector6};
use serde::{Deserialize, Serialize};

use crate::interrupt;
use crate::plant::{self, CurrentModel, Plant, PlantState, PlantTerms};
use crate::scenario::Scenario;

/// Default fraction of each thruster's envelope the reference may use (the rest is left to
/// the feedback): 80 %.
pub const DEFAULT_MARGIN: f64 = 0.8;
/// Spacing of the check's samples along the path, in the path's own time (s, at k = 1).
pub const SAMPLE_PERIOD: f64 = 0.05;
/// The bisection stops when the feasible and the infeasible time scale differ by less than
/// this fraction.
pub const TIME_SCALE_TOLERANCE: f64 = 0.005;
/// The proposed time scale is rounded up to a multiple of this.
pub const TIME_SCALE_STEP: f64 = 0.01;
/// A Gauss–Markov current is checked at the corners of mean ± this many σ per axis.
pub const GAUSS_MARKOV_SIGMAS: f64 = 3.0;

/// Samples per second of path time ([`SAMPLE_PERIOD`]).
const SAMPLE_RATE_HZ: u32 = 20;
/// An unallocated part above this (relative to 1 + |τ|) means the axis was given up; below it
/// is the f32 rounding of an axis met on its bound.
const GIVEN_UP: f32 = 1.0e-4;

/// What one thruster is asked for over the mission (at the scenario's time scale).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThrusterDemand {
    /// The thruster's name ([`THRUSTER_NAMES`]).
    pub thruster: String,
    /// Its envelope [T_min, T_max] at the supply limit (N).
    pub envelope: [f64; 2],
    /// The smallest thrust the reference needs (N), and when (s).
    pub min: f64,
    pub t_min: f64,
    /// The largest thrust the reference needs (N), and when (s).
    pub max: f64,
    pub t_max: f64,
    /// The largest share of the envelope used on either side: max(max/T_max, min/T_min),
    /// feasible when ≤ the margin.
    pub usage: f64,
}

/// The first sample (in time) at which some corner's τ cannot be allocated inside the margin
/// envelope.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Violation {
    /// Time (s) at the time scale checked (for the static check: where on the path, at the
    /// scenario's time scale).
    pub t: f64,
    /// The thruster that exceeds its margin envelope the most (relative to its width).
    pub thruster: String,
    /// What it would need (N) and the margin envelope (N).
    pub demand: f64,
    pub limit: [f64; 2],
    /// The axes the allocator gives up, the lowest priority first.
    pub given_up: Vec<String>,
}

/// The verdict of [`Preflight`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The mission fits the margin envelope at its own time scale.
    Feasible,
    /// Not at its time scale, but at [`Preflight::smallest_time_scale`].
    NeedsTimeScale,
    /// Not even at rest: weight, CG moment or current beyond the thrusters.
    StaticallyInfeasible,
    /// Feasible at rest, but not at any time scale up to [`Trajectory::MAX_TIME_SCALE`].
    Infeasible,
}

impl Verdict {
    /// `feasible`, `needs-time-scale`, `statically-infeasible`, `infeasible`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::NeedsTimeScale => "needs-time-scale",
            Verdict::StaticallyInfeasible => "statically-infeasible",
            Verdict::Infeasible => "infeasible",
        }
    }
}

/// The preflight check of one scenario (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Preflight {
    /// The scenario's name.
    pub name: String,
    pub verdict: Verdict,
    /// The scenario's own time scale.
    pub time_scale: f64,
    /// The scenario's duration (s): it flies the path up to duration/time_scale of path time.
    pub duration: f64,
    /// The smallest feasible time scale in [1, 100] (rounded up to 0.01); `None` if there is
    /// none.
    pub smallest_time_scale: Option<f64>,
    /// The fraction of the envelope the reference may use.
    pub margin: f64,
    /// Thrust unit of Eqs 31–32, heading mode, trim: what was checked.
    pub thrust_unit: String,
    pub heading: String,
    pub trimmed: bool,
    /// Per thruster, at the scenario's time scale.
    pub thrusters: Vec<ThrusterDemand>,
    /// The first violation at the scenario's time scale.
    pub first_violation: Option<Violation>,
    /// The first violation at rest (k = ∞), if the mission is statically infeasible.
    pub static_violation: Option<Violation>,
}

impl Preflight {
    /// True when the mission is feasible at its own time scale.
    pub fn feasible(&self) -> bool {
        self.verdict == Verdict::Feasible
    }
}

fn fmt_violation(v: &Violation) -> String {
    format!(
        "{} needs {:.0} N, margin envelope [{:.0}, {:.0}] N ({} given up)",
        v.thruster,
        v.demand,
        v.limit[0],
        v.limit[1],
        v.given_up.join(", ")
    )
}

impl fmt::Display for Preflight {
    /// The one-line verdict, e.g. `preflight real-circular-10R: FEASIBLE at time scale 1
    /// (margin 80 %: peak 77 % of vert aft's envelope; smallest feasible time scale 1)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pct = 100.0 * self.margin;
        write!(f, "preflight {}: ", self.name)?;
        match self.verdict {
            Verdict::Feasible => {
                let peak = self
                    .thrusters
                    .iter()
                    .max_by(|a, b| a.usage.total_cmp(&b.usage));
                write!(f, "FEASIBLE at time scale {}", self.time_scale)?;
                if let Some(p) = peak {
                    write!(
                        f,
                        " (margin {pct:.0} %: peak {:.0} % of {}'s envelope",
                        100.0 * p.usage,
                        p.thruster
                    )?;
                }
                if let Some(k) = self.smallest_time_scale {
                    write!(f, "; smallest feasible time scale {k}")?;
                }
                f.write_str(")")
            }
            Verdict::StaticallyInfeasible => {
                write!(f, "STATICALLY INFEASIBLE (margin {pct:.0} %): at rest")?;
                if let Some(v) = &self.static_violation {
                    write!(f, ", at t = {:.2} s, {}", v.t, fmt_violation(v))?;
                }
                f.write_str("; no time scale helps")
            }
            Verdict::NeedsTimeScale | Verdict::Infeasible => {
                write!(
                    f,
                    "INFEASIBLE at time scale {} (margin {pct:.0} %)",
                    self.time_scale
                )?;
                if let Some(v) = &self.first_violation {
                    write!(f, ": first at t = {:.2} s, {}", v.t, fmt_violation(v))?;
                }
                match self.smallest_time_scale {
                    Some(k) => write!(f, "; feasible from time scale {k}"),
                    None => write!(
                        f,
                        "; not feasible at any time scale up to {}",
                        Trajectory::MAX_TIME_SCALE
                    ),
                }
            }
        }
    }
}

/// The reference at one sample of the path, at k = 1.
struct PathSample {
    /// Path time (s, at k = 1).
    s: f64,
    eta: Vector6<f64>,
    eta_dot: Vector6<f64>,
    eta_ddot: Vector6<f64>,
    jinv: nalgebra::Matrix6<f64>,
    att: Attitude<f64>,
}

/// One sweep over the samples at one 1/k.
struct Sweep {
    first: Option<Violation>,
    /// Per thruster (min, t_min, max, t_max).
    peaks: [(f64, f64, f64, f64); THRUSTERS],
}

/// Everything the check needs, built once per scenario.
struct Checker<'a> {
    scenario: &'a Scenario,
    samples: Vec<PathSample>,
    plants: Vec<Plant>,
    currents: Vec<Vector3<f64>>,
    margin_allocator: Allocator,
    margin_envelope: ThrustEnvelope,
}

/// Why [`check`] gave no verdict.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CheckError {
    /// The check cannot be made: a margin outside (0, 1], or a scenario whose allocator
    /// cannot be built on the margin envelope.
    Invalid(String),
    /// A stop was requested ([`crate::interrupt`]) before the check was done: a day-long
    /// mission is 1.7·10⁶ samples of the path at each of the 2⁹ corners, minutes of work, so
    /// the check polls the request at every sample (**Choice 120**).
    Interrupted,
}

impl fmt::Display for CheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckError::Invalid(e) => f.write_str(e),
            CheckError::Interrupted => f.write_str("interrupted before the check was done"),
        }
    }
}

impl std::error::Error for CheckError {}

/// Stops a long loop of the check when a stop was requested.
fn poll() -> Result<(), CheckError> {
    if interrupt::requested() {
        Err(CheckError::Interrupted)
    } else {
        Ok(())
    }
}

/// The preflight check of `scenario` at `margin` (a fraction of the envelope, in (0, 1]).
///
/// # Errors
/// [`CheckError::Invalid`]: a margin outside (0, 1], or a scenario whose allocator cannot be
/// built on the margin envelope; [`CheckError::Interrupted`]: a stop was requested.
pub fn check(scenario: &Scenario, margin: f64) -> Result<Preflight, CheckError> {
    if !(margin > 0.0 && margin <= 1.0) {
        return Err(CheckError::Invalid(format!(
            "the margin must be a fraction of the envelope in (0, 1], got {}",
            Readable(margin)
        )));
    }
    let checker = Checker::new(scenario, margin)?;
    let cfg = scenario.config();
    let k = time_scale(cfg.time_scale);
    let own = checker.sweep(1.0 / k, true)?;
    let at_rest = checker.sweep(0.0, false)?;
    let statically_infeasible = at_rest.first.is_some();
    let smallest = if statically_infeasible {
        None
    } else {
        checker.smallest_time_scale(own.first.is_none().then_some(k))?
    };
    let verdict = if own.first.is_none() {
        Verdict::Feasible
    } else if statically_infeasible {
        Verdict::StaticallyInfeasible
    } else if smallest.is_some() {
        Verdict::NeedsTimeScale
    } else {
        Verdict::Infeasible
    };
    let envelope = scenario.controller().envelope();
    let thrusters = (0..THRUSTERS)
        .map(|i| {
            let (min, t_min, max, t_max) = own.peaks[i];
            let (lo, hi) = (f64::from(envelope.min[i]), f64::from(envelope.max[i]));
            ThrusterDemand {
                thruster: THRUSTER_NAMES[i].to_string(),
                envelope: [lo, hi],
                min,
                t_min,
                max,
                t_max,
                usage: (max / hi).max(min / lo),
            }
        })
        .collect();
    Ok(Preflight {
        name: cfg.name.clone(),
        verdict,
        time_scale: k,
        duration: cfg.duration,
        smallest_time_scale: smallest,
        margin,
        thrust_unit: cfg.controller.thrust_unit.to_string(),
        heading: cfg.heading.to_string(),
        trimmed: cfg.trimmed,
        thrusters,
        first_violation: own.first,
        static_violation: at_rest.first,
    })
}

/// The scenario's f32 time scale as the decimal it was written as (1.3, not 1.2999999523).
fn time_scale(k: f32) -> f64 {
    (f64::from(k) * 1e6).round() / 1e6
}

/// The currents the check takes (see the module docs).
fn currents(model: &CurrentModel) -> Vec<Vector3<f64>> {
    match model {
        CurrentModel::None => vec![Vector3::zeros()],
        CurrentModel::Constant(v) => vec![Vector3::from(*v)],
        CurrentModel::GaussMarkov { mean, sigma, .. } => {
            let mut out: Vec<Vector3<f64>> = Vec::new();
            for corner in 0..8u32 {
                let mut v = Vector3::from(*mean);
                for axis in 0..3 {
                    let sign = if corner & (1 << axis) != 0 { 1.0 } else { -1.0 };
                    v[axis] += sign * GAUSS_MARKOV_SIGMAS * sigma[axis];
                }
                if !out.contains(&v) {
                    out.push(v);
                }
            }
            out
        }
    }
}

impl<'a> Checker<'a> {
    fn new(scenario: &'a Scenario, margin: f64) -> Result<Self, CheckError> {
        let cfg = scenario.config();
        let controller = scenario.controller();
        // The path at k = 1, sampled over the part the scenario flies.
        let path = Trajectory::new(Mission {
            time_scale: 1.0,
            ..cfg.mission()
        })
        .map_err(|e| CheckError::Invalid(format!("the mission at time scale 1: {e}")))?;
        let span = cfg.duration / time_scale(cfg.time_scale);
        let n = (span * f64::from(SAMPLE_RATE_HZ)).ceil().max(1.0) as u64;
        let samples = (0..=n)
            .map(|j| {
                if j % 4096 == 0 {
                    poll()?;
                }
                let d = path.sample(j, SAMPLE_RATE_HZ);
                let eta = d.eta.cast::<f64>();
                let att = Attitude::from_eta(&eta);
                Ok(PathSample {
                    s: j as f64 / f64::from(SAMPLE_RATE_HZ),
                    eta,
                    eta_dot: d.eta_dot.cast::<f64>(),
                    eta_ddot: d.eta_ddot.cast::<f64>(),
                    jinv: kinematics::jacobian_inv(&att),
                    att,
                })
            })
            .collect::<Result<_, CheckError>>()?;
        let bx = controller.config().uncertainty.cast(f64::from);
        let nominal = VehicleParams::auv150();
        let plants = (0..controller_core::uncertainty::ParamBox::<f64>::CORNERS)
            .map(|c| {
                let mut p = nominal.with_variation(&bx.corner(c));
                if cfg.trimmed {
                    p = plant::trimmed(&p);
                }
                Plant::new(p, PlantTerms::default())
                    .map_err(|e| CheckError::Invalid(format!("parameter box corner {c}: {e}")))
            })
            .collect::<Result<_, _>>()?;
        let margin_envelope = controller.envelope().scaled(margin as f32);
        let margin_allocator = Allocator::new(
            controller.allocation(),
            &margin_envelope,
            &controller.config().priority,
        )
        .map_err(|e| {
            CheckError::Invalid(format!(
                "the allocator on the {margin} margin envelope: {e}"
            ))
        })?;
        Ok(Checker {
            scenario,
            samples,
            plants,
            currents: currents(&cfg.current),
            margin_allocator,
            margin_envelope,
        })
    }

    /// Every sample at 1/k = `inv_k`; stops at the first violation unless `full` (which also
    /// collects the peaks), and at a stop request.
    fn sweep(&self, inv_k: f64, full: bool) -> Result<Sweep, CheckError> {
        let allocation = self.scenario.controller().allocation();
        let priority = &self.scenario.controller().config().priority;
        let k_scn = time_scale(self.scenario.config().time_scale);
        let mut out = Sweep {
            first: None,
            peaks: [(f64::INFINITY, 0.0, f64::NEG_INFINITY, 0.0); THRUSTERS],
        };
        for smp in &self.samples {
            // One sample is every corner of the box: tens of microseconds.
            poll()?;
            // Time of this sample at the scale checked (at rest: at the scenario's).
            let t = if inv_k > 0.0 {
                smp.s / inv_k
            } else {
                smp.s * k_scn
            };
            let nu = smp.jinv * (smp.eta_dot * inv_k);
            let jjn = kinematics::jinv_jdot_nu(&smp.att, &nu).unwrap_or_else(|_| Vector6::zeros());
            let nu_dot = smp.jinv * (smp.eta_ddot * (inv_k * inv_k)) - jjn;
            let state = PlantState { eta: smp.eta, nu };
            for plant in &self.plants {
                for current in &self.currents {
                    let tau = plant.required_force(&state, &nu_dot, current);
                    let tau32 = tau.cast::<f32>();
                    if full {
                        let thrusts = allocation.thrusts(&tau32);
                        for (i, p) in out.peaks.iter_mut().enumerate() {
                            let x = f64::from(thrusts[i]);
                            if x < p.0 {
                                *p = (x, t, p.2, p.3);
                            }
                            if x > p.2 {
                                *p = (p.0, p.1, x, t);
                            }
                        }
                    }
                    if out.first.is_none() {
                        let a = self.margin_allocator.allocate(&tau32);
                        let lost =
                            |r: usize| a.unallocated[r].abs() > GIVEN_UP * (1.0 + tau32[r].abs());
                        if (0..6).any(lost) {
                            out.first = Some(self.violation(t, &tau32, priority, &lost));
                            if !full {
                                return Ok(out);
                            }
                        }
                    }
                }
            }
        }
        Ok(out)
    }

    fn violation(
        &self,
        t: f64,
        tau: &Vector6<f32>,
        priority: &controller_core::allocation::AxisPriority,
        lost: &dyn Fn(usize) -> bool,
    ) -> Violation {
        let demand = self.scenario.controller().allocation().thrusts(tau);
        let env = &self.margin_envelope;
        let excess = |i: usize| {
            let (lo, hi) = (env.min[i], env.max[i]);
            (demand[i] - hi).max(lo - demand[i]) / (hi - lo)
        };
        let worst = (0..THRUSTERS)
            .max_by(|&a, &b| excess(a).total_cmp(&excess(b)))
            .unwrap_or(0);
        let mut axes: Vec<usize> = (0..6).filter(|&r| lost(r)).collect();
        axes.sort_by_key(|&r| priority.rank[r]);
        Violation {
            t,
            thruster: THRUSTER_NAMES[worst].to_string(),
            demand: f64::from(demand[worst]),
            limit: [f64::from(env.min[worst]), f64::from(env.max[worst])],
            given_up: axes.iter().map(|&r| AXIS_NAMES[r].to_string()).collect(),
        }
    }

    fn feasible_at(&self, k: f64) -> Result<bool, CheckError> {
        Ok(self.sweep(1.0 / k, false)?.first.is_none())
    }

    /// The smallest feasible time scale in [1, MAX_TIME_SCALE] (see the module docs), given a
    /// scale already known to be feasible, if any.
    fn smallest_time_scale(&self, known: Option<f64>) -> Result<Option<f64>, CheckError> {
        let max = f64::from(Trajectory::MAX_TIME_SCALE);
        if known == Some(1.0) || self.feasible_at(1.0)? {
            return Ok(Some(1.0));
        }
        // Doubling to a feasible upper end.
        let (mut lo, mut hi) = (1.0, known.unwrap_or(max).min(max));
        let mut k = 2.0f64;
        while k < hi {
            if self.feasible_at(k)? {
                hi = k;
                break;
            }
            lo = k;
            k *= 2.0;
        }
        if known.is_none() && hi == max && !self.feasible_at(max)? {
            return Ok(None);
        }
        while hi / lo > 1.0 + TIME_SCALE_TOLERANCE {
            let mid = (lo * hi).sqrt();
            if self.feasible_at(mid)? {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let rounded = ((hi / TIME_SCALE_STEP).ceil() * TIME_SCALE_STEP).min(max);
        // Rounded up a feasible scale: feasible again wherever feasibility is monotone.
        Ok(Some((rounded * 100.0).round() / 100.0))
    }
}
