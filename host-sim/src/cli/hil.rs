//! `host-sim hil`: hardware in the loop, the board on a serial port.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use controller_core::readable::Readable;

use super::board_loop::{fly, link_key, loop_scenarios, not_started, LoopArgs, Started};
use super::Exit;
use crate::board::{BoardInTheLoop, Mode, Pacing};
use crate::output::OutputDir;
use crate::scenario::Scenario;

/// The STM32 board's link baud rate (`firmware_images::LINK_BAUD`), `hil`'s default.
pub const DEFAULT_HIL_BAUD: u32 = firmware_images::LINK_BAUD;

/// `hil`'s default reply timeout (s): a board answers every period (10 ms at 100 Hz).
pub const DEFAULT_HIL_REPLY_TIMEOUT: f64 = 5.0;

/// `hil`: hardware in the loop. The board on a serial port (a USB-serial adapter, or QEMU's
/// `-serial pty`) flies the simulated vehicle; compared with SIL. Link faults as `pil`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct HilArgs {
    /// The serial device of the board's link (e.g. /dev/ttyUSB0, or QEMU's /dev/pts/N).
    #[arg(long)]
    pub port: String,
    /// Baud rate (8N1, no flow control); the default is the STM32 board's.
    #[arg(long, default_value_t = DEFAULT_HIL_BAUD)]
    pub baud: u32,
    /// lockstep: the board runs a period per state frame (as PIL; equals SIL); realtime: the
    /// board runs on its own timer and the host flies the plant in wall-clock time.
    #[arg(long, value_enum, default_value_t = Pacing::Lockstep)]
    pub pacing: Pacing,
    /// Seconds without valid telemetry after which the run stops (a silent or garbled link).
    #[arg(long, default_value_t = DEFAULT_HIL_REPLY_TIMEOUT)]
    pub reply_timeout: f64,
    #[command(flatten)]
    pub common: LoopArgs,
    #[arg(long, default_value = "runs/hil")]
    pub out: PathBuf,
}

/// `hil`. Exits 1 if a run diverged or lost its board, or if a lock-step run without link
/// faults differs from SIL by more than [`PIL_SIL_TOLERANCE`](crate::board::PIL_SIL_TOLERANCE);
/// 2 if the port cannot be opened or the board never answers the set-up.
pub fn hil(args: &HilArgs, stdout: &mut dyn Write) -> Result<Exit> {
    if !(args.reply_timeout.is_finite() && args.reply_timeout > 0.0 && args.reply_timeout <= 3600.0)
    {
        bail!(
            "--reply-timeout must be a time in (0, 3600] s, got {}",
            Readable(args.reply_timeout)
        );
    }
    if args.baud == 0 {
        bail!("--baud must be a positive baud rate");
    }
    let scenarios = loop_scenarios(&args.common)?;
    let key = link_key(&args.common)?;
    let dir = OutputDir::prepare(&args.out)?;
    let timeout = std::time::Duration::from_secs_f64(args.reply_timeout);
    fly(
        &args.common,
        &scenarios,
        &dir,
        Mode::Hil,
        stdout,
        |s: &Scenario, _: &OutputDir| {
            let cfg = s.config();
            BoardInTheLoop::over_serial(
                &args.port,
                args.baud,
                s,
                cfg.link_faults.clone(),
                args.pacing,
                timeout,
                key.as_ref(),
            )
            .map_or_else(
                |e| not_started(&cfg.name, e),
                |board| Ok(Some(Started { board, log: None })),
            )
        },
    )
}
