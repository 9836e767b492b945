//! `pil` flies only a flying image that runs in QEMU — the QEMU image, or the STM32 board code's
//! emulator build: the self-test image (which runs its checks and exits), the STM32 flight
//! image (which waits for a crystal QEMU does not have) and anything without an image marker
//! are refused with a message that says why.

use std::path::PathBuf;

use firmware_images::image::Image;
use host_sim::board::image::check_flying_image;

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
    assert_eq!(check_flying_image(&flying), Ok(()));
    let emulator = fake_elf("emulator", Some(Image::Stm32f405Emulator));
    assert_eq!(check_flying_image(&emulator), Ok(()));

    let selftest = fake_elf("selftest", Some(Image::QemuSelftest));
    let err = check_flying_image(&selftest).unwrap_err();
    assert!(err.contains("firmware-qemu-selftest"), "{err}");
    assert!(
        err.contains("(`firmware-qemu` or `firmware-stm32f405-emulator`)"),
        "{err}"
    );

    let stm32 = fake_elf("stm32", Some(Image::Stm32f405));
    assert!(check_flying_image(&stm32)
        .unwrap_err()
        .contains("firmware-stm32f405"));

    let unmarked = fake_elf("unmarked", None);
    assert!(check_flying_image(&unmarked)
        .unwrap_err()
        .contains("not an AUV-150 firmware image"));

    let missing = std::env::temp_dir().join("auv150-pil-elf-does-not-exist");
    assert!(check_flying_image(&missing)
        .unwrap_err()
        .contains("--bin firmware-qemu"));

    for p in [flying, emulator, selftest, stm32, unmarked] {
        let _ = std::fs::remove_file(p);
    }
}
