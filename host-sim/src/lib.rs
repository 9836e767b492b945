//! AUV-150 desktop simulator: the full nonlinear 6-DOF plant (f64) closed around the f32
//! `controller-core` exactly as the firmware runs it (software in the loop), the board in the
//! loop (PIL, HIL), and the studies built on them (Table 1, the real vehicle, preflight, Monte
//! Carlo).
//!
//! The crate is a stack of layers; a module uses only the layers below its own (a test holds
//! this: `xtask`'s source scan, `host_sim_layers`). From the bottom:
//!
//! | layer | module | owns |
//! |---|---|---|
//! | 0 | [`interrupt`] | Ctrl-C / SIGTERM: the process-wide stop flag every long phase polls |
//! | 1 | [`plant`] | the physics: Eq (1) in f64 with RK4, trim, the parameter variation profiles, the ocean current |
//! | 2 | [`scenario`] | what a run is: [`scenario::SimConfig`], TOML files, the one validation, the paper's cases, the real vehicle's missions |
//! | 3 | [`sim`] | the one closed loop (measure, control, actuate, integrate), what a run records, its metrics, bound and progress |
//! | 4 | [`board`] | a board in the loop over any byte transport: the runner, pacing, QEMU launch, PIL/HIL vs SIL |
//! | 4 | [`studies`] | Table 1, preflight feasibility, Monte Carlo, campaigns in shards |
//! | 5 | [`output`] | output folders, CSV, plots, reports, campaign shards and merged reports |
//! | 6 | [`cli`] | the `host-sim` commands, one file each |
//!
//! [`board`] and [`studies`] share layer 4 and do not use each other.

pub mod interrupt;

pub mod plant;

pub mod scenario;

pub mod sim;

pub mod board;
pub mod studies;

pub mod output;

pub mod cli;
