//! The firmware facts that host tools need, without the firmware: [`image`] (which images
//! exist, their boards, memory maps and markers, and how to tell their ELFs apart) and
//! [`qemu_clock`] (QEMU's instruction counts per SysTick count).
//!
//! The `firmware` package re-exports both (`firmware::image`, `firmware::qemu_clock`) and its
//! build script uses [`image`] as a build-dependency. `host-sim` depends on this crate alone:
//! the firmware's build script (golden vectors from the host core, the STM32 link key from the
//! environment) is not part of a host-sim build, so a change of `AUV150_LINK_KEY` or of the
//! firmware does not rebuild and relink the simulator (docs/design.md, Choice 92).
#![cfg_attr(not(test), no_std)]

pub mod image;
pub mod qemu_clock;
