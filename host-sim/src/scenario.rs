//! Scenario files: one TOML file describes one run, a [`SimConfig`].
//!
//! Parsing is strict. Every table denies unknown keys (the error names the key and its line),
//! and every value is checked after parsing: an out-of-range value is a
//! [`ScenarioError::Invalid`] that names the dotted key, e.g. `controller.mu: must be > 0, got -1`.
//! The controller is built once ([`Controller::new`]) so an infeasible configuration (loop rate
//! too low for the boundary-layer gain, Assumption 2, Theorem 2, …) is refused at load time, not
//! half-way through a run.
//!
//! # Schema
//!
//! Every table is optional except `[trajectory]`. Anything left out takes the default of
//! [`SimConfig::new`] and [`ControllerConfig::default`] (the paper's values). Integers are
//! accepted where a number is expected (`duration = 70`).
//!
//! ```toml
//! name = "circular-10R"       # file-name safe; default: the file stem (load_scenario) or "scenario"
//! duration = 70.0             # s, (0, 86400]
//! plant_step = 0.001          # s, (0, 0.1] and ≤ the control period 1/rate_hz
//! ideal_actuators = true      # thrusters deliver the allocated thrust whatever the voltage limit
//! initial_offset = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # added to η(0) = η_d(0), m and rad
//! divergence_limit = 50.0     # m, > 0
//! thruster_lag = 0.1          # s, > 0; leave out for no lag
//!
//! [trajectory]                # required
//! kind = "circle"             # "circle" | "figure-eight" | "lawn-mower" | "helix"
//! radius = 10.0               # circle, helix (required)
//! amplitude = 15.0            # figure-eight (required)
//! scale = 1.0                 # lawn-mower (required)
//! depth_rate = 0.05           # helix (required), m/s, positive descends
//! omega = 0.1                 # rad/s; default 0.1, lawn-mower 0.05
//! depth = 5.0                 # m, positive down; default 5
//!
//! [variation]                 # Table-3 parameter variation of the plant (not the controller)
//! profile = "abs-sin"         # "none" | "constant" | "abs-sin" | "staircase" | "table3-staircase"
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
//! # be left out (holds for ever).
//! # [[variation.steps]]
//! # until = 25.0
//! # mass = 30.0 ...
//!
//! [current]                   # ocean current, earth frame (NED)
//! model = "constant"          # "none" | "constant" | "gauss-markov"
//! velocity = [0.2, 0.1, 0.0]  # constant (required), m/s
//! mean = [0.0, 0.0, 0.0]      # gauss-markov, m/s, default zeros
//! sigma = [0.05, 0.05, 0.0]   # gauss-markov (required), m/s, ≥ 0
//! tau = 30.0                  # gauss-markov (required), s, > 0
//! seed = 1                    # gauss-markov, default 1
//!
//! [noise]                     # present = measurement noise on; absent = off
//! eta_sigma = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # default zeros, ≥ 0
//! nu_sigma = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]   # default zeros, ≥ 0
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
//! ```
//!
//! **Δ fields of `constant` and `abs-sin`**: with none of the nine Δ fields given, Δ is Table 3's
//! maximum ([`ParamVariation::TABLE3_MAX`]: the paper's circle and figure-eight); as soon as one
//! is given, the ones left out are 0. The fields of a staircase step left out are 0. Δ may lie
//! outside Table 3's box (the controller's bounds then no longer cover the plant), but the
//! varied plant's inertia matrix M must stay positive definite. A key that the chosen `kind`,
//! `profile` or `model` does not use is an error, not silently ignored.
//!
//! The six files `scenarios/<case>.toml` are the paper's Table-1 runs; [`table1_scenario`]
//! builds the same [`SimConfig`] in code.

use std::fmt;
use std::path::{Path, PathBuf};

use controller_core::model::{self, ParamVariation, VehicleParams};
use controller_core::trajectory::TrajectoryError;
use controller_core::{
    BBound, Controller, ControllerConfig, RobustLaw, Table1Case, Trajectory, TrajectoryKind,
};
use serde::Deserialize;

use crate::config::{
    CurrentModel, LinkFaults, SensorNoise, SimConfig, TickRange, VariationProfile,
};

/// Longest accepted `duration` (s): one day.
pub const MAX_DURATION: f64 = 86_400.0;
/// Longest accepted `plant_step` (s).
pub const MAX_PLANT_STEP: f64 = 0.1;
/// Default `seed` of `[noise]` and of the Gauss–Markov current.
pub const DEFAULT_SEED: u64 = 1;
/// Default ω of the `abs-sin` variation profile (rad/s), the paper's circle.
pub const DEFAULT_ABS_SIN_OMEGA: f64 = 0.1;
/// Name given to a scenario without `name` by [`parse_scenario`].
pub const DEFAULT_NAME: &str = "scenario";

/// Why a scenario could not be loaded.
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
    /// A value out of its range. `key` is the dotted path, e.g. `controller.mu`,
    /// `variation.steps[1].until`, or `controller` for a check made by [`Controller::new`].
    Invalid { key: String, message: String },
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScenarioError::Io { path, source } => {
                write!(f, "cannot read scenario file {}: {source}", path.display())
            }
            ScenarioError::Toml(message) => write!(f, "invalid scenario: {}", message.trim_end()),
            ScenarioError::Invalid { key, message } => {
                write!(f, "invalid scenario value `{key}`: {message}")
            }
        }
    }
}

impl std::error::Error for ScenarioError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ScenarioError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Parses a scenario from TOML text. A scenario without `name` is called [`DEFAULT_NAME`].
pub fn parse_scenario(text: &str) -> Result<SimConfig, ScenarioError> {
    parse_named(text, DEFAULT_NAME)
}

/// Reads and parses a scenario file. A scenario without `name` takes the file stem.
/// A read error carries the path.
pub fn load_scenario(path: &Path) -> Result<SimConfig, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .unwrap_or(DEFAULT_NAME);
    parse_named(&text, stem)
}

/// The scenario of a Table-1 case (AUV150.md §6–7), with (`robust`) or without Δu.
///
/// Identical to the shipped `scenarios/<case>.toml` (which set `robust = true`): the paper's
/// mission, 70 s, 1 ms plant step, the paper's controller at 100 Hz, ideal actuators, starting
/// on the reference, no current or noise, and the case's Table-3 profile: circles
/// Δ = max·|sin 0.1t|, figure-eights Δ = max, lawn-mowers the 0–25 / 25–50 / >50 s staircase.
pub fn table1_scenario(case: Table1Case, robust: bool) -> SimConfig {
    let mut config = SimConfig::new(case.name(), case.kind());
    config.variation = match case {
        Table1Case::Circular10R | Table1Case::Circular20R => VariationProfile::AbsSin {
            max: ParamVariation::TABLE3_MAX,
            omega: DEFAULT_ABS_SIN_OMEGA,
        },
        Table1Case::FigureEight30x30 | Table1Case::FigureEight40x40 => {
            VariationProfile::Constant(ParamVariation::TABLE3_MAX)
        }
        Table1Case::LawnMower20x10 | Table1Case::LawnMower30x15 => {
            VariationProfile::table3_staircase()
        }
    };
    config.controller.robust = robust;
    config
}

// ---------------------------------------------------------------------------------------------
// Raw TOML shape.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    duration: Option<f64>,
    plant_step: Option<f64>,
    ideal_actuators: Option<bool>,
    initial_offset: Option<[f64; 6]>,
    divergence_limit: Option<f64>,
    thruster_lag: Option<f64>,
    trajectory: RawTrajectory,
    variation: Option<RawVariation>,
    current: Option<RawCurrent>,
    noise: Option<RawNoise>,
    controller: Option<RawController>,
    link_faults: Option<RawLinkFaults>,
}

/// `[link_faults]`: tick ranges "A..B" (processor in the loop only).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLinkFaults {
    drop: Option<Vec<String>>,
    corrupt: Option<Vec<String>>,
    delay: Option<Vec<String>>,
    delay_ticks: Option<u64>,
    silent: Option<Vec<String>>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum KindName {
    Circle,
    FigureEight,
    LawnMower,
    Helix,
}

impl KindName {
    fn as_str(self) -> &'static str {
        match self {
            KindName::Circle => "circle",
            KindName::FigureEight => "figure-eight",
            KindName::LawnMower => "lawn-mower",
            KindName::Helix => "helix",
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTrajectory {
    kind: KindName,
    radius: Option<f64>,
    amplitude: Option<f64>,
    scale: Option<f64>,
    omega: Option<f64>,
    depth: Option<f64>,
    depth_rate: Option<f64>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ProfileName {
    None,
    Constant,
    AbsSin,
    Staircase,
    Table3Staircase,
}

impl ProfileName {
    fn as_str(self) -> &'static str {
        match self {
            ProfileName::None => "none",
            ProfileName::Constant => "constant",
            ProfileName::AbsSin => "abs-sin",
            ProfileName::Staircase => "staircase",
            ProfileName::Table3Staircase => "table3-staircase",
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVariation {
    profile: ProfileName,
    omega: Option<f64>,
    mass: Option<f64>,
    x_g: Option<f64>,
    y_g: Option<f64>,
    z_g: Option<f64>,
    ix: Option<f64>,
    iy: Option<f64>,
    iz: Option<f64>,
    x_udot: Option<f64>,
    y_vdot: Option<f64>,
    steps: Option<Vec<RawStep>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    until: Option<f64>,
    mass: Option<f64>,
    x_g: Option<f64>,
    y_g: Option<f64>,
    z_g: Option<f64>,
    ix: Option<f64>,
    iy: Option<f64>,
    iz: Option<f64>,
    x_udot: Option<f64>,
    y_vdot: Option<f64>,
}

/// The nine Δ fields in a fixed order, with their TOML names.
type DeltaFields = [(&'static str, Option<f64>); 9];

impl RawVariation {
    fn delta(&self) -> DeltaFields {
        [
            ("mass", self.mass),
            ("x_g", self.x_g),
            ("y_g", self.y_g),
            ("z_g", self.z_g),
            ("ix", self.ix),
            ("iy", self.iy),
            ("iz", self.iz),
            ("x_udot", self.x_udot),
            ("y_vdot", self.y_vdot),
        ]
    }
}

impl RawStep {
    fn delta(&self) -> DeltaFields {
        [
            ("mass", self.mass),
            ("x_g", self.x_g),
            ("y_g", self.y_g),
            ("z_g", self.z_g),
            ("ix", self.ix),
            ("iy", self.iy),
            ("iz", self.iz),
            ("x_udot", self.x_udot),
            ("y_vdot", self.y_vdot),
        ]
    }
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum CurrentName {
    None,
    Constant,
    GaussMarkov,
}

impl CurrentName {
    fn as_str(self) -> &'static str {
        match self {
            CurrentName::None => "none",
            CurrentName::Constant => "constant",
            CurrentName::GaussMarkov => "gauss-markov",
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCurrent {
    model: CurrentName,
    velocity: Option<[f64; 3]>,
    mean: Option<[f64; 3]>,
    sigma: Option<[f64; 3]>,
    tau: Option<f64>,
    seed: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNoise {
    eta_sigma: Option<[f64; 6]>,
    nu_sigma: Option<[f64; 6]>,
    seed: Option<u64>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum LawName {
    BoundaryLayer,
    Discontinuous,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum BBoundName {
    ControlledRows,
    Literal,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawController {
    robust: Option<bool>,
    law: Option<LawName>,
    k1: Option<[f64; 6]>,
    k2: Option<[f64; 6]>,
    q: Option<[f64; 2]>,
    beta: Option<f64>,
    mu: Option<f64>,
    delta_max: Option<f64>,
    rate_hz: Option<u32>,
    pitch_limit_deg: Option<f64>,
    voltage_limit: Option<f64>,
    b_bound: Option<BBoundName>,
}

// ---------------------------------------------------------------------------------------------
// Checks.

type Res<T> = Result<T, ScenarioError>;

fn invalid(key: impl Into<String>, message: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}

fn finite(key: &str, x: f64) -> Res<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be a finite number, got {x}")))
    }
}

fn positive(key: &str, x: f64) -> Res<f64> {
    finite(key, x)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be > 0, got {x}")))
    }
}

fn non_negative(key: &str, x: f64) -> Res<f64> {
    finite(key, x)?;
    if x >= 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be ≥ 0, got {x}")))
    }
}

/// `x` in the open interval (lo, hi).
fn open_range(key: &str, x: f64, lo: f64, hi: f64) -> Res<f64> {
    finite(key, x)?;
    if x > lo && x < hi {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be in ({lo}, {hi}), got {x}")))
    }
}

fn each<const N: usize>(
    key: &str,
    xs: [f64; N],
    check: fn(&str, f64) -> Res<f64>,
) -> Res<[f64; N]> {
    for (i, &x) in xs.iter().enumerate() {
        check(&format!("{key}[{i}]"), x)?;
    }
    Ok(xs)
}

/// A finite f64 that stays finite in the controller's f32.
fn to_f32(key: &str, x: f64) -> Res<f32> {
    finite(key, x)?;
    let y = x as f32;
    if y.is_finite() {
        Ok(y)
    } else {
        Err(invalid(key, format!("{x} is out of the f32 range")))
    }
}

fn to_f32_array<const N: usize>(key: &str, xs: [f64; N]) -> Res<[f32; N]> {
    let mut out = [0.0f32; N];
    for (i, &x) in xs.iter().enumerate() {
        out[i] = to_f32(&format!("{key}[{i}]"), x)?;
    }
    Ok(out)
}

/// `key` must be absent because `what` does not use it.
fn unused<T>(key: &str, value: &Option<T>, what: &str) -> Res<()> {
    match value {
        Some(_) => Err(invalid(key, format!("not used with {what}"))),
        None => Ok(()),
    }
}

fn required<T: Copy>(key: &str, value: Option<T>, what: &str) -> Res<T> {
    value.ok_or_else(|| invalid(key, format!("required with {what}")))
}

fn check_name(name: &str) -> Res<()> {
    if name.trim().is_empty() {
        return Err(invalid("name", "must not be empty"));
    }
    if name == "." || name == ".." {
        return Err(invalid(
            "name",
            format!("{name:?} is not a usable file name"),
        ));
    }
    if let Some(c) = name
        .chars()
        .find(|&c| c == '/' || c == '\\' || c.is_control())
    {
        return Err(invalid(
            "name",
            format!("is used in file names and must not contain {c:?}, got {name:?}"),
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Raw → SimConfig.

fn parse_named(text: &str, default_name: &str) -> Res<SimConfig> {
    let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::Toml(e.to_string()))?;
    build(raw, default_name)
}

fn build(raw: RawScenario, default_name: &str) -> Res<SimConfig> {
    let name = raw.name.unwrap_or_else(|| default_name.to_string());
    check_name(&name)?;

    let trajectory = build_trajectory(&raw.trajectory)?;
    let mut config = SimConfig::new(name, trajectory);

    if let Some(raw) = raw.controller {
        config.controller = build_controller(&raw)?;
    }
    let period = 1.0 / f64::from(config.controller.rate_hz);

    if let Some(d) = raw.duration {
        config.duration = positive("duration", d)?;
        if d > MAX_DURATION {
            return Err(invalid(
                "duration",
                format!("must be ≤ {MAX_DURATION} s (one day), got {d}"),
            ));
        }
    }
    if let Some(h) = raw.plant_step {
        config.plant_step = positive("plant_step", h)?;
    }
    let h = config.plant_step;
    if h > MAX_PLANT_STEP {
        return Err(invalid(
            "plant_step",
            format!("must be ≤ {MAX_PLANT_STEP} s, got {h}"),
        ));
    }
    if h > period {
        return Err(invalid(
            "plant_step",
            format!("must be ≤ the control period 1/rate_hz = {period} s, got {h}"),
        ));
    }
    // The loop holds τ over a whole number of plant steps (sil::run).
    let substeps = (period / h).round();
    if (substeps * h - period).abs() >= 1e-9 * period {
        return Err(invalid(
            "plant_step",
            format!(
                "must divide the control period 1/rate_hz = {period} s into whole steps, got {h}"
            ),
        ));
    }
    if let Some(b) = raw.ideal_actuators {
        config.ideal_actuators = b;
    }
    if let Some(offset) = raw.initial_offset {
        config.initial_offset = each("initial_offset", offset, finite)?;
    }
    if let Some(limit) = raw.divergence_limit {
        config.divergence_limit = positive("divergence_limit", limit)?;
    }
    if let Some(lag) = raw.thruster_lag {
        config.thruster_lag = Some(positive("thruster_lag", lag)?);
    }
    if let Some(raw) = raw.variation {
        config.variation = build_variation(&raw)?;
    }
    if let Some(raw) = raw.current {
        config.current = build_current(&raw)?;
    }
    if let Some(raw) = raw.noise {
        config.noise = Some(build_noise(&raw)?);
    }

    if let Some(raw) = raw.link_faults {
        config.link_faults = build_link_faults(&raw)?;
    }

    Controller::new(config.controller).map_err(|e| invalid("controller", e.to_string()))?;
    Ok(config)
}

fn build_link_faults(raw: &RawLinkFaults) -> Res<LinkFaults> {
    let ranges = |key: &str, v: &Option<Vec<String>>| -> Res<Vec<TickRange>> {
        v.iter()
            .flatten()
            .enumerate()
            .map(|(i, s)| {
                TickRange::parse(s).map_err(|m| invalid(format!("link_faults.{key}[{i}]"), m))
            })
            .collect()
    };
    Ok(LinkFaults {
        drop: ranges("drop", &raw.drop)?,
        corrupt: ranges("corrupt", &raw.corrupt)?,
        delay: ranges("delay", &raw.delay)?,
        delay_ticks: raw.delay_ticks.unwrap_or(5),
        silent: ranges("silent", &raw.silent)?,
    })
}

fn build_trajectory(raw: &RawTrajectory) -> Res<TrajectoryKind> {
    let what = format!("kind = \"{}\"", raw.kind.as_str());
    let (size_key, uses_depth_rate) = match raw.kind {
        KindName::Circle => ("radius", false),
        KindName::FigureEight => ("amplitude", false),
        KindName::LawnMower => ("scale", false),
        KindName::Helix => ("radius", true),
    };
    for (key, value) in [
        ("radius", raw.radius),
        ("amplitude", raw.amplitude),
        ("scale", raw.scale),
    ] {
        if key != size_key {
            unused(&format!("trajectory.{key}"), &value, &what)?;
        }
    }
    if !uses_depth_rate {
        unused("trajectory.depth_rate", &raw.depth_rate, &what)?;
    }
    let size_value = match size_key {
        "radius" => raw.radius,
        "amplitude" => raw.amplitude,
        _ => raw.scale,
    };
    // f64 → f32 as is: NaN and overflow to ±inf are reported by Trajectory::new.
    let size = required(&format!("trajectory.{size_key}"), size_value, &what)? as f32;
    let default_omega = match raw.kind {
        KindName::LawnMower => Trajectory::PAPER_LAWN_MOWER_OMEGA,
        _ => Trajectory::PAPER_OMEGA,
    };
    let omega = raw.omega.map_or(default_omega, |w| w as f32);
    let depth = raw.depth.map_or(Trajectory::PAPER_DEPTH, |d| d as f32);
    let kind = match raw.kind {
        KindName::Circle => TrajectoryKind::Circle {
            radius: size,
            omega,
            depth,
        },
        KindName::FigureEight => TrajectoryKind::FigureEight {
            amplitude: size,
            omega,
            depth,
        },
        KindName::LawnMower => TrajectoryKind::LawnMower {
            scale: size,
            omega,
            depth,
        },
        KindName::Helix => TrajectoryKind::Helix {
            radius: size,
            omega,
            depth,
            depth_rate: required("trajectory.depth_rate", raw.depth_rate, &what)? as f32,
        },
    };
    Trajectory::new(kind).map_err(|e| {
        let parameter = match e {
            TrajectoryError::NonFinite { parameter }
            | TrajectoryError::NotPositive { parameter, .. }
            | TrajectoryError::OutOfRange { parameter, .. } => parameter,
        };
        invalid(format!("trajectory.{parameter}"), e.to_string())
    })?;
    Ok(kind)
}

/// Δ from its nine fields: `None` if none is given, else the given ones with the rest 0.
/// Every value finite, and the varied plant's M positive definite.
fn build_delta(prefix: &str, fields: DeltaFields) -> Res<Option<ParamVariation<f64>>> {
    if fields.iter().all(|(_, v)| v.is_none()) {
        return Ok(None);
    }
    let mut x = [0.0f64; 9];
    for (slot, (key, value)) in x.iter_mut().zip(fields) {
        if let Some(v) = value {
            *slot = finite(&format!("{prefix}.{key}"), v)?;
        }
    }
    let delta = ParamVariation {
        mass: x[0],
        r_g: [x[1], x[2], x[3]],
        inertia: [x[4], x[5], x[6]],
        x_udot: x[7],
        y_vdot: x[8],
    };
    check_plant(prefix, &delta)?;
    Ok(Some(delta))
}

/// The plant with Δ must have a positive-definite inertia matrix (M is affine in Δ, so this at
/// the maximum of an abs-sin profile covers the whole profile).
fn check_plant(key: &str, delta: &ParamVariation<f64>) -> Res<()> {
    let p = VehicleParams::auv150().with_variation(delta);
    if p.mass > 0.0 && model::mass_matrix(&p).cholesky().is_some() {
        Ok(())
    } else {
        Err(invalid(
            key,
            "with this Δ the plant's inertia matrix M = M_RB + M_A is not positive definite",
        ))
    }
}

fn build_variation(raw: &RawVariation) -> Res<VariationProfile> {
    let what = format!("profile = \"{}\"", raw.profile.as_str());
    let uses_delta = matches!(raw.profile, ProfileName::Constant | ProfileName::AbsSin);
    if !uses_delta {
        for (key, value) in raw.delta() {
            unused(&format!("variation.{key}"), &value, &what)?;
        }
    }
    if !matches!(raw.profile, ProfileName::AbsSin) {
        unused("variation.omega", &raw.omega, &what)?;
    }
    if !matches!(raw.profile, ProfileName::Staircase) {
        unused("variation.steps", &raw.steps, &what)?;
    }
    let delta = || -> Res<ParamVariation<f64>> {
        Ok(build_delta("variation", raw.delta())?.unwrap_or(ParamVariation::TABLE3_MAX))
    };
    Ok(match raw.profile {
        ProfileName::None => VariationProfile::None,
        ProfileName::Constant => VariationProfile::Constant(delta()?),
        ProfileName::AbsSin => VariationProfile::AbsSin {
            max: delta()?,
            omega: positive(
                "variation.omega",
                raw.omega.unwrap_or(DEFAULT_ABS_SIN_OMEGA),
            )?,
        },
        ProfileName::Table3Staircase => VariationProfile::table3_staircase(),
        ProfileName::Staircase => {
            let steps = raw.steps.as_deref().unwrap_or_default();
            if steps.is_empty() {
                return Err(invalid(
                    "variation.steps",
                    format!("{what} needs at least one [[variation.steps]]"),
                ));
            }
            let mut out: Vec<(f64, ParamVariation<f64>)> = Vec::with_capacity(steps.len());
            for (i, step) in steps.iter().enumerate() {
                let prefix = format!("variation.steps[{i}]");
                let key = format!("{prefix}.until");
                let last = i + 1 == steps.len();
                let until = match step.until {
                    Some(u) if u.is_nan() => {
                        return Err(invalid(key, "must be a number, got NaN"));
                    }
                    Some(u) => u,
                    None if last => f64::INFINITY,
                    None => {
                        return Err(invalid(key, "required on every step but the last"));
                    }
                };
                match out.last() {
                    None if until <= 0.0 => {
                        return Err(invalid(key, format!("must be > 0 s, got {until}")));
                    }
                    Some(&(previous, _)) if until <= previous => {
                        return Err(invalid(
                            key,
                            format!(
                                "step times must increase: {until} is not > \
                                 variation.steps[{}].until = {previous}",
                                i - 1
                            ),
                        ));
                    }
                    _ => {}
                }
                let delta = build_delta(&prefix, step.delta())?.unwrap_or_default();
                out.push((until, delta));
            }
            VariationProfile::Staircase(out)
        }
    })
}

fn build_current(raw: &RawCurrent) -> Res<CurrentModel> {
    let what = format!("model = \"{}\"", raw.model.as_str());
    if !matches!(raw.model, CurrentName::Constant) {
        unused("current.velocity", &raw.velocity, &what)?;
    }
    if !matches!(raw.model, CurrentName::GaussMarkov) {
        unused("current.mean", &raw.mean, &what)?;
        unused("current.sigma", &raw.sigma, &what)?;
        unused("current.tau", &raw.tau, &what)?;
        unused("current.seed", &raw.seed, &what)?;
    }
    Ok(match raw.model {
        CurrentName::None => CurrentModel::None,
        CurrentName::Constant => CurrentModel::Constant(each(
            "current.velocity",
            required("current.velocity", raw.velocity, &what)?,
            finite,
        )?),
        CurrentName::GaussMarkov => CurrentModel::GaussMarkov {
            mean: each("current.mean", raw.mean.unwrap_or_default(), finite)?,
            sigma: each(
                "current.sigma",
                required("current.sigma", raw.sigma, &what)?,
                non_negative,
            )?,
            tau: positive("current.tau", required("current.tau", raw.tau, &what)?)?,
            seed: raw.seed.unwrap_or(DEFAULT_SEED),
        },
    })
}

fn build_noise(raw: &RawNoise) -> Res<SensorNoise> {
    Ok(SensorNoise {
        eta_sigma: each(
            "noise.eta_sigma",
            raw.eta_sigma.unwrap_or_default(),
            non_negative,
        )?,
        nu_sigma: each(
            "noise.nu_sigma",
            raw.nu_sigma.unwrap_or_default(),
            non_negative,
        )?,
        seed: raw.seed.unwrap_or(DEFAULT_SEED),
    })
}

/// Gains: finite, > 0 on the controlled axes, 0 on roll (index 3, not actuated).
fn gains(key: &str, k: [f64; 6]) -> Res<[f32; 6]> {
    for (i, &x) in k.iter().enumerate() {
        let key = format!("{key}[{i}]");
        finite(&key, x)?;
        if i == controller_core::law::ROLL {
            if x != 0.0 {
                return Err(invalid(
                    key,
                    format!("roll is not actuated: its gain must be 0, got {x}"),
                ));
            }
        } else {
            positive(&key, x)?;
        }
    }
    to_f32_array(key, k)
}

fn build_controller(raw: &RawController) -> Res<ControllerConfig> {
    let mut c = ControllerConfig::default();
    if let Some(robust) = raw.robust {
        c.robust = robust;
    }
    if let Some(law) = raw.law {
        c.law = match law {
            LawName::BoundaryLayer => RobustLaw::BoundaryLayer,
            LawName::Discontinuous => RobustLaw::Discontinuous,
        };
    }
    if let Some(k) = raw.k1 {
        c.k1 = gains("controller.k1", k)?;
    }
    if let Some(k) = raw.k2 {
        c.k2 = gains("controller.k2", k)?;
    }
    if let Some(q) = raw.q {
        c.q = to_f32_array("controller.q", each("controller.q", q, positive)?)?;
    }
    if let Some(beta) = raw.beta {
        c.beta = to_f32(
            "controller.beta",
            open_range("controller.beta", beta, 0.0, 1.0)?,
        )?;
    }
    if let Some(mu) = raw.mu {
        c.mu = to_f32("controller.mu", positive("controller.mu", mu)?)?;
    }
    if let Some(d) = raw.delta_max {
        c.delta_max = to_f32("controller.delta_max", positive("controller.delta_max", d)?)?;
    }
    if let Some(rate) = raw.rate_hz {
        if rate == 0 {
            return Err(invalid("controller.rate_hz", "must be ≥ 1, got 0"));
        }
        c.rate_hz = rate;
    }
    if let Some(deg) = raw.pitch_limit_deg {
        let key = "controller.pitch_limit_deg";
        // Through f32, so that 80 gives exactly the default 80.0_f32.to_radians().
        c.pitch_limit = to_f32(key, open_range(key, deg, 0.0, 90.0)?)?.to_radians();
    }
    if let Some(v) = raw.voltage_limit {
        c.voltage_limit = to_f32(
            "controller.voltage_limit",
            positive("controller.voltage_limit", v)?,
        )?;
    }
    if let Some(b) = raw.b_bound {
        c.b_bound = match b {
            BBoundName::ControlledRows => BBound::ControlledRows,
            BBoundName::Literal => BBound::Literal,
        };
    }
    Ok(c)
}
