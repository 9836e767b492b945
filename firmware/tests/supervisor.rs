//! The supervisor's fail-safe rules, frame order, mission clock, configuration checks and
//! refusals, and the PWM mapping, on the host. (The state table is walked cell by cell in
//! `state_table.rs`; the defects of issue 10 each have a test in `regressions.rs`.)

use auv_link::seq::SEQ_WINDOW;
use auv_link::{
    BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason, MissionSpec, Msg, Refusal,
    Telemetry,
};
use controller_core::effectiveness::THRUSTERS;
use firmware::limits::{MAX_RATE_HZ, MAX_STALE_MS};
use firmware::pwm;
use firmware::supervisor::{Mode, Supervisor};

mod common;
use common::{running, state, supervisor, Host, CIRCLE, NOW, SUPPLY};

fn status(s: &mut Supervisor) -> BoardStatus {
    s.step(false, NOW).telemetry.status
}

fn telemetry(s: &mut Supervisor) -> Telemetry {
    s.step(false, NOW).telemetry
}

const STALE: BoardStatus = BoardStatus::FailSafe(FailSafeReason::StaleState);

fn patch(p: ConfigPatch) -> Command {
    Command::SetConfig(p)
}

#[test]
fn disarmed_and_armed_without_mission_keep_thrusters_off() {
    let mut s = supervisor();
    let mut h = Host::new();
    h.give(&mut s, Msg::State(state(0)));
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Disarmed);
    assert_eq!(st.voltages, [0.0; THRUSTERS]);
    h.command(&mut s, Command::Arm);
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Armed);
    assert_eq!(st.voltages, [0.0; THRUSTERS]);
}

#[test]
fn stale_state_fails_safe_after_the_configured_periods_and_latches_until_rearm() {
    let (mut s, mut h) = running();
    assert_eq!(status(&mut s), BoardStatus::Running);
    // Default 2 periods: the 1st and 2nd period without a frame still fly on the last one.
    assert_eq!(status(&mut s), BoardStatus::Running);
    assert_eq!(status(&mut s), BoardStatus::Running);
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, STALE);
    assert_eq!(st.voltages, [0.0; THRUSTERS]);
    // Frames return, but the fail-safe latches until disarm + arm, and a mission is started
    // again (disarming dropped it).
    h.give(&mut s, Msg::State(state(4)));
    assert_eq!(status(&mut s), STALE);
    h.command(&mut s, Command::Disarm);
    h.command(&mut s, Command::Arm);
    h.give(&mut s, Msg::State(state(6)));
    assert_eq!(status(&mut s), BoardStatus::Armed);
    h.command(&mut s, Command::StartMission(CIRCLE));
    assert_eq!(status(&mut s), BoardStatus::Running);
}

#[test]
fn stale_period_count_is_configurable_while_disarmed() {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(
        &mut s,
        patch(ConfigPatch {
            stale_periods: Some(5),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.stale_periods(), 5);
    h.command(&mut s, Command::Arm);
    h.command(&mut s, Command::StartMission(CIRCLE));
    h.give(&mut s, Msg::State(state(0)));
    for _ in 0..6 {
        assert_eq!(status(&mut s), BoardStatus::Running);
    }
    assert_eq!(status(&mut s), STALE);
}

#[test]
fn controller_fault_and_overrun_fail_safe() {
    let (mut s, mut h) = running();
    let mut bad = state(1);
    bad.nu[0] = f32::INFINITY;
    h.give(&mut s, Msg::State(bad));
    let st = s.step(false, NOW);
    assert_eq!(
        st.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::ControllerFault)
    );
    assert_ne!(st.telemetry.controller_fault, 0);
    assert_eq!(st.voltages, [0.0; THRUSTERS]);

    let (mut s, _) = running();
    let st = s.step(true, NOW);
    assert_eq!(
        st.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::Overrun)
    );
    assert_eq!(st.telemetry.loop_overruns, 1);
}

#[test]
fn running_commands_the_controllers_voltages_and_reports_them() {
    let (mut s, _) = running();
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Running);
    assert_eq!(st.voltages, st.telemetry.voltages);
    assert!(st.voltages.iter().any(|v| *v != 0.0));
    assert!(st.telemetry.delta > 0.0);
}

#[test]
fn the_latched_reason_is_in_every_frame_until_rearmed() {
    let (mut s, mut h) = running();
    s.step(true, NOW);
    let overrun = Some(FailSafeReason::Overrun);
    for _ in 0..3 {
        assert_eq!(telemetry(&mut s).latched, overrun);
    }
    h.command(&mut s, Command::Disarm);
    let t = telemetry(&mut s);
    assert_eq!((t.status, t.latched), (BoardStatus::Disarmed, overrun));
    assert_eq!(s.mode(), Mode::DisarmedLatched);
    h.command(&mut s, Command::Arm);
    let t = telemetry(&mut s);
    assert_eq!((t.status, t.latched), (BoardStatus::Armed, None));
}

// ---------------------------------------------------------------------------------------------
// Refusals

#[test]
fn every_refusal_is_counted_and_its_reason_reported_in_telemetry() {
    let mut s = supervisor();
    let mut h = Host::new();
    let t = telemetry(&mut s);
    assert_eq!((t.refused_commands, t.last_refusal), (0, None));
    let cases = [
        (Command::StartMission(CIRCLE), Refusal::NotArmed),
        (
            patch(ConfigPatch {
                rate_hz: Some(MAX_RATE_HZ + 1),
                ..ConfigPatch::EMPTY
            }),
            Refusal::RateTooHigh,
        ),
        (
            patch(ConfigPatch {
                voltage_limit: Some(SUPPLY + 0.01),
                ..ConfigPatch::EMPTY
            }),
            Refusal::VoltageAboveSupply,
        ),
        (
            patch(ConfigPatch {
                stale_periods: Some(0),
                ..ConfigPatch::EMPTY
            }),
            Refusal::StaleLimit,
        ),
        (
            patch(ConfigPatch {
                // Inside the stale limit (2 periods = 200 ms), but too slow for the loop-rate
                // rule of docs/law.md#the-loop-rate-rule (> 21.5 Hz at the defaults).
                rate_hz: Some(10),
                ..ConfigPatch::EMPTY
            }),
            Refusal::ControllerConfig,
        ),
        (
            patch(ConfigPatch {
                delta_max: Some(f32::NAN),
                ..ConfigPatch::EMPTY
            }),
            Refusal::ControllerConfig,
        ),
        (
            patch(ConfigPatch {
                voltage_limit: Some(f32::NAN),
                ..ConfigPatch::EMPTY
            }),
            Refusal::ControllerConfig,
        ),
    ];
    for (i, (c, why)) in cases.into_iter().enumerate() {
        h.command(&mut s, c);
        let t = telemetry(&mut s);
        assert_eq!(t.refused_commands, i as u32 + 1, "{c:?}");
        assert_eq!(t.last_refusal, Some(why), "{c:?}");
    }
    // Armed: the state checks.
    h.command(&mut s, Command::Arm);
    h.command(&mut s, Command::SetConfig(ConfigPatch::EMPTY));
    assert_eq!(s.last_refusal(), Some(Refusal::WhileArmed));
    h.command(
        &mut s,
        Command::StartMission(
            MissionSpec::Circle {
                radius: -1.0,
                omega: 0.1,
                depth: 5.0,
            }
            .into(),
        ),
    );
    assert_eq!(s.last_refusal(), Some(Refusal::InvalidMission));
    h.command(&mut s, Command::StartMission(CIRCLE));
    h.command(&mut s, Command::StartMission(CIRCLE));
    assert_eq!(s.last_refusal(), Some(Refusal::MissionRunning));
    s.step(true, NOW);
    h.command(&mut s, Command::Arm);
    assert_eq!(s.last_refusal(), Some(Refusal::Latched));
    h.command(&mut s, Command::StopMission);
    h.command(&mut s, Command::StartMission(CIRCLE));
    assert_eq!(s.last_refusal(), Some(Refusal::Latched));
    assert_eq!(s.refused_commands(), 12);
}

#[test]
fn a_config_patch_is_validated_whole_and_applied_whole() {
    let mut s = supervisor();
    let mut h = Host::new();
    // A valid rate with a bad voltage: nothing of it applies.
    h.command(
        &mut s,
        patch(ConfigPatch {
            rate_hz: Some(50),
            stale_periods: Some(3),
            lockstep: Some(true),
            voltage_limit: Some(30.0),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.last_refusal(), Some(Refusal::VoltageAboveSupply));
    assert_eq!(
        (s.rate_hz(), s.stale_periods(), s.lockstep()),
        (100, 2, false)
    );
    // The same without the bad field: all of it applies.
    h.command(
        &mut s,
        patch(ConfigPatch {
            rate_hz: Some(50),
            stale_periods: Some(3),
            lockstep: Some(true),
            voltage_limit: Some(20.0),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.refused_commands(), 1);
    assert_eq!(
        (s.rate_hz(), s.stale_periods(), s.lockstep()),
        (50, 3, true)
    );
    assert_eq!(s.controller().config().voltage_limit, 20.0);
    // The voltage limit at exactly the supply is allowed.
    h.command(
        &mut s,
        patch(ConfigPatch {
            voltage_limit: Some(SUPPLY),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.refused_commands(), 1);
}

/// Protocol 6 (issue 29, item 14; Choice 228): every telemetry frame carries the digest of the
/// whole configuration the board flies, so the navigation computer confirms every field it set.
/// A board that took a whole patch reports that patch's digest; a partial patch moves it to
/// the digest of the whole result; a refused one leaves it; and a board that reset (its
/// watchdog) reports its defaults', which a host that configured it sees at once.
#[test]
fn telemetry_reports_the_digest_of_the_whole_configuration_flown() {
    let mut s = supervisor();
    let mut h = Host::new();
    let boot = telemetry(&mut s);
    let defaults = ConfigPatch::whole(&controller_core::ControllerConfig::default(), 2, false);
    assert_eq!(Some(boot.config_digest), defaults.digest());
    // A whole patch, as host-sim's set-up sends it: confirmed field for field.
    let sent = ConfigPatch {
        rate_hz: Some(50),
        robust: Some(false),
        delta_max: Some(2.0),
        voltage_limit: Some(20.0),
        stale_periods: Some(3),
        lockstep: Some(true),
        ..defaults
    };
    h.command(&mut s, patch(sent));
    let t = telemetry(&mut s);
    assert_eq!(t.refused_commands, 0);
    assert_eq!(sent.confirm(&t), Ok(()));
    // A board reset to its defaults does not confirm it.
    assert!(sent.confirm(&boot).is_err());
    // Refused: unchanged.
    h.command(
        &mut s,
        patch(ConfigPatch {
            rate_hz: Some(MAX_RATE_HZ + 1),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(Some(telemetry(&mut s).config_digest), sent.digest());
    // A partial patch: the whole result's digest.
    h.command(
        &mut s,
        patch(ConfigPatch {
            stale_periods: Some(4),
            ..ConfigPatch::EMPTY
        }),
    );
    let t = telemetry(&mut s);
    let now = ConfigPatch {
        stale_periods: Some(4),
        ..sent
    };
    assert_eq!(Some(t.config_digest), now.digest());
    assert_ne!(Some(t.config_digest), sent.digest());
}

#[test]
fn the_stale_limit_is_checked_in_time_at_the_resulting_rate() {
    let mut s = supervisor();
    let mut h = Host::new();
    let max_at_100 = (MAX_STALE_MS / 10) as u8; // periods of 10 ms
    h.command(
        &mut s,
        patch(ConfigPatch {
            stale_periods: Some(max_at_100),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.stale_periods(), max_at_100);
    h.command(
        &mut s,
        patch(ConfigPatch {
            stale_periods: Some(max_at_100 + 1),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.last_refusal(), Some(Refusal::StaleLimit));
    // Halving the rate doubles the time the same count allows: refused as a whole.
    h.command(
        &mut s,
        patch(ConfigPatch {
            rate_hz: Some(50),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.last_refusal(), Some(Refusal::StaleLimit));
    assert_eq!((s.rate_hz(), s.refused_commands()), (100, 2));
}

#[test]
fn the_maximum_rate_is_accepted_and_one_more_is_not() {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(
        &mut s,
        patch(ConfigPatch {
            rate_hz: Some(MAX_RATE_HZ),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!((s.rate_hz(), s.refused_commands()), (MAX_RATE_HZ, 0));
    for rate in [MAX_RATE_HZ + 1, 1_000_000, u32::MAX] {
        h.command(
            &mut s,
            patch(ConfigPatch {
                rate_hz: Some(rate),
                ..ConfigPatch::EMPTY
            }),
        );
        assert_eq!(s.last_refusal(), Some(Refusal::RateTooHigh));
        assert_eq!(s.rate_hz(), MAX_RATE_HZ);
    }
}

// ---------------------------------------------------------------------------------------------
// Frame order

#[test]
fn repeated_old_and_far_ahead_frames_are_counted_and_never_refresh() {
    let (mut s, h) = running();
    let now = h.seq;
    assert_eq!(status(&mut s), BoardStatus::Running);
    for seq in [now, now - 1, now.wrapping_add(SEQ_WINDOW + 1)] {
        s.on_envelope(&Envelope::new(seq, Msg::State(state(1))));
    }
    let t = telemetry(&mut s);
    assert_eq!((t.rx_stale, t.rx_frames, t.last_rx_seq), (3, 3, now));
    // None of them restarted the stale timer: the third period after the last good frame
    // fails safe.
    assert_eq!(status(&mut s), BoardStatus::Running);
    assert_eq!(status(&mut s), STALE);
    // A dropped command does nothing either.
    s.on_envelope(&Envelope::new(now, Msg::Command(Command::Disarm)));
    assert_eq!(s.mode(), Mode::FailSafe);
}

#[test]
fn sequence_numbers_wrap_around() {
    let (mut s, mut h) = running();
    h.seq = u16::MAX - 3;
    // The jump from 3 to 65532 is behind (RFC 1982): dropped, so resync first as a
    // restarted host does, from the board's last_rx_seq.
    h.give(&mut s, Msg::State(state(1)));
    assert_eq!(s.rx_stale(), 1);
    h.seq = telemetry(&mut s).last_rx_seq;
    for k in 2..12u64 {
        h.give(&mut s, Msg::State(state(k)));
        assert_eq!(status(&mut s), BoardStatus::Running, "seq {}", h.seq);
    }
    assert_eq!(s.rx_stale(), 1);
    // Across the wrap.
    let mut s = supervisor();
    let mut h = Host::new();
    h.seq = u16::MAX - 1;
    h.command(&mut s, Command::Arm);
    h.command(&mut s, Command::StartMission(CIRCLE));
    for k in 0..5u64 {
        h.give(&mut s, Msg::State(state(k)));
        assert_eq!(status(&mut s), BoardStatus::Running, "seq {}", h.seq);
    }
    assert_eq!((s.rx_stale(), s.rx_frames()), (0, 7));
}

#[test]
fn telemetry_sent_to_the_board_is_a_receive_error() {
    let mut s = supervisor();
    let t = telemetry(&mut s);
    s.on_envelope(&Envelope::new(1, Msg::Telemetry(t)));
    let t = telemetry(&mut s);
    assert_eq!((t.rx_errors, t.rx_frames, t.last_rx_seq), (1, 0, 0));
}

// ---------------------------------------------------------------------------------------------
// The lock-step mission clock

fn lockstep() -> (Supervisor, Host) {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(
        &mut s,
        patch(ConfigPatch {
            lockstep: Some(true),
            ..ConfigPatch::EMPTY
        }),
    );
    h.command(&mut s, Command::Arm);
    (s, h)
}

/// Gives a state frame for tick `k`; true if it was taken.
fn taken(s: &mut Supervisor, h: &mut Host, k: u64) -> bool {
    let before = s.rx_frames();
    h.give(s, Msg::State(state(k)));
    s.rx_frames() == before + 1
}

#[test]
fn the_mission_clock_takes_one_tick_per_period() {
    let (mut s, mut h) = lockstep();
    // Before the mission, state frames carry no mission tick.
    assert!(taken(&mut s, &mut h, 12345));
    h.command(&mut s, Command::StartMission(CIRCLE));
    // The mission's first frame sets the clock (here where a mission resumes, tick 300); then
    // one frame a period, one tick each.
    for k in 300..320 {
        assert!(taken(&mut s, &mut h, k));
        assert!(!taken(&mut s, &mut h, k + 1), "two frames in one period");
        assert_eq!(status(&mut s), BoardStatus::Running);
    }
    assert_eq!(s.rx_stale(), 20);
}

#[test]
fn the_mission_clock_allows_frames_lost_on_the_link_but_no_more() {
    let (mut s, mut h) = lockstep();
    h.command(&mut s, Command::StartMission(CIRCLE));
    assert!(taken(&mut s, &mut h, 0));
    assert_eq!(status(&mut s), BoardStatus::Running);
    // Frame 1 lost: the board's wait ends after a period, which it flies on frame 0.
    assert_eq!(status(&mut s), BoardStatus::Running);
    // Two periods since frame 0: tick 3 is too far ahead, tick 2 is on the clock.
    assert!(!taken(&mut s, &mut h, 3));
    assert!(taken(&mut s, &mut h, 2));
    assert_eq!(status(&mut s), BoardStatus::Running);
    // A slow host: a period without a frame, then the next tick (1 in 2 periods) is taken.
    assert_eq!(status(&mut s), BoardStatus::Running);
    assert!(taken(&mut s, &mut h, 3));
    // Backwards and standing still: never.
    assert_eq!(status(&mut s), BoardStatus::Running);
    assert!(!taken(&mut s, &mut h, 3));
    assert!(!taken(&mut s, &mut h, 2));
    assert!(!taken(&mut s, &mut h, u64::MAX));
    assert!(taken(&mut s, &mut h, 4));
}

#[test]
fn the_mission_time_in_lockstep_is_the_frames_tick() {
    // The board flies tick k's reference at tick k, as SIL does, whatever its own count.
    let (mut s, mut h) = lockstep();
    h.command(&mut s, Command::StartMission(CIRCLE));
    let ctl = s.controller().clone();
    let traj = controller_core::Trajectory::table1(controller_core::Table1Case::Circular10R);
    for k in [0u64, 1, 3, 4] {
        if k == 3 {
            status(&mut s); // a lost frame
        }
        let f = state(k);
        assert!(taken(&mut s, &mut h, k));
        let got = s.step(false, NOW);
        assert_eq!(got.voltages, ctl.update(k, &f.eta, &f.nu, &traj).voltage);
    }
}

#[test]
fn start_mission_in_lockstep_drops_the_state_held_from_before() {
    let (mut s, mut h) = lockstep();
    assert!(taken(&mut s, &mut h, 5_000));
    h.command(&mut s, Command::StartMission(CIRCLE));
    // No state on the mission's clock yet: the board does not fly the mission at tick 5000.
    // It waits `stale_periods` periods (2) with the thrusters off, then fails safe.
    for _ in 0..=2 {
        let st = s.step(false, NOW);
        assert_eq!(st.telemetry.status, BoardStatus::Running);
        assert_eq!(st.voltages, [0.0; THRUSTERS]);
    }
    assert_eq!(status(&mut s), STALE);
}

/// Regression (issue 29, item 16): free-running, after a state frame and a pause longer than
/// `stale_periods`, `Arm` + `StartMission` latched `fail-safe: stale state` in the mission's
/// first period: the old frame was kept (only lock-step dropped it). A new mission counts from
/// its start (Choice 227): it waits `stale_periods` periods for its first state with the
/// thrusters off, flies on it, and fails safe only if none comes.
#[test]
fn start_mission_free_running_drops_the_state_held_from_before() {
    for first_state in [true, false] {
        let mut s = supervisor();
        let mut h = Host::new();
        assert!(!s.lockstep());
        h.command(&mut s, Command::Arm);
        h.give(&mut s, Msg::State(state(0)));
        assert_eq!(status(&mut s), BoardStatus::Armed);
        // A pause: the board sits armed with no mission, no state comes.
        for _ in 0..10 {
            assert_eq!(status(&mut s), BoardStatus::Armed);
        }
        h.command(&mut s, Command::StartMission(CIRCLE));
        let st = s.step(false, NOW);
        assert_eq!(
            st.telemetry.status,
            BoardStatus::Running,
            "its first period"
        );
        assert_eq!(st.telemetry.latched, None);
        assert_eq!(st.voltages, [0.0; THRUSTERS], "no state of its own yet");
        if first_state {
            h.give(&mut s, Msg::State(state(1)));
            let flying = s.step(false, NOW);
            assert_eq!(flying.telemetry.status, BoardStatus::Running);
            assert!(flying.voltages.iter().any(|v| *v != 0.0), "flies on it");
        } else {
            // The grace is `stale_periods` periods after the first, then the latch.
            for _ in 0..2 {
                assert_eq!(status(&mut s), BoardStatus::Running);
            }
            assert_eq!(status(&mut s), STALE);
        }
    }
}

/// Regression (issue 12, seen once in four CI runs of the real-chain PIL): `StartMission` and
/// the mission's first state frame can reach the board either side of a period edge. The
/// supervisor latched a stale-state fail-safe in that period, at t = 0; the mission now gets
/// the same `stale_periods` grace as a state that stops arriving.
#[test]
fn start_mission_and_its_first_state_may_straddle_a_period() {
    let (mut s, mut h) = lockstep();
    h.command(&mut s, Command::StartMission(CIRCLE));
    let idle = s.step(false, NOW);
    assert_eq!(idle.telemetry.status, BoardStatus::Running);
    assert_eq!(idle.voltages, [0.0; THRUSTERS]);
    let ctl = s.controller().clone();
    let traj = controller_core::Trajectory::table1(controller_core::Table1Case::Circular10R);
    let f = state(0);
    assert!(taken(&mut s, &mut h, 0));
    let flying = s.step(false, NOW);
    assert_eq!(flying.telemetry.status, BoardStatus::Running);
    assert_eq!(flying.voltages, ctl.update(0, &f.eta, &f.nu, &traj).voltage);
}

// ---------------------------------------------------------------------------------------------
// PWM

#[test]
fn pwm_duty_is_linear_with_neutral_at_half() {
    assert_eq!(pwm::duty_counts(0.0, 24.0, 1000), 500);
    assert_eq!(pwm::duty_counts(24.0, 24.0, 1000), 1000);
    assert_eq!(pwm::duty_counts(-24.0, 24.0, 1000), 0);
    assert_eq!(pwm::duty_counts(12.0, 24.0, 1000), 750);
    assert_eq!(pwm::duty_counts(100.0, 24.0, 1000), 1000);
    assert_eq!(pwm::duty_counts(f32::NAN, 24.0, 1000), 500);
    assert_eq!(pwm::duty_counts(5.0, 0.0, 1000), 500);
    // Mean motor voltage (2d − 1)·V_s reproduces V to a count.
    for v in [-23.0f32, -7.5, 0.3, 11.0, 19.9] {
        let d = pwm::duty_counts(v, 24.0, 10_000) as f32 / 10_000.0;
        assert!(((2.0 * d - 1.0) * 24.0 - v).abs() <= 24.0 / 10_000.0 * 2.0);
    }
}
