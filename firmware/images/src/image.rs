//! The firmware images: each is one binary of this package (`src/bin/…`), built for
//! [`TARGET`] with its board's feature, linked with its board's memory map, and carrying a
//! marker in its flash that says which image it is.
//!
//! The table below is the one place that says which images exist: the firmware's `build.rs`
//! links each with its memory map (a build-dependency), `cargo xtask` builds, sizes and checks each, and
//! `host-sim pil` reads the marker so that it flies only a flying image that runs in QEMU (the
//! QEMU image, or the STM32 board code's emulator build), never the self-test (which would exit
//! after its checks) or the STM32 flight image (which would wait for clocks QEMU does not
//! have); `scripts/qemu-run.sh` picks the QEMU machine by it. The `[[bin]]` entries of the
//! firmware's `Cargo.toml` must agree; a host test checks that they do.
//!
//! Core only (no std, no target code): the host crates use it as they are.

/// The target every image is built for (a Cortex-M4F with its single-precision FPU).
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// The symbol the STM32 emulator build's substitutions bring into an image
/// (`stm32f405::emulator`): the emulator image must have it, the flight image must not.
pub const EMULATOR_SYMBOL: &str = "AUV150_EMULATOR_SUBSTITUTIONS";

/// Prefix of every image marker; see [`Image::marker`].
const MARKER_PREFIX: &[u8] = b"auv150-image:";

/// One firmware image (one `[[bin]]` of this package).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Image {
    /// QEMU `mps2-an386`, flying: the fixed-rate control loop with the navigation link on
    /// UART0 (`cargo fw`; what `host-sim pil` runs).
    Qemu,
    /// QEMU `mps2-an386` self-test: golden vectors against the host, instruction counts, the
    /// link and fail-safe exercise, stack depth; exits 0 or 1 (`cargo fw-test`).
    QemuSelftest,
    /// The STM32F405 thruster board (flash with probe-rs).
    Stm32f405,
    /// The STM32F405 board code under QEMU's `netduinoplus2`, with what QEMU does not model
    /// substituted (`stm32f405::emulator`): CI's hardware in the loop over a pty. Not a flight
    /// image.
    Stm32f405Emulator,
}

impl Image {
    /// Every image, in build order.
    pub const ALL: [Image; 4] = [
        Image::Qemu,
        Image::QemuSelftest,
        Image::Stm32f405,
        Image::Stm32f405Emulator,
    ];

    /// The binary's name: `--bin NAME`, and the ELF's file name under
    /// `target/thumbv7em-none-eabihf/<profile>/`.
    pub const fn bin(self) -> &'static str {
        match self {
            Image::Qemu => "firmware-qemu",
            Image::QemuSelftest => "firmware-qemu-selftest",
            Image::Stm32f405 => "firmware-stm32f405",
            Image::Stm32f405Emulator => "firmware-stm32f405-emulator",
        }
    }

    /// The board feature the binary requires (`required-features` in `Cargo.toml`).
    pub const fn board_feature(self) -> &'static str {
        match self {
            Image::Qemu | Image::QemuSelftest => "qemu",
            Image::Stm32f405 => "stm32f405",
            Image::Stm32f405Emulator => "stm32f405-emulator",
        }
    }

    /// The linker memory map (a file at the workspace root) this image is linked with.
    pub const fn memory_map(self) -> &'static str {
        match self {
            Image::Qemu | Image::QemuSelftest => "memory-qemu.x",
            // netduinoplus2 has the STM32F405's flash and SRAM where the chip has them.
            Image::Stm32f405 | Image::Stm32f405Emulator => "memory-stm32f405.x",
        }
    }

    /// The QEMU machine the image runs on (`scripts/qemu-run.sh` picks it by the image's
    /// marker), or `None` for the real board's image, which does not run under QEMU (it waits
    /// for a crystal QEMU's STM32F405 does not have).
    pub const fn qemu_machine(self) -> Option<&'static str> {
        match self {
            Image::Qemu | Image::QemuSelftest => Some("mps2-an386"),
            Image::Stm32f405Emulator => Some("netduinoplus2"),
            Image::Stm32f405 => None,
        }
    }

    /// A flying image that runs under QEMU: one `host-sim pil` and `host-sim hil` can start.
    pub const fn flies_in_qemu(self) -> bool {
        matches!(self, Image::Qemu | Image::Stm32f405Emulator)
    }

    /// The bytes that identify this image inside its ELF: `auv150-image:<bin>;` (the `;` keeps
    /// `firmware-qemu` from matching inside `firmware-qemu-selftest`).
    pub const fn marker(self) -> &'static [u8] {
        match self {
            Image::Qemu => b"auv150-image:firmware-qemu;",
            Image::QemuSelftest => b"auv150-image:firmware-qemu-selftest;",
            Image::Stm32f405 => b"auv150-image:firmware-stm32f405;",
            Image::Stm32f405Emulator => b"auv150-image:firmware-stm32f405-emulator;",
        }
    }

    /// Puts this image's [`marker`](Self::marker) into the image's read-only data, where
    /// [`Image::of_elf`] finds it. Each image's `main` calls it once at boot; it costs a few
    /// instructions and the marker's bytes of flash.
    #[inline(always)]
    pub fn embed(self) {
        core::hint::black_box(self.marker());
    }

    /// Which image an ELF file (its bytes) is, by the marker it carries: `None` if it carries
    /// none (not one of our images, or built before images had markers) or more than one.
    pub fn of_elf(elf: &[u8]) -> Option<Image> {
        let mut found = None;
        for image in Image::ALL {
            if contains(elf, image.marker()) {
                if found.is_some() {
                    return None;
                }
                found = Some(image);
            }
        }
        found
    }
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    // Every marker starts with the prefix: look for it first (fast `position` on one byte),
    // then compare the rest.
    let first = MARKER_PREFIX[0];
    let mut start = 0;
    while let Some(i) = hay[start..].iter().position(|&b| b == first) {
        let at = start + i;
        if hay[at..].starts_with(needle) {
            return true;
        }
        start = at + 1;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markers_name_their_binary_and_none_contains_another() {
        for image in Image::ALL {
            let m = image.marker();
            assert!(m.starts_with(MARKER_PREFIX));
            assert_eq!(&m[MARKER_PREFIX.len()..m.len() - 1], image.bin().as_bytes());
            assert_eq!(m.last(), Some(&b';'));
            for other in Image::ALL {
                if other != image {
                    assert!(!contains(m, other.marker()), "{image:?} contains {other:?}");
                }
            }
        }
    }

    #[test]
    fn an_elf_is_identified_by_its_one_marker() {
        let mut elf = [0x5Au8; 300];
        assert_eq!(Image::of_elf(&elf), None);
        for image in Image::ALL {
            let mut e = elf;
            // A near miss first: the prefix alone, then the marker.
            e[10..10 + MARKER_PREFIX.len()].copy_from_slice(MARKER_PREFIX);
            let m = image.marker();
            e[100..100 + m.len()].copy_from_slice(m);
            assert_eq!(Image::of_elf(&e), Some(image));
        }
        // Two markers: ambiguous.
        let (a, b) = (Image::Qemu.marker(), Image::QemuSelftest.marker());
        elf[0..a.len()].copy_from_slice(a);
        elf[200..200 + b.len()].copy_from_slice(b);
        assert_eq!(Image::of_elf(&elf), None);
        // A marker cut short at the end of the file.
        let m = Image::Stm32f405.marker();
        let mut e = [0u8; 40];
        e[40 - (m.len() - 1)..].copy_from_slice(&m[..m.len() - 1]);
        assert_eq!(Image::of_elf(&e), None);
    }
}
