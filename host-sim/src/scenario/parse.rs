//! [`ScenarioFile`] → [`SimConfig`]: the file's shape beyond what serde checks (keys the
//! chosen kind uses, required keys, defaults, unit conversions). Values are checked
//! afterwards, once, by [`Scenario::new`](super::Scenario::new).

use controller_core::effectiveness::ThrusterGeometry;
use controller_core::model::{ParamVariation, VARIED_PARAMETER_NAMES};
use controller_core::{allocation::AxisPriority, axes::NAMES as AXIS_NAMES};
use controller_core::{
    BBound, ControllerConfig, EstimatorKind, HeadingMode, RobustLaw, Table1Case, ThrustUnit,
};

use controller_core::effectiveness::THRUSTER_NAMES;

use super::file::{
    spelled, AttitudeName, BBoundName, ControllerTable, CurrentName, CurrentTable, Delta,
    EstimatorName, HeadingName, LawName, LinkFaultsTable, ProfileName, ScenarioFile,
    ThrustUnitName, TrajectoryTable, VariationTable,
};
use super::paper;
use super::validate::invalid;
use super::{Bound, InitialAttitude, LinkFaults, ScenarioError, SensorNoise, SimConfig, TickRange};
use crate::plant::{CurrentModel, Integrator, VariationProfile};
use crate::scenario::navigation::NoiseDraws;

/// Default `seed` of `[noise]`, `[navigation]` and the Gauss–Markov current.
pub const DEFAULT_SEED: u64 = 1;
/// Name given to a scenario without `name` by [`parse_scenario`](super::parse_scenario).
pub const DEFAULT_NAME: &str = "scenario";

type Res<T> = Result<T, ScenarioError>;

/// Parses `text`; a scenario without `name` is called `default_name`.
pub(super) fn parse(text: &str, default_name: &str) -> Res<SimConfig> {
    build(ScenarioFile::from_toml(text)?, default_name)
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

/// The configuration of a file's `[trajectory]` table: its path, heading, origin, speed limits
/// and time scale.
fn trajectory(raw: TrajectoryTable, name: String) -> Res<SimConfig> {
    let mut config = SimConfig::new(name, raw.path);
    if let Some(h) = raw.heading {
        config.heading = match h {
            HeadingName::Paper => HeadingMode::Paper,
            HeadingName::Tangent => HeadingMode::Tangent,
        };
    }
    config.origin = raw.origin;
    config.speed_limits = raw.speed_limits;
    if let Some(k) = raw.time_scale {
        config.time_scale = to_f32("trajectory.time_scale", k)?;
    }
    Ok(config)
}

/// The configuration a file describes; a file without `name` is called `default_name`.
pub(super) fn build(raw: ScenarioFile, default_name: &str) -> Res<SimConfig> {
    let name = raw.name.unwrap_or_else(|| default_name.to_string());
    let mut config = trajectory(raw.trajectory, name)?;
    if let Some(case) = raw.table1_case {
        config.case = Some(Table1Case::from_name(&case).ok_or_else(|| {
            let names: Vec<&str> = Table1Case::ALL.iter().map(|c| c.name()).collect();
            invalid(
                "table1_case",
                format!("{case:?} is not one of {}", names.join(", ")),
            )
        })?);
    }
    let est_keys = raw.controller.as_ref().map_or([false; 4], estimator_keys);
    if let Some(raw) = raw.controller {
        config.controller = build_controller(&raw)?;
    }
    config.duration = duration(raw.duration, &config)?;
    if let Some(h) = raw.plant_step {
        config.plant_step = h;
    }
    if let Some(name) = raw.plant_integrator {
        config.plant_integrator = integrator(&name)?;
    }
    if let Some(name) = raw.noise_draws {
        config.noise_draws = noise_draws(&name)?;
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
    config.bound_setting = raw.bound.map(|b| {
        Bound::with_defaults(
            b.max_path,
            b.saturated,
            b.max_reversals_per_s,
            b.max_command_tv,
        )
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
    navigation_and_filter(&mut config, raw.navigation.as_ref(), est_keys)?;
    if let Some(raw) = raw.link_faults {
        config.link_faults = build_link_faults(&raw)?;
    }
    Ok(config)
}

/// Which of the estimator's four keys a `[controller]` table gives (the real chain's default
/// fills the rest).
fn estimator_keys(c: &ControllerTable) -> [bool; 4] {
    [
        c.estimator.is_some(),
        c.estimator_position_sigma.is_some(),
        c.estimator_velocity_sigma.is_some(),
        c.estimator_accel_sigma.is_some(),
    ]
}

/// The file's navigation, else the real chain's default one with its filter for the estimator
/// keys the file does not give (Choices 370–371).
fn navigation_and_filter(
    config: &mut SimConfig,
    navigation: Option<&super::navigation::NavigationTable>,
    est_keys: [bool; 4],
) -> Res<()> {
    if let Some(raw) = navigation {
        config.navigation = super::navigation::build(raw, DEFAULT_SEED)?;
    } else if !config.ideal_actuators {
        config.navigation = super::navigation::real_chain_default(DEFAULT_SEED);
    }
    if !est_keys[0] && !config.ideal_actuators {
        let d = super::navigation::real_chain_estimator();
        let e = &mut config.controller.estimator;
        e.kind = d.kind;
        e.disturbance_time = d.disturbance_time;
        if !est_keys[1] {
            e.position_sigma = d.position_sigma;
        }
        if !est_keys[2] {
            e.velocity_sigma = d.velocity_sigma;
        }
        if !est_keys[3] {
            e.accel_sigma = d.accel_sigma;
        }
    }
    Ok(())
}

/// The file's `duration`, else a waypoint mission's whole path (Choice 312); a path that
/// cannot be built keeps the default, and validation names its key.
fn duration(given: Option<f64>, config: &SimConfig) -> Res<f64> {
    if let Some(d) = given {
        return Ok(d);
    }
    if let Ok(t) = controller_core::Trajectory::new(config.mission()) {
        if let Some(d) = super::path_time::default_duration(&t)? {
            return Ok(d);
        }
    }
    Ok(config.duration)
}

fn build_link_faults(raw: &LinkFaultsTable) -> Res<LinkFaults> {
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
fn build_delta(fields: &Delta) -> Option<ParamVariation<f64>> {
    if fields.iter().all(Option::is_none) {
        return None;
    }
    Some(ParamVariation::from_array(fields.map(|v| v.unwrap_or(0.0))))
}

fn build_variation(raw: &VariationTable) -> Res<VariationProfile> {
    let what = format!("profile = \"{}\"", spelled(&raw.profile));
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
            omega: raw.omega.unwrap_or_else(paper::abs_sin_omega),
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

fn build_current(raw: &CurrentTable) -> Res<CurrentModel> {
    let what = format!("model = \"{}\"", spelled(&raw.model));
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

fn build_controller(raw: &ControllerTable) -> Res<ControllerConfig> {
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
    if let Some(kind) = raw.estimator {
        c.estimator.kind = match kind {
            EstimatorName::Off => EstimatorKind::Off,
            EstimatorName::Kalman => EstimatorKind::Kalman,
        };
    }
    if let Some(x) = raw.estimator_position_sigma {
        c.estimator.position_sigma = to_f32_array("controller.estimator_position_sigma", x)?;
    }
    if let Some(x) = raw.estimator_velocity_sigma {
        c.estimator.velocity_sigma = to_f32_array("controller.estimator_velocity_sigma", x)?;
    }
    if let Some(x) = raw.estimator_accel_sigma {
        c.estimator.accel_sigma = to_f32_array("controller.estimator_accel_sigma", x)?;
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
pub(super) fn axis_priority(order: &[String]) -> Res<AxisPriority> {
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

/// The noise draws named `name` (`noise_draws`, Choice 536).
fn noise_draws(name: &str) -> Res<NoiseDraws> {
    NoiseDraws::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = NoiseDraws::ALL.iter().map(|d| d.name()).collect();
        invalid(
            "noise_draws",
            format!("{name:?} is not one of {}", names.join(", ")),
        )
    })
}

/// The plant integrator named `name` (`plant_integrator`, Choice 542).
fn integrator(name: &str) -> Res<Integrator> {
    Integrator::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Integrator::ALL.iter().map(|i| i.name()).collect();
        invalid(
            "plant_integrator",
            format!("{name:?} is not one of {}", names.join(", ")),
        )
    })
}
