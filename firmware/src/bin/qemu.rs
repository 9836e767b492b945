//! The QEMU flying image (`cargo fw`): the thruster-board loop on `mps2-an386`, the navigation
//! link on UART0. This is the image `host-sim pil` flies (it checks the marker).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::qemu::{halt, QemuBoard};

#[entry]
fn main() -> ! {
    firmware::rt::fly_image(Image::Qemu, halt, |cp, rate_hz| {
        QemuBoard::init(cp.SYST, rate_hz)
    })
}

firmware::fault_handlers!(halt);
