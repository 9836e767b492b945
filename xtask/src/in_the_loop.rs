//! Processor and hardware in the loop: host-sim flies the QEMU flying image and the STM32
//! board code's emulator image. The checks are their own package, `xtask/loop/` (they build on
//! host-sim, whose plots link fontconfig, and the xtask must build before the set-up installs
//! it); this starts them with the ELFs that built and takes their failures into this run's.

use xtask::ci::{Ci, HOST_PROFILE};

use crate::images::{Built, Variant};

pub fn run(ci: &mut Ci, built: &Built) {
    let Some(elf) = built.elf(Variant::QEMU) else {
        ci.fail("PIL: no QEMU flying image (its build failed, see above)");
        return;
    };
    let mut cmd = ci.cargo();
    cmd.args([
        "run",
        "--profile",
        HOST_PROFILE,
        "-p",
        "xtask-loop",
        "--",
        "--qemu",
    ])
    .arg(elf);
    let mut shown = format!(
        "cargo run --profile {HOST_PROFILE} -p xtask-loop -- --qemu {}",
        ci.rel(elf)
    );
    match built.elf(Variant::EMULATOR) {
        Some(emulator) => {
            cmd.arg("--emulator").arg(emulator);
            shown += &format!(" --emulator {}", ci.rel(emulator));
        }
        None => ci.fail("HIL: no STM32 emulator image (its build failed, see above)"),
    }
    ci.run_collecting(cmd, &shown);
}
