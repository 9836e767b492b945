//! The paper's Table-1 runs as scenarios, keyed by [`Table1Case`] (docs/missions.md#closed-form-paths, docs/simulator.md#table-1): each
//! case's run ([`config`]: its mission, its Table-3 variation profile, the paper's controller)
//! and the lawn-mowers' Table-3 staircase. The paper's printed numbers and the twelve runs are
//! [`crate::studies::table1`]'s.
//!
//! The six shipped files `scenarios/<case>.toml` describe the same runs (`table1_case = …`); a
//! test holds them equal to [`config`].

use controller_core::model::ParamVariation;
use controller_core::{Table1Case, Trajectory};

use super::{f32_decimal, Scenario, ScenarioError, SimConfig};
use crate::plant::VariationProfile;

/// ω of the circles' payload profile Δp(t) = max·|sin ωt| (rad/s): the paper's circle
/// frequency, [`Trajectory::PAPER_OMEGA`] (its decimal 0.1 in f64, not the f32's
/// 0.10000000149). Also the scenario files' default for `profile = "abs-sin"`.
pub fn abs_sin_omega() -> f64 {
    f32_decimal(Trajectory::PAPER_OMEGA)
}

/// Table 3's lawn-mower column: Δp piecewise constant, each row holding until its time (s);
/// the last row holds after 50 s. Its first row (0–25 s) is Table 3's maximum.
pub const TABLE3_STAIRCASE: [(f64, ParamVariation<f64>); 3] = [
    (25.0, ParamVariation::TABLE3_MAX),
    (
        50.0,
        ParamVariation {
            mass: 20.0,
            r_g: [0.03, 0.01, 0.018],
            inertia: [1.5, 3.5, 7.0],
            x_udot: 2.0,
            y_vdot: 35.0,
        },
    ),
    (
        f64::INFINITY,
        ParamVariation {
            mass: 10.0,
            r_g: [0.02, 0.005, 0.015],
            inertia: [1.0, 2.5, 5.0],
            x_udot: 1.5,
            y_vdot: 25.0,
        },
    ),
];

/// The lawn-mowers' Table-3 staircase ([`TABLE3_STAIRCASE`]) as a profile; also the scenario
/// files' `profile = "table3-staircase"`.
pub fn table3_staircase() -> VariationProfile {
    VariationProfile::Staircase(TABLE3_STAIRCASE.to_vec())
}

/// The Table-3 profile of a case: circles Δ = max·|sin 0.1t|, figure-eights Δ = max,
/// lawn-mowers the 0–25 / 25–50 / >50 s staircase.
pub fn variation(case: Table1Case) -> VariationProfile {
    match case {
        Table1Case::Circular10R | Table1Case::Circular20R => VariationProfile::AbsSin {
            max: ParamVariation::TABLE3_MAX,
            omega: abs_sin_omega(),
        },
        Table1Case::FigureEight30x30 | Table1Case::FigureEight40x40 => {
            VariationProfile::Constant(ParamVariation::TABLE3_MAX)
        }
        Table1Case::LawnMower20x10 | Table1Case::LawnMower30x15 => table3_staircase(),
    }
}

/// The run of a Table-1 case, with (`robust`) or without Δu: the paper's mission, 70 s, 1 ms
/// plant step, the paper's controller at 100 Hz, ideal actuators, starting on the reference,
/// no current or noise, and the case's [`variation`].
pub fn config(case: Table1Case, robust: bool) -> SimConfig {
    let mut config = SimConfig::new(case.name(), case.kind());
    config.case = Some(case);
    config.variation = variation(case);
    config.controller.robust = robust;
    config
}

/// [`config`], validated.
pub fn scenario(case: Table1Case, robust: bool) -> Result<Scenario, ScenarioError> {
    Scenario::new(config(case, robust))
}
