//! Where the workspace is, how to call cargo, and the list of failures a run collects.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{Context, Result};

/// One CI run.
pub struct Ci {
    /// The workspace root (where `scripts/` and `firmware/snapshots/` are).
    pub root: PathBuf,
    /// Cargo's target directory (honours `CARGO_TARGET_DIR`).
    pub target_dir: PathBuf,
    /// Rewrite the snapshots instead of comparing.
    pub bless: bool,
    failures: Vec<String>,
}

#[derive(serde::Deserialize)]
struct Metadata {
    workspace_root: PathBuf,
    target_directory: PathBuf,
}

impl Ci {
    /// Finds the workspace through `cargo metadata`, so that the xtask works from any folder.
    pub fn new(bless: bool) -> Result<Self> {
        let out = Command::new(cargo())
            .args(["metadata", "--format-version", "1", "--no-deps"])
            .output()
            .context("running cargo metadata")?;
        anyhow::ensure!(
            out.status.success(),
            "cargo metadata failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let meta: Metadata =
            serde_json::from_slice(&out.stdout).context("reading cargo metadata's output")?;
        Ok(Ci {
            root: meta.workspace_root,
            target_dir: meta.target_directory,
            bless,
            failures: Vec::new(),
        })
    }

    /// Prints a step's title.
    pub fn step(&self, title: &str) {
        println!("\n== {title}");
    }

    /// Records (and prints at once) a failed check. `what` says what failed and how to fix or
    /// bless it.
    pub fn fail(&mut self, what: impl Into<String>) {
        let what = what.into();
        println!("FIRMWARE CI FAILURE: {what}");
        self.failures.push(what);
    }

    /// A `cargo` command in the workspace root (the same cargo that runs the xtask).
    pub fn cargo(&self) -> Command {
        let mut c = Command::new(cargo());
        c.current_dir(&self.root);
        c
    }

    /// A directory of the xtask's own files (logs, copies of ELFs, PIL outputs).
    pub fn scratch(&self) -> PathBuf {
        let dir = self.target_dir.join("xtask");
        // A failure here shows up as the first write into it.
        let _ = std::fs::create_dir_all(&dir);
        dir
    }

    /// `path` relative to the workspace root, for messages.
    pub fn rel<'a>(&self, path: &'a Path) -> std::path::Display<'a> {
        path.strip_prefix(&self.root).unwrap_or(path).display()
    }

    /// Prints the verdict; exit status 1 if anything failed.
    pub fn finish(self) -> ExitCode {
        if self.failures.is_empty() {
            println!("\nfirmware CI: passed");
            return ExitCode::SUCCESS;
        }
        let n = self.failures.len();
        let problems = if n == 1 { "problem" } else { "problems" };
        println!("\nfirmware CI: FAILED ({n} {problems})");
        for f in &self.failures {
            println!("  - {f}");
        }
        ExitCode::from(1)
    }
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}
