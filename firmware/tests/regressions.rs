//! Regression tests of issue 10's board defects, one per defect, each named for it.
//!
//! They use only the supervisor's interface that predates the fix (construction, frames,
//! periods, status, the fault code, `last_state_seq`, the loop rate, the lock-step flag and
//! the refusal count), so that the same file also runs against the code before the fix: the
//! `compat` module below is the only part that differs there (`Supervisor::new` took the
//! controller alone, and the refusal count was `rejected_commands`), with `common`'s
//! `supervisor`, `state`, `CIRCLE` and `NOW` (main had no `tests/common`). Every test here
//! fails on that code. The defects that need the new interface to be seen at all (signing,
//! refusal reasons in telemetry) are tested in `supervisor.rs`, `link/tests/sign.rs` and the
//! supervisor fuzz harness (`supervisor_fuzz.rs`, which drives the board's signed end of the
//! link).

use auv_link::{BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason, MissionSpec, Msg};
use controller_core::effectiveness::THRUSTERS;
use firmware::supervisor::Supervisor;

mod common;
use common::{state, CIRCLE, NOW};

mod compat {
    use firmware::supervisor::Supervisor;

    pub fn supervisor() -> Supervisor {
        super::common::supervisor()
    }

    pub fn refused(s: &Supervisor) -> u32 {
        s.refused_commands()
    }
}
use compat::{refused, supervisor};

/// Frames numbered from 1, +1 each.
struct Seq(u16);

impl Seq {
    fn env(&mut self, msg: Msg) -> Envelope {
        self.0 = self.0.wrapping_add(1);
        Envelope {
            version: auv_link::PROTOCOL_VERSION,
            seq: self.0,
            msg,
        }
    }
    fn give(&mut self, s: &mut Supervisor, msg: Msg) {
        let e = self.env(msg);
        s.on_envelope(&e);
    }
    fn command(&mut self, s: &mut Supervisor, c: Command) {
        self.give(s, Msg::Command(c));
    }
}

/// Armed, flying the circle, one state frame (tick 0) delivered.
fn running() -> (Supervisor, Seq) {
    let mut s = supervisor();
    let mut q = Seq(0);
    q.command(&mut s, Command::Arm);
    q.command(&mut s, Command::StartMission(CIRCLE));
    q.give(&mut s, Msg::State(state(0)));
    (s, q)
}

fn status(s: &mut Supervisor) -> BoardStatus {
    s.step(false, NOW).telemetry.status
}

const STALE: BoardStatus = BoardStatus::FailSafe(FailSafeReason::StaleState);

#[test]
fn a_recorded_state_frame_resent_does_not_keep_the_board_fresh() {
    let (mut s, mut q) = running();
    let recorded = q.env(Msg::State(state(1)));
    s.on_envelope(&recorded);
    assert_eq!(status(&mut s), BoardStatus::Running);
    // The same frame, again and again, once per period: only its first copy counted.
    let mut statuses = Vec::new();
    for _ in 0..10 {
        s.on_envelope(&recorded);
        statuses.push(status(&mut s));
    }
    assert_eq!(&statuses[..2], &[BoardStatus::Running; 2]);
    assert!(statuses[2..].iter().all(|st| *st == STALE), "{statuses:?}");
}

#[test]
fn an_old_sequence_number_is_dropped() {
    let (mut s, mut q) = running();
    assert_eq!(status(&mut s), BoardStatus::Running);
    let last = s.step(false, NOW).telemetry.last_state_seq;
    // A state frame numbered before the last one accepted.
    s.on_envelope(&Envelope::new(last.wrapping_sub(1), Msg::State(state(2))));
    assert_eq!(s.step(false, NOW).telemetry.last_state_seq, last);
    // The next number is taken.
    q.give(&mut s, Msg::State(state(3)));
    assert_eq!(s.step(false, NOW).telemetry.last_state_seq, q.0);
}

/// Lock-step, armed, flying, state frames for ticks 0 and 1 taken (one period each).
fn lockstep_running() -> (Supervisor, Seq) {
    let mut s = supervisor();
    let mut q = Seq(0);
    q.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            lockstep: Some(true),
            ..ConfigPatch::EMPTY
        }),
    );
    assert!(s.lockstep());
    q.command(&mut s, Command::Arm);
    q.command(&mut s, Command::StartMission(CIRCLE));
    for k in 0..2 {
        q.give(&mut s, Msg::State(state(k)));
        assert_eq!(status(&mut s), BoardStatus::Running);
    }
    (s, q)
}

#[test]
fn lockstep_ticks_may_not_jump_forward() {
    let (mut s, mut q) = lockstep_running();
    let taken = q.0;
    let mut jump = state(2);
    jump.t_ticks = 1_000_000_000_000_000;
    q.give(&mut s, Msg::State(jump));
    assert_eq!(s.step(false, NOW).telemetry.last_state_seq, taken);
}

#[test]
fn lockstep_ticks_may_not_run_backwards() {
    let (mut s, mut q) = lockstep_running();
    let taken = q.0;
    // A newer frame number carrying an older tick (a delayed or replayed state).
    q.give(&mut s, Msg::State(state(0)));
    assert_eq!(s.step(false, NOW).telemetry.last_state_seq, taken);
}

#[test]
fn a_refused_config_patch_changes_nothing() {
    let (mut s, mut q) = running();
    // Armed: refused. Before the fix its stale_periods and lockstep were applied first.
    q.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            rate_hz: Some(50),
            stale_periods: Some(255),
            lockstep: Some(true),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(refused(&s), 1);
    assert!(!s.lockstep());
    assert_eq!(s.rate_hz(), 100);
    // The stale-state fail-safe still acts after the default 2 periods, not 255.
    let statuses: Vec<_> = (0..4).map(|_| status(&mut s)).collect();
    assert_eq!(
        statuses,
        [
            BoardStatus::Running,
            BoardStatus::Running,
            BoardStatus::Running,
            STALE
        ]
    );
}

#[test]
fn a_lone_arm_does_not_clear_a_latched_fail_safe() {
    let (mut s, mut q) = running();
    assert_eq!(
        s.step(true, NOW).telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::Overrun)
    );
    q.command(&mut s, Command::Arm);
    q.give(&mut s, Msg::State(state(2)));
    assert_eq!(
        status(&mut s),
        BoardStatus::FailSafe(FailSafeReason::Overrun)
    );
}

#[test]
fn disarm_drops_the_mission() {
    let (mut s, mut q) = running();
    assert_eq!(status(&mut s), BoardStatus::Running);
    q.command(&mut s, Command::Disarm);
    q.command(&mut s, Command::Arm);
    q.give(&mut s, Msg::State(state(2)));
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Armed);
    assert_eq!(st.voltages, [0.0; THRUSTERS]);
}

#[test]
fn start_mission_while_running_is_refused_and_the_trajectory_kept() {
    let (mut s, mut q) = running();
    let (mut reference, mut r) = running();
    for k in 1..5u64 {
        if k == 2 {
            q.command(
                &mut s,
                Command::StartMission(
                    MissionSpec::Circle {
                        radius: 20.0,
                        omega: 0.05,
                        depth: 8.0,
                    }
                    .into(),
                ),
            );
        }
        let a = s.step(false, NOW);
        let b = reference.step(false, NOW);
        assert_eq!(
            a.voltages, b.voltages,
            "period {k}: the trajectory was swapped"
        );
        q.give(&mut s, Msg::State(state(k)));
        r.give(&mut reference, Msg::State(state(k)));
    }
    assert_eq!(refused(&s), 1);
}

#[test]
fn the_fault_code_is_reported_in_every_latched_period() {
    let (mut s, mut q) = running();
    let mut bad = state(1);
    bad.nu[0] = f32::INFINITY;
    q.give(&mut s, Msg::State(bad));
    let first = s.step(false, NOW).telemetry;
    assert_eq!(
        first.status,
        BoardStatus::FailSafe(FailSafeReason::ControllerFault)
    );
    assert_ne!(first.controller_fault, 0);
    for _ in 0..3 {
        assert_eq!(
            s.step(false, NOW).telemetry.controller_fault,
            first.controller_fault
        );
    }
    // Also while disarmed, until the re-arm.
    q.command(&mut s, Command::Disarm);
    assert_eq!(
        s.step(false, NOW).telemetry.controller_fault,
        first.controller_fault
    );
    q.command(&mut s, Command::Arm);
    assert_eq!(s.step(false, NOW).telemetry.controller_fault, 0);
}

#[test]
fn a_voltage_limit_above_the_supply_is_refused() {
    let mut s = supervisor();
    let mut q = Seq(0);
    q.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            voltage_limit: Some(48.0),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(refused(&s), 1);
    assert_eq!(s.controller().config().voltage_limit, 24.0);
}

#[test]
fn an_absurd_loop_rate_is_refused() {
    let mut s = supervisor();
    let mut q = Seq(0);
    q.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            rate_hz: Some(u32::MAX),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(refused(&s), 1);
    assert_eq!(s.rate_hz(), 100);
}

// Issue 22's board defects. Like the ones above, each uses only the interface that predates its
// fix (here: the board's signed end of the link, `LinkBuffers`, and `common::Host`), so that it
// runs, and fails, on the code before the fix.

/// Issue 22, item 6: a peer holding the key stamped a frame at 2⁴⁸ − 1; the board, which
/// stamps above the last stamp it accepted, had no timestamp left to sign its telemetry with,
/// and its navigation computer's later frames were replays, until the board reset. Now the
/// board refuses that frame (above its ceiling, and far beyond the lead it allows), keeps
/// signing, and flies on its peer's frames.
#[test]
fn a_frame_stamped_at_the_last_timestamp_leaves_the_board_able_to_sign() {
    use auv_link::sign::MAX_TIMESTAMP;
    use common::{board_info, controller, Host, KEY};
    use firmware::board::LinkBuffers;

    let mut s = Supervisor::new(controller(), board_info(true));
    let mut link = LinkBuffers::signed(&KEY);
    let mut nav = Host::signed(&KEY);
    nav.send(&mut s, &mut link, Msg::Command(Command::Arm));
    nav.send(
        &mut s,
        &mut link,
        Msg::Command(Command::StartMission(CIRCLE)),
    );
    nav.send(&mut s, &mut link, Msg::State(state(0)));
    // Another key holder's state frame, newer in sequence, stamped 2⁴⁸ − 1.
    let mut wild = Host::signed(&KEY);
    wild.seq = nav.seq;
    if let Some(signer) = &mut wild.signer {
        signer.advance_to(MAX_TIMESTAMP - 1);
    }
    wild.send(&mut s, &mut link, Msg::State(state(1)));
    for k in 1..=6 {
        nav.send(&mut s, &mut link, Msg::State(state(k)));
        let step = s.step(false, NOW);
        assert_eq!(step.telemetry.status, BoardStatus::Running, "period {k}");
        let env = s.envelope(step.telemetry);
        assert!(
            link.encode(&env).is_ok(),
            "period {k}: telemetry not signed"
        );
    }
}
