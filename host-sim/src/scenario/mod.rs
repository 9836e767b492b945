//! Scenarios: one TOML file describes one run, a [`SimConfig`]; [`Scenario::new`] validates it
//! into a [`Scenario`], which holds what the run needs built (the [`Controller`], the
//! [`Trajectory`]) and its step counts.
//!
//! Two stages, each written once:
//! - **Parsing** ([`parse_scenario`], [`load_scenario`]; [`ScenarioFile`] and `parse.rs`) is
//!   about the file's shape.
//!   Every table denies unknown keys (the error names the key and its line), a key that the
//!   chosen `kind`, `profile` or `model` does not use is an error, not silently ignored, and a
//!   required one must be there. The `[trajectory]` table is the core's own
//!   [`TrajectoryKind`](controller_core::TrajectoryKind) (its `serde` form, with the paper's ω
//!   and depth as defaults).
//! - **Validation** ([`Scenario::new`]; `check.rs`) is about the values, for any
//!   [`SimConfig`], from a file or built in code. An out-of-range value is a
//!   [`ScenarioError::Invalid`] that names the dotted key, e.g.
//!   `controller.mu: mu must be a finite number > 0, got -1`. The controller's and the
//!   trajectory's ranges are checked by the core once ([`Controller::new`],
//!   [`Trajectory::new`]): their errors name their field, which is mapped to the key. So an
//!   infeasible configuration (loop rate too low for the boundary-layer gain, Assumption 2,
//!   Theorem 2, …) is refused at load time, not half-way through a run.
//!
//! # Schema
//!
//! The file's shape is one type, [`ScenarioFile`] (`file.rs`): the reader deserializes it and
//! every writer (`import-plan`, `check`'s pinned profile, a campaign's worst-run file)
//! serializes one (`write.rs`). Every key with its meaning, unit, range and default is shown,
//! runnable, in **`scenarios/example-all-knobs.toml`** (a test holds it to the type's keys).
//! Every table is optional except `[trajectory]`; a key left out takes the default of
//! [`SimConfig::new`] and [`ControllerConfig::default`](controller_core::ControllerConfig) (the
//! paper's values). Integers are accepted where a number is expected (`duration = 70`).
//!
//! **Arrays** have exactly their length (`k1` six numbers, `q` two, `velocity` three…):
//! more or fewer entries, or an entry that is not a number, is an error at the key.
//!
//! **Limits checked with the run as a whole** (each refusal names its key and says why):
//! - the step cap: at most [`MAX_CONTROL_PERIODS`] control periods (duration × rate_hz) and
//!   [`MAX_PLANT_STEPS`] plant steps (one day at 100 Hz and 1 ms), unless
//!   [`SimConfig::allow_long_run`] (the CLI's `--allow-long-run`); never beyond 2⁵³;
//! - `current.tau` ≥ `plant_step` (the plant holds the current over a step: a Gauss–Markov
//!   current faster than the step is not resolved);
//! - `variation.omega` · `plant_step` ≤ [`MAX_VARIATION_OMEGA_STEP`] (the plant resolves the
//!   variation; 1e308 used to give NaN parameters);
//! - what the vehicle can meet (**Choice 124**): the start offset (its position part within
//!   `divergence_limit`, which is at most the controller's 10 km; roll and yaw within ±π, pitch
//!   inside ±π/2), the current's speed ([`MAX_CURRENT_SPEED`]), the thruster lag
//!   ([`MAX_THRUSTER_LAG`]) and the noise σ (see the example): 10³⁰⁸ used to pass and diverge
//!   at t = 0;
//! - the reference stays inside what the controller accepts as input
//!   (`controller_core::controller::MAX_POSITION`, `MAX_LINEAR_SPEED`, `MAX_ANGULAR_RATE`;
//!   checked at every tick up to 10⁵ ticks, else at 10⁵ evenly spaced ones): a faster or
//!   longer mission would be flown in fail-safe;
//! - the law does not overflow f32 on the reference itself (gains like k1 = 1e30, which the
//!   loop-rate rule on k2 does not catch, made every update a fail-safe).
//!
//! **Δ fields of `constant` and `abs-sin`** (their names:
//! [`VARIED_PARAMETER_NAMES`](controller_core::model::VARIED_PARAMETER_NAMES)): with none of
//! the nine given, Δ is Table 3's maximum
//! ([`ParamVariation::TABLE3_MAX`](controller_core::model::ParamVariation::TABLE3_MAX): the
//! paper's circle and figure-eight); as soon as one is given, the ones left out are 0. The
//! fields of a staircase step left out are 0. Δ may lie outside Table 3's box (the
//! controller's bounds then no longer cover the plant), but the varied plant's inertia matrix
//! M must stay positive definite.
//!
//! The six files `scenarios/<case>.toml` are the paper's Table-1 runs; [`paper::config`]
//! builds the same [`SimConfig`] in code.

use std::fmt;
use std::path::{Path, PathBuf};

use controller_core::{Controller, Trajectory};

use crate::plant::{static_heel, PlantState};

mod config;
pub mod file;
mod fixed_arrays;
mod from_config;
pub mod navigation;
pub mod paper;
mod parse;
pub mod path_time;
pub mod plan;
pub mod real_vehicle;
mod start;
pub mod ultimate_bound;
mod validate;
mod write;

pub use config::{Bound, InitialAttitude, LinkFaults, SensorNoise, SimConfig, TickRange};
pub use file::ScenarioFile;
pub use from_config::Unwritable;
pub use parse::{reversed_mask, DEFAULT_NAME, DEFAULT_SEED};
pub use start::start_state;
pub use validate::check_name;
pub use validate::{
    MAX_CONTROL_PERIODS, MAX_CURRENT_SPEED, MAX_DURATION, MAX_PLANT_STEP, MAX_PLANT_STEPS,
    MAX_THRUSTER_LAG, MAX_VARIATION_OMEGA_STEP,
};
pub use write::{KeyPath, ScenarioDocument};

/// Why a scenario could not be loaded or validated.
#[derive(Debug)]
pub enum ScenarioError {
    /// The file could not be read.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Not valid TOML, an unknown key, a missing required key or a value of the wrong type.
    /// The message is the `toml` crate's: it names the line, column and key.
    Toml(String),
    /// A value out of its range, or a key that does not belong. `key` is the dotted path,
    /// e.g. `controller.mu`, `variation.steps[1].until`, or `controller` for a check of the
    /// controller as a whole made by [`Controller::new`].
    Invalid { key: String, message: String },
    /// A [`ScenarioFile`] that TOML cannot hold (the `toml` crates' message), or a writer's
    /// layout that does not match the file ([`ScenarioDocument`]).
    Write(String),
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // The reason is the source (Choice 128): printed once, by whoever prints the chain.
            ScenarioError::Io { path, .. } => {
                write!(f, "cannot read scenario file {}", path.display())
            }
            ScenarioError::Toml(message) => write!(f, "invalid scenario: {}", message.trim_end()),
            ScenarioError::Invalid { key, message } => {
                write!(f, "invalid scenario value `{key}`: {message}")
            }
            ScenarioError::Write(message) => write!(f, "cannot write the scenario: {message}"),
        }
    }
}

/// The I/O reason of [`ScenarioError::Io`] is its `source()`, and not in its message: a chain
/// printed whole (`{:#}`, as the binary does) says it once (**Choice 128**: it was printed
/// twice, "Is a directory (os error 21): Is a directory (os error 21)").
impl std::error::Error for ScenarioError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ScenarioError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// A validated run: its [`SimConfig`], the [`Controller`] and [`Trajectory`] built from it
/// (once), and its step counts. Only [`Scenario::new`] makes one, so a `Scenario` always runs.
#[derive(Clone, Debug)]
pub struct Scenario {
    config: SimConfig,
    controller: Controller,
    trajectory: Trajectory,
    steps: u64,
    substeps: usize,
}

impl PartialEq for Scenario {
    /// Equal configurations (everything else is built from the configuration).
    fn eq(&self, other: &Self) -> bool {
        self.config == other.config
    }
}

impl Scenario {
    /// Validates `config` (every check, see the module doc) and builds its controller and
    /// trajectory.
    pub fn new(config: SimConfig) -> Result<Self, ScenarioError> {
        let controller = validate::controller(&config)?;
        let trajectory = validate::trajectory(&config.mission())?;
        Self::assemble(config, controller, trajectory, true)
    }

    /// This scenario with `change` applied to its configuration, validated again. The built
    /// controller and trajectory are kept when `change` leaves their settings as they were
    /// (a Monte Carlo draw, a shorter duration), so only what changed is rebuilt.
    pub fn with(&self, change: impl FnOnce(&mut SimConfig)) -> Result<Self, ScenarioError> {
        let mut config = self.config.clone();
        change(&mut config);
        let controller = if config.controller == self.config.controller {
            self.controller.clone()
        } else {
            validate::controller(&config)?
        };
        let trajectory = if config.mission() == self.config.mission() {
            self.trajectory
        } else {
            validate::trajectory(&config.mission())?
        };
        // The mission's reference depends only on these (a Monte Carlo draw keeps them all).
        let same_mission = config.controller == self.config.controller
            && config.mission() == self.config.mission()
            && config.duration == self.config.duration;
        Self::assemble(config, controller, trajectory, !same_mission)
    }

    fn assemble(
        config: SimConfig,
        controller: Controller,
        trajectory: Trajectory,
        check_mission: bool,
    ) -> Result<Self, ScenarioError> {
        let (steps, substeps) = validate::run(&config)?;
        if check_mission {
            validate::mission(&config, &controller, &trajectory, steps)?;
        }
        Ok(Scenario {
            config,
            controller,
            trajectory,
            steps,
            substeps,
        })
    }

    /// The configuration (read only: change it with [`Scenario::with`]).
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// The configuration, for building another scenario from it.
    pub fn into_config(self) -> SimConfig {
        self.config
    }

    /// The controller of [`SimConfig::controller`], built.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// The mission of [`SimConfig::trajectory`], built.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// The last control tick: the run samples ticks 0..=steps, steps = duration · rate_hz
    /// rounded.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Plant steps per control period (the plant step divides the period).
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// The control period 1/rate_hz (s).
    pub fn period(&self) -> f64 {
        1.0 / f64::from(self.config.controller.rate_hz)
    }

    /// Where the run starts ([`start_state`]): on the reference plus the configured offset,
    /// heeled to the payload's static heel if it starts in trim
    /// ([`SimConfig::initial_attitude`]).
    pub fn initial_state(&self) -> PlantState {
        let rate = self.config.controller.rate_hz;
        let mut offset = self.config.initial_offset;
        if self.config.initial_attitude() == InitialAttitude::Trim {
            let d0 = self.trajectory.sample(0, rate);
            let params = self.config.plant_params_at(0.0);
            if let Some(heel) = static_heel(&params, f64::from(d0.eta[4])) {
                offset[3] += heel - f64::from(d0.eta[3]);
            }
        }
        start_state(&self.trajectory, rate, &offset)
    }
}

/// An f32 as the f64 of its shortest decimal (0.1, not 0.10000000149011612): the number a
/// user wrote, which turns back into the same f32.
pub fn f32_decimal(x: f32) -> f64 {
    match x.to_string().parse::<f64>() {
        Ok(d) if d as f32 == x || x.is_nan() => d,
        _ => f64::from(x),
    }
}

/// Parses and validates a scenario from TOML text. A scenario without `name` is called
/// [`DEFAULT_NAME`].
pub fn parse_scenario(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::new(parse::parse(text, DEFAULT_NAME)?)
}

/// Reads, parses and validates a scenario file. A scenario without `name` takes the file stem.
/// A read error carries the path.
pub fn load_scenario(path: &Path) -> Result<Scenario, ScenarioError> {
    Scenario::new(load_config(path)?)
}

/// Reads and parses a scenario file into its [`SimConfig`], not yet validated (for a caller
/// that sets what a file cannot, e.g. [`SimConfig::allow_long_run`], before
/// [`Scenario::new`]). A scenario without `name` takes the file stem.
pub fn load_config(path: &Path) -> Result<SimConfig, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .unwrap_or(DEFAULT_NAME);
    parse::parse(&text, stem)
}
