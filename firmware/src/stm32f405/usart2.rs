//! The navigation link on USART2, interrupt driven through the two queues of
//! [`crate::serial`]: the same code in the board image and in its emulator build (QEMU's
//! `netduinoplus2` models USART2 and its interrupt, IRQ 38).

use core::cell::RefCell;

use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::NVIC;
use embedded_io::{ErrorType, Read, ReadReady, Write};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::serial::{Event as SerialEvent, Serial};

use crate::serial::{self, IrqSide, LineError, LoopSide, RxFlags, RxQueue, TxQueue};

/// The interrupt's end of the queues, put here by [`Usart2Link::new`] before it unmasks the
/// interrupt. Only [`on_usart2_interrupt`] and the diagnostics use it, each in a critical
/// section.
static IRQ_SIDE: Mutex<RefCell<Option<IrqSide<'static>>>> = Mutex::new(RefCell::new(None));

fn usart2() -> &'static pac::usart1::RegisterBlock {
    // SAFETY: USART2's register block is always mapped. `Usart2Link` owns the peripheral; the
    // interrupt only reads SR/DR, writes DR and clears TXEIE, the main side only sets TXEIE
    // (in a critical section) and reads SR — see `on_usart2_interrupt` and `Usart2Link::write`.
    unsafe { &*pac::USART2::ptr() }
}

/// The body of the `USART2` interrupt handler (each STM32 image binds it:
/// [`stm32f405_handlers!`](crate::stm32f405_handlers)): moves a received byte, with its status flags, into the receive queue, and the
/// next queued byte into the data register.
pub fn on_usart2_interrupt() {
    let u = usart2();
    let sr = u.sr().read();
    let flags = RxFlags {
        byte: sr.rxne().bit_is_set(),
        damaged: sr.fe().bit_is_set() || sr.nf().bit_is_set() || sr.pe().bit_is_set(),
        overrun: sr.ore().bit_is_set(),
    };
    // Reading DR after SR clears RXNE and the error flags (ORE would otherwise keep the
    // interrupt pending).
    let received =
        (flags.byte || flags.damaged || flags.overrun).then(|| u.dr().read().dr().bits() as u8);
    let send = sr.txe().bit_is_set() && u.cr1().read().txeie().bit_is_set();
    let next = cortex_m::interrupt::free(|cs| {
        let mut guard = IRQ_SIDE.borrow(cs).try_borrow_mut().ok()?;
        let side = guard.as_mut()?;
        if let Some(b) = received {
            side.received(flags, b);
        }
        if send {
            side.next_tx()
        } else {
            None
        }
    });
    if send {
        match next {
            Some(b) => {
                u.dr().write(|w| w.dr().set(b as u16));
            }
            // Nothing left: stop the TXE interrupt until `write` queues more.
            None => {
                u.cr1().modify(|_, w| w.txeie().clear_bit());
            }
        }
    }
}

/// The navigation link on USART2 (PA2 TX, PA3 RX), 460800 8N1, as an `embedded_io` port: the
/// loop's end of the [`crate::serial`] queues (see [`LoopSide`] for how reads and writes
/// behave).
///
/// A line error (overrun, framing, noise, parity) or a byte dropped on a full queue comes out of
/// [`Read::read`] as a [`LineError`] at the place in the stream where it happened; the control
/// loop then resynchronises the frame decoder ([`crate::board::pump`]). The counts are in
/// [`Usart2Link::rx_line_errors`] and [`Usart2Link::rx_dropped`].
pub struct Usart2Link {
    queues: LoopSide<'static>,
    _serial: Serial<pac::USART2, u8>,
}

impl Usart2Link {
    /// Takes the configured USART2 (the HAL's `Serial`, 8N1 at the board's baud rate), puts the
    /// interrupt's end of the two queues where [`on_usart2_interrupt`] finds it, enables the
    /// receive interrupt and unmasks `USART2` in the NVIC.
    ///
    /// # Panics
    ///
    /// The queues are static and made once: a second call panics (the board's `init` runs once;
    /// a second call would already have failed to take the device peripherals).
    pub fn new(mut serial: Serial<pac::USART2, u8>) -> Self {
        let rx = cortex_m::singleton!(: RxQueue = RxQueue::new()).expect("init runs once");
        let tx = cortex_m::singleton!(: TxQueue = TxQueue::new()).expect("init runs once");
        let (irq_side, loop_side) = serial::split(rx, tx);
        cortex_m::interrupt::free(|cs| IRQ_SIDE.borrow(cs).replace(Some(irq_side)));
        serial.listen(SerialEvent::RxNotEmpty);
        // SAFETY: the handler only touches USART2 and its end of the queues; unmasking it
        // cannot break a critical section (none is active here).
        unsafe { NVIC::unmask(pac::Interrupt::USART2) };
        Usart2Link {
            queues: loop_side,
            _serial: serial,
        }
    }
}

// Diagnostics (for logs or a debugger); the control loop itself does not need them.
impl Usart2Link {
    /// Receive line errors so far (overrun, framing, noise, parity).
    pub fn rx_line_errors(&self) -> u32 {
        irq_side(|s| s.line_errors())
    }

    /// Received bytes dropped because the receive queue was full (the loop stalled > 11 ms).
    pub fn rx_dropped(&self) -> u32 {
        irq_side(|s| s.dropped())
    }
}

fn irq_side(f: impl FnOnce(&IrqSide<'static>) -> u32) -> u32 {
    cortex_m::interrupt::free(|cs| {
        IRQ_SIDE
            .borrow(cs)
            .try_borrow()
            .ok()
            .and_then(|s| s.as_ref().map(f))
            .unwrap_or(0)
    })
}

impl ErrorType for Usart2Link {
    type Error = LineError;
}

impl ReadReady for Usart2Link {
    fn read_ready(&mut self) -> Result<bool, LineError> {
        self.queues.read_ready()
    }
}

impl Read for Usart2Link {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, LineError> {
        self.queues.read(buf)
    }
}

impl Write for Usart2Link {
    fn write(&mut self, buf: &[u8]) -> Result<usize, LineError> {
        // The interrupt drains the queue (TXEIE is on whenever it holds bytes).
        let n = self.queues.write(buf)?;
        // The interrupt clears TXEIE (read-modify-write of CR1): set it where it cannot
        // interleave.
        cortex_m::interrupt::free(|_| usart2().cr1().modify(|_, w| w.txeie().set_bit()));
        Ok(n)
    }

    fn flush(&mut self) -> Result<(), LineError> {
        self.queues.flush()?;
        while usart2().sr().read().tc().bit_is_clear() {}
        Ok(())
    }
}
