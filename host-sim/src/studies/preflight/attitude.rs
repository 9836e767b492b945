//! The attitude the vehicle holds along a mission, which the preflight evaluates the thrust
//! demand at (docs/real-vehicle.md#the-attitude-the-vehicle-holds): not the reference's level attitude, but
//!
//! - **the heel** — roll is neither actuated nor controlled (every thruster sits on the centre
//!   line), so the vehicle floats at the roll angle where the roll row of Eq (1) balances: the
//!   static heel of a lateral CG shift against the righting moment, moved a little by the
//!   dynamic roll moment of the turn ([`heel`]); around it, a **roll swing** of the amplitude
//!   the start and the payload's jumps leave (the model has no roll damping), whose extremes
//!   are evaluated with the roll acceleration that brings them ([`Swing`]);
//! - **the pitch offset** — the law has no integrator: the model mismatch in pitch (the
//!   payload's CG moment, above all) is held by a steady pitch error e_θ = −m/S, with S the
//!   law's pitch stiffness at zero error, M̂₅₅ (k₁ + p₁₂ δ/μ) inside the boundary layer
//!   ([`axis_stiffness`]); the vehicle flies nose-up or -down by e_θ, and at speed the Munk
//!   moment of that angle of attack is thrust the pair must give;
//! - **the yaw offset** — the same in yaw: the law's model has no current, so the current's
//!   yaw moment (its Munk moment, strongest with the current across the track) and the
//!   payload's yaw mismatch are held by a steady heading error e_ψ = −n/S_ψ; the vehicle then
//!   flies at that sideslip to its track, and the sway force and Munk moment of the sideslip
//!   are thrust the horizontal pair must give — on a reversed thruster's weak side, more than
//!   the margin leaves (docs/real-vehicle.md#the-attitude-the-vehicle-holds, **Choice 550**).

use controller_core::law::{self, DeltaInputs};
use controller_core::{Controller, RobustLaw};
use nalgebra::Vector6;

use crate::plant::{roll_moments, Plant, PlantState};

/// Index of roll, pitch and yaw in η, ν and τ.
const ROLL: usize = 3;
const PITCH: usize = 4;
const YAW: usize = 5;

/// The heel (rad) at which the roll row of the force `plant` needs at `state` (with `nu_dot`
/// and the current `current`) vanishes: one Newton step from the static heel on
/// g₄ = cθ ρ sin(φ − φ₀), ρ = √(m_y² + k₄²), φ₀ = atan2(m_y, k₄), the rest of the roll row
/// (the turn's dynamic moment, a few N m against ρ ≈ 400 N m) held at its value there.
/// `state.eta[3]` is ignored; `None` when the vehicle has no righting moment.
pub fn heel(
    plant: &Plant,
    state: &PlantState,
    nu_dot: &Vector6<f64>,
    current: &nalgebra::Vector3<f64>,
) -> Option<f64> {
    let (my, k4) = roll_moments(plant.params());
    let rho = my.hypot(k4);
    let c_theta = state.eta[PITCH].cos();
    if k4 <= 0.0 || c_theta.abs() < 1e-6 {
        return None;
    }
    let phi0 = my.atan2(k4);
    let mut at = *state;
    at.eta[ROLL] = phi0;
    // The roll row at the static heel is its dynamic part (g₄ vanishes there).
    let dynamic = plant.required_force(&at, nu_dot, current)[ROLL];
    let s = (-dynamic / (c_theta * rho)).clamp(-1.0, 1.0);
    Some(phi0 + s.asin())
}

/// The roll swing about the heel: amplitude (rad) and the natural frequency ω (rad/s) of the
/// undamped roll, ω² = c_θ ρ / M₄₄.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swing {
    pub amplitude: f64,
    pub omega: f64,
}

impl Swing {
    /// No swing.
    pub const NONE: Swing = Swing {
        amplitude: 0.0,
        omega: 0.0,
    };

    /// Below this amplitude (rad) the swing is not evaluated (its extremes are the heel).
    pub const NEGLIGIBLE: f64 = 1e-4;

    /// The roll attitudes to evaluate about the heel `phi`, each with the roll acceleration
    /// ṗ = −ω² (φ − heel) the swing has there: the heel alone, or the swing's two extremes.
    pub fn extremes(&self, phi: f64) -> impl Iterator<Item = (f64, f64)> + use<> {
        let (a, w2) = (self.amplitude, self.omega * self.omega);
        let swings = a > Self::NEGLIGIBLE;
        let centre = (!swings).then_some((phi, 0.0));
        let ends = swings.then_some([(phi - a, w2 * a), (phi + a, -w2 * a)]);
        centre.into_iter().chain(ends.into_iter().flatten())
    }
}

/// The natural frequency ω (rad/s) of the undamped roll of `plant` pitched by θ: ω² =
/// |cθ| ρ / M₄₄, with ρ the righting coefficient √(m_y² + k₄²) and M₄₄ = I_x − K_ṗ.
pub fn roll_frequency(plant: &Plant, theta: f64) -> f64 {
    let (my, k4) = roll_moments(plant.params());
    let m44 = plant.mass_matrix()[(ROLL, ROLL)];
    (theta.cos().abs() * my.hypot(k4) / m44).max(0.0).sqrt()
}

/// The amplitude of the undamped roll oscillator φ̈ = −ω² (φ − φ_eq(t)) driven by its moving
/// equilibrium, sampled at the preflight's sample times: the phase vector
/// z = (φ − φ_eq) + i φ̇/ω is rotated exactly between steps of at most `dt`, and shifted by
/// every jump of φ_eq (exact for an equilibrium held over each step); its modulus is the
/// amplitude. `equilibrium(t)` gives φ_eq; the swing starts from `start` (the level start's
/// 0, or the trim start's φ_eq(0), which gives no swing).
pub fn swing_amplitudes(
    times: &[f64],
    omega: f64,
    start: Option<f64>,
    equilibrium: &dyn Fn(f64) -> f64,
) -> Vec<f64> {
    /// Longest step of the phase rotation (s): ω dt ≤ 0.05 for the AUV-150's ω ≈ 4.6 rad/s.
    const DT: f64 = 0.01;
    let mut out = Vec::with_capacity(times.len());
    let Some(&t0) = times.first() else {
        return out;
    };
    let mut eq = equilibrium(t0);
    let (mut re, mut im) = (start.map_or(0.0, |s| s - eq), 0.0);
    let mut t = t0;
    for &t_next in times {
        while t < t_next {
            let h = DT.min(t_next - t);
            let (s, c) = (omega * h).sin_cos();
            (re, im) = (re * c + im * s, im * c - re * s);
            t += h;
            let next = equilibrium(t);
            re -= next - eq;
            eq = next;
        }
        out.push(re.hypot(im));
    }
    out
}

/// The law's stiffness at zero error on the axes that hold a steady error: pitch and yaw
/// (N m per rad of error), [`axis_stiffness`] of each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stiffness {
    pub pitch: f64,
    pub yaw: f64,
}

/// The law's pitch and yaw stiffness on the reference with body velocity `nu`
/// ([`axis_stiffness`]): δ is formed once, as the law forms it once for every axis.
pub fn stiffness(
    controller: &Controller,
    nu: &Vector6<f64>,
    jinv_jdot_nu: &Vector6<f64>,
    cos_theta: f64,
    accel_bound: f64,
) -> Stiffness {
    let c = controller.config();
    let inputs = DeltaInputs {
        accel_bound: accel_bound as f32,
        error_norm: 0.0,
        nu_norm: nu.norm() as f32,
        jinv_jdot_nu_norm: jinv_jdot_nu.norm() as f32,
        cos_theta_abs: cos_theta.abs() as f32,
    };
    let delta = law::uncertainty_bound(controller.delta_constants(), &inputs).min(c.delta_max);
    Stiffness {
        pitch: axis_stiffness(controller, PITCH, delta),
        yaw: axis_stiffness(controller, YAW, delta),
    }
}

/// The law's stiffness at zero error on `axis` (N m per rad of error): the feedback
/// acceleration k₁ e plus the robust term's p₁₂ (δ/μ) e inside the boundary layer (Theorem 4;
/// Theorem 3's discontinuous term has no finite slope and is taken as the boundary layer's at
/// μ), times the nominal inertia M̂ᵢᵢ. δ is the law's own bound at zero error
/// ([`stiffness`]), the smallest it takes there, so the stiffness is the least the law gives
/// and the steady error the largest (conservative: a larger angle of attack or of sideslip, a
/// larger Munk moment).
pub fn axis_stiffness(controller: &Controller, axis: usize, delta: f32) -> f64 {
    let c = controller.config();
    let robust = match (c.robust, c.law) {
        (false, _) => 0.0,
        (true, RobustLaw::BoundaryLayer | RobustLaw::Discontinuous) => {
            f64::from(controller.lyapunov()[axis].p12 * delta / c.mu)
        }
    };
    let m = f64::from(controller.mass_matrix()[(axis, axis)]);
    m * (f64::from(c.k1[axis]) + robust)
}

/// The steady error (rad) that holds a moment mismatch `mismatch` (the moment the plant needs
/// minus what the law's nominal model gives, N m) against the stiffness `stiffness`: the
/// pitch offset, and the yaw offset (the heading error that holds the current's yaw moment,
/// which the law's model does not have).
pub fn steady_error(mismatch: f64, stiffness: f64) -> f64 {
    if stiffness > 0.0 {
        -mismatch / stiffness
    } else {
        0.0
    }
}

/// The steady errors (pitch, yaw; rad) that hold the mismatch between the force the plant
/// `needed` and the one the law's nominal model `modelled` gives, against the law's
/// `stiffness` ([`steady_error`] per axis): where the preflight evaluates the demand.
pub fn steady_errors(
    needed: &Vector6<f64>,
    modelled: &Vector6<f64>,
    stiffness: &Stiffness,
) -> (f64, f64) {
    (
        steady_error(needed[PITCH] - modelled[PITCH], stiffness.pitch),
        steady_error(needed[YAW] - modelled[YAW], stiffness.yaw),
    )
}
