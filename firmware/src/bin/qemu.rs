//! The QEMU flying image (`cargo fw`): the thruster-board loop on `mps2-an386`, the navigation
//! link on UART0. This is the image `host-sim pil` flies (it checks the marker). Signing is on
//! if the semihosting command line provisions a key (`-append link-key=<64 hex digits>`;
//! `host-sim pil --link-key-file` does), off otherwise; a malformed key stops the board.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::mps2_an386::{halt, QemuBoard};
use firmware::semihosting::link_key_or_halt;

#[entry]
fn main() -> ! {
    let key = link_key_or_halt();
    firmware::rt::fly_image(Image::Qemu, halt, key, |cp, rate_hz| {
        QemuBoard::init(cp.SYST, rate_hz)
    })
}

firmware::fault_handlers!(halt);
