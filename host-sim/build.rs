//! The git revision host-sim is built from, for the flight log's `version` metadata
//! (**Choice 380**, docs/logs.md#metadata): `HOST_SIM_GIT` as the build's environment gives it
//! (a build from a source archive), else `git describe --always --dirty --abbrev=12` of the
//! checkout, else `unknown` (no git, not a checkout). It never fails the build.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `git args` in this package's folder: its trimmed output, or `None` if git is absent, fails,
/// or says nothing.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(dir)
        .output()
        .ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    let text = text.trim();
    (out.status.success() && !text.is_empty()).then(|| text.to_string())
}

fn main() {
    println!("cargo:rerun-if-env-changed=HOST_SIM_GIT");
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let given = std::env::var("HOST_SIM_GIT")
        .ok()
        .filter(|g| !g.trim().is_empty());
    let revision = given
        .or_else(|| git(&dir, &["describe", "--always", "--dirty", "--abbrev=12"]))
        .unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=HOST_SIM_GIT={revision}");
    // Described again when HEAD moves (a checkout, a commit on the branch) or the package's
    // sources change (dirty or not); not on every index write, which would rebuild host-sim
    // on every `git add`.
    println!("cargo:rerun-if-changed=src");
    let at = |p: String| {
        let p = PathBuf::from(p);
        if p.is_absolute() {
            p
        } else {
            dir.join(p)
        }
    };
    // Only files that exist: cargo reruns a script whose watched file is missing every build.
    let watch = |p: PathBuf| {
        if p.is_file() {
            println!("cargo:rerun-if-changed={}", p.display());
        }
    };
    if let Some(git_dir) = git(&dir, &["rev-parse", "--git-dir"]).map(at) {
        watch(git_dir.join("HEAD"));
    }
    if let Some(common) = git(&dir, &["rev-parse", "--git-common-dir"]).map(at) {
        watch(common.join("packed-refs"));
        if let Some(head_ref) = git(&dir, &["symbolic-ref", "-q", "HEAD"]) {
            watch(common.join(head_ref));
        }
    }
}
