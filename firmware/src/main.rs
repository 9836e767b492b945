//! AUV-150 thruster-board firmware.
//!
//! Bare for now: it proves that `controller-core` links into a `thumbv7em-none-eabihf`
//! binary. The control loop, the link and the QEMU runs are the firmware issue's work.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::panic::PanicInfo;

    #[panic_handler]
    fn panic(_info: &PanicInfo) -> ! {
        loop {}
    }

    /// Keeps the core's math linked so the cross-build exercises it.
    #[no_mangle]
    pub extern "C" fn firmware_wrap_pi(x: f32) -> f32 {
        controller_core::math::wrap_pi(x)
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "firmware: build with --target thumbv7em-none-eabihf (math backend: {})",
        controller_core::math::BACKEND
    );
}
