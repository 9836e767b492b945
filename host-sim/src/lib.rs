//! AUV-150 desktop simulator: the full nonlinear 6-DOF plant (f64) closed around the f32
//! `controller-core` exactly as the firmware runs it (software in the loop).
//!
//! | module | owns |
//! |---|---|
//! | [`config`] | what a run is ([`config::SimConfig`]) |
//! | [`plant`] | the 6-DOF plant with varying parameters, current and RK4 |
//! | [`sil`] | the sampled-data loop: ZOH, actuator chain, noise, divergence |
//! | [`metrics`] | the paper's Table-1 metrics from a run |
//! | [`link`] | what the simulator sends the board over `auv-link` |
//! | [`record`] | samples, outcome, metrics of a run |
//! | `scenario` | TOML scenario files |
//! | [`table1`] | the paper's six missions with and without Δu |
//! | [`pil`] | processor in the loop: the firmware in QEMU flies the plant |
//! | [`montecarlo`] | Monte Carlo over the Table-3 box |
//! | `output` | CSV, plots, report |

pub mod config;
pub mod link;
pub mod metrics;
pub mod montecarlo;
pub mod output;
pub mod pil;
pub mod plant;
pub mod record;
pub mod scenario;
pub mod sil;
pub mod table1;
