//! A board on the bench, made of queues, for tests that run the whole loop
//! (`firmware::board::period`): thruster channels that keep their duty, the link as two byte
//! queues, and a period timer the test drives.

use std::collections::VecDeque;
use std::convert::Infallible;

use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use firmware::board::Board;

use super::SUPPLY;

/// A thruster channel that keeps its duty (of 1000).
pub struct Channel(pub u16);

impl ErrorType for Channel {
    type Error = Infallible;
}

impl SetDutyCycle for Channel {
    fn max_duty_cycle(&self) -> u16 {
        1000
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        self.0 = duty;
        Ok(())
    }
}

/// The link as two queues: bytes to the board, bytes from it.
#[derive(Default)]
pub struct Wire {
    pub to_board: VecDeque<u8>,
    pub from_board: Vec<u8>,
    /// The period boundary passes while the board writes this period's telemetry, that is,
    /// after the period's work: the work outlasted the period ([`Bench::late`]).
    pub late: bool,
    /// A boundary passed that the board has not read yet.
    pub passed: bool,
}

impl embedded_io::ErrorType for Wire {
    type Error = Infallible;
}

impl embedded_io::Read for Wire {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        let n = buf.len().min(self.to_board.len());
        for (slot, b) in buf.iter_mut().zip(self.to_board.drain(..n)) {
            *slot = b;
        }
        Ok(n)
    }
}

impl embedded_io::ReadReady for Wire {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(!self.to_board.is_empty())
    }
}

impl embedded_io::Write for Wire {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.from_board.extend_from_slice(buf);
        self.passed |= std::mem::take(&mut self.late);
        Ok(buf.len())
    }
    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// A board whose period boundary comes when it waits for it, unless the test made the period
/// [`late`](Bench::late): then the boundary passes during the period's work, and the board
/// finds it passed when it next looks.
pub struct Bench {
    pub thrusters: [Channel; 5],
    pub wire: Wire,
}

impl Bench {
    pub fn new() -> Self {
        Bench {
            thrusters: std::array::from_fn(|_| Channel(0)),
            wire: Wire::default(),
        }
    }

    /// This period's work outlasts it: its boundary passes before the period ends.
    pub fn late(&mut self) {
        self.wire.late = true;
    }
}

impl Default for Bench {
    fn default() -> Self {
        Self::new()
    }
}

impl Board for Bench {
    type Thruster = Channel;
    type Link = Wire;

    fn supply_voltage(&self) -> f32 {
        SUPPLY
    }
    fn thrusters(&mut self) -> &mut [Channel; 5] {
        &mut self.thrusters
    }
    fn link(&mut self) -> &mut Wire {
        &mut self.wire
    }
    fn set_rate(&mut self, _hz: u32) {}
    fn period_elapsed(&mut self) -> bool {
        std::mem::take(&mut self.wire.passed)
    }
    /// The previous period overran if its boundary passed already; otherwise the boundary
    /// comes now.
    fn wait_period(&mut self) -> bool {
        self.period_elapsed()
    }
    fn now(&self) -> u32 {
        0
    }
}
