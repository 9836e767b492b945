//! The law's pieces against closed forms and invariants: Lyapunov residual, Eq 7's literal
//! route, and the properties of Δu that Theorems 3 and 4 rely on.

use controller_core::kinematics::{self, Attitude, Kinematics};
use controller_core::law::{self, AxisLyapunov, RobustLaw};
use controller_core::model::{self, ParamVariation, VehicleParams};
use nalgebra::{Matrix2, Matrix6, Vector6};
use proptest::prelude::*;

#[test]
fn lyapunov_solution_satisfies_the_equation_and_is_positive_definite() {
    for &(k1, k2, q1, q2) in &[
        (4.0f64, 4.0, 1.0, 1.0),
        (1.0, 0.5, 1.0, 1.0),
        (9.0, 6.0, 2.0, 0.5),
        (0.25, 3.0, 1.0, 10.0),
    ] {
        let p = AxisLyapunov::solve(k1, k2, q1, q2);
        let pm = Matrix2::new(p.p11, p.p12, p.p12, p.p22);
        let a = Matrix2::new(0.0, 1.0, -k1, -k2);
        let residual = a.transpose() * pm + pm * a + Matrix2::new(q1, 0.0, 0.0, q2);
        assert!(residual.amax() < 1e-12, "residual {residual}");
        assert!(pm.symmetric_eigen().eigenvalues.min() > 0.0);
    }
    // The f32 solution the controller uses, to the 1e-5.
    let p = AxisLyapunov::solve(4.0f32, 4.0, 1.0, 1.0);
    let pm = Matrix2::new(p.p11, p.p12, p.p12, p.p22);
    let a = Matrix2::new(0.0f32, 1.0, -4.0, -4.0);
    let residual = a.transpose() * pm + pm * a + Matrix2::identity();
    assert!(residual.amax() < 1e-5);
}

/// Eq 7 taken literally, in f64: M̄ = J⁻ᵀMJ⁻¹, C̄ = J⁻ᵀ[C − MJ⁻¹J̇]J⁻¹, D̄ = J⁻ᵀDJ⁻¹,
/// ḡ = J⁻ᵀg, H = C̄η̇ + D̄η̇ + ḡ, b = M̄⁻¹, f = bH, τ̄ = b⁻¹(u + f), τ = Jᵀτ̄ — with numerical
/// inverses throughout.
fn literal_eq7(
    p: &VehicleParams<f64>,
    eta: &Vector6<f64>,
    nu: &Vector6<f64>,
    u: &Vector6<f64>,
) -> Vector6<f64> {
    let a = Attitude::from_eta(eta);
    let j = kinematics::jacobian(&a).unwrap();
    let jinv = j.try_inverse().unwrap();
    let jinv_t = jinv.transpose();
    let jdot = kinematics::jacobian_dot(&a, nu).unwrap();
    let m = model::mass_matrix(p);
    let m_bar = jinv_t * m * jinv;
    let c_bar = jinv_t * (model::coriolis(&m, nu) - m * jinv * jdot) * jinv;
    let d_bar = jinv_t * model::damping(p, nu) * jinv;
    let g_bar = jinv_t * model::restoring(p, &a);
    let eta_dot = j * nu;
    let h = c_bar * eta_dot + d_bar * eta_dot + g_bar;
    let b: Matrix6<f64> = m_bar.try_inverse().unwrap();
    let f = b * h;
    let tau_bar = b.try_inverse().unwrap() * (u + f);
    j.transpose() * tau_bar
}

proptest! {
    #[test]
    fn inversion_free_tau_equals_the_literal_eq7_route(
        eta in prop::array::uniform6(-1.2f64..1.2),
        nu in prop::array::uniform6(-2.0f64..2.0),
        u in prop::array::uniform6(-1.0f64..1.0),
        s in 0.0f64..1.0,
    ) {
        let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX.scaled(s));
        let (eta, nu, u) = (Vector6::from(eta), Vector6::from(nu), Vector6::from(u));
        let a = Attitude::from_eta(&eta);
        let k = Kinematics::new(a).unwrap();
        let jjn = k.jinv_jdot_nu(&nu);
        let fast = law::body_force(&model::mass_matrix(&p), &p, &k, &nu, &u, &jjn);
        let literal = literal_eq7(&p, &eta, &nu, &u);
        prop_assert!((fast - literal).amax() < 1e-8 * (1.0 + literal.amax()),
            "inversion-free {fast} vs literal {literal}");
    }

    /// ‖Δu‖ ≤ δ for both theorems, and Δu opposes w (wᵀΔu ≤ 0, the sign the proofs need).
    #[test]
    fn robust_term_is_bounded_by_delta_and_opposes_w(
        w in prop::array::uniform6(-1.0f32..1.0),
        scale in prop::sample::select(vec![1e-4f32, 1e-2, 0.05, 0.1, 1.0, 10.0]),
        delta in 0.0f32..30.0,
        mu in 0.01f32..1.0,
    ) {
        let w = Vector6::from(w) * scale;
        let w_norm = controller_core::math::norm(&w.into());
        for law_kind in [RobustLaw::Discontinuous, RobustLaw::BoundaryLayer] {
            let du = law::robust_term(law_kind, &w, w_norm, delta, mu);
            // micromath's sqrt is ≈ 6 % off, so ‖w‖ and with it ‖Δu‖ can be off by as much.
            let slack = if cfg!(feature = "micromath") { 1.07 } else { 1.0 + 1e-5 };
            prop_assert!(du.norm() <= delta * slack + 1e-6, "‖Δu‖ = {} > δ = {}", du.norm(), delta);
            prop_assert!(w.dot(&du) <= 1e-6);
        }
    }

    /// Outside the boundary layer (‖w‖ ≥ μ) Theorems 3 and 4 give the same Δu.
    #[test]
    fn theorems_3_and_4_agree_outside_the_layer(
        w in prop::array::uniform6(-10.0f32..10.0),
        delta in 0.0f32..30.0,
        mu in 0.01f32..0.5,
    ) {
        let w = Vector6::from(w);
        let w_norm = controller_core::math::norm(&w.into());
        prop_assume!(w_norm >= mu);
        let d3 = law::robust_term(RobustLaw::Discontinuous, &w, w_norm, delta, mu);
        let d4 = law::robust_term(RobustLaw::BoundaryLayer, &w, w_norm, delta, mu);
        prop_assert_eq!(d3, d4);
    }
}

#[test]
fn boundary_layer_term_is_continuous_at_the_layer_edge() {
    let (delta, mu) = (5.0f32, 0.1f32);
    let dir = Vector6::new(0.3f32, -0.5, 0.2, 0.0, 0.7, -0.1).normalize();
    let at = |r: f32| {
        let w = dir * r;
        law::robust_term(RobustLaw::BoundaryLayer, &w, r, delta, mu)
    };
    let inside = at(mu * (1.0 - 1e-6));
    let outside = at(mu);
    // Both sides → −δ·dir: the jump is O(δ·1e-6).
    assert!((inside - outside).amax() < 1e-4, "{inside} vs {outside}");
    assert!((outside + dir * delta).amax() < 1e-5);
    // Inside, it is linear in w: −(δ/μ) w.
    let half = at(mu / 2.0);
    assert!((half + dir * (delta / 2.0)).amax() < 1e-5);
    // The discontinuous law jumps at w = 0: −δ·dir for any small w, 0 at w = 0.
    let tiny = dir * 1e-6;
    let d3 = law::robust_term(RobustLaw::Discontinuous, &tiny, 1e-6, delta, mu);
    assert!((d3 + dir * delta).amax() < 1e-4);
    let zero = law::robust_term(RobustLaw::Discontinuous, &Vector6::zeros(), 0.0, delta, mu);
    assert_eq!(zero, Vector6::zeros());
}

#[test]
fn yaw_error_is_wrapped_and_other_axes_are_not() {
    let eta = Vector6::new(0.0f32, 0.0, 0.0, 0.0, 0.0, 179f32.to_radians());
    let eta_d = Vector6::new(0.0f32, 0.0, 0.0, 0.0, 0.0, -179f32.to_radians());
    let z = Vector6::zeros();
    let (e1, _) = law::tracking_errors(&eta, &z, &eta_d, &z);
    assert!((e1[5] + 2f32.to_radians()).abs() < 1e-5, "e_ψ = {}", e1[5]);
    // x is not an angle: a 7 m error stays 7 m.
    let (e1, _) = law::tracking_errors(&Vector6::new(7.0, 0.0, 0.0, 0.0, 0.0, 0.0), &z, &z, &z);
    assert_eq!(e1[0], 7.0);
}

#[test]
fn nominal_input_is_eq17() {
    let k = Vector6::new(4.0f64, 4.0, 4.0, 0.0, 4.0, 4.0);
    let e1 = Vector6::new(1.0, -1.0, 0.5, 9.0, 0.1, -0.2);
    let e2 = Vector6::new(0.0, 2.0, -0.5, 9.0, 0.3, 0.0);
    let acc = Vector6::new(0.1, 0.2, 0.0, 0.0, 0.0, 0.01);
    let u = law::nominal_input(&acc, &k, &k, &e1, &e2);
    let expected = Vector6::new(0.1 - 4.0, 0.2 + 4.0 - 8.0, 0.0, 0.0, -1.6, 0.01 + 0.8);
    assert!((u - expected).amax() < 1e-12);
}

#[test]
fn switching_signal_is_b_transpose_p_e() {
    // Build the full 12×12 P from the per-axis blocks and form BᵀPe literally.
    let p_axis = AxisLyapunov::solve(4.0f64, 4.0, 1.0, 1.0);
    let mut lyap = [p_axis; 6];
    lyap[3] = AxisLyapunov::default();
    let e1 = Vector6::new(0.3, -0.2, 0.1, 0.5, 0.05, -0.4);
    let e2 = Vector6::new(-0.1, 0.4, 0.0, 0.7, 0.02, 0.3);
    let mut big = nalgebra::SMatrix::<f64, 12, 12>::zeros();
    for i in 0..6 {
        big[(i, i)] = lyap[i].p11;
        big[(i, i + 6)] = lyap[i].p12;
        big[(i + 6, i)] = lyap[i].p12;
        big[(i + 6, i + 6)] = lyap[i].p22;
    }
    let mut e = nalgebra::SVector::<f64, 12>::zeros();
    e.fixed_rows_mut::<6>(0).copy_from(&e1);
    e.fixed_rows_mut::<6>(6).copy_from(&e2);
    let pe = big * e;
    let w_literal = pe.fixed_rows::<6>(6).into_owned(); // Bᵀ = [0 I]
    let w = law::switching_signal(&lyap, &e1, &e2);
    assert!((w - w_literal).amax() < 1e-12);
    assert_eq!(w[3], 0.0);
}
