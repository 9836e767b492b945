//! The robust Lyapunov law of Roy et al. (2013), Eqs (7), (12)–(17), (26), (29), (30).
//!
//! One idea per function: tracking errors, the nominal input ū, the Lyapunov matrix P, the
//! switching signal w = BᵀPe, the uncertainty bound δ(e,t), the robust term Δu, and the body
//! force τ by the inversion-free route. [`crate::controller::Controller::update`] strings them
//! together with the allocation.
//!
//! Axes: η = [x y z φ θ ψ]. Roll ([`crate::axes::ROLL`]) is neither actuated nor controlled
//! (K₁₄ = K₂₄ = 0 in the paper): it is excluded from ‖e‖, from w and from Δu; the controlled
//! axes are [`crate::axes::ACTUATED`].

use nalgebra::{Matrix6, RealField, Vector6};

use crate::axes::YAW;
use crate::kinematics::Kinematics;
use crate::model::{self, VehicleParams};

/// Which robust term Δu the law adds to ū.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RobustLaw {
    /// Theorem 3, Eq (26): Δu = −δ w/‖w‖ (discontinuous; chatters in a sampled loop).
    Discontinuous,
    /// Theorem 4, Eq (30): Δu = −δ w/‖w‖ outside the boundary layer ‖w‖ ≥ μ, −(δ/μ) w inside.
    /// The default.
    BoundaryLayer,
}

/// Per-axis solution P = [[p₁₁, p₁₂], [p₁₂, p₂₂]] of Āᵢᵀ P + P Āᵢ = −diag(q₁, q₂) with
/// Āᵢ = [[0, 1], [−k₁, −k₂]] (Eqs 14–15 and Theorem 3, per axis: docs/law.md#the-lyapunov-matrix-p-theorem-3 **Choice**).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisLyapunov<T> {
    pub p11: T,
    pub p12: T,
    pub p22: T,
}

impl<T: RealField + Copy> AxisLyapunov<T> {
    /// Closed form: p₁₂ = q₁/(2k₁), p₂₂ = (q₂ + 2p₁₂)/(2k₂), p₁₁ = k₁p₂₂ + k₂p₁₂.
    ///
    /// The full 12×12 Lyapunov equation of Theorem 3 has no positive-definite solution with the
    /// paper's K₁₄ = K₂₄ = 0 (the roll block of Ā has a double zero eigenvalue); Ā is block
    /// diagonal per axis, so P is solved per controlled axis and the roll rows are zero.
    /// Requires k₁, k₂ > 0 (checked by the configuration).
    pub fn solve(k1: T, k2: T, q1: T, q2: T) -> Self {
        let two = T::one() + T::one();
        let p12 = q1 / (two * k1);
        let p22 = (q2 + two * p12) / (two * k2);
        let p11 = k1 * p22 + k2 * p12;
        AxisLyapunov { p11, p12, p22 }
    }
}

/// Tracking errors e₁ = η − η_d (Eq 12) and e₂ = η̇ − η̇_d (Eq 13).
///
/// **Choice** (docs/law.md#structure): the yaw component of e₁ is wrapped to (−π, π], so a vehicle at
/// ψ = 179° tracking ψ_d = −179° sees a 2° error, not 358°.
pub fn tracking_errors(
    eta: &Vector6<f32>,
    eta_dot: &Vector6<f32>,
    eta_d: &Vector6<f32>,
    eta_d_dot: &Vector6<f32>,
) -> (Vector6<f32>, Vector6<f32>) {
    let mut e1 = eta - eta_d;
    e1[YAW] = crate::math::wrap_pi(e1[YAW]);
    (e1, eta_dot - eta_d_dot)
}

/// Nominal input ū = η̈_d − K₁e₁ − K₂e₂ (Eq 17).
pub fn nominal_input<T: RealField + Copy>(
    eta_d_ddot: &Vector6<T>,
    k1: &Vector6<T>,
    k2: &Vector6<T>,
    e1: &Vector6<T>,
    e2: &Vector6<T>,
) -> Vector6<T> {
    eta_d_ddot - k1.component_mul(e1) - k2.component_mul(e2)
}

/// w = BᵀPe (Theorem 3), per axis wᵢ = p₁₂ e₁ᵢ + p₂₂ e₂ᵢ; zero on roll (its P rows are zero).
pub fn switching_signal<T: RealField + Copy>(
    p: &[AxisLyapunov<T>; 6],
    e1: &Vector6<T>,
    e2: &Vector6<T>,
) -> Vector6<T> {
    Vector6::from_fn(|i, _| p[i].p12 * e1[i] + p[i].p22 * e2[i])
}

/// Robust term Δu of Eq (26) (Theorem 3) or Eq (30) (Theorem 4), given w, ‖w‖, δ and μ.
///
/// Both satisfy ‖Δu‖ ≤ δ; Eq (30) is continuous at ‖w‖ = μ. Fixed work: no branch depends on
/// anything but the comparison of ‖w‖ with μ (or 0).
pub fn robust_term(
    law: RobustLaw,
    w: &Vector6<f32>,
    w_norm: f32,
    delta: f32,
    mu: f32,
) -> Vector6<f32> {
    let gain = match law {
        RobustLaw::Discontinuous => {
            if w_norm > 0.0 {
                delta / w_norm
            } else {
                0.0
            }
        }
        RobustLaw::BoundaryLayer => {
            if w_norm >= mu {
                delta / w_norm
            } else {
                delta / mu
            }
        }
    };
    w * -gain
}

/// Inputs of the uncertainty bound δ(e,t) of Eq (29) that change every step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaInputs {
    /// K_d: bound on ‖η̈_d‖ (Assumption 1, Eq 19), from the trajectory.
    pub accel_bound: f32,
    /// ‖e‖ over the controlled axes, e = [e₁; e₂].
    pub error_norm: f32,
    /// ‖ν‖ (body velocity).
    pub nu_norm: f32,
    /// ‖J⁻¹J̇ν‖.
    pub jinv_jdot_nu_norm: f32,
    /// |cos θ|.
    pub cos_theta_abs: f32,
}

/// Configuration-time constants of δ(e,t): see [`crate::uncertainty`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaConstants {
    /// β of Assumption 2 (0 < β < 1).
    pub beta: f32,
    /// ‖K‖ = ‖[K₁ K₂]‖₂.
    pub k_norm: f32,
    /// ΔM = sup‖M(p) − M(p₀)‖₂ over the parameter box.
    pub delta_m: f32,
    /// Δg = sup‖g(p, η) − g(p₀, η)‖ over the box and every attitude.
    pub delta_g: f32,
    /// ‖b‖ at level attitude (controlled rows, or the literal full bound).
    pub b_level: f32,
    /// Power of 1/|cos θ| with which the ‖b‖ bound grows: 1 for the controlled rows, 2 for the
    /// literal ‖J M⁻¹ Jᵀ‖ ≤ ‖J‖² ‖M⁻¹‖.
    pub b_sec_power: u8,
}

/// γ(t) of Eq (21) (Assumption 3), docs/law.md#the-uncertainty-bound-eq-29 **Choice**: a bound on the body-frame model
/// mismatch ‖Δh‖ = ‖ΔC ν + Δg‖ over the parameter box:
/// γ = √2·ΔM·‖ν‖² + ΔM·‖J⁻¹J̇ν‖ + Δg.
pub fn gamma(c: &DeltaConstants, nu_norm: f32, jinv_jdot_nu_norm: f32) -> f32 {
    core::f32::consts::SQRT_2 * c.delta_m * nu_norm * nu_norm
        + c.delta_m * jinv_jdot_nu_norm
        + c.delta_g
}

/// ‖b‖ bound at the current pitch: b_level · max(1, 1/|cos θ|)^power (docs/law.md#the-uncertainty-bound-eq-29).
pub fn b_norm_bound(c: &DeltaConstants, cos_theta_abs: f32) -> f32 {
    let sec = if cos_theta_abs < 1.0 {
        1.0 / cos_theta_abs
    } else {
        1.0
    };
    if c.b_sec_power >= 2 {
        c.b_level * sec * sec
    } else {
        c.b_level * sec
    }
}

/// δ(e,t) = (β K_d + ‖K‖ ‖e‖ + ‖b‖ γ(t)) / (1 − β) (Eq 29), unclamped.
pub fn uncertainty_bound(c: &DeltaConstants, x: &DeltaInputs) -> f32 {
    let g = gamma(c, x.nu_norm, x.jinv_jdot_nu_norm);
    (c.beta * x.accel_bound + c.k_norm * x.error_norm + b_norm_bound(c, x.cos_theta_abs) * g)
        / (1.0 - c.beta)
}

/// Body force by the inversion-free route (docs/law.md#the-inversion-free-route-to-τ):
/// τ = M̂ (J⁻¹u − J⁻¹J̇ν) + Ĉ(ν)ν + D̂(ν)ν + ĝ(η).
///
/// This is Eq (7), τ̄ = b̂⁻¹(u + f̂), mapped to the body by τ = Jᵀτ̄: with b̂⁻¹ = M̄̂ and
/// f̂ = b̂Ĥ the products collapse and no matrix is inverted at run time (a test keeps the
/// literal Eq 7 route and this one in agreement). `jinv_jdot_nu` is
/// [`Kinematics::jinv_jdot_nu`], passed in because δ(e,t) needs its norm too; `kin` is the
/// step's one kinematics value. C(ν)ν and D(ν)ν are formed as vectors
/// ([`model::coriolis_force_of`], [`model::damping_force`]); `m_hat` is a
/// [`model::mass_matrix`], whose structure [`model::mass_mul_pair`] multiplies by, both
/// products at once (Choices 521, 574).
pub fn body_force<T: RealField + Copy>(
    m_hat: &Matrix6<T>,
    params: &VehicleParams<T>,
    kin: &Kinematics<T>,
    nu: &Vector6<T>,
    u: &Vector6<T>,
    jinv_jdot_nu: &Vector6<T>,
) -> Vector6<T> {
    let accel = kin.jinv_mul(u) - jinv_jdot_nu;
    let (m_accel, m_nu) = model::mass_mul_pair(m_hat, &accel, nu);
    m_accel
        + model::coriolis_force_of(&m_nu, nu)
        + model::damping_force(params, nu)
        + model::restoring(params, &kin.att)
}
