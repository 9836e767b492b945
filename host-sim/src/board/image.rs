//! Which firmware ELF may fly in the loop, and where the build leaves the default one.

use std::path::{Path, PathBuf};

use super::error::Error;

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
pub fn check_flying_image(elf: &Path) -> Result<(), Error> {
    use firmware_images::image::Image;
    let bytes = std::fs::read(elf).map_err(|io| Error::ElfUnreadable {
        path: elf.to_path_buf(),
        io,
    })?;
    match Image::of_elf(&bytes) {
        Some(image) if image.flies_in_qemu() => Ok(()),
        Some(image) => Err(Error::NotFlyingImage {
            path: elf.to_path_buf(),
            image,
        }),
        None => Err(Error::NoImageMarker {
            path: elf.to_path_buf(),
        }),
    }
}
