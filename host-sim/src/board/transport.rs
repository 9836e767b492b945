//! The byte transport under the board link: the one seam between the PIL/HIL runner
//! ([`super::BoardInTheLoop`]) and what carries its bytes — a loopback TCP socket to QEMU
//! (`pil`), or a serial device (`hil`: a USB-serial adapter wired to the board, or the
//! pseudo-terminal of QEMU's `-serial pty`).
//!
//! A transport reads with a timeout (a read that times out is `Ok(0)` through
//! [`Transport::read_some`], never an error, so the runner bounds every wait itself) and writes
//! whole frames. End of stream and a port that went away are errors, named for the operator.

use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use super::error::Error;

/// What the runner needs from a byte transport.
///
/// **Choice 62** (docs/board.md#hardware-in-the-loop): one runner over this seam, not a runner per transport.
pub trait Transport: Send {
    /// Up to `buf.len()` bytes, waiting at most the read timeout for the first: `Ok(0)` when
    /// nothing came in that time. A closed link is `Err` ([`io::ErrorKind::UnexpectedEof`]).
    fn read_some(&mut self, buf: &mut [u8]) -> io::Result<usize>;
    /// Writes every byte.
    fn write_frame(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// The longest a [`Transport::read_some`] waits.
    fn set_read_timeout(&mut self, timeout: Duration) -> io::Result<()>;
    /// This end may join the board's byte stream in the middle of a frame: the board talks
    /// before the port is opened (a serial line), so the bytes up to the first delimiter are
    /// the tail of a frame sent before, not a frame (**Choice 490**). A socket QEMU connects
    /// before its guest runs starts at a frame's first byte.
    fn joins_mid_stream(&self) -> bool {
        false
    }
}

/// A read that timed out, as `std` reports it on a socket or serialport on a tty.
fn timed_out(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

fn eof() -> io::Error {
    io::Error::new(
        io::ErrorKind::UnexpectedEof,
        "the other end closed the link",
    )
}

impl Transport for TcpStream {
    fn read_some(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.read(buf) {
            Ok(0) => Err(eof()),
            Ok(n) => Ok(n),
            Err(e) if timed_out(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }
    fn write_frame(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.write_all(bytes)
    }
    fn set_read_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        TcpStream::set_read_timeout(self, Some(timeout))
    }
}

/// A serial device (`serialport`: termios raw mode, 8N1, no flow control, exclusive).
pub struct Serial {
    port: Box<dyn serialport::SerialPort>,
}

impl Serial {
    /// Opens `path` at `baud` (8N1, no flow control) in raw mode — no echo, no line editing,
    /// which a pseudo-terminal would otherwise apply (the board's frames would come back).
    ///
    /// **Choice 63**: 8N1, no flow control, raw, exclusive (serialport's default), both
    /// buffers cleared; the caller's default baud is the STM32's (`firmware_images::LINK_BAUD`).
    pub fn open(path: &str, baud: u32) -> Result<Serial, Error> {
        if !std::path::Path::new(path).exists() {
            return Err(Error::NoPort {
                path: path.to_string(),
            });
        }
        let port = serialport::new(path, baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(Duration::from_millis(100))
            .open()
            .map_err(|error| Error::PortOpen {
                path: path.to_string(),
                baud,
                error,
            })?;
        // Bytes left from before this run (an earlier run, the board's boot) are not ours.
        let _ = port.clear(serialport::ClearBuffer::All);
        Ok(Serial { port })
    }
}

impl Transport for Serial {
    fn read_some(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.port.read(buf) {
            // A tty read of 0 bytes after poll said readable: the other end hung up.
            Ok(0) => Err(eof()),
            Ok(n) => Ok(n),
            Err(e) if timed_out(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }
    fn write_frame(&mut self, bytes: &[u8]) -> io::Result<()> {
        // No flush: the tty write is unbuffered, and `tcdrain` on a pty would wait for the
        // emulated UART to take every byte.
        self.port.write_all(bytes)
    }
    fn set_read_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.port.set_timeout(timeout).map_err(io::Error::from)
    }
    fn joins_mid_stream(&self) -> bool {
        true
    }
}
