//! The board's own limits on its configuration, once. `SetConfig` is refused with a reason
//! ([`auv_link::Refusal`]) when the resulting configuration breaks one; the core's own checks
//! (`controller_core::Controller::new`: the loop-rate rule of docs/law.md#the-loop-rate-rule, δ_max > 0, …)
//! come after these.

/// Highest loop rate (Hz) the board accepts.
///
/// **Choice:** 200 Hz. One period must carry a telemetry frame out and a state frame in; the
/// largest telemetry frame (179 bytes, signed) takes 3.9 ms at the STM32 board's 460 800 baud
/// ([`crate::serial::LINK_BAUD`]), so the link alone allows at most ≈ 257 Hz, and the largest
/// frame of all (`auv_link::MAX_FRAME` = 225 bytes, a whole signed `SetConfig`, protocol 8,
/// sent disarmed) still fits a period at this rate (4.9 ms, tested below); and
/// 200 Hz (5 ms) leaves room for the update and the state frame's own latency. The core's
/// `update` costs ≈ 0.2 ms on the 168 MHz M4F (firmware/README.md). Before this limit the
/// board accepted 4 294 967 295 Hz.
pub const MAX_RATE_HZ: u32 = 200;

/// Longest the board may keep flying on its last state frame (ms): `stale_periods` periods at
/// the loop rate may not exceed this.
///
/// **Choice:** 250 ms: 25 periods at 100 Hz, half a metre at the AUV-150's 2 m/s. The default
/// (`auv_link::DEFAULT_STALE_PERIODS` = 2 periods, 20 ms at 100 Hz) is far inside it.
pub const MAX_STALE_MS: u32 = 250;

/// True if `stale_periods` periods at `rate_hz` are a stale-state limit the board accepts: at
/// least one period, and no longer than [`MAX_STALE_MS`].
pub const fn stale_limit_ok(stale_periods: u8, rate_hz: u32) -> bool {
    // periods / rate ≤ MAX_STALE_MS / 1000, in integers (no overflow: u8 × 1000 < 2³²).
    stale_periods >= 1
        && rate_hz >= 1
        && (stale_periods as u64) * 1000 <= (MAX_STALE_MS as u64) * (rate_hz as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_frame_fits_a_period_at_the_maximum_rate() {
        let frame_ns = firmware_images::wire_nanos(auv_link::MAX_FRAME as u64);
        let period_ns = 1_000_000_000 / MAX_RATE_HZ as u64;
        assert!(
            frame_ns < period_ns,
            "{frame_ns} ns in a {period_ns} ns period"
        );
    }

    #[test]
    fn the_default_stale_limit_is_accepted_at_the_default_rate() {
        assert!(stale_limit_ok(auv_link::DEFAULT_STALE_PERIODS, 100));
        // 25 periods at 100 Hz is exactly 250 ms; 26 is not.
        assert!(stale_limit_ok(25, 100));
        assert!(!stale_limit_ok(26, 100));
        assert!(!stale_limit_ok(0, 100));
        assert!(!stale_limit_ok(255, 100));
        // At 200 Hz, 50 periods; at 22 Hz, 5 (227 ms) but not 6 (273 ms).
        assert!(stale_limit_ok(50, 200) && !stale_limit_ok(51, 200));
        assert!(stale_limit_ok(5, 22) && !stale_limit_ok(6, 22));
    }
}
