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

use std::cell::RefCell;
use std::rc::Rc;

use controller_core::allocation::Allocator;
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
/// command's peak on each side).
#[cfg(test)]
pub(super) fn response_range(
    lp: &Loop,
    lag: f64,
    e0: f64,
    periods: usize,
    d: impl Fn(usize) -> f64,
) -> (f64, f64) {
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    let finite = fly(lp, lag, e0, periods, d, |u, _| {
        lo = lo.min(u);
        hi = hi.max(u);
    });
    match finite {
        true => (lo, hi),
        false => (f64::NEG_INFINITY, f64::INFINITY),
    }
}

/// Flies the loop `lp` (L1) from the initial error `e0` under `d(k)` for `periods` periods
/// with the thrusters' lag `lag` (s; 0: none), giving `visit` each period's command uₖ and
/// dₖ; false if the loop diverged.
fn fly(
    lp: &Loop,
    lag: f64,
    e0: f64,
    periods: usize,
    d: impl Fn(usize) -> f64,
    mut visit: impl FnMut(f64, f64),
) -> bool {
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
    for k in 0..periods {
        let u = lp.input(&s, &est);
        let dk = d(k);
        visit(u, dk);
        let a = u + (applied - u) * mean;
        applied = u + (applied - u) * lambda;
        let next = f * s + g * (a + dk);
        est = lp.estimate_step(&est, u, &next);
        s = next;
        if !s.iter().all(|x| x.is_finite()) {
            return false;
        }
    }
    true
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
fn start(scenario: &Scenario, inv_k: f64, periods: usize) -> Result<Start, CheckError> {
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
        payload: payload_profile(scenario, periods, &state, &nu_dot)?,
    })
}

/// Periods the loop is flown (L3): the mission's span at 1/k = `inv_k` (its path's span
/// times k, whatever the scale it is written at; at rest, unbounded), at most the payload's
/// profile (its last step, or one period π/ω of an abs-sin) and [`STEP_PERIODS`] after it to
/// settle.
fn horizon(scenario: &Scenario, inv_k: f64) -> usize {
    let cfg = scenario.config();
    let t = 1.0 / f64::from(scenario.controller().config().rate_hz);
    let profile = match &cfg.variation {
        VariationProfile::Staircase(steps) => steps.iter().map(|s| s.0).fold(0.0, f64::max),
        VariationProfile::AbsSin { omega, .. } if omega.abs() > 0.0 => {
            std::f64::consts::PI / omega.abs()
        }
        _ => 0.0,
    };
    let duration = cfg.duration / super::time_scale(cfg.time_scale) / inv_k;
    let span = (duration / t).ceil().max(1.0);
    let wanted = (profile / t).ceil().min(MAX_PROFILE_PERIODS as f64) + STEP_PERIODS as f64;
    span.min(wanted) as usize
}

/// The payload's share of the mismatch per period k, Δτ_p(kT) − Δτ_p(0), at the start's
/// state (L3): a staircase's levels as they are, an abs-sin's as |sin ωt| of its maximum's
/// (the mismatch is affine in Δp at a state).
fn payload_profile(
    scenario: &Scenario,
    n: usize,
    state: &PlantState,
    nu_dot: &Vector6<f64>,
) -> Result<Vec<Vector6<f64>>, CheckError> {
    let cfg = scenario.config();
    let force = |t: f64| -> Result<Vector6<f64>, CheckError> {
        let plant = Plant::new(cfg.plant_params_at(t), PlantTerms::default())
            .map_err(|e| CheckError::Invalid(format!("the payload at t = {t} s: {e}")))?;
        Ok(plant.required_force(state, nu_dot, &Vector3::zeros()))
    };
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

/// The width (N) a side with no room left keeps, for the allocator.
const SLIVER: f32 = 1e-3;

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
    /// [`super::navigation::keep`] keeps one share on both. A share larger than its side
    /// crosses zero (Choice 548): the transient is measured from the demand, so a demand must
    /// then stand on the other side by the excess; a side with no room left is a sliver.
    pub fn keep(&self, envelope: ThrustEnvelope) -> ThrustEnvelope {
        let mut e = envelope;
        for i in 0..THRUSTERS {
            let (up, down) = (self.upper[i], self.lower[i]);
            if up == 0.0 && down == 0.0 {
                continue;
            }
            e.min[i] += down as f32;
            e.max[i] -= up as f32;
            if e.max[i] <= e.min[i] {
                e.max[i] = e.min[i] + SLIVER.max(e.min[i].abs() * 1e-6);
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

/// The part of the room between the envelope and the margin envelope the margin covers of the
/// loop's own transient without a lag, (L2'') (**Choice 548**).
pub const COVERED: f64 = 1.0;

/// The share of the periods the bound lets saturate a start's transient may take, (L2'')
/// (**Choice 548**): the rest is left to the flight's other saturations.
pub const SATURATED_SHARE: f64 = 0.2;

/// Per period k, per thruster, the loop's excursion (N, ≥ 0) below ([k][i][.][0]) and above
/// ([k][i][.][1]) the span between its feedforward and its steady demand, with the thrusters'
/// lag ([k][i][0]) and without ([k][i][1]), the largest over the currents, (L2'').
#[derive(Clone, Debug, Default, PartialEq)]
struct Excursions(Vec<[[[f64; 2]; 2]; THRUSTERS]>);

impl Excursions {
    /// The larger of each, period by period.
    fn max(mut self, other: &Excursions) -> Excursions {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            for (x, y) in a
                .iter_mut()
                .flatten()
                .flatten()
                .zip(b.iter().flatten().flatten())
            {
                *x = x.max(*y);
            }
        }
        self
    }

    /// Per thruster, lag and side, the level the excursion passes in more than `allowed`
    /// periods (its `allowed`-th largest from 0; 0 when it passes 0 in no more).
    fn level(&self, allowed: usize) -> [[[f64; 2]; 2]; THRUSTERS] {
        let mut out = [[[0.0f64; 2]; 2]; THRUSTERS];
        let mut v = Vec::with_capacity(self.0.len());
        for (i, o) in out.iter_mut().enumerate() {
            for (which, o) in o.iter_mut().enumerate() {
                for (side, o) in o.iter_mut().enumerate() {
                    v.clear();
                    v.extend(self.0.iter().map(|p| p[i][which][side]));
                    if allowed < v.len() {
                        let (_, x, _) = v.select_nth_unstable_by(allowed, |a, b| b.total_cmp(a));
                        *o = *x;
                    }
                }
            }
        }
        out
    }
}

/// The loop's excursions on every thruster from the start at 1/k = `inv_k` (at rest: 0),
/// flown `periods` periods under each current the check takes (L2''): every controlled
/// axis's loop at the law's δ there, its start offset at its sign as written and its mismatch
/// at its own, the axes' commands summed on each thruster period by period through the
/// allocation's signed column at the start's heading.
fn excursions(
    scenario: &Scenario,
    lag: f64,
    mass: &nalgebra::Matrix6<f64>,
    inv_k: f64,
    periods: usize,
) -> Result<Excursions, CheckError> {
    let cfg = scenario.config();
    let st = start(scenario, inv_k, periods)?;
    let n = st.payload.len();
    let alloc = scenario.controller().allocation();
    let mut loops = Vec::with_capacity(ACTUATED.len());
    for &j in &ACTUATED {
        let dir = body_direction(j, st.yaw);
        let column = alloc.thrusts(&dir).map(|b| f64::from(b) * mass[(j, j)]);
        let lp = Loop::with_delta(scenario, j, st.delta)?;
        loops.push((j, lp, dir.cast::<f64>(), column));
    }
    let lags: &[f64] = if lag > 0.0 { &[lag, 0.0] } else { &[0.0] };
    let mut out = Excursions(vec![[[[0.0f64; 2]; 2]; THRUSTERS]; n]);
    for mismatch in &st.mismatch {
        for (which, &l) in lags.iter().enumerate() {
            // Per period and thruster, the loop's thrust and its steady demand (N).
            let mut thrust = vec![[0.0f64; THRUSTERS]; n];
            let mut steady = vec![[0.0f64; THRUSTERS]; n];
            for (j, lp, dir, column) in &loops {
                let m = mass[(*j, *j)];
                // The plant needs Δτ more than the law's model gives: ë = u − Δτⱼ/M̂ⱼⱼ (L3).
                let c = dir.dot(mismatch);
                let d = |k: usize| -(c + dir.dot(&st.payload[k])) / m;
                let mut k = 0;
                let finite = fly(lp, l, cfg.initial_offset[*j], n, d, |u, dk| {
                    for i in 0..THRUSTERS {
                        thrust[k][i] += column[i] * u;
                        steady[k][i] -= column[i] * dk;
                    }
                    k += 1;
                });
                if !finite {
                    return Err(CheckError::Invalid(format!(
                        "the loop with a thruster lag of {l} s is unstable"
                    )));
                }
            }
            for ((v, s), o) in thrust.iter().zip(&steady).zip(out.0.iter_mut()) {
                for i in 0..THRUSTERS {
                    let x = &mut o[i][which];
                    x[0] = x[0].max(s[i].min(0.0) - v[i]);
                    x[1] = x[1].max(v[i] - s[i].max(0.0));
                }
            }
        }
    }
    if lag <= 0.0 {
        for x in out.0.iter_mut().flatten() {
            x[1] = x[0];
        }
    }
    Ok(out)
}

/// The loop's transient on each thruster's sides at every time scale, (L2''): what the
/// margin does not cover of it, kept on the side it takes.
struct Shares<'a> {
    scenario: &'a Scenario,
    lag: f64,
    mass: nalgebra::Matrix6<f64>,
    /// Per thruster, what the margin covers below ([0]) and above ([1]) (N): [`COVERED`] of
    /// the room between the envelope and the margin envelope.
    covered: [[f64; 2]; THRUSTERS],
    /// The excursions from the start at rest (which every time scale keeps too) by the
    /// periods flown.
    rest: RefCell<Vec<(usize, Excursions)>>,
}

impl<'a> Shares<'a> {
    /// `None` on ideal actuators (they never saturate), and without a lag and a start
    /// offset: the loop's transient is then the mismatch's own step, which the margin is
    /// measured to cover (the contract's missions fly within it).
    fn new(scenario: &'a Scenario, margin: f64) -> Result<Option<Self>, CheckError> {
        let cfg = scenario.config();
        let lag = cfg.thruster_lag.filter(|l| *l > 0.0).unwrap_or(0.0);
        let offset = ACTUATED.iter().any(|&j| cfg.initial_offset[j] != 0.0);
        if cfg.ideal_actuators || (lag == 0.0 && !offset) {
            return Ok(None);
        }
        let controller = scenario.controller();
        let mass = Plant::new(controller.params().cast(f64::from), PlantTerms::default())
            .map_err(|e| CheckError::Invalid(format!("the law's nominal model: {e}")))?
            .mass_matrix();
        let env = controller.envelope();
        let room = COVERED * (1.0 - margin);
        let covered =
            std::array::from_fn(|i| [-room * f64::from(env.min[i]), room * f64::from(env.max[i])]);
        Ok(Some(Shares {
            scenario,
            lag,
            mass,
            covered,
            rest: RefCell::new(Vec::new()),
        }))
    }

    /// Per thruster, the loop's transient the margin does not cover at 1/k = `inv_k` (L2'').
    fn reserve(&self, inv_k: f64) -> Result<Reserve, CheckError> {
        // The mission's span at this scale, flown from the start at its speed and at rest;
        // at rest the mission is unbounded and a start's transient takes none of it.
        if inv_k <= 0.0 {
            return Ok(Reserve::default());
        }
        let n = horizon(self.scenario, inv_k);
        let cached = self
            .rest
            .borrow()
            .iter()
            .find(|r| r.0 == n)
            .map(|r| r.1.clone());
        let rest = match cached {
            Some(r) => r,
            None => {
                let r = excursions(self.scenario, self.lag, &self.mass, 0.0, n)?;
                self.rest.borrow_mut().push((n, r.clone()));
                r
            }
        };
        let exc = excursions(self.scenario, self.lag, &self.mass, inv_k, n)?.max(&rest);
        // The periods the bound lets saturate, at most [`SATURATED_SHARE`] of them.
        let cfg = self.scenario.config();
        let t_period = 1.0 / f64::from(self.scenario.controller().config().rate_hz);
        let periods = cfg.duration / super::time_scale(cfg.time_scale) / inv_k / t_period;
        let fraction = cfg.bound().map_or(0.0, |b| b.saturated);
        let allowed = (SATURATED_SHARE * fraction * periods).floor() as usize;
        let t = exc.level(allowed);
        let mut out = Reserve::default();
        for (i, [lagged, plain]) in t.iter().enumerate() {
            let kept =
                |side: usize| (lagged[side] - plain[side].min(self.covered[i][side])).max(0.0);
            (out.lower[i], out.upper[i]) = (kept(0), kept(1));
        }
        if out.upper.iter().chain(&out.lower).any(|x| !x.is_finite()) {
            return Err(CheckError::Invalid(format!(
                "the loop with a thruster lag of {} s is unstable",
                self.lag
            )));
        }
        Ok(out)
    }
}

/// The margin envelope at one time scale with the loop's transient kept (L2''), and its
/// allocator.
pub struct Margin {
    pub envelope: ThrustEnvelope,
    pub allocator: Allocator,
}

/// The margin envelope at each time scale the check asks for (**Choice 558**): the loop's
/// transient at that scale kept on the envelope `base`, so that the verdict at a scale does
/// not depend on the scale the file is written at; each scale's built once.
pub struct Margins<'a> {
    scenario: &'a Scenario,
    margin: f64,
    shares: Option<Shares<'a>>,
    base: Rc<Margin>,
    cache: RefCell<Vec<(u64, Rc<Margin>)>>,
}

impl<'a> Margins<'a> {
    /// The margin envelope `base` (the navigation's share kept) of `scenario` at the fraction
    /// `margin` of the envelope.
    pub fn new(
        scenario: &'a Scenario,
        margin: f64,
        base: ThrustEnvelope,
    ) -> Result<Self, CheckError> {
        let shares = Shares::new(scenario, margin)?;
        let base = Rc::new(margin_at(scenario, margin, base)?);
        Ok(Margins {
            scenario,
            margin,
            shares,
            base,
            cache: RefCell::new(Vec::new()),
        })
    }

    /// The margin envelope and its allocator at 1/k = `inv_k` (at rest: 0).
    pub fn at(&self, inv_k: f64) -> Result<Rc<Margin>, CheckError> {
        let Some(shares) = &self.shares else {
            return Ok(self.base.clone());
        };
        let key = inv_k.to_bits();
        if let Some((_, m)) = self.cache.borrow().iter().find(|(k, _)| *k == key) {
            return Ok(m.clone());
        }
        let reserve = shares.reserve(inv_k)?;
        let m = match reserve == Reserve::default() {
            true => self.base.clone(),
            false => Rc::new(margin_at(
                self.scenario,
                self.margin,
                reserve.keep(self.base.envelope),
            )?),
        };
        self.cache.borrow_mut().push((key, m.clone()));
        Ok(m)
    }

    /// What the margin envelope at each scale reads besides the base envelope, by its bits:
    /// the scenario as a whole but its name and time scale (the check's [`Kept`] context).
    ///
    /// [`Kept`]: super::sweep
    pub fn context(&self) -> Vec<u64> {
        let env = &self.base.envelope;
        let mut out: Vec<u64> = env
            .min
            .iter()
            .chain(&env.max)
            .map(|x| u64::from(x.to_bits()))
            .collect();
        if self.shares.is_some() {
            use std::hash::{Hash, Hasher};
            let mut cfg = self.scenario.config().clone();
            cfg.name.clear();
            cfg.time_scale = 1.0;
            cfg.speed_limits = None;
            let mut h = std::collections::hash_map::DefaultHasher::new();
            format!("{cfg:?}").hash(&mut h);
            out.extend([self.margin.to_bits(), h.finish()]);
        }
        out
    }
}

/// The envelope `env` with its allocator.
fn margin_at(scenario: &Scenario, margin: f64, env: ThrustEnvelope) -> Result<Margin, CheckError> {
    let controller = scenario.controller();
    let allocator = Allocator::new(controller.allocation(), &env, &controller.config().priority)
        .map_err(|e| {
            CheckError::Invalid(format!(
                "the allocator on the {margin} margin envelope: {e}"
            ))
        })?;
    Ok(Margin {
        envelope: env,
        allocator,
    })
}

/// Per thruster, the loop's transient the margin does not cover on each side at 1/k = `inv_k`
/// and at rest, (L2''); zeros on ideal actuators.
pub fn reserve(scenario: &Scenario, margin: f64, inv_k: f64) -> Result<Reserve, CheckError> {
    match Shares::new(scenario, margin)? {
        Some(s) => s.reserve(inv_k),
        None => Ok(Reserve::default()),
    }
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
    /// there, and crosses zero by what a share exceeds its side.
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
        assert_eq!((k.min[1], k.max[1]), (40.0, 200.0));
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
        let (h, j) = (
            reserve(&held, 0.8, 1.0).unwrap(),
            reserve(&jump, 0.8, 1.0).unwrap(),
        );
        let (h, j) = (both(&h), both(&j));
        assert!(h.iter().zip(&j).all(|(h, j)| j >= h), "{h:?} {j:?}");
        assert!(h.iter().zip(&j).any(|(h, j)| j > h), "{h:?} {j:?}");
    }
}
