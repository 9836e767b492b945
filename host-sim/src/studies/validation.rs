//! Does the preflight's verdict hold? (docs/real-vehicle.md#the-preflights-contract). A
//! campaign that checks missions and then flies them: for each mission `check`'s verdict and
//! proposed time scale (the mission as written), the flight at that scale through the real
//! chain, and — by flying — the smallest scale that actually stays within the bound.
//!
//! Two numbers come out: **false feasible**, missions the preflight called feasible at its
//! proposed scale that missed the bound when flown (it must be 0: a team flies on that
//! verdict), and **conservativeness**, the median over the flown missions of the proposed
//! scale over the smallest scale that flies (≥ 1: how much slower than necessary the verdict
//! makes a team fly).
//!
//! The missions: the Table-1 paths of `scenarios/real/` under each thruster mounting of a
//! list (the AUV-150 layout's reversed-thruster masks), and random missions (path kind, size,
//! speed, mounting, a payload inside the box with a constant, abs-sin or staircase profile, a
//! constant current), each deterministic from (seed, index) and made when it is flown
//! ([`Missions`]).

use controller_core::effectiveness::{ThrusterGeometry, THRUSTERS};
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::mission_space::{self, Reach};
use super::preflight::{self, CheckError, Verdict};
use crate::interrupt;
use crate::plant::CurrentModel;
use crate::scenario::navigation::Preset;
use crate::scenario::{real_vehicle, Scenario, ScenarioError, SimConfig};
use crate::sim::{self, bound, LocalController, Recording};

/// The vertical × horizontal mountings a team would build: each vertical pair combination
/// (down, fore up, aft up, both up) with both horizontal thrusters to starboard or to port,
/// the main thruster forward. Bits as [`ThrusterGeometry::auv150`].
pub const TEAM_MOUNTINGS: [u8; 8] = [0, 24, 2, 26, 4, 28, 6, 30];

/// Every mask of the AUV-150 layout (every one is a valid, invertible geometry).
pub fn all_mountings() -> Vec<u8> {
    (0..1u8 << THRUSTERS).collect()
}

pub use super::mission_space::RANDOM_MAX_CURRENT;
/// A random mission's thruster time constant is drawn in this range (s): real thrusters answer
/// in 0.05–0.3 s (issue 28's missions).
pub const RANDOM_LAG: [f64; 2] = [0.05, 0.3];
/// A Gauss–Markov current's σ per horizontal axis is drawn in this range (m/s), its
/// correlation time [`RANDOM_GM_TAU`].
pub const RANDOM_GM_SIGMA: [f64; 2] = [0.02, 0.05];
/// … its correlation time (s).
pub const RANDOM_GM_TAU: f64 = 60.0;
// The disturbed contract's draws lie inside the space the falsifier searches
// (`mission_space`), so a falsifier's verdict covers them: checked when this compiles.
const _: () = {
    use super::mission_space::{GM_TAU_RANGE, MAX_GM_SIGMA, MAX_LAG};
    assert!(0.0 <= RANDOM_LAG[0] && RANDOM_LAG[1] <= MAX_LAG);
    assert!(0.0 <= RANDOM_GM_SIGMA[0] && RANDOM_GM_SIGMA[1] <= MAX_GM_SIGMA);
    assert!(GM_TAU_RANGE[0] <= RANDOM_GM_TAU && RANDOM_GM_TAU <= GM_TAU_RANGE[1]);
};
/// Relative resolution of the smallest flying time scale, found by bisection.
pub const FLYING_TOLERANCE: f64 = 0.02;

/// Which missions a campaign flies: the real paths under each mounting of `masks`, and
/// `random` random missions from `seed`, all of them under each navigation preset of
/// `navigation` (Choice 373).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Campaign {
    pub masks: Vec<u8>,
    pub random: usize,
    pub seed: u64,
    pub navigation: Vec<Preset>,
    /// Whether the random missions draw a thruster lag and (on half) a Gauss–Markov current
    /// (Choice 373; off by default until the check answers for them: measured, docs).
    pub disturbed: bool,
}

/// The presets the contract flies every mission under (Choice 373): the exact state (told as
/// is, the estimator off) and the real chain's default.
pub const CONTRACT_PRESETS: [Preset; 2] = [Preset::Ideal, Preset::Survey];

impl Default for Campaign {
    /// The contract's campaign (docs/real-vehicle.md#the-preflights-contract): every mounting, 200 random missions, seed 1.
    fn default() -> Self {
        Campaign {
            masks: all_mountings(),
            random: DEFAULT_RANDOM,
            seed: 1,
            navigation: CONTRACT_PRESETS.to_vec(),
            disturbed: false,
        }
    }
}

impl Campaign {
    /// Its missions, made one at a time as they are flown ([`Missions::get`]): the matrix,
    /// then the random ones. Only the six real scenarios are read here, so the memory does not
    /// grow with [`Campaign::random`] (**Choice 303**).
    pub fn missions(&self) -> Result<Missions<'_>, ScenarioError> {
        Ok(Missions {
            campaign: self,
            real: real_vehicle::real_scenarios()?,
        })
    }
}

/// A campaign's missions, by index: mission i is made when it is asked for (the matrix's
/// real path i mod 6 under mounting i / 6, then random mission i − matrix), deterministic
/// from the campaign alone.
#[derive(Clone, Debug)]
pub struct Missions<'a> {
    campaign: &'a Campaign,
    real: Vec<Scenario>,
}

impl Missions<'_> {
    /// How many: the real paths under each mounting, and the random ones, under each preset.
    pub fn len(&self) -> usize {
        (self.matrix_len() + self.campaign.random) * self.campaign.navigation.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether mission `i` is one of the random missions (under any preset).
    pub fn is_sampled(&self, i: usize) -> bool {
        i % (self.matrix_len() + self.campaign.random) >= self.matrix_len()
    }

    fn matrix_len(&self) -> usize {
        self.campaign.masks.len() * self.real.len()
    }

    /// Mission `i` (< [`Missions::len`]): mission i mod (matrix + random) of the list, under
    /// preset i / (matrix + random), its navigation seed drawn from (seed, i).
    pub fn get(&self, i: usize) -> Result<Scenario, ScenarioError> {
        let per_preset = self.matrix_len() + self.campaign.random;
        let (preset, j) = (self.campaign.navigation[i / per_preset], i % per_preset);
        let mission = match j.checked_sub(self.matrix_len()) {
            None => matrix_mission(
                &self.real[j % self.real.len()],
                self.campaign.masks[j / self.real.len()],
            ),
            Some(r) => random_mission(
                &self.real[0],
                self.campaign.seed,
                r,
                self.campaign.disturbed,
            ),
        }?;
        let seed = rand::rngs::StdRng::seed_from_u64(
            self.campaign.seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
        )
        .random::<u64>();
        // The real chain's own filter (a random mission is drawn without one).
        let filter = self.real[0].config().controller.estimator.kind;
        mission_space::under_preset(&mission, preset, seed, filter)?
            .with(|c| c.name = format!("{}-{}", c.name, preset.name()))
    }
}

/// Random missions of the contract's campaign.
pub const DEFAULT_RANDOM: usize = 200;

/// The campaign's two numbers and what they count, for reports and JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContractSummary {
    pub campaign: Campaign,
    pub missions: usize,
    pub flown: usize,
    pub refused: usize,
    pub false_feasible: usize,
    pub median_ratio: f64,
    pub partial: bool,
}

/// One mission of the campaign, and what became of it.
#[derive(Clone, Debug, Serialize)]
pub struct MissionResult {
    pub name: String,
    /// The navigation preset it was checked and flown on.
    pub navigation: Preset,
    /// The reversed-thruster mask.
    pub mounting: u8,
    /// The preflight's verdict at time scale 1 (as written).
    pub verdict: Verdict,
    /// The time scale the preflight proposes (`None`: it proposes none — refused).
    pub proposed: Option<f64>,
    /// The flight at the proposed scale: max path error (m), saturated fraction, and whether
    /// it stayed within the bound.
    pub max_path: Option<f64>,
    pub saturated: Option<f64>,
    pub within: Option<bool>,
    /// The smallest time scale (to [`FLYING_TOLERANCE`]) at which a flight stays within the
    /// bound, when the proposed one does.
    pub smallest_flying: Option<f64>,
    /// One of the campaign's random missions (an independent draw), not of its matrix of real
    /// paths × mountings (an enumeration): only these bound a rate (Choice 471).
    pub sampled: bool,
}

impl MissionResult {
    /// Called feasible at its proposed scale, and missed there.
    pub fn false_feasible(&self) -> bool {
        self.within == Some(false)
    }

    /// Proposed scale over the smallest that flies (≥ 1).
    pub fn ratio(&self) -> Option<f64> {
        Some(self.proposed? / self.smallest_flying?)
    }
}

/// The campaign's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    pub missions: Vec<MissionResult>,
    /// Missions flown (the preflight proposed a scale).
    pub flown: usize,
    /// Missions the preflight refused (no feasible scale).
    pub refused: usize,
    pub false_feasible: usize,
    /// Median of [`MissionResult::ratio`] over the flown missions within bound.
    pub median_ratio: f64,
    /// The same numbers per navigation preset (Choice 373).
    pub per_preset: Vec<PresetFigures>,
    /// Interrupted: the missions not yet done are missing.
    pub partial: bool,
}

/// The real mission `s` under the mounting `mask`, at time scale 1.
fn matrix_mission(s: &Scenario, mask: u8) -> Result<Scenario, ScenarioError> {
    s.with(|c| {
        c.name = format!("{}-m{mask:02}", c.name);
        c.controller.geometry = ThrusterGeometry::auv150(mask);
        // The file's time scale is its own mounting's; the campaign asks anew.
        c.duration /= f64::from(c.time_scale);
        c.time_scale = 1.0;
    })
}

/// Random mission `i` of `seed`, on the first real mission `base` (see the module docs): it
/// depends only on (seed, i), drawn by [`mission_space::mission`] from a generator (Choice
/// 410); `disturbed` then draws its thrusters' lag and, on half of them, a Gauss–Markov current
/// about the drawn mean (Choice 373). A draw the core refuses (a tangent heading too slow
/// somewhere) is drawn again.
fn random_mission(
    base: &Scenario,
    seed: u64,
    i: usize,
    disturbed: bool,
) -> Result<Scenario, ScenarioError> {
    let mut rng =
        rand::rngs::StdRng::seed_from_u64(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    loop {
        let name = format!("random-{i:03}");
        let made = mission_space::mission(base, Reach::Contract, name, CONTRACT_DURATION, &mut rng)
            .and_then(|s| {
                if disturbed {
                    disturb(&s, &mut rng)
                } else {
                    Ok(s)
                }
            });
        match made {
            Ok(s) => return Ok(s),
            // Too slow for the tangent heading somewhere: draw again.
            Err(ScenarioError::Invalid { key, .. }) if key.starts_with("trajectory") => continue,
            Err(e) => return Err(e),
        }
    }
}

/// A contract mission with the thrusters' lag drawn in [`RANDOM_LAG`] and, on half of the
/// missions, a Gauss–Markov current of σ in [`RANDOM_GM_SIGMA`] about its constant one (Choice
/// 373).
fn disturb(s: &Scenario, rng: &mut impl RngExt) -> Result<Scenario, ScenarioError> {
    let lag = RANDOM_LAG[0] + (RANDOM_LAG[1] - RANDOM_LAG[0]) * rng.random::<f64>();
    let wander = rng.random::<bool>();
    let sigma =
        RANDOM_GM_SIGMA[0] + (RANDOM_GM_SIGMA[1] - RANDOM_GM_SIGMA[0]) * rng.random::<f64>();
    let seed = rng.random::<u64>();
    s.with(|c: &mut SimConfig| {
        c.thruster_lag = Some(lag);
        if let (true, CurrentModel::Constant(mean)) = (wander, &c.current) {
            c.current = CurrentModel::GaussMarkov {
                mean: *mean,
                sigma: [sigma, sigma, 0.0],
                tau: RANDOM_GM_TAU,
                seed,
            };
        }
    })
}

/// How long the contract's random missions fly (s, at time scale 1): the paper's 70 s.
pub const CONTRACT_DURATION: f64 = 70.0;

/// `base` at time scale `k`: the same path (its duration scaled).
fn at_scale(base: &Scenario, k: f64) -> Result<Scenario, ScenarioError> {
    let cfg = base.config();
    let span = cfg.duration / f64::from(cfg.time_scale);
    base.with(|c| {
        c.time_scale = k as f32;
        c.duration = span * k;
    })
}

/// Flies `scenario` (metrics only); within the bound?
fn flies(scenario: &Scenario) -> (bool, sim::Metrics) {
    let run = sim::fly(
        scenario,
        &mut LocalController::new(scenario),
        &mut (),
        Recording::MetricsOnly,
    );
    (bound::within_bound(&run), run.metrics)
}

/// What a campaign measures besides the false-feasible count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    /// Only whether each proposed scale flies within the bound.
    Verdicts,
    /// Also the smallest scale that flies, by bisection (about six flights more a mission).
    Conservativeness,
}

/// A mission flown at the time scale the preflight proposed.
#[derive(Clone, Debug)]
pub struct Flown {
    /// The mission at the proposed scale (what was flown).
    pub scenario: Scenario,
    pub metrics: sim::Metrics,
    /// Completed within the real vehicle's bound ([`bound::within_bound`]).
    pub within: bool,
}

/// Why [`check_and_fly`] has no answer.
#[derive(Debug, thiserror::Error)]
pub enum CheckFlyError {
    /// The check itself failed.
    #[error("{0}")]
    Check(CheckError),
    /// The core refuses the mission at the scale the preflight proposed (a tangent heading
    /// too slow there, say).
    #[error("at the proposed time scale {scale}: {error}")]
    AtScale { scale: f64, error: ScenarioError },
}

/// Checks one mission as written and flies it at the proposed scale, as the contract does
/// (see the module docs); `None` if a stop was requested ([`crate::interrupt`]) during its
/// check. The flight is `None` when the preflight proposes no scale.
pub fn check_and_fly(
    base: &Scenario,
    margin: f64,
) -> Result<Option<(MissionResult, Option<Flown>)>, CheckFlyError> {
    Ok(check_and_fly_report(base, margin)?.map(|(_, result, flown)| (result, flown)))
}

/// [`check_and_fly`], with the check's own report (what a refused mission missed by: the
/// falsifier's graded score, docs/search.md#refused-candidates).
///
/// # Errors
/// As [`check_and_fly`].
pub fn check_and_fly_report(
    base: &Scenario,
    margin: f64,
) -> Result<Option<(preflight::Preflight, MissionResult, Option<Flown>)>, CheckFlyError> {
    let p = match preflight::check_as_written(base, margin) {
        Ok(p) => p,
        Err(CheckError::Interrupted) => return Ok(None),
        Err(e) => return Err(CheckFlyError::Check(e)),
    };
    let mounting = base
        .config()
        .controller
        .geometry
        .auv150_reversed()
        .unwrap_or(u8::MAX);
    let proposed = match p.verdict {
        Verdict::Feasible => Some(p.time_scale),
        _ => p.smallest_time_scale,
    };
    let mut out = MissionResult {
        name: base.config().name.clone(),
        navigation: base
            .config()
            .navigation
            .as_ref()
            .map_or(Preset::Ideal, |m| m.preset),
        mounting,
        verdict: p.verdict,
        proposed,
        max_path: None,
        saturated: None,
        within: None,
        smallest_flying: None,
        sampled: false,
    };
    let Some(k) = proposed else {
        return Ok(Some((p, out, None)));
    };
    let scenario = at_scale(base, k).map_err(|error| CheckFlyError::AtScale { scale: k, error })?;
    let (within, metrics) = flies(&scenario);
    (out.max_path, out.saturated, out.within) = (
        Some(metrics.max_path),
        Some(metrics.saturated_fraction),
        Some(within),
    );
    Ok(Some((
        p,
        out,
        Some(Flown {
            scenario,
            metrics,
            within,
        }),
    )))
}

/// Checks and flies one mission (see the module docs); `None` if a stop was requested
/// ([`crate::interrupt`]) during its check.
pub fn validate_one(
    base: &Scenario,
    margin: f64,
    measure: Measure,
) -> Result<Option<MissionResult>, String> {
    let Some((mut out, flown)) = check_and_fly(base, margin).map_err(|e| e.to_string())? else {
        return Ok(None);
    };
    if let (Some(k), Some(f)) = (out.proposed, flown) {
        if f.within && measure == Measure::Conservativeness {
            let scenario = |k: f64| at_scale(base, k).map_err(|e| e.to_string());
            out.smallest_flying = Some(smallest_flying(k, &mut |k| Ok(flies(&scenario(k)?).0))?);
        }
    }
    Ok(Some(out))
}

/// The smallest scale in [1, `k`] at which `flies_at` holds, given that it holds at `k`, by
/// bisection to [`FLYING_TOLERANCE`] (assuming it holds from some scale on).
fn smallest_flying(
    k: f64,
    flies_at: &mut dyn FnMut(f64) -> Result<bool, String>,
) -> Result<f64, String> {
    if k <= 1.0 || flies_at(1.0)? {
        return Ok(1.0);
    }
    let (mut lo, mut hi) = (1.0, k);
    while hi / lo > 1.0 + FLYING_TOLERANCE && !interrupt::requested() {
        let mid = (lo * hi).sqrt();
        if flies_at(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}

/// The campaign over `missions`, in parallel, each mission made when its turn comes (a stop
/// requested, [`crate::interrupt`], is seen before each is made: Choice 303); `on_done` is
/// called after each mission.
pub fn validate(
    missions: &Missions<'_>,
    margin: f64,
    measure: Measure,
    on_done: impl Fn() + Sync,
) -> Result<Validation, String> {
    let results: Result<Vec<Option<MissionResult>>, String> = (0..missions.len())
        .into_par_iter()
        .map(|i| {
            if interrupt::requested() {
                return Ok(None);
            }
            let m = missions.get(i).map_err(|e| e.to_string())?;
            let r = validate_one(&m, margin, measure).map(|r| {
                r.map(|r| MissionResult {
                    sampled: missions.is_sampled(i),
                    ..r
                })
            });
            on_done();
            r
        })
        .collect();
    let done: Vec<MissionResult> = results?.into_iter().flatten().collect();
    let mut presets: Vec<Preset> = Vec::new();
    for m in &done {
        if !presets.contains(&m.navigation) {
            presets.push(m.navigation);
        }
    }
    let per_preset = presets
        .into_iter()
        .map(|p| {
            let of: Vec<&MissionResult> = done.iter().filter(|m| m.navigation == p).collect();
            PresetFigures::of(p, &of)
        })
        .collect();
    let all: Vec<&MissionResult> = done.iter().collect();
    let whole = PresetFigures::of(Preset::Ideal, &all);
    Ok(Validation {
        flown: whole.flown,
        refused: whole.refused,
        false_feasible: whole.false_feasible,
        median_ratio: whole.median_ratio,
        partial: done.len() < missions.len(),
        per_preset,
        missions: done,
    })
}

/// The contract's numbers over the missions flown on one navigation preset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PresetFigures {
    pub navigation: Preset,
    pub missions: usize,
    pub flown: usize,
    pub refused: usize,
    pub false_feasible: usize,
    pub median_ratio: f64,
}

/// A median conservativeness as the reports print it: `1.12×`, or `—` when no mission was flown
/// within its bound (the median of nothing; `NaN` in the figures, `null` in JSON).
pub fn median_text(ratio: f64) -> String {
    if ratio.is_finite() {
        format!("{ratio:.2}×")
    } else {
        "—".to_string()
    }
}

impl PresetFigures {
    fn of(navigation: Preset, done: &[&MissionResult]) -> Self {
        let mut ratios: Vec<f64> = done.iter().filter_map(|m| m.ratio()).collect();
        ratios.sort_by(f64::total_cmp);
        PresetFigures {
            navigation,
            missions: done.len(),
            flown: done.iter().filter(|m| m.within.is_some()).count(),
            refused: done.iter().filter(|m| m.proposed.is_none()).count(),
            false_feasible: done.iter().filter(|m| m.false_feasible()).count(),
            median_ratio: ratios.get(ratios.len() / 2).copied().unwrap_or(f64::NAN),
        }
    }

    /// One line: `survey: 392 missions, 380 flown, 12 refused, false feasible 0, median 1.10×`.
    pub fn line(&self) -> String {
        format!(
            "{}: {} missions, {} flown, {} refused, false feasible {}, conservativeness median {}",
            self.navigation.name(),
            self.missions,
            self.flown,
            self.refused,
            self.false_feasible,
            median_text(self.median_ratio)
        )
    }
}

impl Validation {
    /// Its two numbers, for `campaign`.
    pub fn summary(&self, campaign: &Campaign) -> ContractSummary {
        ContractSummary {
            campaign: campaign.clone(),
            missions: self.missions.len(),
            flown: self.flown,
            refused: self.refused,
            false_feasible: self.false_feasible,
            median_ratio: self.median_ratio,
            partial: self.partial,
        }
    }

    /// The two numbers in a sentence.
    pub fn headline(&self) -> String {
        format!(
            "preflight contract: {} missions{}, {} flown at the proposed time scale, {} refused; \
             false feasible {}; conservativeness median {} (proposed / smallest flying scale)",
            self.missions.len(),
            if self.partial { " (PARTIAL)" } else { "" },
            self.flown,
            self.refused,
            self.false_feasible,
            median_text(self.median_ratio)
        ) + &self
            .per_preset
            .iter()
            .map(|p| format!("; {}", p.line()))
            .collect::<String>()
    }

    /// The report: the two numbers, then one row per mission.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "## The preflight's contract (docs/real-vehicle.md#the-preflights-contract)\n\n\
             {} missions{}: {} flown at the time scale `check` proposes, {} refused (no feasible \
             scale). **False feasible: {}** (called feasible, missed the bound when flown). \
             **Conservativeness: median {}** (the proposed scale over the smallest that \
             flies within the bound, found by flying).\n\n\
             {}\n\n\
             | mission | mounting | verdict at k = 1 | proposed k | max path (m) | saturated | \
             within bound | smallest flying k |\n|---|---|---|---:|---:|---:|---|---:|\n",
            self.missions.len(),
            if self.partial {
                " (PARTIAL: interrupted)"
            } else {
                ""
            },
            self.flown,
            self.refused,
            self.false_feasible,
            median_text(self.median_ratio),
            self.per_preset
                .iter()
                .map(|p| format!("- {}", p.line()))
                .collect::<Vec<_>>()
                .join("\n")
        );
        let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("—".to_string(), f);
        for m in &self.missions {
            s += &format!(
                "| {} | {:05b} | {} | {} | {} | {} | {} | {} |\n",
                m.name,
                m.mounting,
                m.verdict.as_str(),
                opt(m.proposed, &|k| format!("{k}")),
                opt(m.max_path, &|v| format!("{v:.4}")),
                opt(m.saturated, &|v| format!("{:.1} %", 100.0 * v)),
                match m.within {
                    Some(true) => "yes",
                    Some(false) => "**NO**",
                    None => "—",
                },
                opt(m.smallest_flying, &|k| format!("{k:.2}")),
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A preset under which every mission was refused (the contract's `low-cost`) has no
    /// median: its line says so instead of printing `NaN×`.
    #[test]
    fn a_preset_with_nothing_flown_prints_no_median() {
        let refused = MissionResult {
            name: "random-000-low-cost".to_string(),
            navigation: Preset::LowCost,
            mounting: 0,
            verdict: Verdict::StaticallyInfeasible,
            proposed: None,
            max_path: None,
            saturated: None,
            within: None,
            smallest_flying: None,
            sampled: true,
        };
        let line = PresetFigures::of(Preset::LowCost, &[&refused]).line();
        assert!(line.ends_with("conservativeness median —"), "{line}");
        assert!(!line.contains("NaN"), "{line}");
        assert_eq!(median_text(1.1234), "1.12×");
    }
}
