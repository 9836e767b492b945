//! The navigation computer's side of the board link (`auv-link`): what the simulator sends the
//! firmware. Used by the processor-in-the-loop runner; shared types, no copies.

use auv_link::{MissionSpec, StateFrame};
use controller_core::TrajectoryKind;
use nalgebra::Vector6;

/// The link's mission description of a core trajectory (the board builds the same trajectory
/// from it).
pub fn mission_spec(kind: &TrajectoryKind) -> MissionSpec {
    match *kind {
        TrajectoryKind::Circle {
            radius,
            omega,
            depth,
        } => MissionSpec::Circle {
            radius,
            omega,
            depth,
        },
        TrajectoryKind::FigureEight {
            amplitude,
            omega,
            depth,
        } => MissionSpec::FigureEight {
            amplitude,
            omega,
            depth,
        },
        TrajectoryKind::LawnMower {
            scale,
            omega,
            depth,
        } => MissionSpec::LawnMower {
            scale,
            omega,
            depth,
        },
        TrajectoryKind::Helix {
            radius,
            omega,
            depth,
            depth_rate,
        } => MissionSpec::Helix {
            radius,
            omega,
            depth,
            depth_rate,
        },
    }
}

/// A state frame from the plant's (measured) state, rounded to f32 as the board's law sees it.
pub fn state_frame(tick: u64, eta: &Vector6<f64>, nu: &Vector6<f64>) -> StateFrame {
    StateFrame {
        t_ticks: tick,
        eta: eta.cast::<f32>().into(),
        nu: nu.cast::<f32>().into(),
    }
}
