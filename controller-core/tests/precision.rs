//! What f32 costs: the board's τ (f32 `Controller::update`, the default math backend) against
//! an f64 evaluation of the same equations from the same inputs (docs/design.md §16).
//!
//! The reference takes the f32 inputs and the f32 desired state widened to f64 (the trajectory's
//! own accuracy against f64 is measured in tests/trajectory.rs and tests/phase.rs), the nominal
//! parameters in f64, and evaluates Eqs 12–13, 17 and the inversion-free Eq 7 route with f64
//! sin/cos. Δu is off: the comparison is of the law's arithmetic, not of δ's suprema (computed in
//! f32 at configuration time from the f32 parameters).

use controller_core::kinematics::{Attitude, Kinematics};
use controller_core::law;
use controller_core::model::{self, VehicleParams};
use controller_core::{Controller, ControllerConfig, Status, Table1Case, Trajectory};
use nalgebra::Vector6;
use proptest::prelude::*;

fn wrap(x: f64) -> f64 {
    let r = x.rem_euclid(std::f64::consts::TAU);
    if r > std::f64::consts::PI {
        r - std::f64::consts::TAU
    } else {
        r
    }
}

/// τ of Eq 7 in f64 from the same inputs as `update`.
fn tau_f64(
    cfg: &ControllerConfig,
    eta: &[f32; 6],
    nu: &[f32; 6],
    eta_d: &Vector6<f32>,
    eta_d_dot: &Vector6<f32>,
    eta_d_ddot: &Vector6<f32>,
) -> Vector6<f64> {
    let p = VehicleParams::auv150();
    let eta = Vector6::from(*eta).cast::<f64>();
    let nu = Vector6::from(*nu).cast::<f64>();
    let k = Kinematics::new(Attitude::from_eta(&eta)).unwrap();
    let mut e1 = eta - eta_d.cast::<f64>();
    e1[5] = wrap(e1[5]);
    let e2 = k.eta_dot(&nu) - eta_d_dot.cast::<f64>();
    let k1 = Vector6::from(cfg.k1).cast::<f64>();
    let k2 = Vector6::from(cfg.k2).cast::<f64>();
    let u = law::nominal_input(&eta_d_ddot.cast::<f64>(), &k1, &k2, &e1, &e2);
    let jjn = k.jinv_jdot_nu(&nu);
    law::body_force(&model::mass_matrix(&p), &p, &k, &nu, &u, &jjn)
}

/// 1e-6 (issue 11's target) with the kernels or libm; micromath's ≈ 1e-3 sin/cos and 6 % sqrt
/// are not meant to meet it (measured and reported only, within a loose 5 %).
const TOLERANCE: f64 = if cfg!(feature = "micromath") {
    5e-2
} else {
    1e-6
};

fn relative_error(tau: &[f32; 6], reference: &Vector6<f64>) -> f64 {
    let scale = reference.amax();
    let diff = (Vector6::from(*tau).cast::<f64>() - reference).amax();
    diff / scale
}

/// The controller without Δu, built once (`Controller::new` takes the bounds over the box).
fn controller() -> &'static Controller {
    static C: std::sync::OnceLock<Controller> = std::sync::OnceLock::new();
    C.get_or_init(|| {
        Controller::new(ControllerConfig {
            robust: false,
            ..ControllerConfig::default()
        })
        .expect("defaults without Δu")
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    /// Within 1e-6 of ‖τ‖∞ (relative) for states near every Table-1 mission: offsets up to
    /// 2 m and 0.3 rad, body rates up to 0.3 rad/s, pitch within ±0.6 rad.
    #[test]
    fn tau_is_within_1e_6_of_f64(
        case in 0usize..6,
        ticks in 0u64..7000,
        d_eta in prop::array::uniform6(-1.0f32..1.0),
        d_nu in prop::array::uniform6(-1.0f32..1.0),
    ) {
        let c = controller();
        let cfg = *c.config();
        let tr = Trajectory::table1(Table1Case::ALL[case]);
        let d = tr.sample(ticks, 100);
        let mut eta: [f32; 6] = d.eta.into();
        for i in 0..3 {
            eta[i] += 2.0 * d_eta[i];
        }
        for i in 3..6 {
            eta[i] += 0.3 * d_eta[i];
        }
        eta[4] = eta[4].clamp(-0.6, 0.6);
        let mut nu = [1.5f32, 0.0, 0.0, 0.0, 0.0, 0.1];
        for i in 0..3 {
            nu[i] += 0.5 * d_nu[i];
        }
        for i in 3..6 {
            nu[i] += 0.3 * d_nu[i];
        }
        let out = c.update(ticks, &eta, &nu, &tr);
        prop_assert_eq!(out.status, Status::Ok);
        let reference = tau_f64(&cfg, &eta, &nu, &d.eta, &d.eta_dot, &d.eta_ddot);
        let e = relative_error(&out.tau, &reference);
        prop_assert!(e <= TOLERANCE, "relative error {e:.2e}: {:?} vs {reference}", out.tau);
    }
}

/// The f32 parameters keep the vehicle's net weight: nominally neutral in f64, neutral in f32
/// (a regression: casting B on its own left one ulp of W, 0.5 mN, in every heave force).
#[test]
fn f32_parameters_keep_the_net_weight() {
    let p = VehicleParams::auv150();
    assert_eq!(p.weight() - p.buoyancy, 0.0);
    let p32 = p.cast(|x| x as f32);
    assert_eq!(p32.weight() - p32.buoyancy, 0.0);
    let heavy = p.with_variation(&model::ParamVariation::TABLE3_MAX);
    let h32 = heavy.cast(|x| x as f32);
    let net = (heavy.weight() - heavy.buoyancy) as f32;
    // B = W − net rounds once at the size of W.
    assert!((h32.weight() - h32.buoyancy - net).abs() <= h32.weight() * f32::EPSILON);
}

/// The figure the note quotes: the worst relative error over a deterministic sweep.
#[test]
fn report_tau_error_over_the_missions() {
    let c = controller();
    let cfg = *c.config();
    let mut worst = 0.0f64;
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        for ticks in (0..7000).step_by(37) {
            let d = tr.sample(ticks, 100);
            let w = ticks as f32 * 0.013;
            let mut eta: [f32; 6] = d.eta.into();
            eta[0] += 0.3 * w.sin();
            eta[1] -= 0.2 * w.cos();
            eta[3] += 0.1 * (1.3 * w).sin();
            eta[4] += 0.05 * (0.7 * w).cos();
            eta[5] += 0.05 * (0.9 * w).sin();
            let nu = [1.2 + 0.3 * w.cos(), 0.1, -0.05, 0.02, 0.01, 0.1];
            let out = c.update(ticks, &eta, &nu, &tr);
            assert_eq!(out.status, Status::Ok);
            let reference = tau_f64(&cfg, &eta, &nu, &d.eta, &d.eta_dot, &d.eta_ddot);
            worst = worst.max(relative_error(&out.tau, &reference));
        }
    }
    eprintln!(
        "f32 τ vs f64 over the Table-1 missions ({}): worst {worst:.2e} of ‖τ‖∞",
        controller_core::math::BACKEND
    );
    assert!(worst <= TOLERANCE);
}
