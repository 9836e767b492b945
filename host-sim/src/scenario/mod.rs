//! Scenarios: one TOML file describes one run, a [`SimConfig`]; [`Scenario::new`] validates it
//! into a [`Scenario`], which holds what the run needs built (the [`Controller`], the
//! [`Trajectory`]) and its step counts.
//!
//! Two stages, each written once:
//! - **Parsing** ([`parse_scenario`], [`load_scenario`]; `parse.rs`) is about the file's shape.
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
//! Every table is optional except `[trajectory]`. Anything left out takes the default of
//! [`SimConfig::new`] and [`ControllerConfig::default`](controller_core::ControllerConfig) (the
//! paper's values). Integers are accepted where a number is expected (`duration = 70`).
//!
//! ```toml
//! name = "circular-10R"       # file-name safe; default: the file stem (load_scenario) or "scenario"
//! table1_case = "circular-10R" # this run is that case of the paper's Table 1: reports print
//!                             # the paper's numbers beside ours; default: none
//! duration = 70.0             # s, (0, 86400]; and the step cap below
//! plant_step = 0.001          # s, (0, 0.1] and ≤ the control period 1/rate_hz
//! ideal_actuators = true      # thrusters deliver the allocated thrust whatever the voltage limit
//! initial_offset = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # added to η(0) = η_d(0), m and rad; the
//!                             # position part ≤ divergence_limit in norm, roll and yaw within
//!                             # ±π, pitch inside ±π/2
//! divergence_limit = 50.0     # m, (0, 10000]
//! thruster_lag = 0.1          # s, (0, 10]; leave out for no lag
//! expect_faults = false       # true: periods with the controller in fail-safe are reported but
//!                             # do not fail the command (else exit 3); default false
//! initial_attitude = "trim"   # "trim" (the payload's static heel) | "level"; default trim for
//!                             # the real chain, level for ideal actuators
//! expect_missed = false       # true: a miss of [bound] is reported, no exit 4; default false
//!
//! [trajectory]                # required
//! kind = "circle"             # "circle" | "figure-eight" | "lawn-mower" | "helix" | "waypoints"
//! radius = 10.0               # circle, helix (required)
//! amplitude = 15.0            # figure-eight (required)
//! scale = 1.0                 # lawn-mower (required)
//! depth_rate = 0.05           # helix (required), m/s, positive descends
//! omega = 0.1                 # rad/s; default 0.1, lawn-mower 0.05
//! depth = 5.0                 # m, positive down; default 5
//! points = [[0.0, 0.0, 5.0], [50.0, 0.0, 5.0]]  # waypoints (required): 2 to 32 points
//!                             # as [x, y, z] in the mission frame (m, z down; docs/missions.md#waypoint-paths)
//! speed = 0.5                 # waypoints (required): m/s along the legs, (0, 10]
//! turn_radius = 2.5           # waypoints, m: the corners' smallest radius; default speed²/0.1
//! speeds = [2.11, 0.7, 1.5]   # waypoints: the flown speed profile, one per part (leg 0, turn
//!                             # at 1, leg 1, …; 2n − 3), m/s; `check` proposes it; default none
//! speed_change = 0.05         # waypoints: the speed changes' peak |σ̈|, m/s²; default 0.05
//! speed_limits = [1.5, 0.8]   # waypoints: a cap per leg (n − 1 values), m/s in (0, 10]: check's
//!                             # profile proposes no leg faster (docs/missions.md#the-speed-profile); default none
//! heading = "paper"           # "paper" | "tangent" (ψ_d along the course); default "paper",
//!                             # "tangent" for waypoints (their only heading)
//! time_scale = 1.0            # k in [1, 100]: the reference is η_d(t/k); default 1
//! origin = [43.295, 5.362, 0.0]  # the frame's origin: lat, lon (deg), alt (m); run then writes
//!                             # the flown path as GeoJSON; default none
//!
//! [variation]                 # Table-3 parameter variation of the plant (not the controller)
//! profile = "abs-sin"         # "none" | "constant" | "abs-sin" | "staircase" | "table3-staircase"
//! trimmed = false             # true: payload ballasted to W = B (mass, inertia, CG shift act)
//! omega = 0.1                 # abs-sin only, rad/s, default 0.1
//! mass = 30.0                 # constant / abs-sin: Δ (abs-sin: the maximum); see below
//! x_g = 0.05
//! y_g = 0.02
//! z_g = 0.02
//! ix = 2.0
//! iy = 5.0
//! iz = 10.0
//! x_udot = 3.0
//! y_vdot = 50.0
//! # staircase only: one table per step, Δ holds while t ≤ until; the last step's `until` may
//! # be left out (holds for ever); a step's Δ fields are those above, 0 when left out.
//! # [[variation.steps]]
//! # until = 25.0
//! # mass = 30.0
//! # x_g = 0.05
//! # y_g = 0.02
//! # z_g = 0.02
//! # ix = 2.0
//! # iy = 5.0
//! # iz = 10.0
//! # x_udot = 3.0
//! # y_vdot = 50.0
//!
//! [current]                   # ocean current, earth frame (NED)
//! model = "constant"          # "none" | "constant" | "gauss-markov"
//! velocity = [0.2, 0.1, 0.0]  # constant (required), m/s, ‖velocity‖ ≤ 5 (MAX_CURRENT_SPEED)
//! mean = [0.0, 0.0, 0.0]      # gauss-markov, m/s, default zeros, ‖mean‖ ≤ 5
//! sigma = [0.05, 0.05, 0.0]   # gauss-markov (required), m/s, ≥ 0, ‖sigma‖ ≤ 5
//! tau = 30.0                  # gauss-markov (required), s, > 0
//! seed = 1                    # gauss-markov, default 1
//!
//! [noise]                     # present = measurement noise on; absent = off
//! eta_sigma = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # default zeros, ≥ 0; m ≤ divergence_limit, rad ≤ π
//! nu_sigma = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]   # default zeros, ≥ 0; m/s ≤ 50, rad/s ≤ 50
//! seed = 1                                    # default 1
//!
//! [controller]
//! robust = true               # false: u = ū only (the paper's "without Δu")
//! law = "boundary-layer"      # "boundary-layer" (Theorem 4) | "discontinuous" (Theorem 3)
//! k1 = [4.0, 4.0, 4.0, 0.0, 4.0, 4.0]  # controlled axes > 0, roll (index 3) = 0
//! k2 = [4.0, 4.0, 4.0, 0.0, 4.0, 4.0]
//! q = [1.0, 1.0]              # > 0
//! beta = 0.605                # (0, 1)
//! mu = 0.1                    # > 0
//! delta_max = 25.0            # > 0
//! rate_hz = 100               # integer ≥ 1
//! pitch_limit_deg = 80.0      # (0, 90)
//! voltage_limit = 24.0        # V, > 0
//! b_bound = "controlled-rows" # "controlled-rows" | "literal"
//! thrust_unit = "kgf"         # "kgf" | "newton": the unit of Eqs 31–32; default "kgf"
//! axis_priority = ["pitch", "depth", "yaw", "sway", "surge"]  # the five axes, highest first
//! reversed_thrusters = ["vert fore", "horz fore", "horz aft"]  # strong side against the
//!                             # reference axis (+x main, +z vertical, +y horizontal); default:
//!                             # the core's (this list: fore up, aft down, both to port)
//!
//! [bound]                     # a run completing outside it is "missed" (exit 4); default these
//!                             # two for the real chain (ideal_actuators = false), none for ideal
//! max_path = 0.05             # m, > 0
//! saturated = 0.01            # fraction of control periods with a thruster saturated, [0, 1]
//!
//! [link_faults]               # processor in the loop only: tick ranges "A..B" (A included)
//! drop = ["100..101"]         # state frames not sent
//! corrupt = ["150..152"]      # state frames with a byte flipped
//! delay = ["200..210"]        # the state from delay_ticks earlier is sent instead
//! delay_ticks = 5             # default 5
//! silent = ["300..310"]       # nothing sent at all
//! lose_upload_chunks = [1]    # a waypoint mission's upload chunks lost on their first sending
//! ```
//!
//! **Arrays** have exactly the length shown (`k1` six numbers, `q` two, `velocity` three…):
//! more or fewer entries, or an entry that is not a number, is an error at the key.
//!
//! **Limits checked with the run as a whole** (each refusal names its key and says why):
//! - the step cap: at most [`MAX_CONTROL_PERIODS`] control periods (duration × rate_hz) and
//!   [`MAX_PLANT_STEPS`] plant steps (one day at 100 Hz and 1 ms), unless
//!   [`SimConfig::allow_long_run`] (the CLI's `--allow-long-run`); never beyond 2⁵³;
//! - `current.tau` ≥ `plant_step` (Euler–Maruyama of the Gauss–Markov current is unstable
//!   below half the step, and its variance is σ²/(1 − h/2τ));
//! - `variation.omega` · `plant_step` ≤ [`MAX_VARIATION_OMEGA_STEP`] (the plant resolves the
//!   variation; 1e308 used to give NaN parameters);
//! - what the vehicle can meet (**Choice 124**): the start offset (its position part within
//!   `divergence_limit`, which is at most the controller's 10 km; roll and yaw within ±π, pitch
//!   inside ±π/2), the current's speed ([`MAX_CURRENT_SPEED`]), the thruster lag
//!   ([`MAX_THRUSTER_LAG`]) and the noise σ (see the schema): 10³⁰⁸ used to pass and diverge at
//!   t = 0;
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
mod fixed_arrays;
pub mod paper;
mod parse;
pub mod plan;
pub mod real_vehicle;
mod start;
mod validate;

pub use config::{Bound, InitialAttitude, LinkFaults, SensorNoise, SimConfig, TickRange};
pub use parse::{reversed_mask, DEFAULT_NAME, DEFAULT_SEED};
pub use start::start_state;
pub use validate::{
    MAX_CONTROL_PERIODS, MAX_CURRENT_SPEED, MAX_DURATION, MAX_PLANT_STEP, MAX_PLANT_STEPS,
    MAX_THRUSTER_LAG, MAX_VARIATION_OMEGA_STEP,
};

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
