//! AUV-150 thruster-board firmware: a thin fixed-rate shell around `controller-core`.
//!
//! Hardware-free parts live here so they are tested on the host: [`supervisor`] (arming,
//! missions, fail-safe), [`pwm`] (voltage → H-bridge duty) and [`board`] (the board trait and
//! one control period). The target binary (`src/main.rs`) adds a board: `qemu` (mps2-an386)
//! or `stm32f405`.
#![cfg_attr(not(test), no_std)]

pub mod board;
pub mod pwm;
pub mod supervisor;
