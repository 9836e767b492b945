//! `cargo xtask ci`: the one CI entry point (`.ci/run` and the README's test command call it),
//! in the manner of defmt's `xtask test-all`. [`STEPS`] runs in order; each prints its name and
//! time, every step runs even after one failed, and the end lists every failure (exit 1).
//!
//! The xtask is host Rust with no system library, so it builds on a fresh Debian machine
//! before the set-up: `rust-toolchain.toml` has rustup install the toolchain, and the first
//! step, `scripts/setup.sh` (shell, since it installs the toolchain's pieces and the Debian
//! packages), installs what the rest needs. The checks that fly host-sim against the boards
//! build after it, in their own package (`xtask/loop/`), since host-sim's plots link fontconfig.
//!
//! A new step is one more entry in [`STEPS`]: a cargo command, another command, or a function
//! of this crate that records its own failures.

use std::process::Command;

use firmware::image::TARGET;
use xtask::ci::Ci;

/// What a step runs.
pub enum Run {
    /// `program args…` in the workspace root.
    Command(&'static str, &'static [&'static str]),
    /// `cargo args…` in the workspace root (the cargo that runs the xtask).
    Cargo(&'static [&'static str]),
    /// A task of the xtask; it records its own failures.
    Task(fn(&mut Ci)),
}

/// One named step of the CI.
pub struct Step {
    pub name: &'static str,
    pub run: Run,
}

/// The CI, in order (docs/ci.md#one-entry-point, Choice 85).
pub const STEPS: &[Step] = &[
    Step {
        name: "set-up: toolchain pieces, Debian packages (fonts, QEMU 10), defmt-print",
        run: Run::Command("bash", &["scripts/setup.sh"]),
    },
    Step {
        name: "the link key the STM32 image is built with",
        run: Run::Task(link_key),
    },
    Step {
        name: "format",
        run: Run::Cargo(&["fmt", "--all", "--", "--check"]),
    },
    Step {
        name: "clippy: the workspace on the host",
        run: Run::Cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"]),
    },
    Step {
        name: "clippy: controller-core with micromath",
        run: Run::Cargo(&[
            "clippy",
            "-p",
            "controller-core",
            "--all-targets",
            "--features",
            "micromath",
            "--",
            "-D",
            "warnings",
        ]),
    },
    Step {
        name: "clippy: controller-core with libm",
        run: Run::Cargo(&[
            "clippy",
            "-p",
            "controller-core",
            "--all-targets",
            "--features",
            "libm-math",
            "--",
            "-D",
            "warnings",
        ]),
    },
    // Every firmware image (src/bin/) and the library with both boards, each math backend.
    Step {
        name: "clippy: the firmware on the target, both boards",
        run: Run::Cargo(&[
            "clippy",
            "-p",
            "firmware",
            "--release",
            "--target",
            TARGET,
            "--features",
            "qemu,stm32f405-emulator",
            "--lib",
            "--bins",
            "--",
            "-D",
            "warnings",
        ]),
    },
    Step {
        name: "clippy: the firmware on the target with micromath",
        run: Run::Cargo(&[
            "clippy",
            "-p",
            "firmware",
            "--release",
            "--target",
            TARGET,
            "--features",
            "qemu,micromath",
            "--lib",
            "--bins",
            "--",
            "-D",
            "warnings",
        ]),
    },
    Step {
        name: "host tests, kernels backend: controller-core, link, host-sim, closed loop, firmware logic, xtask (source rules)",
        run: Run::Cargo(&["test", "--workspace", "--profile", "host"]),
    },
    Step {
        name: "controller-core tests with micromath",
        run: Run::Cargo(&[
            "test",
            "-p",
            "controller-core",
            "--profile",
            "host",
            "--features",
            "micromath",
        ]),
    },
    Step {
        name: "controller-core tests with libm",
        run: Run::Cargo(&[
            "test",
            "-p",
            "controller-core",
            "--profile",
            "host",
            "--features",
            "libm-math",
        ]),
    },
    Step {
        name: "campaigns on a real Slurm: a one-node cluster on localhost runs deploy/slurm/campaign.sbatch (4 shards + the merge), merged = one machine byte for byte",
        run: Run::Command("bash", &["deploy/slurm/ci/run.sh", "target/host/host-sim"]),
    },
    Step {
        name: "controller-core cross-build",
        run: Run::Cargo(&["build", "-p", "controller-core", "--release", "--target", TARGET]),
    },
    Step {
        name: "controller-core cross-build with micromath",
        run: Run::Cargo(&[
            "build",
            "-p",
            "controller-core",
            "--release",
            "--target",
            TARGET,
            "--features",
            "micromath",
        ]),
    },
    Step {
        name: "firmware on the target: images, QEMU self-test, snapshots, failure injection, PIL and HIL",
        run: Run::Task(crate::firmware),
    },
    Step {
        name: "a second host-sim build is a no-op (the host profile CI builds; issue 18)",
        run: Run::Task(rebuild_noop),
    },
];

/// [`crate::rebuild::run`] with the host profile, which CI has built already (the release
/// profile's fat-LTO host-sim would cost minutes; the fingerprints are the same).
fn rebuild_noop(ci: &mut Ci) {
    crate::rebuild::run(ci, "host");
}

/// Runs every step of [`STEPS`].
pub fn ci(ci: &mut Ci) {
    for (i, step) in STEPS.iter().enumerate() {
        ci.timed(i + 1, STEPS.len(), step.name, |ci| run(ci, &step.run));
    }
}

fn run(ci: &mut Ci, what: &Run) {
    match *what {
        Run::Command(program, args) => {
            let mut cmd = Command::new(program);
            cmd.current_dir(&ci.root).args(args);
            status(ci, cmd, &format!("{program} {}", args.join(" ")));
        }
        Run::Cargo(args) => {
            let mut cmd = ci.cargo();
            cmd.args(args);
            status(ci, cmd, &format!("cargo {}", args.join(" ")));
        }
        Run::Task(task) => task(ci),
    }
}

/// Runs `cmd` with its output on the terminal; a failure if it does not succeed.
fn status(ci: &mut Ci, mut cmd: Command, shown: &str) {
    println!("{shown}");
    match cmd.status() {
        Ok(s) if s.success() => {}
        Ok(s) => ci.fail(format!("`{shown}` failed ({s}); its messages are above")),
        Err(e) => ci.fail(format!("`{shown}`: could not run it: {e}")),
    }
}

/// The STM32 image signs its link and does not build without a key (firmware/README.md,
/// "Link key"). `scripts/ci-link-key.sh` is the one place that says which key CI builds with
/// (the caller's `AUV150_LINK_KEY`; none with `AUV150_LINK_UNSIGNED=1`; else the PUBLIC CI test
/// key): this evaluates it and gives its `AUV150_LINK_KEY` to every later command, as sourcing
/// it does in a shell.
fn link_key(ci: &mut Ci) {
    const VAR: &str = firmware::LINK_KEY_VAR;
    let script = format!("source scripts/ci-link-key.sh && printf %s \"${{{VAR}-}}\"");
    let out = Command::new("bash")
        .args(["-c", &script])
        .current_dir(&ci.root)
        .output();
    match out {
        Ok(o) if o.status.success() => {
            let key = String::from_utf8_lossy(&o.stdout).into_owned();
            let given = std::env::var_os(VAR).is_some();
            if key.is_empty() {
                println!(
                    "no {VAR}: the STM32 image builds unsigned ({})",
                    firmware::LINK_UNSIGNED_VAR
                );
            } else if given {
                println!("{VAR}: the caller's key");
            } else {
                println!("{VAR}: the PUBLIC CI test key (firmware/ci-test-link-key.hex)");
                // Single-threaded here: no other thread reads the environment.
                std::env::set_var(VAR, key);
            }
        }
        Ok(o) => ci.fail(format!(
            "scripts/ci-link-key.sh failed ({}): {}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        )),
        Err(e) => ci.fail(format!("running scripts/ci-link-key.sh: {e}")),
    }
}
