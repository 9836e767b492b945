//! What f32 costs: the board's τ (f32 `Controller::update`, the default math backend) against
//! an f64 evaluation of the same equations from the same inputs (docs/numerics.md#what-f32-costs).
//!
//! The reference takes the f32 inputs and the f32 desired state widened to f64 (the trajectory's
//! own accuracy against f64 is measured in tests/trajectory.rs and tests/phase.rs), the nominal
//! parameters in f64, and evaluates Eqs 12–13, 17 and the inversion-free Eq 7 route with f64
//! sin/cos. Δu is off: the comparison is of the law's arithmetic, not of δ's suprema (computed in
//! f32 at configuration time from the f32 parameters).
//!
//! # The bound, from the computation (docs/numerics.md#what-f32-costs, Choice 90)
//!
//! τ = M(J⁻¹ū − J⁻¹J̇ν) + C(ν)ν + D(ν)ν + g(η) with ū = η̈_d − K₁e₁ − K₂e₂, e₁ = η − η_d,
//! e₂ = J(η)ν − η̇_d. The inputs (η, ν, η_d, η̇_d, η̈_d, the gains) are the same f32 numbers on
//! both sides; every f32 operation returns its exact result times (1 + δ), |δ| ≤ u = 2⁻²⁴,
//! and sin/cos are within 1 ulp ≤ 2u (the kernels within 0.82 ulp, tests/kernels.rs; libm's
//! within 0.501 ulp, reported there), two such factors. Multiply out τ₃₂: it is τ's expression
//! with each term (a product of inputs, parameters, sines, cosines and 1/cos θ) carrying at most
//! N factors (1 + δ)^±1, where N is the most roundings any value passes through on its way from
//! the inputs; such a product is within γ_N of 1 (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, 2nd ed., Lemma 3.1). Summing the terms' errors, per component,
//!
//! ```text
//! |τ₃₂ − τ| ≤ γ_N · S,   γ_N = N·u / (1 − N·u),
//! ```
//!
//! where S is the sum of the terms' magnitudes: τ evaluated with every input replaced by its
//! magnitude and every subtraction by an addition ([`tau_abs`]), the size of what the law adds
//! and cancels, not of the sum. e₁ = η − η_d, a difference of exact inputs, is one rounding of
//! its own value, so it enters S as |e₁|. N along the longest chain, in the code's order of
//! operations (a dot product of n terms: one product, then n − 1 sums):
//!
//! | step                                         | roundings      | N  |
//! |----------------------------------------------|----------------|----|
//! | sin, cos of φ, θ, ψ (1 ulp)                  | 2              | 2  |
//! | an entry of R, e.g. cψ sθ sφ − sψ cφ         | 2 ×, 1 +       | 5  |
//! | η̇ = Jν, a 3-term dot product                 | 1 ×, 2 +       | 8  |
//! | e₂ = η̇ − η̇_d                                 | 1 −            | 9  |
//! | K₂e₂, then ū = (η̈_d − K₁e₁) − K₂e₂           | 1 ×, 1 −       | 11 |
//! | J⁻¹ū: Rᵀū, a 3-term dot product              | 1 ×, 2 +       | 14 |
//! | J⁻¹ū − J⁻¹J̇ν                                 | 1 −            | 15 |
//! | M(…), a 6-term dot product                   | 1 ×, 5 +       | 21 |
//! | + C(ν)ν + D(ν)ν + g(η)                       | 3 +            | 24 |
//!
//! The other chains are shorter: J⁻¹J̇ν 13 (sec θ = 1/cos θ 3, tan θ 4, an entry of Ṫ 8, Ṫω
//! 11, T⁻¹(Ṫω) 13), C(ν)ν 12, g 8, D(ν)ν 3, e₁ 3 (a yaw wrap by 2π), the parameters' entries
//! of M 3 (the f64 → f32 cast, m·z_G, M_RB + M_A). W − B is 0 exactly in both precisions
//! (Choice 76, `f32_parameters_keep_the_net_weight`), so the first three rows of g are exact.
//! The f64 reference has the same error bound at u = 2⁻⁵³; the test allows both.
//!
//! **Where the digits go.** τ is often much smaller than S: the law cancels the velocity
//! feedback K₂Jν against K₂η̇_d, and K₁e₁ and η̈_d against both, and each term is rounded at
//! its own size. Issue 18's failing case (1.53·10⁻⁶ of ‖τ‖∞, above the 10⁻⁶ this test
//! asserted until then) lost its digits in the sway force, 1.1·10⁻³ N. So does the worst of
//! 2·10⁶ random states drawn like this test's (1.62·10⁻⁶; kept as
//! `the_worst_relative_case_found_is_within_the_rounding_bound`): η̇ = Rν at 1.7 m/s is off by
//! a few ulps (3·10⁻⁷ m/s), which K₂ (4 s⁻¹) and M₂₂ (1326 kg) carry into τ_y as 1.2·10⁻³ N;
//! S_y there is 2.5·10⁴ N, ‖τ‖∞ 767 N. No f32 evaluation of this law is within 10⁻⁶ of ‖τ‖∞
//! everywhere (the error scales with S, and S/‖τ‖∞ grows without bound as τ → 0); every one
//! is within γ₂₄·S, which is what is asserted. Removing the cancellation would take wider
//! arithmetic on the per-step path (f64 is software on the Cortex-M4F). The relative error is
//! still reported: `report_tau_error_over_the_missions` prints both figures.
//!
//! micromath's sin/cos are off by ≈ 10⁻³ absolute, not a few ulps: the bound does not apply,
//! and its τ is only measured, within a loose 5 % of ‖τ‖∞.

use controller_core::kinematics::{Attitude, Kinematics};
use controller_core::law;
use controller_core::model::{self, VehicleParams};
use controller_core::{Controller, ControllerConfig, Desired, Status, Table1Case, Trajectory};
use nalgebra::{Matrix3, Vector3, Vector6};
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
fn tau_f64(cfg: &ControllerConfig, eta: &[f32; 6], nu: &[f32; 6], d: &Desired) -> Vector6<f64> {
    let p = VehicleParams::auv150();
    let eta = Vector6::from(*eta).cast::<f64>();
    let nu = Vector6::from(*nu).cast::<f64>();
    let k = Kinematics::new(Attitude::from_eta(&eta)).unwrap();
    let mut e1 = eta - d.eta.cast::<f64>();
    e1[5] = wrap(e1[5]);
    let e2 = k.eta_dot(&nu) - d.eta_dot.cast::<f64>();
    let k1 = Vector6::from(cfg.k1).cast::<f64>();
    let k2 = Vector6::from(cfg.k2).cast::<f64>();
    let u = law::nominal_input(&d.eta_ddot.cast::<f64>(), &k1, &k2, &e1, &e2);
    let jjn = k.jinv_jdot_nu(&nu);
    law::body_force(&model::mass_matrix(&p), &p, &k, &nu, &u, &jjn)
}

/// |a| × |b| evaluated as a sum of magnitudes.
fn cross_abs(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
    let (a, b) = (a.abs(), b.abs());
    Vector3::new(
        a.y * b.z + a.z * b.y,
        a.z * b.x + a.x * b.z,
        a.x * b.y + a.y * b.x,
    )
}

/// S: τ of [`tau_f64`] with every input replaced by its magnitude and every subtraction by an
/// addition, formula by formula (`kinematics::{rotation, Kinematics}`, `law`, `model`).
fn tau_abs(cfg: &ControllerConfig, eta: &[f32; 6], nu: &[f32; 6], d: &Desired) -> Vector6<f64> {
    let p = VehicleParams::auv150();
    let eta = Vector6::from(*eta).cast::<f64>();
    let nu = Vector6::from(*nu).cast::<f64>();
    let a = Attitude::from_eta(&eta);
    let (sf, cf, st, ct, sp, cp) = (
        a.sphi.abs(),
        a.cphi.abs(),
        a.stheta.abs(),
        a.ctheta.abs(),
        a.spsi.abs(),
        a.cpsi.abs(),
    );
    let sec = 1.0 / ct;
    let tan = st * sec;
    #[rustfmt::skip]
    let r = Matrix3::new(
        cp * ct, sp * cf + cp * st * sf, sp * sf + cp * cf * st,
        sp * ct, cp * cf + sf * st * sp, cp * sf + st * sp * cf,
        st,      ct * sf,                ct * cf,
    );
    // T ω and T⁻¹ x.
    let euler_rates = |w: &Vector3<f64>| {
        let w = w.abs();
        let s = w.y * sf + w.z * cf;
        Vector3::new(w.x + s * tan, w.y * cf + w.z * sf, s * sec)
    };
    let euler_rates_inv = |x: &Vector3<f64>| {
        let x = x.abs();
        Vector3::new(
            x.x + st * x.z,
            cf * x.y + ct * sf * x.z,
            sf * x.y + ct * cf * x.z,
        )
    };
    let v = Vector3::new(nu[0], nu[1], nu[2]);
    let w = Vector3::new(nu[3], nu[4], nu[5]);
    let (lin, ang) = (r * v.abs(), euler_rates(&w));
    let eta_dot = Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z);
    // e₁: one rounding of its own value, and 2π per wrap of the yaw error.
    let mut e1 = (eta - d.eta.cast::<f64>()).abs();
    let wraps = (e1[5] + std::f64::consts::PI).div_euclid(std::f64::consts::TAU);
    e1[5] += wraps * std::f64::consts::TAU;
    let e2 = eta_dot + d.eta_dot.cast::<f64>().abs();
    let k1 = Vector6::from(cfg.k1).cast::<f64>().abs();
    let k2 = Vector6::from(cfg.k2).cast::<f64>().abs();
    let u = d.eta_ddot.cast::<f64>().abs() + k1.component_mul(&e1) + k2.component_mul(&e2);
    let jinv_u_lin = r.transpose() * Vector3::new(u[0], u[1], u[2]);
    let jinv_u_ang = euler_rates_inv(&Vector3::new(u[3], u[4], u[5]));
    // J⁻¹J̇ν = [ω × v; T⁻¹ Ṫ ω], Ṫ from the Euler rates (φ̇, θ̇).
    let rates = euler_rates(&w);
    let (pd, td) = (rates.x, rates.y);
    #[rustfmt::skip]
    let t_dot = Matrix3::new(
        0.0, cf * tan * pd + sf * sec * sec * td, sf * tan * pd + cf * sec * sec * td,
        0.0, sf * pd,                             cf * pd,
        0.0, cf * sec * pd + sf * tan * sec * td, sf * sec * pd + cf * tan * sec * td,
    );
    let jj_lin = cross_abs(&w, &v);
    let jj_ang = euler_rates_inv(&(t_dot * w.abs()));
    let accel = Vector6::new(
        jinv_u_lin.x + jj_lin.x,
        jinv_u_lin.y + jj_lin.y,
        jinv_u_lin.z + jj_lin.z,
        jinv_u_ang.x + jj_ang.x,
        jinv_u_ang.y + jj_ang.y,
        jinv_u_ang.z + jj_ang.z,
    );
    let m = model::mass_matrix(&p).abs();
    // C(ν)ν = [ω × a; v × a + ω × b], [a; b] = Mν.
    let ab = m * nu.abs();
    let (a, b) = (
        Vector3::new(ab[0], ab[1], ab[2]),
        Vector3::new(ab[3], ab[4], ab[5]),
    );
    let (c_lin, c_ang) = (cross_abs(&w, &a), cross_abs(&v, &a) + cross_abs(&w, &b));
    let coriolis = Vector6::new(c_lin.x, c_lin.y, c_lin.z, c_ang.x, c_ang.y, c_ang.z);
    let damping = Vector6::from_fn(|i, _| p.damping[i].abs() * nu[i] * nu[i]);
    // g(η): W − B is exactly 0 (the first three rows), the moments' arms by magnitude.
    let (wt, bu) = (p.weight(), p.buoyancy);
    let k4 = p.r_g[2].abs() * wt + p.z_b_roll.abs() * bu;
    let k5 = p.r_g[2].abs() * wt + p.z_b_pitch.abs() * bu;
    let mx = p.r_g[0].abs() * wt + p.r_b_xy[0].abs() * bu;
    let my = p.r_g[1].abs() * wt + p.r_b_xy[1].abs() * bu;
    let restoring = Vector6::new(
        0.0,
        0.0,
        0.0,
        my * ct * cf + k4 * ct * sf,
        k5 * st + mx * ct * cf,
        mx * ct * sf + my * st,
    );
    m * accel + coriolis + damping + restoring
}

/// Roundings on the longest chain of the f32 τ (the table in the module docs).
const ROUNDINGS: f64 = 24.0;

/// γ_n = n·u/(1 − n·u) for unit roundoff `u`.
fn gamma(n: f64, u: f64) -> f64 {
    n * u / (1.0 - n * u)
}

/// f32's unit roundoff, 2⁻²⁴.
const U32: f64 = f32::EPSILON as f64 / 2.0;
/// f64's, 2⁻⁵³ (the reference's own error).
const U64: f64 = f64::EPSILON / 2.0;

/// micromath's sin/cos are off by ≈ 1e-3 absolute: measured and held within a loose 5 % of
/// ‖τ‖∞ only (the rounding bound does not apply).
const MICROMATH_TOLERANCE: f64 = 5e-2;

/// The board's τ against the f64 one at one state.
struct Comparison {
    /// |τ₃₂ − τ₆₄| per component.
    error: Vector6<f64>,
    /// S per component ([`tau_abs`]).
    scale: Vector6<f64>,
    /// ‖τ₆₄‖∞.
    tau_norm: f64,
}

impl Comparison {
    fn new(c: &Controller, ticks: u64, eta: &[f32; 6], nu: &[f32; 6], tr: &Trajectory) -> Self {
        let out = c.update(ticks, eta, nu, tr);
        assert_eq!(out.status, Status::Ok);
        let d = tr.sample(ticks, c.config().rate_hz);
        let reference = tau_f64(c.config(), eta, nu, &d);
        Comparison {
            error: (Vector6::from(out.tau).cast::<f64>() - reference).abs(),
            scale: tau_abs(c.config(), eta, nu, &d),
            tau_norm: reference.amax(),
        }
    }

    /// max |τ₃₂ − τ₆₄| / ‖τ₆₄‖∞.
    fn relative(&self) -> f64 {
        self.error.max() / self.tau_norm
    }

    /// The largest error in units of u·S (the bound is [`ROUNDINGS`] of them, and a hair).
    fn in_roundings(&self) -> f64 {
        self.error.component_div(&(self.scale * U32)).max()
    }

    /// Within γ₂₄·S (+ the reference's own γ₂₄·S at f64) in every component; micromath within
    /// its tolerance of ‖τ‖∞.
    fn holds(&self) -> bool {
        if cfg!(feature = "micromath") {
            return self.relative() <= MICROMATH_TOLERANCE;
        }
        let bound = self.scale * (gamma(ROUNDINGS, U32) + gamma(ROUNDINGS, U64));
        self.error.iter().zip(bound.iter()).all(|(e, b)| e <= b)
    }
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
    /// Within γ₂₄·S of the f64 τ, component by component (the module docs derive it), for
    /// states near every Table-1 mission: offsets up to 2 m and 0.3 rad, body rates up to
    /// 0.3 rad/s, pitch within ±0.6 rad.
    #[test]
    fn tau_is_within_its_rounding_bound_of_f64(
        case in 0usize..6,
        ticks in 0u64..7000,
        d_eta in prop::array::uniform6(-1.0f32..1.0),
        d_nu in prop::array::uniform6(-1.0f32..1.0),
    ) {
        let c = controller();
        let tr = Trajectory::table1(Table1Case::ALL[case]);
        let d = tr.sample(ticks, c.config().rate_hz);
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
        let cmp = Comparison::new(c, ticks, &eta, &nu, &tr);
        prop_assert!(
            cmp.holds(),
            "error {:?} beyond {ROUNDINGS} roundings of S {:?} ({:.2} u·S; {:.2e} of ‖τ‖∞)",
            cmp.error, cmp.scale, cmp.in_roundings(), cmp.relative()
        );
    }
}

/// The largest relative error in 2·10⁶ random states drawn like the property test's
/// (1.62·10⁻⁶ of ‖τ‖∞, beyond the 10⁻⁶ asserted until issue 18): like issue 18's case, the
/// sway force loses its digits to K₂·M₂₂ times the rounding of η̇ = Rν. Within the bound.
#[test]
fn the_worst_relative_case_found_is_within_the_rounding_bound() {
    let c = controller();
    let tr = Trajectory::table1(Table1Case::FigureEight40x40);
    let eta = [
        -16.77202,
        -16.50406,
        5.5094943,
        -0.08543912,
        0.12573896,
        -2.3796172,
    ];
    let nu = [
        1.698024,
        -0.45323002,
        -0.4431514,
        -0.16165839,
        -0.106656976,
        0.014307387,
    ];
    let cmp = Comparison::new(c, 5085, &eta, &nu, &tr);
    eprintln!(
        "the worst relative case found: sway error {:.2e} N, S_y {:.3e} N, ‖τ‖∞ {:.1} N: {:.2e} of ‖τ‖∞, {:.2} u·S",
        cmp.error[1], cmp.scale[1], cmp.tau_norm, cmp.relative(), cmp.in_roundings()
    );
    assert!(cmp.holds());
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

/// The figures the note quotes: over a deterministic sweep of the missions, the worst error
/// relative to ‖τ‖∞ and in units of u·S (the bound is 24 of them; module docs).
#[test]
fn report_tau_error_over_the_missions() {
    let c = controller();
    let (mut relative, mut roundings) = (0.0f64, 0.0f64);
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        for ticks in (0..7000).step_by(37) {
            let d = tr.sample(ticks, c.config().rate_hz);
            let w = ticks as f32 * 0.013;
            let mut eta: [f32; 6] = d.eta.into();
            eta[0] += 0.3 * w.sin();
            eta[1] -= 0.2 * w.cos();
            eta[3] += 0.1 * (1.3 * w).sin();
            eta[4] += 0.05 * (0.7 * w).cos();
            eta[5] += 0.05 * (0.9 * w).sin();
            let nu = [1.2 + 0.3 * w.cos(), 0.1, -0.05, 0.02, 0.01, 0.1];
            let cmp = Comparison::new(c, ticks, &eta, &nu, &tr);
            assert!(
                cmp.holds(),
                "{case:?} at tick {ticks}: {:?} vs S {:?}",
                cmp.error,
                cmp.scale
            );
            relative = relative.max(cmp.relative());
            roundings = roundings.max(cmp.in_roundings());
        }
    }
    let bound = if cfg!(feature = "micromath") {
        format!("micromath: bound {MICROMATH_TOLERANCE} of ‖τ‖∞")
    } else {
        format!("bound {ROUNDINGS} u·S")
    };
    eprintln!(
        "f32 τ vs f64 over the Table-1 missions ({}): worst {relative:.2e} of ‖τ‖∞, {roundings:.2} u·S ({bound})",
        controller_core::math::BACKEND
    );
}
