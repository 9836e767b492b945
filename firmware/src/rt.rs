//! What every image does at boot, in flight and on a fault (target only). Each image's `main`
//! (`src/bin/…`) picks its board and its way to end the program (`halt`: QEMU exits through
//! semihosting, the STM32 resets) and hands them to these functions.

use auv_link::sign::LinkKey;
use controller_core::Controller;
use cortex_m_rt::ExceptionFrame;
use defmt::{error, info, warn};

use crate::board::{period, Board, LinkBuffers};
use crate::image::Image;
use crate::supervisor::{BoardInfo, Supervisor};

/// Ends the program with an exit code (0 = success); never returns.
pub type Halt = fn(i32) -> !;

/// The core peripherals, taken once at boot (a second take is a bug: logged, then `halt(1)`).
pub fn core_peripherals(halt: Halt) -> cortex_m::Peripherals {
    match cortex_m::Peripherals::take() {
        Some(cp) => cp,
        None => {
            error!("core peripherals already taken");
            halt(1)
        }
    }
}

/// The controller with the default configuration, and the boot line that names the loop rate
/// and the math backend (`halt(1)` if the defaults were rejected, which the host tests rule
/// out).
pub fn controller(halt: Halt) -> Controller {
    let controller = match crate::boot::controller() {
        Ok(c) => c,
        Err(_) => {
            error!("default controller configuration rejected");
            halt(1)
        }
    };
    info!(
        "AUV-150 thruster board: {} Hz loop, controller-core {} backend",
        controller.config().rate_hz,
        controller_core::math::BACKEND
    );
    controller
}

/// The flying loop: one [`period`] after another, forever, logging every status change and
/// following rate changes the supervisor accepts.
pub fn fly<B: Board>(board: &mut B, mut sup: Supervisor, mut bufs: LinkBuffers) -> ! {
    let mut rate = sup.rate_hz();
    board.set_rate(rate);
    let mut last = None;
    let mut mounting = None;
    loop {
        let step = period(board, &mut sup, &mut bufs);
        if mounting != Some(step.telemetry.reversed_thrusters) {
            mounting = Some(step.telemetry.reversed_thrusters);
            log_mounting(step.telemetry.reversed_thrusters);
        }
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

/// Logs the thrusters' mounting in words (the strong side of each: docs/real-vehicle.md#the-default-mounting), as the
/// telemetry's reversed-thruster mask says it, so that a team reads which mounting a board
/// flies without decoding the mask.
fn log_mounting(mask: u8) {
    if mask == crate::supervisor::NOT_AUV150 {
        info!("mounting: not the AUV-150 layout");
        return;
    }
    let w = controller_core::effectiveness::mounting_words(mask);
    info!(
        "mounting (strong side): main {=str}, vert fore {=str}, vert aft {=str}, horz fore {=str}, horz aft {=str}",
        w[0], w[1], w[2], w[3], w[4]
    );
}

/// Logs a panic (where it is: file and line); the image's `#[panic_handler]` then halts.
///
/// **Choice 360:** the location only, never the message. Formatting the message is
/// `core::fmt` (its writer, padding and integer printing, ≈ 3 kB of the flying images'
/// flash), which nothing else on the board uses; the file and line name the panic as well.
pub fn report_panic(info: &core::panic::PanicInfo) {
    match info.location() {
        Some(at) => error!("panic: {=str}:{=u32}", at.file(), at.line()),
        None => error!("panic: (no location)"),
    }
}

/// Logs a HardFault; the image's `HardFault` handler then halts.
pub fn report_hard_fault(ef: &ExceptionFrame) {
    error!("HardFault at pc = {:#010x}", ef.pc());
}

/// The link with the image's key (signing on) or without (off), and the boot line that says
/// which (the key's fingerprint, never the key).
pub fn link(key: Option<&LinkKey>) -> LinkBuffers {
    match key {
        Some(k) => info!(
            "link signing on (key fingerprint {=u32:08x}): unsigned frames are refused",
            k.fingerprint()
        ),
        None => warn!("link signing OFF: any peer that computes the CRC can command the board"),
    }
    LinkBuffers::with_key(key)
}

/// What a flying image's `main` does: marks the image, takes the core peripherals, builds the
/// controller, brings the board up with them at the controller's rate (`init`), sets up the
/// link with the image's key (`None`: signing off), and flies.
pub fn fly_image<B: Board>(
    image: Image,
    halt: Halt,
    key: Option<LinkKey>,
    init: impl FnOnce(cortex_m::Peripherals, u32) -> B,
) -> ! {
    image.embed();
    let cp = core_peripherals(halt);
    let controller = controller(halt);
    let mut board = init(cp, controller.config().rate_hz);
    let bufs = link(key.as_ref());
    let info = BoardInfo {
        supply_voltage: board.supply_voltage(),
        signing: bufs.signing(),
    };
    fly(&mut board, Supervisor::new(controller, info), bufs)
}

/// Defines an image's `#[panic_handler]` and `HardFault` handler: report, then `$halt(1)`.
/// Each image's binary invokes it once with its board's `halt`.
#[macro_export]
macro_rules! fault_handlers {
    ($halt:path) => {
        #[panic_handler]
        fn panic(info: &core::panic::PanicInfo) -> ! {
            $crate::rt::report_panic(info);
            $halt(1)
        }

        #[cortex_m_rt::exception]
        unsafe fn HardFault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::rt::report_hard_fault(ef);
            $halt(1)
        }
    };
}
