//! A board in the loop: the firmware flies the simulated vehicle. Processor in the loop
//! (`host-sim pil`): the firmware ELF runs in QEMU (`mps2-an386`, or the STM32 board code on
//! `netduinoplus2`) with its navigation link on a loopback TCP socket; hardware in the loop
//! (`host-sim hil`): a board on a serial port. The simulator plays the vehicle and its
//! navigation computer; the loop is [`crate::sim::fly`]'s, with [`BoardInTheLoop`] as its
//! [`ControlSource`](crate::sim::ControlSource).
//!
//! | module | owns |
//! |---|---|
//! | [`runner`] | [`BoardInTheLoop`]: start (QEMU on a socket, a serial port), one control period as the loop's [`ControlSource`](crate::sim::ControlSource), the end; it composes the parts below |
//! | `link` | the link's state: framing, signing, this end's sequence numbers, the decoder and the board's numbers, the reply timeout and what came instead (silence or noise) |
//! | `faults` | the scenario's link faults per period, and the recent states a delay sends |
//! | `session` | what the run asks of the board (configuration, mission, unit, mounting) and the set-up, the mission's start and the re-arm after a fail-safe |
//! | [`upload`] | a waypoint mission's chunked upload before `Arm`, resent until verified |
//! | `period` | the board's answer to each period, lock-step or real time, and its newest telemetry |
//! | [`pacing`] | lock-step or real time, and a real-time run's timing figures |
//! | [`stats`], [`comparison`] | a run's link and board figures (an upload's too); the board run against SIL |
//! | [`error`] | how a board in the loop fails ([`Error`]), and how a run ends on it |
//! | [`transport`] | the byte transport under the link: a TCP socket or a serial device |
//! | [`emulator`] | QEMU launched through the runner script: on a socket or a pty |
//! | [`image`] | which firmware ELF may fly (its image marker), and where the build leaves it |
//! | [`frames`] | the navigation computer's side of the wire: state frames, signing time |
//!
//! Set-up: the runner waits for the board's first telemetry and numbers its own frames from the
//! board's `last_rx_seq` on (a restarted runner is heard again: `auv_link::seq`), then sends
//! `SetConfig { lockstep, rate, Δu on/off, δ_max, voltage limit, stale periods, thrust unit,
//! thruster mounting, axis priority }` from the scenario's validated controller and `Arm`,
//! and waits for the board to report itself armed with that configuration, every field of it
//! (its unit, its mounting, and the digest of the whole, `Session::set_up`; a refused
//! command is reported with the board's reason; a waypoint mission is uploaded
//! between the `SetConfig` and the `Arm`, [`upload`]); then `StartMission` with the
//! scenario's validated mission (path, heading, time scale) and the first state frame. Every
//! telemetry frame must name the thrust unit the plant reads the voltages in, or the run
//! stops (docs/thrusters.md#the-thrust-unit). In lock-step the board runs
//! one control period per state frame and takes the frame's `t_ticks` as mission time (on its
//! mission clock), so the result does not depend on host speed.
//!
//! Signing ([`auv_link::sign`]): with a key, QEMU is started with `-append link-key=…` (the
//! QEMU image's configuration; the key never crosses the link), the runner signs every frame
//! (timestamps: 10 µs units since 2015-01-01 UTC, as MAVLink) and refuses telemetry that is not
//! signed by the board. Telemetry frames are also checked for sequence order. Each period the simulator sends a state frame from
//! the plant and applies the returned telemetry (voltages, or τ for ideal actuators) through
//! the same actuator chain as SIL ([`crate::sim::fly`]).
//!
//! Link faults ([`LinkFaults`](crate::scenario::LinkFaults)) drop, corrupt, delay or silence state frames over tick ranges.
//! The board must go to fail-safe within its stale-state limit; a delayed frame is an old state
//! the board drops (off its mission clock). Once the link is healthy again the simulator
//! re-arms it (disarm, arm, and start the mission again where it is, since disarming drops it)
//! and it must resume. Every fail-safe entry and exit is recorded.
//!
//! Hardware in the loop (`host-sim hil`) is the same runner over another byte transport
//! ([`transport`]): a serial device instead of QEMU's socket ([`BoardInTheLoop::over_serial`]).
//! It paces the run one of two ways ([`Pacing`], docs/board.md#pacing): lock-step, exactly the
//! protocol above; or real time, where the board runs on its own timer (`lockstep = false`)
//! and the host sends each state frame at its wall-clock period and flies the plant on the
//! newest telemetry it has when the next period is due ([`RealTimeStats`]).
//!
//! Every wait is bounded: no valid telemetry for the reply timeout (10 s for PIL,
//! `hil --reply-timeout`) ends the run with an error that says whether the board sent
//! nothing (not powered, not wired, wrong port: [`Error::Silent`]) or only bytes that did not
//! decode (a wrong baud rate or key: [`Error::Noise`]); a link that closes or a port that goes
//! away ends it at once ([`Error::LinkGone`]). A run that fails so ends
//! [`Outcome::LostBoard`](crate::sim::Outcome::LostBoard), not diverged (Choice 200).

pub mod comparison;
pub mod emulator;
pub mod error;
mod faults;
pub mod frames;
pub mod image;
mod link;
pub mod pacing;
mod period;
pub mod runner;
mod session;
pub mod stats;
pub mod transport;
pub mod upload;

pub use comparison::{BoardComparison, Mode, PIL_SIL_TOLERANCE};
pub use error::Error;
pub use pacing::{Pacing, RealTimeStats};
pub use runner::BoardInTheLoop;
pub use stats::{BoardStats, FailSafeEvent, FailSafeEventKind, UploadStats};
