//! The STM32F405 board code under QEMU's `netduinoplus2`: **not a flight image** (the
//! substitutions are in the library's `stm32f405::emulator` module). CI flies it with
//! `host-sim hil` over a pseudo-terminal on USART2. Logs over semihosting; the link key, as
//! the QEMU image's, from the semihosting command line (`-append link-key=<64 hex digits>`),
//! signing off without one.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::semihosting::link_key_or_halt;
use firmware::stm32f405::emulator::halt;
use firmware::stm32f405::Stm32Board;

#[entry]
fn main() -> ! {
    let key = link_key_or_halt();
    firmware::rt::fly_image(Image::Stm32f405Emulator, halt, key, |cp, _rate_hz| {
        Stm32Board::init_emulated(cp)
    })
}

firmware::stm32f405_handlers!();

firmware::fault_handlers!(halt);
