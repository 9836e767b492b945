//! Board: QEMU `mps2-an386` (ARM MPS2 with a Cortex-M4F, 25 MHz), for the QEMU images
//! (feature `qemu`, target only).
//!
//! - Navigation link: CMSDK APB UART0 at 0x4000_4000 (`-serial` of QEMU).
//! - Period timer: SysTick on the 25 MHz core clock. Its count is the unit of [`Board::now`]
//!   here: [`INSTRUCTIONS_PER_TICK`](crate::qemu_clock::INSTRUCTIONS_PER_TICK) instructions
//!   under the runner's `-icount`, which makes update timings deterministic instruction counts
//!   (see [`crate::qemu_clock`]).
//! - Thrusters: the board has no PWM; [`MemPwm`] channels keep the commanded duty in RAM (they
//!   implement `SetDutyCycle` like a real timer channel would).
//! - Receive buffering: UART0 holds one received byte and raises no interrupt this board
//!   uses, so while the loop waits for its period ([`QemuBoard::wait_period`]) it drains the
//!   UART into a RAM queue ([`CmsdkUart::poll_rx`]), as the STM32's USART interrupt does into
//!   its SPSC queue; the loop's reads take that queue first. Without it a free-running board
//!   (`host-sim hil --pacing realtime`) read only the bytes that came while it pumped at the
//!   start of a period — a few dozen — and fell further behind every period. Lock-step never
//!   waits there (it polls the link itself), so PIL is unchanged. (Choice 71,
//!   docs/board.md#pacing.)
//! - No watchdog.
//! - Configuration at boot: QEMU's semihosting command line (`-append "…"`, see
//!   [`crate::semihosting::command_line`]); the flying image takes its link key from it
//!   ([`crate::semihosting::link_key`]), the
//!   self-test its failure injections.

use core::cell::Cell;
use core::convert::Infallible;
use core::ptr::{read_volatile, write_volatile};

use controller_core::effectiveness::THRUSTERS;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use embedded_io::{ErrorType, Read, ReadReady, Write};

use crate::board::Board;
pub use crate::pwm::MemPwm;
use crate::qemu_clock::CORE_HZ;
pub use crate::semihosting::halt;

/// Nominal H-bridge supply (V).
pub const SUPPLY_VOLTAGE: f32 = controller_core::DEFAULT_V_LIMIT;

const UART0: usize = 0x4000_4000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;

/// CMSDK APB UART as an `embedded_io` serial port, with a software receive queue.
pub struct CmsdkUart {
    base: usize,
    /// Bytes taken from the UART while the loop waited ([`CmsdkUart::poll_rx`]), in order,
    /// before any still in the UART. As large as the STM32's receive queue.
    rx: heapless::Deque<u8, { crate::serial::RX_CAPACITY }>,
}

impl CmsdkUart {
    /// # Safety
    /// `base` must be the address of a CMSDK UART owned by nobody else.
    unsafe fn new(base: usize, baud: u32) -> Self {
        let u = CmsdkUart {
            base,
            rx: heapless::Deque::new(),
        };
        // SAFETY: registers of a UART the caller gives us exclusive use of.
        unsafe {
            write_volatile((base + BAUDDIV) as *mut u32, CORE_HZ / baud);
            write_volatile((base + CTRL) as *mut u32, 0b11); // TX and RX enable
        }
        u
    }

    fn reg(&self, off: usize) -> u32 {
        // SAFETY: a register of our UART.
        unsafe { read_volatile((self.base + off) as *const u32) }
    }

    /// Moves every byte the UART holds into the receive queue (while it has room: a full
    /// queue leaves the rest in the UART, as flow control would).
    pub fn poll_rx(&mut self) {
        while !self.rx.is_full() && self.reg(STATE) & STATE_RX_FULL != 0 {
            let _ = self.rx.push_back(self.reg(DATA) as u8);
        }
    }
}

impl ErrorType for CmsdkUart {
    type Error = Infallible;
}

impl ReadReady for CmsdkUart {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(!self.rx.is_empty() || self.reg(STATE) & STATE_RX_FULL != 0)
    }
}

impl Read for CmsdkUart {
    /// Blocks for the first byte, then returns what is available without waiting.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        let mut n = 0;
        while n < buf.len() {
            match self.rx.pop_front() {
                Some(b) => {
                    buf[n] = b;
                    n += 1;
                }
                None => break,
            }
        }
        if n > 0 {
            return Ok(n);
        }
        while self.reg(STATE) & STATE_RX_FULL == 0 {}
        while n < buf.len() && self.reg(STATE) & STATE_RX_FULL != 0 {
            buf[n] = self.reg(DATA) as u8;
            n += 1;
        }
        Ok(n)
    }
}

impl Write for CmsdkUart {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        for &b in buf {
            while self.reg(STATE) & STATE_TX_FULL != 0 {}
            // SAFETY: the data register of our UART.
            unsafe { write_volatile((self.base + DATA) as *mut u32, b as u32) };
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// Cycles between two reads of SysTick's flag while waiting for a period (40 µs at 25 MHz, 0.4 %
/// of a 10 ms period).
pub const WAIT_POLL_CYCLES: u32 = 1000;

/// Counts of full duty: 10-bit resolution, like a 24 kHz timer channel at 25 MHz.
pub const MAX_DUTY: u16 = 1000;

pub struct QemuBoard {
    syst: SYST,
    uart: CmsdkUart,
    thrusters: [MemPwm; THRUSTERS],
    reload: u32,
    /// Software extension of the 24-bit SysTick for `now()`: last counter value seen and the
    /// ticks accumulated so far. Correct while `now()` is called at least once per period.
    last_cvr: Cell<u32>,
    ticks: Cell<u32>,
}

impl QemuBoard {
    /// Takes SysTick and UART0. Call once.
    pub fn init(syst: SYST, rate_hz: u32) -> Self {
        // SAFETY: UART0 is used by this board only.
        let uart = unsafe { CmsdkUart::new(UART0, 115_200) };
        let mut b = QemuBoard {
            syst,
            uart,
            thrusters: [MemPwm::neutral(MAX_DUTY); THRUSTERS],
            reload: 0,
            last_cvr: Cell::new(0),
            ticks: Cell::new(0),
        };
        b.syst.set_clock_source(SystClkSource::Core);
        b.set_rate(rate_hz);
        b.syst.enable_counter();
        b
    }
}

impl Board for QemuBoard {
    type Thruster = MemPwm;
    type Link = CmsdkUart;

    fn supply_voltage(&self) -> f32 {
        SUPPLY_VOLTAGE
    }
    fn thrusters(&mut self) -> &mut [MemPwm; THRUSTERS] {
        &mut self.thrusters
    }
    fn link(&mut self) -> &mut CmsdkUart {
        &mut self.uart
    }
    fn set_rate(&mut self, hz: u32) {
        let reload = (CORE_HZ / hz.max(2)).clamp(2, 0x0100_0000) - 1;
        self.reload = reload;
        self.syst.set_reload(reload);
        self.syst.clear_current();
    }
    fn period_elapsed(&mut self) -> bool {
        // COUNTFLAG is set at each wrap and cleared by reading it.
        self.syst.has_wrapped()
    }
    /// As the default, but reads SysTick's flag only every [`WAIT_POLL_CYCLES`] cycles: under
    /// `-icount` every device-register read leaves QEMU's translated code, so a tight polling
    /// loop makes an idle 10 ms period cost seconds of wall time and keeps QEMU's I/O thread,
    /// which feeds UART0's bytes, waiting for its lock (PIL's arming handshake, which runs on
    /// these periods, then timed out on an idle host). The boundary is seen at most that many
    /// cycles late; what the loop does with it does not change.
    ///
    /// Between two reads of the flag it drains UART0 into its receive queue (module docs).
    fn wait_period(&mut self) -> bool {
        let overrun = self.period_elapsed();
        if !overrun {
            while !self.period_elapsed() {
                self.uart.poll_rx();
                cortex_m::asm::delay(WAIT_POLL_CYCLES);
            }
        }
        overrun
    }
    fn now(&self) -> u32 {
        // Down-counter: elapsed = last − current, modulo the period.
        let cvr = SYST::get_current();
        let last = self.last_cvr.replace(cvr);
        let elapsed = if cvr <= last {
            last - cvr
        } else {
            last + (self.reload + 1 - cvr)
        };
        let t = self.ticks.get().wrapping_add(elapsed);
        self.ticks.set(t);
        t
    }
}
