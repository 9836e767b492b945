//! `host-sim pil`: processor in the loop, the firmware in QEMU.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::board_loop::{
    fly, link_key, loop_scenarios, not_started, workspace_root, LoopArgs, Started,
};
use super::Exit;
use crate::board::image::{check_flying_image, default_elf};
use crate::board::{BoardInTheLoop, Mode};
use crate::output::{atomic, OutputDir};
use crate::scenario::Scenario;

/// `pil`: processor in the loop. The firmware ELF in QEMU flies the simulated vehicle over a
/// loopback socket, lock-stepped; compared with SIL. Link faults by tick range (A..B).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct PilArgs {
    #[command(flatten)]
    pub common: LoopArgs,
    #[arg(long, default_value = "runs/pil")]
    pub out: PathBuf,
    /// Firmware ELF: a flying image that runs in QEMU, `firmware-qemu` or
    /// `firmware-stm32f405-emulator` [default: target/thumbv7em-none-eabihf/release/firmware-qemu].
    #[arg(long)]
    pub elf: Option<PathBuf>,
}

/// `pil`. Exits 1 if a run diverged or lost its board, or if a run without link faults differs
/// from SIL by more than [`PIL_SIL_TOLERANCE`](crate::board::PIL_SIL_TOLERANCE).
pub fn pil(args: &PilArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let scenarios = loop_scenarios(&args.common)?;
    let root = workspace_root();
    let elf = args.elf.clone().unwrap_or_else(|| default_elf(&root));
    check_flying_image(&elf)?;
    let runner = root.join(firmware_images::qemu_runner::SCRIPT);
    let key = link_key(&args.common)?;
    let dir = OutputDir::prepare(&args.out)?;
    fly(
        &args.common,
        &scenarios,
        &dir,
        Mode::Pil,
        stdout,
        |s: &Scenario, dir: &OutputDir| {
            let cfg = s.config();
            let log_path = dir.claim(&format!("{}-qemu.log", cfg.name))?;
            let (log, log_file) = atomic::Pending::create(&log_path)
                .with_context(|| format!("writing {}", log_path.display()))?;
            match BoardInTheLoop::start(
                &elf,
                &runner,
                s,
                cfg.link_faults.clone(),
                log_file,
                &log_path,
                key.as_ref(),
            ) {
                Ok(board) => Ok(Some(Started {
                    board,
                    log: Some((log, log_path)),
                })),
                Err(e) => {
                    // Keep QEMU's log: it says why.
                    let _ = log.commit();
                    not_started(&cfg.name, e)
                }
            }
        },
    )
}
