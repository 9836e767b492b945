//! Which firmware ELF may fly in the loop, and where the build leaves the default one.

use std::path::{Path, PathBuf};

/// The QEMU flying image as `cargo build -p firmware --release --target thumbv7em-none-eabihf
/// --features qemu --bin firmware-qemu` (or `cargo xtask firmware`) leaves it under `root`.
pub fn default_elf(root: &Path) -> PathBuf {
    use firmware_images::image::{Image, TARGET};
    root.join("target")
        .join(TARGET)
        .join("release")
        .join(Image::Qemu.bin())
}

/// Refuses an ELF that is not the QEMU flying image: the self-test image would run its checks
/// and exit, the STM32 image would wait for clocks QEMU does not have. The image says which it
/// is by the marker in its flash ([`firmware_images::image::Image::of_elf`]).
pub fn check_flying_image(elf: &Path) -> Result<(), String> {
    use firmware_images::image::{Image, TARGET};
    let bytes = std::fs::read(elf).map_err(|e| {
        format!(
            "firmware ELF {}: {e}; build it with `cargo build -p firmware --release --target {} --features qemu --bin {}`",
            elf.display(),
            TARGET,
            Image::Qemu.bin()
        )
    })?;
    let flying: Vec<&str> = Image::ALL
        .iter()
        .filter(|i| i.flies_in_qemu())
        .map(|i| i.bin())
        .collect();
    let flying = flying.join("` or `");
    match Image::of_elf(&bytes) {
        Some(image) if image.flies_in_qemu() => Ok(()),
        Some(other) => Err(format!(
            "{} is the `{}` image, not a flying image that runs in QEMU (`{flying}`) as the board in the loop (see --elf)",
            elf.display(),
            other.bin(),
        )),
        None => Err(format!(
            "{} is not an AUV-150 firmware image (no image marker; built before the images were binaries?); the board in the loop is `{flying}`",
            elf.display(),
        )),
    }
}
