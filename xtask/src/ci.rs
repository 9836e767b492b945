//! One CI run's bookkeeping: where the workspace is, how to call cargo, the steps' titles and
//! times, and the failures the run collects (every check runs even after one failed; the end
//! lists them all and the exit status is 1).

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

/// The workspace's host test profile (`[profile.host]` in Cargo.toml): the xtask's own
/// binaries and the `host-sim` the in-the-loop checks run are built with it.
pub const HOST_PROFILE: &str = "host";

/// How a failure's line starts when it is recorded: a run that starts another xtask binary
/// ([`Ci::run_collecting`]) takes the child's failures into its own list by it.
pub const FAILURE: &str = "CI FAILURE: ";

/// One CI run.
pub struct Ci {
    /// What the run is, for its verdict ("firmware CI", "CI").
    title: &'static str,
    /// The workspace root (where `scripts/` and `firmware/snapshots/` are).
    pub root: PathBuf,
    /// Cargo's target directory (honours `CARGO_TARGET_DIR`).
    pub target_dir: PathBuf,
    /// Rewrite the snapshots instead of comparing.
    pub bless: bool,
    failures: Vec<String>,
    /// Each top-level step ([`Ci::timed`]): name, time, whether it added no failure.
    times: Vec<(String, Duration, bool)>,
}

#[derive(serde::Deserialize)]
struct Metadata {
    workspace_root: PathBuf,
    target_directory: PathBuf,
}

impl Ci {
    /// Finds the workspace through `cargo metadata`, so that the xtask works from any folder.
    pub fn new(title: &'static str, bless: bool) -> Result<Self> {
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
            title,
            root: meta.workspace_root,
            target_dir: meta.target_directory,
            bless,
            failures: Vec::new(),
            times: Vec::new(),
        })
    }

    /// Prints a step's title.
    pub fn step(&self, title: &str) {
        println!("\n== {title}");
    }

    /// Runs `f` as the top-level step `name`: prints its name, then its time and whether it
    /// added a failure; [`Ci::finish`] lists every step's time.
    pub fn timed(&mut self, index: usize, of: usize, name: &str, f: impl FnOnce(&mut Ci)) {
        println!("\n=== [{index}/{of}] {name}");
        let before = self.failures.len();
        let start = Instant::now();
        f(self);
        let took = start.elapsed();
        let ok = self.failures.len() == before;
        println!(
            "=== {name}: {} in {:.1} s",
            if ok { "ok" } else { "FAILED" },
            took.as_secs_f64()
        );
        self.times.push((name.to_string(), took, ok));
    }

    /// Records (and prints at once) a failed check. `what` says what failed and how to fix or
    /// bless it.
    pub fn fail(&mut self, what: impl Into<String>) {
        let what = what.into();
        println!("{FAILURE}{what}");
        self.failures.push(what);
    }

    /// A `cargo` command in the workspace root (the same cargo that runs the xtask).
    pub fn cargo(&self) -> Command {
        let mut c = Command::new(cargo());
        c.current_dir(&self.root);
        c
    }

    /// Runs `cmd` (`shown` in messages), printing its output as it comes, and records a
    /// failure if it does not succeed. Lines of its output that start with [`FAILURE`] (another
    /// xtask binary's failures) become this run's failures, so the final list has them all.
    pub fn run_collecting(&mut self, mut cmd: Command, shown: &str) {
        println!("{shown}");
        let child = cmd.stdout(Stdio::piped()).spawn();
        let mut child = match child {
            Ok(c) => c,
            Err(e) => {
                self.fail(format!("{shown}: could not start it: {e}"));
                return;
            }
        };
        let mut collected = 0;
        if let Some(out) = child.stdout.take() {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { break };
                println!("{line}");
                if let Some(what) = line.strip_prefix(FAILURE) {
                    self.failures.push(what.to_string());
                    collected += 1;
                }
            }
        }
        match child.wait() {
            Ok(s) if s.success() => {}
            Ok(s) if collected > 0 => {
                println!("{shown}: {s}, with the {collected} failures above");
            }
            Ok(s) => self.fail(format!("{shown} failed ({s}); its messages are above")),
            Err(e) => self.fail(format!("{shown}: {e}")),
        }
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

    /// Prints the steps' times and the verdict; exit status 1 if anything failed.
    pub fn finish(self) -> ExitCode {
        if !self.times.is_empty() {
            println!("\n{}: steps", self.title);
            for (name, took, ok) in &self.times {
                let verdict = if *ok { "ok" } else { "FAILED" };
                println!("  {verdict:6} {:7.1} s  {name}", took.as_secs_f64());
            }
        }
        if self.failures.is_empty() {
            println!("\n{}: passed", self.title);
            return ExitCode::SUCCESS;
        }
        let n = self.failures.len();
        let problems = if n == 1 { "problem" } else { "problems" };
        println!("\n{}: FAILED ({n} {problems})", self.title);
        for f in &self.failures {
            println!("  - {f}");
        }
        ExitCode::from(1)
    }
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}
