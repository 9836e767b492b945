//! What one simulation run is: mission, plant, disturbances, actuators and controller.
//!
//! [`SimConfig`] is plain data. [`crate::scenario`] reads it from TOML and validates it into a
//! runnable [`Scenario`](crate::scenario::Scenario); [`crate::scenario::paper`] builds the
//! paper's six cases.

use controller_core::{ControllerConfig, HeadingMode, Mission, Table1Case, TrajectoryKind};

use controller_core::model::VehicleParams;

use crate::plant::{self, CurrentModel, VariationProfile};

/// The attitude a run starts in (scenario key `initial_attitude`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InitialAttitude {
    /// Roll and pitch of the reference (0): the vehicle released level, whatever its payload.
    Level,
    /// **Choice 102** (docs/real-vehicle.md#the-bound-and-the-start-in-trim): at the static heel of the payload present at
    /// t = 0 ([`crate::plant::static_heel`]; roll is not actuated, so a lateral CG shift leaves
    /// the vehicle heeled), pitch as the reference (pitch is controlled).
    Trim,
}

impl InitialAttitude {
    /// `level` or `trim` (the scenario key's values).
    pub fn as_str(self) -> &'static str {
        match self {
            InitialAttitude::Level => "level",
            InitialAttitude::Trim => "trim",
        }
    }
}

/// The bound a run must fly within (scenario table `[bound]`, docs/real-vehicle.md#the-bound-and-the-start-in-trim): a run that
/// completes outside it has missed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// Largest max path error (m).
    pub max_path: f64,
    /// Largest fraction of control periods with a thruster saturated.
    pub saturated: f64,
    /// Most sign reversals per second of any thruster's command through ±0.5 V (1/s;
    /// [`crate::sim::chatter`]).
    pub max_reversals_per_s: f64,
    /// Largest total variation per second of any thruster's command (V/s).
    pub max_command_tv: f64,
}

impl Bound {
    /// The real vehicle's bound (**Choice 103**, docs/real-vehicle.md#the-bound-and-the-start-in-trim): 0.05 m, 1 % of periods;
    /// and its chatter (**Choice 322**, docs/real-vehicle.md#chatter): at most 2 reversals a
    /// second per thruster through ±0.5 V and 100 V/s of command total variation.
    pub const REAL_VEHICLE: Bound = Bound {
        max_path: 0.05,
        saturated: 0.01,
        max_reversals_per_s: 2.0,
        max_command_tv: 100.0,
    };

    /// `table`'s limits, the real vehicle's for a key left out.
    pub fn with_defaults(
        max_path: Option<f64>,
        saturated: Option<f64>,
        max_reversals_per_s: Option<f64>,
        max_command_tv: Option<f64>,
    ) -> Bound {
        let d = Bound::REAL_VEHICLE;
        Bound {
            max_path: max_path.unwrap_or(d.max_path),
            saturated: saturated.unwrap_or(d.saturated),
            max_reversals_per_s: max_reversals_per_s.unwrap_or(d.max_reversals_per_s),
            max_command_tv: max_command_tv.unwrap_or(d.max_command_tv),
        }
    }
}

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
    /// Chunks of a waypoint mission's upload whose first sending is lost (the runner must
    /// resend them on the board's acknowledgement; no fail-safe follows).
    pub lose_upload_chunks: Vec<u8>,
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
            lose_upload_chunks: Vec::new(),
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
    /// docs/missions.md#heading).
    pub heading: HeadingMode,
    /// The mission's time scale k ≥ 1: the reference is η_d(t/k) (`trajectory.time_scale`,
    /// default 1; docs/missions.md#time-scaling).
    pub time_scale: f32,
    /// The mission frame's origin on the earth, [latitude, longitude (degrees), altitude (m)]
    /// (`trajectory.origin`, e.g. a QGroundControl plan's home): `run` then writes the flown
    /// path as GeoJSON (docs/missions.md#plans-from-qgroundcontrol). `None`: the frame is not placed on the earth.
    pub origin: Option<[f64; 3]>,
    /// A waypoint mission's per-leg speed caps (m/s, one per leg: n − 1 for n points;
    /// `trajectory.speed_limits`, **Choice 161**): a planning input of `check`'s speed profile
    /// ([`crate::studies::preflight::profile`]), never flown (the pinned `speeds` are). `None`:
    /// no caps.
    pub speed_limits: Option<Vec<f64>>,
    /// Simulated time (s). Paper: 70. A waypoint mission without `duration`: its path's time
    /// to the last waypoint ([`crate::scenario::path_time`], Choice 312).
    pub duration: f64,
    /// Plant step (s). Default 1 ms.
    pub plant_step: f64,
    /// How the plant is stepped (scenario key `plant_integrator`, **Choice 542**). Default RK4.
    pub plant_integrator: crate::plant::Integrator,
    /// How the navigation errors and `[noise]` are drawn (scenario key `noise_draws`,
    /// **Choice 536**). Default every period from ChaCha12.
    pub noise_draws: crate::scenario::navigation::NoiseDraws,
    /// The controller (its `rate_hz` is the sampled loop's rate; zero-order hold in between).
    pub controller: ControllerConfig,
    pub variation: VariationProfile,
    /// The payload is ballasted to neutral buoyancy, W = B (scenario key `variation.trimmed`,
    /// default false; plant only): its mass, inertia and CG shift still act, its net weight
    /// does not ([`crate::plant::trimmed`], docs/real-vehicle.md#trim).
    pub trimmed: bool,
    pub current: CurrentModel,
    pub noise: Option<SensorNoise>,
    /// The navigation solution the law is told (`[navigation]`, docs/navigation.md); `None`:
    /// the plant's exact state (the `ideal` preset).
    pub navigation: Option<super::navigation::NavigationModel>,
    /// First-order thruster lag time constant (s), if any.
    pub thruster_lag: Option<f64>,
    /// Ideal actuators: the thrusters deliver the allocated thrust whatever the voltage limit
    /// (the Table-1 reproduction; docs/thrusters.md#the-chain-end-to-end). Voltages are still computed and reported.
    pub ideal_actuators: bool,
    /// Added to η(0) = η_d(0) (m, rad).
    pub initial_offset: [f64; 6],
    /// The attitude the run starts in (scenario key `initial_attitude`); `None`: the default
    /// for the actuators, [`SimConfig::initial_attitude`].
    pub start_attitude: Option<InitialAttitude>,
    /// A position error beyond this (m) is a runaway: the run stops and says so.
    pub divergence_limit: f64,
    /// Faults on the board link (PIL only).
    pub link_faults: LinkFaults,
    /// The controller is expected to fault in this run (scenario key `expect_faults`): its
    /// fail-safe periods are still counted and reported, but do not make the command fail
    /// (exit 3, [`crate::cli::Exit::Faulted`]).
    pub expect_faults: bool,
    /// The bound the run must fly within (scenario table `[bound]`); `None`: the default for
    /// the actuators, [`SimConfig::bound`].
    pub bound_setting: Option<Bound>,
    /// The run is expected to miss its bound (scenario key `expect_missed`): the miss is still
    /// reported, but does not make the command fail (exit 4).
    pub expect_missed: bool,
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

    /// The attitude the run starts in: as configured, else **trim** for the real actuator
    /// chain (a real vehicle is released in the attitude its payload gives it,
    /// docs/real-vehicle.md#the-bound-and-the-start-in-trim) and **level** for ideal actuators (the paper's Table 1, bit for bit as before).
    pub fn initial_attitude(&self) -> InitialAttitude {
        self.start_attitude.unwrap_or(match self.ideal_actuators {
            true => InitialAttitude::Level,
            false => InitialAttitude::Trim,
        })
    }

    /// The bound the run must fly within: as configured, else the real vehicle's
    /// ([`Bound::REAL_VEHICLE`]) for the real actuator chain, and none for ideal actuators.
    pub fn bound(&self) -> Option<Bound> {
        self.bound_setting
            .or((!self.ideal_actuators).then_some(Bound::REAL_VEHICLE))
    }

    /// The plant's parameters at time `t` (s): the nominal AUV-150 with the profile's Δp,
    /// trimmed if the scenario says so (plant only; the controller keeps the nominal model).
    pub fn plant_params_at(&self, t: f64) -> VehicleParams<f64> {
        let params = VehicleParams::auv150().with_variation(&self.variation.at(t));
        match self.trimmed {
            true => plant::trimmed(&params),
            false => params,
        }
    }

    /// Defaults around a path: the paper's heading (the tangent heading for waypoints, which
    /// have no other: docs/missions.md#waypoint-paths) at time scale 1, 70 s, 1 ms plant step, the
    /// paper's controller at 100 Hz, no variation (untrimmed), no current, no noise, ideal
    /// actuators, starting on the reference, no Table-1 case, no faults expected, the step cap
    /// in force.
    pub fn new(name: impl Into<String>, trajectory: TrajectoryKind) -> Self {
        SimConfig {
            name: name.into(),
            case: None,
            trajectory,
            heading: match trajectory {
                TrajectoryKind::Waypoints { .. } => HeadingMode::Tangent,
                _ => HeadingMode::Paper,
            },
            time_scale: 1.0,
            origin: None,
            speed_limits: None,
            duration: 70.0,
            plant_step: 0.001,
            plant_integrator: crate::plant::Integrator::Rk4,
            noise_draws: crate::scenario::navigation::NoiseDraws::EveryPeriod,
            controller: ControllerConfig::default(),
            variation: VariationProfile::None,
            trimmed: false,
            current: CurrentModel::None,
            noise: None,
            navigation: None,
            thruster_lag: None,
            ideal_actuators: true,
            initial_offset: [0.0; 6],
            start_attitude: None,
            divergence_limit: 50.0,
            link_faults: LinkFaults::default(),
            expect_faults: false,
            bound_setting: None,
            expect_missed: false,
            allow_long_run: false,
        }
    }
}
