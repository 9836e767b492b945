//! Square root, correctly rounded (IEEE 754), on every target.
//!
//! On an Arm hard-float target (the Cortex-M4F: `thumbv7em-none-eabihf`) it is the FPU's
//! `vsqrt.f32`: libm's `sqrtf` compiles there to its generic software algorithm (libm selects
//! the instruction only on x86, AArch64 and wasm), and core has no stable `sqrt` without std.
//! Elsewhere (the host) it is libm's `sqrtf`, also correctly rounded, so host and target give
//! the same bits (`tests/kernels.rs` checks libm against the correctly rounded f64 root; the
//! self-test checks the instruction against libm on the target).

/// √x (NaN for x < 0, −0 for −0).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
#[inline]
pub fn sqrt(x: f32) -> f32 {
    let root: u32;
    // SAFETY: the instructions read and write only the named registers (s0 is declared
    // clobbered); no memory, no stack, no condition flags. `vsqrt.f32` exists on every Arm FPU
    // a hard-float ABI implies. The `sreg` register class would need the `vfp2` target
    // feature, which this target does not name (it has the single-precision FPv4), hence the
    // moves through core registers.
    unsafe {
        core::arch::asm!(
            "vmov s0, {x}",
            "vsqrt.f32 s0, s0",
            "vmov {root}, s0",
            x = in(reg) x.to_bits(),
            root = lateout(reg) root,
            out("s0") _,
            options(pure, nomem, nostack, preserves_flags),
        );
    }
    f32::from_bits(root)
}

/// √x (NaN for x < 0, −0 for −0).
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}
