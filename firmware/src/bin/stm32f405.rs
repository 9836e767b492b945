//! The STM32F405 image: the thruster board (clocks, pins, watchdog and safe state in the
//! library's `stm32f405` module; flashing in firmware/README.md). Logs over RTT.
#![no_std]
#![no_main]

use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_rtt as _;
use firmware::image::Image;
use firmware::rt;
use firmware::stm32f405::{self, halt, Stm32Board};
use firmware::supervisor::Supervisor;
use stm32f4xx_hal::pac::interrupt;

#[entry]
fn main() -> ! {
    Image::Stm32f405.embed();
    let cp = rt::core_peripherals(halt);
    let controller = rt::controller(halt);
    let mut board = Stm32Board::init(cp);
    rt::fly(&mut board, Supervisor::new(controller))
}

#[interrupt]
fn USART2() {
    stm32f405::on_usart2_interrupt();
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    rt::report_panic(info);
    halt(1)
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    rt::report_hard_fault(ef);
    halt(1)
}
