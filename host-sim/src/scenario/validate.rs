//! The one validation of a [`SimConfig`]: every value against its range, each error naming the
//! scenario file's dotted key. The controller's and the trajectory's own ranges are the core's
//! ([`Controller::new`], [`Trajectory::new`]); here their errors are only mapped to keys.

use std::f64::consts::{FRAC_PI_2, PI};

use controller_core::config::ConfigField;
use controller_core::controller::{MAX_ANGULAR_RATE, MAX_LINEAR_SPEED, MAX_POSITION};
use controller_core::model::{self, ParamVariation, VehicleParams, VARIED_PARAMETER_NAMES};
use controller_core::readable::Readable;
use controller_core::trajectory::MAX_SPEED;
use controller_core::{Controller, Mission, Trajectory, TrajectoryKind};
use controller_core::{Fault, Status};

use super::start::start_state;
use super::{plan, Bound, SensorNoise, SimConfig};
use crate::plant::{CurrentModel, VariationProfile};

use super::ScenarioError;

/// Longest accepted `duration` (s): one day.
pub const MAX_DURATION: f64 = 86_400.0;
/// Longest accepted `plant_step` (s).
pub const MAX_PLANT_STEP: f64 = 0.1;
/// Most control periods (duration × rate_hz) a run may have (one day at the default 100 Hz):
/// each period is a CSV row (≈ 1 kB) and a controller update. More needs the explicit override
/// [`SimConfig::allow_long_run`] (the CLI's `--allow-long-run`).
pub const MAX_CONTROL_PERIODS: u64 = 8_640_000;
/// Most plant RK4 steps a run may have (one day at the default 1 ms step): the work of a run.
/// More needs [`SimConfig::allow_long_run`].
pub const MAX_PLANT_STEPS: u64 = 86_400_000;
/// Even with the override, step counts stay below 2⁵³, where counting in f64 is exact (a
/// `plant_step` of 1e-300 would otherwise loop for ever).
const ABSOLUTE_MAX_STEPS: f64 = 9_007_199_254_740_992.0;
/// Fastest ocean current (m/s, ‖v‖; for a Gauss–Markov current its mean, and ‖σ‖):
/// **Choice 124**, twice the AUV-150's top speed. At full main thrust (≈ 719 N at ±24 V) the
/// surge damping 120 u|u| N allows √(719/120) ≈ 2.45 m/s; a current beyond twice that no
/// thrust model (ideal or real) makes a question worth simulating, and 10³⁰⁸ m/s made every
/// run diverge at t = 0.
pub const MAX_CURRENT_SPEED: f64 = 5.0;
/// Longest `thruster_lag` (s), Choice 124: real thrusters answer in about 0.1 s.
pub const MAX_THRUSTER_LAG: f64 = 10.0;
/// Largest ω·plant_step of an abs-sin variation (rad): at least 2π/0.1 ≈ 63 plant steps per
/// period of sin, so that the plant resolves the variation (and ω·t stays finite).
pub const MAX_VARIATION_OMEGA_STEP: f64 = 0.1;

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
                name: "priority", ..
            }) => "controller.axis_priority".to_string(),
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

/// The mission's trajectory, built; its error under `trajectory.<field>` (`trajectory.radius`,
/// `trajectory.time_scale`, `trajectory.heading`).
pub(super) fn trajectory(mission: &Mission) -> Res<Trajectory> {
    Trajectory::new(*mission)
        .map_err(|e| invalid(format!("trajectory.{}", e.parameter()), e.to_string()))
}

/// Everything else, in the order of the file; returns the step counts (control periods, plant
/// steps per period). `config.controller` is valid (so `rate_hz ≥ 1`).
pub(super) fn run(config: &SimConfig) -> Res<(u64, usize)> {
    check_name(&config.name)?;
    check_origin(config.origin)?;
    check_speed_limits(config)?;
    check_lost_chunks(config)?;
    let rate = f64::from(config.controller.rate_hz);
    let period = 1.0 / rate;

    let d = positive("duration", config.duration)?;
    if d > MAX_DURATION {
        return Err(invalid(
            "duration",
            format!("must be ≤ {MAX_DURATION} s (one day), got {}", Readable(d)),
        ));
    }
    let h = positive("plant_step", config.plant_step)?;
    if h > MAX_PLANT_STEP {
        return Err(invalid(
            "plant_step",
            format!("must be ≤ {MAX_PLANT_STEP} s, got {}", Readable(h)),
        ));
    }
    if h > period {
        return Err(invalid(
            "plant_step",
            format!(
                "must be ≤ the control period 1/rate_hz = {} s, got {}",
                Readable(period),
                Readable(h)
            ),
        ));
    }
    // The loop holds τ over a whole number of plant steps (sil::run).
    let substeps = (period / h).round();
    let steps = (config.duration * rate).round();
    step_cap(config, steps, substeps)?;
    if (substeps * h - period).abs() >= 1e-9 * period {
        return Err(invalid(
            "plant_step",
            format!(
                "must divide the control period 1/rate_hz = {} s into whole steps, got {}",
                Readable(period),
                Readable(h)
            ),
        ));
    }
    each("initial_offset", &config.initial_offset, finite)?;
    if let Some(b) = &config.bound_setting {
        bound(b)?;
    }
    let limit = at_most(
        "divergence_limit",
        positive("divergence_limit", config.divergence_limit)?,
        f64::from(MAX_POSITION),
        "m, the positions the controller accepts",
    )?;
    start_offset(&config.initial_offset, limit)?;
    if let Some(lag) = config.thruster_lag {
        let what = "s: a thruster slower than that is not one the vehicle has";
        at_most(
            "thruster_lag",
            positive("thruster_lag", lag)?,
            MAX_THRUSTER_LAG,
            what,
        )?;
    }
    variation(&config.variation, h)?;
    current(&config.current, h)?;
    sensors(config, limit)?;
    Ok((steps as u64, substeps as usize))
}

/// `x` if it is ≤ `max` (a physical limit, Choice 124; `unit` says what `max` is).
fn at_most(key: &str, x: f64, max: f64, unit: &str) -> Res<f64> {
    if x <= max {
        Ok(x)
    } else {
        Err(invalid(
            key,
            format!("must be ≤ {} {unit}, got {}", Readable(max), Readable(x)),
        ))
    }
}

/// Where a run may start (Choice 124): the position offset inside the divergence limit (else
/// the run stops before its first period, with nothing recorded), roll and yaw within ±π (a
/// larger offset is the same attitude), pitch inside ±π/2 (where the Euler angles are
/// singular). A pitch past the controller's pitch limit is allowed: it starts the controller
/// in fail-safe, which is a case worth flying.
fn start_offset(offset: &[f64; 6], limit: f64) -> Res<()> {
    let p = norm3(&[offset[0], offset[1], offset[2]]);
    if p > limit {
        return Err(invalid(
            "initial_offset",
            format!(
                "the start is {} m from the reference, beyond divergence_limit = {} m: the run \
                 would stop before its first period",
                Readable(p),
                Readable(limit)
            ),
        ));
    }
    let half_turn = "rad (a larger offset is the same attitude)";
    at_most("initial_offset[3]", offset[3].abs(), PI, half_turn)?;
    at_most("initial_offset[5]", offset[5].abs(), PI, half_turn)?;
    if offset[4].abs() >= FRAC_PI_2 {
        return Err(invalid(
            "initial_offset[4]",
            format!(
                "the pitch offset must be inside ±π/2 rad, where the Euler angles are singular, \
                 got {}",
                Readable(offset[4])
            ),
        ));
    }
    Ok(())
}

/// `[noise]` and `[navigation]`.
fn sensors(config: &SimConfig, limit: f64) -> Res<()> {
    if let Some(n) = &config.noise {
        noise(n, limit)?;
    }
    match &config.navigation {
        Some(n) => super::navigation::validate(n),
        None => Ok(()),
    }
}

/// Measurement noise a sensor could have (Choice 124): each σ ≥ 0; a position σ at most the
/// divergence limit, an angle σ at most π, a velocity σ at most what the controller accepts
/// as input.
fn noise(n: &SensorNoise, limit: f64) -> Res<()> {
    each("noise.eta_sigma", &n.eta_sigma, non_negative)?;
    each("noise.nu_sigma", &n.nu_sigma, non_negative)?;
    let linear = f64::from(MAX_LINEAR_SPEED);
    let angular = f64::from(MAX_ANGULAR_RATE);
    for i in 0..6 {
        let (max, unit) = if i < 3 {
            (limit, "m, the divergence limit")
        } else {
            (PI, "rad")
        };
        at_most(&format!("noise.eta_sigma[{i}]"), n.eta_sigma[i], max, unit)?;
        let (max, unit) = if i < 3 {
            (linear, "m/s, the speeds the controller accepts")
        } else {
            (angular, "rad/s, the rates the controller accepts")
        };
        at_most(&format!("noise.nu_sigma[{i}]"), n.nu_sigma[i], max, unit)?;
    }
    Ok(())
}

/// ‖v‖, without overflow for any finite v (a message then names 1e308, not inf).
fn norm3(v: &[f64; 3]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return 0.0;
    }
    m * v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
}

/// A current's speed ‖v‖ within [`MAX_CURRENT_SPEED`] (Choice 124).
fn current_speed(key: &str, v: &[f64; 3]) -> Res<()> {
    let speed = norm3(v);
    at_most(
        key,
        speed,
        MAX_CURRENT_SPEED,
        "m/s in norm, twice the AUV-150's top speed: a current the vehicle could never meet",
    )
    .map(|_| ())
}

/// The run's size against [`MAX_CONTROL_PERIODS`] and [`MAX_PLANT_STEPS`] (unless
/// `allow_long_run`), and against 2⁵³ always: `steps` = duration × rate_hz control periods
/// (the run samples ticks 0..=steps), `substeps` plant steps each.
fn step_cap(config: &SimConfig, steps: f64, substeps: f64) -> Res<()> {
    let periods = steps;
    let plant = steps * substeps;
    let how = "(duration × rate_hz control periods, each 1/(rate_hz × plant_step) plant steps)";
    if periods > ABSOLUTE_MAX_STEPS || plant > ABSOLUTE_MAX_STEPS {
        return Err(invalid(
            "plant_step",
            format!(
                "the run would take {plant:.3e} plant steps and {periods:.3e} control periods \
                 {how}: more than 2^53, beyond any run"
            ),
        ));
    }
    if config.allow_long_run {
        return Ok(());
    }
    let over = |count: f64, cap: u64, what: &str, key: &str| -> Res<()> {
        if count > cap as f64 {
            Err(invalid(
                key,
                format!(
                    "the run would take {count:.0} {what} {how}, more than the cap of {cap} \
                     (one day at the default 100 Hz and 1 ms); shorten it, or give \
                     --allow-long-run to run it anyway (the CSV grows by ≈ 1 kB a period)"
                ),
            ))
        } else {
            Ok(())
        }
    };
    over(periods, MAX_CONTROL_PERIODS, "control periods", "duration")?;
    over(plant, MAX_PLANT_STEPS, "plant steps", "plant_step")
}

fn finite(key: &str, x: f64) -> Res<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(
            key,
            format!("must be a finite number, got {}", Readable(x)),
        ))
    }
}

/// `[bound]`: a path limit > 0, a saturated fraction in [0, 1], chatter limits ≥ 0.
fn bound(b: &Bound) -> Res<()> {
    positive("bound.max_path", b.max_path)?;
    non_negative("bound.max_reversals_per_s", b.max_reversals_per_s)?;
    non_negative("bound.max_command_tv", b.max_command_tv)?;
    let s = non_negative("bound.saturated", b.saturated)?;
    if s > 1.0 {
        return Err(invalid(
            "bound.saturated",
            format!("is a fraction of the control periods, in [0, 1], got {s}"),
        ));
    }
    Ok(())
}

fn positive(key: &str, x: f64) -> Res<f64> {
    finite(key, x)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be > 0, got {}", Readable(x))))
    }
}

fn non_negative(key: &str, x: f64) -> Res<f64> {
    finite(key, x)?;
    if x >= 0.0 {
        Ok(x)
    } else {
        Err(invalid(key, format!("must be ≥ 0, got {}", Readable(x))))
    }
}

/// `check` on every element, keyed `key[i]`.
fn each(key: &str, xs: &[f64], check: fn(&str, f64) -> Res<f64>) -> Res<()> {
    for (i, &x) in xs.iter().enumerate() {
        check(&format!("{key}[{i}]"), x)?;
    }
    Ok(())
}

/// `trajectory.origin`: a latitude in [−90, 90] and not within
/// [`plan::pole_margin_degrees`] of a pole (**Choice 301**, [`plan::Origin::new`]), a longitude
/// in [−180, 180], a finite altitude.
fn check_origin(origin: Option<[f64; 3]>) -> Res<()> {
    let Some([lat, lon, alt]) = origin else {
        return Ok(());
    };
    let range = match lon.abs() <= 180.0 {
        true => plan::Origin::new(lat, lon, alt)
            .map(|_| ())
            .map_err(|e| e.to_string()),
        false => Err(format!(
            "longitude {} is outside [-180, 180]",
            Readable(lon)
        )),
    };
    range.map_err(|why| {
        invalid(
            "trajectory.origin",
            format!(
                "must be [latitude, longitude, altitude] off the poles, got [{}, {}, {}]: {why}",
                Readable(lat),
                Readable(lon),
                Readable(alt)
            ),
        )
    })
}

/// `trajectory.speed_limits` (**Choice 161**): a waypoint mission's, one per leg (n − 1 for n
/// points), each finite in (0, [`MAX_SPEED`]] m/s; the error names the leg.
fn check_speed_limits(config: &SimConfig) -> Res<()> {
    const KEY: &str = "trajectory.speed_limits";
    let Some(caps) = &config.speed_limits else {
        return Ok(());
    };
    let TrajectoryKind::Waypoints { points, .. } = config.trajectory else {
        return Err(invalid(KEY, "only used with kind = \"waypoints\""));
    };
    let legs = points.as_slice().len().saturating_sub(1);
    if caps.len() != legs {
        return Err(invalid(
            KEY,
            format!(
                "needs one speed per leg ({legs} for {} points), got {}",
                legs + 1,
                caps.len()
            ),
        ));
    }
    let max = f64::from(MAX_SPEED);
    match caps.iter().position(|&v| !(v > 0.0 && v <= max)) {
        Some(leg) => Err(invalid(
            KEY,
            format!(
                "leg {leg}: must be a speed in (0, {}] m/s, got {}",
                Readable(max),
                Readable(caps[leg])
            ),
        )),
        None => Ok(()),
    }
}

/// `link_faults.lose_upload_chunks` (**Choice 166**): only a waypoint mission is uploaded, and
/// each index must be one of its upload's chunks.
fn check_lost_chunks(config: &SimConfig) -> Res<()> {
    const KEY: &str = "link_faults.lose_upload_chunks";
    let lost = &config.link_faults.lose_upload_chunks;
    if lost.is_empty() {
        return Ok(());
    }
    let mission = controller_core::Mission {
        path: config.trajectory,
        heading: config.heading,
        time_scale: config.time_scale,
    };
    let Some(up) = auv_link::MissionUpload::of(&mission) else {
        return Err(invalid(
            KEY,
            "only a waypoint mission is uploaded (kind = \"waypoints\")",
        ));
    };
    match lost.iter().find(|&&i| i >= up.chunks()) {
        Some(i) => Err(invalid(
            KEY,
            format!(
                "chunk {i}: the upload has {} chunks (0 to {})",
                up.chunks(),
                up.chunks() - 1
            ),
        )),
        None => Ok(()),
    }
}

/// A scenario `name`: used in file names, so not empty, not `.` or `..`, and without `/`, `\` or
/// a control character (the error is keyed `name`).
pub fn check_name(name: &str) -> Res<()> {
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

fn variation(v: &VariationProfile, plant_step: f64) -> Res<()> {
    match v {
        VariationProfile::None => Ok(()),
        VariationProfile::Constant(d) => delta("variation", d),
        VariationProfile::AbsSin { max, omega } => {
            delta("variation", max)?;
            let omega = positive("variation.omega", *omega)?;
            if omega * plant_step > MAX_VARIATION_OMEGA_STEP {
                return Err(invalid(
                    "variation.omega",
                    format!(
                        "{} rad/s is too fast for the plant step {} s: ω·plant_step must be ≤ \
                         {MAX_VARIATION_OMEGA_STEP} (≥ 63 plant steps per period), so ω ≤ {} rad/s",
                        Readable(omega),
                        Readable(plant_step),
                        Readable(MAX_VARIATION_OMEGA_STEP / plant_step)
                    ),
                ));
            }
            Ok(())
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
                        return Err(invalid(
                            key,
                            format!("must be > 0 s, got {}", Readable(until)),
                        ));
                    }
                    Some(p) if until <= p => {
                        return Err(invalid(
                            key,
                            format!(
                                "step times must increase: {} is not > \
                                 variation.steps[{}].until = {}",
                                Readable(until),
                                i - 1,
                                Readable(p)
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

fn current(c: &CurrentModel, plant_step: f64) -> Res<()> {
    match c {
        CurrentModel::None => Ok(()),
        CurrentModel::Constant(v) => {
            each("current.velocity", v, finite)?;
            current_speed("current.velocity", v)
        }
        CurrentModel::GaussMarkov {
            mean, sigma, tau, ..
        } => {
            each("current.mean", mean, finite)?;
            current_speed("current.mean", mean)?;
            each("current.sigma", sigma, non_negative)?;
            current_speed("current.sigma", sigma)?;
            let tau = positive("current.tau", *tau)?;
            // Euler–Maruyama of v̇ = −(v − mean)/τ + …: v ← (1 − h/τ) v + …, unstable for
            // h > 2τ, and its stationary variance is σ²/(1 − h/2τ) (≤ 5 % high for τ ≥ 10 h).
            if tau < plant_step {
                return Err(invalid(
                    "current.tau",
                    format!(
                        "{} s is below the plant step {} s: the Gauss–Markov process \
                         is stepped by Euler–Maruyama at the plant step, which is unstable for \
                         tau < plant_step/2 and inflates the variance by 1/(1 − plant_step/(2 tau)) \
                         (×2 at tau = plant_step); use tau ≥ plant_step, better ≥ 10 plant steps",
                        Readable(tau),
                        Readable(plant_step)
                    ),
                ));
            }
            Ok(())
        }
    }
}

/// Every control tick of the mission up to this many is checked by [`mission`]; a longer
/// mission is checked at this many evenly spaced ticks.
const MISSION_SAMPLES: u64 = 100_000;

/// What the run would do to the controller, refused before it starts (with the reason):
/// - a reference that leaves the range the controller accepts as input
///   ([`MAX_POSITION`] per position component, [`MAX_LINEAR_SPEED`] for ‖η̇_d‖ of the
///   position, [`MAX_ANGULAR_RATE`] for the Euler-angle rates): a vehicle on it would be in
///   fail-safe (`fault:input-out-of-range`) from then on;
/// - a law that overflows f32 on the reference itself (zero error, the first period): then
///   every update would (`fault:non-finite-result`), e.g. for gains like 1e30.
pub(super) fn mission(
    config: &SimConfig,
    controller: &Controller,
    trajectory: &Trajectory,
    steps: u64,
) -> Res<()> {
    let rate = config.controller.rate_hz;
    let n = steps.clamp(1, MISSION_SAMPLES);
    let t_of = |k: u64| k as f64 / f64::from(rate);
    for j in 0..=n {
        let k = (u128::from(j) * u128::from(steps) / u128::from(n)) as u64;
        let d = trajectory.sample(k, rate);
        let speed = d.eta_dot.fixed_rows::<3>(0).norm();
        let turn = d.eta_dot.fixed_rows::<3>(3).norm();
        let position = d.eta.fixed_rows::<3>(0).amax();
        let refuse = |what: String| {
            invalid(
                "trajectory",
                format!(
                    "at t = {:.2} s {what}: a vehicle on this reference would be in fail-safe \
                     (fault:input-out-of-range)",
                    t_of(k)
                ),
            )
        };
        if !speed.is_finite() || speed > MAX_LINEAR_SPEED {
            return Err(refuse(format!(
                "the reference moves at {} m/s, above the {MAX_LINEAR_SPEED} m/s the controller \
                 accepts",
                Readable(speed)
            )));
        }
        if !turn.is_finite() || turn > MAX_ANGULAR_RATE {
            return Err(refuse(format!(
                "the reference turns at {} rad/s, above the {MAX_ANGULAR_RATE} rad/s the \
                 controller accepts",
                Readable(turn)
            )));
        }
        if !position.is_finite() || position > MAX_POSITION {
            return Err(refuse(format!(
                "the reference is {} m from the mission origin along an axis, beyond the \
                 ±{MAX_POSITION} m the controller accepts (shorten the mission)",
                Readable(position)
            )));
        }
    }
    let start = start_state(trajectory, rate, &[0.0; 6]);
    let out = controller.update(
        0,
        &start.eta.cast::<f32>().into(),
        &start.nu.cast::<f32>().into(),
        trajectory,
    );
    if out.status == Status::Fault(Fault::NonFiniteResult) {
        return Err(invalid(
            "controller",
            format!(
                "on the reference itself (zero tracking error, first period) the law overflows \
                 f32 ({}): every update would put the thrusters off; the gains k1, k2 (or q) are \
                 too large",
                out.status
            ),
        ));
    }
    Ok(())
}
