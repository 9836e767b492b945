//! AUV-150 thruster-board firmware: a thin fixed-rate shell around `controller-core`.
//!
//! Hardware-free parts, tested on the host: [`boot`] (the controller a flying image boots
//! with, on bounds computed at build time), [`supervisor`] (arming, missions, fail-safe,
//! refusals), [`limits`] (what the board's configuration may be), [`budget`] (the
//! instruction budgets on the target: the control step, the long jobs, a period's work),
//! [`pwm`] (voltage → H-bridge duty), [`board`] (the board trait and one control period),
//! [`serial`] (the UART's byte queues between interrupt and loop), [`watchdog`] (the flight
//! board's watchdog and clock in numbers), [`image`] (which images exist and how to tell
//! their ELFs apart), [`qemu_clock`] (QEMU's instruction counts) and [`qemu_runner`] (what
//! `scripts/qemu-run.sh` reads).
//!
//! Target only (`thumbv7em-none-eabihf`): `rt` (boot, the flying loop, fault reports) and one
//! module per board, each behind its feature — `mps2_an386` (feature `qemu`) and `stm32f405`, whose
//! `emulator` build (feature `stm32f405-emulator`) runs the STM32 board code under QEMU's
//! netduinoplus2 — and `semihosting` (exit and boot configuration under QEMU). The features
//! only add a board (and its crates); they can be combined. The images themselves are the
//! binaries in `src/bin/`: `firmware-qemu`, `firmware-qemu-selftest`, `firmware-stm32f405`,
//! `firmware-stm32f405-emulator` (see firmware/README.md).
#![cfg_attr(not(test), no_std)]

pub mod board;
pub mod boot;
pub mod budget;
pub mod limits;
pub mod pwm;
pub mod serial;
pub mod supervisor;
pub mod watchdog;

// Their own crate, without this package's build script, so that host-sim can use them alone.
pub use firmware_images::{image, qemu_clock, qemu_runner, LINK_KEY_VAR, LINK_UNSIGNED_VAR};

#[cfg(target_os = "none")]
pub mod rt;

#[cfg(all(target_os = "none", feature = "qemu"))]
pub mod mps2_an386;

#[cfg(all(
    target_os = "none",
    any(feature = "qemu", feature = "stm32f405-emulator")
))]
pub mod semihosting;

#[cfg(all(target_os = "none", feature = "stm32f405"))]
pub mod stm32f405;
