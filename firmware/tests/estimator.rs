//! The state estimator on the board (docs/law.md#the-state-estimator, docs/board.md): the
//! supervisor takes the estimator's settings by `SetConfig` (protocol 7), computes the gains
//! while disarmed, and flies `update_from_solution` as the host's core does on the same
//! solutions (PIL = SIL on the host); a solution that stops (a repeated lock-step stamp), or
//! a period without a fresh one, is predicted forward and then latches the stale-state
//! fail-safe (Choice 362).

mod common;

use auv_link::{BoardStatus, Command, ConfigPatch, FailSafeReason, Msg, StateFrame};
use common::{state, supervisor, Host, CIRCLE, NOW};
use controller_core::{
    Controller, ControllerConfig, Estimate, EstimatorKind, Solution, Trajectory,
};
use firmware::supervisor::Supervisor;

fn estimator_config() -> ControllerConfig {
    let mut c = ControllerConfig::default();
    c.estimator.kind = EstimatorKind::Kalman;
    c
}

/// A state frame on the circle at tick `k` with a deterministic error of a few millimetres
/// and milliradians (a navigation solution, not the truth).
fn noisy(k: u64) -> StateFrame {
    let mut s = state(k);
    let x = k as f32;
    for i in 0..6 {
        let phase = 0.37 * x * (i as f32 + 1.0) + i as f32;
        let scale = if i < 3 { 0.005 } else { 0.001 };
        s.eta[i] += scale * libm::sinf(phase);
        s.nu[i] += 0.4 * scale * libm::cosf(1.3 * phase);
    }
    s
}

/// Configured with the estimator on (`lockstep` pacing), armed, flying the circle.
fn flying(lockstep: bool) -> (Supervisor, Host, Controller) {
    let mut s = supervisor();
    let mut h = Host::new();
    let cfg = estimator_config();
    let whole = ConfigPatch::whole(&cfg, 2, lockstep);
    h.command(&mut s, Command::SetConfig(whole));
    assert_eq!(s.last_refusal(), None, "the estimator's settings taken");
    assert_eq!(s.controller().config().estimator, cfg.estimator);
    assert_eq!(s.config_digest(), whole.digest().unwrap());
    s.step(false, NOW); // the rebuild's period (the long job)
    h.command(&mut s, Command::Arm);
    h.command(&mut s, Command::StartMission(CIRCLE));
    (s, h, Controller::new(cfg).unwrap())
}

fn circle() -> Trajectory {
    let mission: controller_core::Mission = CIRCLE.try_into().unwrap();
    Trajectory::new(mission).unwrap()
}

/// The host's core on `solution` at `ticks`: the voltages the board must command.
fn host_voltages(
    c: &Controller,
    memory: &mut Estimate,
    ticks: u64,
    stamp: u64,
    f: &StateFrame,
) -> [f32; 5] {
    let solution = Solution {
        stamp,
        eta: f.eta,
        nu: f.nu,
    };
    let out = c.update_from_solution(memory, ticks, &solution, &circle());
    assert!(out.status == controller_core::Status::Ok, "{out:?}");
    out.voltage
}

fn bits(v: &[f32; 5]) -> [u32; 5] {
    v.map(f32::to_bits)
}

/// Gives the board frame `k` of the noisy solution and runs its period: the board is running
/// and commands what the host's core commands at tick `k` (SIL); returns those voltages.
fn fly_frame_as_sil(
    s: &mut Supervisor,
    h: &mut Host,
    c: &Controller,
    memory: &mut Estimate,
    k: u64,
) -> [f32; 5] {
    let f = noisy(k);
    h.give(s, Msg::State(f));
    let step = s.step(false, NOW);
    assert_eq!(step.telemetry.status, BoardStatus::Running, "tick {k}");
    let want = host_voltages(c, memory, k, k, &f);
    assert_eq!(bits(&step.voltages), bits(&want), "tick {k}");
    want
}

#[test]
fn the_board_flies_the_estimator_as_the_host_core_does() {
    let (mut s, mut h, c) = flying(true);
    let mut memory = Estimate::new();
    let mut differs = 0;
    for k in 0..200 {
        let want = fly_frame_as_sil(&mut s, &mut h, &c, &mut memory, k);
        let f = noisy(k);
        // The law on the raw solution commands something else: the board does filter.
        let raw = c.update(k, &f.eta, &f.nu, &circle()).voltage;
        differs += usize::from(bits(&raw) != bits(&want));
    }
    assert!(
        differs > 150,
        "only {differs} of 200 periods differ from the raw law"
    );
}

#[test]
fn a_repeated_lock_step_stamp_is_dropped_predicted_then_latches_stale_state() {
    let (mut s, mut h, c) = flying(true);
    let mut memory = Estimate::new();
    for k in 0..50 {
        fly_frame_as_sil(&mut s, &mut h, &c, &mut memory, k);
    }
    // The navigation computer's solution stops: it repeats tick 49's frame (new sequence
    // numbers). Off the mission clock: counted and dropped, so the board flies tick 49's
    // solution predicted 1, then 2 periods forward, then latches.
    let last = noisy(49);
    for age in 1..=2u64 {
        let stale_before = s.rx_stale();
        h.give(&mut s, Msg::State(last));
        assert_eq!(
            s.rx_stale(),
            stale_before + 1,
            "the repeated stamp is dropped"
        );
        let step = s.step(false, NOW);
        assert_eq!(step.telemetry.status, BoardStatus::Running, "age {age}");
        let want = host_voltages(&c, &mut memory, 49 + age, 49, &last);
        assert_eq!(bits(&step.voltages), bits(&want), "age {age}");
    }
    h.give(&mut s, Msg::State(last));
    let step = s.step(false, NOW);
    assert_eq!(
        step.telemetry.status,
        BoardStatus::FailSafe(FailSafeReason::StaleState)
    );
    assert_eq!(step.voltages, [0.0; 5]);
}

#[test]
fn a_late_frame_free_running_is_predicted_over_the_periods_it_missed() {
    let (mut s, mut h, c) = flying(false);
    let mut memory = Estimate::new();
    // Free-running: mission time is the board's own periods since StartMission; the frame of
    // a period holds at that period.
    for k in 0..30 {
        fly_frame_as_sil(&mut s, &mut h, &c, &mut memory, k);
    }
    // Period 30's frame is late: the board flies period 29's solution one period old, ...
    let step = s.step(false, NOW);
    let want = host_voltages(&c, &mut memory, 30, 29, &noisy(29));
    assert_eq!(bits(&step.voltages), bits(&want));
    // ... and takes it when it arrives, in period 31, as that period's.
    let f = noisy(30);
    h.give(&mut s, Msg::State(f));
    let step = s.step(false, NOW);
    assert_eq!(
        bits(&step.voltages),
        bits(&host_voltages(&c, &mut memory, 31, 31, &f))
    );
}

#[test]
fn a_new_mission_starts_the_estimate_afresh() {
    let (mut s, mut h, c) = flying(true);
    for k in 0..20 {
        h.give(&mut s, Msg::State(noisy(k)));
        s.step(false, NOW);
    }
    h.command(&mut s, Command::StopMission);
    s.step(false, NOW);
    h.command(&mut s, Command::StartMission(CIRCLE));
    // The new mission's first frame is its tick 0: the estimate starts from it, as a fresh
    // memory on the host does (the old mission's memory would predict from tick 19).
    let f = noisy(0);
    h.give(&mut s, Msg::State(f));
    let step = s.step(false, NOW);
    let want = host_voltages(&c, &mut Estimate::new(), 0, 0, &f);
    assert_eq!(bits(&step.voltages), bits(&want));
}

#[test]
fn an_estimator_setting_the_core_refuses_is_refused_whole() {
    let mut s = supervisor();
    let mut h = Host::new();
    let mut cfg = estimator_config();
    cfg.estimator.accel_sigma[2] = -1.0;
    h.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            estimator: Some(cfg.estimator.into()),
            rate_hz: Some(200),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.last_refusal(), Some(auv_link::Refusal::ControllerConfig));
    assert_eq!(s.controller().config().estimator.kind, EstimatorKind::Off);
    assert_eq!(s.rate_hz(), 100, "nothing of the patch applied");
}

/// Lock-step PIL: the board's virtual clock sometimes runs a period before the host's next
/// frame arrives (the host skips that period's answer). The repeat predicts tick k's frame
/// to k + 1 and records its thrust for k + 1; frame k + 1 then flies k + 1 again and must
/// command exactly what SIL (one period per frame) commands, and so must every frame after.
#[test]
fn a_lock_step_period_without_a_frame_leaves_the_next_frames_as_sil_flies_them() {
    let (mut s, mut h, c) = flying(true);
    let mut memory = Estimate::new();
    for k in 0..120 {
        fly_frame_as_sil(&mut s, &mut h, &c, &mut memory, k);
        if k % 7 == 3 {
            // The board's timer runs out before frame k + 1: a repeat of frame k.
            let repeat = s.step(false, NOW);
            assert_eq!(repeat.telemetry.status, BoardStatus::Running, "repeat {k}");
        }
    }
}
