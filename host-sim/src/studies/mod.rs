//! The studies built on the closed loop: what the paper's Table 1 and the real vehicle show,
//! whether the real thrusters can fly a mission before it is flown, and how the law fares over
//! the parameter box.
//!
//! | module | owns |
//! |---|---|
//! | [`table1`] | the paper's printed Table 1, the notes on how our runs were made, the twelve runs |
//! | [`preflight`] | can the real thrusters fly a scenario, and at what time scale (`host-sim check`) |
//! | [`montecarlo`] | Monte Carlo over the Table-3 box, on one machine |
//! | [`campaign`] | Monte Carlo campaigns in shards on any engine (Slurm, Kubernetes), merged, worst cases reproducible |
//! | [`validation`] | does the preflight's verdict hold: missions checked, then flown |
//! | [`falsify`] | searching for the mission the preflight gets wrong (`host-sim falsify`) |
//! | [`contract_statistics`] | the contract's false feasibles per preset, sampled and searched, with their rate bound |

pub mod campaign;
pub mod contract_statistics;
pub mod falsify;
pub mod mission_space;
pub mod montecarlo;
pub mod preflight;
pub mod rate_bound;
pub mod table1;
pub mod tune;
pub mod validation;
