//! The QEMU flying image (`cargo fw`): the thruster-board loop on `mps2-an386`, the navigation
//! link on UART0. This is the image `host-sim pil` flies (it checks the marker).
#![no_std]
#![no_main]

use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::qemu::{halt, QemuBoard};
use firmware::rt;
use firmware::supervisor::Supervisor;

#[entry]
fn main() -> ! {
    Image::Qemu.embed();
    let cp = rt::core_peripherals(halt);
    let controller = rt::controller(halt);
    let mut board = QemuBoard::init(cp.SYST, controller.config().rate_hz);
    rt::fly(&mut board, Supervisor::new(controller))
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
