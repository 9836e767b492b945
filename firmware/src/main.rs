//! AUV-150 thruster-board firmware binary.
//!
//! Boards (cargo features): `qemu` (default; mps2-an386) or `stm32f405`. With `selftest` the
//! QEMU image runs the self-test and exits instead of flying. See firmware/README.md.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(all(target_os = "none", feature = "qemu", feature = "stm32f405"))]
compile_error!("select one board: --no-default-features --features stm32f405 for the STM32");

// The self-test image uses only the board's constants; the rest is the flying image's.
#[cfg(all(target_os = "none", feature = "qemu"))]
#[cfg_attr(feature = "selftest", allow(dead_code))]
mod qemu;
#[cfg(all(target_os = "none", feature = "selftest"))]
mod selftest;
#[cfg(all(target_os = "none", feature = "selftest"))]
mod stack;
#[cfg(all(target_os = "none", feature = "stm32f405"))]
mod stm32f405;

#[cfg(target_os = "none")]
#[cfg_attr(feature = "selftest", allow(dead_code, unused_imports))]
mod rt {
    #[cfg(not(feature = "selftest"))]
    use controller_core::{Controller, ControllerConfig};
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use defmt::{error, info};
    use firmware::board::{period, Board, LinkBuffers};
    use firmware::supervisor::Supervisor;

    #[cfg(feature = "stm32f405")]
    use defmt_rtt as _;
    #[cfg(feature = "qemu")]
    use defmt_semihosting as _;

    /// Ends the program: QEMU exits with `code` through semihosting; a real board resets (its
    /// PWM pins float as inputs after reset: the H-bridge inputs need pull-downs so that a reset
    /// disables them — see firmware/README.md).
    pub fn halt(code: i32) -> ! {
        #[cfg(feature = "qemu")]
        {
            let status = if code == 0 {
                cortex_m_semihosting::debug::EXIT_SUCCESS
            } else {
                cortex_m_semihosting::debug::EXIT_FAILURE
            };
            cortex_m_semihosting::debug::exit(status);
        }
        #[allow(unreachable_code)]
        {
            let _ = code;
            cortex_m::peripheral::SCB::sys_reset()
        }
    }

    #[entry]
    fn main() -> ! {
        #[cfg(feature = "selftest")]
        crate::stack::paint();
        let Some(cp) = cortex_m::Peripherals::take() else {
            error!("core peripherals already taken");
            halt(1)
        };
        #[cfg(feature = "selftest")]
        {
            let ok = crate::selftest::run(cp.SYST);
            halt(if ok { 0 } else { 1 })
        }
        #[cfg(not(feature = "selftest"))]
        {
            let controller = match Controller::new(ControllerConfig::default()) {
                Ok(c) => c,
                Err(_) => {
                    error!("default controller configuration rejected");
                    halt(1)
                }
            };
            let rate = controller.config().rate_hz;
            info!(
                "AUV-150 thruster board: {} Hz loop, controller-core {} backend",
                rate,
                controller_core::math::BACKEND
            );
            #[cfg(feature = "qemu")]
            let mut board = crate::qemu::QemuBoard::init(cp.SYST, rate);
            #[cfg(feature = "stm32f405")]
            let mut board = crate::stm32f405::Stm32Board::init(cp);
            fly(&mut board, Supervisor::new(controller))
        }
    }

    fn fly<B: Board>(board: &mut B, mut sup: Supervisor) -> ! {
        let mut bufs = LinkBuffers::new();
        let mut rate = sup.rate_hz();
        board.set_rate(rate);
        let mut last = None;
        loop {
            let step = period(board, &mut sup, &mut bufs);
            if last != Some(step.telemetry.status) {
                info!(
                    "tick {}: {}",
                    step.telemetry.tick,
                    step.telemetry.status.as_str()
                );
                last = Some(step.telemetry.status);
            }
            if sup.rate_hz() != rate {
                rate = sup.rate_hz();
                board.set_rate(rate);
                info!("loop rate now {} Hz", rate);
            }
        }
    }

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        error!("panic: {}", defmt::Display2Format(info));
        halt(1)
    }

    #[exception]
    unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
        error!("HardFault at pc = {:#010x}", ef.pc());
        halt(1)
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "firmware: build with --target thumbv7em-none-eabihf (cargo fw / cargo fw-test); math backend {}",
        controller_core::math::BACKEND
    );
}
