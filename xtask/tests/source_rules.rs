//! The workspace's source rules (xtask/src/source/, docs/ci.md, Choices 86, 210, 211),
//! on the repository and on small fixture packages that break them: no function outside test
//! code over 80 lines without its reason written above it, and no set of modules of a crate
//! that reach each other through their imports. Every crate of the repository is read
//! (libraries, binaries, examples, benchmarks, build scripts); integration tests and fuzz
//! targets are test code.

use std::path::{Path, PathBuf};

use xtask::source::{self, LONG_FN_LINES, LONG_MARKER};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask/ is in the workspace root")
        .to_path_buf()
}

/// (file, function, line, lines) of every long function without a reason under `root`.
fn unexplained(root: &Path) -> Vec<(String, String, usize, usize)> {
    source::workspace_long_functions(root)
        .expect("the sources")
        .into_iter()
        .filter(|(_, f)| f.reason.is_none())
        .map(|(file, f)| (file.display().to_string(), f.name, f.line, f.lines))
        .collect()
}

/// Every long function without a reason under `root`, as a message.
fn long_offenders(root: &Path) -> Vec<String> {
    unexplained(root)
        .into_iter()
        .map(|(file, name, line, lines)| format!("{file}:{line} fn {name}: {lines} lines"))
        .collect()
}

#[test]
fn no_function_is_long_without_its_reason() {
    let offenders = long_offenders(&root());
    assert!(
        offenders.is_empty(),
        "functions over {LONG_FN_LINES} lines without a `{LONG_MARKER} <reason>` comment directly above them (split them into named steps, or say why they are right long):\n  {}",
        offenders.join("\n  ")
    );
}

/// Every import circle under `root`, as a report.
fn circle_offenders(root: &Path) -> Vec<String> {
    source::circles(root)
        .expect("the crates")
        .iter()
        .map(ToString::to_string)
        .collect()
}

#[test]
fn no_modules_of_a_crate_import_each_other_in_a_circle() {
    let offenders = circle_offenders(&root());
    assert!(
        offenders.is_empty(),
        "import circles (each step is a module and the line that makes it depend on the next; \
         move what the circle's modules share into a module of its own that imports none of \
         them):\n{}",
        offenders.join("\n")
    );
}

#[test]
fn every_rust_file_belongs_to_a_crate() {
    // A file no crate reads (not declared by any `mod`) is one the rules never see.
    let unseen = source::unseen_rust_files(&root()).expect("the sources");
    assert!(
        unseen.is_empty(),
        "Rust files that no crate of the repository reads (a leftover, or a target Cargo does not find):\n  {}",
        unseen
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join("\n  ")
    );
}

#[test]
fn the_scan_sees_every_crate_and_its_modules() {
    // A scan that found no crate or no module would pass the rules above vacuously.
    let crates = source::crates(&root()).expect("the workspace's crates");
    let names: Vec<&str> = crates.iter().map(|c| c.name.as_str()).collect();
    for expected in [
        "controller-core",
        "controller-core example track",
        "controller-core example kernel_constants",
        "controller-core bench update",
        "auv-link",
        "firmware",
        "firmware bin firmware-qemu-selftest",
        "firmware build",
        "host-sim",
        "host-sim bin host-sim",
        "host-sim bench sim",
        "xtask",
        "xtask bin xtask",
        "xtask-loop bin xtask-loop",
    ] {
        assert!(names.contains(&expected), "{expected} not in {names:?}");
    }
    assert!(
        !names
            .iter()
            .any(|n| n.contains(" test ") || n.contains(" fuzz ")),
        "integration tests and fuzz targets are test code: {names:?}"
    );
    let core = crates.iter().find(|c| c.name == "controller-core").unwrap();
    let graph = core.graph();
    // `PseudoInverse` is defined in allocation/pseudo_inverse.rs and re-exported by
    // allocation/mod.rs; controller.rs names it through the re-export.
    assert!(graph["controller"].contains("allocation::pseudo_inverse"));
    assert!(!graph["controller"].contains("allocation"));
    assert!(graph.contains_key("trajectory::paths::circle"));
    // The build script reads the firmware's provisioning module through `#[path]`.
    let build = crates.iter().find(|c| c.name == "firmware build").unwrap();
    assert!(build.modules["provision"]
        .file
        .ends_with("firmware/src/provision.rs"));
}

/// A package written under the test's scratch directory: (path, text) of each file.
fn fixture(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("source-rules")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let manifest = format!("[package]\nname = \"{name}\"\nversion = \"0.0.0\"\n");
    for (path, text) in [("Cargo.toml", manifest.as_str())].iter().chain(files) {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().expect("a file in a directory")).expect("mkdir");
        std::fs::write(&p, text).expect("write a fixture file");
    }
    dir
}

#[test]
fn a_circle_of_three_modules_fails_the_rule() {
    // No two of them import each other: a pairwise check passes it.
    let dir = fixture(
        "three",
        &[
            ("src/lib.rs", "mod runner;\nmod stats;\nmod upload;\n"),
            (
                "src/runner.rs",
                "use crate::stats::Stats;\npub struct Runner(Stats);\n",
            ),
            (
                "src/stats.rs",
                "use crate::upload::Upload;\npub struct Stats(Upload);\n",
            ),
            (
                "src/upload.rs",
                "pub struct Upload;\nfn f() { crate::runner::g(); }\n",
            ),
        ],
    );
    let offenders = circle_offenders(&dir);
    assert_eq!(offenders.len(), 1, "{offenders:?}");
    assert!(
        offenders[0].contains("three: 3 modules import each other: runner, stats, upload"),
        "{}",
        offenders[0]
    );
    for step in [
        "runner -> stats  (",
        "src/runner.rs:1 `use crate::stats::Stats`)",
        "stats -> upload  (",
        "upload -> runner  (",
        "src/upload.rs:2 `crate::runner::g`)",
    ] {
        assert!(offenders[0].contains(step), "{step}: {}", offenders[0]);
    }
}

#[test]
fn a_circle_through_a_re_export_fails_the_rule() {
    // `error` names `Limits` through its parent's re-export; `Limits` is defined in
    // `waypoints`, which uses `error`. Read as "`error` uses its parent", it is no circle.
    let dir = fixture(
        "reexport",
        &[
            ("src/lib.rs", "pub mod trajectory;\n"),
            (
                "src/trajectory/mod.rs",
                "mod error;\nmod waypoints;\npub use waypoints::Limits;\npub use error::Error;\n",
            ),
            (
                "src/trajectory/error.rs",
                "use super::Limits;\npub struct Error(Limits);\n",
            ),
            (
                "src/trajectory/waypoints.rs",
                "pub struct Limits;\nfn check() -> Result<(), super::error::Error> { Ok(()) }\n",
            ),
        ],
    );
    let offenders = circle_offenders(&dir);
    assert_eq!(offenders.len(), 1, "{offenders:?}");
    for part in [
        "trajectory::error, trajectory::waypoints",
        "trajectory::error -> trajectory::waypoints  (src/trajectory/error.rs:1 `use super::Limits (through trajectory)`)",
    ] {
        assert!(offenders[0].contains(part), "{part}: {}", offenders[0]);
    }
}

#[test]
fn a_long_function_in_a_build_script_or_an_example_fails_the_rule() {
    let body = "    step();\n".repeat(LONG_FN_LINES);
    let long = format!("fn main() {{\n{body}}}\nfn step() {{}}\n");
    let explained = format!("// Long: a table.\nfn main() {{\n{body}}}\nfn step() {{}}\n");
    let dir = fixture(
        "long",
        &[
            ("src/lib.rs", ""),
            ("build.rs", &long),
            ("examples/demo.rs", &long),
            ("examples/fine.rs", &explained),
            ("benches/b.rs", &long),
            // Integration tests and fuzz targets are test code.
            ("tests/t.rs", &long),
            (
                "fuzz/Cargo.toml",
                "[package]\nname = \"f\"\n[package.metadata]\ncargo-fuzz = true\n\
                 [[bin]]\nname = \"t\"\npath = \"targets/t.rs\"\n",
            ),
            ("fuzz/targets/t.rs", &long),
        ],
    );
    let lines = LONG_FN_LINES + 2;
    assert_eq!(
        long_offenders(&dir),
        [
            format!("benches/b.rs:1 fn main: {lines} lines"),
            format!("build.rs:1 fn main: {lines} lines"),
            format!("examples/demo.rs:1 fn main: {lines} lines"),
        ]
    );
}

#[test]
fn a_file_no_crate_reads_is_reported() {
    let dir = fixture(
        "unseen",
        &[
            ("src/lib.rs", "mod a;\n#[cfg(test)]\nmod tests;\n"),
            ("src/a.rs", ""),
            ("src/tests.rs", ""),
            ("src/forgotten.rs", "fn f() {}\n"),
            ("tests/common/mod.rs", ""),
            ("tests/t.rs", "mod common;\n"),
        ],
    );
    assert_eq!(
        source::unseen_rust_files(&dir).expect("the fixture"),
        [PathBuf::from("src/forgotten.rs")]
    );
}

/// host-sim's layers, as `host-sim/src/lib.rs`'s table gives them: (top-level module, layer).
/// The table is the one statement of the layering; this reads it (`//! | N | [`module`] | …`).
fn host_sim_layers() -> Vec<(String, u32)> {
    let lib =
        std::fs::read_to_string(root().join("host-sim/src/lib.rs")).expect("host-sim's lib.rs");
    lib.lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.strip_prefix("//! |")?.split('|').map(str::trim).collect();
            let layer = cells.first()?.parse().ok()?;
            let module = cells
                .get(1)?
                .trim_start_matches("[`")
                .trim_end_matches("`]");
            Some((module.to_string(), layer))
        })
        .collect()
}

/// host-sim is a stack of layers (docs/simulator.md#structure, Choice 100): a module uses only modules
/// of the layers below its own (or its own top-level module); two top-level modules of one
/// layer (`board`, `studies`) do not use each other. Every top-level module has a layer.
#[test]
fn host_sim_modules_use_only_the_layers_below() {
    let layers = host_sim_layers();
    assert!(
        layers.len() >= 8,
        "the layer table of host-sim/src/lib.rs: {layers:?}"
    );
    let crates = source::crates(&root()).expect("the workspace's crates");
    let host_sim = crates
        .iter()
        .find(|c| c.name == "host-sim")
        .expect("host-sim's lib");
    let top = |m: &str| m.split("::").next().unwrap_or("").to_string();
    let layer = |m: &str| {
        layers
            .iter()
            .find(|(name, _)| *name == top(m))
            .map(|(_, l)| *l)
    };
    let mut offenders = Vec::new();
    for (module, imports) in host_sim.graph() {
        if module.is_empty() {
            continue; // the crate root declares every module
        }
        let Some(own) = layer(module) else {
            offenders.push(format!(
                "{module}: its top-level module has no layer in lib.rs"
            ));
            continue;
        };
        for used in imports
            .iter()
            .filter(|d| !d.is_empty() && top(d) != top(module))
        {
            match layer(used) {
                Some(l) if l < own => {}
                Some(l) => {
                    offenders.push(format!("{module} (layer {own}) uses {used} (layer {l})"))
                }
                None => offenders.push(format!("{module} uses {used}, which has no layer")),
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "host-sim's layering (host-sim/src/lib.rs):\n  {}",
        offenders.join("\n  ")
    );
}
