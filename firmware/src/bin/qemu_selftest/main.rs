//! The QEMU self-test image (`cargo fw-test`): checks the core on the target against the host,
//! counts the instructions of `update`, of each of its stages and of the math kernels,
//! exercises the link and the fail-safe, flies the loop at the flight clock (`flight`),
//! reports the stack high-water mark, and exits through
//! semihosting (0 = every check passed). `cargo xtask firmware` compares its decoded log with
//! `firmware/snapshots/selftest-*.log` and checks the counts against `firmware::budget`.
#![no_std]
#![no_main]

mod cost;
mod counter;
mod estimator;
mod flight;
mod golden;
mod kernels;
mod selftest;
mod stack;
mod vector;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::mps2_an386::halt;
use firmware::rt;

#[entry]
fn main() -> ! {
    stack::paint();
    Image::QemuSelftest.embed();
    let cp = rt::core_peripherals(halt);
    let ok = selftest::run(cp.SYST);
    halt(if ok { 0 } else { 1 })
}

firmware::fault_handlers!(halt);
