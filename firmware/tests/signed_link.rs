//! The board's signed end of the link through its whole loop (`board::period` on a bench board
//! made of queues, `common::bench`): how far ahead of the last accepted stamp a navigation
//! computer's frames may run (Choices 95–96, docs/link.md#how-far-ahead-a-stamp-may-run). A silence the board lived through is counted, a clock
//! that jumped ahead of that count is refused and counted, the board then fails safe on the
//! silence and keeps signing its telemetry, and a reset takes the new clock.

use auv_link::sign::{Direction, Verifier, CEILING, MAX_LEAD, UNITS_PER_SECOND};
use auv_link::{BoardStatus, Command, FailSafeReason, FrameDecoder, Msg, Telemetry};
use firmware::board::{self, LinkBuffers};
use firmware::supervisor::Supervisor;

mod common;
use common::bench::Bench;
use common::{board_info, controller, state, Host, CIRCLE, KEY};

/// A signed board on the bench, its navigation computer (stamping its own clock, in 10 µs
/// units), and the navigation computer's end of the telemetry.
struct Rig {
    bench: Bench,
    sup: Supervisor,
    link: LinkBuffers,
    nav: Host,
    clock: u64,
    telemetry: FrameDecoder,
}

/// 2026-01-01 in MAVLink time (10 µs units since 2015-01-01: 11 years, 3 of them leap).
const JAN_2026: u64 = (11 * 365 + 3) * 86_400 * UNITS_PER_SECOND;
/// One 100 Hz period in timestamp units.
const PERIOD: u64 = UNITS_PER_SECOND / 100;

impl Rig {
    /// A board just reset, its peer's clock at `clock`.
    fn new(clock: u64) -> Rig {
        Rig {
            bench: Bench::new(),
            sup: Supervisor::new(controller(), board_info(true)),
            link: LinkBuffers::signed(&KEY),
            nav: Host::signed(&KEY),
            clock,
            telemetry: FrameDecoder::signed(Verifier::new(&KEY, Direction::FromBoard)),
        }
    }

    /// The navigation computer sends `msg`, stamped with its clock.
    fn send(&mut self, msg: Msg) {
        if let Some(s) = &mut self.nav.signer {
            s.advance_to(self.clock);
        }
        let w = self.nav.wire(msg);
        self.bench.wire.to_board.extend(w);
    }

    /// One board period (and a period of the peer's clock); the telemetry it sent, as the
    /// navigation computer reads it (it must verify).
    fn period(&mut self) -> Telemetry {
        board::period(&mut self.bench, &mut self.sup, &mut self.link);
        self.clock += PERIOD;
        let bytes = std::mem::take(&mut self.bench.wire.from_board);
        let mut got = Vec::new();
        self.telemetry.push_slice(&bytes, |r| got.push(r));
        match got.as_slice() {
            [Ok(env)] => match env.msg {
                Msg::Telemetry(t) => t,
                _ => panic!("not telemetry: {env:?}"),
            },
            other => panic!("one signed telemetry frame expected, got {other:?}"),
        }
    }

    /// Armed, flying the circle, state frames 0 ..= 4 taken.
    fn flying(clock: u64) -> Rig {
        let mut r = Rig::new(clock);
        r.send(Msg::Command(Command::Arm));
        r.send(Msg::Command(Command::StartMission(CIRCLE)));
        for k in 0..5 {
            r.send(Msg::State(state(k)));
            assert_eq!(r.period().status, BoardStatus::Running, "period {k}");
        }
        r
    }
}

#[test]
fn a_silence_the_board_lived_through_does_not_refuse_its_peer() {
    let mut r = Rig::new(JAN_2026);
    r.send(Msg::Command(Command::Arm));
    assert_eq!(r.period().status, BoardStatus::Armed);
    // The navigation computer is away for 11 minutes (a reboot), more than the lead alone
    // allows; the board counts the 66 000 periods, and its peer's clock moved on by as much.
    r.send(Msg::Command(Command::Disarm));
    let away = 11 * 60 * 100;
    assert!(away * PERIOD > MAX_LEAD);
    for _ in 0..away {
        r.bench.wire.to_board.clear();
        r.period();
    }
    r.send(Msg::Command(Command::Disarm));
    let t = r.period();
    assert_eq!(
        (t.status, t.rx_ahead, t.rx_auth_errors),
        (BoardStatus::Disarmed, 0, 0)
    );
    // The same jump without the periods the board counted is refused.
    let mut fresh = Rig::new(JAN_2026);
    fresh.send(Msg::Command(Command::Arm));
    fresh.period();
    fresh.clock += away * PERIOD;
    fresh.send(Msg::Command(Command::Disarm));
    let t = fresh.period();
    assert_eq!((t.status, t.rx_ahead), (BoardStatus::Armed, 1));
}

#[test]
fn every_frame_of_a_clock_that_jumped_is_refused_and_the_board_fails_safe_on_silence() {
    let mut r = Rig::flying(JAN_2026);
    // The navigation computer's clock jumps an hour ahead (a wrong time source), and runs on.
    r.clock += 3600 * UNITS_PER_SECOND;
    let mut statuses = Vec::new();
    let mut last = None;
    for k in 5..25 {
        r.send(Msg::State(state(k)));
        let t = r.period();
        statuses.push(t.status);
        last = Some(t);
    }
    let t = last.unwrap();
    let stale = BoardStatus::FailSafe(FailSafeReason::StaleState);
    let grace = usize::from(auv_link::DEFAULT_STALE_PERIODS);
    assert!(statuses[..grace].iter().all(|s| *s == BoardStatus::Running));
    assert!(
        statuses[grace..].iter().all(|s| *s == stale),
        "{statuses:?}"
    );
    assert!(r.bench.thrusters.iter().all(|c| c.0 == 500), "neutral duty");
    // Every one of the 20 frames refused and counted, as an authentication failure too.
    assert_eq!((t.rx_ahead, t.rx_auth_errors, t.rx_errors), (20, 20, 20));
    assert_eq!(t.rx_frames, 2 + 5);
}

#[test]
fn a_reset_takes_the_new_clock_but_never_a_stamp_above_the_ceiling() {
    // After the jump of the test above, a reset board (no last stamp) takes the new clock.
    let mut r = Rig::flying(JAN_2026 + 3600 * UNITS_PER_SECOND);
    assert_eq!(r.period().rx_ahead, 0);
    // A peer at the ceiling's edge: the board never takes a stamp above the ceiling, even
    // first; it takes one at the ceiling, and then signs on, above it, while its peer's later
    // stamps are all refused.
    let mut r = Rig::new(CEILING);
    r.send(Msg::Command(Command::Arm));
    let t = r.period();
    assert_eq!((t.status, t.rx_ahead), (BoardStatus::Disarmed, 1));
    r.nav = Host::signed(&KEY);
    r.clock = CEILING - 1;
    r.send(Msg::Command(Command::Arm));
    assert_eq!(r.period().status, BoardStatus::Armed);
    for _ in 0..1000 {
        r.send(Msg::Command(Command::Disarm));
        r.period();
    }
    let t = r.period();
    assert_eq!((t.status, t.rx_ahead), (BoardStatus::Armed, 1 + 1000));
}
