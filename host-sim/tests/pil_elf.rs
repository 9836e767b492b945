//! `pil` flies only a flying image that runs in QEMU — the QEMU image, or the STM32 board code's
//! emulator build: the self-test image (which runs its checks and exits), the STM32 flight
//! image (which waits for a crystal QEMU does not have) and anything without an image marker
//! are refused with a message that says why.

use std::path::PathBuf;

use firmware_images::image::Image;
use host_sim::board::image::check_flying_image;
use host_sim::board::Error;

fn fake_elf(name: &str, marker: Option<Image>) -> PathBuf {
    let mut bytes = b"\x7fELF".to_vec();
    bytes.resize(4096, 0xA5);
    if let Some(image) = marker {
        let m = image.marker();
        bytes[1000..1000 + m.len()].copy_from_slice(m);
    }
    let path = std::env::temp_dir().join(format!("auv150-pil-elf-{}-{name}", std::process::id()));
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn only_flying_images_that_run_in_qemu_are_flown() {
    let flying = fake_elf("flying", Some(Image::Qemu));
    assert!(check_flying_image(&flying).is_ok());
    let emulator = fake_elf("emulator", Some(Image::Stm32f405Emulator));
    assert!(check_flying_image(&emulator).is_ok());

    let selftest = fake_elf("selftest", Some(Image::QemuSelftest));
    let err = check_flying_image(&selftest);
    assert!(
        matches!(
            err,
            Err(Error::NotFlyingImage {
                image: Image::QemuSelftest,
                ..
            })
        ),
        "{err:?}"
    );
    // The message names the images that do fly (what to give --elf instead).
    let message = err.map_or_else(|e| e.to_string(), |()| String::new());
    for image in Image::ALL.iter().filter(|i| i.flies_in_qemu()) {
        assert!(message.contains(image.bin()), "{message}");
    }

    let stm32 = fake_elf("stm32", Some(Image::Stm32f405));
    let err = check_flying_image(&stm32);
    assert!(
        matches!(
            err,
            Err(Error::NotFlyingImage {
                image: Image::Stm32f405,
                ..
            })
        ),
        "{err:?}"
    );

    let unmarked = fake_elf("unmarked", None);
    let err = check_flying_image(&unmarked);
    assert!(matches!(err, Err(Error::NoImageMarker { .. })), "{err:?}");

    let missing = std::env::temp_dir().join("auv150-pil-elf-does-not-exist");
    let err = check_flying_image(&missing);
    assert!(
        matches!(&err, Err(Error::ElfUnreadable { io, .. }) if io.kind() == std::io::ErrorKind::NotFound),
        "{err:?}"
    );

    for p in [flying, emulator, selftest, stm32, unmarked] {
        let _ = std::fs::remove_file(p);
    }
}
