//! The xtask's in-the-loop checks: host-sim flies the QEMU images, processor in the loop over
//! a socket (`processor_in_loop.rs`) and hardware in the loop over QEMU's pty
//! (`hardware_in_loop.rs`). `cargo xtask pil` and `cargo xtask firmware` start this with the
//! ELFs they built (xtask/src/in_the_loop.rs). It is its own package because it builds on
//! host-sim, whose plots link fontconfig, while the xtask must build on a fresh machine before
//! the set-up installs it.
//!
//! ```text
//! xtask-loop --qemu ELF [--emulator ELF]
//! ```

mod hardware_in_loop;
mod processor_in_loop;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use xtask::ci::Ci;

use crate::hardware_in_loop::Board;
use crate::processor_in_loop::CI_TEST_KEY;

#[derive(Parser)]
#[command(
    about = "AUV-150 firmware CI: processor and hardware in the loop (started by cargo xtask)"
)]
struct Args {
    /// The QEMU flying image (firmware-qemu): PIL, and HIL unsigned.
    #[arg(long)]
    qemu: PathBuf,
    /// The STM32 board code's emulator image (firmware-stm32f405-emulator): HIL signed.
    #[arg(long)]
    emulator: Option<PathBuf>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let mut ci = match Ci::new("in-the-loop checks", false) {
        Ok(ci) => ci,
        Err(e) => {
            eprintln!("xtask-loop: {e:#}");
            return ExitCode::from(2);
        }
    };
    let Some(host_sim) = processor_in_loop::build_host_sim(&mut ci) else {
        return ci.finish();
    };
    processor_in_loop::checks(&mut ci, &host_sim, &args.qemu);
    let key = ci.root.join(CI_TEST_KEY);
    let mut boards = vec![Board {
        name: "qemu",
        elf: &args.qemu,
        key_file: None,
    }];
    if let Some(emulator) = &args.emulator {
        boards.push(Board {
            name: "stm32-emulator",
            elf: emulator,
            key_file: Some(&key),
        });
    }
    hardware_in_loop::checks(&mut ci, &host_sim, &boards);
    ci.finish()
}
