//! [`SimConfig`] → [`ScenarioFile`]: the file that reads back to a configuration, every key
//! written (a later change of a default does not change what it flies). What a file cannot say
//! (a vehicle model or geometry other than the AUV-150's, unequal axis weights) is refused by
//! name ([`Unwritable`]).

use controller_core::allocation::AxisPriority;
use controller_core::axes::NAMES as AXIS_NAMES;
use controller_core::effectiveness::THRUSTER_NAMES;
use controller_core::model::ParamVariation;
use controller_core::{
    BBound, ControllerConfig, EstimatorKind, HeadingMode, RobustLaw, ThrustUnit,
};

use super::file::{
    AttitudeName, BBoundName, BoundTable, ControllerTable, CurrentName, CurrentTable,
    EstimatorName, HeadingName, LawName, LinkFaultsTable, NoiseTable, ProfileName, ScenarioFile,
    StepTable, ThrustUnitName, VariationTable,
};
use super::{f32_decimal, parse, InitialAttitude, SimConfig, TickRange};
use crate::plant::{CurrentModel, Integrator, VariationProfile};
use crate::scenario::navigation::NoiseDraws;

/// A configuration a scenario file cannot describe: the field, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unwritable {
    /// The configuration's field, e.g. `controller.params`.
    pub field: &'static str,
    pub why: &'static str,
}

impl std::fmt::Display for Unwritable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` cannot be written in a scenario file: {}",
            self.field, self.why
        )
    }
}

impl std::error::Error for Unwritable {}

fn f32_decimals<const N: usize>(xs: [f32; N]) -> [f64; N] {
    xs.map(f32_decimal)
}

/// `pitch_limit_deg` for the limit `radians`: the degrees the reader turns back into it
/// (`(deg as f32).to_radians()`), searched among the f32s next to `radians.to_degrees()`.
fn pitch_limit_deg(radians: f32) -> Result<f64, Unwritable> {
    let mut deg = radians.to_degrees();
    for _ in 0..4 {
        deg = deg.next_down();
    }
    (0..9)
        .scan(deg, |d, _| {
            let here = *d;
            *d = d.next_up();
            Some(here)
        })
        .find(|d| d.to_radians() == radians)
        .map(f32_decimal)
        .ok_or(Unwritable {
            field: "controller.pitch_limit",
            why: "no angle in degrees reads back to it",
        })
}

impl TryFrom<&SimConfig> for ScenarioFile {
    type Error = Unwritable;

    fn try_from(c: &SimConfig) -> Result<Self, Unwritable> {
        if c.allow_long_run {
            return Err(Unwritable {
                field: "allow_long_run",
                why: "the step cap is lifted by the command's --allow-long-run, not by a file",
            });
        }
        let mut file = ScenarioFile::new(c.trajectory);
        file.name = Some(c.name.clone());
        file.table1_case = c.case.map(|case| case.name().to_string());
        file.duration = Some(c.duration);
        file.plant_step = Some(c.plant_step);
        // Written when not the default, so a file of an RK4 run reads as it always did.
        file.plant_integrator =
            (c.plant_integrator != Integrator::Rk4).then(|| c.plant_integrator.name().into());
        file.noise_draws =
            (c.noise_draws != NoiseDraws::EveryPeriod).then(|| c.noise_draws.name().into());
        file.ideal_actuators = Some(c.ideal_actuators);
        file.initial_offset = Some(c.initial_offset);
        file.divergence_limit = Some(c.divergence_limit);
        file.thruster_lag = c.thruster_lag;
        file.expect_faults = Some(c.expect_faults);
        file.initial_attitude = c.start_attitude.map(|a| match a {
            InitialAttitude::Level => AttitudeName::Level,
            InitialAttitude::Trim => AttitudeName::Trim,
        });
        file.expect_missed = Some(c.expect_missed);
        let t = &mut file.trajectory;
        t.heading = Some(match c.heading {
            HeadingMode::Paper => HeadingName::Paper,
            HeadingMode::Tangent => HeadingName::Tangent,
        });
        t.time_scale = Some(f32_decimal(c.time_scale));
        t.origin = c.origin;
        t.speed_limits = c.speed_limits.clone();
        file.variation = Some(variation(&c.variation, c.trimmed));
        file.current = Some(current(&c.current));
        file.noise = c.noise.as_ref().map(|n| NoiseTable {
            eta_sigma: Some(n.eta_sigma),
            nu_sigma: Some(n.nu_sigma),
            seed: Some(n.seed),
        });
        file.navigation = match &c.navigation {
            Some(m) => Some(super::navigation::table(m)),
            // The real chain's default is not the exact state (Choice 370): written out.
            None if !c.ideal_actuators => Some(super::navigation::NavigationTable {
                preset: Some(super::navigation::Preset::Ideal),
                ..Default::default()
            }),
            None => None,
        };
        file.controller = Some(controller(&c.controller)?);
        if let Some(t) = &mut file.controller {
            // The real chain's default estimator is on (Choice 370): off is written out there.
            if !c.ideal_actuators && t.estimator.is_none() {
                t.estimator = Some(EstimatorName::Off);
            }
        }
        file.bound = c.bound_setting.map(BoundTable::from);
        let ranges =
            |v: &[TickRange]| Some(v.iter().map(|r| format!("{}..{}", r.from, r.to)).collect());
        let f = &c.link_faults;
        file.link_faults = Some(LinkFaultsTable {
            drop: ranges(&f.drop),
            corrupt: ranges(&f.corrupt),
            delay: ranges(&f.delay),
            delay_ticks: Some(f.delay_ticks),
            silent: ranges(&f.silent),
            lose_upload_chunks: Some(f.lose_upload_chunks.clone()),
        });
        Ok(file)
    }
}

fn all_given(d: &ParamVariation<f64>) -> [Option<f64>; controller_core::model::VARIED_PARAMETERS] {
    d.to_array().map(Some)
}

fn variation(v: &VariationProfile, trimmed: bool) -> VariationTable {
    let mut table = VariationTable {
        profile: ProfileName::None,
        trimmed: Some(trimmed),
        omega: None,
        delta: Default::default(),
        steps: None,
    };
    match v {
        VariationProfile::None => {}
        VariationProfile::Constant(d) => {
            table.profile = ProfileName::Constant;
            table.delta = all_given(d);
        }
        VariationProfile::AbsSin { max, omega } => {
            table.profile = ProfileName::AbsSin;
            table.delta = all_given(max);
            table.omega = Some(*omega);
        }
        VariationProfile::Staircase(steps) => {
            table.profile = ProfileName::Staircase;
            let last = steps.len().saturating_sub(1);
            table.steps = Some(
                steps
                    .iter()
                    .enumerate()
                    .map(|(i, (until, d))| StepTable {
                        // The last step's "for ever" is its `until` left out.
                        until: (i != last || until.is_finite()).then_some(*until),
                        delta: all_given(d),
                    })
                    .collect(),
            );
        }
    }
    table
}

fn current(c: &CurrentModel) -> CurrentTable {
    match *c {
        CurrentModel::None => CurrentTable::new(CurrentName::None),
        CurrentModel::Constant(v) => CurrentTable {
            velocity: Some(v),
            ..CurrentTable::new(CurrentName::Constant)
        },
        CurrentModel::GaussMarkov {
            mean,
            sigma,
            tau,
            seed,
        } => CurrentTable {
            mean: Some(mean),
            sigma: Some(sigma),
            tau: Some(tau),
            seed: Some(seed),
            ..CurrentTable::new(CurrentName::GaussMarkov)
        },
    }
}

fn controller(c: &ControllerConfig) -> Result<ControllerTable, Unwritable> {
    let default = ControllerConfig::default();
    if c.params != default.params {
        return Err(Unwritable {
            field: "controller.params",
            why: "a file's controller has the AUV-150's nominal model",
        });
    }
    if c.uncertainty != default.uncertainty {
        return Err(Unwritable {
            field: "controller.uncertainty",
            why: "a file's controller has Table 3's parameter box",
        });
    }
    let mask = c.geometry.auv150_reversed().ok_or(Unwritable {
        field: "controller.geometry",
        why: "a file's thrusters are the AUV-150 layout, some reversed",
    })?;
    let on = c.estimator.kind != EstimatorKind::Off;
    Ok(ControllerTable {
        robust: Some(c.robust),
        law: Some(match c.law {
            RobustLaw::BoundaryLayer => LawName::BoundaryLayer,
            RobustLaw::Discontinuous => LawName::Discontinuous,
        }),
        k1: Some(f32_decimals(c.k1)),
        k2: Some(f32_decimals(c.k2)),
        q: Some(f32_decimals(c.q)),
        beta: Some(f32_decimal(c.beta)),
        mu: Some(f32_decimal(c.mu)),
        delta_max: Some(f32_decimal(c.delta_max)),
        rate_hz: Some(c.rate_hz),
        pitch_limit_deg: Some(pitch_limit_deg(c.pitch_limit)?),
        voltage_limit: Some(f32_decimal(c.voltage_limit)),
        b_bound: Some(match c.b_bound {
            BBound::ControlledRows => BBoundName::ControlledRows,
            BBound::Literal => BBoundName::Literal,
        }),
        thrust_unit: Some(match c.thrust_unit {
            ThrustUnit::Kgf => ThrustUnitName::Kgf,
            ThrustUnit::Newton => ThrustUnitName::Newton,
        }),
        axis_priority: Some(axis_order(&c.priority)?),
        reversed_thrusters: Some(
            THRUSTER_NAMES
                .iter()
                .enumerate()
                .filter(|(i, _)| mask & (1 << i) != 0)
                .map(|(_, n)| n.to_string())
                .collect(),
        ),
        // Written only when on, so that a file written for a controller without the estimator
        // reads as it did before the estimator existed.
        estimator: on.then_some(EstimatorName::Kalman),
        estimator_position_sigma: on.then(|| f32_decimals(c.estimator.position_sigma)),
        estimator_velocity_sigma: on.then(|| f32_decimals(c.estimator.velocity_sigma)),
        estimator_accel_sigma: on.then(|| f32_decimals(c.estimator.accel_sigma)),
    })
}

/// `controller.axis_priority`: the actuated axes from the highest rank down, if the reader
/// turns that list back into the same priority (equal weights, ranks 5 to 1).
fn axis_order(p: &AxisPriority) -> Result<Vec<String>, Unwritable> {
    let mut order: Vec<(u8, &str)> = p.rank.iter().copied().zip(AXIS_NAMES).collect();
    order.retain(|(_, n)| *n != "roll");
    order.sort_by_key(|(rank, _)| std::cmp::Reverse(*rank));
    let names: Vec<String> = order.into_iter().map(|(_, n)| n.to_string()).collect();
    match parse::axis_priority(&names) {
        Ok(read) if read == *p => Ok(names),
        _ => Err(Unwritable {
            field: "controller.priority",
            why: "a file gives the five actuated axes in order, with equal weights",
        }),
    }
}
