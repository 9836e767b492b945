//! The firmware's CI as code, in the manner of defmt's and RTIC's xtasks (`cargo xtask …`; the
//! alias is in `.cargo/config.toml`). `scripts/test-all.sh` runs `cargo xtask firmware`.
//!
//! ```text
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
//!                                  at its exact ticks; hardware in the loop over QEMU's pty
//!                                  (xtask/src/hil.rs): lock-step equals SIL, real-time
//!                                  figures, the port going away mid-mission
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
//! from `firmware::image`.

mod callgraph;
mod ci;
mod hil;
mod images;
mod no_f64;
mod pil;
mod qemu;
mod rebuild;
mod selftest;
mod snapshot;
mod thumb;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::ci::Ci;
use crate::images::Variant;

#[derive(Parser)]
#[command(about = "AUV-150 firmware CI: images, QEMU self-test, snapshots, PIL")]
struct Cli {
    #[command(subcommand)]
    command: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Every firmware check: images, self-test, failure injection, PIL.
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
    /// Run the QEMU self-test (both math backends) and the failure injection.
    Selftest {
        /// Rewrite firmware/snapshots/selftest-*.log from this run instead of comparing.
        #[arg(long)]
        bless: bool,
    },
    /// Processor in the loop: PIL = SIL, and the link-fault case; HIL over QEMU's pty.
    Pil,
    /// Build host-sim twice: the second build must rebuild nothing (no compile, no build
    /// script, no link), with the link key's environment variable changed in between.
    RebuildNoop {
        /// The cargo profile (the README's commands use release).
        #[arg(long, default_value = rebuild::README_PROFILE)]
        profile: String,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let bless = match cli.command {
        Task::Firmware { bless } | Task::Images { bless } | Task::Selftest { bless } => bless,
        Task::Pil | Task::RebuildNoop { .. } => false,
    };
    let mut ci = match Ci::new(bless) {
        Ok(ci) => ci,
        Err(e) => {
            eprintln!("xtask: {e:#}");
            return ExitCode::from(2);
        }
    };
    match cli.command {
        Task::Firmware { .. } => {
            let built = images::build(&mut ci, &Variant::ALL);
            images::check(&mut ci, &built);
            no_f64::run(&mut ci, &built);
            selftest::run(&mut ci, &built);
            pil::run(&mut ci, &built);
        }
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
            pil::run(&mut ci, &built);
        }
        Task::RebuildNoop { profile } => rebuild::run(&mut ci, &profile),
    }
    ci.finish()
}
