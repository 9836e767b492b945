//! The navigation computer's side of the board link (`auv-link`): what the simulator puts on
//! the wire. Shared types, no copies: a mission goes out as `auv_link::MissionPlan::from(…)`
//! (the link crate's one conversion), the state as [`state_frame`], signed with the time
//! [`mavlink_time`].

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

/// MAVLink 2's signing time: 10 µs units since 2015-01-01 00:00 UTC (1 420 070 400 s after the
/// Unix epoch), so that a restarted runner still counts upwards.
pub fn mavlink_time() -> u64 {
    const EPOCH_2015: u64 = 1_420_070_400;
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| {
            d.as_secs().saturating_sub(EPOCH_2015) * auv_link::sign::UNITS_PER_SECOND
                + u64::from(d.subsec_micros() / 10)
        })
}
