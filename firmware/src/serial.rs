//! The navigation link's bytes between a UART interrupt and the control loop, through two
//! `heapless::spsc` queues (one producer and one consumer each, lock-free).
//!
//! - [`IrqSide`] is what the UART's interrupt handler holds: it hands every received byte, with
//!   the status flags read with it, to [`IrqSide::received`], and takes the next byte to send
//!   from [`IrqSide::next_tx`].
//! - [`LoopSide`] is the control loop's end: an `embedded_io` serial port
//!   ([`Read`], [`ReadReady`], [`Write`]).
//!
//! No registers here: the STM32 board (`stm32f405` module) owns the peripheral and the
//! interrupt, and the host tests drive both sides.
//!
//! # Line errors
//!
//! A byte lost by the UART (overrun) or received damaged (framing error, noise, parity) breaks
//! the frame it belongs to. The interrupt puts a [`RxEvent::LineError`] into the receive queue
//! at the place in the byte stream where it happened, and [`Read::read`] returns it as an
//! error there, so that the loop calls the decoder's
//! [`resync`](auv_link::FrameDecoder::resync) (see [`crate::board::pump`]) exactly between the
//! bytes before and after the damage:
//!
//! - a **damaged** byte (FE, NF, PE) is itself suspect: the error goes *before* it;
//! - an **overrun** (ORE) means the byte in the data register is good and the one *after* it
//!   was lost: the error goes *after* it (so a frame that the good byte completes is kept);
//! - bytes that find the receive queue **full** are dropped and counted, and an error is
//!   queued before the next byte that fits.

use embedded_io::{ErrorKind, ErrorType, Read, ReadReady, Write};
use heapless::spsc::{Consumer, Producer, Queue};

pub use firmware_images::LINK_BAUD;

/// Received bytes (and line errors) the queue holds: 11 ms of line at 460 800 baud, longer
/// than a 100 Hz control period.
pub const RX_CAPACITY: usize = 512;
/// Bytes to send the queue holds: more than one telemetry frame (`auv_link::MAX_FRAME`, 179
/// bytes signed).
pub const TX_CAPACITY: usize = 512;

/// Storage of the receive queue (heapless keeps one slot free: N = capacity + 1).
pub type RxQueue = Queue<RxEvent, { RX_CAPACITY + 1 }>;
/// Storage of the transmit queue.
pub type TxQueue = Queue<u8, { TX_CAPACITY + 1 }>;

/// What the interrupt passes to the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RxEvent {
    /// A received byte.
    Byte(u8),
    /// The byte stream is broken here (see the module docs).
    LineError,
}

/// What the UART's status register said about the data register when the interrupt read it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RxFlags {
    /// A received byte is in the data register (RXNE).
    pub byte: bool,
    /// That byte is damaged: framing error, noise or parity error (FE, NF, PE).
    pub damaged: bool,
    /// A byte after it was lost: the receiver overran (ORE).
    pub overrun: bool,
}

/// The loop side's read error: the byte stream is broken at this point (a line error or bytes
/// dropped on a full queue). The next read continues with the bytes after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineError;

impl core::fmt::Display for LineError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("UART line error (bytes lost or damaged)")
    }
}

impl core::error::Error for LineError {}

impl embedded_io::Error for LineError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::InvalidData
    }
}

/// Splits the two queues into the interrupt's end and the loop's end.
pub fn split<'q>(rx: &'q mut RxQueue, tx: &'q mut TxQueue) -> (IrqSide<'q>, LoopSide<'q>) {
    let (rx_in, rx_out) = rx.split();
    let (tx_in, tx_out) = tx.split();
    (
        IrqSide {
            rx: rx_in,
            tx: tx_out,
            owed_error: false,
            dropped: 0,
            line_errors: 0,
        },
        LoopSide {
            rx: rx_out,
            tx: tx_in,
        },
    )
}

/// The interrupt handler's end: produces received bytes, consumes bytes to send.
pub struct IrqSide<'q> {
    rx: Producer<'q, RxEvent>,
    tx: Consumer<'q, u8>,
    /// Something was dropped on a full queue: a line error must precede the next event.
    owed_error: bool,
    dropped: u32,
    line_errors: u32,
}

impl IrqSide<'_> {
    /// One read of the data register: `byte` is its content, valid if `flags.byte`.
    pub fn received(&mut self, flags: RxFlags, byte: u8) {
        if flags.damaged {
            self.line_error();
        }
        if flags.byte {
            self.push(RxEvent::Byte(byte));
        }
        if flags.overrun {
            self.line_error();
        }
    }

    /// The next byte to put into the data register, if any (none: the caller stops the
    /// transmit interrupt until the loop queues more).
    pub fn next_tx(&mut self) -> Option<u8> {
        self.tx.dequeue()
    }

    /// Received bytes dropped because the receive queue was full (the loop stalled).
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Line errors the UART reported (overrun, framing, noise, parity).
    pub fn line_errors(&self) -> u32 {
        self.line_errors
    }

    fn line_error(&mut self) {
        self.line_errors = self.line_errors.wrapping_add(1);
        self.push(RxEvent::LineError);
    }

    fn push(&mut self, event: RxEvent) {
        if self.owed_error {
            if self.rx.enqueue(RxEvent::LineError).is_err() {
                self.count_drop(event);
                return;
            }
            self.owed_error = false;
        }
        if self.rx.enqueue(event).is_err() {
            self.count_drop(event);
            self.owed_error = true;
        }
    }

    fn count_drop(&mut self, event: RxEvent) {
        if let RxEvent::Byte(_) = event {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }
}

/// The control loop's end: an `embedded_io` port over the two queues.
///
/// - [`Read::read`] returns every queued byte that fits up to the next line error (at least
///   one byte, waiting for the first as `embedded_io` requires), or `Err(LineError)` when the
///   line error is next; the loop reads only after [`ReadReady::read_ready`] says true.
/// - [`Write::write`] queues bytes and returns at once, waiting only while the queue is full
///   (the interrupt drains it; the owner must enable the transmit interrupt after each write).
///   [`Write::flush`] waits until the queue is empty.
pub struct LoopSide<'q> {
    rx: Consumer<'q, RxEvent>,
    tx: Producer<'q, u8>,
}

impl LoopSide<'_> {
    /// True if every queued byte has been taken by the interrupt.
    pub fn tx_empty(&self) -> bool {
        self.tx.is_empty()
    }
}

impl ErrorType for LoopSide<'_> {
    type Error = LineError;
}

impl ReadReady for LoopSide<'_> {
    fn read_ready(&mut self) -> Result<bool, LineError> {
        Ok(self.rx.ready())
    }
}

impl Read for LoopSide<'_> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, LineError> {
        if buf.is_empty() {
            return Ok(0);
        }
        while !self.rx.ready() {}
        let mut n = 0;
        for slot in buf.iter_mut() {
            match self.rx.peek() {
                Some(&RxEvent::Byte(b)) => {
                    *slot = b;
                    self.rx.dequeue();
                    n += 1;
                }
                Some(RxEvent::LineError) if n == 0 => {
                    self.rx.dequeue();
                    return Err(LineError);
                }
                // A line error after some bytes: those first, the error on the next read.
                Some(RxEvent::LineError) | None => break,
            }
        }
        Ok(n)
    }
}

impl Write for LoopSide<'_> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, LineError> {
        if buf.is_empty() {
            return Ok(0);
        }
        while !self.tx.ready() {}
        let mut n = 0;
        for &b in buf {
            if self.tx.enqueue(b).is_err() {
                break;
            }
            n += 1;
        }
        Ok(n)
    }

    fn flush(&mut self) -> Result<(), LineError> {
        while !self.tx.is_empty() {}
        Ok(())
    }
}
