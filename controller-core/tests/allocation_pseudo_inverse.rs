//! Control allocation T = B₅⁻¹τ (`controller_core::allocation`, docs/thrusters.md#allocation): against
//! the closed form of the default geometry written here in f64, the round trip B·B₅⁻¹ on a
//! general tilted layout, and the singular and ill-conditioned layouts it must refuse.

use controller_core::allocation::{AllocationError, PseudoInverse, MAX_CONDITION};
use controller_core::effectiveness::{
    ThrusterGeometry, AUV150_REVERSED, HORZ_AFT, HORZ_FORE, THRUSTERS,
};
use nalgebra::Vector6;
use proptest::prelude::*;

const EPS: f64 = f32::EPSILON as f64;

#[test]
fn default_condition_number_by_hand() {
    // ‖B₅‖∞ = 2 · 1.8 (the M and N rows), ‖B₅⁻¹‖∞ = 1 (the main row; the tunnel rows sum to
    // 0.5 + 0.5/1.8 ≈ 0.78), so κ∞ = 3.6.
    let a = PseudoInverse::new(&ThrusterGeometry::default()).expect("default geometry accepted");
    assert!((a.condition() - 3.6).abs() < 1e-5, "{}", a.condition());
}

fn wrench() -> impl Strategy<Value = [f32; 6]> {
    proptest::array::uniform6(-1.0e4f32..1.0e4)
}

/// docs/thrusters.md#allocation closed form, in f64, for every thruster along its reference axis
/// (+x, +z, +z, +y, +y); a reversed thruster (bit i of `reversed`) gives the negated thrust.
fn closed_form(tau: &[f32; 6], reversed: u8) -> [f64; THRUSTERS] {
    let [x, y, z, _k, m, n] = tau.map(|v| v as f64);
    let t = [
        x,
        (z - m / 1.8) / 2.0,
        (z + m / 1.8) / 2.0,
        (y + n / 1.8) / 2.0,
        (y - n / 1.8) / 2.0,
    ];
    std::array::from_fn(|i| {
        if reversed & (1 << i) != 0 {
            -t[i]
        } else {
            t[i]
        }
    })
}

#[test]
fn default_is_the_real_vehicle_mounting() {
    // Vertical fore pushing up, aft down, horizontal pair pushing to port
    // (docs/real-vehicle.md#the-default-mounting): a pure upward force is positive (strong) thrust fore and negative (weak) aft, a
    // nose-up moment positive thrust on both vertical tunnels, a pure force to port positive
    // thrust on both horizontal ones.
    let a = PseudoInverse::new(&ThrusterGeometry::default()).expect("default geometry");
    let up = a.thrusts(&Vector6::new(0.0, 0.0, -100.0, 0.0, 0.0, 0.0));
    assert_eq!(up, [0.0, 50.0, -50.0, 0.0, 0.0]);
    // M = Σ (z F_x − x F_z): a nose-up moment of 360 N m is +100 N up at x = +1.8 m and
    // +100 N down at x = −1.8 m.
    let nose_up = a.thrusts(&Vector6::new(0.0, 0.0, 0.0, 0.0, 360.0, 0.0));
    for (t, want) in nose_up.iter().zip([0.0, 100.0, 100.0, 0.0, 0.0]) {
        assert!((t - want).abs() < 1e-4, "{nose_up:?}");
    }
    let port = a.thrusts(&Vector6::new(0.0, -100.0, 0.0, 0.0, 0.0, 0.0));
    assert_eq!(port, [0.0, 0.0, 0.0, 50.0, 50.0]);
    assert_eq!(AUV150_REVERSED, 0b11010);
}

proptest! {
    #[test]
    fn default_thrusts_equal_closed_form(tau in wrench(), reversed in 0u8..32) {
        let a = PseudoInverse::new(&ThrusterGeometry::auv150(reversed)).expect("AUV-150 layout");
        let t = a.thrusts(&Vector6::from(tau));
        let want = closed_form(&tau, reversed);
        let scale: f64 = tau.iter().map(|v| v.abs() as f64).sum::<f64>().max(1.0);
        for i in 0..5 {
            prop_assert!((t[i] as f64 - want[i]).abs() <= 4.0 * EPS * scale,
                "thruster {}: {} vs {}", i, t[i], want[i]);
        }
        // τ_K is dropped: changing it changes nothing.
        let mut tau_k = tau;
        tau_k[3] = 1234.5;
        prop_assert_eq!(a.thrusts(&Vector6::from(tau_k)), t);
        prop_assert_eq!(ThrusterGeometry::auv150(reversed).auv150_reversed(), Some(reversed));
    }

    #[test]
    fn wrench_of_thrusts_reproduces_actuated_rows(tau in wrench()) {
        let a = PseudoInverse::new(&ThrusterGeometry::default()).expect("default geometry");
        let back = a.wrench(&a.thrusts(&Vector6::from(tau)));
        let scale: f64 = tau.iter().map(|v| v.abs() as f64).sum::<f64>().max(1.0);
        for r in [0usize, 1, 2, 4, 5] {
            prop_assert!((back[r] as f64 - tau[r] as f64).abs() <= 8.0 * EPS * scale,
                "row {}: {} vs {}", r, back[r], tau[r]);
        }
        prop_assert_eq!(back[3], 0.0); // all thrusters on the centre line: no roll moment
    }

    #[test]
    fn general_geometry_round_trip(tau in wrench()) {
        // A tilted, offset layout (unit directions), to check the inverse beyond the closed form.
        let s = 0.5f32.sqrt();
        let g = ThrusterGeometry {
            position: [
                [-2.4, 0.05, 0.1],
                [1.7, 0.0, -0.1],
                [-1.9, 0.1, 0.0],
                [1.6, 0.0, 0.2],
                [-1.5, -0.1, 0.0],
            ],
            direction: [
                [0.99, 0.0, (1.0f32 - 0.99 * 0.99).sqrt()],
                [0.0, 0.0, 1.0],
                [0.0, s, s],
                [0.0, 1.0, 0.0],
                [s, s, 0.0],
            ],
        };
        let a = PseudoInverse::new(&g).expect("tilted geometry accepted");
        let back = a.wrench(&a.thrusts(&Vector6::from(tau)));
        let scale: f64 = tau.iter().map(|v| v.abs() as f64).sum::<f64>().max(1.0);
        let tol = 8.0 * EPS * a.condition() as f64 * scale;
        for r in [0usize, 1, 2, 4, 5] {
            prop_assert!((back[r] as f64 - tau[r] as f64).abs() <= tol,
                "row {}: {} vs {}", r, back[r], tau[r]);
        }
    }
}

#[test]
fn rejects_two_identical_thrusters() {
    let mut g = ThrusterGeometry::default();
    g.position[HORZ_AFT] = g.position[HORZ_FORE];
    g.direction[HORZ_AFT] = g.direction[HORZ_FORE];
    let err = PseudoInverse::new(&g).expect_err("duplicate thrusters must be rejected");
    assert!(
        matches!(
            err,
            AllocationError::Singular | AllocationError::IllConditioned { .. }
        ),
        "{err:?}"
    );
}

#[test]
fn rejects_ill_conditioned_layout() {
    // Horizontal tunnels 0.1 mm apart: N = 1.8 T_f + 1.7999 T_a, so B₅⁻¹ has entries ≈ 1/1e-4.
    let mut g = ThrusterGeometry::default();
    g.position[HORZ_AFT] = [1.8 - 1e-4, 0.0, 0.0];
    match PseudoInverse::new(&g) {
        Err(AllocationError::IllConditioned { condition, limit }) => {
            assert_eq!(limit, MAX_CONDITION);
            assert!(
                condition > MAX_CONDITION && condition.is_finite(),
                "{condition}"
            );
            let msg = AllocationError::IllConditioned { condition, limit }.to_string();
            assert!(msg.contains("condition") && msg.contains("10000"), "{msg}");
        }
        other => panic!("expected IllConditioned, got {other:?}"),
    }
}
