//! The crates of the repository as Cargo finds them: every package (the workspace's members
//! and any package outside the workspace, such as `fuzz/`) and each of its targets (library,
//! binaries, examples, benchmarks, integration tests, build script), declared in its
//! `Cargo.toml` or found where Cargo looks for them (`src/main.rs`, `src/bin/`, `examples/`,
//! `benches/`, `tests/`, `build.rs`).

use std::path::{Path, PathBuf};

/// What a target is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    Lib,
    Bin,
    Example,
    Bench,
    /// An integration test (`tests/NAME.rs`): test code, which the source rules leave out.
    Test,
    /// A fuzz target (a binary of a package with `[package.metadata] cargo-fuzz = true`):
    /// test code too; it includes the integration tests' shared helpers as its own modules.
    Fuzz,
    /// The build script.
    Build,
}

impl Kind {
    /// Integration tests and fuzz targets: test code, which the rules leave out.
    pub fn is_test_code(self) -> bool {
        matches!(self, Kind::Test | Kind::Fuzz)
    }
}

/// One target: its package, kind, name and root file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Target {
    pub package: String,
    pub kind: Kind,
    pub name: String,
    pub root: PathBuf,
}

impl Target {
    /// How the rules name the crate: the package for its library, `host-sim bin host-sim`,
    /// `controller-core example track`, `firmware build`.
    pub fn crate_name(&self) -> String {
        let kind = match self.kind {
            Kind::Lib => return self.package.clone(),
            Kind::Build => return format!("{} build", self.package),
            Kind::Bin => "bin",
            Kind::Example => "example",
            Kind::Bench => "bench",
            Kind::Test => "test",
            Kind::Fuzz => "fuzz",
        };
        format!("{} {kind} {}", self.package, self.name)
    }
}

/// Every package under `root` (a directory holding a `Cargo.toml` with a `[package]`), as
/// (name, directory, manifest), sorted by directory. Directories named `target` or starting
/// with a dot are not searched.
pub fn packages(root: &Path) -> Result<Vec<(String, PathBuf, toml::Table)>, String> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let manifest = dir.join("Cargo.toml");
        if manifest.is_file() {
            let text = std::fs::read_to_string(&manifest)
                .map_err(|e| format!("{}: {e}", manifest.display()))?;
            let table: toml::Table = text
                .parse()
                .map_err(|e| format!("{}: {e}", manifest.display()))?;
            if let Some(package) = table.get("package") {
                let name = package
                    .get("name")
                    .and_then(|n| n.as_str())
                    .ok_or_else(|| format!("{}: no package name", manifest.display()))?;
                out.push((name.to_string(), dir.clone(), table));
            }
        }
        for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if e.path().is_dir() && name != "target" && !name.starts_with('.') {
                stack.push(e.path());
            }
        }
    }
    out.sort_by(|a, b| a.1.cmp(&b.1));
    Ok(out)
}

/// Every target of the package `name` in `dir` with manifest `manifest`, as Cargo finds
/// them: declared targets first, then the ones found in Cargo's places whose file no declared
/// target took (unless `autobins = false` etc.).
pub fn targets(name: &str, dir: &Path, manifest: &toml::Table) -> Vec<Target> {
    let package = manifest.get("package").and_then(|p| p.as_table());
    let target = |kind, target_name: &str, root: PathBuf| Target {
        package: name.to_string(),
        kind,
        name: target_name.to_string(),
        root,
    };
    let mut out = Vec::new();
    let lib_path = manifest
        .get("lib")
        .and_then(|l| l.get("path"))
        .and_then(|p| p.as_str())
        .map(|p| dir.join(p))
        .unwrap_or_else(|| dir.join("src/lib.rs"));
    if lib_path.is_file() {
        out.push(target(Kind::Lib, name, lib_path));
    }
    for (kind, key, auto, place) in [
        (Kind::Bin, "bin", "autobins", "src/bin"),
        (Kind::Example, "example", "autoexamples", "examples"),
        (Kind::Bench, "bench", "autobenches", "benches"),
        (Kind::Test, "test", "autotests", "tests"),
    ] {
        let mut found: Vec<(String, PathBuf)> = Vec::new();
        for t in manifest
            .get(key)
            .and_then(|t| t.as_array())
            .into_iter()
            .flatten()
        {
            let Some(n) = t.get("name").and_then(|n| n.as_str()) else {
                continue;
            };
            let path = match t.get("path").and_then(|p| p.as_str()) {
                Some(p) => dir.join(p),
                None => default_path(dir, place, kind, n, name),
            };
            found.push((n.to_string(), path));
        }
        let automatic = package
            .and_then(|p| p.get(auto))
            .and_then(|a| a.as_bool())
            .unwrap_or(true);
        if automatic {
            for (n, path) in in_place(dir, place, kind, name) {
                if !found.iter().any(|(_, p)| *p == path) {
                    found.push((n, path));
                }
            }
        }
        let fuzz = package
            .and_then(|p| p.get("metadata"))
            .and_then(|m| m.get("cargo-fuzz"))
            .and_then(|f| f.as_bool())
            .unwrap_or(false);
        let kind = if fuzz && kind == Kind::Bin {
            Kind::Fuzz
        } else {
            kind
        };
        out.extend(
            found
                .into_iter()
                .filter(|(_, p)| p.is_file())
                .map(|(n, p)| target(kind, &n, p)),
        );
    }
    let build = match package.and_then(|p| p.get("build")) {
        Some(toml::Value::String(p)) => Some(dir.join(p)),
        Some(toml::Value::Boolean(false)) => None,
        _ => Some(dir.join("build.rs")),
    };
    if let Some(b) = build.filter(|b| b.is_file()) {
        out.push(target(Kind::Build, "build", b));
    }
    out
}

/// Where Cargo looks for a declared target without a `path`.
fn default_path(dir: &Path, place: &str, kind: Kind, name: &str, package: &str) -> PathBuf {
    if kind == Kind::Bin && name == package && dir.join("src/main.rs").is_file() {
        return dir.join("src/main.rs");
    }
    let flat = dir.join(place).join(format!("{name}.rs"));
    if flat.is_file() {
        flat
    } else {
        dir.join(place).join(name).join("main.rs")
    }
}

/// The targets of one kind Cargo finds by itself: `place/NAME.rs`, `place/NAME/main.rs`, and
/// for binaries `src/main.rs` (named after the package).
fn in_place(dir: &Path, place: &str, kind: Kind, package: &str) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    if kind == Kind::Bin && dir.join("src/main.rs").is_file() {
        out.push((package.to_string(), dir.join("src/main.rs")));
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir.join(place))
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .collect();
    entries.sort();
    for p in entries {
        let stem = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if p.extension().is_some_and(|x| x == "rs") && p.is_file() {
            out.push((stem, p));
        } else if p.join("main.rs").is_file() {
            out.push((stem, p.join("main.rs")));
        }
    }
    out
}
