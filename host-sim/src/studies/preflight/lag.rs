//! The thrusters' lag's share of the envelope (docs/real-vehicle.md#the-lags-share,
//! **Choice 509**): the overshoot of the feedback taking up the model mismatch through
//! lagged thrusters, per thruster, kept on each side of the margin envelope.
//!
//! **What it is** (measured, docs/search.md#against-the-real-preflight): the law's feedforward
//! is its nominal model; the plant as written (its payload, the current the law does not know)
//! needs Δτ = τ − τ̂ more, which the feedback takes up from zero error at the start of a
//! mission (and holds thereafter). Its command answering that step overshoots the steady
//! Δτ; through a first-order lag τ_L the applied thrust arrives late, the error grows further
//! before it is met, and the command overshoots more: on the falsifying missions of the
//! realities (τ_L 0.18–0.26 s) the vertical thrusters reached −83 to −88 N for 0.2–1.8 s
//! against a steady −55 N, every saturated period in the first two seconds.
//!
//! **The loop** (per controlled axis j of η: x, y, z, pitch, yaw, as the path budget's
//! [`Loop`] flies it, one period T at a time): the error s = [e, ė] moves as
//! s⁺ = F s + g(a + d) (F = [[1, T], [0, 1]], g = [T²/2, T]), d a unit step of unexplained
//! acceleration, the law's command u = −G s with G = [K₁, K₂]
//! (the nominal feedback: outside its boundary layer the switching term of Eq 30 is a push
//! bounded by δ_max, not a gain — the linear gain (δ_max/μ)p would overshoot far more than
//! the flights do) and a the acceleration the thrusters apply over the period: with the lag's state
//! aₖ (the thrust at the period's start) and λ = e^(−T/τ_L),
//!
//!   a̅ = u + (aₖ − u)(τ_L/T)(1 − λ),   aₖ₊₁ = u + (aₖ − u)λ,                     (L1)
//!
//! (the lag's exact mean over a held command, the simulator's Choice 400; the lag starts at
//! the first command, as the simulator's does), and a̅ = u without a lag. The loop starts at
//! the scenario's start offset s₀ = [e₀ⱼ, 0] under the step dⱼ = ±|Δτⱼ|/M̂ⱼⱼ, and
//! Pⱼ(τ_L) = maxₜ |u(t)| is its command's peak. The margin already covers the loop without a
//! lag (the contract's measured missions fly within it), so the lag's share is the peak it
//! adds, the worse sign of d:
//!
//!   rᵢ = Σⱼ |(B₅⁻¹)ᵢⱼ| · M̂ⱼⱼ · max±(Pⱼ(τ_L) − Pⱼ(0))⁺,                            (L2)
//!
//! Δτ the mismatch at the start of the path (the reference's first sample, at the scenario's
//! speed and at rest, the larger per axis), the plant as written at t = 0 (its payload) under
//! each current the check takes (a Gauss–Markov current's ±3σ corners), against the nominal
//! model with no current, through the board's allocation B₅⁻¹ with each axis at its worst sign.
//! rᵢ is kept on each side of the margin envelope, as the navigation's share is
//! ([`super::navigation::keep`]): a mission whose peak demand leaves less room than rᵢ is
//! refused, and one whose mismatch alone takes it is refused at every time scale.
//!
//! Not modelled here: a payload profile's later jumps (each a step of the mismatch too), and
//! a wandering current's rate (the falsifying missions searched did not need it).

use controller_core::axes::ACTUATED;
use controller_core::effectiveness::THRUSTERS;
use controller_core::kinematics::{self, Attitude};
use controller_core::{Mission, Trajectory};
use nalgebra::{Vector2, Vector3, Vector6};

use super::path_budget::{current_corners, Loop, LoopEstimate};
use super::CheckError;
use crate::plant::{Plant, PlantState, PlantTerms};
use crate::scenario::Scenario;

/// Periods the step response is flown (20 s at 100 Hz: every loop of the vehicle's gains has
/// settled long before).
const STEP_PERIODS: usize = 2000;

/// Peak |u| (m/s² or rad/s²) of the loop `lp` from the initial error `e0` under a step `d` of
/// unexplained acceleration, with the thrusters' lag `lag` (s; 0: none), (L1).
pub(super) fn response_peak(lp: &Loop, lag: f64, e0: f64, d: f64) -> f64 {
    let (f, g) = (lp.f(), lp.g());
    let (lambda, mean) = if lag > 0.0 {
        let l = (-lp.t / lag).exp();
        (l, (lag / lp.t) * (1.0 - l))
    } else {
        (0.0, 0.0)
    };
    let mut s = Vector2::new(e0, 0.0);
    let mut est = LoopEstimate {
        x: s,
        ..LoopEstimate::default()
    };
    // The thrusters hold the law's first command before the mission starts (the simulator's
    // lag starts at its first target).
    let mut applied = lp.input(&s, &est);
    let mut peak: f64 = 0.0;
    for _ in 0..STEP_PERIODS {
        let u = lp.input(&s, &est);
        peak = peak.max(u.abs());
        let a = u + (applied - u) * mean;
        applied = u + (applied - u) * lambda;
        let next = f * s + g * (a + d);
        est = lp.estimate_step(&est, u, &next);
        s = next;
        if !s.iter().all(|x| x.is_finite()) {
            return f64::INFINITY;
        }
    }
    peak
}

/// The mismatch Δτ = τ − τ̂ at the start of the path at 1/k = `inv_k`, per current.
fn start_mismatch(scenario: &Scenario, inv_k: f64) -> Result<Vec<Vector6<f64>>, CheckError> {
    let cfg = scenario.config();
    let path = Trajectory::new(Mission {
        time_scale: 1.0,
        ..cfg.mission()
    })
    .map_err(|e| CheckError::Invalid(format!("the mission at time scale 1: {e}")))?;
    let d = path.sample(0, 20);
    let eta: Vector6<f64> = d.eta.cast();
    let att = Attitude::from_eta(&eta);
    let jinv = kinematics::jacobian_inv(&att);
    let nu = jinv * (d.eta_dot.cast::<f64>() * inv_k);
    let jjn = kinematics::jinv_jdot_nu(&att, &nu).unwrap_or_else(|_| Vector6::zeros());
    let nu_dot = jinv * (d.eta_ddot.cast::<f64>() * (inv_k * inv_k)) - jjn;
    let state = PlantState { eta, nu };
    let plant = Plant::new(cfg.plant_params_at(0.0), PlantTerms::default())
        .map_err(|e| CheckError::Invalid(format!("the payload at t = 0: {e}")))?;
    let nominal = Plant::new(
        scenario.controller().params().cast(f64::from),
        PlantTerms::default(),
    )
    .map_err(|e| CheckError::Invalid(format!("the law's nominal model: {e}")))?;
    let tau_hat = nominal.required_force(&state, &nu_dot, &Vector3::zeros());
    Ok(current_corners(&cfg.current)
        .iter()
        .map(|c| plant.required_force(&state, &nu_dot, c) - tau_hat)
        .collect())
}

/// Per thruster, the thrust (N) the lag's overshoot needs on each side of the margin
/// envelope, (L2); zeros without a lag or on ideal actuators.
pub fn reserve(scenario: &Scenario) -> Result<[f64; THRUSTERS], CheckError> {
    let cfg = scenario.config();
    let lag = match cfg.thruster_lag {
        Some(l) if l > 0.0 && !cfg.ideal_actuators => l,
        _ => return Ok([0.0; THRUSTERS]),
    };
    let scale = super::time_scale(cfg.time_scale);
    let mut dtau = Vector6::<f64>::zeros();
    for inv_k in [1.0 / scale, 0.0] {
        for m in start_mismatch(scenario, inv_k)? {
            for j in 0..6 {
                dtau[j] = dtau[j].max(m[j].abs());
            }
        }
    }
    let mass = Plant::new(
        scenario.controller().params().cast(f64::from),
        PlantTerms::default(),
    )
    .map_err(|e| CheckError::Invalid(format!("the law's nominal model: {e}")))?
    .mass_matrix();
    // Per axis, the force (N, N·m) the lag adds to the command's peak: the mismatch's step
    // and the start offset together, at the worst relative sign (L2).
    let mut extra = [0.0; 6];
    for &j in &ACTUATED {
        // The nominal feedback K₁, K₂: outside its boundary layer the switching term is a
        // bounded push, not a gain (module docs).
        let lp = Loop::with_delta(scenario, j, 0.0)?;
        let (m, e0) = (mass[(j, j)], cfg.initial_offset[j]);
        let d = dtau[j] / m;
        extra[j] = [d, -d]
            .iter()
            .map(|&d| m * (response_peak(&lp, lag, e0, d) - response_peak(&lp, 0.0, e0, d)))
            .fold(0.0, f64::max);
    }
    let alloc = scenario.controller().allocation();
    let mut out = [0.0; THRUSTERS];
    for &j in &ACTUATED {
        let mut unit = Vector6::<f32>::zeros();
        unit[j] = 1.0;
        let column = alloc.thrusts(&unit);
        for (o, b) in out.iter_mut().zip(column) {
            *o += f64::from(b).abs() * extra[j];
        }
    }
    if out.iter().any(|x| !x.is_finite()) {
        return Err(CheckError::Invalid(format!(
            "the loop with a thruster lag of {lag} s is unstable"
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The loop's step response without a lag settles at u = −d: its peak is at least 1; a
    /// lag makes it overshoot more, the more the longer the lag.
    #[test]
    fn the_lag_adds_overshoot_monotonically() {
        let s = crate::scenario::real_vehicle::real_scenarios()
            .unwrap()
            .swap_remove(0);
        let lp = Loop::with_delta(&s, 2, 0.0).unwrap();
        let p0 = response_peak(&lp, 0.0, 0.0, 1.0);
        let p1 = response_peak(&lp, 0.1, 0.0, 1.0);
        let p3 = response_peak(&lp, 0.3, 0.0, 1.0);
        assert!(p0 >= 1.0 - 1e-9, "{p0}");
        assert!(p1 > p0 && p3 > p1, "{p0} {p1} {p3}");
    }
}
