//! The real vehicle (docs/real-vehicle.md#the-real-missions): the six missions of `scenarios/real/` — the Table-1
//! paths with the tangent heading, the Table-3 payload trimmed, Eqs 31–32 in kgf, the real
//! actuator chain, each at the time scale `host-sim check` proposes — and the paper's own six
//! missions through the same real chain ([`paper_real_chain`]), which `host-sim table1` flies
//! after the paper's Table 1 and reports in a second table.
//!
//! The files are the one definition of the real missions: they are compiled in
//! ([`REAL_SCENARIOS`]), so `table1` flies exactly what `check --scenario` checks.

use controller_core::{ControllerConfig, Table1Case};

use super::{paper, parse_scenario, Scenario, ScenarioError, SimConfig};

/// `[(file name, its text)]` of files of `scenarios/real/`, each name written once.
macro_rules! shipped {
    ($($file:literal),* $(,)?) => {
        [$(($file, include_str!(concat!("../../scenarios/real/", $file)))),*]
    };
}

/// The six real missions, in the order of [`Table1Case::ALL`]: (file name, its text).
pub const REAL_SCENARIOS: [(&str, &str); 6] = shipped![
    "circular-10R.toml",
    "circular-20R.toml",
    "figure-eight-30x30.toml",
    "figure-eight-40x40.toml",
    "lawn-mower-20x10.toml",
    "lawn-mower-30x15.toml",
];

/// The real vehicle's waypoint missions (docs/missions.md#waypoint-paths), flown in the same table after
/// [`REAL_SCENARIOS`]: (file name, its text).
pub const WAYPOINT_SCENARIOS: [(&str, &str); 3] =
    shipped!["survey-200x100.toml", "harbour-wall.toml", "pipeline.toml"];

/// The waypoint missions, validated ([`WAYPOINT_SCENARIOS`]).
pub fn waypoint_scenarios() -> Result<Vec<Scenario>, ScenarioError> {
    WAYPOINT_SCENARIOS
        .iter()
        .map(|(_, text)| parse_scenario(text))
        .collect()
}

/// The real missions, validated ([`REAL_SCENARIOS`]).
pub fn real_scenarios() -> Result<Vec<Scenario>, ScenarioError> {
    REAL_SCENARIOS
        .iter()
        .map(|(_, text)| parse_scenario(text))
        .collect()
}

/// The paper's mission `case` (with Δu) flown through the real actuator chain of the real
/// vehicle `vehicle` (its thrust unit, mounting and allocator priority: those of the real
/// missions): the paper's own heading, time scale 1, its untrimmed Table-3 payload, ±24 V,
/// started in trim (the real chain's default). Named `<case>-real-chain`; expected to miss
/// the real vehicle's bound (what an infeasible verdict means, shown).
pub fn paper_real_chain(case: Table1Case, vehicle: &ControllerConfig) -> SimConfig {
    let mut config = paper::config(case, true);
    config.name = format!("{}-real-chain", case.name());
    config.case = None;
    config.ideal_actuators = false;
    config.controller.thrust_unit = vehicle.thrust_unit;
    config.controller.geometry = vehicle.geometry;
    config.controller.priority = vehicle.priority;
    config.expect_missed = true;
    config
}

/// [`paper_real_chain`] of every case, each on the vehicle of its real mission
/// ([`real_scenarios`], same order), validated.
pub fn paper_real_chain_scenarios(real: &[Scenario]) -> Result<Vec<Scenario>, ScenarioError> {
    Table1Case::ALL
        .iter()
        .zip(real)
        .map(|(&c, r)| Scenario::new(paper_real_chain(c, &r.config().controller)))
        .collect()
}
