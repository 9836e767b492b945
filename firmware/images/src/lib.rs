//! The firmware facts that host tools need, without the firmware: [`image`] (which images
//! exist, their boards, memory maps and markers, and how to tell their ELFs apart),
//! [`qemu_clock`] (QEMU's instruction counts per SysTick count) and [`qemu_runner`] (what the
//! runner script reads from its environment).
//!
//! The `firmware` package re-exports them (`firmware::image`, `firmware::qemu_clock`,
//! `firmware::qemu_runner`) and its
//! build script uses [`image`] as a build-dependency. `host-sim` depends on this crate alone:
//! the firmware's build script (golden vectors from the host core, the STM32 link key from the
//! environment) is not part of a host-sim build, so a change of `AUV150_LINK_KEY` or of the
//! firmware does not rebuild and relink the simulator (docs/ci.md#deterministic-tests-and-quick-rebuilds, Choice 92).
#![cfg_attr(not(test), no_std)]

pub mod image;
pub mod qemu_clock;
pub mod qemu_runner;

/// The navigation link's baud rate, 8N1 (10 bits on the wire a byte): the STM32 board's USART2
/// (`firmware::serial::LINK_BAUD`) and the default of `host-sim hil --baud`.
pub const LINK_BAUD: u32 = 460_800;

/// Bits on the line a byte at 8N1: start, 8 data, stop.
pub const LINK_BITS_PER_BYTE: u32 = 10;

/// The time `bytes` take on the link at [`LINK_BAUD`], 8N1 (ns, rounded down).
pub const fn wire_nanos(bytes: u64) -> u64 {
    bytes * LINK_BITS_PER_BYTE as u64 * 1_000_000_000 / LINK_BAUD as u64
}

/// The time `bytes` take on the link at [`LINK_BAUD`], 8N1 (s).
pub fn wire_seconds(bytes: u64) -> f64 {
    bytes as f64 * f64::from(LINK_BITS_PER_BYTE) / f64::from(LINK_BAUD)
}

/// [`LINK_BAUD`] as text reads it, thousands apart: `460 800` (`format!("{LinkBaud}")`).
pub struct LinkBaud;

impl core::fmt::Display for LinkBaud {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} {:03}", LINK_BAUD / 1000, LINK_BAUD % 1000)
    }
}

/// The build-time environment variable with the STM32 image's link key: 64 hexadecimal digits
/// (`firmware/src/provision.rs`, `scripts/ci-link-key.sh`).
pub const LINK_KEY_VAR: &str = "AUV150_LINK_KEY";
/// `1`: build the STM32 image without a key (signing off), explicitly.
pub const LINK_UNSIGNED_VAR: &str = "AUV150_LINK_UNSIGNED";

#[cfg(test)]
mod wire_tests {
    use super::*;

    /// 460 800 baud at 10 bits a byte is 46 080 bytes a second (link/src/lib.rs's figure).
    #[test]
    fn a_second_of_line_is_46080_bytes() {
        assert_eq!(wire_seconds(46_080), 1.0);
        assert_eq!(wire_nanos(46_080), 1_000_000_000);
        assert_eq!(std::format!("{LinkBaud}"), "460 800");
    }
}
