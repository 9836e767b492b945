//! Kinematics of Eqs (2)–(3) against identities and finite differences.

use controller_core::kinematics::{self, Attitude, GimbalLock, Kinematics};
use nalgebra::{Matrix3, Matrix6, Vector6};
use proptest::prelude::*;

fn attitude_strategy() -> impl Strategy<Value = (f64, f64, f64)> {
    (-3.1f64..3.1, -1.4f64..1.4, -3.1f64..3.1)
}

/// Integrates η̇ = J(η)ν for a short time with RK4 so J̇ can be differenced along a true
/// trajectory of the kinematics.
fn eta_after(eta: &Vector6<f64>, nu: &Vector6<f64>, h: f64) -> Vector6<f64> {
    let f = |e: &Vector6<f64>| kinematics::eta_dot(&Attitude::from_eta(e), nu).unwrap();
    let k1 = f(eta);
    let k2 = f(&(eta + k1 * (h / 2.0)));
    let k3 = f(&(eta + k2 * (h / 2.0)));
    let k4 = f(&(eta + k3 * h));
    eta + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

proptest! {
    #[test]
    fn rotation_is_orthonormal_with_unit_determinant((phi, theta, psi) in attitude_strategy()) {
        let r = kinematics::rotation(&Attitude::from_euler(phi, theta, psi));
        prop_assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-12);
        prop_assert!((r.determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn closed_form_inverse_inverts_j((phi, theta, psi) in attitude_strategy()) {
        let a = Attitude::from_euler(phi, theta, psi);
        let j = kinematics::jacobian(&a).unwrap();
        let jinv = kinematics::jacobian_inv(&a);
        prop_assert!((jinv * j - Matrix6::identity()).amax() < 1e-9);
        prop_assert!((j * jinv - Matrix6::identity()).amax() < 1e-9);
    }

    /// Ṙ and Ṫ against central differences of R and T along the motion η(t).
    #[test]
    fn jacobian_derivative_matches_finite_differences(
        (phi, theta, psi) in attitude_strategy(),
        nu in prop::array::uniform6(-1.0f64..1.0),
    ) {
        let nu = Vector6::from(nu);
        let eta = Vector6::new(1.0, 2.0, 3.0, phi, theta, psi);
        let h = 1e-5;
        let jp = kinematics::jacobian(&Attitude::from_eta(&eta_after(&eta, &nu, h))).unwrap();
        let jm = kinematics::jacobian(&Attitude::from_eta(&eta_after(&eta, &nu, -h))).unwrap();
        let fd = (jp - jm) / (2.0 * h);
        let jd = kinematics::jacobian_dot(&Attitude::from_eta(&eta), &nu).unwrap();
        // Central difference error O(h²·J⃛) plus rounding O(ε/h): ≈ 1e-9 at θ ≤ 1.4 rad,
        // where sec²θ ≈ 35.
        prop_assert!((fd - jd).amax() < 1e-6 * (1.0 + jd.amax()), "fd {fd} vs {jd}");
    }

    /// The step's kinematics value applies J, J⁻¹ and T as the matrices do.
    #[test]
    fn kinematics_value_applies_the_matrices(
        (phi, theta, psi) in attitude_strategy(),
        x in prop::array::uniform6(-2.0f64..2.0),
    ) {
        let x = Vector6::from(x);
        let a = Attitude::from_euler(phi, theta, psi);
        let k = Kinematics::new(a).unwrap();
        let j = kinematics::jacobian(&a).unwrap();
        prop_assert!((k.eta_dot(&x) - j * x).amax() < 1e-9 * (1.0 + (j * x).amax()));
        let jinv = kinematics::jacobian_inv(&a);
        prop_assert!((k.jinv_mul(&x) - jinv * x).amax() < 1e-12 * (1.0 + x.amax()));
        prop_assert!((k.jinv_mul(&k.eta_dot(&x)) - x).amax() < 1e-9 * (1.0 + x.amax()));
    }

    /// J⁻¹J̇ν in closed form ([ω × v; T⁻¹Ṫω]) equals the matrix product J⁻¹·(J̇ν).
    #[test]
    fn closed_form_jinv_jdot_nu_matches_the_matrix_product(
        (phi, theta, psi) in attitude_strategy(),
        nu in prop::array::uniform6(-2.0f64..2.0),
    ) {
        let nu = Vector6::from(nu);
        let a = Attitude::from_euler(phi, theta, psi);
        let product = kinematics::jacobian_inv(&a) * kinematics::jacobian_dot(&a, &nu).unwrap() * nu;
        let closed = kinematics::jinv_jdot_nu(&a, &nu).unwrap();
        prop_assert!((product - closed).amax() < 1e-9 * (1.0 + product.amax()));
    }

    /// η̈ = J ν̇ + J̇ ν (Eq 3): along constant ν, η̈ is J̇ν; check it by differencing η̇.
    #[test]
    fn jdot_nu_is_the_acceleration_of_eta_at_constant_nu(
        (phi, theta, psi) in attitude_strategy(),
        nu in prop::array::uniform6(-1.0f64..1.0),
    ) {
        let nu = Vector6::from(nu);
        let eta = Vector6::new(0.0, 0.0, 0.0, phi, theta, psi);
        let h = 1e-5;
        let ed = |e: &Vector6<f64>| kinematics::eta_dot(&Attitude::from_eta(e), &nu).unwrap();
        let fd = (ed(&eta_after(&eta, &nu, h)) - ed(&eta_after(&eta, &nu, -h))) / (2.0 * h);
        let jdnu = kinematics::jacobian_dot(&Attitude::from_eta(&eta), &nu).unwrap() * nu;
        prop_assert!((fd - jdnu).amax() < 1e-6 * (1.0 + jdnu.amax()));
    }
}

#[test]
fn pitch_at_ninety_degrees_is_a_reported_fault_not_a_nan() {
    for theta in [std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2] {
        let a = Attitude::from_euler(0.2, theta, 0.1);
        assert_eq!(kinematics::jacobian(&a), Err(GimbalLock));
        assert_eq!(kinematics::euler_rate_matrix(&a), Err(GimbalLock));
        let nu = Vector6::repeat(0.1);
        assert_eq!(kinematics::jinv_jdot_nu(&a, &nu), Err(GimbalLock));
        assert_eq!(kinematics::eta_dot(&a, &nu), Err(GimbalLock));
        // J⁻¹ needs no division and stays finite.
        assert!(kinematics::jacobian_inv(&a).iter().all(|x| x.is_finite()));
    }
    let a = Attitude::<f32>::from_euler(0.0, core::f32::consts::FRAC_PI_2, 0.0);
    assert_eq!(kinematics::jacobian(&a), Err(GimbalLock));
}

#[test]
fn f32_backend_attitude_matches_f64() {
    let eta = Vector6::new(0.0f32, 0.0, 0.0, 0.3, -0.7, 2.9);
    let a32 = Attitude::from_eta_f32(&eta);
    let a64 = Attitude::from_euler(0.3f64, -0.7, 2.9);
    let r32 = kinematics::rotation(&a32);
    let r64 = kinematics::rotation(&a64);
    // libm: a few ulp; micromath: its sin/cos error, measured ≈ 1e-3.
    let tol = if cfg!(feature = "micromath") {
        5e-3
    } else {
        1e-6
    };
    for i in 0..3 {
        for j in 0..3 {
            assert!((r32[(i, j)] as f64 - r64[(i, j)]).abs() < tol);
        }
    }
}
