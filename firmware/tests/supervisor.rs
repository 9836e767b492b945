//! The supervisor's fail-safe rules and the PWM mapping, on the host.

use auv_link::{
    BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason, MissionSpec, Msg, StateFrame,
    PROTOCOL_VERSION,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Table1Case, Trajectory};
use firmware::pwm;
use firmware::supervisor::Supervisor;

fn env(msg: Msg) -> Envelope {
    Envelope {
        version: PROTOCOL_VERSION,
        seq: 1,
        msg,
    }
}

fn state(k: u64) -> StateFrame {
    let d = Trajectory::table1(Table1Case::Circular10R).sample(k, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    StateFrame {
        t_ticks: k,
        eta: d.eta.into(),
        nu: nu.into(),
    }
}

fn running() -> Supervisor {
    let mut s = Supervisor::new(Controller::new(ControllerConfig::default()).unwrap());
    s.on_envelope(&env(Msg::Command(Command::Arm)));
    s.on_envelope(&env(Msg::Command(Command::StartMission(
        MissionSpec::Circle {
            radius: 10.0,
            omega: 0.1,
            depth: 5.0,
        },
    ))));
    s.on_envelope(&env(Msg::State(state(0))));
    s
}

const NOW: &dyn Fn() -> u32 = &|| 0;

#[test]
fn disarmed_and_armed_without_mission_keep_thrusters_off() {
    let mut s = Supervisor::new(Controller::new(ControllerConfig::default()).unwrap());
    s.on_envelope(&env(Msg::State(state(0))));
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Disarmed);
    assert_eq!(st.voltages, [0.0; 5]);
    s.on_envelope(&env(Msg::Command(Command::Arm)));
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Armed);
    assert_eq!(st.voltages, [0.0; 5]);
}

#[test]
fn stale_state_fails_safe_after_the_configured_periods_and_latches_until_rearm() {
    let mut s = running();
    assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Running);
    // Default 2 periods: the 1st and 2nd period without a frame still fly on the last one.
    assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Running);
    assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Running);
    let st = s.step(false, NOW);
    assert_eq!(
        st.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::StaleState)
    );
    assert_eq!(st.voltages, [0.0; 5]);
    // Frames return, but the fail-safe latches until disarm + arm.
    s.on_envelope(&env(Msg::State(state(4))));
    assert_eq!(
        s.step(false, NOW).telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::StaleState)
    );
    s.on_envelope(&env(Msg::Command(Command::Disarm)));
    s.on_envelope(&env(Msg::Command(Command::Arm)));
    s.on_envelope(&env(Msg::State(state(6))));
    assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Running);
}

#[test]
fn stale_period_count_is_configurable() {
    let mut s = running();
    s.on_envelope(&env(Msg::Command(Command::SetConfig(ConfigPatch {
        stale_periods: Some(5),
        ..Default::default()
    }))));
    for _ in 0..6 {
        assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Running);
    }
    assert_eq!(
        s.step(false, NOW).telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::StaleState)
    );
}

#[test]
fn controller_fault_and_overrun_fail_safe() {
    let mut s = running();
    let mut bad = state(1);
    bad.nu[0] = f32::INFINITY;
    s.on_envelope(&env(Msg::State(bad)));
    let st = s.step(false, NOW);
    assert_eq!(
        st.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::ControllerFault)
    );
    assert_ne!(st.telemetry.controller_fault, 0);
    assert_eq!(st.voltages, [0.0; 5]);

    let mut s = running();
    let st = s.step(true, NOW);
    assert_eq!(
        st.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::Overrun)
    );
    assert_eq!(st.telemetry.loop_overruns, 1);
}

#[test]
fn running_commands_the_controllers_voltages_and_reports_them() {
    let mut s = running();
    let st = s.step(false, NOW);
    assert_eq!(st.telemetry.status, BoardStatus::Running);
    assert_eq!(st.voltages, st.telemetry.voltages);
    assert!(st.voltages.iter().any(|v| *v != 0.0));
    assert!(st.telemetry.delta > 0.0);
}

#[test]
fn config_changes_only_while_disarmed_and_only_if_valid() {
    let mut s = running();
    let patch = |rate| {
        env(Msg::Command(Command::SetConfig(ConfigPatch {
            rate_hz: Some(rate),
            ..Default::default()
        })))
    };
    s.on_envelope(&patch(50));
    assert_eq!(s.rate_hz(), 100, "armed: refused");
    assert_eq!(s.rejected_commands(), 1);
    s.on_envelope(&env(Msg::Command(Command::Disarm)));
    s.on_envelope(&patch(50));
    assert_eq!(s.rate_hz(), 50);
    s.on_envelope(&patch(5)); // violates the loop-rate check of docs/design.md §8
    assert_eq!(s.rate_hz(), 50);
    assert_eq!(s.rejected_commands(), 2);
}

#[test]
fn an_invalid_mission_is_rejected_not_flown() {
    let mut s = Supervisor::new(Controller::new(ControllerConfig::default()).unwrap());
    s.on_envelope(&env(Msg::Command(Command::Arm)));
    s.on_envelope(&env(Msg::Command(Command::StartMission(
        MissionSpec::Circle {
            radius: -1.0,
            omega: 0.1,
            depth: 5.0,
        },
    ))));
    assert_eq!(s.rejected_commands(), 1);
    s.on_envelope(&env(Msg::State(state(0))));
    assert_eq!(s.step(false, NOW).telemetry.status, BoardStatus::Armed);
}

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
