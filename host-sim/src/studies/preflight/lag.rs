//! The thrusters' lag's share of the envelope (docs/real-vehicle.md#the-lags-share,
//! **Choice 509**): the overshoot of the feedback taking up the model mismatch through
//! lagged thrusters, per thruster, kept on the side of the margin envelope it takes.
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
//! s⁺ = F s + g(a + dₖ) (F = [[1, T], [0, 1]], g = [T²/2, T]), dₖ the unexplained
//! acceleration of period k, the law's command u = −G s with G = [K₁ + (δ₀/μ)p₁₂,
//! K₂ + (δ₀/μ)p₂₂] (**Choice 546**): the nominal feedback and the switching term of Eq 30
//! inside its boundary layer, where the start's error keeps it (‖w‖ = ‖BᵀP s‖ is a few
//! thousandths against μ = 0.1 on the falsifying missions), at the law's own δ₀ there (Eq 29
//! at the path's first sample and the start offset, 2.7–4.5 on those missions, not δ_max);
//! and a the acceleration the thrusters apply over the period: with the lag's state aₖ (the
//! thrust at the period's start) and λ = e^(−T/τ_L),
//!
//!   a̅ = u + (aₖ − u)(τ_L/T)(1 − λ),   aₖ₊₁ = u + (aₖ − u)λ,                     (L1)
//!
//! (the lag's exact mean over a held command, the simulator's Choice 400; the lag starts at
//! the first command, as the simulator's does), and a̅ = u without a lag. Choice 509 flew the
//! nominal feedback alone (δ₀ = 0); its overshoot was short of the flights' (measured per
//! period on the missions the search still found: yaw's command peaked at 440 N·m against 424
//! predicted with δ₀ and far less without; pitch overshot its steady demand by 206 N·m against
//! 200 predicted). The loop starts at the scenario's start offset s₀ = [e₀ⱼ, 0] and
//! its command's range is [Lⱼ(τ_L), Hⱼ(τ_L)] = [minₖ uₖ, maxₖ uₖ] (signed, each end
//! including 0). The margin already covers the loop without a lag (the contract's measured
//! missions fly within it), so the lag's share is what it adds on each side (**Choice 557**):
//!
//!   hⱼ = M̂ⱼⱼ · max_c (Hⱼ(τ_L) − Hⱼ(0))⁺,   lⱼ = M̂ⱼⱼ · max_c (Lⱼ(0) − Lⱼ(τ_L))⁺,
//!   rᵢ⁺ = Σⱼ (bᵢⱼ⁺ hⱼ + bᵢⱼ⁻ lⱼ),   rᵢ⁻ = Σⱼ (bᵢⱼ⁺ lⱼ + bᵢⱼ⁻ hⱼ),                   (L2')
//!
//! c the currents' two extremes of the axis's start mismatch, bᵢⱼ the board's allocation B₅⁻¹
//! of η's axis j as a body force at the start's heading (surge and sway turn with ψ; depth,
//! pitch and yaw keep their axis), b⁺ = max(b, 0), b⁻ = max(−b, 0): a thruster that moves with
//! the axis's command takes its excursion above on its upper side, one that moves against it
//! on its lower. rᵢ⁺ is kept below the upper side of the margin envelope and rᵢ⁻ above the
//! lower ([`Reserve::keep`]). Choice 509 kept one
//!
//!   rᵢ = Σⱼ |(B₅⁻¹)ᵢⱼ| · M̂ⱼⱼ · max±(Pⱼ(τ_L) − Pⱼ(0))⁺,  Pⱼ = maxₖ |uₖ|,                 (L2)
//!
//! on both sides: a start offset's first command is its largest |u| with and without the lag,
//! and the lagged loop's swing past it onto the other side (−386 N on depth against +223 N
//! first, a thruster's reversed side, measured on the falsifying mission) added nothing to
//! (L2) beyond what the |u| peak grew. Each side measured and kept on both refused missions
//! that fly; each kept on its own side does not.
//!
//! The mismatch the loop takes up (**Choices 547, 557**) is
//!
//!   dₖ = −(Δτⱼ(0) + Δτₚ,ⱼ(kT) − Δτₚ,ⱼ(0)) / M̂ⱼⱼ,                                      (L3)
//!
//! with its sign (the plant needs Δτ more than the law's model gives: the error accelerates
//! by −Δτ/M̂ until the command u takes it up, e = η − η_d as the start offset is written),
//! Δτⱼ the body's mismatch along η's axis j at the start's heading; Δτ(0) the mismatch at the start of the path (the reference's first sample, at the
//! scenario's speed and at rest, each flown) under each current the check takes (a
//! Gauss–Markov current's ±3σ corners; the axis's two extremes are flown), the plant as
//! written at t = 0 against the nominal model with no current; Δτₚ(t) the payload's part at
//! the same state as its profile moves it: each step of a staircase (a later jump is a step of
//! the mismatch like the start's), |sin ωt| of an abs-sin's maximum (the mismatch is affine in
//! Δp at a state: its rate ωΔτₚ through the lag adds about τ_L ω Δτₚ to the command, the
//! lagged loop's f + τ_L ḟ). It is flown over the mission's span, at most the profile (the
//! last step, one period π/ω of an abs-sin, at most 600 s) and 20 s to settle.
//! A mission whose peak demand leaves less room on a side than rᵢ⁺ or rᵢ⁻ is refused, and
//! one whose mismatch alone takes it is refused at every time scale.
//!
//! Not modelled here: a wandering current's rate (a Gauss–Markov current is held at its ±3σ
//! corners; the falsifying missions measured saturated at the start, not as the current
//! moved), the start's roll and pitch (depth, pitch and yaw are kept on their own body axis),
//! and the η axis's own mass M̂ⱼⱼ for surge and sway at any heading.

use controller_core::axes::ACTUATED;
use controller_core::effectiveness::THRUSTERS;
use controller_core::kinematics::{self, Attitude};
use controller_core::law::{self, DeltaInputs};
use controller_core::thruster::ThrustEnvelope;
use controller_core::{Mission, Trajectory};
use nalgebra::{Vector2, Vector3, Vector6};

use super::path_budget::{current_corners, Loop, LoopEstimate};
use super::CheckError;
use crate::plant::{Plant, PlantState, PlantTerms, VariationProfile};
use crate::scenario::Scenario;

/// Periods the step response is flown (20 s at 100 Hz: every loop of the vehicle's gains has
/// settled long before).
const STEP_PERIODS: usize = 2000;

/// At most this many periods of a payload's profile are flown (600 s at 100 Hz): a slower
/// abs-sin's rate, ω Δτ_p, is smaller still.
const MAX_PROFILE_PERIODS: usize = 60_000;

/// Peak |u| (m/s² or rad/s²) of the loop `lp` from the initial error `e0` under the
/// unexplained acceleration `d(k)` of period k, flown `periods` periods, with the thrusters'
/// lag `lag` (s; 0: none), (L1).
#[cfg(test)]
pub(super) fn response_peak(
    lp: &Loop,
    lag: f64,
    e0: f64,
    periods: usize,
    d: impl Fn(usize) -> f64,
) -> f64 {
    let (lo, hi) = response_range(lp, lag, e0, periods, d);
    hi.max(-lo)
}

/// The range [minₖ uₖ, maxₖ uₖ] (m/s² or rad/s², signed) of the loop `lp`'s command from the
/// initial error `e0` under the unexplained acceleration `d(k)` of period k, flown `periods`
/// periods, with the thrusters' lag `lag` (s; 0: none), (L1); both ends include 0 (the
/// command's peak on each side, (L2')).
pub(super) fn response_range(
    lp: &Loop,
    lag: f64,
    e0: f64,
    periods: usize,
    d: impl Fn(usize) -> f64,
) -> (f64, f64) {
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
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for k in 0..periods {
        let u = lp.input(&s, &est);
        lo = lo.min(u);
        hi = hi.max(u);
        let a = u + (applied - u) * mean;
        applied = u + (applied - u) * lambda;
        let next = f * s + g * (a + d(k));
        est = lp.estimate_step(&est, u, &next);
        s = next;
        if !s.iter().all(|x| x.is_finite()) {
            return (f64::NEG_INFINITY, f64::INFINITY);
        }
    }
    (lo, hi)
}

/// What the loop starts from at 1/k = `inv_k`: the mismatch Δτ = τ − τ̂ at the start of the
/// path per current, and the law's δ there (Eq 29 at the start offset, clamped at δ_max).
struct Start {
    yaw: f64,
    mismatch: Vec<Vector6<f64>>,
    delta: f64,
    payload: Vec<Vector6<f64>>,
}

/// The loop's start at the path's first sample at 1/k = `inv_k` ([`Start`]).
fn start(scenario: &Scenario, inv_k: f64) -> Result<Start, CheckError> {
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
    let controller = scenario.controller();
    let nominal = Plant::new(controller.params().cast(f64::from), PlantTerms::default())
        .map_err(|e| CheckError::Invalid(format!("the law's nominal model: {e}")))?;
    let tau_hat = nominal.required_force(&state, &nu_dot, &Vector3::zeros());
    let offset: f64 = ACTUATED
        .iter()
        .map(|&j| cfg.initial_offset[j].powi(2))
        .sum();
    let delta = law::uncertainty_bound(
        controller.delta_constants(),
        &DeltaInputs {
            accel_bound: (f64::from(path.accel_bound()) * inv_k * inv_k) as f32,
            error_norm: offset.sqrt() as f32,
            nu_norm: nu.norm() as f32,
            jinv_jdot_nu_norm: jjn.norm() as f32,
            cos_theta_abs: att.ctheta.abs() as f32,
        },
    );
    let delta_max = f64::from(controller.config().delta_max);
    Ok(Start {
        yaw: eta[5],
        mismatch: current_corners(&cfg.current)
            .iter()
            .map(|c| plant.required_force(&state, &nu_dot, c) - tau_hat)
            .collect(),
        delta: if delta.is_finite() {
            f64::from(delta).min(delta_max)
        } else {
            delta_max
        },
        payload: payload_profile(scenario, &state, &nu_dot)?,
    })
}

/// Periods the loop is flown (L3): the mission's span, at most the payload's profile (its
/// last step, or one period π/ω of an abs-sin) and [`STEP_PERIODS`] after it to settle.
fn horizon(scenario: &Scenario) -> usize {
    let cfg = scenario.config();
    let t = 1.0 / f64::from(scenario.controller().config().rate_hz);
    let profile = match &cfg.variation {
        VariationProfile::Staircase(steps) => steps.iter().map(|s| s.0).fold(0.0, f64::max),
        VariationProfile::AbsSin { omega, .. } if omega.abs() > 0.0 => {
            std::f64::consts::PI / omega.abs()
        }
        _ => 0.0,
    };
    let span = (cfg.duration / t).ceil().max(1.0);
    let wanted = (profile / t).ceil().min(MAX_PROFILE_PERIODS as f64) + STEP_PERIODS as f64;
    span.min(wanted) as usize
}

/// The payload's share of the mismatch per period k, Δτ_p(kT) − Δτ_p(0), at the start's
/// state (L3): a staircase's levels as they are, an abs-sin's as |sin ωt| of its maximum's
/// (the mismatch is affine in Δp at a state).
fn payload_profile(
    scenario: &Scenario,
    state: &PlantState,
    nu_dot: &Vector6<f64>,
) -> Result<Vec<Vector6<f64>>, CheckError> {
    let cfg = scenario.config();
    let force = |t: f64| -> Result<Vector6<f64>, CheckError> {
        let plant = Plant::new(cfg.plant_params_at(t), PlantTerms::default())
            .map_err(|e| CheckError::Invalid(format!("the payload at t = {t} s: {e}")))?;
        Ok(plant.required_force(state, nu_dot, &Vector3::zeros()))
    };
    let n = horizon(scenario);
    let t = 1.0 / f64::from(scenario.controller().config().rate_hz);
    let at0 = force(0.0)?;
    let mut out = Vec::with_capacity(n);
    match &cfg.variation {
        VariationProfile::Staircase(_) => {
            let (mut level, mut here) = (cfg.variation.at(0.0), Vector6::zeros());
            for k in 0..n {
                let now = cfg.variation.at(k as f64 * t);
                if now != level {
                    here = force(k as f64 * t)? - at0;
                    level = now;
                }
                out.push(here);
            }
        }
        VariationProfile::AbsSin { omega, .. } if omega.abs() > 0.0 => {
            let top = force(std::f64::consts::FRAC_PI_2 / omega.abs())? - at0;
            out.extend((0..n).map(|k| top * (omega * k as f64 * t).sin().abs()));
        }
        _ => out.resize(n, Vector6::zeros()),
    }
    Ok(out)
}

/// Per thruster, the thrust (N) the lag's overshoot adds above its command (`upper`, rᵢ⁺)
/// and below it (`lower`, rᵢ⁻), each kept on its own side of the margin envelope, (L2').
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reserve {
    /// rᵢ⁺ (N, ≥ 0): taken from the envelope's upper (forward) side.
    pub upper: [f64; THRUSTERS],
    /// rᵢ⁻ (N, ≥ 0): taken from the envelope's lower (reversed) side.
    pub lower: [f64; THRUSTERS],
}

impl Reserve {
    /// The envelope with rᵢ⁺ kept below its upper side and rᵢ⁻ above its lower side, as
    /// [`super::navigation::keep`] keeps one share on both (an emptied side stays at zero).
    pub fn keep(&self, envelope: ThrustEnvelope) -> ThrustEnvelope {
        let mut e = envelope;
        for i in 0..THRUSTERS {
            let (up, down) = (self.upper[i], self.lower[i]);
            if up == 0.0 && down == 0.0 {
                continue;
            }
            e.min[i] = (e.min[i] + down as f32).min(0.0);
            e.max[i] = (e.max[i] - up as f32).max(0.0);
            if e.max[i] <= e.min[i] {
                e.max[i] = e.min[i] + f32::EPSILON;
            }
        }
        e
    }
}

/// The body force or moment (per unit) a unit command of η's axis `j` is at the start's
/// heading ψ (L2'): surge and sway turn with it (x: [cos ψ, −sin ψ], y: [sin ψ, cos ψ]); depth,
/// pitch and yaw keep their own axis (roll and pitch at the start are small).
fn body_direction(j: usize, yaw: f64) -> Vector6<f32> {
    let (s, c) = yaw.sin_cos();
    let mut v = Vector6::<f64>::zeros();
    match j {
        0 => (v[0], v[1]) = (c, -s),
        1 => (v[0], v[1]) = (s, c),
        _ => v[j] = 1.0,
    }
    v.cast()
}

/// Per thruster, the thrust (N) the lag's overshoot needs on each side of the margin
/// envelope, (L2'); zeros without a lag or on ideal actuators.
pub fn reserve(scenario: &Scenario) -> Result<Reserve, CheckError> {
    let cfg = scenario.config();
    let lag = match cfg.thruster_lag {
        Some(l) if l > 0.0 && !cfg.ideal_actuators => l,
        _ => return Ok(Reserve::default()),
    };
    let scale = super::time_scale(cfg.time_scale);
    let mass = Plant::new(
        scenario.controller().params().cast(f64::from),
        PlantTerms::default(),
    )
    .map_err(|e| CheckError::Invalid(format!("the law's nominal model: {e}")))?
    .mass_matrix();
    // Per axis, the force (N, N·m) the lag adds to the command above ([0]) and below ([1]):
    // the mismatch's step and the start offset (its sign as written) together, the mismatch
    // at either sign, at the scenario's speed and at rest, each with the law's δ there (L2').
    let mut extra = [[0.0f64; 2]; 6];
    let mut yaw = 0.0;
    for inv_k in [1.0 / scale, 0.0] {
        let st = start(scenario, inv_k)?;
        yaw = st.yaw;
        let n = st.payload.len();
        for &j in &ACTUATED {
            let lp = Loop::with_delta(scenario, j, st.delta)?;
            let (m, e0) = (mass[(j, j)], cfg.initial_offset[j]);
            // The currents' extremes of this axis's start mismatch (the body's Δτ along η's
            // axis j at the start's heading); the loop takes it up, ë = u − Δτⱼ/M̂ⱼⱼ.
            let dir = body_direction(j, st.yaw).cast::<f64>();
            let along = |v: &Vector6<f64>| dir.dot(v);
            let lo = st.mismatch.iter().map(along).fold(f64::INFINITY, f64::min);
            let hi = st
                .mismatch
                .iter()
                .map(along)
                .fold(f64::NEG_INFINITY, f64::max);
            for c in [lo, hi] {
                let d = |k: usize| -(c + along(&st.payload[k])) / m;
                let (lag_lo, lag_hi) = response_range(&lp, lag, e0, n, d);
                let (lo0, hi0) = response_range(&lp, 0.0, e0, n, d);
                extra[j][0] = extra[j][0].max(m * (lag_hi - hi0));
                extra[j][1] = extra[j][1].max(m * (lo0 - lag_lo));
            }
        }
    }
    let alloc = scenario.controller().allocation();
    let mut out = Reserve::default();
    for &j in &ACTUATED {
        let [up, down] = extra[j];
        let column = alloc.thrusts(&body_direction(j, yaw));
        for (i, b) in column.iter().enumerate() {
            // A positive entry moves thruster i as the axis's command does; a negative one
            // against it: the command's excursion above is the thruster's below.
            let b = f64::from(*b);
            let (with, against) = (b.max(0.0), (-b).max(0.0));
            out.upper[i] += with * up + against * down;
            out.lower[i] += with * down + against * up;
        }
    }
    if out.upper.iter().chain(&out.lower).any(|x| !x.is_finite()) {
        return Err(CheckError::Invalid(format!(
            "the loop with a thruster lag of {lag} s is unstable"
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both sides of a reserve, upper then lower.
    fn both(r: &Reserve) -> Vec<f64> {
        r.upper.iter().chain(&r.lower).copied().collect()
    }

    /// A start offset without a mismatch: the first command answers it on its own side
    /// (u₀ = −G₁e₀ > 0 for e₀ < 0) and the lagged loop swings past zero onto the other: the
    /// lag adds nothing above and a swing below, which (L2)'s one |u| peak on both sides did
    /// not see (L2').
    #[test]
    fn a_lagged_offset_swings_past_onto_the_other_side() {
        let s = crate::scenario::real_vehicle::real_scenarios()
            .unwrap()
            .swap_remove(0);
        let lp = Loop::with_delta(&s, 2, 3.0).unwrap();
        let e0 = -0.017;
        let (lo0, hi0) = response_range(&lp, 0.0, e0, STEP_PERIODS, |_| 0.0);
        let (lo, hi) = response_range(&lp, 0.26, e0, STEP_PERIODS, |_| 0.0);
        // Without a lag the first command is the peak (u₀ = −G₁e₀ at ė = 0).
        assert!((hi0 + lp.gain[0] * e0).abs() < 1e-9, "{hi0} {:?}", lp.gain);
        assert!((hi - hi0).abs() < 1e-9, "{hi} {hi0}");
        // The swing below is the lag's; (L2)'s |u| peak does not grow (the first command
        // stays the largest |u|), so it kept nothing for it.
        assert!(lo0 - lo > 0.2 * hi0, "{lo0} {lo} {hi0}");
        assert_eq!(hi.max(-lo), hi0.max(-lo0));
    }

    /// [`Reserve::keep`] takes rᵢ⁺ from the upper side and rᵢ⁻ from the lower, each only
    /// there, and never crosses zero.
    #[test]
    fn a_reserve_is_kept_on_its_own_side() {
        let mut env = ThrustEnvelope {
            min: [-90.0; THRUSTERS],
            max: [200.0; THRUSTERS],
        };
        env.min[1] = -10.0;
        let mut r = Reserve::default();
        r.upper[0] = 30.0;
        r.lower[1] = 50.0;
        let k = r.keep(env);
        assert_eq!((k.min[0], k.max[0]), (-90.0, 170.0));
        assert_eq!(k.min[1], 0.0);
        assert!(k.max[1] > 0.0);
        assert_eq!((k.min[2], k.max[2]), (-90.0, 200.0));
    }

    /// The loop's step response without a lag settles at u = −d: its peak is at least 1; a
    /// lag makes it overshoot more, the more the longer the lag.
    #[test]
    fn the_lag_adds_overshoot_monotonically() {
        let s = crate::scenario::real_vehicle::real_scenarios()
            .unwrap()
            .swap_remove(0);
        let lp = Loop::with_delta(&s, 2, 0.0).unwrap();
        let p0 = response_peak(&lp, 0.0, 0.0, STEP_PERIODS, |_| 1.0);
        let p1 = response_peak(&lp, 0.1, 0.0, STEP_PERIODS, |_| 1.0);
        let p3 = response_peak(&lp, 0.3, 0.0, STEP_PERIODS, |_| 1.0);
        assert!(p0 >= 1.0 - 1e-9, "{p0}");
        assert!(p1 > p0 && p3 > p1, "{p0} {p1} {p3}");
    }

    /// A ramp of unexplained acceleration d = r t (a moving mismatch): once the loop has
    /// settled, the command lags it by the same amount with and without the lag but for the
    /// lag's own delay, u = −(d + τ_L ḋ − d̈/K₁) (the loop's transfer K(1 + τ_L s) over
    /// s²(1 + τ_L s) + K, to first order in s): the lag adds τ_L r to the peak (L3), with the
    /// law's δ₀ in the gain as without it.
    #[test]
    fn a_ramp_through_the_lag_adds_its_rate_times_the_lag() {
        let s = crate::scenario::real_vehicle::real_scenarios()
            .unwrap()
            .swap_remove(0);
        for delta in [0.0, 3.0] {
            let lp = Loop::with_delta(&s, 4, delta).unwrap();
            let (lag, r) = (0.2, 0.05);
            let ramp = |k: usize| r * k as f64 * lp.t;
            let added = response_peak(&lp, lag, 0.0, STEP_PERIODS, ramp)
                - response_peak(&lp, 0.0, 0.0, STEP_PERIODS, ramp);
            assert!((added / (lag * r) - 1.0).abs() < 0.03, "{delta}: {added}");
        }
    }

    /// A staircase's later jump is a step of the mismatch as the start is (L3): a payload
    /// that doubles at 10 s needs a larger share than the same first level held.
    #[test]
    fn a_later_payload_jump_adds_to_the_share() {
        use controller_core::model::ParamVariation;
        let base = crate::scenario::real_vehicle::real_scenarios()
            .unwrap()
            .swap_remove(0)
            .with(|c| {
                c.thruster_lag = Some(0.2);
                c.duration = 40.0;
            })
            .unwrap();
        let level = ParamVariation::TABLE3_MAX.scaled(0.3);
        let held = base
            .with(|c| c.variation = VariationProfile::Constant(level))
            .unwrap();
        let jump = base
            .with(|c| {
                c.variation = VariationProfile::Staircase(vec![
                    (10.0, level),
                    (100.0, ParamVariation::TABLE3_MAX),
                ])
            })
            .unwrap();
        let (h, j) = (reserve(&held).unwrap(), reserve(&jump).unwrap());
        let (h, j) = (both(&h), both(&j));
        assert!(h.iter().zip(&j).all(|(h, j)| j >= h), "{h:?} {j:?}");
        assert!(h.iter().zip(&j).any(|(h, j)| j > h), "{h:?} {j:?}");
    }
}
