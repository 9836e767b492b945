//! `Controller::update` end to end: fail-safe behaviour, δ clamp, no non-finite output for any
//! input, and the closed loop on the exact nominal model against the closed-form error decay.
// Tests change one field of the defaults at a time; that reads best as an assignment.
#![allow(clippy::field_reassign_with_default)]

use controller_core::controller::MAX_POSITION;
use controller_core::effectiveness::THRUSTERS;
use controller_core::kinematics::{self, Attitude};
use controller_core::model::{self, VehicleParams};
use controller_core::{Controller, ControllerConfig, Fault, Status, Table1Case, Trajectory};
use nalgebra::Vector6;
use proptest::prelude::*;

fn controller() -> Controller {
    Controller::new(ControllerConfig::default()).unwrap()
}

/// On the reference: η = η_d, ν = J⁻¹η̇_d.
fn on_reference(tr: &Trajectory, ticks: u64) -> ([f32; 6], [f32; 6]) {
    let d = tr.sample(ticks, 100);
    let a = Attitude::from_eta_f32(&d.eta);
    let nu = kinematics::jacobian_inv(&a) * d.eta_dot;
    (d.eta.into(), nu.into())
}

#[test]
fn on_the_reference_the_errors_and_w_vanish_and_delta_is_the_model_bound() {
    let c = controller();
    // micromath's sin/cos (≈ 1e-3) make J and J⁻¹ only approximately consistent.
    let tol = if cfg!(feature = "micromath") {
        2e-3
    } else {
        1e-4
    };
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        for ticks in [0u64, 1234, 6999] {
            let (eta, nu) = on_reference(&tr, ticks);
            let out = c.update(ticks, &eta, &nu, &tr);
            assert_eq!(out.status, Status::Ok);
            assert!(out.w_norm < tol, "{case:?}: ‖w‖ = {}", out.w_norm);
            assert!(out.e1.iter().all(|e| e.abs() < tol));
            // δ stays in single digits on the paper's missions with the controlled-rows bound (docs/law.md#the-uncertainty-bound-eq-29).
            assert!(
                out.delta > 1.0 && out.delta < 10.0,
                "{case:?}: δ = {}",
                out.delta
            );
            assert!(!out.delta_clamped);
        }
    }
}

#[test]
fn a_large_offset_clamps_delta_and_says_so() {
    let c = controller();
    let tr = Trajectory::table1(Table1Case::Circular10R);
    let (mut eta, nu) = on_reference(&tr, 0);
    eta[0] += 10.0;
    let out = c.update(0, &eta, &nu, &tr);
    assert_eq!(out.status, Status::Ok);
    assert!(out.delta_clamped);
    assert_eq!(out.delta, c.config().delta_max);
    // Δu pushes back along −x: the commanded surge force is negative and large.
    assert!(out.tau[0] < -1000.0, "X = {}", out.tau[0]);
}

#[test]
fn without_delta_u_the_clamp_is_never_reported() {
    let mut cfg = ControllerConfig::default();
    cfg.robust = false;
    let c = Controller::new(cfg).unwrap();
    let tr = Trajectory::table1(Table1Case::Circular10R);
    let (mut eta, nu) = on_reference(&tr, 0);
    eta[0] += 10.0;
    let out = c.update(0, &eta, &nu, &tr);
    assert!(!out.delta_clamped);
    // ū alone, at t = 0 where ψ = 0, ν = (1 m/s, 0, 0, 0, 0, 0.1 rad/s) and ẍ_d = 0:
    // X = M₁₁·(−K₁·10) + X_u|u|u = −539·40 + 120·1·1 (Coriolis has no X part here).
    assert!(
        (out.tau[0] - (-539.0 * 40.0 + 120.0)).abs() < 0.5,
        "X = {}",
        out.tau[0]
    );
}

#[test]
fn faults_turn_every_thruster_off_and_say_why() {
    let c = controller();
    let tr = Trajectory::table1(Table1Case::FigureEight30x30);
    let (eta, nu) = on_reference(&tr, 100);
    let check = |eta: [f32; 6], nu: [f32; 6], fault: Fault| {
        let out = c.update(100, &eta, &nu, &tr);
        assert_eq!(out.status, Status::Fault(fault));
        assert_eq!(out.voltage, [0.0; THRUSTERS]);
        assert_eq!(out.thrust, [0.0; THRUSTERS]);
        assert_eq!(out.tau, [0.0; 6]);
    };
    let mut bad = eta;
    bad[2] = f32::NAN;
    check(bad, nu, Fault::NonFiniteInput);
    let mut bad = nu;
    bad[5] = f32::NEG_INFINITY;
    check(eta, bad, Fault::NonFiniteInput);
    let mut bad = eta;
    bad[0] = 2.0 * MAX_POSITION;
    check(bad, nu, Fault::InputOutOfRange);
    let mut bad = eta;
    bad[4] = 85f32.to_radians();
    check(bad, nu, Fault::PitchLimit);
    bad[4] = -std::f32::consts::FRAC_PI_2;
    check(bad, nu, Fault::PitchLimit);
    // 79° is inside the default 80° limit: the law runs.
    let mut ok = eta;
    ok[4] = 79f32.to_radians();
    assert_eq!(c.update(100, &ok, &nu, &tr).status, Status::Ok);
}

#[test]
fn voltages_respect_the_supply_limit_and_report_saturation() {
    let c = controller();
    let tr = Trajectory::table1(Table1Case::Circular20R);
    let (eta, nu) = on_reference(&tr, 0);
    let out = c.update(0, &eta, &nu, &tr);
    // The paper's crabbing circle asks the horizontal pair for far more sway force than it
    // has (docs/thrusters.md#envelopes-at-the-supply-limit): saturated, inside the envelope, within the supply.
    assert!(out.saturated != 0);
    assert!(out.voltage.iter().all(|v| v.abs() <= 24.0));
    let e = c.envelope();
    assert!(e.contains(&out.thrust), "{:?} outside {e:?}", out.thrust);
    // What is reported as achieved is what B gives for the achieved thrusts; the allocator
    // keeps yaw (higher priority than sway) where it can and gives up sway, and the
    // unallocated part is what is missing.
    let b = c.allocation().matrix();
    for r in 0..6 {
        let achieved: f32 = (0..5).map(|i| b[(r, i)] * out.thrust[i]).sum();
        assert!((achieved - out.tau_achieved[r]).abs() < 1e-3, "row {r}");
    }
    assert!(
        out.tau_unallocated[1].abs() > 10.0,
        "{:?}",
        out.tau_unallocated
    );
    let scale = out.tau[1].abs().max(1.0);
    assert!(
        (out.tau[1] - out.tau_unallocated[1] - out.tau_achieved[1]).abs() < 1e-3 * scale,
        "sway: τ {} = achieved {} + unallocated {}",
        out.tau[1],
        out.tau_achieved[1],
        out.tau_unallocated[1]
    );
    assert!(
        out.tau_unallocated[5].abs() < 1e-3,
        "{:?}",
        out.tau_unallocated
    );
}

/// Built once: validation takes the bounds over 2⁹ box corners.
static CONTROLLERS: std::sync::OnceLock<[Controller; 2]> = std::sync::OnceLock::new();

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        prop::num::f32::ANY,
        -1e3f32..1e3,
        -10f32..10.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    /// The property: for any input — NaN, ±∞, huge, subnormal — `update` returns, every
    /// output is finite and every voltage within the limit.
    #[test]
    fn update_never_panics_and_never_emits_non_finite(
        ticks in any::<u64>(),
        eta in prop::array::uniform6(any_f32()),
        nu in prop::array::uniform6(any_f32()),
        case in 0usize..6,
        robust in any::<bool>(),
    ) {
        let c = &CONTROLLERS.get_or_init(|| {
            let mut without = ControllerConfig::default();
            without.robust = false;
            [controller(), Controller::new(without).unwrap()]
        })[usize::from(!robust)];
        let tr = Trajectory::table1(Table1Case::ALL[case]);
        let out = c.update(ticks, &eta, &nu, &tr);
        let scalars = [out.delta, out.w_norm];
        let all = out.tau.iter().chain(&out.tau_achieved).chain(&out.thrust).chain(&out.voltage)
            .chain(&out.tau_unallocated).chain(&out.eta_d).chain(&out.e1).chain(&out.u).chain(&scalars);
        for x in all {
            prop_assert!(x.is_finite());
        }
        for v in out.voltage {
            prop_assert!(v.abs() <= c.config().voltage_limit);
        }
        prop_assert!(out.delta <= c.config().delta_max);
    }
}

/// Closed loop on the exact nominal model with ideal actuators and no Δu: η̈ = ū exactly, so
/// each axis's error obeys ë + 4ė + 4e = 0 — critically damped, e(t) = e₀(1 + 2t)e^{−2t} for
/// ė(0) = 0. An independent fact about the whole chain (signs, frames, J, M, C, D, g).
#[test]
fn exact_model_closed_loop_follows_the_critically_damped_error_decay() {
    let mut cfg = ControllerConfig::default();
    cfg.robust = false;
    let c = Controller::new(cfg).unwrap();
    let p = VehicleParams::auv150();
    let m_inv = model::mass_matrix(&p).try_inverse().unwrap();
    let tr = Trajectory::table1(Table1Case::Circular10R);
    let d0 = tr.sample(0, 100);
    let e0 = 0.2f64;
    let mut eta: Vector6<f64> = d0.eta.cast();
    eta[0] += e0;
    let mut nu: Vector6<f64> =
        kinematics::jacobian_inv(&Attitude::from_eta(&eta)) * d0.eta_dot.cast::<f64>();

    let deriv = |eta: &Vector6<f64>, nu: &Vector6<f64>, tau: &Vector6<f64>| {
        let a = Attitude::from_eta(eta);
        let acc = m_inv
            * (tau
                - model::coriolis(&model::mass_matrix(&p), nu) * nu
                - model::damping(&p, nu) * nu
                - model::restoring(&p, &a));
        (kinematics::eta_dot(&a, nu).unwrap(), acc)
    };
    let h = 0.001;
    for tick in 0..400u64 {
        let out = c.update(
            tick,
            &eta.cast::<f32>().into(),
            &nu.cast::<f32>().into(),
            &tr,
        );
        assert_eq!(out.status, Status::Ok);
        let tau = Vector6::from(out.tau).cast::<f64>();
        for _ in 0..10 {
            let (k1e, k1n) = deriv(&eta, &nu, &tau);
            let (k2e, k2n) = deriv(&(eta + k1e * (h / 2.0)), &(nu + k1n * (h / 2.0)), &tau);
            let (k3e, k3n) = deriv(&(eta + k2e * (h / 2.0)), &(nu + k2n * (h / 2.0)), &tau);
            let (k4e, k4n) = deriv(&(eta + k3e * h), &(nu + k3n * h), &tau);
            eta += (k1e + k2e * 2.0 + k3e * 2.0 + k4e) * (h / 6.0);
            nu += (k1n + k2n * 2.0 + k3n * 2.0 + k4n) * (h / 6.0);
        }
        let t = (tick + 1) as f64 * 0.01;
        let d = tr.sample(tick + 1, 100);
        let ex = eta[0] - d.eta[0] as f64;
        let expected = e0 * (1.0 + 2.0 * t) * (-2.0 * t).exp();
        // Zero-order hold at 100 Hz delays the loop by ≈ 5 ms: a few mm on a 0.2 m error.
        assert!(
            (ex - expected).abs() < 0.006,
            "t = {t:.2}: e_x = {ex:.5}, closed form {expected:.5}"
        );
        // The other axes start on the reference and stay there.
        let ey = eta[1] - d.eta[1] as f64;
        assert!(ey.abs() < 0.005, "t = {t:.2}: e_y = {ey}");
    }
}
