//! A board in a test thread: the firmware's own supervisor on the master end of a pty, which
//! `host-sim hil` opens as its serial port (tests/hil_port.rs, tests/law_on_board.rs). Each test
//! drives its own period: how many frames a period takes is what those tests vary.
// Each test file uses some of these.
#![allow(dead_code)]

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::time::Duration;

use controller_core::{Controller, ControllerConfig};
use firmware::board::{receive, LinkBuffers};
use firmware::supervisor::{BoardInfo, Supervisor};
use serialport::{SerialPort, TTYPort};

/// A pty pair: the master (the test's end, the "board") and the slave's path, free for `hil`
/// to open (the pair's own slave handle is closed: it holds the port exclusively).
pub fn pty() -> (TTYPort, String) {
    let (master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    // Not inherited by the `host-sim` processes the tests start (this test's or another's): a
    // board that hangs up must close the master's last copy.
    // SAFETY: fcntl(2) on a descriptor the pair owns.
    unsafe {
        libc::fcntl(master.as_raw_fd(), libc::F_SETFD, libc::FD_CLOEXEC);
    }
    let path = slave.name().expect("the slave's path");
    drop(slave);
    (master, path)
}

/// The supervisor booted on the core's defaults, as the flying images are (every law setting
/// it flies comes over the link), its link buffers and the bytes its "UART" has received.
pub struct SoftBoard {
    port: TTYPort,
    pub sup: Supervisor,
    bufs: LinkBuffers,
    inbox: VecDeque<u8>,
}

impl SoftBoard {
    pub fn new(mut port: TTYPort) -> Self {
        let controller = Controller::new(ControllerConfig::default()).expect("default config");
        let info = BoardInfo {
            supply_voltage: controller_core::DEFAULT_V_LIMIT,
            signing: false,
        };
        let _ = port.set_timeout(Duration::from_millis(1));
        SoftBoard {
            port,
            sup: Supervisor::new(controller, info),
            bufs: LinkBuffers::new(),
            inbox: VecDeque::new(),
        }
    }

    /// One board period at the supervisor's rate.
    pub fn period(&self) -> Duration {
        Duration::from_secs_f64(1.0 / f64::from(self.sup.rate_hz().max(1)))
    }

    /// What the line has brought (at most 1 ms of waiting).
    pub fn listen(&mut self) {
        let mut chunk = [0u8; 256];
        match self.port.read(&mut chunk) {
            Ok(n) => self.inbox.extend(&chunk[..n]),
            // A master reads EIO while no one holds the slave (before `hil` opens it).
            Err(_) => std::thread::sleep(Duration::from_millis(1)),
        }
    }

    /// The bytes of one whole frame (up to its `0x00` delimiter) to the supervisor, if a whole
    /// one is there; whether one was.
    pub fn take_frame(&mut self) -> bool {
        let Some(end) = self.inbox.iter().position(|&b| b == 0) else {
            return false;
        };
        let frame: Vec<u8> = self.inbox.drain(..=end).collect();
        receive(&mut self.sup, &mut self.bufs, &frame);
        true
    }

    /// One supervisor step and its telemetry. Nobody listening yet (or any more): the frame is
    /// lost, as on a real line.
    pub fn step_and_answer(&mut self) {
        let step = self.sup.step(false, &|| 0);
        let env = self.sup.envelope(step.telemetry);
        if let Ok(frame) = self.bufs.encode(&env) {
            let _ = self.port.write_all(frame);
        }
    }
}
