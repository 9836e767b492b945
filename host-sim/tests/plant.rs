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
/// level. Roll has restoring but no damping (d_p = 0, docs/design.md §8): it keeps oscillating with
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
