//! The workspace's CI as code, in the manner of defmt's and RTIC's xtasks (`cargo xtask …`; the
//! alias is in `.cargo/config.toml`). `.ci/run` and the README's test command run
//! `cargo xtask ci`.
//!
//! ```text
//! cargo xtask ci                   the CI: set-up, link key, fmt, clippy, host tests with the
//!                                  three math backends, cross-builds, then `firmware` below
//!                                  (src/steps.rs lists the steps)
//! cargo xtask firmware [--bless]   everything below, in this order
//! cargo xtask images   [--bless]   build every image; its marker, memory map, flash and RAM
//!                                  against the budgets and firmware/snapshots/sizes.txt; the
//!                                  soft-float f64 routines reachable from Controller::update
//!                                  in its call graph (xtask/src/no_f64.rs)
//! cargo xtask selftest [--bless]   the QEMU self-test with each math backend against
//!                                  firmware/snapshots/selftest-<backend>.log, each stage's
//!                                  instructions against firmware/src/budget.rs, and the failure
//!                                  injection (a wrong answer, a panic, a HardFault, a hang)
//! cargo xtask pil                  processor in the loop: a short mission must equal SIL bit
//!                                  for bit; the link-fault case must enter and leave fail-safe
//!                                  at its exact ticks; hardware in the loop over QEMU's pty:
//!                                  lock-step equals SIL, real-time figures, the port going away
//!                                  mid-mission (the package xtask/loop/, xtask-loop)
//! cargo xtask rebuild-noop         a second `cargo build --release -p host-sim` rebuilds
//!   [--profile P]                  nothing, with the link key's variable changed
//!                                  (xtask/src/rebuild.rs)
//! ```
//!
//! `--bless` rewrites the snapshots from this run instead of comparing (review the diff, then
//! commit it). Every check runs even after one failed; the end lists each failure with what to
//! do about it, and the exit status is 1.
//!
//! QEMU runs through `scripts/qemu-run.sh` (the cargo runner, kept in shell with
//! `scripts/setup.sh`); everything else is here. The images, their features and ELF names come
//! from `firmware::image`, the runner's variables from `firmware::qemu_runner`.

mod callgraph;
mod images;
mod in_the_loop;
mod no_f64;
mod qemu_run;
mod rebuild;
mod selftest;
mod snapshot;
mod steps;
mod thumb;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use xtask::ci::Ci;

use crate::images::Variant;

#[derive(Parser)]
#[command(
    about = "AUV-150 CI: the whole CI, or the firmware's images, QEMU self-test, snapshots, PIL"
)]
struct Cli {
    #[command(subcommand)]
    command: Task,
}

#[derive(Subcommand)]
enum Task {
    /// The whole CI, step by step (set-up, lints, every test, the firmware's checks).
    Ci,
    /// Every firmware check: images, self-test, failure injection, PIL and HIL.
    Firmware {
        /// Rewrite firmware/snapshots/ from this run instead of comparing.
        #[arg(long)]
        bless: bool,
    },
    /// Build every image; check its marker, memory map, flash and RAM, and report the f64
    /// routines reachable from `update`.
    Images {
        /// Rewrite firmware/snapshots/sizes.txt from this run instead of comparing.
        #[arg(long)]
        bless: bool,
    },
    /// Run the QEMU self-test (each math backend) and the failure injection.
    Selftest {
        /// Rewrite firmware/snapshots/selftest-*.log from this run instead of comparing.
        #[arg(long)]
        bless: bool,
    },
    /// Processor in the loop: PIL = SIL, and the link-fault case; HIL over QEMU's pty.
    Pil,
    /// Build host-sim twice: the second build must rebuild nothing (no compile, no build
    /// script, no link), with the link key's variable changed in between.
    RebuildNoop {
        /// The cargo profile to build with.
        #[arg(long, default_value = rebuild::README_PROFILE)]
        profile: String,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let (title, bless) = match cli.command {
        Task::Ci => ("CI", false),
        Task::Firmware { bless } | Task::Images { bless } | Task::Selftest { bless } => {
            ("firmware CI", bless)
        }
        Task::Pil => ("firmware CI", false),
        Task::RebuildNoop { .. } => ("rebuild check", false),
    };
    let mut ci = match Ci::new(title, bless) {
        Ok(ci) => ci,
        Err(e) => {
            eprintln!("xtask: {e:#}");
            return ExitCode::from(2);
        }
    };
    match cli.command {
        Task::Ci => steps::ci(&mut ci),
        Task::Firmware { .. } => firmware(&mut ci),
        Task::Images { .. } => {
            let built = images::build(&mut ci, &Variant::ALL);
            images::check(&mut ci, &built);
            no_f64::run(&mut ci, &built);
        }
        Task::Selftest { .. } => {
            let built = images::build(&mut ci, &Variant::SELFTEST);
            selftest::run(&mut ci, &built);
        }
        Task::Pil => {
            let built = images::build(&mut ci, &[Variant::QEMU, Variant::EMULATOR]);
            in_the_loop::run(&mut ci, &built);
        }
        Task::RebuildNoop { profile } => rebuild::run(&mut ci, &profile),
    }
    ci.finish()
}

/// Every firmware check (`cargo xtask firmware`, and the CI's last step).
fn firmware(ci: &mut Ci) {
    let built = images::build(ci, &Variant::ALL);
    images::check(ci, &built);
    no_f64::run(ci, &built);
    selftest::run(ci, &built);
    in_the_loop::run(ci, &built);
}
