//! How a board in the loop fails: [`Error`], one variant per thing the operator does something
//! different about. The messages are the runner's words to the operator (what came, what to
//! check); tests match the variants. A run that fails mid-mission ends
//! [`Outcome::LostBoard`](crate::sim::Outcome::LostBoard) through [`Stop`] (an interrupt ends
//! it [`Outcome::Interrupted`](crate::sim::Outcome::Interrupted)).
//!
//! **Choice 201**: the messages carry what they name (an I/O error's text included), so no
//! variant has an error `source`: an `anyhow` chain printed with `{:#}` says each thing once.

use std::io;
use std::path::PathBuf;
use std::process::ExitStatus;
use std::time::Duration;

use auv_link::sign::AuthError;
use auv_link::{BoardStatus, LinkError, Refusal, ThrustUnit};
use firmware_images::image::{Image, TARGET};
use firmware_images::LINK_BAUD;

use crate::sim::{BoardLoss, Stop};

/// A board in the loop failed: before the run (its image, its emulator, its port, the set-up)
/// or during it (its link, what it reports).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    // The image.
    /// The firmware ELF cannot be read.
    #[error("firmware ELF {}: {io}; build it with `cargo build -p firmware --release --target {} --features qemu --bin {}`", path.display(), TARGET, Image::Qemu.bin())]
    ElfUnreadable { path: PathBuf, io: io::Error },
    /// The ELF is another of the workspace's images (the self-test, the STM32 flight image).
    #[error("{} is the `{}` image, not a flying image that runs in QEMU (`{}`) as the board in the loop (see --elf)", path.display(), image.bin(), flying_images())]
    NotFlyingImage { path: PathBuf, image: Image },
    /// The ELF carries no image marker: not one of the workspace's images.
    #[error("{} is not an AUV-150 firmware image (no image marker; built before the images were binaries?); the board in the loop is `{}`", path.display(), flying_images())]
    NoImageMarker { path: PathBuf },

    // QEMU.
    /// QEMU could not be started through its runner script.
    #[error("starting QEMU through {}: {io}", runner.display())]
    QemuStart { runner: PathBuf, io: io::Error },
    /// QEMU's log could not be created.
    #[error("creating {}: {io}", path.display())]
    QemuLog { path: PathBuf, io: io::Error },
    /// A step of starting QEMU failed (`op` says which: its log, the loopback socket to its
    /// UART).
    #[error("{op}: {io}")]
    QemuIo { op: &'static str, io: io::Error },
    /// QEMU did not connect its UART to the loopback socket in time.
    #[error("QEMU did not connect its UART within {} s (see {})", waited.as_secs(), log.display())]
    QemuNoUart { waited: Duration, log: PathBuf },
    /// QEMU did not name its pseudo-terminal in time.
    #[error("QEMU did not name its pty within {} s (see {})", waited.as_secs(), log.display())]
    QemuNoPty { waited: Duration, log: PathBuf },
    /// QEMU ended before naming its pseudo-terminal.
    #[error("QEMU ended ({status}) before naming its pty (see {})", log.display())]
    QemuEnded { status: ExitStatus, log: PathBuf },

    // The serial port.
    /// The serial device does not exist.
    #[error("serial port {path} does not exist: is the USB-serial adapter plugged in (see `ls /dev/ttyUSB* /dev/ttyACM*`), or, for QEMU, is the path its `char device redirected to` line printed?")]
    NoPort { path: String },
    /// The serial device exists but cannot be opened (busy, no permission, not a tty).
    #[error("cannot open serial port {path} at {baud} baud: {error}")]
    PortOpen {
        path: String,
        baud: u32,
        error: serialport::Error,
    },

    // The link.
    /// No valid telemetry for the reply timeout, and no byte at all (**Choice 64**).
    #[error("no telemetry from the board for {:.1} s: it sent nothing ({context}); is it powered, flashed with its flying image and wired (its TX to this end's RX, a common ground), and is this the right port?", waited.as_secs_f64())]
    Silent { waited: Duration, context: String },
    /// No valid telemetry for the reply timeout, but bytes and frames that did not decode.
    #[error("no valid telemetry from the board for {:.1} s: {bytes} bytes came, and {refused} frames that did not decode ({context}); a wrong baud rate (--baud; the STM32 board's is {}), a wrong or missing link key (--link-key-file), or another device on this port", waited.as_secs_f64(), LINK_BAUD)]
    Noise {
        waited: Duration,
        bytes: u64,
        refused: u64,
        context: String,
    },
    /// The two ends disagree on signing: the board signs and this end does not
    /// ([`AuthError::SigningOff`]), or the other way round ([`AuthError::Unsigned`]).
    #[error("the board's telemetry is {} but this end has signing {}: {error}; give the board and host-sim the same key (--link-key-file), or neither", if *error == AuthError::SigningOff { "signed" } else { "unsigned" }, if *error == AuthError::SigningOff { "off" } else { "on" })]
    Signing { error: AuthError },
    /// The link closed, or its port went away (a tty's EIO, end of stream, a reset).
    #[error("the board's link went away ({io}): the port was unplugged, the board lost power, or its emulator ended ({context})")]
    LinkGone { io: io::Error, context: String },
    /// Another I/O error on the link (`op`: `"read"`, `"write"`, `"set-up"`).
    #[error("board link {op} failed: {io} ({context})")]
    LinkIo {
        op: &'static str,
        io: io::Error,
        context: String,
    },
    /// A frame could not be encoded.
    #[error("encoding: {0}")]
    Encode(LinkError),

    // The set-up, and what the board reports.
    /// The scenario's thruster geometry is not one the link carries.
    #[error("the board's link carries the thruster geometry as the AUV-150 layout with some thrusters reversed; this scenario's geometry is another one, which PIL cannot fly")]
    Geometry,
    /// The board refused a command of the set-up, with its reason.
    #[error("the board refused the set-up: {}", reason.map_or("(no reason)", Refusal::as_str))]
    Refused { reason: Option<Refusal> },
    /// The board did not verify the mission upload in the rounds allowed.
    #[error("the board did not verify the mission upload (CRC {crc:#010x}, {chunks} chunks) in {rounds} rounds{}", last_refusal.map_or(String::new(), |r| format!("; its last refusal: {}", r.as_str())))]
    UploadNotVerified {
        crc: u32,
        chunks: u8,
        rounds: u32,
        last_refusal: Option<Refusal>,
    },
    /// The board did not report itself armed in time.
    #[error("board did not arm (status {status:?})")]
    NotArmed { status: BoardStatus },
    /// The board flies another thruster mounting than the scenario's.
    #[error("the board flies thruster mounting {board:#07b}, not the scenario's {scenario:#07b}")]
    Mounting { board: u8, scenario: u8 },
    /// The board does not fly every field of the configuration sent: its telemetry's digest
    /// of the whole configuration is another (protocol 6, Choice 228), e.g. a board its
    /// watchdog reset to its defaults between the `SetConfig` and the `Arm`.
    #[error("the board does not fly the configuration sent: {mismatch}")]
    Config { mismatch: auv_link::ConfigMismatch },
    /// The board reports another thrust unit than the plant reads its voltages in
    /// (docs/thrusters.md#the-thrust-unit): at the set-up or in any period.
    #[error("the board reports thrust unit {}, but the plant reads its voltages in {} (tick {tick})", unit_name(*board), unit_name(*plant))]
    ThrustUnit {
        board: ThrustUnit,
        plant: ThrustUnit,
        tick: u64,
    },

    /// A stop was requested (Ctrl-C, SIGTERM) while waiting for `waiting_for` (Choice 120).
    #[error("interrupted while waiting for {waiting_for}")]
    Interrupted { waiting_for: &'static str },
}

/// The core's name of a wire thrust unit (`"kgf"`, `"newton"`: the scenario key's values).
pub(super) fn unit_name(u: ThrustUnit) -> &'static str {
    controller_core::ThrustUnit::from(u).as_str()
}

/// The images that fly in QEMU, as the messages name them: `` a` or `b ``.
fn flying_images() -> String {
    let flying: Vec<&str> = Image::ALL
        .iter()
        .filter(|i| i.flies_in_qemu())
        .map(|i| i.bin())
        .collect();
    flying.join("` or `")
}

impl From<Error> for Stop {
    /// How a run ends on `e`: an interrupt is [`Stop::Interrupted`], anything else loses the
    /// board, with the cause the operator looks at first (Choice 200).
    fn from(e: Error) -> Stop {
        let cause = match &e {
            Error::Interrupted { .. } => return Stop::Interrupted,
            Error::Silent { .. } => BoardLoss::Silent,
            Error::Noise { .. } | Error::Signing { .. } => BoardLoss::Noise,
            Error::LinkGone { .. } => BoardLoss::LinkGone,
            Error::ThrustUnit { .. }
            | Error::Mounting { .. }
            | Error::Config { .. }
            | Error::Refused { .. }
            | Error::UploadNotVerified { .. }
            | Error::NotArmed { .. }
            | Error::Geometry => BoardLoss::Misconfigured,
            Error::LinkIo { .. }
            | Error::Encode(_)
            | Error::ElfUnreadable { .. }
            | Error::NotFlyingImage { .. }
            | Error::NoImageMarker { .. }
            | Error::QemuStart { .. }
            | Error::QemuLog { .. }
            | Error::QemuIo { .. }
            | Error::QemuNoUart { .. }
            | Error::QemuNoPty { .. }
            | Error::QemuEnded { .. }
            | Error::NoPort { .. }
            | Error::PortOpen { .. } => BoardLoss::Failed,
        };
        Stop::LostBoard {
            cause,
            reason: e.to_string(),
        }
    }
}
