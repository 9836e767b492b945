//! What one simulation run is: mission, plant, disturbances, actuators and controller.
//!
//! [`SimConfig`] is plain data. [`crate::scenario`] reads it from TOML and validates it into a
//! runnable [`Scenario`](crate::scenario::Scenario); [`crate::scenario::paper`] builds the
//! paper's six cases.

use controller_core::{ControllerConfig, HeadingMode, Mission, Table1Case, TrajectoryKind};

use crate::plant::{CurrentModel, VariationProfile};

/// Gaussian noise added to the measured η and ν the controller sees (seeded).
#[derive(Clone, Debug, PartialEq)]
pub struct SensorNoise {
    pub eta_sigma: [f64; 6],
    pub nu_sigma: [f64; 6],
    pub seed: u64,
}

/// A half-open range of control ticks [from, to).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct TickRange {
    pub from: u64,
    pub to: u64,
}

impl TickRange {
    pub fn contains(&self, k: u64) -> bool {
        self.from <= k && k < self.to
    }

    /// Parses "A..B" (ticks).
    pub fn parse(s: &str) -> Result<Self, String> {
        let (a, b) = s
            .split_once("..")
            .ok_or_else(|| format!("tick range `{s}` must be A..B"))?;
        let from = a
            .trim()
            .parse()
            .map_err(|_| format!("bad tick `{a}` in `{s}`"))?;
        let to = b
            .trim()
            .parse()
            .map_err(|_| format!("bad tick `{b}` in `{s}`"))?;
        if to <= from {
            return Err(format!("tick range `{s}` is empty"));
        }
        Ok(TickRange { from, to })
    }
}

/// Faults injected on the board link, by control tick (processor in the loop only; a SIL run
/// has no link and ignores them).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LinkFaults {
    /// State frames not sent.
    pub drop: Vec<TickRange>,
    /// State frames sent with one byte flipped (the board must count and drop them).
    pub corrupt: Vec<TickRange>,
    /// State frames replaced by the frame from `delay_ticks` earlier (stale data).
    pub delay: Vec<TickRange>,
    /// How old a delayed state frame is (ticks). Default [`LinkFaults::DEFAULT_DELAY_TICKS`].
    pub delay_ticks: u64,
    /// Nothing is sent at all (no state, no commands).
    pub silent: Vec<TickRange>,
}

impl Default for LinkFaults {
    /// No faults.
    fn default() -> Self {
        LinkFaults {
            drop: Vec::new(),
            corrupt: Vec::new(),
            delay: Vec::new(),
            delay_ticks: Self::DEFAULT_DELAY_TICKS,
            silent: Vec::new(),
        }
    }
}

impl LinkFaults {
    /// Default age of a delayed state frame (ticks): 5 periods, more than the board's
    /// stale-state limit would allow if the frames stopped.
    pub const DEFAULT_DELAY_TICKS: u64 = 5;

    pub fn any(v: &[TickRange], k: u64) -> bool {
        v.iter().any(|r| r.contains(k))
    }
    pub fn is_empty(&self) -> bool {
        self.drop.is_empty()
            && self.corrupt.is_empty()
            && self.delay.is_empty()
            && self.silent.is_empty()
    }
}

/// One run.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Case name, used for file names and reports.
    pub name: String,
    /// The paper's Table-1 case this run reproduces, if any: the reports print the paper's
    /// numbers beside it ([`crate::studies::table1`]).
    pub case: Option<Table1Case>,
    /// The mission's path (scenario table `[trajectory]`).
    pub trajectory: TrajectoryKind,
    /// How the mission's heading ψ_d is formed (`trajectory.heading`, default the paper's;
    /// docs/design.md §9).
    pub heading: HeadingMode,
    /// The mission's time scale k ≥ 1: the reference is η_d(t/k) (`trajectory.time_scale`,
    /// default 1; docs/design.md §9).
    pub time_scale: f32,
    /// Simulated time (s). Paper: 70.
    pub duration: f64,
    /// Plant RK4 step (s). Default 1 ms.
    pub plant_step: f64,
    /// The controller (its `rate_hz` is the sampled loop's rate; zero-order hold in between).
    pub controller: ControllerConfig,
    pub variation: VariationProfile,
    /// The payload is ballasted to neutral buoyancy, W = B (scenario key `variation.trimmed`,
    /// default false; plant only): its mass, inertia and CG shift still act, its net weight
    /// does not ([`crate::plant::trimmed`], docs/design.md §9).
    pub trimmed: bool,
    pub current: CurrentModel,
    pub noise: Option<SensorNoise>,
    /// First-order thruster lag time constant (s), if any.
    pub thruster_lag: Option<f64>,
    /// Ideal actuators: the thrusters deliver the allocated thrust whatever the voltage limit
    /// (the Table-1 reproduction; docs/design.md §5). Voltages are still computed and reported.
    pub ideal_actuators: bool,
    /// Added to η(0) = η_d(0) (m, rad).
    pub initial_offset: [f64; 6],
    /// A position error beyond this (m) is a runaway: the run stops and says so.
    pub divergence_limit: f64,
    /// Faults on the board link (PIL only).
    pub link_faults: LinkFaults,
    /// The controller is expected to fault in this run (scenario key `expect_faults`): its
    /// fail-safe periods are still counted and reported, but do not make the command fail
    /// (exit 3, [`crate::cli::Exit::Faulted`]).
    pub expect_faults: bool,
    /// Lift the step cap ([`crate::scenario::MAX_CONTROL_PERIODS`],
    /// [`crate::scenario::MAX_PLANT_STEPS`]). Not a scenario key: the explicit override is the
    /// CLI's `--allow-long-run`.
    pub allow_long_run: bool,
}

impl SimConfig {
    /// The mission the controller flies (and the board is sent in `StartMission`): the path,
    /// its heading and its time scale.
    pub fn mission(&self) -> Mission {
        Mission {
            path: self.trajectory,
            heading: self.heading,
            time_scale: self.time_scale,
        }
    }

    /// Defaults around a path: the paper's heading at time scale 1, 70 s, 1 ms plant step, the
    /// paper's controller at 100 Hz, no variation (untrimmed), no current, no noise, ideal
    /// actuators, starting on the reference, no Table-1 case, no faults expected, the step cap
    /// in force.
    pub fn new(name: impl Into<String>, trajectory: TrajectoryKind) -> Self {
        SimConfig {
            name: name.into(),
            case: None,
            trajectory,
            heading: HeadingMode::Paper,
            time_scale: 1.0,
            duration: 70.0,
            plant_step: 0.001,
            controller: ControllerConfig::default(),
            variation: VariationProfile::None,
            trimmed: false,
            current: CurrentModel::None,
            noise: None,
            thruster_lag: None,
            ideal_actuators: true,
            initial_offset: [0.0; 6],
            divergence_limit: 50.0,
            link_faults: LinkFaults::default(),
            expect_faults: false,
            allow_long_run: false,
        }
    }
}
