//! The navigation computer's side of the board link (`auv-link`): what the simulator sends the
//! firmware. Shared types, no copies: a mission goes out as `auv_link::MissionSpec::from(kind)`
//! (the link crate's one conversion), the state as [`state_frame`].

use auv_link::StateFrame;
use nalgebra::Vector6;

/// A state frame from the plant's (measured) state, rounded to f32 as the board's law sees it.
pub fn state_frame(tick: u64, eta: &Vector6<f64>, nu: &Vector6<f64>) -> StateFrame {
    StateFrame {
        t_ticks: tick,
        eta: eta.cast::<f32>().into(),
        nu: nu.cast::<f32>().into(),
    }
}
