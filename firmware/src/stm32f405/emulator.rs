//! The STM32F405 board code under emulation: QEMU's `netduinoplus2` (an STM32F405RG), for the
//! `firmware-stm32f405-emulator` image (feature `stm32f405-emulator`). It is **not a flight
//! image**: it exists so that CI runs the board's own link path — USART2, its interrupt, the
//! SPSC queues, [`Usart2Link`](super::Usart2Link) — and the supervisor and control loop above
//! it, against `host-sim hil` over a pseudo-terminal.
//!
//! # Substitutions
//!
//! QEMU 10's STM32F405 models the core (SysTick on a 168 MHz core clock, the NVIC), the USARTs
//! and TIM2–TIM5; RCC, GPIO, TIM1/TIM8, the IWDG and DBGMCU are *unimplemented devices*:
//! their registers read as zero and ignore writes. What this build does differently, and only
//! this build: 1 and 2 in [`Stm32Board::init_emulated`] (the real image's
//! [`Stm32Board::init`] has none of it, and its ELF is checked not to contain this function),
//! 3 and 4 in the emulator's binary (`src/bin/stm32f405_emulator.rs`):
//!
//! 1. **Clock tree.** `RCC.freeze()` waits for the crystal's ready flag, which QEMU never sets.
//!    The emulator build takes the HAL's reset-state view instead (`RCC.constrain()`: the 16 MHz
//!    HSI on every bus) and programs nothing. The view is used for one thing, USART2's baud
//!    register, which QEMU ignores (a pty has no baud rate). SysTick is unaffected: QEMU's core
//!    clock is 168 MHz, [`SYSCLK_HZ`](super::SYSCLK_HZ), so the control period is the board's.
//! 2. **Thruster PWM.** TIM1/TIM8 are not modelled (a duty written there reads back 0), so the
//!    five outputs are [`MemPwm`] channels with the real timers' resolution,
//!    [`PWM_COUNTS`] = 8400: the voltage → duty path is the same, the duty
//!    stays in RAM.
//! 3. **Logs and the end of the program.** defmt goes over semihosting (QEMU's stdout, decoded
//!    by `defmt-print`) instead of RTT, and `halt` exits QEMU with the code through
//!    semihosting instead of resetting the MCU.
//! 4. **Link key.** From the semihosting command line (`-append link-key=…`), as the QEMU
//!    image takes it, so that `host-sim hil --link-key-file` provisions both ends; the real
//!    image carries its key in flash from the build (`AUV150_LINK_KEY`).
//!
//! # What runs, and what it proves
//!
//! Unchanged from the real image: the HAL's `Serial` set-up of USART2 and its RXNE interrupt,
//! [`on_usart2_interrupt`](super::on_usart2_interrupt) behind NVIC IRQ 38 (receive and the
//! TXE-driven transmit), both queues, SysTick's period programming, the IWDG programming
//! sequence, the DBGMCU writes, the GPIO port set-up, the supervisor and the control loop.
//!
//! What stays verified only on hardware (where QEMU reads zeros or does nothing) is listed
//! once, in firmware/README.md ("Verified only on hardware"). Here, DWT CYCCNT reads 0, so
//! `now()` and the telemetry's update timings are 0.

use super::{stop_in_debug, Stm32Board, ThrusterOutputs, PWM_COUNTS};
use crate::image::Image;
use crate::pwm::MemPwm;
use controller_core::effectiveness::THRUSTERS;
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;

pub use crate::semihosting::halt;

/// The QEMU machine this build runs on (the images' table says which).
pub const QEMU_MACHINE: &str = match Image::Stm32f405Emulator.qemu_machine() {
    Some(m) => m,
    None => panic!("the emulator image runs in QEMU"),
};

/// A symbol that exists in an image exactly when [`Stm32Board::init_emulated`] is linked into
/// it: `cargo xtask images` checks that the emulator image has it and the flight image does
/// not ([`crate::image::EMULATOR_SYMBOL`] is its name).
#[export_name = "AUV150_EMULATOR_SUBSTITUTIONS"]
static EMULATOR_SUBSTITUTIONS: u8 = 0;

/// The five thruster outputs as RAM channels (substitution 2 above).
pub struct EmulatedTimers([MemPwm; THRUSTERS]);

impl ThrusterOutputs for EmulatedTimers {
    type Channel = MemPwm;
    fn channels(&mut self) -> &mut [MemPwm; THRUSTERS] {
        &mut self.0
    }
}

impl Stm32Board<EmulatedTimers> {
    /// [`Stm32Board::init`] as far as QEMU's `netduinoplus2` allows (module docs: the
    /// substitutions). Call once, as `init`.
    ///
    /// # Panics
    ///
    /// As [`Stm32Board::init`]: on a second call.
    pub fn init_emulated(cp: cortex_m::Peripherals) -> Self {
        core::hint::black_box(&EMULATOR_SUBSTITUTIONS);
        let dp = pac::Peripherals::take().expect("device peripherals already taken");
        stop_in_debug(&dp.DBGMCU);
        defmt::warn!(
            "stm32f405 EMULATOR build ({=str}): no clock tree, thrusters in RAM; not a flight image",
            QEMU_MACHINE
        );
        // Substitution 1: the HAL's reset-state clocks, nothing programmed.
        let mut rcc = dp.RCC.constrain();
        let gpioa = dp.GPIOA.split(&mut rcc);
        let thrusters = EmulatedTimers([MemPwm::neutral(PWM_COUNTS); THRUSTERS]);
        Stm32Board::assemble(
            cp,
            dp.USART2,
            (gpioa.pa2, gpioa.pa3),
            dp.IWDG,
            &mut rcc,
            thrusters,
        )
    }
}
