//! Where a run starts (docs/missions.md#closed-form-paths): on the reference, plus an offset.

use controller_core::kinematics::{self, Attitude};
use controller_core::Trajectory;
use nalgebra::Vector6;

use crate::plant::PlantState;

/// The vehicle on the reference at t = 0 plus `offset`: η = η_d(0) + offset, with the
/// reference's velocity ν = J⁻¹(η) η̇_d(0).
pub fn start_state(trajectory: &Trajectory, rate_hz: u32, offset: &[f64; 6]) -> PlantState {
    let d0 = trajectory.sample(0, rate_hz);
    let eta = d0.eta.cast::<f64>() + Vector6::from(*offset);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta(&eta)) * d0.eta_dot.cast::<f64>();
    PlantState { eta, nu }
}
