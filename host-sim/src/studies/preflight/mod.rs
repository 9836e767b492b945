//! Preflight feasibility (docs/real-vehicle.md#preflight-feasibility): before any simulation, can the real
//! thrusters fly this scenario's mission, and if not, why not and how slowly could they?
//!
//! For the mission's reference η_d, η̇_d, η̈_d (the path the scenario flies, sampled every
//! [`SAMPLE_PERIOD`] of the path's own time), the body force the vehicle needs is Eq (1) solved
//! for τ ([`Plant::required_force`](crate::plant::Plant::required_force)) with
//! ν = J⁻¹η̇ and ν̇ = J⁻¹(η̈_d − J̇ν) **at the attitude the vehicle holds there**
//! ([`attitude`]: the heel of its payload's lateral CG, which roll — not actuated — cannot
//! remove, and its swing; the pitch offset at which the law holds its model mismatch, and the
//! Munk moment of that angle of attack at speed), under the configured current (constant: that
//! velocity; Gauss–Markov: every corner of mean ± [`GAUSS_MARKOV_SIGMAS`]·σ). Each τ goes
//! through **the board's own allocator** (`controller_core::allocator::Allocator`, the
//! scenario's geometry, unit and axis priority) built on the envelope shrunk to the margin
//! (default [`DEFAULT_MARGIN`] = 80 % of [T_min, T_max]): feasible when every block of every τ
//! is met, i.e. every thruster's demand lies inside the margin envelope. The rest of the
//! envelope is left to the feedback (the tracking transients, noise), which this check does
//! not model.
//!
//! **Two verdicts** ([`Scope`]): for the mission **as written** — the scenario's own payload
//! profile (its roll swings included) and current — which decides `check`'s exit code and the
//! proposed time scale; and over **the whole configured box**, every corner of the
//! controller's parameter box held constant (2⁹ plants, trimmed if the scenario is): what the
//! law is certified for, reported beside it.
//!
//! **Time scale.** With k the time scale, η̇_d scales as 1/k and η̈_d (and with it every
//! velocity-squared term: Coriolis, damping, Munk) as 1/k², so the check is run at any k from
//! the path sampled once at k = 1. At k = ∞ (`1/k = 0`) only g(η) and the current's drag
//! remain: a mission infeasible there is **statically infeasible** — payload weight or CG
//! moment beyond what the thrusters can hold at zero speed, which no time scale cures.
//! Otherwise the smallest feasible k in [1, [`Trajectory::MAX_TIME_SCALE`]] is found by
//! doubling, then bisection to a relative [`TIME_SCALE_TOLERANCE`], rounded up to
//! [`TIME_SCALE_STEP`], and checked again (the attitude terms make feasibility only nearly
//! monotone in k: a rounded scale that fails is raised by steps until one passes). The
//! proposed scale flies the same path: the scenario's duration D covers the path up to
//! D/k_scenario, which at scale k takes D·k/k_scenario.
//!
//! **Choices** (docs/real-vehicle.md#preflight-feasibility): the box is the controller's `uncertainty` box; the margin
//! is 80 %; the path is sampled at 20 Hz of its own time; Gauss–Markov currents are taken at
//! ±3σ; the attitude model is [`attitude`]'s (**Choice 104**). Beside the navigation's share
//! ([`navigation`], Choice 372) each thruster's margin envelope keeps the thrusters' lag's
//! share ([`lag`], Choice 509): the start transient's overshoot through a lagged thruster.

use std::fmt;

use controller_core::effectiveness::{Mounting, THRUSTERS, THRUSTER_NAMES};
use controller_core::readable::Readable;
use controller_core::Trajectory;
use serde::{Deserialize, Serialize};

use crate::interrupt;
use crate::scenario::Scenario;

pub mod attitude;
mod bits;
pub mod chatter;
pub mod lag;
pub mod navigation;
pub mod path_budget;
pub mod period;
pub mod profile;
mod sweep;

use sweep::{Checker, Peaks};

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

/// Why [`check`] gave no verdict.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CheckError {
    /// The check cannot be made: a margin outside (0, 1], or a scenario whose allocator or
    /// plants cannot be built.
    Invalid(String),
    /// A stop was requested ([`crate::interrupt`]) before the check was done: a day-long
    /// mission is 1.7·10⁶ samples of the path at each of the 2⁹ corners, minutes of work, so
    /// the check polls the request at every sample (**Choice 120**).
    Interrupted,
    /// A waypoint mission with no speed profile: `part` cannot be flown over the whole box
    /// even at the slowest speed the search tries, `thruster` beyond its envelope there (the
    /// box cannot be held at rest: docs/missions.md#the-speed-profile, **Choice 175**).
    NoProfile {
        /// `leg j` or `turn at j`.
        part: String,
        /// The thruster out of its envelope.
        thruster: String,
    },
    /// A waypoint mission with no speed profile its own check passes (Choice 543): the
    /// path-error budget or the chatter term refuses it at every speed the search tries, or
    /// the check as flown still refuses it after the search's rounds.
    NoProfileTerm {
        /// What refuses it, as a clause.
        why: String,
    },
}

impl fmt::Display for CheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckError::Invalid(e) => f.write_str(e),
            CheckError::Interrupted => f.write_str("interrupted before the check was done"),
            CheckError::NoProfile { part, thruster } => write!(
                f,
                "no speed profile: {part} cannot be flown over the whole box even at {} m/s ({thruster} beyond its envelope)",
                profile::MIN_PROFILE_SPEED
            ),
            CheckError::NoProfileTerm { why } => write!(f, "no speed profile: {why}"),
        }
    }
}

impl std::error::Error for CheckError {}

/// Stops a long loop of the check when a stop was requested.
pub(super) fn poll() -> Result<(), CheckError> {
    if interrupt::requested() {
        Err(CheckError::Interrupted)
    } else {
        Ok(())
    }
}

/// How a sweep evaluates its points (docs/real-vehicle.md#how-the-check-is-made, **Choices
/// 390–392**). Both give the same verdicts, time scales, violations and peaks, bit for bit
/// (tests/preflight_engines.rs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Engine {
    /// What `check` runs: each sample's shared work formed once, each distinct sample judged
    /// once per sweep, a bisection's probe starting where the last one failed.
    #[default]
    Fast,
    /// The reference: every case of every sample evaluated from scratch, as written
    /// (Eq 1 per point, [`attitude`]'s functions as they are).
    Exhaustive,
}

/// Which payloads and currents a verdict covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// The scenario's own payload profile and current.
    AsWritten = 0,
    /// Every corner of the controller's parameter box, held constant, under the configured
    /// current.
    WholeBox = 1,
}

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

/// A verdict over one [`Scope`]: whether the mission fits at its own time scale, the smallest
/// scale at which it does, and the first violations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScopeVerdict {
    pub verdict: Verdict,
    /// The smallest feasible time scale in [1, 100] (rounded up to 0.01); `None` if there is
    /// none.
    pub smallest_time_scale: Option<f64>,
    /// The first violation at the scenario's time scale.
    pub first_violation: Option<Violation>,
    /// The first violation at rest (k = ∞), if the mission is statically infeasible.
    pub static_violation: Option<Violation>,
}

/// The preflight check of one scenario (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Preflight {
    /// The scenario's name.
    pub name: String,
    /// The verdict for the mission as written (its own payload profile and current): the one
    /// `check`'s exit code and the proposed time scale follow.
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
    /// Thrust unit of Eqs 31–32, heading mode, trim, start attitude: what was checked.
    pub thrust_unit: String,
    pub heading: String,
    pub trimmed: bool,
    pub initial_attitude: String,
    /// The thrusters' mounting in words (`main forward, vert fore up, …`), and as the link's
    /// reversed-thruster mask (`None`: not the AUV-150 layout).
    pub mounting: String,
    pub reversed_thrusters: Option<u8>,
    /// Per thruster, at the scenario's time scale, the mission as written.
    pub thrusters: Vec<ThrusterDemand>,
    /// The first violation at the scenario's time scale (as written).
    pub first_violation: Option<Violation>,
    /// The first violation at rest (k = ∞), if the mission as written is statically
    /// infeasible.
    pub static_violation: Option<Violation>,
    /// The same check over every corner of the configured parameter box (`None`: not asked
    /// for, [`check_as_written`]).
    pub whole_box: Option<ScopeVerdict>,
    /// The navigation the check assumed, the thrust its noise takes per thruster (kept on each
    /// side of the margin envelope), and what the mission needs of it.
    pub navigation: navigation::NavigationShare,
    /// The path error the mission will show on its navigation, against the bound (`None`: the
    /// scenario has no bound), Choice 424: a mission whose force fits but whose budget does
    /// not is not feasible at its scale.
    pub path_budget: Option<path_budget::PathBudget>,
    /// The chatter the mission will show on its navigation, per thruster, against the bound's
    /// chatter limits (`None`: the scenario has no bound), Choice 504: a mission whose force
    /// and budget fit but whose chatter does not is not feasible at its scale.
    pub chatter: Option<chatter::ChatterPrediction>,
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

impl Preflight {
    /// The terms beside the force check that do not fit at the scale checked: the path-error
    /// budget and the chatter term, each with what it needs.
    fn write_terms_missed(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(b) = self.path_budget.as_ref().filter(|b| !b.fits()) {
            write!(
                f,
                ": path-error budget {:.1} mm over the {:.0} mm bound",
                1e3 * b.total,
                1e3 * b.bound
            )?;
            if let Some(n) = &b.needs {
                write!(f, " at every time scale ({n})")?;
            }
        }
        if let Some(c) = self.chatter.as_ref().filter(|c| !c.fits()) {
            let (r, i) = c.worst_reversals();
            let (tv, j) = c.worst_tv();
            write!(
                f,
                ": chatter {} {r:.1} reversals/s (bound {}), {} {tv:.0} V/s (bound {})",
                THRUSTER_NAMES[i], c.max_reversals_per_s, THRUSTER_NAMES[j], c.max_command_tv
            )?;
            if let Some(n) = &c.needs {
                write!(f, " at every time scale ({n})")?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for Preflight {
    /// The one-line verdict, e.g. `preflight real-circular-10R: FEASIBLE at time scale 1 for
    /// this mission (margin 80 %: peak 77 % of vert aft's envelope; smallest feasible time
    /// scale 1); over the whole configured box: feasible from time scale 1.2`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pct = 100.0 * self.margin;
        write!(f, "preflight {}: ", self.name)?;
        match self.verdict {
            Verdict::Feasible => {
                let peak = self
                    .thrusters
                    .iter()
                    .max_by(|a, b| a.usage.total_cmp(&b.usage));
                write!(
                    f,
                    "FEASIBLE at time scale {} for this mission",
                    self.time_scale
                )?;
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
                f.write_str(")")?;
            }
            Verdict::StaticallyInfeasible => {
                write!(
                    f,
                    "STATICALLY INFEASIBLE for this mission (margin {pct:.0} %): at rest"
                )?;
                if let Some(v) = &self.static_violation {
                    write!(f, ", at t = {:.2} s, {}", v.t, fmt_violation(v))?;
                }
                f.write_str("; no time scale helps")?;
            }
            Verdict::NeedsTimeScale | Verdict::Infeasible => {
                write!(
                    f,
                    "INFEASIBLE at time scale {} for this mission (margin {pct:.0} %)",
                    self.time_scale
                )?;
                if let Some(v) = &self.first_violation {
                    write!(f, ": first at t = {:.2} s, {}", v.t, fmt_violation(v))?;
                }
                self.write_terms_missed(f)?;
                match self.smallest_time_scale {
                    Some(k) => write!(f, "; feasible from time scale {k}")?,
                    None => write!(
                        f,
                        "; not feasible at any time scale up to {}",
                        Trajectory::MAX_TIME_SCALE
                    )?,
                }
            }
        }
        match &self.whole_box {
            Some(b) => write!(
                f,
                "; over the whole configured box: {}",
                b.short(self.time_scale)
            ),
            None => Ok(()),
        }
    }
}

impl ScopeVerdict {
    /// The verdict in a few words: `feasible`, `feasible from time scale 2.35`, `statically
    /// infeasible`, `infeasible at any time scale up to 100`.
    pub fn short(&self, time_scale: f64) -> String {
        match (self.verdict, self.smallest_time_scale) {
            (Verdict::Feasible, _) => format!("feasible at time scale {time_scale}"),
            (Verdict::NeedsTimeScale, Some(k)) => format!("feasible from time scale {k}"),
            (Verdict::StaticallyInfeasible, _) => "STATICALLY INFEASIBLE".to_string(),
            _ => format!(
                "INFEASIBLE at any time scale up to {}",
                Trajectory::MAX_TIME_SCALE
            ),
        }
    }
}

/// The preflight check of `scenario` at `margin` (a fraction of the envelope, in (0, 1]): the
/// mission as written and the whole configured box.
///
/// # Errors
/// [`CheckError::Invalid`]: a margin outside (0, 1], or a scenario whose allocator or plants
/// cannot be built; [`CheckError::Interrupted`]: a stop was requested.
pub fn check(scenario: &Scenario, margin: f64) -> Result<Preflight, CheckError> {
    check_with(scenario, margin, true, Engine::Fast)
}

/// Forgets the box's samples this thread kept judged inside the margin (Choice 537): a
/// benchmark that times `check` afresh each iteration calls it, or the later iterations
/// would find the first's samples kept.
pub fn forget_kept() {
    sweep::forget_kept();
}

/// [`check`] of the mission as written only (no [`Preflight::whole_box`]): what flying it
/// needs, at a 2⁹th of the work.
///
/// # Errors
/// As [`check`].
pub fn check_as_written(scenario: &Scenario, margin: f64) -> Result<Preflight, CheckError> {
    check_with(scenario, margin, false, Engine::Fast)
}

/// Each thruster's peaks over the flight as checked (`peaks`: min, its t, max, its t) against
/// its envelope.
fn thruster_demands(
    envelope: &controller_core::thruster::ThrustEnvelope,
    peaks: &[(f64, f64, f64, f64); THRUSTERS],
) -> Vec<ThrusterDemand> {
    (0..THRUSTERS)
        .map(|i| {
            let (min, t_min, max, t_max) = peaks[i];
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
        .collect()
}

/// [`check`] (`whole_box`) or [`check_as_written`] by `engine`: the reference engine
/// ([`Engine::Exhaustive`]) is what the fast one is tested against.
///
/// # Errors
/// As [`check`].
pub fn check_with(
    scenario: &Scenario,
    margin: f64,
    whole_box: bool,
    engine: Engine,
) -> Result<Preflight, CheckError> {
    if !(margin > 0.0 && margin <= 1.0) {
        return Err(CheckError::Invalid(format!(
            "the margin must be a fraction of the envelope in (0, 1], got {}",
            Readable(margin)
        )));
    }
    let checker = Checker::new(scenario, margin, engine)?;
    let cfg = scenario.config();
    let k = time_scale(cfg.time_scale);
    let (mut as_written, peaks) = verdict(&checker, Scope::AsWritten, k)?;
    let budget = path_budget::Budget::new(scenario)?;
    let path_budget = match &budget {
        Some(b) => Some(b.evaluate()?),
        None => None,
    };
    let mut whole_box = match whole_box {
        true => Some(verdict(&checker, Scope::WholeBox, k)?.0),
        false => None,
    };
    let chatter_model = chatter::Chatter::new(scenario)?;
    let chatter = match &chatter_model {
        Some(c) => Some(c.evaluate()?),
        None => None,
    };
    // Both scopes' verdicts join the budget and the chatter term: the box's too, or its line
    // would call a mission feasible at a scale the budget or the term refuses.
    let terms = Terms {
        budget: budget.as_ref().zip(path_budget.as_ref()),
        chatter: chatter_model.as_ref().zip(chatter.as_ref()),
    };
    with_terms(&checker, Scope::AsWritten, &mut as_written, k, &terms)?;
    if let Some(v) = whole_box.as_mut() {
        with_terms(&checker, Scope::WholeBox, v, k, &terms)?;
    }
    let envelope = scenario.controller().envelope();
    let thrusters = thruster_demands(envelope, &peaks);
    let mask = cfg.controller.geometry.auv150_reversed();
    let margin_envelope = envelope.scaled(margin as f32);
    let extremes = peaks.map(|(min, _, max, _)| (min, max));
    let navigation = navigation::share(scenario, Some((&extremes, &margin_envelope)));
    Ok(Preflight {
        name: cfg.name.clone(),
        verdict: as_written.verdict,
        time_scale: k,
        duration: cfg.duration,
        smallest_time_scale: as_written.smallest_time_scale,
        margin,
        thrust_unit: cfg.controller.thrust_unit.to_string(),
        heading: cfg.heading.to_string(),
        trimmed: cfg.trimmed,
        initial_attitude: cfg.initial_attitude().as_str().to_string(),
        mounting: mask.map_or_else(
            || "not the AUV-150 layout".to_string(),
            |m| Mounting(m).to_string(),
        ),
        reversed_thrusters: mask,
        thrusters,
        first_violation: as_written.first_violation,
        static_violation: as_written.static_violation,
        whole_box,
        navigation,
        path_budget,
        chatter,
    })
}

/// The terms a force verdict is joined with: the path-error budget (Choice 424) and the chatter
/// term (Choice 504), each with its model (to evaluate at any scale) and its evaluation.
struct Terms<'a> {
    budget: Option<(&'a path_budget::Budget<'a>, &'a path_budget::PathBudget)>,
    chatter: Option<(&'a chatter::Chatter<'a>, &'a chatter::ChatterPrediction)>,
}

impl Terms<'_> {
    /// Each term's smallest fitting scale (`None` inside: that term fits at no scale).
    fn smallest(&self) -> Vec<Option<f64>> {
        let mut v = Vec::new();
        if let Some((_, pb)) = self.budget {
            v.push(pb.smallest_time_scale);
        }
        if let Some((_, c)) = self.chatter {
            v.push(c.smallest_time_scale);
        }
        v
    }

    /// Every term fits at scale `k`.
    fn fit_at(&self, k: f64) -> Result<bool, CheckError> {
        if let Some((b, _)) = self.budget {
            if !b.fits_at(k)? {
                return Ok(false);
            }
        }
        if let Some((c, _)) = self.chatter {
            if !c.fits_at(k)? {
                return Ok(false);
            }
        }
        Ok(true)
    }
}

/// The force verdict `v` over `scope` at the scenario's scale `k` joined with the path-error
/// budget (Choice 424) and the chatter term (Choice 504) of the mission as written: feasible
/// only when all fit at `k`; the proposed scale the smallest at which all fit (the largest of
/// their smallest, raised by steps until every one fits); infeasible when a term fits at no
/// scale.
fn with_terms(
    checker: &Checker,
    scope: Scope,
    v: &mut ScopeVerdict,
    k: f64,
    terms: &Terms,
) -> Result<(), CheckError> {
    if matches!(
        v.verdict,
        Verdict::StaticallyInfeasible | Verdict::Infeasible
    ) {
        return Ok(());
    }
    let smallest = terms.smallest();
    if smallest.iter().any(Option::is_none) {
        v.verdict = Verdict::Infeasible;
        v.smallest_time_scale = None;
        return Ok(());
    }
    let Some(kf) = v.smallest_time_scale else {
        return Ok(());
    };
    let kt = smallest.into_iter().flatten().fold(kf, f64::max);
    if kt <= kf && terms.fit_at(kf)? {
        return Ok(());
    }
    let max = f64::from(Trajectory::MAX_TIME_SCALE);
    let mut at = kt;
    let mut found = None;
    for _ in 0..=MAX_ROUNDING_STEPS {
        if at > max {
            break;
        }
        if checker.feasible(scope, 1.0 / at)? && terms.fit_at(at)? {
            found = Some(at);
            break;
        }
        at = ((at + TIME_SCALE_STEP) * 100.0).round() / 100.0;
    }
    v.smallest_time_scale = found;
    v.verdict = match found {
        Some(s) if s <= k => Verdict::Feasible,
        Some(_) => Verdict::NeedsTimeScale,
        None => Verdict::Infeasible,
    };
    Ok(())
}

/// The verdict over `scope` at the scenario's scale `k`, and the peaks of the full sweep there.
fn verdict(checker: &Checker, scope: Scope, k: f64) -> Result<(ScopeVerdict, Peaks), CheckError> {
    // The box's peaks are not reported: its sweep may stop at its first violation.
    let own = checker.sweep(scope, 1.0 / k, scope == Scope::AsWritten)?;
    let at_rest = checker.sweep(scope, 0.0, false)?;
    let statically_infeasible = at_rest.first.is_some();
    let smallest = if statically_infeasible {
        None
    } else {
        smallest_time_scale(checker, scope, own.first.is_none().then_some(k))?
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
    Ok((
        ScopeVerdict {
            verdict,
            smallest_time_scale: smallest,
            first_violation: own.first,
            static_violation: at_rest.first,
        },
        own.peaks,
    ))
}

/// The scenario's f32 time scale as the decimal it was written as (1.3, not 1.2999999523).
pub(super) fn time_scale(k: f32) -> f64 {
    (f64::from(k) * 1e6).round() / 1e6
}

/// The smallest feasible time scale of `scope` in [1, MAX_TIME_SCALE] (see the module docs),
/// given a scale already known to be feasible, if any.
fn smallest_time_scale(
    checker: &Checker,
    scope: Scope,
    known: Option<f64>,
) -> Result<Option<f64>, CheckError> {
    let max = f64::from(Trajectory::MAX_TIME_SCALE);
    let feasible_at = |k: f64| checker.feasible(scope, 1.0 / k);
    if known == Some(1.0) || feasible_at(1.0)? {
        return Ok(Some(1.0));
    }
    // Doubling to a feasible upper end.
    let (mut lo, mut hi) = (1.0, known.unwrap_or(max).min(max));
    let mut k = 2.0f64;
    while k < hi {
        if feasible_at(k)? {
            hi = k;
            break;
        }
        lo = k;
        k *= 2.0;
    }
    if known.is_none() && hi == max && !feasible_at(max)? {
        return Ok(None);
    }
    // The spans at the infeasible end, so that the probes between are screened (Choice 531).
    if hi / lo > 1.0 + TIME_SCALE_TOLERANCE {
        checker.prime(scope, 1.0 / lo)?;
    }
    while hi / lo > 1.0 + TIME_SCALE_TOLERANCE {
        let mid = (lo * hi).sqrt();
        if feasible_at(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // Rounded up to the step, and checked: feasibility is only nearly monotone in k.
    let mut rounded = (hi / TIME_SCALE_STEP).ceil() * TIME_SCALE_STEP;
    for _ in 0..MAX_ROUNDING_STEPS {
        rounded = ((rounded.min(max)) * 100.0).round() / 100.0;
        if feasible_at(rounded)? {
            return Ok(Some(rounded));
        }
        rounded += TIME_SCALE_STEP;
    }
    // No rounded scale passed: the bisection's own feasible end, to a millionth.
    Ok(Some((hi * 1e6).ceil() / 1e6))
}

/// Steps of [`TIME_SCALE_STEP`] a rounded time scale is raised by, at most, until it is
/// feasible; beyond them the mission has no feasible scale the check can name.
const MAX_ROUNDING_STEPS: usize = 20;
