//! The QEMU self-test image (`cargo fw-test`): checks the core on the target against the host,
//! counts the instructions of `update`, exercises the link and the fail-safe, reports the stack
//! high-water mark, and exits through semihosting (0 = every check passed). `cargo xtask
//! firmware` compares its decoded log with `firmware/snapshots/selftest-*.log`.
#![no_std]
#![no_main]

mod selftest;
mod stack;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use firmware::image::Image;
use firmware::qemu::halt;
use firmware::rt;

#[entry]
fn main() -> ! {
    stack::paint();
    Image::QemuSelftest.embed();
    let cp = rt::core_peripherals(halt);
    let ok = selftest::run(cp.SYST);
    halt(if ok { 0 } else { 1 })
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
