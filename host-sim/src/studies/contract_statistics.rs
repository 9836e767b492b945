//! The contract with its statistics (docs/search.md#the-contract-in-the-main-jobs-report): per
//! navigation preset the contract flies, "N false feasible in S sampled and A adversarial
//! evaluations; 95 % upper bound on the false-feasible rate: x %" ([`rate_bound::Counts`]).
//!
//! **Choice 471:** the sampled evaluations are the contract's random missions of the preset
//! that were flown at a proposed scale ([`MissionResult::sampled`]): independent draws, so they
//! bound a rate; its matrix of real paths × mountings is an enumeration, counted in the
//! contract's own line and not in the rate. **Choice 472:** the adversarial ones are a small
//! fixed-seed search of the contract's mission space on that preset
//! ([`falsify::Setup::with_navigation`]): one restart of the cross-entropy method,
//! [`SEARCH_BUDGET`] evaluations of [`SEARCH_DURATION`]-s missions from seed [`SEARCH_SEED`],
//! against the real preflight at the contract's margin. The random search beside it in
//! `falsify` is not flown here: the contract's random missions are that sample.

use super::falsify::{self, Evaluation, Method, Restart, Setup, Spec};
use super::mission_space::Reach;
use super::preflight::DEFAULT_MARGIN;
use super::rate_bound::Counts;
use super::validation::{MissionResult, Validation};
use crate::scenario::navigation::Preset;
use crate::scenario::ScenarioError;

/// Evaluations of the main job's search per preset (Choice 472).
pub const SEARCH_BUDGET: usize = 200;
/// Each candidate's duration at time scale 1 (s): shorter than the contract's 70 s, so that
/// the search costs what the contract's flights do.
pub const SEARCH_DURATION: f64 = 20.0;
/// The search's seed: the same search in every run of the main job.
pub const SEARCH_SEED: u64 = 1;

/// The main job's search on `preset`, as a falsification's spec (one restart, so `falsify
/// --reach contract --navigation P --budget B --restarts 1 --duration D --seed S` runs it and
/// the random search beside it).
pub fn search_spec(preset: Preset) -> Spec {
    Spec {
        reach: Reach::Contract,
        margin: DEFAULT_MARGIN,
        duration: SEARCH_DURATION,
        seed: SEARCH_SEED,
        budget: SEARCH_BUDGET,
        restarts: 1,
        navigation: Some(preset),
        refused: falsify::Refused::Graded,
    }
}

/// The command that runs [`search_spec`] with random search beside it.
pub fn search_command(preset: Preset) -> String {
    let s = search_spec(preset);
    format!(
        "host-sim falsify --reach contract --navigation {} --budget {} --restarts {} \
         --duration {} --seed {} --margin {} --out runs/falsify-{}",
        preset.name(),
        s.budget,
        s.restarts,
        s.duration,
        s.seed,
        s.margin,
        preset.name()
    )
}

/// The cross-entropy restart of [`search_spec`] on `preset`; `on_done` after each evaluation.
pub fn search(preset: Preset, on_done: &(dyn Fn() + Sync)) -> Result<Restart, String> {
    let spec = search_spec(preset);
    let setup: Setup = spec.setup().map_err(|e: ScenarioError| e.to_string())?;
    falsify::run_restart(
        &setup,
        Method::CrossEntropy,
        spec.seed,
        0,
        spec.budget,
        on_done,
    )
}

/// One preset's statistics.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PresetStatistics {
    pub navigation: Preset,
    pub counts: Counts,
    /// The least robustness of the search (`None`: not searched, or nothing counted).
    pub least_robustness: Option<f64>,
    /// The search stopped early (an interrupt).
    pub partial: bool,
}

impl PresetStatistics {
    /// The contract's figures on `preset` from `v` and the search `restart` on it.
    pub fn of(preset: Preset, v: &Validation, restart: Option<&Restart>) -> Self {
        let sampled: Vec<&MissionResult> = v
            .missions
            .iter()
            .filter(|m| m.navigation == preset && m.sampled && m.within.is_some())
            .collect();
        let trace: Vec<f64> = restart
            .map(|r| r.trace.iter().flatten().copied().collect())
            .unwrap_or_default();
        PresetStatistics {
            navigation: preset,
            counts: Counts {
                sampled: sampled.len() as u64,
                sampled_false_feasible: sampled.iter().filter(|m| m.false_feasible()).count()
                    as u64,
                adversarial: trace.len() as u64,
                adversarial_false_feasible: trace
                    .iter()
                    .filter(|v| Evaluation::is_false_feasible(**v))
                    .count() as u64,
            },
            least_robustness: restart.and_then(Restart::min_robustness),
            partial: restart.is_some_and(|r| r.partial),
        }
    }

    /// Whether a false feasible was found, sampled or adversarial.
    pub fn broken(&self) -> bool {
        self.counts.sampled_false_feasible + self.counts.adversarial_false_feasible > 0
    }
}

/// The report's section: a sentence per preset, what was searched and at what cost, and the
/// command that runs each search with random search beside it.
pub fn markdown(stats: &[PresetStatistics], seconds: f64, written: &[String]) -> String {
    let mut s = format!(
        "### The contract's statistics (docs/search.md#the-contract-in-the-main-jobs-report)\n\n\
         Sampled: the contract's random missions flown at the proposed scale (independent \
         draws). Adversarial: the cross-entropy method over the contract's mission space, \
         {SEARCH_BUDGET} evaluations of {SEARCH_DURATION} s missions from seed {SEARCH_SEED} \
         per preset against the real preflight ({seconds:.1} s of wall time for all presets).\n\n"
    );
    for p in stats {
        s += &format!(
            "- **{}**: {}{}{}.\n",
            p.navigation.name(),
            p.counts.sentence(),
            p.least_robustness.map_or(String::new(), |r| format!(
                "; least robustness searched {r:.4}"
            )),
            if p.partial { " (search PARTIAL)" } else { "" },
        );
    }
    let unflown: Vec<&str> = Preset::ALL
        .iter()
        .filter(|p| !stats.iter().any(|s| s.navigation == **p))
        .map(|p| p.name())
        .collect();
    if !unflown.is_empty() {
        s += &format!(
            "- not flown by this contract: {} (`host-sim validate-preflight --navigation …` \
             samples them, the command below with that preset searches them).\n",
            unflown.join(", ")
        );
    }
    s += "\nEach search with random search beside it at the same budget, and its falsifying \
          mission as a scenario file:\n\n```text\n";
    for p in stats {
        s += &search_command(p.navigation);
        s += "\n";
    }
    s += "```\n";
    if !written.is_empty() {
        s += "\nFalsifying missions the search found (at the proposed scale; `host-sim run \
              --scenario FILE` flies each bit for bit):\n\n";
        for f in written {
            s += &format!("- `{f}`\n");
        }
    }
    s
}
