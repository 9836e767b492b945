//! The STM32F405 image: the thruster board (clocks, pins, watchdog and safe state in the
//! library's `stm32f405` module; flashing in firmware/README.md). Logs over RTT.
//!
//! Signing is on by default: the link key is provisioned at build time from `AUV150_LINK_KEY`
//! (firmware/build.rs writes it into `link_key.rs`), and the build fails with a message that
//! says how to set one, or to opt out explicitly with `AUV150_LINK_UNSIGNED=1`.
#![no_std]
#![no_main]

use auv_link::sign::LinkKey;
use cortex_m_rt::entry;
use defmt_rtt as _;
use firmware::image::Image;
use firmware::stm32f405::{halt, Stm32Board};

/// `LINK_KEY` (`None`: built with `AUV150_LINK_UNSIGNED=1`) and `LINK_KEY_IS_CI_TEST_KEY`.
mod link_key {
    include!(concat!(env!("OUT_DIR"), "/link_key.rs"));
}

#[entry]
fn main() -> ! {
    if link_key::LINK_KEY_IS_CI_TEST_KEY {
        defmt::warn!("this image carries the PUBLIC CI test key: it is not fit to fly");
    }
    // The board starts at its DEFAULT_RATE_HZ; the loop sets the controller's rate.
    firmware::rt::fly_image(
        Image::Stm32f405,
        halt,
        link_key::LINK_KEY.map(LinkKey::new),
        |cp, _rate_hz| Stm32Board::init(cp),
    )
}

firmware::stm32f405_handlers!();

firmware::fault_handlers!(halt);
