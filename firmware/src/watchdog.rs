//! The flight board's independent watchdog (the STM32F405's IWDG) and clock, in numbers, once:
//! hardware-free, so that the budgets of `crate::budget` are checked against them on the host.
//! `crate::stm32f405` programs the IWDG from these.
//!
//! The IWDG counts the LSI, an RC oscillator specified only to 17–47 kHz (32 kHz nominal): a
//! timeout programmed as T ms at 32 kHz lasts T · 32/47 = 0.68 T at the fastest LSI and
//! 1.9 T at the slowest. The loop feeds it once a period ([`crate::board::period`]), so the
//! longest time between two feeds — one period's wait plus the next period's work — must stay
//! under the shortest timeout, [`shortest_timeout_us`].

/// The flight board's core clock (Hz): SYSCLK = HCLK of the STM32F405 at 168 MHz.
pub const FLIGHT_CLOCK_HZ: u32 = 168_000_000;

/// Shortest watchdog timeout (ms, nominal at a 32 kHz LSI).
pub const WATCHDOG_MIN_MS: u32 = 50;
/// Longest timeout the IWDG's /32 prescaler reaches (ms at the nominal LSI): 4096 counts.
pub const WATCHDOG_MAX_MS: u32 = 4096;
/// Nominal LSI frequency (Hz) clocking the IWDG.
pub const LSI_HZ: u32 = 32_000;
/// Fastest LSI the STM32F405 allows (Hz; datasheet: 17–47 kHz): the shortest real timeout.
pub const LSI_MAX_HZ: u32 = 47_000;

/// Nominal watchdog timeout (ms) at a control rate: four periods, at least
/// [`WATCHDOG_MIN_MS`], at most [`WATCHDOG_MAX_MS`].
pub const fn timeout_ms(rate_hz: u32) -> u32 {
    let ms = 4000 / if rate_hz == 0 { 1 } else { rate_hz };
    if ms < WATCHDOG_MIN_MS {
        WATCHDOG_MIN_MS
    } else if ms > WATCHDOG_MAX_MS {
        WATCHDOG_MAX_MS
    } else {
        ms
    }
}

/// The shortest the timeout at `rate_hz` really lasts (µs): its nominal length at the fastest
/// LSI.
pub const fn shortest_timeout_us(rate_hz: u32) -> u64 {
    timeout_ms(rate_hz) as u64 * 1000 * LSI_HZ as u64 / LSI_MAX_HZ as u64
}

/// One control period at `rate_hz` (µs, rounded up).
pub const fn period_us(rate_hz: u32) -> u64 {
    1_000_000u64.div_ceil(if rate_hz == 0 { 1 } else { rate_hz as u64 })
}

/// `cycles` of the flight clock (µs, rounded up).
pub const fn flight_us(cycles: u64) -> u64 {
    (cycles * 1_000_000).div_ceil(FLIGHT_CLOCK_HZ as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_timeout_is_four_periods_within_its_bounds_and_shorter_at_the_fastest_lsi() {
        // 50 ms at 100 Hz and 200 Hz (the floor), 80 ms at 50 Hz, 4 s at 1 Hz.
        assert_eq!(
            [
                timeout_ms(200),
                timeout_ms(100),
                timeout_ms(50),
                timeout_ms(1)
            ],
            [50, 50, 80, 4000]
        );
        assert_eq!(timeout_ms(0), 4000);
        // 50 ms at 47 kHz instead of 32 kHz: 34.04 ms.
        assert_eq!(shortest_timeout_us(100), 34_042);
        assert_eq!(period_us(100), 10_000);
        assert_eq!(period_us(3), 333_334);
        // 168 000 cycles are a millisecond.
        assert_eq!(flight_us(168_000), 1000);
    }
}
