//! Searching for the mission the preflight gets wrong (docs/search.md): a candidate is a
//! point of the mission space's cube ([`super::mission_space`], [`Reach::Realities`]); it is
//! checked as written and flown at the time scale the preflight proposes, as the contract does
//! ([`validation::check_and_fly`]); its **robustness** is the smallest, over the bound's limits,
//! of how far the flight stayed inside each limit normalised by that limit
//! ([`bound::robustness`], Choice 412). Negative: the preflight called the mission feasible at
//! a scale at which it missed — **false feasible**. A candidate the preflight refuses (no
//! scale proposed) or the core does not accept does not count (it cannot be false feasible);
//! a refused one scores, for the search, how far its check is from feasible ([`refusal`],
//! Choice 551), above every flown robustness.
//!
//! Two searches at the same budget of evaluations, each in restarts (one restart per shard
//! index, Choice 414): the cross-entropy method ([`cross_entropy`], Choice 413) and uniform
//! random search. Each evaluation depends only on its point, so a restart depends only on
//! (seed, method, restart index): any sharding gives the same restarts.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::mission_space::{self, Point, Reach};
use super::validation;
use crate::scenario::navigation::Preset;
use crate::scenario::{real_vehicle, Bound, Scenario, ScenarioError};
use crate::sim::bound;

pub mod cross_entropy;
pub mod refusal;

/// What a candidate the preflight refuses scores for the search (**Choice 551**,
/// docs/search.md#refused-candidates).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Refused {
    /// [`refusal::REFUSED_BASE`] plus how far its check is from feasible
    /// ([`refusal::excess`]): the search is pulled towards the feasibility boundary.
    #[default]
    Graded,
    /// +∞: never an elite, the search learns nothing from it (what a shard written without
    /// this field did; the tests' comparison).
    Flat,
}

impl Refused {
    /// A shard written without the field scored refusals +∞.
    fn unrecorded() -> Self {
        Refused::Flat
    }
}

/// What every candidate of a search shares.
#[derive(Clone, Debug)]
pub struct Setup {
    /// The mission the candidates are made on (the real circle: its chain, unit, bound).
    pub base: Scenario,
    pub reach: Reach,
    /// The preflight's margin (the contract's 0.8; a test weakens it to 1.0).
    pub margin: f64,
    /// Each candidate's duration at time scale 1 (s).
    pub duration: f64,
    /// Every candidate told its state through this preset (`None`: as the reach has it — the
    /// exact state for the contract's, a drawn preset for the realities).
    pub navigation: Option<Preset>,
    /// What a refused candidate scores.
    pub refused: Refused,
}

impl Setup {
    /// Candidates on the first real mission (as the contract's random missions).
    pub fn new(reach: Reach, margin: f64, duration: f64) -> Result<Self, ScenarioError> {
        let base = real_vehicle::real_scenarios()?.swap_remove(0);
        Ok(Setup {
            base,
            reach,
            margin,
            duration,
            navigation: None,
            refused: Refused::default(),
        })
    }

    /// The same candidates, a refused one scored as `refused` says.
    pub fn with_refused(self, refused: Refused) -> Self {
        Setup { refused, ..self }
    }

    /// The same candidates, each told its state through `preset` (Choice 470): the realities'
    /// preset coordinate is held at it; a contract mission is flown under it as the contract
    /// flies every mission under each of its presets ([`mission_space::under_preset`]), its
    /// navigation seed a function of the point.
    pub fn with_navigation(self, preset: Option<Preset>) -> Self {
        Setup {
            navigation: preset,
            ..self
        }
    }

    /// The cube's dimension.
    pub fn dims(&self) -> usize {
        self.reach.dims()
    }

    /// The mission at `x`, named `name` (unflown, at time scale 1).
    pub fn mission(&self, x: &[f64], name: &str) -> Result<Scenario, ScenarioError> {
        let held;
        let x = match (self.navigation, self.reach) {
            (Some(p), Reach::Realities) => {
                held = mission_space::with_preset(x, p);
                &held[..]
            }
            _ => x,
        };
        let m = mission_space::mission(
            &self.base,
            self.reach,
            name.to_string(),
            self.duration,
            &mut Point(x),
        )?;
        match (self.navigation, self.reach) {
            (Some(p), Reach::Contract) => mission_space::under_preset(
                &m,
                p,
                point_seed(x),
                self.base.config().controller.estimator.kind,
            ),
            _ => Ok(m),
        }
    }
}

/// A navigation seed from a point's bits (within a TOML integer): the same point, the same
/// seed.
fn point_seed(x: &[f64]) -> u64 {
    let h = x.iter().fold(0xCBF2_9CE4_8422_2325u64, |h, v| {
        (h ^ v.to_bits()).wrapping_mul(0x0000_0100_0000_01B3)
    });
    (h ^ (h >> 32)) & u64::from(u32::MAX)
}

/// One candidate, evaluated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Its point of the cube.
    pub x: Vec<f64>,
    /// The preflight's proposed time scale; `None`: refused, or not a mission the core accepts.
    pub proposed: Option<f64>,
    /// Per limit ([`bound::LIMITS`]) of the flight at the proposed scale.
    pub terms: Option<[f64; 4]>,
    /// Completed outside the real vehicle's bound at the proposed scale.
    pub falsified: bool,
    /// Refused by the preflight and scored graded: how far its check is from feasible
    /// ([`refusal::Excess::distance`]).
    #[serde(default)]
    pub refusal: Option<f64>,
}

impl Evaluation {
    /// The smallest term; `None`: it does not count.
    pub fn robustness(&self) -> Option<f64> {
        let t = self.terms?;
        let r = t.into_iter().fold(f64::INFINITY, f64::min);
        // A run that ended early (diverged) is outside the bound whatever its terms say.
        Some(if self.falsified { r.min(-0.0) } else { r })
    }

    /// Whether a robustness of the trace is a false feasible: below 0, or −0 (a run that ended
    /// early with every term inside its limit, [`Evaluation::robustness`]).
    pub fn is_false_feasible(robustness: f64) -> bool {
        robustness.is_sign_negative()
    }

    /// What a minimiser sees: the robustness; for a refused candidate scored graded,
    /// [`refusal::REFUSED_BASE`] plus its distance from feasible; +∞ otherwise.
    pub fn score(&self) -> f64 {
        match (self.robustness(), self.refusal) {
            (Some(r), _) => r,
            (None, Some(d)) => refusal::REFUSED_BASE + d,
            (None, None) => f64::INFINITY,
        }
    }
}

/// Checks and flies the candidate at `x` (metrics only); `Err` on a failure of the check
/// itself or an interrupt.
pub fn evaluate(setup: &Setup, x: &[f64]) -> Result<Evaluation, String> {
    let not_counted = Evaluation {
        x: x.to_vec(),
        proposed: None,
        terms: None,
        falsified: false,
        refusal: None,
    };
    let mission = match setup.mission(x, "candidate") {
        Ok(m) => m,
        Err(ScenarioError::Invalid { .. }) => return Ok(not_counted),
        Err(e) => return Err(e.to_string()),
    };
    let (check, result, flown) = match validation::check_and_fly_report(&mission, setup.margin) {
        Ok(Some(r)) => r,
        Ok(None) => return Err("interrupted".to_string()),
        // The core refuses the proposed scale: nothing flies, nothing counts.
        Err(validation::CheckFlyError::AtScale { .. }) => return Ok(not_counted),
        Err(e) => return Err(e.to_string()),
    };
    Ok(match flown {
        None if setup.refused == Refused::Graded => Evaluation {
            refusal: Some(
                refusal::excess(&mission, &check)
                    .map_err(|e| e.to_string())?
                    .distance(),
            ),
            ..not_counted
        },
        None => not_counted,
        Some(f) => Evaluation {
            proposed: result.proposed,
            terms: Some(bound::robustness(&Bound::REAL_VEHICLE, &f.metrics)),
            falsified: !f.within,
            ..not_counted
        },
    })
}

/// The mission at `x` as flown (at the proposed scale), named `name`: `None` when the
/// preflight proposes no scale.
pub fn flown_mission(setup: &Setup, x: &[f64], name: &str) -> Result<Option<Scenario>, String> {
    let mission = setup.mission(x, name).map_err(|e| e.to_string())?;
    Ok(validation::check_and_fly(&mission, setup.margin)
        .map_err(|e| e.to_string())?
        .and_then(|(_, f)| f)
        .map(|f| f.scenario))
}

/// How a restart searches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The cross-entropy method ([`cross_entropy`]).
    CrossEntropy,
    /// Uniform points of the cube.
    Random,
}

impl Method {
    pub const ALL: [Method; 2] = [Method::CrossEntropy, Method::Random];

    pub fn name(self) -> &'static str {
        match self {
            Method::CrossEntropy => "cross-entropy",
            Method::Random => "random",
        }
    }
}

/// One restart of one method: its robustness at each evaluation, and its worst candidate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Restart {
    pub method: Method,
    pub index: u64,
    /// The robustness of each evaluation in order (`None`: did not count).
    pub trace: Vec<Option<f64>>,
    /// The evaluation of least robustness (`None`: none counted).
    pub worst: Option<Evaluation>,
    /// The 1-based count of evaluations at the first false feasible.
    pub first_falsified: Option<usize>,
    /// Stopped by an interrupt before its budget was spent.
    pub partial: bool,
}

impl Restart {
    /// The least robustness over its evaluations.
    pub fn min_robustness(&self) -> Option<f64> {
        self.worst.as_ref().and_then(Evaluation::robustness)
    }
}

/// The generator of restart `index` of `method` for `seed`: ChaCha8 on a stream of its own.
fn rng(seed: u64, method: Method, index: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(2 * index + u64::from(method == Method::Random));
    r
}

/// Evaluates `points` in parallel (in order), appending to `restart`.
fn evaluate_batch(
    setup: &Setup,
    points: &[Vec<f64>],
    restart: &mut Restart,
    on_done: &(dyn Fn() + Sync),
) -> Result<Vec<f64>, String> {
    let evals: Vec<Evaluation> = points
        .par_iter()
        .map(|x| {
            let e = evaluate(setup, x);
            on_done();
            e
        })
        .collect::<Result<_, _>>()?;
    let mut scores = Vec::with_capacity(evals.len());
    for e in evals {
        restart.trace.push(e.robustness());
        if e.falsified && restart.first_falsified.is_none() {
            restart.first_falsified = Some(restart.trace.len());
        }
        scores.push(e.score());
        // The worst is of the candidates that count (a refused one's score is not a
        // robustness).
        let least = restart.min_robustness().unwrap_or(f64::INFINITY);
        if e.robustness().is_some_and(|r| r < least) {
            restart.worst = Some(e);
        }
    }
    Ok(scores)
}

/// Restart `index` of `method` at `budget` evaluations, from `seed`; `on_done` after each
/// evaluation. An interrupt ends it early, marked partial.
pub fn run_restart(
    setup: &Setup,
    method: Method,
    seed: u64,
    index: u64,
    budget: usize,
    on_done: &(dyn Fn() + Sync),
) -> Result<Restart, String> {
    let mut restart = Restart {
        method,
        index,
        trace: Vec::with_capacity(budget),
        worst: None,
        first_falsified: None,
        partial: false,
    };
    let mut r = rng(seed, method, index);
    let n = setup.dims();
    let mut ce = cross_entropy::Search::new(n, &mut r);
    while restart.trace.len() < budget {
        if crate::interrupt::requested() {
            restart.partial = true;
            break;
        }
        let left = budget - restart.trace.len();
        let points: Vec<Vec<f64>> = match method {
            Method::Random => (0..left.min(ce.population()))
                .map(|_| (0..n).map(|_| r.random::<f64>()).collect())
                .collect(),
            Method::CrossEntropy => {
                let mut p = ce.ask(&mut r);
                p.truncate(left);
                p
            }
        };
        match evaluate_batch(setup, &points, &mut restart, on_done) {
            Ok(scores) => {
                if method == Method::CrossEntropy {
                    ce.tell(&points, &scores, &mut r);
                }
            }
            Err(e) if e == "interrupted" => {
                restart.partial = true;
                break;
            }
            Err(e) => return Err(e),
        }
    }
    Ok(restart)
}

/// What a falsification is: the same spec makes the same restarts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spec {
    pub reach: Reach,
    pub margin: f64,
    pub duration: f64,
    pub seed: u64,
    /// Evaluations per restart.
    pub budget: usize,
    /// Restarts of each method.
    pub restarts: u64,
    /// The navigation preset every candidate is told its state through ([`Setup::navigation`]).
    #[serde(default)]
    pub navigation: Option<Preset>,
    /// What a refused candidate scores ([`Setup::refused`]).
    #[serde(default = "Refused::unrecorded")]
    pub refused: Refused,
}

impl Spec {
    /// Its candidates' setup.
    pub fn setup(&self) -> Result<Setup, ScenarioError> {
        Ok(Setup::new(self.reach, self.margin, self.duration)?
            .with_navigation(self.navigation)
            .with_refused(self.refused))
    }
}

/// What one shard did (its `shard.json`): the restarts r ≡ I (mod N) of both methods.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardResult {
    pub spec: Spec,
    /// [I, N].
    pub shard: [u64; 2],
    pub restarts: Vec<Restart>,
    /// Wall-clock seconds the shard took.
    pub seconds: f64,
}

/// Runs shard `index`/`count` of `spec`: restarts r ≡ index (mod count) of each method, one
/// after the other (each evaluates its generations in parallel); `on_done` after each
/// evaluation. Stops starting restarts on an interrupt.
pub fn run_shard(
    spec: &Spec,
    index: u64,
    count: u64,
    on_done: &(dyn Fn() + Sync),
) -> Result<ShardResult, String> {
    let start = std::time::Instant::now();
    let setup = spec.setup().map_err(|e| e.to_string())?;
    let shard = super::campaign::Shard {
        runs: spec.restarts,
        index,
        count,
    };
    let mut restarts = Vec::new();
    for k in 0..shard.len() {
        for method in Method::ALL {
            if crate::interrupt::requested() {
                break;
            }
            restarts.push(run_restart(
                &setup,
                method,
                spec.seed,
                shard.run(k),
                spec.budget,
                on_done,
            )?);
        }
    }
    Ok(ShardResult {
        spec: spec.clone(),
        shard: [index, count],
        restarts,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Why shards do not merge.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MergeError {
    #[error("no shard given")]
    Empty,
    #[error("shard {0} is of another falsification (its spec differs from the first shard's)")]
    OtherSpec(usize),
    #[error("restart {index} of {method} is in more than one shard")]
    Twice { method: &'static str, index: u64 },
}

/// The shards' restarts as one falsification, sorted by (method, index); the restarts no
/// shard ran are listed (the merge is then partial). Every restart is kept: the report takes
/// the worst.
pub fn merge(shards: &[ShardResult]) -> Result<(Spec, Vec<Restart>, Vec<String>), MergeError> {
    let spec = shards.first().ok_or(MergeError::Empty)?.spec.clone();
    if let Some(i) = shards.iter().position(|s| s.spec != spec) {
        return Err(MergeError::OtherSpec(i));
    }
    let mut all: Vec<Restart> = shards.iter().flat_map(|s| s.restarts.clone()).collect();
    all.sort_by_key(|r| (r.method == Method::Random, r.index));
    for w in all.windows(2) {
        if (w[0].method, w[0].index) == (w[1].method, w[1].index) {
            return Err(MergeError::Twice {
                method: w[0].method.name(),
                index: w[0].index,
            });
        }
    }
    let missing = Method::ALL
        .iter()
        .flat_map(|&m| (0..spec.restarts).map(move |i| (m, i)))
        .filter(|&(m, i)| !all.iter().any(|r| r.method == m && r.index == i))
        .map(|(m, i)| format!("{} restart {i}", m.name()))
        .collect();
    Ok((spec, all, missing))
}
