//! The STM32F405 image: the thruster board (clocks, pins, watchdog and safe state in the
//! library's `stm32f405` module; flashing in firmware/README.md). Logs over RTT.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_rtt as _;
use firmware::image::Image;
use firmware::stm32f405::{self, halt, Stm32Board};
use stm32f4xx_hal::pac::interrupt;

#[entry]
fn main() -> ! {
    // The board starts at its DEFAULT_RATE_HZ; the loop sets the controller's rate.
    firmware::rt::fly_image(Image::Stm32f405, halt, |cp, _rate_hz| Stm32Board::init(cp))
}

#[interrupt]
fn USART2() {
    stm32f405::on_usart2_interrupt();
}

firmware::fault_handlers!(halt);
