//! The plant against physics: energy conservation without damping and restoring, and
//! hydrostatic restoring.

use controller_core::model::{ParamVariation, VehicleParams};
use host_sim::plant::{Plant, PlantState, PlantTerms};
use nalgebra::{Vector3, Vector6};

/// With no damping, no restoring and τ = 0 the only forces are Coriolis–centripetal, which do
/// no work: ½νᵀMν is constant. RK4 at 1 ms must hold it to 1e-6 relative over 10 s.
#[test]
fn kinetic_energy_is_conserved_without_damping_and_restoring() {
    let params = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let plant = Plant::new(
        params,
        PlantTerms {
            damping: false,
            restoring: false,
        },
    )
    .unwrap();
    let mut s = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.1, -0.2, 0.3),
        nu: Vector6::new(1.5, -0.4, 0.3, 0.2, 0.1, -0.15),
    };
    let e0 = plant.kinetic_energy(&s.nu);
    let mut worst = 0.0f64;
    for _ in 0..10_000 {
        s = plant
            .rk4_step(&s, &Vector6::zeros(), &Vector3::zeros(), 0.001)
            .unwrap();
        worst = worst.max(((plant.kinetic_energy(&s.nu) - e0) / e0).abs());
    }
    assert!(worst < 1e-6, "relative energy drift {worst:e}");
    // The motion is not trivial: the velocity direction changed.
    assert!((s.nu - Vector6::new(1.5, -0.4, 0.3, 0.2, 0.1, -0.15)).norm() > 1e-2);
}

/// Pitch has restoring (291.1 sin θ) and damping (2731|q|q): a pitched vehicle returns to
/// level. Roll has restoring but no damping (d_p = 0, docs/law.md#the-sampled-f32-loop): it keeps oscillating with
/// its amplitude, the energy of a frictionless pendulum.
#[test]
fn restoring_levels_pitch_and_roll_swings_undamped() {
    let plant = Plant::new(VehicleParams::auv150(), PlantTerms::default()).unwrap();
    let mut s = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.0, 0.3, 0.0),
        nu: Vector6::zeros(),
    };
    let mut late_max = 0.0f64;
    for i in 0..120_000 {
        s = plant
            .rk4_step(&s, &Vector6::zeros(), &Vector3::zeros(), 0.001)
            .unwrap();
        if i > 110_000 {
            late_max = late_max.max(s.eta[4].abs());
        }
    }
    assert!(late_max < 0.1, "pitch still {late_max} rad after 110 s");

    let mut s = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.2, 0.0, 0.0),
        nu: Vector6::zeros(),
    };
    let mut late_max = 0.0f64;
    for i in 0..60_000 {
        s = plant
            .rk4_step(&s, &Vector6::zeros(), &Vector3::zeros(), 0.001)
            .unwrap();
        if i > 50_000 {
            late_max = late_max.max(s.eta[3].abs());
        }
    }
    assert!((late_max - 0.2).abs() < 0.01, "roll amplitude {late_max}");
}

/// A vehicle at rest in a current is pushed along with it (drag on the relative velocity):
/// after a long time its earth-frame velocity approaches the current.
#[test]
fn current_drags_a_free_vehicle_along() {
    let plant = Plant::new(VehicleParams::auv150(), PlantTerms::default()).unwrap();
    let current = Vector3::new(0.3, 0.0, 0.0);
    let mut s = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.0, 0.0, 0.0),
        nu: Vector6::zeros(),
    };
    for _ in 0..300_000 {
        s = plant
            .rk4_step(&s, &Vector6::zeros(), &current, 0.001)
            .unwrap();
    }
    assert!((s.nu[0] - 0.3).abs() < 0.03, "u = {}", s.nu[0]);
}

#[test]
fn payload_weight_sinks_a_neutral_vehicle() {
    // 30 kg payload with unchanged buoyancy: the vehicle accelerates downwards (+z).
    let params = VehicleParams::auv150().with_variation(&ParamVariation {
        mass: 30.0,
        ..Default::default()
    });
    let plant = Plant::new(params, PlantTerms::default()).unwrap();
    let s = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.0, 0.0, 0.0),
        nu: Vector6::zeros(),
    };
    let (_, nu_dot) = plant
        .derivative(&s, &Vector6::zeros(), &Vector3::zeros())
        .unwrap();
    // ẇ = ΔW / (m + Δm − Z_ẇ) = 294.3 / (520 + 836).
    assert!(
        (nu_dot[2] - 30.0 * 9.81 / (520.0 + 836.0)).abs() < 1e-9,
        "{}",
        nu_dot[2]
    );
}

/// Eq (1) solved for ν̇ the way `controller_core::model` writes it: the matrices C_RB(ν),
/// C_A(ν_r), D(ν_r), M_A and M formed in full, R built for η̇ and again for ν_c, M factorised
/// here. The plant's derivative forms none of these matrices and reuses its factor; it must
/// give the same (η̇, ν̇).
fn derivative_from_the_model_matrices(
    p: &VehicleParams<f64>,
    s: &PlantState,
    tau: &Vector6<f64>,
    current: &Vector3<f64>,
) -> (Vector6<f64>, Vector6<f64>) {
    use controller_core::kinematics::{self, Attitude};
    use controller_core::model;
    let att = Attitude::from_eta(&s.eta);
    let eta_dot = kinematics::eta_dot(&att, &s.nu).unwrap();
    let omega = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
    let vc_body = kinematics::rotation(&att).transpose() * current;
    let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
    let dvc = -omega.cross(&vc_body);
    let nu_c_dot = Vector6::new(dvc.x, dvc.y, dvc.z, 0.0, 0.0, 0.0);
    let nu_r = s.nu - nu_c;
    let (m_rb, m_a) = (model::rigid_body_mass(p), model::added_mass(p));
    let rhs = tau - model::coriolis(&m_rb, &s.nu) * s.nu - model::coriolis(&m_a, &nu_r) * nu_r
        + m_a * nu_c_dot
        - model::damping(p, &nu_r) * nu_r
        - model::restoring(p, &att);
    (eta_dot, (m_rb + m_a).lu().solve(&rhs).unwrap())
}

/// Deterministic spread of states, forces and currents over the flight envelope.
fn envelope() -> impl Iterator<Item = (PlantState, Vector6<f64>, Vector3<f64>)> {
    (0..200).map(|i| {
        let x = |k: u32| ((i * 7919 + k as usize * 104_729) % 1000) as f64 / 500.0 - 1.0;
        let s = PlantState {
            eta: Vector6::new(
                30.0 * x(0),
                20.0 * x(1),
                5.0 + x(2),
                0.6 * x(3),
                1.2 * x(4),
                7.0 * x(5),
            ),
            nu: Vector6::new(
                2.0 * x(6),
                0.5 * x(7),
                0.5 * x(8),
                0.3 * x(9),
                0.3 * x(10),
                0.3 * x(11),
            ),
        };
        let tau = Vector6::new(
            800.0 * x(12),
            400.0 * x(13),
            400.0 * x(14),
            10.0 * x(15),
            300.0 * x(16),
            300.0 * x(17),
        );
        // Every fourth without a current (the plant's shorter path).
        let current = Vector3::new(0.5 * x(18), 0.5 * x(19), 0.1 * x(20)) * f64::from(i % 4 != 0);
        (s, tau, current)
    })
}

#[test]
fn derivative_equals_the_model_matrices_form() {
    let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    for p in [p, host_sim::plant::trimmed(&p)] {
        let plant = Plant::new(p, PlantTerms::default()).unwrap();
        let mut worst = 0.0f64;
        for (s, tau, current) in envelope() {
            let (eta_dot, nu_dot) = plant.derivative(&s, &tau, &current).unwrap();
            let (eta_ref, nu_ref) = derivative_from_the_model_matrices(&p, &s, &tau, &current);
            worst = worst
                .max((eta_dot - eta_ref).norm() / eta_ref.norm())
                .max((nu_dot - nu_ref).norm() / nu_ref.norm());
        }
        assert!(worst < 1e-12, "relative difference {worst:e}");
    }
}

/// [`Plant::set_params`] keeps the factor for equal parameters and forms a new one for new
/// parameters: a plant stepped through a staircase of parameter sets moves exactly (bit for
/// bit) as a plant built afresh at every step, and factorises once per distinct set.
#[test]
fn set_params_refactorises_only_when_the_parameters_change() {
    let nominal = VehicleParams::auv150();
    let staircase = [
        ParamVariation::TABLE3_MAX,
        ParamVariation::TABLE3_MAX.scaled(0.5),
        ParamVariation::default(),
    ];
    let mut cached = Plant::new(nominal, PlantTerms::default()).unwrap();
    let (mut a, tau, current) = envelope().nth(3).unwrap();
    let mut b = a;
    for k in 0..3000 {
        let p = nominal.with_variation(&staircase[k / 1000]);
        cached.set_params(p).unwrap();
        a = cached.rk4_step(&a, &tau, &current, 0.001).unwrap();
        b = Plant::new(p, PlantTerms::default())
            .unwrap()
            .rk4_step(&b, &tau, &current, 0.001)
            .unwrap();
        assert_eq!(a, b, "step {k}");
    }
    // The nominal set of `new`, then one per stair.
    assert_eq!(cached.factorisations(), 4);
    // A set M(p) cannot factor is refused, and the plant keeps the last good one.
    let mut bad = nominal;
    bad.mass = -1000.0;
    assert!(cached.set_params(bad).is_err());
    assert_eq!(cached.params(), &nominal.with_variation(&staircase[2]));
}

/// One classical RK4 step built from the public derivative (libm's sin/cos at every stage).
fn rk4_from_derivatives(
    plant: &Plant,
    s: &PlantState,
    tau: &Vector6<f64>,
    current: &Vector3<f64>,
    h: f64,
) -> PlantState {
    let f = |st: &PlantState| plant.derivative(st, tau, current).unwrap();
    let at = |eta, nu| PlantState { eta, nu };
    let (k1e, k1n) = f(s);
    let (k2e, k2n) = f(&at(s.eta + k1e * (h / 2.0), s.nu + k1n * (h / 2.0)));
    let (k3e, k3n) = f(&at(s.eta + k2e * (h / 2.0), s.nu + k2n * (h / 2.0)));
    let (k4e, k4n) = f(&at(s.eta + k3e * h, s.nu + k3n * h));
    at(
        s.eta + (k1e + k2e * 2.0 + k3e * 2.0 + k4e) * (h / 6.0),
        s.nu + (k1n + k2n * 2.0 + k3n * 2.0 + k4n) * (h / 6.0),
    )
}

/// The RK4 step takes its stages' sines and cosines from the step's by angle addition; it must
/// move the vehicle as the step that evaluates them at every stage does, to the last few ulps:
/// at ordinary rates (series path) and at rates so high that a stage's angle moves more than
/// the series covers (50 rad/s: 0.025 rad in half a 1 ms step; direct path).
#[test]
fn rk4_step_with_stage_attitudes_by_angle_addition_equals_the_plain_step() {
    let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let plant = Plant::new(p, PlantTerms::default()).unwrap();
    let mut worst = 0.0f64;
    for (mut s, tau, current) in envelope() {
        for fast in [false, true] {
            if fast {
                s.nu[3] *= 160.0;
                s.nu[5] *= 160.0;
            }
            let a = plant.rk4_step(&s, &tau, &current, 0.001).unwrap();
            let b = rk4_from_derivatives(&plant, &s, &tau, &current, 0.001);
            // Relative to the step's change (what the stage attitudes act on).
            worst = worst
                .max((a.eta - b.eta).norm() / (b.eta - s.eta).norm())
                .max((a.nu - b.nu).norm() / (b.nu - s.nu).norm());
        }
    }
    assert!(worst < 1e-12, "relative difference {worst:e}");
}

/// Choice 542: the study-grade integrator, the explicit midpoint rule, is a second-order
/// method: over a fixed time its error against a fine RK4 solution falls by 2² = 4 when its
/// step is halved (RK4's by 2⁴ = 16), on the full plant (damping, restoring, a current, a
/// held τ, the attitude moving), and at the study-grade 10 ms step, open loop, it is within
/// the study tolerance's absolute 0.5 mm (and 0.5 mrad) of the fine solution after 2 s.
#[test]
fn the_midpoint_step_is_second_order_and_close_at_the_control_period() {
    use host_sim::plant::Integrator;
    let params = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let plant = Plant::new(params, PlantTerms::default()).unwrap();
    let start = PlantState {
        eta: Vector6::new(0.0, 0.0, 5.0, 0.1, -0.2, 0.3),
        nu: Vector6::new(1.2, -0.3, 0.2, 0.3, 0.1, -0.4),
    };
    let tau = Vector6::new(400.0, -150.0, 80.0, 0.0, 120.0, -90.0);
    let current = Vector3::new(0.15, -0.1, 0.02);
    let fly = |method: Integrator, h: f64| {
        let n = (2.0 / h).round() as usize;
        let mut s = start;
        for _ in 0..n {
            s = plant.step(method, &s, &tau, &current, h).unwrap();
        }
        s
    };
    let truth = fly(Integrator::Rk4, 1e-4);
    let error = |s: PlantState| {
        let e = s.eta - truth.eta;
        e.iter().map(|x| x.abs()).fold(0.0, f64::max)
    };
    let (e20, e10, e5) = (
        error(fly(Integrator::Midpoint, 0.02)),
        error(fly(Integrator::Midpoint, 0.01)),
        error(fly(Integrator::Midpoint, 0.005)),
    );
    for (coarse, fine) in [(e20, e10), (e10, e5)] {
        let ratio = coarse / fine;
        assert!(
            (3.0..5.5).contains(&ratio),
            "halving the step divided the error by {ratio} ({coarse:e} → {fine:e})"
        );
    }
    let rk4 = error(fly(Integrator::Rk4, 0.02)) / error(fly(Integrator::Rk4, 0.01));
    assert!((12.0..20.0).contains(&rk4), "RK4's ratio {rk4}");
    assert!(
        e10 < host_sim::studies::campaign::STUDY_PATH_TOLERANCE.0,
        "midpoint at 10 ms: {e10:e} after 2 s"
    );
    // The motion is not trivial: the vehicle moved and turned.
    assert!((truth.eta - start.eta).norm() > 1.0);
}
