//! TOML → [`SimConfig`]: the file's shape (known keys, keys the chosen kind uses, required
//! keys, defaults, unit conversions). Values are checked afterwards, once, by
//! [`Scenario::new`](super::Scenario::new).

use std::fmt;

use controller_core::effectiveness::ThrusterGeometry;
use controller_core::model::{ParamVariation, VARIED_PARAMETERS, VARIED_PARAMETER_NAMES};
use controller_core::{allocation::AxisPriority, axes::NAMES as AXIS_NAMES};
use controller_core::{
    BBound, ControllerConfig, HeadingMode, RobustLaw, Table1Case, ThrustUnit, TrajectoryKind,
};
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};

use controller_core::effectiveness::THRUSTER_NAMES;

use super::validate::invalid;
use super::{fixed_arrays, paper};
use super::{Bound, InitialAttitude, LinkFaults, ScenarioError, SensorNoise, SimConfig, TickRange};
use crate::plant::{CurrentModel, VariationProfile};

/// Default `seed` of `[noise]` and of the Gauss–Markov current.
pub const DEFAULT_SEED: u64 = 1;
/// Name given to a scenario without `name` by [`parse_scenario`](super::parse_scenario).
pub const DEFAULT_NAME: &str = "scenario";

type Res<T> = Result<T, ScenarioError>;

/// Parses `text`; a scenario without `name` is called `default_name`.
pub(super) fn parse(text: &str, default_name: &str) -> Res<SimConfig> {
    let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::Toml(e.to_string()))?;
    build(raw, default_name)
}

// ---------------------------------------------------------------------------------------------
// Raw TOML shape.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    table1_case: Option<String>,
    duration: Option<f64>,
    plant_step: Option<f64>,
    ideal_actuators: Option<bool>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    initial_offset: Option<[f64; 6]>,
    divergence_limit: Option<f64>,
    thruster_lag: Option<f64>,
    expect_faults: Option<bool>,
    initial_attitude: Option<AttitudeName>,
    expect_missed: Option<bool>,
    bound: Option<RawBound>,
    trajectory: RawTrajectory,
    variation: Option<RawVariation>,
    current: Option<RawCurrent>,
    noise: Option<RawNoise>,
    controller: Option<RawController>,
    link_faults: Option<RawLinkFaults>,
}

/// `[trajectory]`: the path is the core's own type (kind-specific keys, defaults and unknown
/// keys are its serde form's), plus how the mission is flown: `heading` and `time_scale`.
#[derive(Deserialize)]
struct RawTrajectory {
    heading: Option<HeadingName>,
    time_scale: Option<f64>,
    origin: Option<[f64; 3]>,
    speed_limits: Option<Vec<f64>>,
    #[serde(flatten)]
    path: TrajectoryKind,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum HeadingName {
    Paper,
    Tangent,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum AttitudeName {
    Level,
    Trim,
}

/// `[bound]`: the bound a run must fly within; a key left out takes the real vehicle's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBound {
    max_path: Option<f64>,
    saturated: Option<f64>,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ThrustUnitName {
    Kgf,
    Newton,
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
    lose_upload_chunks: Option<Vec<u8>>,
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

/// The nine Δ of a table, by [`VARIED_PARAMETER_NAMES`]; `None`: not given.
type RawDelta = [Option<f64>; VARIED_PARAMETERS];

/// `[variation]`: `profile`, `omega`, `steps` and the nine Δ keys.
struct RawVariation {
    profile: ProfileName,
    trimmed: Option<bool>,
    omega: Option<f64>,
    steps: Option<Vec<RawStep>>,
    delta: RawDelta,
}

/// One `[[variation.steps]]`: `until` and the nine Δ keys.
struct RawStep {
    until: Option<f64>,
    delta: RawDelta,
}

/// Reads a table whose keys are the nine Δ keys and the ones `own` takes (it returns false for
/// a key it does not know); anything else is an unknown-field error.
fn visit_delta_table<'de, A: MapAccess<'de>>(
    map: &mut A,
    own_keys: &str,
    mut own: impl FnMut(&str, &mut A) -> Result<bool, A::Error>,
) -> Result<RawDelta, A::Error> {
    let mut delta = [None; VARIED_PARAMETERS];
    while let Some(key) = map.next_key::<String>()? {
        if own(&key, map)? {
            continue;
        }
        match VARIED_PARAMETER_NAMES.iter().position(|n| *n == key) {
            Some(i) => delta[i] = Some(map.next_value()?),
            None => {
                return Err(de::Error::custom(format_args!(
                    "unknown field `{key}`, expected {own_keys} or one of `{}`",
                    VARIED_PARAMETER_NAMES.join("`, `")
                )))
            }
        }
    }
    Ok(delta)
}

impl<'de> Deserialize<'de> for RawVariation {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> Visitor<'de> for Table {
            type Value = RawVariation;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a [variation] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawVariation, A::Error> {
                let (mut profile, mut omega, mut steps, mut trimmed) = (None, None, None, None);
                let own = "`profile`, `trimmed`, `omega`, `steps`";
                let delta = visit_delta_table(&mut map, own, |k, m| {
                    match k {
                        "profile" => profile = Some(m.next_value()?),
                        "trimmed" => trimmed = Some(m.next_value()?),
                        "omega" => omega = Some(m.next_value()?),
                        "steps" => steps = Some(m.next_value()?),
                        _ => return Ok(false),
                    }
                    Ok(true)
                })?;
                Ok(RawVariation {
                    profile: profile.ok_or_else(|| de::Error::missing_field("profile"))?,
                    trimmed,
                    omega,
                    steps,
                    delta,
                })
            }
        }
        deserializer.deserialize_map(Table)
    }
}

impl<'de> Deserialize<'de> for RawStep {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> Visitor<'de> for Table {
            type Value = RawStep;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a [[variation.steps]] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawStep, A::Error> {
                let mut until = None;
                let delta = visit_delta_table(&mut map, "`until`", |k, m| {
                    if k != "until" {
                        return Ok(false);
                    }
                    until = Some(m.next_value()?);
                    Ok(true)
                })?;
                Ok(RawStep { until, delta })
            }
        }
        deserializer.deserialize_map(Table)
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
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    velocity: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    mean: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    sigma: Option<[f64; 3]>,
    tau: Option<f64>,
    seed: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNoise {
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    eta_sigma: Option<[f64; 6]>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
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
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    k1: Option<[f64; 6]>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    k2: Option<[f64; 6]>,
    #[serde(default, deserialize_with = "fixed_arrays::option")]
    q: Option<[f64; 2]>,
    beta: Option<f64>,
    mu: Option<f64>,
    delta_max: Option<f64>,
    rate_hz: Option<u32>,
    pitch_limit_deg: Option<f64>,
    voltage_limit: Option<f64>,
    b_bound: Option<BBoundName>,
    thrust_unit: Option<ThrustUnitName>,
    axis_priority: Option<Vec<String>>,
    reversed_thrusters: Option<Vec<String>>,
}

// ---------------------------------------------------------------------------------------------
// Shape checks and conversions.

/// `x` as the controller's f32. A finite value beyond f32's range is refused here (it would
/// silently become ∞); NaN and ±∞ pass as they are, for the controller's checks to name.
fn to_f32(key: &str, x: f64) -> Res<f32> {
    let y = x as f32;
    if x.is_finite() && !y.is_finite() {
        Err(invalid(key, format!("{x} is out of the f32 range")))
    } else {
        Ok(y)
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

fn build(raw: RawScenario, default_name: &str) -> Res<SimConfig> {
    let name = raw.name.unwrap_or_else(|| default_name.to_string());
    let mut config = SimConfig::new(name, raw.trajectory.path);
    if let Some(h) = raw.trajectory.heading {
        config.heading = match h {
            HeadingName::Paper => HeadingMode::Paper,
            HeadingName::Tangent => HeadingMode::Tangent,
        };
    }
    config.origin = raw.trajectory.origin;
    config.speed_limits = raw.trajectory.speed_limits;
    if let Some(k) = raw.trajectory.time_scale {
        config.time_scale = to_f32("trajectory.time_scale", k)?;
    }
    if let Some(case) = raw.table1_case {
        config.case = Some(Table1Case::from_name(&case).ok_or_else(|| {
            let names: Vec<&str> = Table1Case::ALL.iter().map(|c| c.name()).collect();
            invalid(
                "table1_case",
                format!("{case:?} is not one of {}", names.join(", ")),
            )
        })?);
    }
    if let Some(raw) = raw.controller {
        config.controller = build_controller(&raw)?;
    }
    if let Some(d) = raw.duration {
        config.duration = d;
    }
    if let Some(h) = raw.plant_step {
        config.plant_step = h;
    }
    if let Some(b) = raw.ideal_actuators {
        config.ideal_actuators = b;
    }
    if let Some(offset) = raw.initial_offset {
        config.initial_offset = offset;
    }
    if let Some(limit) = raw.divergence_limit {
        config.divergence_limit = limit;
    }
    config.thruster_lag = raw.thruster_lag;
    config.expect_faults = raw.expect_faults.unwrap_or(false);
    config.expect_missed = raw.expect_missed.unwrap_or(false);
    config.start_attitude = raw.initial_attitude.map(|a| match a {
        AttitudeName::Level => InitialAttitude::Level,
        AttitudeName::Trim => InitialAttitude::Trim,
    });
    config.bound_setting = raw.bound.map(|b| Bound {
        max_path: b.max_path.unwrap_or(Bound::REAL_VEHICLE.max_path),
        saturated: b.saturated.unwrap_or(Bound::REAL_VEHICLE.saturated),
    });
    if let Some(raw) = raw.variation {
        config.variation = build_variation(&raw)?;
        config.trimmed = raw.trimmed.unwrap_or(false);
    }
    if let Some(raw) = raw.current {
        config.current = build_current(&raw)?;
    }
    if let Some(raw) = raw.noise {
        config.noise = Some(SensorNoise {
            eta_sigma: raw.eta_sigma.unwrap_or_default(),
            nu_sigma: raw.nu_sigma.unwrap_or_default(),
            seed: raw.seed.unwrap_or(DEFAULT_SEED),
        });
    }
    if let Some(raw) = raw.link_faults {
        config.link_faults = build_link_faults(&raw)?;
    }
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
        delay_ticks: raw.delay_ticks.unwrap_or(LinkFaults::DEFAULT_DELAY_TICKS),
        silent: ranges("silent", &raw.silent)?,
        lose_upload_chunks: raw.lose_upload_chunks.clone().unwrap_or_default(),
    })
}

/// Δ from its nine fields: `None` if none is given, else the given ones with the rest 0.
fn build_delta(fields: &RawDelta) -> Option<ParamVariation<f64>> {
    if fields.iter().all(Option::is_none) {
        return None;
    }
    Some(ParamVariation::from_array(fields.map(|v| v.unwrap_or(0.0))))
}

fn build_variation(raw: &RawVariation) -> Res<VariationProfile> {
    let what = format!("profile = \"{}\"", raw.profile.as_str());
    let uses_delta = matches!(raw.profile, ProfileName::Constant | ProfileName::AbsSin);
    if !uses_delta {
        for (key, value) in VARIED_PARAMETER_NAMES.iter().zip(&raw.delta) {
            unused(&format!("variation.{key}"), value, &what)?;
        }
    }
    if !matches!(raw.profile, ProfileName::AbsSin) {
        unused("variation.omega", &raw.omega, &what)?;
    }
    if !matches!(raw.profile, ProfileName::Staircase) {
        unused("variation.steps", &raw.steps, &what)?;
    }
    let delta = || build_delta(&raw.delta).unwrap_or(ParamVariation::TABLE3_MAX);
    Ok(match raw.profile {
        ProfileName::None => VariationProfile::None,
        ProfileName::Constant => VariationProfile::Constant(delta()),
        ProfileName::AbsSin => VariationProfile::AbsSin {
            max: delta(),
            omega: raw.omega.unwrap_or(paper::ABS_SIN_OMEGA),
        },
        ProfileName::Table3Staircase => paper::table3_staircase(),
        ProfileName::Staircase => {
            let steps = raw.steps.as_deref().unwrap_or_default();
            let mut out = Vec::with_capacity(steps.len());
            for (i, step) in steps.iter().enumerate() {
                let until = match step.until {
                    Some(u) => u,
                    None if i + 1 == steps.len() => f64::INFINITY,
                    None => {
                        return Err(invalid(
                            format!("variation.steps[{i}].until"),
                            "required on every step but the last",
                        ));
                    }
                };
                out.push((until, build_delta(&step.delta).unwrap_or_default()));
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
        CurrentName::Constant => {
            CurrentModel::Constant(required("current.velocity", raw.velocity, &what)?)
        }
        CurrentName::GaussMarkov => CurrentModel::GaussMarkov {
            mean: raw.mean.unwrap_or_default(),
            sigma: required("current.sigma", raw.sigma, &what)?,
            tau: required("current.tau", raw.tau, &what)?,
            seed: raw.seed.unwrap_or(DEFAULT_SEED),
        },
    })
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
        c.k1 = to_f32_array("controller.k1", k)?;
    }
    if let Some(k) = raw.k2 {
        c.k2 = to_f32_array("controller.k2", k)?;
    }
    if let Some(q) = raw.q {
        c.q = to_f32_array("controller.q", q)?;
    }
    if let Some(beta) = raw.beta {
        c.beta = to_f32("controller.beta", beta)?;
    }
    if let Some(mu) = raw.mu {
        c.mu = to_f32("controller.mu", mu)?;
    }
    if let Some(d) = raw.delta_max {
        c.delta_max = to_f32("controller.delta_max", d)?;
    }
    if let Some(rate) = raw.rate_hz {
        c.rate_hz = rate;
    }
    if let Some(deg) = raw.pitch_limit_deg {
        // Through f32, so that 80 gives exactly the default 80.0_f32.to_radians().
        c.pitch_limit = to_f32("controller.pitch_limit_deg", deg)?.to_radians();
    }
    if let Some(v) = raw.voltage_limit {
        c.voltage_limit = to_f32("controller.voltage_limit", v)?;
    }
    if let Some(b) = raw.b_bound {
        c.b_bound = match b {
            BBoundName::ControlledRows => BBound::ControlledRows,
            BBoundName::Literal => BBound::Literal,
        };
    }
    if let Some(u) = raw.thrust_unit {
        c.thrust_unit = match u {
            ThrustUnitName::Kgf => ThrustUnit::Kgf,
            ThrustUnitName::Newton => ThrustUnit::Newton,
        };
    }
    if let Some(order) = &raw.axis_priority {
        c.priority = axis_priority(order)?;
    }
    if let Some(names) = &raw.reversed_thrusters {
        c.geometry =
            ThrusterGeometry::auv150(reversed_mask("controller.reversed_thrusters", names)?);
    }
    Ok(c)
}

/// `controller.reversed_thrusters`: the thrusters (by [`THRUSTER_NAMES`]) mounted with their
/// strong (positive-thrust) side against their reference axis (+x main, +z vertical, +y
/// horizontal), each at most once: the AUV-150 layout with those mounting signs
/// ([`ThrusterGeometry::auv150`], docs/real-vehicle.md#the-default-mounting).
/// `key` names the list in errors (`key[i]`); a campaign's `draw.mountings[k]` uses it too.
pub fn reversed_mask(key: &str, names: &[String]) -> Res<u8> {
    let mut mask = 0u8;
    for (i, name) in names.iter().enumerate() {
        let t = THRUSTER_NAMES
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| {
                invalid(
                    format!("{key}[{i}]"),
                    format!(
                        "{name:?} is not a thruster: one of `{}`",
                        THRUSTER_NAMES.join("`, `")
                    ),
                )
            })?;
        if mask & (1 << t) != 0 {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("{name:?} is given twice"),
            ));
        }
        mask |= 1 << t;
    }
    Ok(mask)
}

/// `controller.axis_priority`: the five actuated axes by name ([`AXIS_NAMES`] without roll),
/// each once, highest first; equal weights (docs/thrusters.md#allocation-blocks-and-the-axis-priority).
fn axis_priority(order: &[String]) -> Res<AxisPriority> {
    let key = "controller.axis_priority";
    let actuated: Vec<&str> = AXIS_NAMES
        .iter()
        .copied()
        .filter(|n| *n != "roll")
        .collect();
    let expected = || format!("each of `{}` once, highest first", actuated.join("`, `"));
    if order.len() != actuated.len() {
        return Err(invalid(
            key,
            format!("{} axes given, need {}", order.len(), expected()),
        ));
    }
    let mut priority = AxisPriority {
        rank: [0; 6],
        ..AxisPriority::default()
    };
    for (i, name) in order.iter().enumerate() {
        let axis = AXIS_NAMES
            .iter()
            .position(|n| n == name && *n != "roll")
            .ok_or_else(|| {
                invalid(
                    format!("{key}[{i}]"),
                    format!("{name:?} is not an actuated axis: need {}", expected()),
                )
            })?;
        if priority.rank[axis] != 0 {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("{name:?} is given twice: need {}", expected()),
            ));
        }
        priority.rank[axis] = (order.len() - i) as u8;
    }
    Ok(priority)
}
