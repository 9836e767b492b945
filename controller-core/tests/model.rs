//! Model of Eq (1) against the paper's printed matrices and physical invariants.

use controller_core::kinematics::Attitude;
use controller_core::model::{self, ParamVariation, VehicleParams};
use nalgebra::{Matrix6, Vector6};
use proptest::prelude::*;

/// The M printed in the paper (section "Brief Design Aspects and Dynamics of AUV-150").
fn printed_m() -> Matrix6<f64> {
    #[rustfmt::skip]
    let m = Matrix6::new(
        539.0, 0.0,    0.0,    0.0,   5.88,   0.0,
        0.0,   1326.0, 0.0,    -5.88, 0.0,    0.0,
        0.0,   0.0,    1326.0, 0.0,   0.0,    0.0,
        0.0,   -5.88,  0.0,    17.1,  0.0,    0.0,
        5.88,  0.0,    0.0,    0.0,   1836.0, 0.0,
        0.0,   0.0,    0.0,    0.0,   0.0,    1834.0,
    );
    m
}

#[test]
fn nominal_mass_matrix_is_the_printed_one_entry_by_entry() {
    let m = model::mass_matrix(&VehicleParams::auv150());
    let printed = printed_m();
    for i in 0..6 {
        for j in 0..6 {
            assert!(
                (m[(i, j)] - printed[(i, j)]).abs() < 1e-9,
                "M[{i}][{j}] = {} but the paper prints {}",
                m[(i, j)],
                printed[(i, j)]
            );
        }
    }
}

#[test]
fn nominal_mass_matrix_in_f32_matches_too() {
    let p = VehicleParams::auv150().cast(|x| x as f32);
    let m = model::mass_matrix(&p);
    let printed = printed_m();
    for i in 0..6 {
        for j in 0..6 {
            assert!((m[(i, j)] as f64 - printed[(i, j)]).abs() < 1e-4);
        }
    }
}

#[test]
fn mass_matrix_is_symmetric_positive_definite_over_the_table3_box() {
    let nominal = VehicleParams::auv150();
    for s in [0.0, 0.5, 1.0] {
        let p = nominal.with_variation(&ParamVariation::TABLE3_MAX.scaled(s));
        let m = model::mass_matrix(&p);
        assert!((m - m.transpose()).amax() < 1e-12);
        let eig = m.symmetric_eigen().eigenvalues;
        assert!(eig.min() > 0.0, "λmin = {}", eig.min());
        // Cholesky succeeds only for SPD matrices: an independent check of the eigenvalues.
        assert!(m.cholesky().is_some());
    }
}

#[test]
fn nominal_restoring_vector_is_the_printed_one() {
    let p = VehicleParams::auv150();
    for &(phi, theta, psi) in &[
        (0.0, 0.0, 0.0),
        (0.3, -0.2, 1.0),
        (-1.0, 0.7, -2.5),
        (0.05, 1.2, 3.0),
    ] {
        let g = model::restoring(&p, &Attitude::from_euler(phi, theta, psi));
        let printed = Vector6::new(
            0.0,
            0.0,
            0.0,
            296.1 * f64::cos(theta) * f64::sin(phi),
            291.1 * f64::sin(theta),
            0.0,
        );
        assert!(
            (g - printed).amax() < 1e-9,
            "g = {g:?}, printed {printed:?}"
        );
    }
}

#[test]
fn payload_weight_shows_in_heave_and_a_lateral_cg_shift_heels_the_vehicle() {
    // 30 kg of payload is 294.3 N of extra weight (positive z is down in NED).
    let p = VehicleParams::auv150().with_variation(&ParamVariation {
        mass: 30.0,
        ..Default::default()
    });
    let g = model::restoring(&p, &Attitude::from_euler(0.0, 0.0, 0.0));
    assert!((g[2] + 30.0 * 9.81).abs() < 1e-9, "g3 = {}", g[2]);
    // A 2 cm lateral CG shift at level attitude gives the roll moment −y_G W (Fossen's g₄).
    let p = VehicleParams::auv150().with_variation(&ParamVariation {
        r_g: [0.0, 0.02, 0.0],
        ..Default::default()
    });
    let g = model::restoring(&p, &Attitude::from_euler(0.0, 0.0, 0.0));
    assert!((g[3] + 0.02 * 490.0 * 9.81).abs() < 1e-9);
}

fn nu_strategy() -> impl Strategy<Value = Vector6<f64>> {
    prop::array::uniform6(-5.0f64..5.0).prop_map(Vector6::from)
}

proptest! {
    /// Kirchhoff form: C(ν) is skew-symmetric for symmetric M, so νᵀC(ν)ν = 0 — the
    /// Coriolis forces do no work.
    #[test]
    fn coriolis_does_no_work(nu in nu_strategy(), s in 0.0f64..1.0) {
        let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX.scaled(s));
        for m in [model::mass_matrix(&p), model::rigid_body_mass(&p), model::added_mass(&p)] {
            let c = model::coriolis(&m, &nu);
            let work = nu.dot(&(c * nu));
            prop_assert!(work.abs() < 1e-9 * (1.0 + (c * nu).norm() * nu.norm()), "νᵀCν = {}", work);
            prop_assert!((c + c.transpose()).amax() < 1e-9);
        }
    }

    /// C(ν)ν = [ω × a; v × a + ω × b] with [a; b] = Mν (docs/model.md#the-coriolis-and-centripetal-matrix), written out here.
    #[test]
    fn coriolis_product_is_the_cross_product_form(nu in nu_strategy()) {
        let m = model::mass_matrix(&VehicleParams::auv150());
        let ab = m * nu;
        let (a, b) = (ab.fixed_rows::<3>(0).into_owned(), ab.fixed_rows::<3>(3).into_owned());
        let (v, w) = (nu.fixed_rows::<3>(0).into_owned(), nu.fixed_rows::<3>(3).into_owned());
        let top = w.cross(&a);
        let bottom = v.cross(&a) + w.cross(&b);
        let cnu = model::coriolis(&m, &nu) * nu;
        prop_assert!((cnu.fixed_rows::<3>(0) - top).amax() < 1e-9);
        prop_assert!((cnu.fixed_rows::<3>(3) - bottom).amax() < 1e-9);
    }

    /// The vector forms C(ν)ν and D(ν)ν (what the law and the plant use) equal the matrices
    /// times ν.
    #[test]
    fn force_vectors_equal_the_matrices_times_nu(nu in nu_strategy(), s in 0.0f64..1.0) {
        let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX.scaled(s));
        for m in [model::mass_matrix(&p), model::rigid_body_mass(&p), model::added_mass(&p)] {
            let want = model::coriolis(&m, &nu) * nu;
            prop_assert!((model::coriolis_force(&m, &nu) - want).amax() < 1e-9 * (1.0 + want.amax()));
        }
        let want = model::damping(&p, &nu) * nu;
        prop_assert!((model::damping_force(&p, &nu) - want).amax() < 1e-9 * (1.0 + want.amax()));
    }

    /// Choice 521: `mass_mul` (M x from M's 18 structural non-zeros) has the bits of nalgebra's
    /// dense M x, in f32 as the law runs it, for any parameters `mass_matrix` takes (the centre
    /// of gravity anywhere in a box of ±0.5 m, every inertia and added mass positive). A zero
    /// may differ in its sign only. `mass_mul_pair` gives `mass_mul`'s bits for each of its two.
    #[test]
    fn structured_mass_product_has_the_dense_products_bits(
        x in proptest::array::uniform6(-1.0e3f32..1.0e3),
        r_g in proptest::array::uniform3(-0.5f32..0.5),
        inertia in proptest::array::uniform3(1.0f32..2000.0),
        added in proptest::array::uniform6(0.0f32..2000.0),
        mass in 10.0f32..2000.0,
    ) {
        let mut p = VehicleParams::auv150().cast(|v| v as f32);
        p.mass = mass;
        p.r_g = r_g;
        p.inertia = inertia;
        p.added_mass = added;
        let m = model::mass_matrix(&p);
        let x = nalgebra::Vector6::from(x);
        let (fast, dense) = (model::mass_mul(&m, &x), m * x);
        for i in 0..6 {
            prop_assert!(
                fast[i].to_bits() == dense[i].to_bits() || (fast[i] == 0.0 && dense[i] == 0.0),
                "row {}: {} vs {}", i, fast[i], dense[i]
            );
        }
        // Choice 574: the pair product is the single one twice, bit for bit, either order.
        let y = nalgebra::Vector6::from([x[3], -x[0], x[5], x[1], -x[4], x[2]]);
        let (px, py) = model::mass_mul_pair(&m, &x, &y);
        let (sx, sy) = (model::mass_mul(&m, &x), model::mass_mul(&m, &y));
        for i in 0..6 {
            prop_assert_eq!(px[i].to_bits(), sx[i].to_bits(), "row {} of M x", i);
            prop_assert_eq!(py[i].to_bits(), sy[i].to_bits(), "row {} of M y", i);
        }
    }

    /// Damping dissipates: νᵀD(ν)ν ≥ 0.
    #[test]
    fn damping_dissipates(nu in nu_strategy()) {
        let p = VehicleParams::auv150();
        prop_assert!(nu.dot(&(model::damping(&p, &nu) * nu)) >= 0.0);
    }
}

#[test]
fn printed_damping_diagonal() {
    let p = VehicleParams::auv150();
    let nu = Vector6::new(1.0, -2.0, 0.5, 3.0, -0.25, 0.1);
    let d = model::damping(&p, &nu);
    let expected = [
        120.0,
        1224.0 * 2.0,
        1224.0 * 0.5,
        0.0,
        2731.0 * 0.25,
        2731.0 * 0.1,
    ];
    for i in 0..6 {
        assert!((d[(i, i)] - expected[i]).abs() < 1e-9);
    }
    assert_eq!(d.iter().filter(|x| **x != 0.0).count(), 5);
}
