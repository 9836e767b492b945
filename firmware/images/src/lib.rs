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

/// The build-time environment variable with the STM32 image's link key: 64 hexadecimal digits
/// (`firmware/src/provision.rs`, `scripts/ci-link-key.sh`).
pub const LINK_KEY_VAR: &str = "AUV150_LINK_KEY";
/// `1`: build the STM32 image without a key (signing off), explicitly.
pub const LINK_UNSIGNED_VAR: &str = "AUV150_LINK_UNSIGNED";
