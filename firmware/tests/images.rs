//! `Cargo.toml`'s `[[bin]]` entries and the images' table (`firmware::image`) say the same
//! thing: every image is a binary of its name, requiring its board's feature, and its memory
//! map exists.

use std::path::Path;

use firmware::image::Image;

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_image_is_a_bin_with_its_board_feature() {
    let text = std::fs::read_to_string(manifest_dir().join("Cargo.toml")).unwrap();
    let manifest: toml::Table = text.parse().unwrap();
    let bins = manifest["bin"].as_array().expect("[[bin]] entries");
    assert_eq!(bins.len(), Image::ALL.len(), "one [[bin]] per image");
    let features = manifest["features"].as_table().unwrap();
    for image in Image::ALL {
        let bin = bins
            .iter()
            .find(|b| b["name"].as_str() == Some(image.bin()))
            .unwrap_or_else(|| panic!("no [[bin]] named {}", image.bin()));
        let required: Vec<&str> = bin["required-features"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        assert_eq!(required, [image.board_feature()], "{}", image.bin());
        assert!(features.contains_key(image.board_feature()));
        let path = bin["path"].as_str().unwrap();
        assert!(manifest_dir().join(path).is_file(), "{path}");
        // Host builds of the workspace must not try to build an image.
        assert_eq!(bin["test"].as_bool(), Some(false), "{}", image.bin());
    }
    assert_eq!(
        features["default"].as_array().map(Vec::len),
        Some(0),
        "no default board: a host build builds the library only"
    );
}

#[test]
fn every_memory_map_exists_and_none_sits_at_the_root_as_memory_x() {
    let root = manifest_dir().join("..");
    for image in Image::ALL {
        assert!(root.join(image.memory_map()).is_file(), "{image:?}");
    }
    // The linker searches the working directory first: a root memory.x would shadow them.
    assert!(!root.join("memory.x").exists());
}

/// The runner picks the QEMU machine by the image's marker (scripts/qemu-run.sh): its table
/// must say what `Image::qemu_machine` says, and refuse the images that do not run in QEMU.
#[test]
fn the_runner_runs_each_image_on_its_machine() {
    let runner = std::fs::read_to_string(manifest_dir().join("../scripts/qemu-run.sh")).unwrap();
    let arm = |bin: &str| {
        runner
            .lines()
            .map(str::trim_start)
            .find(|l| l.starts_with(&format!("{bin})")))
            .map(str::to_string)
    };
    let default = arm("*").expect("a default arm");
    for image in Image::ALL {
        let line = arm(image.bin());
        match image.qemu_machine() {
            Some(machine) => {
                let line = line.unwrap_or_else(|| default.clone());
                assert!(
                    line.contains(&format!("machine={machine} ")),
                    "{}: the runner's `{line}` must run it on {machine}",
                    image.bin()
                );
            }
            None => {
                let line =
                    line.unwrap_or_else(|| panic!("{}: the runner must refuse it", image.bin()));
                assert!(!line.contains("machine="), "{}: {line}", image.bin());
                assert!(
                    runner.contains("does not run under QEMU"),
                    "the refusal says why"
                );
            }
        }
    }
    // The marker the runner greps for is the images' marker.
    let prefix = std::str::from_utf8(Image::Qemu.marker())
        .unwrap()
        .trim_end_matches(&(Image::Qemu.bin().to_owned() + ";"));
    assert!(
        runner.contains(&format!("'{prefix}[a-z0-9-]*;'")),
        "{prefix}"
    );
    assert!(runner.contains(&format!("bin=${{marker#{prefix}}}")));
}
