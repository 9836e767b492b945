//! Tuning the controller's gains for the real vehicle (docs/tune.md): a multi-objective
//! search over K₁, K₂ by axis group, μ, δ_max and the estimator's bandwidth, each candidate
//! scored over one fixed sample of missions (common random numbers across candidates).
//!
//! - The candidates ([`Gains`], **Choice 440**): K₁ and K₂ of three axis groups (surge;
//!   sway and yaw; heave and pitch; roll stays 0 as the paper has it), μ, δ_max and a factor
//!   on the estimator's σₐ (its bandwidth: a larger σₐ trusts the solution more), each on a
//!   log scale over [`RANGES`], a point of [0, 1]⁹.
//! - The constraint filter ([`admissible`], **Choice 442**): the law's own conditions as the
//!   core checks them when it is built (`Controller::new`, reached through the scenario's
//!   validation: Assumption 2's β̂ ≤ β, Theorem 2, the loop-rate rule, the estimator's
//!   steady state), and Theorem 4's ball (Eq 40) at δ_max no larger than the shipped gains'.
//!   A candidate that breaks one is never flown.
//! - The sample ([`sample`], **Choice 443**): the contract's random missions with their
//!   realities ([`validation::Campaign`], `disturbed`: payload in the box and its profile,
//!   mounting, current with a Gauss–Markov part, thruster lag), each under the navigation
//!   presets `ideal` and `survey`, shortened to [`Spec::duration`] and flown study-grade
//!   (Choice 400). Every candidate flies the same missions with the same seeds.
//! - The scores ([`Scores`], **Choice 444**): per mission, checked as written and flown at the
//!   time scale the preflight proposes ([`validation::check_and_fly`]): max path error,
//!   reversals per second, command total variation, saturated fraction, and the proposed time
//!   scale (a refused mission counts as [`Trajectory::MAX_TIME_SCALE`]); each as p95 (nearest
//!   rank) and worst. The search minimises the five p95s; a refused mission and a flight with
//!   a metric not a number are constraint violations (Deb's rule: fewer first).
//! - The search ([`nsga2`], Choice 441) in restarts, the shards' unit (**Choice 496**): restart
//!   r is its own stream of the seed, its first member the shipped gains; the merge takes the
//!   non-dominated set of every candidate the restarts flew (Choice 496).
//! - The chosen point ([`choose`], **Choice 446**): of the feasible front, the one whose worst
//!   ratio to the shipped gains' score over the five objectives is least.

use controller_core::{ControllerConfig, Trajectory};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::campaign::PlantStep;
use super::validation::{self, CheckFlyError};
use crate::scenario::navigation::Preset;
use crate::scenario::ultimate_bound;
use crate::scenario::{real_vehicle, Scenario, ScenarioError};

pub mod nsga2;

/// The search's coordinates: K₁ (surge, sway/yaw, heave/pitch), K₂ (the same), μ, δ_max,
/// the estimator's σₐ factor.
pub const DIMS: usize = 9;
/// The range of each coordinate (log scale between them).
pub const RANGES: [[f64; 2]; DIMS] = [
    [0.5, 16.0],
    [0.5, 16.0],
    [0.5, 16.0],
    [0.5, 16.0],
    [0.5, 16.0],
    [0.5, 16.0],
    [0.02, 0.5],
    [5.0, 50.0],
    [0.25, 4.0],
];
/// The names of the coordinates, in order.
pub const NAMES: [&str; DIMS] = [
    "k1_surge",
    "k1_sway_yaw",
    "k1_heave_pitch",
    "k2_surge",
    "k2_sway_yaw",
    "k2_heave_pitch",
    "mu",
    "delta_max",
    "accel_sigma_factor",
];
/// The axes of each group, η = [x y z φ θ ψ].
const GROUPS: [&[usize]; 3] = [&[0], &[1, 5], &[2, 4]];

/// One candidate's settings (in physical units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gains(pub [f64; DIMS]);

impl Gains {
    /// The point of [0, 1]⁹ `x` (clamped), each coordinate log-scaled over its range.
    pub fn from_unit(x: &[f64]) -> Self {
        Gains(std::array::from_fn(|j| {
            let [lo, hi] = RANGES[j];
            let u = x.get(j).copied().unwrap_or(0.5).clamp(0.0, 1.0);
            lo * (hi / lo).powf(u)
        }))
    }

    /// Its point of [0, 1]⁹ (clamped into the cube).
    pub fn to_unit(&self) -> Vec<f64> {
        (0..DIMS)
            .map(|j| {
                let [lo, hi] = RANGES[j];
                ((self.0[j] / lo).ln() / (hi / lo).ln()).clamp(0.0, 1.0)
            })
            .collect()
    }

    /// The settings of `c` (each group's first axis), σₐ factor 1.
    pub fn of(c: &ControllerConfig) -> Self {
        let mut g = [1.0; DIMS];
        for (k, axes) in GROUPS.iter().enumerate() {
            g[k] = f64::from(c.k1[axes[0]]);
            g[3 + k] = f64::from(c.k2[axes[0]]);
        }
        g[6] = f64::from(c.mu);
        g[7] = f64::from(c.delta_max);
        Gains(g)
    }

    /// `c` with these settings (σₐ scaled from `c`'s own).
    pub fn apply(&self, c: &mut ControllerConfig) {
        for (k, axes) in GROUPS.iter().enumerate() {
            for &i in *axes {
                c.k1[i] = self.0[k] as f32;
                c.k2[i] = self.0[3 + k] as f32;
            }
        }
        c.mu = self.0[6] as f32;
        c.delta_max = self.0[7] as f32;
        let f = self.0[8] as f32;
        c.estimator.accel_sigma = c.estimator.accel_sigma.map(|s| s * f);
    }
}

/// Why a candidate is not flown.
#[derive(Debug, thiserror::Error)]
pub enum Refusal {
    /// The core refuses the configuration (β, Theorem 2, the loop-rate rule, the estimator).
    #[error("{0}")]
    Law(ScenarioError),
    /// Theorem 4's ball at δ_max is larger than the shipped gains'.
    #[error("Theorem 4's ball (Eq 40) at δ_max is {radius:.4}, larger than {limit:.4}")]
    Ball { radius: f64, limit: f64 },
}

/// Theorem 4's ball (Eq 40) at δ = δ_max for `c` (the log's own formula).
pub fn ball_at_delta_max(c: &ControllerConfig) -> f64 {
    ultimate_bound::ball_radius(c, f64::from(c.delta_max)).unwrap_or(0.0)
}

/// `base` with `gains`, if the law's conditions hold (Choice 442): the core's own checks,
/// then Theorem 4's ball at δ_max no larger than `ball_limit`.
pub fn admissible(base: &Scenario, gains: &Gains, ball_limit: f64) -> Result<Scenario, Refusal> {
    let s = base
        .with(|c| gains.apply(&mut c.controller))
        .map_err(Refusal::Law)?;
    let radius = ball_at_delta_max(&s.config().controller);
    if radius > ball_limit * (1.0 + 1e-9) {
        return Err(Refusal::Ball {
            radius,
            limit: ball_limit,
        });
    }
    Ok(s)
}

/// What a study is: the same spec makes the same study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spec {
    pub seed: u64,
    /// Random missions of the sample (each flown under both presets).
    pub missions: usize,
    /// Each mission's duration at time scale 1 (s).
    pub duration: f64,
    /// The preflight's margin.
    pub margin: f64,
    pub population: usize,
    pub generations: usize,
    /// NSGA-II restarts (the shards' unit).
    pub restarts: u64,
}

impl Spec {
    /// Evaluations of one restart.
    pub fn evaluations_per_restart(&self) -> usize {
        self.population * (self.generations + 1)
    }
}

/// The main job's study (**Choices 447 and 545**, docs/tune.md#in-the-main-job): small and
/// fixed-seed, its cost bounded (measured in docs/tune.md): 24 evaluations of 12 missions.
pub const MAIN_JOB_TUNE: Spec = Spec {
    seed: 1,
    missions: 6,
    duration: 20.0,
    margin: crate::studies::preflight::DEFAULT_MARGIN,
    population: 8,
    generations: 2,
    restarts: 1,
};

/// The presets every sample mission is flown under.
pub const PRESETS: [Preset; 2] = [Preset::Ideal, Preset::Survey];

/// The fixed sample (Choice 443) and the shipped gains it starts from.
#[derive(Clone, Debug)]
pub struct Sample {
    pub missions: Vec<Scenario>,
    /// The shipped gains (the real chain's `[controller]`: the paper's).
    pub shipped: Gains,
    /// Theorem 4's ball at δ_max of the shipped gains.
    pub ball_limit: f64,
}

/// The sample of `spec`: the contract's disturbed random missions of its seed under
/// [`PRESETS`], shortened and flown study-grade.
pub fn sample(spec: &Spec) -> Result<Sample, ScenarioError> {
    let campaign = validation::Campaign {
        masks: Vec::new(),
        random: spec.missions,
        seed: spec.seed,
        navigation: PRESETS.to_vec(),
        disturbed: true,
    };
    let all = campaign.missions()?;
    let missions = (0..all.len())
        .map(|i| {
            all.get(i)?.with(|c| {
                c.duration = spec.duration;
                PlantStep::ControlPeriod.apply(c);
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let base = real_vehicle::real_scenarios()?.swap_remove(0);
    let c = base.config().controller;
    Ok(Sample {
        missions,
        shipped: Gains::of(&c),
        ball_limit: ball_at_delta_max(&c),
    })
}

/// The five objectives, in order.
pub const OBJECTIVES: [&str; 5] = [
    "max path (m)",
    "reversals (1/s)",
    "command TV (V/s)",
    "saturated",
    "time scale",
];

/// A candidate's scores over the sample (Choice 444).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// p95 of each objective ([`OBJECTIVES`]).
    pub p95: [f64; 5],
    /// Worst of each.
    pub worst: [f64; 5],
    /// Missions the preflight proposed no scale for.
    pub refused: usize,
    /// Flights that ended early or with a metric not a number.
    pub failed: usize,
    /// Flights within the real vehicle's bound at the proposed scale.
    pub within: usize,
}

impl Scores {
    /// What the search sees: the five p95s, and as the violation the missions refused or
    /// failed (a refused mission is not flown, so its path, chatter and saturation would
    /// otherwise go unscored: a candidate must not look better by being refused).
    pub fn scored(&self) -> nsga2::Scored {
        nsga2::Scored {
            objectives: self.p95.to_vec(),
            violation: (self.failed + self.refused) as f64,
        }
    }
}

/// The nearest-rank p-quantile of `xs` (p in (0, 1]; [`super::montecarlo::percentile`] of the
/// sorted values); NaN when empty.
pub fn quantile(xs: &[f64], p: f64) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    super::montecarlo::percentile(&v, p * 100.0)
}

/// `gains` over `sample` (missions in turn); `Err` on an interrupt or a failing check.
pub fn score(sample: &Sample, gains: &Gains, margin: f64) -> Result<Scores, String> {
    let mut cols: [Vec<f64>; 5] = Default::default();
    let (mut refused, mut failed, mut within) = (0, 0, 0);
    for m in &sample.missions {
        let m = m
            .with(|c| gains.apply(&mut c.controller))
            .map_err(|e| e.to_string())?;
        let flown = match validation::check_and_fly(&m, margin) {
            Ok(Some((_, f))) => f,
            Ok(None) => return Err("interrupted".to_string()),
            Err(CheckFlyError::AtScale { .. }) => None,
            Err(e) => return Err(e.to_string()),
        };
        let Some(f) = flown else {
            refused += 1;
            cols[4].push(f64::from(Trajectory::MAX_TIME_SCALE));
            continue;
        };
        let x = &f.metrics;
        let values = [
            x.max_path,
            x.reversals_per_s,
            x.command_tv,
            x.saturated_fraction,
        ];
        let scale = f64::from(f.scenario.config().time_scale);
        if !values.iter().all(|v| v.is_finite()) {
            failed += 1;
        }
        within += usize::from(f.within);
        for (c, v) in cols.iter_mut().zip(values) {
            c.push(if v.is_finite() { v } else { f64::INFINITY });
        }
        cols[4].push(scale);
    }
    let p = |c: &Vec<f64>, q: f64| if c.is_empty() { 0.0 } else { quantile(c, q) };
    Ok(Scores {
        p95: std::array::from_fn(|k| p(&cols[k], 0.95)),
        worst: std::array::from_fn(|k| p(&cols[k], 1.0)),
        refused,
        failed,
        within,
    })
}

/// One candidate, scored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    pub x: Vec<f64>,
    pub gains: Gains,
    pub scores: Scores,
}

/// One NSGA-II restart: its last population, and every candidate it flew.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Restart {
    pub index: u64,
    pub population: Vec<Candidate>,
    /// Every candidate flown, in order (the first population, then each generation's
    /// children): what the front is checked against (tests/tune.rs).
    #[serde(default)]
    pub evaluated: Vec<Candidate>,
    /// Candidates evaluated (flown over the sample).
    pub evaluations: usize,
    /// Candidates the constraint filter refused (drawn again, never flown).
    pub refused_by_law: usize,
    pub partial: bool,
}

/// Restart `index`'s generator: ChaCha8 of the seed on stream `index`.
fn rng(seed: u64, index: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(index);
    r
}

/// Draws an admissible point: `draw` until the filter passes (at most 1000 times; then the
/// shipped gains' point). Counts the refusals.
fn admissible_point(
    sample: &Sample,
    refused: &mut usize,
    mut draw: impl FnMut() -> Vec<f64>,
) -> Vec<f64> {
    for _ in 0..1000 {
        let x = draw();
        if admissible(
            &sample.missions[0],
            &Gains::from_unit(&x),
            sample.ball_limit,
        )
        .is_ok()
        {
            return x;
        }
        *refused += 1;
    }
    sample.shipped.to_unit()
}

/// Scores `points` in parallel, in order.
fn evaluate(
    sample: &Sample,
    points: Vec<Vec<f64>>,
    margin: f64,
    on_done: &(dyn Fn() + Sync),
) -> Result<Vec<Candidate>, String> {
    points
        .into_par_iter()
        .map(|x| {
            let gains = Gains::from_unit(&x);
            let scores = score(sample, &gains, margin);
            on_done();
            Ok(Candidate {
                x,
                gains,
                scores: scores?,
            })
        })
        .collect()
}

/// Restart `index` of `spec` on `sample`; `on_done` after each evaluation. An interrupt ends
/// it after its last whole generation, marked partial.
pub fn run_restart(
    spec: &Spec,
    sample: &Sample,
    index: u64,
    on_done: &(dyn Fn() + Sync),
) -> Result<Restart, String> {
    let mut r = rng(spec.seed, index);
    let mut refused = 0;
    let mut points = vec![sample.shipped.to_unit()];
    while points.len() < spec.population {
        let x = admissible_point(sample, &mut refused, || {
            (0..DIMS).map(|_| r.random::<f64>()).collect()
        });
        points.push(x);
    }
    let mut restart = Restart {
        index,
        population: Vec::new(),
        evaluated: Vec::new(),
        evaluations: 0,
        refused_by_law: 0,
        partial: false,
    };
    match evaluate(sample, points, spec.margin, on_done) {
        Ok(p) => restart.population = p,
        Err(e) if e == "interrupted" => {
            restart.partial = true;
            return Ok(restart);
        }
        Err(e) => return Err(e),
    }
    restart.evaluations = restart.population.len();
    restart.evaluated.clone_from(&restart.population);
    for _ in 0..spec.generations {
        if crate::interrupt::requested() {
            restart.partial = true;
            break;
        }
        let scored: Vec<nsga2::Scored> = restart
            .population
            .iter()
            .map(|c| c.scores.scored())
            .collect();
        let rc = nsga2::rank_and_crowding(&scored);
        let parents: Vec<Vec<f64>> = restart.population.iter().map(|c| c.x.clone()).collect();
        let mut children = Vec::with_capacity(spec.population);
        let mut pending: Vec<Vec<f64>> = Vec::new();
        while children.len() < spec.population {
            let x = admissible_point(sample, &mut refused, || {
                if pending.is_empty() {
                    pending.extend(nsga2::offspring(&parents, &rc, &mut r));
                }
                pending.remove(0)
            });
            children.push(x);
        }
        let children = match evaluate(sample, children, spec.margin, on_done) {
            Ok(c) => c,
            Err(e) if e == "interrupted" => {
                restart.partial = true;
                break;
            }
            Err(e) => return Err(e),
        };
        restart.evaluations += children.len();
        restart.evaluated.extend(children.iter().cloned());
        let mut all = std::mem::take(&mut restart.population);
        all.extend(children);
        let scored: Vec<nsga2::Scored> = all.iter().map(|c| c.scores.scored()).collect();
        let keep = nsga2::survivors(&scored, spec.population);
        restart.population = keep.into_iter().map(|i| all[i].clone()).collect();
    }
    restart.refused_by_law = refused;
    Ok(restart)
}

/// What one shard did (its `shard.json`): restarts r ≡ I (mod N).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardResult {
    pub spec: Spec,
    /// [I, N].
    pub shard: [u64; 2],
    pub restarts: Vec<Restart>,
    /// The shipped gains over the same sample (every shard scores them: the same numbers).
    pub shipped: Candidate,
    /// CPU-free wall-clock seconds of the shard and its evaluations.
    pub seconds: f64,
}

/// Runs shard `index`/`count` of `spec`; `on_done` after each evaluation.
pub fn run_shard(
    spec: &Spec,
    index: u64,
    count: u64,
    on_done: &(dyn Fn() + Sync),
) -> Result<ShardResult, String> {
    let start = std::time::Instant::now();
    let sample = sample(spec).map_err(|e| e.to_string())?;
    let shard = super::campaign::Shard {
        runs: spec.restarts,
        index,
        count,
    };
    let shipped = Candidate {
        x: sample.shipped.to_unit(),
        gains: sample.shipped,
        scores: score(&sample, &sample.shipped, spec.margin)?,
    };
    let mut restarts = Vec::new();
    for k in 0..shard.len() {
        if crate::interrupt::requested() {
            break;
        }
        restarts.push(run_restart(spec, &sample, shard.run(k), on_done)?);
    }
    Ok(ShardResult {
        spec: spec.clone(),
        shard: [index, count],
        restarts,
        shipped,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A study: the front, the shipped gains and the chosen point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Study {
    pub spec: Spec,
    /// The non-dominated candidates of every candidate the restarts flew, by their first
    /// objective (ties by the coordinates).
    pub front: Vec<Candidate>,
    pub shipped: Candidate,
    /// Index into `front`.
    pub chosen: Option<usize>,
    pub evaluations: usize,
    pub refused_by_law: usize,
    /// The restarts no shard ran, or that were interrupted.
    pub missing: Vec<String>,
    pub seconds: f64,
}

/// Why shards do not merge.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MergeError {
    #[error("no shard given")]
    Empty,
    #[error("shard {0} is of another study (its spec differs from the first shard's)")]
    OtherSpec(usize),
    #[error("restart {0} is in more than one shard")]
    Twice(u64),
}

/// The shards as one study (Choice 496).
pub fn merge(shards: &[ShardResult]) -> Result<Study, MergeError> {
    let first = shards.first().ok_or(MergeError::Empty)?;
    let spec = first.spec.clone();
    if let Some(i) = shards.iter().position(|s| s.spec != spec) {
        return Err(MergeError::OtherSpec(i));
    }
    let mut restarts: Vec<&Restart> = shards.iter().flat_map(|s| &s.restarts).collect();
    restarts.sort_by_key(|r| r.index);
    for w in restarts.windows(2) {
        if w[0].index == w[1].index {
            return Err(MergeError::Twice(w[0].index));
        }
    }
    let mut missing: Vec<String> = (0..spec.restarts)
        .filter(|i| !restarts.iter().any(|r| r.index == *i))
        .map(|i| format!("restart {i}"))
        .collect();
    missing.extend(
        restarts
            .iter()
            .filter(|r| r.partial)
            .map(|r| format!("restart {} (interrupted)", r.index)),
    );
    // The front is over every candidate a restart flew, not only its last population: NSGA-II's
    // crowding truncation drops non-dominated candidates when the first front outgrows the
    // population, and a dropped one is still a point the study measured (tests/tune.rs checks
    // the front against every flown candidate by brute force). A shard file written before
    // `evaluated` existed gives its population.
    let all: Vec<Candidate> = restarts
        .iter()
        .flat_map(|r| {
            if r.evaluated.is_empty() {
                r.population.iter().cloned()
            } else {
                r.evaluated.iter().cloned()
            }
        })
        .collect();
    let scored: Vec<nsga2::Scored> = all.iter().map(|c| c.scores.scored()).collect();
    let first_front = nsga2::non_dominated_sort(&scored)
        .into_iter()
        .next()
        .unwrap_or_default();
    let mut front: Vec<Candidate> = first_front.into_iter().map(|i| all[i].clone()).collect();
    front.sort_by(|a, b| {
        a.scores.p95[0].total_cmp(&b.scores.p95[0]).then_with(|| {
            a.x.iter()
                .zip(&b.x)
                .fold(std::cmp::Ordering::Equal, |o, (p, q)| {
                    o.then(p.total_cmp(q))
                })
        })
    });
    front.dedup_by(|a, b| a.x == b.x);
    let chosen = choose(&front, &first.shipped);
    Ok(Study {
        spec,
        chosen,
        shipped: first.shipped.clone(),
        evaluations: restarts.iter().map(|r| r.evaluations).sum(),
        refused_by_law: restarts.iter().map(|r| r.refused_by_law).sum(),
        front,
        missing,
        seconds: shards.iter().map(|s| s.seconds).sum(),
    })
}

/// Floors added to both sides of a ratio to the shipped score (an objective at 0 compares by
/// its floor): 1 mm, 0.1 reversal/s, 1 V/s, 0.1 % saturated, 0.01 of time scale.
pub const RATIO_FLOORS: [f64; 5] = [1e-3, 0.1, 1.0, 1e-3, 0.01];

/// A candidate's worst ratio to the shipped gains' p95 over the five objectives (< 1: better
/// on every one).
pub fn worst_ratio(c: &Candidate, shipped: &Candidate) -> f64 {
    (0..5)
        .map(|k| (c.scores.p95[k] + RATIO_FLOORS[k]) / (shipped.scores.p95[k] + RATIO_FLOORS[k]))
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The chosen point (Choice 446): of the front's candidates with no failed flight and no more
/// refused missions than the shipped gains, the least [`worst_ratio`] (ties: the first).
pub fn choose(front: &[Candidate], shipped: &Candidate) -> Option<usize> {
    front
        .iter()
        .enumerate()
        .filter(|(_, c)| c.scores.failed == 0 && c.scores.refused <= shipped.scores.refused)
        .map(|(i, c)| (i, worst_ratio(c, shipped)))
        .fold(None, |best: Option<(usize, f64)>, (i, r)| match best {
            Some((_, b)) if b <= r => best,
            _ => Some((i, r)),
        })
        .map(|(i, _)| i)
}
