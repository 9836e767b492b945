//! The paper's Table 1 as a study (docs/simulator.md#table-1): the paper's printed numbers
//! ([`table1_row`]), the report's notes on how our runs were made ([`notes`]), and the twelve
//! runs themselves ([`run_all`]). The runs' scenarios are [`crate::scenario::paper`]'s.

use controller_core::{RobustLaw, Table1Case};
use rayon::prelude::*;

use crate::scenario::paper::scenario;
use crate::scenario::{Scenario, ScenarioError};
use crate::sim::{self, RunResult};

/// The paper's Table 1 numbers for a case (max errors, metres), each `[without, with]` Δu.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperRow {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub z: [f64; 2],
    pub path: [f64; 2],
}

/// The paper's Table 1 (docs/simulator.md#table-1): its row for `case`.
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

/// What the report says about how these runs relate to the paper's: the plant, the
/// controller and the actuators of the paper's runs, as their configuration
/// ([`crate::scenario::paper::config`]) has them.
pub fn notes() -> String {
    let cfg = crate::scenario::paper::config(Table1Case::Circular10R, true);
    let c = &cfg.controller;
    let diag = |k: &[f32; 6]| {
        let v: Vec<String> = k.iter().map(f32::to_string).collect();
        format!("diag({})", v.join(","))
    };
    let gains = if c.k1 == c.k2 {
        format!("K₁ = K₂ = {}", diag(&c.k1))
    } else {
        format!("K₁ = {}, K₂ = {}", diag(&c.k1), diag(&c.k2))
    };
    let theorem = match c.law {
        RobustLaw::BoundaryLayer => "Theorem 4",
        RobustLaw::Discontinuous => "Theorem 3",
    };
    format!(
        "\
## How these runs were made

- Plant: full nonlinear 6-DOF model of Eq (1) in f64, RK4 at {step} ms, with the Table-3
  parameter profiles acting on the plant only (abs-sin for the circles, constant maximum for
  the figure-eights, the staircase for the lawn-mowers).
- Controller: `controller-core` in f32 exactly as the firmware runs it, sampled at {rate} Hz with
  zero-order hold; paper gains {gains}, β = {beta}, μ = {mu}, {theorem}.
- Actuators: ideal (the allocated thrusts are delivered). The voltages in the table are what
  the controller commanded at the board's ±{volts} V supply limit: the paper's missions need far
  more thrust than Eqs 31–32 give at {volts} V, so a real board would saturate (docs/thrusters.md#saturation).
- The paper does not state its step size, integrator or loop rate; differences in the
  \"without Δu\" column come mostly from that and from the choices listed in docs/decisions.md.
",
        step = cfg.plant_step * 1000.0,
        rate = c.rate_hz,
        beta = c.beta,
        mu = c.mu,
        volts = c.voltage_limit,
    )
}

/// Runs all six cases with and without Δu in parallel; returns (with, without) per case in
/// the order of [`Table1Case::ALL`]. `on_done` is called after each run (progress).
pub fn run_all(on_done: impl Fn() + Sync) -> Result<Vec<(RunResult, RunResult)>, ScenarioError> {
    Ok(run_jobs(&jobs()?, |s| {
        let r = sim::run(s);
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
