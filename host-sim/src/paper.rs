//! Everything about the paper's Table 1, keyed by [`Table1Case`] (docs/design.md §6–7): each case's
//! run ([`config`]: its mission, its Table-3 variation profile, the paper's controller), the
//! lawn-mowers' Table-3 staircase, the paper's printed numbers ([`table1_row`]), the report's
//! notes on how our runs were made, and the twelve runs themselves ([`run_all`]).
//!
//! The six shipped files `scenarios/<case>.toml` describe the same runs (`table1_case = …`); a
//! test holds them equal to [`config`].

use controller_core::model::ParamVariation;
use controller_core::Table1Case;
use rayon::prelude::*;

use crate::config::{SimConfig, VariationProfile};
use crate::record::RunResult;
use crate::scenario::{Scenario, ScenarioError};
use crate::sil;

/// ω of the circles' payload profile Δp(t) = max·|sin ωt| (rad/s): the paper's circle
/// frequency. Also the scenario files' default for `profile = "abs-sin"`.
pub const ABS_SIN_OMEGA: f64 = 0.1;

/// Table 3's lawn-mower column: Δp piecewise constant, each row holding until its time (s);
/// the last row holds after 50 s. Rows are the nine Δ in the order of
/// [`controller_core::model::VARIED_PARAMETER_NAMES`] (m, x_G, y_G, z_G, I_x, I_y, I_z,
/// −X_u̇, −Y_v̇).
pub const TABLE3_STAIRCASE: [(f64, [f64; 9]); 3] = [
    (25.0, [30.0, 0.05, 0.02, 0.02, 2.0, 5.0, 10.0, 3.0, 50.0]),
    (50.0, [20.0, 0.03, 0.01, 0.018, 1.5, 3.5, 7.0, 2.0, 35.0]),
    (
        f64::INFINITY,
        [10.0, 0.02, 0.005, 0.015, 1.0, 2.5, 5.0, 1.5, 25.0],
    ),
];

/// The lawn-mowers' Table-3 staircase ([`TABLE3_STAIRCASE`]) as a profile; also the scenario
/// files' `profile = "table3-staircase"`.
pub fn table3_staircase() -> VariationProfile {
    VariationProfile::Staircase(
        TABLE3_STAIRCASE
            .iter()
            .map(|&(until, d)| (until, ParamVariation::from_array(d)))
            .collect(),
    )
}

/// The Table-3 profile of a case: circles Δ = max·|sin 0.1t|, figure-eights Δ = max,
/// lawn-mowers the 0–25 / 25–50 / >50 s staircase.
pub fn variation(case: Table1Case) -> VariationProfile {
    match case {
        Table1Case::Circular10R | Table1Case::Circular20R => VariationProfile::AbsSin {
            max: ParamVariation::TABLE3_MAX,
            omega: ABS_SIN_OMEGA,
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

/// The paper's Table 1 numbers for a case (max errors, metres), each `[without, with]` Δu.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperRow {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub z: [f64; 2],
    pub path: [f64; 2],
}

/// The paper's Table 1 (docs/design.md §7): its row for `case`.
pub fn table1_row(case: Table1Case) -> PaperRow {
    let row = |x: [f64; 2], y: [f64; 2], z: [f64; 2], path: [f64; 2]| PaperRow { x, y, z, path };
    match case {
        Table1Case::Circular10R => row(
            [0.485, 0.020],
            [0.145, 0.002],
            [0.015, 0.001],
            [0.506, 0.022],
        ),
        Table1Case::Circular20R => row(
            [3.992, 0.021],
            [1.205, 0.002],
            [0.320, 0.011],
            [4.187, 0.023],
        ),
        Table1Case::FigureEight30x30 => row(
            [1.465, 0.031],
            [0.895, 0.002],
            [0.270, 0.003],
            [1.738, 0.031],
        ),
        Table1Case::FigureEight40x40 => row(
            [2.368, 0.036],
            [1.580, 0.003],
            [0.543, 0.001],
            [2.897, 0.036],
        ),
        Table1Case::LawnMower20x10 => row(
            [0.746, 0.001],
            [1.491, 0.001],
            [0.391, 0.102],
            [1.712, 0.102],
        ),
        Table1Case::LawnMower30x15 => row(
            [1.092, 0.001],
            [3.205, 0.011],
            [0.452, 0.121],
            [3.420, 0.162],
        ),
    }
}

/// What the report says about how these runs relate to the paper's.
pub const NOTES: &str = "\
## How these runs were made

- Plant: full nonlinear 6-DOF model of Eq (1) in f64, RK4 at 1 ms, with the Table-3
  parameter profiles acting on the plant only (abs-sin for the circles, constant maximum for
  the figure-eights, the staircase for the lawn-mowers).
- Controller: `controller-core` in f32 exactly as the firmware runs it, sampled at 100 Hz with
  zero-order hold; paper gains K₁ = K₂ = diag(4,4,4,0,4,4), β = 0.605, μ = 0.1, Theorem 4.
- Actuators: ideal (the allocated thrusts are delivered). The voltages in the table are what
  the controller commanded at the board's ±24 V supply limit: the paper's missions need far
  more thrust than Eqs 31–32 give at 24 V, so a real board would saturate (docs/design.md §5).
- The paper does not state its step size, integrator or loop rate; differences in the
  \"without Δu\" column come mostly from that and from the choices listed in docs/design.md.
";

/// Runs all six cases with and without Δu in parallel; returns (with, without) per case in
/// the order of [`Table1Case::ALL`]. `on_done` is called after each run (progress).
pub fn run_all(on_done: impl Fn() + Sync) -> Result<Vec<(RunResult, RunResult)>, ScenarioError> {
    Ok(run_jobs(&jobs()?, |s| {
        let r = sil::run(s);
        on_done();
        r
    }))
}

/// The twelve runs of Table 1: per case of [`Table1Case::ALL`] with, then without Δu.
pub fn jobs() -> Result<Vec<Scenario>, ScenarioError> {
    Table1Case::ALL
        .iter()
        .flat_map(|&c| [scenario(c, true), scenario(c, false)])
        .collect()
}

/// Runs [`jobs`] in parallel with `run` (the CLI's streams each run's CSV); returns (with,
/// without) per case.
pub fn run_jobs(
    jobs: &[Scenario],
    run: impl Fn(&Scenario) -> RunResult + Sync,
) -> Vec<(RunResult, RunResult)> {
    let mut results = jobs
        .par_iter()
        .map(&run)
        .collect::<Vec<RunResult>>()
        .into_iter();
    let mut pairs = Vec::new();
    while let (Some(with), Some(without)) = (results.next(), results.next()) {
        pairs.push((with, without));
    }
    pairs
}
