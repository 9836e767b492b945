//! The one validation of a [`SimConfig`]: every value against its range, each error naming the
//! scenario file's dotted key. The controller's and the trajectory's own ranges are the core's
//! ([`Controller::new`], [`Trajectory::new`]); here their errors are only mapped to keys.

use controller_core::config::ConfigField;
use controller_core::model::{self, ParamVariation, VehicleParams, VARIED_PARAMETER_NAMES};
use controller_core::{Controller, Trajectory, TrajectoryKind};

use crate::config::{CurrentModel, SimConfig, VariationProfile};

use super::ScenarioError;

/// Longest accepted `duration` (s): one day.
pub const MAX_DURATION: f64 = 86_400.0;
/// Longest accepted `plant_step` (s).
pub const MAX_PLANT_STEP: f64 = 0.1;

type Res<T> = Result<T, ScenarioError>;

pub(super) fn invalid(key: impl Into<String>, message: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}

/// The controller, built; its error under the scenario key of the field it names
/// (`controller.k1[3]`, `controller.pitch_limit_deg`), or `controller` for a check of the
/// whole configuration and for settings a scenario file cannot reach.
pub(super) fn controller(config: &SimConfig) -> Res<Controller> {
    Controller::new(config.controller).map_err(|e| {
        let key = match e.field() {
            // The file gives the pitch limit in degrees.
            Some(ConfigField {
                name: "pitch_limit",
                ..
            }) => "controller.pitch_limit_deg".to_string(),
            Some(ConfigField {
                name: "params" | "uncertainty" | "geometry",
                ..
            })
            | None => "controller".to_string(),
            Some(ConfigField {
                name,
                index: Some(i),
            }) => format!("controller.{name}[{i}]"),
            Some(ConfigField { name, index: None }) => format!("controller.{name}"),
        };
        invalid(key, e.to_string())
    })
}

/// The trajectory, built; its error under `trajectory.<field>`.
pub(super) fn trajectory(kind: &TrajectoryKind) -> Res<Trajectory> {
    Trajectory::new(*kind)
        .map_err(|e| invalid(format!("trajectory.{}", e.parameter()), e.to_string()))
}

/// Everything else, in the order of the file; returns the step counts (control periods, plant
/// steps per period). `config.controller` is valid (so `rate_hz ≥ 1`).
pub(super) fn run(config: &SimConfig) -> Res<(u64, usize)> {
    check_name(&config.name)?;
    let rate = f64::from(config.controller.rate_hz);
    let period = 1.0 / rate;

    let d = positive("duration", config.duration)?;
    if d > MAX_DURATION {
        return Err(invalid(
            "duration",
            format!("must be ≤ {MAX_DURATION} s (one day), got {d}"),
        ));
    }
    let h = positive("plant_step", config.plant_step)?;
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
    each("initial_offset", &config.initial_offset, finite)?;
    positive("divergence_limit", config.divergence_limit)?;
    if let Some(lag) = config.thruster_lag {
        positive("thruster_lag", lag)?;
    }
    variation(&config.variation)?;
    current(&config.current)?;
    if let Some(n) = &config.noise {
        each("noise.eta_sigma", &n.eta_sigma, non_negative)?;
        each("noise.nu_sigma", &n.nu_sigma, non_negative)?;
    }
    let steps = (config.duration * rate).round() as u64;
    Ok((steps, substeps as usize))
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

/// `check` on every element, keyed `key[i]`.
fn each(key: &str, xs: &[f64], check: fn(&str, f64) -> Res<f64>) -> Res<()> {
    for (i, &x) in xs.iter().enumerate() {
        check(&format!("{key}[{i}]"), x)?;
    }
    Ok(())
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

/// Every Δ finite (keyed `prefix.<name>`), and the varied plant's M positive definite (keyed
/// `prefix`). M is affine in Δ, so this at the maximum of an abs-sin profile covers the whole
/// profile.
fn delta(prefix: &str, d: &ParamVariation<f64>) -> Res<()> {
    for (name, x) in VARIED_PARAMETER_NAMES.iter().zip(d.to_array()) {
        finite(&format!("{prefix}.{name}"), x)?;
    }
    let p = VehicleParams::auv150().with_variation(d);
    if p.mass > 0.0 && model::mass_matrix(&p).cholesky().is_some() {
        Ok(())
    } else {
        Err(invalid(
            prefix,
            "with this Δ the plant's inertia matrix M = M_RB + M_A is not positive definite",
        ))
    }
}

fn variation(v: &VariationProfile) -> Res<()> {
    match v {
        VariationProfile::None => Ok(()),
        VariationProfile::Constant(d) => delta("variation", d),
        VariationProfile::AbsSin { max, omega } => {
            delta("variation", max)?;
            positive("variation.omega", *omega).map(|_| ())
        }
        VariationProfile::Staircase(steps) => {
            if steps.is_empty() {
                return Err(invalid(
                    "variation.steps",
                    "profile = \"staircase\" needs at least one [[variation.steps]]",
                ));
            }
            let mut previous: Option<f64> = None;
            for (i, (until, d)) in steps.iter().enumerate() {
                let prefix = format!("variation.steps[{i}]");
                let key = format!("{prefix}.until");
                let until = *until;
                if until.is_nan() {
                    return Err(invalid(key, "must be a number, got NaN"));
                }
                match previous {
                    None if until <= 0.0 => {
                        return Err(invalid(key, format!("must be > 0 s, got {until}")));
                    }
                    Some(p) if until <= p => {
                        return Err(invalid(
                            key,
                            format!(
                                "step times must increase: {until} is not > \
                                 variation.steps[{}].until = {p}",
                                i - 1
                            ),
                        ));
                    }
                    _ => {}
                }
                previous = Some(until);
                delta(&prefix, d)?;
            }
            Ok(())
        }
    }
}

fn current(c: &CurrentModel) -> Res<()> {
    match c {
        CurrentModel::None => Ok(()),
        CurrentModel::Constant(v) => each("current.velocity", v, finite),
        CurrentModel::GaussMarkov {
            mean, sigma, tau, ..
        } => {
            each("current.mean", mean, finite)?;
            each("current.sigma", sigma, non_negative)?;
            positive("current.tau", *tau).map(|_| ())
        }
    }
}
