//! One golden vector ([`Golden`]): the mission as the board receives it, the inputs, and the
//! host core's outputs. The one definition: build.rs computes the vectors with it (through
//! `#[path]`) and writes them out, the self-test reads them back.

use auv_link::MissionPlan;
use controller_core::effectiveness::THRUSTERS;

/// One golden vector: its mission, inputs and the host core's outputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Golden {
    /// The mission, as `StartMission` carries it: a closed-form path by its parameters, the
    /// shipped survey by its upload's CRC (the self-test resolves it from the upload, as the
    /// board does).
    pub plan: MissionPlan,
    /// The control tick (100 Hz).
    pub ticks: u64,
    /// Δu on.
    pub robust: bool,
    /// The navigation solution η.
    pub eta: [f32; 6],
    /// The navigation solution ν.
    pub nu: [f32; 6],
    /// The host's voltages.
    pub voltage: [f32; THRUSTERS],
    /// The host's τ.
    pub tau: [f32; 6],
    /// The host's δ.
    pub delta: f32,
    /// The host's ‖w‖.
    pub w_norm: f32,
    /// 0: `Status::Ok`, 1: a fault.
    pub status: u8,
}
