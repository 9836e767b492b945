//! The workspace's source rules (xtask/src/source/, docs/ci.md#the-source-rules): no function outside
//! test code over 80 lines without its reason written above it, and no two modules of a crate
//! that import each other.

use std::path::{Path, PathBuf};

use xtask::source::{self, modules, LONG_FN_LINES, LONG_MARKER};

/// Functions over the limit that may stay so without a reason, (file, function): none. A test
/// below fails when an entry is no longer an offender, so the list only shrinks (it held
/// host-sim's seven until issue 19's restructure).
const LONG_FNS_ALLOWED: &[(&str, &str)] = &[];

/// Import circles allowed, (crate, module, module): none (host-sim had four until issue 19).
const CIRCLES_ALLOWED: &[(&str, &str, &str)] = &[];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask/ is in the workspace root")
        .to_path_buf()
}

/// (file, function, line, lines) of every long function without a reason.
fn unexplained() -> Vec<(String, String, usize, usize)> {
    source::workspace_long_functions(&root())
        .expect("the workspace's sources")
        .into_iter()
        .filter(|(_, f)| f.reason.is_none())
        .map(|(file, f)| (file.display().to_string(), f.name, f.line, f.lines))
        .collect()
}

fn allowed_long(file: &str, name: &str) -> bool {
    LONG_FNS_ALLOWED.contains(&(file, name))
}

#[test]
fn no_function_is_long_without_its_reason() {
    let offenders: Vec<String> = unexplained()
        .into_iter()
        .filter(|(file, name, _, _)| !allowed_long(file, name))
        .map(|(file, name, line, lines)| format!("{file}:{line} fn {name}: {lines} lines"))
        .collect();
    assert!(
        offenders.is_empty(),
        "functions over {LONG_FN_LINES} lines without a `{LONG_MARKER} <reason>` comment directly above them (split them into named steps, or say why they are right long):\n  {}",
        offenders.join("\n  ")
    );
}

#[test]
fn the_long_function_allow_list_holds_only_offenders() {
    let now = unexplained();
    let stale: Vec<String> = LONG_FNS_ALLOWED
        .iter()
        .filter(|(file, name)| !now.iter().any(|(f, n, _, _)| f == file && n == name))
        .map(|(file, name)| format!("{file} fn {name}"))
        .collect();
    assert!(
        stale.is_empty(),
        "no longer long (or moved): remove from LONG_FNS_ALLOWED:\n  {}",
        stale.join("\n  ")
    );
}

/// (crate, module, module) of every import circle.
fn circles() -> Vec<(String, String, String)> {
    source::crates(&root())
        .expect("the workspace's crates")
        .iter()
        .flat_map(|c| {
            modules::import_circles(c)
                .into_iter()
                .map(|(a, b)| (c.name.clone(), a, b))
        })
        .collect()
}

#[test]
fn no_two_modules_of_a_crate_import_each_other() {
    let offenders: Vec<String> = circles()
        .into_iter()
        .filter(|(c, a, b)| !CIRCLES_ALLOWED.contains(&(c.as_str(), a.as_str(), b.as_str())))
        .map(|(c, a, b)| format!("{c}: {a} <-> {b}"))
        .collect();
    assert!(
        offenders.is_empty(),
        "modules that import each other (or each other's parent; move what both need into a module of its own):\n  {}",
        offenders.join("\n  ")
    );
}

#[test]
fn the_import_circle_allow_list_holds_only_circles() {
    let now = circles();
    let stale: Vec<String> = CIRCLES_ALLOWED
        .iter()
        .filter(|(c, a, b)| !now.iter().any(|(x, y, z)| x == c && y == a && z == b))
        .map(|(c, a, b)| format!("{c}: {a} <-> {b}"))
        .collect();
    assert!(
        stale.is_empty(),
        "no longer a circle: remove from CIRCLES_ALLOWED:\n  {}",
        stale.join("\n  ")
    );
}

#[test]
fn the_scan_sees_every_crate_and_its_modules() {
    // A scan that found no crate or no module would pass the rules above vacuously.
    let crates = source::crates(&root()).expect("the workspace's crates");
    let names: Vec<&str> = crates.iter().map(|c| c.name.as_str()).collect();
    for expected in [
        "controller-core",
        "auv-link",
        "firmware",
        "firmware bin qemu_selftest",
        "host-sim",
        "host-sim bin host-sim",
        "xtask",
        "xtask bin xtask",
        "xtask-loop bin xtask-loop",
    ] {
        assert!(names.contains(&expected), "{expected} not in {names:?}");
    }
    let core = crates.iter().find(|c| c.name == "controller-core").unwrap();
    let graph = core.graph();
    assert!(graph["controller"].contains("allocation"));
    assert!(graph.contains_key("trajectory::paths::circle"));
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
