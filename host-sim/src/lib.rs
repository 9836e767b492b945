//! AUV-150 desktop simulator: the full nonlinear 6-DOF plant (f64) closed around the f32
//! `controller-core` exactly as the firmware runs it (software in the loop).
//!
//! | module | owns |
//! |---|---|
//! | [`config`] | what a run is ([`config::SimConfig`]) |
//! | [`scenario`] | TOML scenario files, and the one validation of a run ([`scenario::Scenario`]) |
//! | [`plant`] | the 6-DOF plant with varying parameters, current and RK4 |
//! | [`sil`] | the sampled-data loop: ZOH, actuator chain, noise, divergence |
//! | [`metrics`] | the paper's Table-1 metrics from a run, accumulated as it goes |
//! | [`decimate`] | the bounded plot series of a long run |
//! | [`progress`] | progress of long commands, on a terminal or not |
//! | [`interrupt`] | Ctrl-C / SIGTERM: finish the current period, keep what is done |
//! | [`link`] | what the simulator sends the board over `auv-link` |
//! | [`record`] | samples, outcome, metrics and JSON summary of a run |
//! | [`paper`] | the paper's Table 1: cases, profiles, its numbers, notes, the twelve runs |
//! | [`preflight`] | can the real thrusters fly a scenario, and at what time scale |
//! | [`real`] | the real vehicle's six missions (`scenarios/real/`) and the paper's through the real chain |
//! | [`pil`] | processor and hardware in the loop: the firmware in QEMU or on a board flies the plant; PIL/HIL vs SIL |
//! | [`pacing`] | lock-step or real time, and a real-time run's timing figures |
//! | [`qemu`] | the QEMU image as a board in the loop: on a socket or a pty |
//! | [`transport`] | the byte transport under the board link: TCP socket or serial port |
//! | [`montecarlo`] | Monte Carlo over the Table-3 box |
//! | [`output`] | CSV, plots, report |
//! | [`cli`] | the `host-sim` commands |

pub mod cli;
pub mod config;
pub mod decimate;
pub mod interrupt;
pub mod link;
pub mod metrics;
pub mod montecarlo;
pub mod output;
pub mod pacing;
pub mod paper;
pub mod pil;
pub mod plant;
pub mod preflight;
pub mod progress;
pub mod qemu;
pub mod real;
pub mod record;
pub mod scenario;
pub mod sil;
pub mod transport;
