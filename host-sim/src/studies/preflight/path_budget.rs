//! The path-error budget (docs/real-vehicle.md#the-path-error-budget, **Choices 420–424**): the
//! path error a mission will show on its navigation, predicted before it flies, against the
//! bound. The force check ([`super::navigation`], Choice 372) sees the thrust noise costs; it
//! cannot see a vehicle that follows its navigation's error within every envelope.
//!
//! Per translational axis i of η (x, y, z) the loop is linearised as the law flies it, one
//! period T at a time (the same loop as [`super::navigation`]'s): the vehicle's error
//! s = [e, ė] moves as s⁺ = F s + g(u + d) (F = [[1, T], [0, 1]], g = [T²/2, T]), d the
//! acceleration the law's nominal model does not explain; the law's input is u = −G ŝ with
//! G = [K₁ + (δ_max/μ)p₁₂, K₂ + (δ_max/μ)p₂₂] (Eq 17, and Δu of Eq 30 inside its boundary
//! layer), ŝ the solution as told (s + n) or the estimator's posterior. The estimator is the
//! board's own (the steady-state gain of `controller_core::estimator`, its rows K of η, η̇ and
//! kd of the disturbance estimate d̂, **Choice 512**): its prior is x̂⁻ = (F − gG)x̂ + g d̂ (its
//! prediction uses u and d̂, so d − d̂ is what it does not know), its innovation
//! ν = s⁺ + n⁺ − x̂⁻, and x̂⁺ = x̂⁻ + Kν, d̂⁺ = d̂ + kd·ν: d̂ integrates the innovations, so a
//! steady d leaves the estimate without a lag, and the noise reaches u through d̂ too. With
//! the two-state filter kd = 0 and d̂ stays 0. The law itself does not use d̂.
//!
//! **Navigation error n** (Choice 421): not white. Its position part is the last fix's error
//! (σ_f, a new draw at each fix, held in between) plus its bias, plus the dead reckoning's
//! drift since the fix: n_p⁺ = n_p + T n_v; its velocity part is the last DVL ping's error
//! (σ_v, held until the next ping) plus the DVL's bias and the heading bias's share of the
//! speed (V σ_ψ), plus the INS's acceleration bias integrated since the ping:
//! n_v⁺ = n_v + T b_a. For z the fixes are the pressure depths. Fixes and pings come at their
//! sources' rates, none in their outages; with no fixes the position drifts for the whole
//! mission. The scenario's `[noise]` adds white noise per period. The covariance of the whole
//! state [s, x̂, n, d̂] is propagated period by period over the flight (P⁺ = A P Aᵀ + Q, a fix or
//! ping replacing its state's row by a fresh draw), and σᵢ = maxₜ √P_ee(t).
//!
//! **Confidence** (Choice 422): a mission's largest error per axis is over N = D·f_fix
//! independent fixes (D the flight's duration, at least 1); with the mission's miss
//! probability p = [`MISS_PROBABILITY`] for the draws and p for the biases, each shared by the
//! 3 axes (and, for the draws, N fixes: a union bound), the axis's noise term is
//! q·σᵢ + q_b·σ_bᵢ with 2φ(q)/q = p/(3N) and 2φ(q_b)/q_b = p/3 (Mills' bound on the Gaussian
//! tail, so q is never too small). Together the two miss with at most 2p: the budget reports 2p.
//!
//! **Lag** (Choice 423): d is deterministic for a given mission: the plant as written (its
//! payload, the current's mean and a Gauss–Markov current's ±3σ corners) against the law's
//! nominal model along the reference, d = J M⁻¹(τ̂ − τ) (τ̂ the nominal model's force for the
//! reference, τ the plant's), plus the thrusters' lag τ_L times the reference's jerk. Its
//! error is bounded by the ℓ₁ norm of the loop's impulse response from d to e:
//! |e| ≤ ‖h‖₁ · max|d| for every d of that amplitude (the bound is reached only by a d that
//! flips sign with h; on a constant d it is the DC gain, for the loop without the estimator
//! 1/G₁). The budget takes the peak of the loop's response to d flown along the reference,
//! which this bound caps. With no estimator a solution τ_lat late adds V·τ_lat.
//!
//! **The loop the lag is flown on** (Choice 567): the loop as the law flies it, not the
//! stiffest one. Its boundary layer's gain is δ/μ with δ the law's Eq 29, which along a
//! survey mission is 3–4, not δ_max = 25 (a 7× stiffer loop answered the current with 28.7 mm
//! where the flight showed 33 mm without a lag); δ is taken on a grid from Eq 29's least along
//! the reference (‖e‖ = 0) to its largest with ‖e‖ at the bound, the worst response kept. The
//! thrusters' lag τ_L is in the loop: the acceleration applied over a period is the lag's mean
//! over the held command ((L1) of [`super::lag`]; the lag delayed the answer to the current:
//! 44 mm flown against 33 mm without it). The loop starts at the scenario's start offset
//! s₀ = [e₀ᵢ, 0], the estimate on it (the board's first solution becomes its estimate), each
//! sign of e₀ᵢ against d's taken: a run's error starts at the offset. The ℓ₁ gain (`lag_gain`)
//! stays the δ_max loop's without the lag: it is reported, not used.
//!
//! **Budget** (Choice 424): per axis eᵢ = q·σᵢ + ‖hᵢ‖₁ max|dᵢ| (+ V τ_lat), and the path
//! error √(Σ eᵢ²), as the run's max path combines its axes' maxima. At time scale k the
//! reference's speed falls as 1/k, its acceleration as 1/k², its jerk as 1/k³: the budget's
//! mismatch and lag fall with them; its navigation part does not (only the heading's share
//! and a drift over the longer flight change). The budget at k = [`MAX_TIME_SCALE`] is the
//! mission's speed-independent error: beyond the bound, no time scale helps.

use controller_core::estimator::{AxisGain, EstimatorConfig, EstimatorGains, EstimatorKind};
use controller_core::kinematics::{self, Attitude};
use controller_core::law::{uncertainty_bound, DeltaInputs};
use controller_core::model::VehicleParams;
use controller_core::{Mission, Trajectory};
use nalgebra::{Matrix2, RowVector2, SMatrix, Vector2, Vector3, Vector6};
use serde::{Deserialize, Serialize};

use super::{period, CheckError, SAMPLE_PERIOD};
use crate::plant::{CurrentModel, Plant, PlantState, PlantTerms};
use crate::scenario::navigation::{ErrorModel, Timing};
use crate::scenario::Scenario;

/// Each of the budget's two parts (the draws, the biases) may exceed its share with this
/// probability; a mission the budget passes may exceed it with at most twice it (Choice 422).
pub const MISS_PROBABILITY: f64 = 0.01;
/// The slowest time scale the budget tries (the trajectory's own limit).
pub const MAX_TIME_SCALE: f64 = controller_core::Trajectory::MAX_TIME_SCALE as f64;
/// The longest flight whose covariance is propagated (s): beyond, the budget of a mission
/// with fixes is periodic, and one without fixes has long left any bound.
const MAX_PROPAGATION: f64 = 4.0 * 3600.0;
/// How long a flight with fixes is propagated (s): its covariance repeats with its fixes
/// long before (the loop settles in seconds; the biases are constant).
const SETTLED: f64 = 120.0;
/// Periods of the impulse response summed for ‖h‖₁, at most (a stable loop's has died long
/// before: 600 s at 100 Hz).
const MAX_IMPULSE_PERIODS: usize = 60_000;
/// The ratio between the boundary layer's δ the lag is flown at (Choice 567).
const LAG_DELTA_STEP: f64 = 2.0;
/// How much the lag loop's ‖h‖₁ is widened before it decides that a flight cannot raise the
/// worst (Choice 559): covers the sum's truncated tail and the flights' rounding.
const LAG_SKIP_MARGIN: f64 = 1e-3;
/// Standard deviations of a Gauss–Markov current's corners (as the force check's).
const CURRENT_SIGMAS: f64 = super::GAUSS_MARKOV_SIGMAS;

/// The three translational axes.
pub(super) const AXES: usize = 3;
const AXIS_NAMES: [&str; AXES] = ["x", "y", "z"];

/// The budget of one mission at one time scale (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathBudget {
    /// The bound on the max path error (m).
    pub bound: f64,
    /// The time scale the figures below are at.
    pub time_scale: f64,
    /// The mission's miss probability the budget allows, and the q it gives per axis.
    pub miss_probability: f64,
    pub quantile: [f64; AXES],
    /// σ of the vehicle's true error on x y z under the navigation's draws (fixes, pings,
    /// white noise) and under its biases (m).
    pub noise_sigma: [f64; AXES],
    pub bias_sigma: [f64; AXES],
    /// The loop's ℓ₁ gain from unexplained acceleration d to the error (m per m/s²), and
    /// max|d| at this scale (m/s²).
    pub lag_gain: [f64; AXES],
    pub mismatch: [f64; AXES],
    /// Per axis: q·σ, ‖h‖₁·max|d| (+ V·τ_lat), and their sum (m).
    pub noise: [f64; AXES],
    pub lag: [f64; AXES],
    pub axis: [f64; AXES],
    /// √(Σ axis²) (m): the predicted max path error.
    pub total: f64,
    /// The same at the slowest scale: the part no time scale removes (m).
    pub speed_independent: f64,
    /// The smallest time scale at which `total` fits the bound (`None`: none up to
    /// [`MAX_TIME_SCALE`]).
    pub smallest_time_scale: Option<f64>,
    /// When no scale fits: what navigation the mission needs.
    pub needs: Option<String>,
}

impl PathBudget {
    /// Fits the bound at its time scale.
    pub fn fits(&self) -> bool {
        self.total <= self.bound
    }

    /// One line for `check`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "path-error budget at time scale {}: {:.1} mm of the {:.0} mm bound ({:.0} % miss \
             probability; navigation {:.1}/{:.1}/{:.1} mm, lag {:.1}/{:.1}/{:.1} mm on x/y/z); \
             speed-independent {:.1} mm",
            self.time_scale,
            1e3 * self.total,
            1e3 * self.bound,
            100.0 * self.miss_probability,
            1e3 * self.noise[0],
            1e3 * self.noise[1],
            1e3 * self.noise[2],
            1e3 * self.lag[0],
            1e3 * self.lag[1],
            1e3 * self.lag[2],
            1e3 * self.speed_independent,
        );
        match (self.smallest_time_scale, &self.needs) {
            (_, Some(n)) => s.push_str(&format!("; no time scale fits: {n}")),
            (Some(k), None) => s.push_str(&format!("; fits from time scale {k}")),
            (None, None) => {}
        }
        s
    }
}

/// One axis's navigation error sources (module docs), in the η axis's units.
#[derive(Clone, Debug, Default)]
pub(super) struct AxisNoise {
    /// The position source resetting the drift (fix or pressure depth): σ, bias σ, its
    /// timing.
    pub(super) fix: Option<(f64, f64, Timing)>,
    /// DVL ping: σ, bias σ (with the heading's share), timing; `None`: no velocity aiding.
    pub(super) ping: Option<(f64, f64, Timing)>,
    /// INS acceleration bias σ (m/s²).
    pub(super) accel_bias: f64,
    /// White noise per period from `[noise]` (position, velocity).
    pub(super) white: [f64; 2],
}

fn steady<const N: usize>(e: &ErrorModel<N>, i: usize) -> f64 {
    e.bias[i].hypot(e.bias_sigma[i])
}

/// The error sources of axis `i` of `scenario` at reference speed `speed` (m/s).
pub(super) fn axis_noise(scenario: &Scenario, i: usize, speed: f64) -> AxisNoise {
    let cfg = scenario.config();
    let mut a = AxisNoise::default();
    if let Some(m) = &cfg.navigation {
        let horizontal = i < 2;
        a.fix = if horizontal {
            m.fix
                .as_ref()
                .map(|f| (f.error.sigma[i], steady(&f.error, i), f.timing.clone()))
        } else {
            Some((
                m.depth.error.sigma[0],
                steady(&m.depth.error, 0),
                m.depth.timing.clone(),
            ))
        };
        // The DVL measures in the body frame: either horizontal η axis may carry surge's or
        // sway's error; the heading's bias turns the speed into a velocity error.
        let v = &m.dvl.velocity;
        let (sigma, bias) = if horizontal {
            (
                v.sigma[0].max(v.sigma[1]),
                steady(v, 0)
                    .max(steady(v, 1))
                    .hypot(speed * steady(&m.ins.attitude, 2)),
            )
        } else {
            (
                v.sigma[2],
                steady(v, 2).hypot(speed * steady(&m.ins.attitude, 1)),
            )
        };
        a.ping = Some((sigma, bias, m.dvl.timing.clone()));
        let ab = &m.ins.accel;
        a.accel_bias = if horizontal {
            steady(ab, 0).max(steady(ab, 1))
        } else {
            steady(ab, 2)
        };
    }
    if let Some(n) = &cfg.noise {
        a.white = [n.eta_sigma[i], n.nu_sigma[i]];
    }
    a
}

/// Whether a source of `timing` samples at control period `k` (T each), outside its outages.
fn samples_at(timing: &Timing, k: u64, t_period: f64) -> bool {
    let every = (1.0 / (timing.rate_hz * t_period)).round().max(1.0) as u64;
    let t = k as f64 * t_period;
    k.is_multiple_of(every) && !timing.outages.iter().any(|o| t >= o[0] && t < o[1])
}

/// The law's linear loop on one axis: T, G, and the estimator's K (`None`: off) with its row
/// kd of the disturbance estimate (zero without the disturbance state or the estimator).
#[derive(Clone, Copy, Debug)]
pub(super) struct Loop {
    pub(super) t: f64,
    pub(super) gain: [f64; 2],
    pub(super) k: Option<Matrix2<f64>>,
    pub(super) kd: RowVector2<f64>,
}

/// The estimator's state in the loop's linear model: x̂ = [ê, ê̇] and d̂ (module docs).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct LoopEstimate {
    pub(super) x: Vector2<f64>,
    pub(super) d: f64,
}

impl Loop {
    pub(super) fn of(scenario: &Scenario, axis: usize) -> Result<Self, CheckError> {
        let c = scenario.controller().config();
        Self::with_robust_gain(scenario, axis, f64::from(c.delta_max / c.mu))
    }

    /// The loop with the boundary layer's gain at δ = `delta` (δ/μ; [`Loop::of`]: δ_max).
    pub(super) fn with_delta(
        scenario: &Scenario,
        axis: usize,
        delta: f64,
    ) -> Result<Self, CheckError> {
        let c = scenario.controller().config();
        Self::with_robust_gain(scenario, axis, delta / f64::from(c.mu))
    }

    /// The loop with the boundary layer's gain δ/μ = `gain` (0 when the law is not robust).
    fn with_robust_gain(scenario: &Scenario, axis: usize, gain: f64) -> Result<Self, CheckError> {
        let controller = scenario.controller();
        let c = controller.config();
        let lyap = controller.lyapunov();
        let robust = if c.robust { gain } else { 0.0 };
        let t = 1.0 / f64::from(c.rate_hz);
        let gain = [
            f64::from(c.k1[axis]) + robust * f64::from(lyap[axis].p12),
            f64::from(c.k2[axis]) + robust * f64::from(lyap[axis].p22),
        ];
        let e = &scenario.config().controller.estimator;
        let (k, kd) = match e.kind {
            EstimatorKind::Off => (None, RowVector2::zeros()),
            EstimatorKind::Kalman => {
                let b = board_gain(e, c.rate_hz, axis).ok_or_else(|| {
                    CheckError::Invalid(format!("the estimator has no steady state on axis {axis}"))
                })?;
                (
                    Some(b.k.cast::<f64>()),
                    RowVector2::new(f64::from(b.kd[0]), f64::from(b.kd[1])),
                )
            }
        };
        Ok(Loop { t, gain, k, kd })
    }

    /// This loop with the boundary layer's gain at δ = `delta` (its estimator's rows kept:
    /// they do not depend on δ), as [`Loop::with_delta`] builds it.
    pub(super) fn regained(&self, scenario: &Scenario, axis: usize, delta: f64) -> Self {
        let controller = scenario.controller();
        let c = controller.config();
        let lyap = controller.lyapunov();
        let robust = if c.robust {
            delta / f64::from(c.mu)
        } else {
            0.0
        };
        Loop {
            gain: [
                f64::from(c.k1[axis]) + robust * f64::from(lyap[axis].p12),
                f64::from(c.k2[axis]) + robust * f64::from(lyap[axis].p22),
            ],
            ..*self
        }
    }

    /// The law's input u = −G ŝ on the estimate (the estimator on) or on `s` (off).
    pub(super) fn input(&self, s: &Vector2<f64>, est: &LoopEstimate) -> f64 {
        let gr = RowVector2::new(self.gain[0], self.gain[1]);
        let on = if self.k.is_some() { est.x } else { *s };
        -(gr * on)[0]
    }

    /// One period of the board's estimator (module docs): from `est` with the input `u`
    /// applied, corrected on the measured `z` (the error s⁺, plus the navigation's error).
    pub(super) fn estimate_step(
        &self,
        est: &LoopEstimate,
        u: f64,
        z: &Vector2<f64>,
    ) -> LoopEstimate {
        let Some(k) = self.k else {
            return *est;
        };
        let prior = self.f() * est.x + self.g() * (u + est.d);
        let innovation = z - prior;
        LoopEstimate {
            x: prior + k * innovation,
            d: est.d + (self.kd * innovation)[0],
        }
    }

    pub(super) fn f(&self) -> Matrix2<f64> {
        Matrix2::new(1.0, self.t, 0.0, 1.0)
    }

    pub(super) fn g(&self) -> Vector2<f64> {
        Vector2::new(0.5 * self.t * self.t, self.t)
    }

    /// ‖h‖₁ of the impulse response from d (one period of unit unexplained acceleration) to
    /// the position error e; `None` when the loop is unstable.
    fn lag_gain(&self) -> Option<f64> {
        let (f, g) = (self.f(), self.g());
        let mut s = g;
        // The period of the impulse: the estimate, from zero, corrected on it.
        let mut est = self.estimate_step(&LoopEstimate::default(), 0.0, &s);
        let mut sum = 0.0;
        for n in 0..MAX_IMPULSE_PERIODS {
            sum += s[0].abs();
            let u = self.input(&s, &est);
            let s_next = f * s + g * u;
            est = self.estimate_step(&est, u, &s_next);
            s = s_next;
            if !s.iter().all(|x| x.is_finite()) {
                return None;
            }
            let small = 1e-15 * sum.max(1e-300);
            if n > 100 && s.amax() < small && est.x.amax() < small && est.d.abs() < small {
                return Some(sum);
            }
        }
        (s.amax() < 1e-6 * sum).then_some(sum)
    }
}

/// The plant as written at the latest payload, rebuilt only when the payload changes (a
/// sweep along the reference meets the same parameters for many samples in a row).
#[derive(Default)]
pub(super) struct PlantCache(Option<(VehicleParams<f64>, Plant)>);

impl PlantCache {
    /// The plant of `params`.
    pub(super) fn at(&mut self, params: VehicleParams<f64>) -> Result<&Plant, CheckError> {
        let built = match self.0.take() {
            Some((had, plant)) if had == params => (had, plant),
            _ => (
                params,
                Plant::new(params, PlantTerms::default())
                    .map_err(|e| CheckError::Invalid(format!("the plant: {e}")))?,
            ),
        };
        Ok(&self.0.insert(built).1)
    }
}

/// Axis `axis`'s steady-state gain of the board's own estimator (`EstimatorGains`, the one
/// `controller_core` flies: with the disturbance state of Choice 510 when `disturbance_time` is
/// above 0). The loops here take all its rows: η and η̇ (Choice 505) and the disturbance
/// estimate's `kd`, which integrates the innovations (Choice 512).
pub(super) fn board_gain(e: &EstimatorConfig, rate_hz: u32, axis: usize) -> Option<AxisGain> {
    EstimatorGains::new(e, rate_hz)
        .ok()
        .and_then(|g| g.axes.get(axis).copied())
}

/// The state of the noise propagation: [s₀, s₁, x̂₀, x̂₁, f, h, b_v, b_a, b_p, d̂] (module
/// docs: f the held fix error and its drift, h the held ping error and its drift, d̂ the
/// estimator's disturbance estimate).
pub(super) const N: usize = 10;
/// d̂'s index in the noise propagation's state.
pub(super) const D_HAT: usize = 9;
pub(super) type Cov = SMatrix<f64, N, N>;

/// One period's maps of the noise propagation (module docs): the loop's step, the noise's
/// drift, the estimator's correction, and the white noise's covariance.
pub(super) struct PeriodMaps {
    pub(super) loop_step: Cov,
    pub(super) drift: Cov,
    pub(super) correct: Option<Cov>,
    pub(super) q_white: Cov,
}

/// The maps of one period of the loop `lp` under `noise`.
pub(super) fn period_maps(lp: &Loop, noise: &AxisNoise) -> PeriodMaps {
    let (t, f, g) = (lp.t, lp.f(), lp.g());
    let gr = nalgebra::RowVector2::new(lp.gain[0], lp.gain[1]);
    // The loop's step after the noise (module docs), as a map on the state.
    let mut loop_step = Cov::identity();
    // s⁺ = F s − g G ŝ.
    loop_step.fixed_view_mut::<2, 2>(0, 0).copy_from(&f);
    let ggr = g * gr;
    match lp.k {
        Some(_) => {
            // x̂ is the estimate; s⁺ = F s − gG x̂, and x̂⁺ = (I−K)(F−gG)x̂ + K(s⁺ + m⁺).
            loop_step.fixed_view_mut::<2, 2>(0, 2).copy_from(&(-ggr));
        }
        None => {
            // ŝ = s + m: s⁺ = (F − gG)s − gG m.
            loop_step.fixed_view_mut::<2, 2>(0, 0).copy_from(&(f - ggr));
            let mut m = SMatrix::<f64, 2, N>::zeros();
            m[(0, 4)] = 1.0;
            m[(0, 8)] = 1.0;
            m[(1, 5)] = 1.0;
            m[(1, 6)] = 1.0;
            let cols = -ggr * m;
            for c in 4..N {
                for r in 0..2 {
                    loop_step[(r, c)] = cols[(r, c)];
                }
            }
        }
    }
    // The drift of the noise: f⁺ = f + T(h + b_v), h⁺ = h + T b_a.
    let mut drift = Cov::identity();
    drift[(4, 5)] = t;
    drift[(4, 6)] = t;
    drift[(5, 7)] = t;
    // The estimator's correction with the new noise (module docs): the prior
    // x̂⁻ = (F−gG)x̂ + g d̂, the innovation ν = s + m − x̂⁻, x̂⁺ = x̂⁻ + Kν, d̂⁺ = d̂ + kd·ν.
    let correct = lp.k.map(|k| {
        // ν as a map on the state: s + m − (F−gG)x̂ − g d̂, with m = [f + b_p, h + b_v].
        let mut nu = SMatrix::<f64, 2, N>::zeros();
        nu.fixed_view_mut::<2, 2>(0, 0)
            .copy_from(&Matrix2::identity());
        nu.fixed_view_mut::<2, 2>(0, 2).copy_from(&(-(f - ggr)));
        nu[(0, 4)] = 1.0;
        nu[(0, 8)] = 1.0;
        nu[(1, 5)] = 1.0;
        nu[(1, 6)] = 1.0;
        nu.fixed_view_mut::<2, 1>(0, D_HAT).copy_from(&(-g));
        let mut prior = SMatrix::<f64, 2, N>::zeros();
        prior.fixed_view_mut::<2, 2>(0, 2).copy_from(&(f - ggr));
        prior.fixed_view_mut::<2, 1>(0, D_HAT).copy_from(&g);
        let mut c = Cov::identity();
        c.fixed_view_mut::<2, N>(2, 0).copy_from(&(prior + k * nu));
        let d_row = lp.kd * nu;
        for j in 0..N {
            c[(D_HAT, j)] += d_row[j];
        }
        c
    });
    let white = Matrix2::new(noise.white[0].powi(2), 0.0, 0.0, noise.white[1].powi(2));
    // White measurement noise enters through −gG on s (off), or K on x̂ and kd on d̂
    // (the estimator).
    let mut wb = SMatrix::<f64, N, 2>::zeros();
    match lp.k {
        Some(k) => {
            wb.fixed_view_mut::<2, 2>(2, 0).copy_from(&k);
            wb.fixed_view_mut::<1, 2>(D_HAT, 0).copy_from(&lp.kd);
        }
        None => wb.fixed_view_mut::<2, 2>(0, 0).copy_from(&(-ggr)),
    }
    let q_white = wb * white * wb.transpose();
    PeriodMaps {
        loop_step,
        drift,
        correct,
        q_white,
    }
}

/// A held source's new draw: state `i` forgets what it was (its row and column of `p` zeroed)
/// and takes the variance `var` of a fresh, independent draw (a fix or a DVL ping).
pub(super) fn redraw(p: &mut Cov, i: usize, var: f64) {
    for j in 0..N {
        p[(i, j)] = 0.0;
        p[(j, i)] = 0.0;
    }
    p[(i, i)] = var;
}

/// The periods of a flight of `duration` s over which [`noise_sigma`] propagates the
/// covariance of `noise` on the loop `lp`: the whole flight, or until it repeats with its
/// fixes.
fn propagation_steps(lp: &Loop, noise: &AxisNoise, duration: f64) -> u64 {
    let t = lp.t;
    // With fixes and no outages the covariance is periodic once the loop has settled.
    let held = noise.fix.as_ref().is_some_and(|f| f.2.outages.is_empty())
        && noise.ping.as_ref().is_none_or(|p| p.2.outages.is_empty());
    // Settled means past the loop's transient and at least two of the slowest held source's
    // periods (a fix every 600 s drifts for 600 s before the second one).
    let slowest = [&noise.fix, &noise.ping]
        .into_iter()
        .flatten()
        .map(|src| 1.0 / src.2.rate_hz)
        .fold(0.0, f64::max);
    let span = if held {
        duration.min(SETTLED.max(2.0 * slowest))
    } else {
        duration
    };
    (span.min(MAX_PROPAGATION) / t).ceil() as u64
}

/// A map on the noise propagation's state that is the identity but on a few rows (**Choice
/// 555**): the loop's step changes s, the drift f and h, the estimator's correction x̂ and d̂.
/// `A P Aᵀ` then changes only those rows and columns of P, each entry a sum over the row's
/// non-zero entries: `O(N·nnz)` operations, not the dense product's `2N³`.
///
/// The sums are taken as the dense product (nalgebra's column-by-column `gemm`) takes them:
/// over the columns in ascending order, starting from the first product. The terms it leaves
/// out are products with an exact zero, whose sum with anything is that thing, so every
/// non-zero entry of P is bit for bit the dense product's (a zero entry may differ in sign).
#[derive(Clone, Debug)]
pub(super) struct SparseMap {
    /// The rows that are not the identity's, each with its non-zero entries, columns
    /// ascending.
    rows: Vec<(usize, Vec<(usize, f64)>)>,
}

impl SparseMap {
    /// The rows of `a` that are not the identity's.
    pub(super) fn of(a: &Cov) -> Self {
        let rows = (0..N)
            .filter(|&i| (0..N).any(|k| a[(i, k)] != if k == i { 1.0 } else { 0.0 }))
            .map(|i| {
                let row = (0..N)
                    .filter(|&k| a[(i, k)] != 0.0)
                    .map(|k| (k, a[(i, k)]))
                    .collect();
                (i, row)
            })
            .collect();
        SparseMap { rows }
    }

    /// Σₖ aₖ·x(k) over a row's entries, in the dense product's order.
    fn dot(row: &[(usize, f64)], x: impl Fn(usize) -> f64) -> f64 {
        let mut it = row.iter();
        let Some(&(k0, a0)) = it.next() else {
            return 0.0;
        };
        let mut sum = a0 * x(k0);
        for &(k, a) in it {
            sum += a * x(k);
        }
        sum
    }

    /// P ← A P Aᵀ in place: the rows of A P that differ from P's, then the columns of
    /// (A P) Aᵀ that differ from A P's.
    pub(super) fn sandwich(&self, p: &mut Cov) {
        let mut new = [[0.0; N]; N];
        for ((_, row), out) in self.rows.iter().zip(new.iter_mut()) {
            for (j, o) in out.iter_mut().enumerate() {
                *o = Self::dot(row, |k| p[(k, j)]);
            }
        }
        for ((i, _), out) in self.rows.iter().zip(new.iter()) {
            for (j, o) in out.iter().enumerate() {
                p[(*i, j)] = *o;
            }
        }
        for ((_, row), out) in self.rows.iter().zip(new.iter_mut()) {
            for (i, o) in out.iter_mut().enumerate() {
                *o = Self::dot(row, |k| p[(i, k)]);
            }
        }
        for ((j, _), out) in self.rows.iter().zip(new.iter()) {
            for (i, o) in out.iter().enumerate() {
                p[(i, *j)] = *o;
            }
        }
    }
}

/// The initial covariance of the noise propagation: each held source's first draw and the
/// biases (module docs).
fn initial_covariance(noise: &AxisNoise) -> Cov {
    let (fix_s, fix_b) = noise.fix.as_ref().map_or((0.0, 0.0), |x| (x.0, x.1));
    let (ping_s, ping_b) = noise.ping.as_ref().map_or((0.0, 0.0), |x| (x.0, x.1));
    let mut p = Cov::zeros();
    p[(4, 4)] = fix_s * fix_s;
    p[(5, 5)] = ping_s * ping_s;
    p[(6, 6)] = ping_b * ping_b;
    p[(7, 7)] = noise.accel_bias * noise.accel_bias;
    p[(8, 8)] = fix_b * fix_b;
    p
}

/// σ = maxₜ √P_ee over `steps` periods of the loop `lp` ([`propagation_steps`], module
/// docs), stopping once above `stop_above`. Each period's maps are applied as
/// [`SparseMap`]s (Choice 555): bit for bit the dense products of
/// [`noise_sigma_dense`], the reference it is tested against.
fn noise_sigma(lp: &Loop, noise: &AxisNoise, steps: u64, stop_above: f64) -> f64 {
    let t = lp.t;
    let fix_s = noise.fix.as_ref().map_or(0.0, |x| x.0);
    let ping_s = noise.ping.as_ref().map_or(0.0, |x| x.0);
    let mut p = initial_covariance(noise);
    let maps = period_maps(lp, noise);
    let (loop_step, drift) = (SparseMap::of(&maps.loop_step), SparseMap::of(&maps.drift));
    let correct = maps.correct.as_ref().map(SparseMap::of);
    let q_white = maps.q_white;
    let samples = |src: &Option<(f64, f64, Timing)>, k: u64| {
        src.as_ref().is_some_and(|x| samples_at(&x.2, k, t))
    };
    let mut worst = 0.0f64;
    for n in 0..steps {
        loop_step.sandwich(&mut p);
        if lp.k.is_none() {
            p += q_white;
        }
        drift.sandwich(&mut p);
        if samples(&noise.fix, n + 1) {
            redraw(&mut p, 4, fix_s * fix_s);
        }
        if samples(&noise.ping, n + 1) {
            redraw(&mut p, 5, ping_s * ping_s);
        }
        if let Some(c) = &correct {
            c.sandwich(&mut p);
            p += q_white;
        }
        worst = worst.max(p[(0, 0)]);
        if !worst.is_finite() || worst.sqrt() > stop_above {
            return worst.sqrt();
        }
    }
    // A zero of either sign is σ = +0.
    (worst.max(0.0) + 0.0).sqrt()
}

/// [`noise_sigma`] with the dense products, period by period: the reference the sparse one
/// is tested against (bit for bit).
#[cfg(test)]
fn noise_sigma_dense(lp: &Loop, noise: &AxisNoise, steps: u64, stop_above: f64) -> f64 {
    let t = lp.t;
    let fix_s = noise.fix.as_ref().map_or(0.0, |x| x.0);
    let ping_s = noise.ping.as_ref().map_or(0.0, |x| x.0);
    let mut p = initial_covariance(noise);
    let PeriodMaps {
        loop_step,
        drift,
        correct,
        q_white,
    } = period_maps(lp, noise);
    let mut worst = 0.0f64;
    for n in 0..steps {
        p = loop_step * p * loop_step.transpose();
        if lp.k.is_none() {
            p += q_white;
        }
        p = drift * p * drift.transpose();
        if let Some((_, _, timing)) = &noise.fix {
            if samples_at(timing, n + 1, t) {
                redraw(&mut p, 4, fix_s * fix_s);
            }
        }
        if let Some((_, _, timing)) = &noise.ping {
            if samples_at(timing, n + 1, t) {
                redraw(&mut p, 5, ping_s * ping_s);
            }
        }
        if let Some(c) = &correct {
            p = c * p * c.transpose() + q_white;
        }
        worst = worst.max(p[(0, 0)]);
        if !worst.is_finite() || worst.sqrt() > stop_above {
            return worst.sqrt();
        }
    }
    (worst.max(0.0) + 0.0).sqrt()
}

/// The navigation's part of one axis's budget (Choice 422): q, σ of the draws and of the
/// biases, and q·σ + q_b·σ_b (m).
struct NavigationPart {
    quantile: f64,
    sigma: f64,
    bias: f64,
    noise: f64,
}

/// The predicted max path error √(Σ eᵢ²) of the axes' budgets (Choice 424).
fn path_total(axis: &[f64; AXES]) -> f64 {
    axis.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// q with 2φ(q)/q = `tail` (Mills' bound on P(|x| > q) for a standard normal x).
fn quantile(tail: f64) -> f64 {
    let bound = |q: f64| 2.0 * (-0.5 * q * q).exp() / (q * (2.0 * std::f64::consts::PI).sqrt());
    let (mut lo, mut hi) = (0.5, 40.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if bound(mid) > tail {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// One sample of the reference at k = 1: η_d, η̇_d, η̈_d and the jerk.
#[derive(Clone, Copy, Debug)]
pub(super) struct RefSample {
    pub(super) s: f64,
    pub(super) eta: Vector6<f64>,
    pub(super) eta_dot: Vector6<f64>,
    pub(super) eta_ddot: Vector6<f64>,
    pub(super) jerk: Vector6<f64>,
}

/// What the budget needs of a mission, computed once; evaluated at any time scale.
pub struct Budget<'a> {
    scenario: &'a Scenario,
    bound: f64,
    loops: [Loop; AXES],
    lag_gain: [f64; AXES],
    samples: Vec<RefSample>,
    currents: Vec<Vector3<f64>>,
    nominal: Plant,
    /// Max reference speed per axis at k = 1, and the horizontal speed (m/s).
    speed: [f64; AXES],
    latency: f64,
    /// The reference's K_d of Eq 19 at k = 1 (m/s²), and per sample ‖ν‖, ‖J⁻¹J̇ν‖ at k = 1
    /// and |cos θ|: Eq 29's inputs (Choice 567).
    accel_bound: f64,
    delta_inputs: Vec<[f64; 3]>,
    /// How the reference repeats, when it does (Choices 393, 538–539).
    reduction: Option<period::Reduction>,
    /// Every budget evaluated, by the bits of its time scale and duration (Choice 532): the
    /// check's search, the joined verdicts of both scopes and their rounding ask for the same
    /// scale more than once, and each is a propagation over the whole flight.
    memo: std::cell::RefCell<Vec<([u64; 2], PathBudget)>>,
}

/// The most σ [`SIGMAS`] keeps; past it, it starts again (a check asks for tens).
const SIGMA_MEMO_LIMIT: usize = 4096;

thread_local! {
    /// Every σ propagated on this thread, by the bits of all it reads (Choices 535, 555): the
    /// draws' σ does not depend on the time scale (a ping's error, not the heading's share of
    /// the speed), with fixes the propagation stops where the covariance repeats, so every
    /// scale of a search past that length asks for the same one; and the budgets a check
    /// builds (the profile's probes, the fix-period search, both scopes) fly the same loops on
    /// the same navigation. Keyed by the loop, not by the budget or its axis.
    static SIGMAS: std::cell::RefCell<std::collections::HashMap<Vec<u64>, f64>> =
        std::cell::RefCell::new(std::collections::HashMap::new());
}

impl<'a> Budget<'a> {
    /// The budget's model of `scenario`; `None` when the scenario has no bound.
    ///
    /// # Errors
    /// [`CheckError::Invalid`] for a loop the budget cannot model (an unstable one, an
    /// estimator without a steady state, a nominal model that cannot be built).
    pub fn new(scenario: &'a Scenario) -> Result<Option<Self>, CheckError> {
        Self::with_reduction(scenario, true)
    }

    /// [`Budget::new`], or with `reduce` false the reference it is tested against: the whole
    /// flight, the reference sampled over all of it (no Choice 393, 538 or 539).
    ///
    /// # Errors
    /// As [`Budget::new`].
    pub fn with_reduction(
        scenario: &'a Scenario,
        reduce: bool,
    ) -> Result<Option<Self>, CheckError> {
        let cfg = scenario.config();
        let Some(bound) = cfg.bound() else {
            return Ok(None);
        };
        let invalid = CheckError::Invalid;
        let loops = [
            Loop::of(scenario, 0)?,
            Loop::of(scenario, 1)?,
            Loop::of(scenario, 2)?,
        ];
        let mut lag_gain = [0.0; AXES];
        for (i, l) in loops.iter().enumerate() {
            lag_gain[i] = l.lag_gain().ok_or_else(|| {
                invalid(format!("the law's loop on {} is not stable", AXIS_NAMES[i]))
            })?;
        }
        let path = Trajectory::new(Mission {
            time_scale: 1.0,
            ..cfg.mission()
        })
        .map_err(|e| invalid(format!("the mission at time scale 1: {e}")))?;
        let span = cfg.duration / super::time_scale(cfg.time_scale);
        // A periodic mission's first period (Choice 393), a long one's window (Choice 539).
        let reduction = period::reduction(cfg).filter(|_| reduce);
        let checked = reduction
            .as_ref()
            .map_or(span, |r| span.min(r.reference_span() + SAMPLE_PERIOD));
        let (samples, speed) = reference_samples(&path, checked)?;
        let nominal = Plant::new(
            scenario.controller().params().cast(f64::from),
            PlantTerms::default(),
        )
        .map_err(|e| invalid(format!("the law's nominal model: {e}")))?;
        let currents = current_corners(&cfg.current);
        let latency = match (&cfg.navigation, cfg.controller.estimator.kind) {
            (Some(m), EstimatorKind::Off) => m.ins.timing.latency,
            _ => 0.0,
        };
        let eq29 = samples.iter().map(delta_inputs).collect();
        Ok(Some(Budget {
            scenario,
            bound: bound.max_path,
            loops,
            lag_gain,
            samples,
            currents,
            nominal,
            speed,
            latency,
            accel_bound: f64::from(path.accel_bound()),
            delta_inputs: eq29,
            reduction,
            memo: std::cell::RefCell::new(Vec::new()),
        }))
    }

    /// d along the reference at time scale `k` (module docs): per current corner, per sample,
    /// d on x y z (m/s²).
    fn mismatch(&self, k: f64) -> Result<Vec<Vec<[f64; AXES]>>, CheckError> {
        let cfg = self.scenario.config();
        let lag = cfg.thruster_lag.unwrap_or(0.0);
        let mut out = vec![Vec::with_capacity(self.samples.len()); self.currents.len()];
        let mut plant = PlantCache::default();
        for (j, r) in self.samples.iter().enumerate() {
            if j % 4096 == 0 {
                super::poll()?;
            }
            let (v, a) = (r.eta_dot / k, r.eta_ddot / (k * k));
            let att = Attitude::from_eta(&r.eta);
            let rot = kinematics::rotation(&att);
            let lin = rot.transpose() * Vector3::new(v[0], v[1], v[2]);
            let omega = Vector3::new(v[3], v[4], v[5]);
            let nu = Vector6::new(lin.x, lin.y, lin.z, omega.x, omega.y, omega.z);
            let lin_dot = rot.transpose() * Vector3::new(a[0], a[1], a[2]) - omega.cross(&lin);
            let nu_dot = Vector6::new(lin_dot.x, lin_dot.y, lin_dot.z, a[3], a[4], a[5]);
            let state = PlantState { eta: r.eta, nu };
            let params = cfg.plant_params_at(r.s * k);
            let true_plant = plant.at(params)?;
            // The translational block: a moment the models disagree on is held by the
            // attitude (the heel roll settles at, the pitch and yaw loops), not the path.
            let minv = true_plant
                .mass_matrix()
                .fixed_view::<3, 3>(0, 0)
                .into_owned()
                .try_inverse()
                .ok_or_else(|| CheckError::Invalid("the plant's mass matrix".to_string()))?;
            let nominal = self
                .nominal
                .required_force(&state, &nu_dot, &Vector3::zeros());
            for (c, o) in self.currents.iter().zip(out.iter_mut()) {
                let truth = true_plant.required_force(&state, &nu_dot, c);
                let dtau = nominal - truth;
                let d = rot * (minv * Vector3::new(dtau[0], dtau[1], dtau[2]));
                // The thrust lags the command by τ_L: the acceleration by τ_L·jerk.
                o.push(std::array::from_fn(|i| {
                    d[i] - lag * r.jerk[i] / (k * k * k)
                }));
            }
        }
        Ok(out)
    }

    /// The boundary layer's δ the lag is flown at, at time scale `k` (module docs, Choice
    /// 567): Eq 29 along the reference, from its least with ‖e‖ = 0 (the law's δ is never
    /// below it) to its largest with ‖e‖ at the bound (the errors the budget allows), in
    /// steps of at most [`LAG_DELTA_STEP`], each at most δ_max.
    fn lag_deltas(&self, k: f64) -> Vec<f64> {
        let controller = self.scenario.controller();
        let constants = controller.delta_constants();
        let delta_max = f64::from(controller.config().delta_max);
        let (mut least, mut most) = (f64::INFINITY, 0.0f64);
        // ‖ν‖ falls as 1/k and ‖J⁻¹J̇ν‖ (quadratic in ν) as 1/k².
        for &[nu, jjn, cos_theta] in &self.delta_inputs {
            let delta = |error_norm: f64| {
                f64::from(uncertainty_bound(
                    constants,
                    &DeltaInputs {
                        accel_bound: (self.accel_bound / (k * k)) as f32,
                        error_norm: error_norm as f32,
                        nu_norm: (nu / k) as f32,
                        jinv_jdot_nu_norm: (jjn / (k * k)) as f32,
                        cos_theta_abs: cos_theta as f32,
                    },
                ))
            };
            least = least.min(delta(0.0));
            most = most.max(delta(self.bound));
        }
        let clamp = |d: f64| {
            if d.is_finite() && d > 0.0 {
                d.min(delta_max)
            } else {
                delta_max
            }
        };
        let (least, most) = (clamp(least), clamp(most).max(clamp(least)));
        let steps = ((most / least).ln() / LAG_DELTA_STEP.ln()).ceil().max(1.0) as i32;
        (0..=steps)
            .map(|j| least * (most / least).powf(f64::from(j) / f64::from(steps)))
            .collect()
    }

    /// The periods of the lag's flight at time scale `k` over `duration` s: the whole flight,
    /// or a long mission's window (Choice 539: the loop settled and the reference repeated).
    fn lag_steps(&self, lp: &Loop, k: f64, duration: f64) -> u64 {
        let steps = (duration.min(MAX_PROPAGATION) / lp.t).ceil() as u64;
        match self.reduction.as_ref().filter(|r| r.long) {
            Some(r) => steps.min((r.window(k) * k / lp.t).ceil() as u64),
            None => steps,
        }
    }

    /// |eᵢ| after each of `steps` periods of the linear loop `lp` of axis `i` flown on d (one
    /// current corner's at time scale `k`; `None`: no d) from the start offset `start` (the
    /// estimate on it: the board's first solution becomes its estimate), with the thrusters'
    /// lag in the loop (Choice 567); `visit` is told each period's |e|. d at the control
    /// periods by linear interpolation between the reference's samples (a periodic mission's
    /// repeating).
    fn fly_lag(
        &self,
        (i, lp): (usize, &Loop),
        d: Option<&[[f64; AXES]]>,
        (k, steps): (f64, u64),
        start: f64,
        mut visit: impl FnMut(usize, f64) -> bool,
    ) {
        let (f, g) = (lp.f(), lp.g());
        let at = |t: f64| -> f64 {
            let Some(d) = d else { return 0.0 };
            let span_samples = d.len().saturating_sub(1).max(1) as f64 * SAMPLE_PERIOD;
            let mut s = t / k;
            if let Some(r) = &self.reduction {
                s = r.fold(s);
            }
            let x = (s / SAMPLE_PERIOD).min(span_samples / SAMPLE_PERIOD);
            let j = (x.floor() as usize).min(d.len().saturating_sub(1));
            let j1 = (j + 1).min(d.len() - 1);
            let w = x - j as f64;
            d[j][i] * (1.0 - w) + d[j1][i] * w
        };
        // The acceleration applied over a period is the lag's mean over the held command,
        // (L1) of [`super::lag`].
        let (lambda, mean) = self.lag_terms(lp);
        let mut s = Vector2::new(start, 0.0);
        let mut est = LoopEstimate { x: s, d: 0.0 };
        // The thrusters hold the law's first command before the flight (the simulator's lag
        // starts at its first target).
        let mut applied = lp.input(&s, &est);
        for n in 0..steps {
            let u = lp.input(&s, &est);
            let a = u + (applied - u) * mean;
            applied = u + (applied - u) * lambda;
            let s_next = f * s + g * (a + at(n as f64 * lp.t));
            est = lp.estimate_step(&est, u, &s_next);
            s = s_next;
            if !visit(n as usize, s[0].abs()) {
                return;
            }
        }
    }

    /// ‖h‖₁ of the impulse response from d to e of [`Budget::fly_lag`]'s loop `lp` (the
    /// thrusters' lag in it), widened by [`LAG_SKIP_MARGIN`]; `None` when it has not died
    /// within [`MAX_IMPULSE_PERIODS`] (an unstable or barely damped loop).
    fn lag_l1(&self, lp: &Loop) -> Option<f64> {
        let (f, g) = (lp.f(), lp.g());
        let (lambda, mean) = self.lag_terms(lp);
        let mut s = Vector2::zeros();
        let mut est = LoopEstimate::default();
        let mut applied = 0.0;
        let mut sum = 0.0;
        for n in 0..MAX_IMPULSE_PERIODS {
            let u = lp.input(&s, &est);
            let a = u + (applied - u) * mean;
            applied = u + (applied - u) * lambda;
            let s_next = f * s + g * (a + if n == 0 { 1.0 } else { 0.0 });
            est = lp.estimate_step(&est, u, &s_next);
            s = s_next;
            if !s.iter().all(|x| x.is_finite()) {
                return None;
            }
            sum += s[0].abs();
            let small = 1e-15 * sum.max(1e-300);
            let quiet = s.amax() < small && est.x.amax() < small && est.d.abs() < small;
            if n > 100 && quiet && applied.abs() < small {
                return Some(sum * (1.0 + LAG_SKIP_MARGIN));
            }
        }
        None
    }

    /// The thrusters' lag over one period of `lp`: the state's decay λ = e^(−T/τ_L) and the
    /// held command's mean share ((L1) of [`super::lag`]); (0, 0) without a lag.
    fn lag_terms(&self, lp: &Loop) -> (f64, f64) {
        match self.scenario.config().thruster_lag {
            Some(tl) if tl > 0.0 => {
                let l = (-lp.t / tl).exp();
                (l, (tl / lp.t) * (1.0 - l))
            }
            _ => (0.0, 0.0),
        }
    }

    /// maxₜ |eᵢ(t)| of axis `i`'s lag part at time scale `k` over `duration` s (Choice 567):
    /// per δ of `deltas`, the loop's response to the start offset e₀ᵢ (once) and to each
    /// current corner's d; the response is linear, so the worse sign of e₀ᵢ at each period
    /// is |e_d(t)| + |e_off(t)|, and the run's error starts at |e₀ᵢ|. A corner's flight is
    /// skipped when it cannot raise the worst (**Choice 559**): |e_d(t)| ≤ ‖h‖₁·max|d| (d at
    /// a period is a convex combination of the samples'), so a flight whose
    /// ‖h‖₁·max|d| + maxₜ|e_off| is not above the worst so far leaves the max as it is (an
    /// axis the reference never accelerates on, d = 0, is never flown).
    fn lag_part(
        &self,
        i: usize,
        d: &[Vec<[f64; AXES]>],
        deltas: &[f64],
        k: f64,
        duration: f64,
    ) -> f64 {
        let offset = self.scenario.config().initial_offset[i].abs();
        let mut worst = offset;
        for &delta in deltas {
            let lp = self.loops[i].regained(self.scenario, i, delta);
            let steps = self.lag_steps(&lp, k, duration);
            // The offset's transient, until it has died (a stable loop's does in seconds).
            let mut off = Vec::new();
            if offset > 0.0 {
                let mut quiet = 0;
                self.fly_lag((i, &lp), None, (k, steps), offset, |_, e| {
                    off.push(e);
                    quiet = if e < 1e-9 * offset { quiet + 1 } else { 0 };
                    quiet < 1000
                });
            }
            let off_peak = off.iter().copied().fold(0.0, f64::max);
            let l1 = self.lag_l1(&lp);
            for c in d {
                if let Some(l1) = l1 {
                    let peak = c.iter().map(|x| x[i].abs()).fold(0.0, f64::max);
                    if l1 * peak + off_peak <= worst {
                        continue;
                    }
                }
                self.fly_lag((i, &lp), Some(c), (k, steps), 0.0, |n, e| {
                    worst = worst.max(e + off.get(n).copied().unwrap_or(0.0));
                    true
                });
            }
        }
        worst
    }

    /// The budget at time scale `k` (without the search: `smallest_time_scale` and `needs`
    /// unset).
    fn at(&self, k: f64) -> Result<PathBudget, CheckError> {
        self.at_for(k, self.duration(k))
    }

    /// The flight's duration at time scale `k` (s): the same path.
    fn duration(&self, k: f64) -> f64 {
        let cfg = self.scenario.config();
        cfg.duration * k / super::time_scale(cfg.time_scale)
    }

    /// Whether the budget fits the bound at time scale `k`.
    ///
    /// # Errors
    /// [`CheckError::Interrupted`].
    pub fn fits_at(&self, k: f64) -> Result<bool, CheckError> {
        Ok(self.at(k)?.fits())
    }

    /// [`noise_sigma`] of axis `i` under `noise` over a flight of `duration` s, propagated
    /// once per distinct input on a thread ([`SIGMAS`]: the same bits in, the same σ out).
    fn noise_sigma(&self, i: usize, noise: &AxisNoise, duration: f64, stop: f64) -> f64 {
        let lp = &self.loops[i];
        let steps = propagation_steps(lp, noise, duration);
        let source = |s: &Option<(f64, f64, Timing)>| -> Vec<u64> {
            match s {
                None => vec![0],
                // The outages' count first: the key reads back one way only.
                Some((sigma, bias, timing)) => [1, timing.outages.len() as u64]
                    .into_iter()
                    .chain(
                        [*sigma, *bias, timing.rate_hz]
                            .into_iter()
                            .chain(timing.outages.iter().flatten().copied())
                            .map(f64::to_bits),
                    )
                    .collect(),
            }
        };
        // Keyed by the loop's own bits, not its axis: x and y mostly fly the same loop on the
        // same navigation (Choice 555).
        let mut key: Vec<u64> = [lp.t, lp.gain[0], lp.gain[1]]
            .into_iter()
            .chain(lp.k.iter().flat_map(|k| k.iter().copied()))
            .chain(lp.kd.iter().copied())
            .map(f64::to_bits)
            .collect();
        key.extend([u64::from(lp.k.is_some()), steps, stop.to_bits()]);
        key.push(noise.accel_bias.to_bits());
        key.extend(noise.white.map(f64::to_bits));
        key.extend(source(&noise.fix));
        key.extend(source(&noise.ping));
        if let Some(sigma) = SIGMAS.with(|m| m.borrow().get(&key).copied()) {
            return sigma;
        }
        let sigma = noise_sigma(lp, noise, steps, stop);
        SIGMAS.with(|m| {
            let mut m = m.borrow_mut();
            if m.len() >= SIGMA_MEMO_LIMIT {
                m.clear();
            }
            m.insert(key, sigma);
        });
        sigma
    }

    /// The budget at time scale `k` over a flight of `duration` s: evaluated once per pair
    /// (the same bits in, the same budget out).
    fn at_for(&self, k: f64, duration: f64) -> Result<PathBudget, CheckError> {
        let key = [k.to_bits(), duration.to_bits()];
        if let Some((_, b)) = self.memo.borrow().iter().find(|m| m.0 == key) {
            return Ok(b.clone());
        }
        let b = self.evaluate_at_for(k, duration)?;
        self.memo.borrow_mut().push((key, b.clone()));
        Ok(b)
    }

    /// The navigation's part of axis `i`'s budget (module docs, Choice 422) with the
    /// navigation of `scenario` (the budget's own, or a probe's of [`Budget::fix_period_needed`]),
    /// the horizontal reference speed `horizontal` (m/s), over a flight of `duration` s.
    fn navigation_part(
        &self,
        scenario: &Scenario,
        i: usize,
        horizontal: f64,
        duration: f64,
    ) -> NavigationPart {
        let noise = axis_noise(scenario, i, horizontal);
        let fixes = noise
            .fix
            .as_ref()
            .map_or(1.0, |(_, _, t)| (duration * t.rate_hz).max(1.0));
        // The draws (a fix's, a ping's, white noise: new ones all flight) and the biases
        // (one draw a flight), each at its own quantile (Choice 422).
        let mut draws = noise.clone();
        draws.accel_bias = 0.0;
        for src in [&mut draws.fix, &mut draws.ping].into_iter().flatten() {
            src.1 = 0.0;
        }
        let mut biases = noise;
        biases.white = [0.0; 2];
        for src in [&mut biases.fix, &mut biases.ping].into_iter().flatten() {
            src.0 = 0.0;
        }
        // p for the draws and p for the biases: by the union bound the two together miss
        // with at most 2p, the figure the budget reports (`miss_probability`).
        let q = quantile(MISS_PROBABILITY / (AXES as f64 * fixes));
        // σ beyond the bound: the budget cannot fit (q > 1), no need to fly further.
        let stop = self.bound;
        let sigma = self.noise_sigma(i, &draws, duration, stop);
        let bias = self.noise_sigma(i, &biases, duration, stop);
        NavigationPart {
            quantile: q,
            sigma,
            bias,
            noise: q * sigma + quantile(MISS_PROBABILITY / AXES as f64) * bias,
        }
    }

    /// [`Budget::at_for`], evaluated.
    fn evaluate_at_for(&self, k: f64, duration: f64) -> Result<PathBudget, CheckError> {
        let d = self.mismatch(k)?;
        let deltas = self.lag_deltas(k);
        let mismatch: [f64; AXES] = std::array::from_fn(|i| {
            d.iter()
                .flat_map(|c| c.iter().map(move |x| x[i].abs()))
                .fold(0.0, f64::max)
        });
        let horizontal = self.speed[0].hypot(self.speed[1]) / k;
        let mut out = PathBudget {
            bound: self.bound,
            time_scale: k,
            miss_probability: 2.0 * MISS_PROBABILITY,
            quantile: [0.0; AXES],
            noise_sigma: [0.0; AXES],
            bias_sigma: [0.0; AXES],
            lag_gain: self.lag_gain,
            mismatch,
            noise: [0.0; AXES],
            lag: [0.0; AXES],
            axis: [0.0; AXES],
            total: 0.0,
            speed_independent: 0.0,
            smallest_time_scale: None,
            needs: None,
        };
        for i in 0..AXES {
            let nav = self.navigation_part(self.scenario, i, horizontal, duration);
            out.quantile[i] = nav.quantile;
            out.noise_sigma[i] = nav.sigma;
            out.bias_sigma[i] = nav.bias;
            out.noise[i] = nav.noise;
            let response = self.lag_part(i, &d, &deltas, k, duration);
            out.lag[i] = response + self.speed[i] / k * self.latency;
            out.axis[i] = out.noise[i] + out.lag[i];
        }
        out.total = path_total(&out.axis);
        Ok(out)
    }

    /// The budget at the scenario's own scale, with the smallest scale that fits and, when
    /// none does, what the navigation would have to be.
    ///
    /// # Errors
    /// As [`Budget::new`]; [`CheckError::Interrupted`].
    pub fn evaluate(&self) -> Result<PathBudget, CheckError> {
        let k0 = super::time_scale(self.scenario.config().time_scale);
        let mut out = self.at(k0)?;
        // The speed-independent part: the reference slowed to the slowest scale, over the
        // flight as written (a slower flight drifts longer: the search below flies that).
        let slowest = self.at_for(MAX_TIME_SCALE, self.duration(k0))?;
        out.speed_independent = slowest.total;
        if out.fits() {
            out.smallest_time_scale = Some(self.smallest(1.0, k0)?);
        } else if !slowest.fits() {
            out.needs = Some(self.needs(&slowest));
        } else {
            // Doubling to a scale that fits (a flight without fixes drifts longer as it slows:
            // there may be none), then bisection.
            let mut hi = k0;
            let mut found = None;
            while hi < MAX_TIME_SCALE {
                let lo = hi;
                hi = (2.0 * hi).min(MAX_TIME_SCALE);
                if self.at(hi)?.fits() {
                    found = Some(self.smallest(lo, hi)?);
                    break;
                }
            }
            match found {
                Some(k) => out.smallest_time_scale = Some(k),
                None => out.needs = Some(self.needs(&slowest)),
            }
        }
        Ok(out)
    }

    /// The smallest k in [lo, hi] at which the budget fits (it fits at hi), by bisection to
    /// [`super::TIME_SCALE_TOLERANCE`], rounded up to [`super::TIME_SCALE_STEP`].
    fn smallest(&self, lo: f64, hi: f64) -> Result<f64, CheckError> {
        if self.at(lo)?.fits() {
            return Ok(lo);
        }
        let (mut lo, mut hi) = (lo, hi);
        while hi / lo > 1.0 + super::TIME_SCALE_TOLERANCE {
            let mid = (lo * hi).sqrt();
            if self.at(mid)?.fits() {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let mut k =
            ((hi / super::TIME_SCALE_STEP).ceil() * super::TIME_SCALE_STEP * 100.0).round() / 100.0;
        while k < MAX_TIME_SCALE && !self.at(k)?.fits() {
            k = ((k + super::TIME_SCALE_STEP) * 100.0).round() / 100.0;
        }
        Ok(k.min(MAX_TIME_SCALE))
    }

    /// What the navigation must deliver for the speed-independent budget `slowest` to fit: the
    /// position error per axis it leaves room for, and how often fixes must come for it.
    fn needs(&self, slowest: &PathBudget) -> String {
        // The navigation part scales with the navigation's error: the room left after the lag.
        let lag2: f64 = slowest.lag.iter().map(|x| x * x).sum();
        let room = (self.bound * self.bound - lag2).max(0.0).sqrt();
        let nav = slowest.noise.iter().map(|x| x * x).sum::<f64>().sqrt();
        if room <= 0.0 || nav <= 0.0 {
            return format!(
                "the lag alone is {:.1} mm at the slowest scale",
                1e3 * lag2.sqrt()
            );
        }
        let scale = room / nav;
        let worst = (0..AXES)
            .max_by(|&a, &b| slowest.noise_sigma[a].total_cmp(&slowest.noise_sigma[b]))
            .unwrap_or(0);
        let sigma = scale * slowest.noise_sigma[worst];
        let mut s = format!(
            "needs position error σ ≤ {:.1} mm on {} (assumed {:.1} mm)",
            1e3 * sigma,
            AXIS_NAMES[worst],
            1e3 * slowest.noise_sigma[worst],
        );
        if let Some(p) = self.fix_period_needed(slowest.time_scale) {
            s.push_str(&format!(": fixes at least every {p:.1} s"));
        }
        s
    }

    /// The longest fix period (s) at which the navigation part fits at scale `k`, the fixes'
    /// σ as configured (an LBL's 1 cm when the navigation has none).
    fn fix_period_needed(&self, k: f64) -> Option<f64> {
        let k0 = super::time_scale(self.scenario.config().time_scale);
        let base = self.scenario.config().navigation.as_ref()?;
        let duration = self.duration(k0);
        let lag = self.at_for(k, duration).ok()?.lag;
        let horizontal = self.speed[0].hypot(self.speed[1]) / k;
        let with_period = |period: f64| -> Option<bool> {
            let mut m = base.clone();
            let mut fix = m
                .fix
                .clone()
                .unwrap_or(crate::scenario::navigation::Source {
                    timing: Timing {
                        rate_hz: 1.0,
                        latency: 0.0,
                        outages: Vec::new(),
                    },
                    error: ErrorModel::white_gm([0.01; 2], [0.0; 2], 600.0),
                });
            fix.timing.rate_hz = 1.0 / period;
            m.fix = Some(fix);
            let s = self.scenario.with(|c| c.navigation = Some(m)).ok()?;
            // Only the navigation's part changes with the fixes (Choice 555): the lag is the
            // budget's own at (k, duration).
            let axis: [f64; AXES] = std::array::from_fn(|i| {
                self.navigation_part(&s, i, horizontal, duration).noise + lag[i]
            });
            Some(path_total(&axis) <= self.bound)
        };
        let control = 1.0 / f64::from(self.scenario.config().controller.rate_hz);
        if !with_period(control)? {
            return None;
        }
        let (mut lo, mut hi) = (control, 600.0);
        if with_period(hi)? {
            return Some(hi);
        }
        while hi / lo > 1.01 {
            let mid = (lo * hi).sqrt();
            if with_period(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(lo)
    }
}

/// The budget of `scenario` (module docs); `None` when it has no bound.
///
/// # Errors
/// As [`Budget::new`].
pub fn budget(scenario: &Scenario) -> Result<Option<PathBudget>, CheckError> {
    match Budget::new(scenario)? {
        Some(b) => Ok(Some(b.evaluate()?)),
        None => Ok(None),
    }
}

/// The reference at time scale 1 every [`SAMPLE_PERIOD`] over `checked` s of path time, each
/// sample with its jerk (a finite difference of η̈), and the largest speed per axis.
pub(super) fn reference_samples(
    path: &Trajectory,
    checked: f64,
) -> Result<(Vec<RefSample>, [f64; AXES]), CheckError> {
    let rate = (1.0 / SAMPLE_PERIOD).round() as u32;
    let n = (checked / SAMPLE_PERIOD).ceil().max(1.0) as u64;
    let mut samples: Vec<RefSample> = Vec::with_capacity(n as usize + 2);
    let mut speed = [0.0f64; AXES];
    for j in 0..=n + 1 {
        if j % 4096 == 0 {
            super::poll()?;
        }
        let d = path.sample(j, rate);
        let s = RefSample {
            s: j as f64 * SAMPLE_PERIOD,
            eta: d.eta.cast(),
            eta_dot: d.eta_dot.cast(),
            eta_ddot: d.eta_ddot.cast(),
            jerk: Vector6::zeros(),
        };
        if let Some(prev) = samples.last_mut() {
            prev.jerk = (s.eta_ddot - prev.eta_ddot) / SAMPLE_PERIOD;
        }
        samples.push(s);
    }
    // The last sample has no jerk of its own: it only closed its neighbour's.
    samples.pop();
    for s in &samples {
        for (i, v) in speed.iter_mut().enumerate() {
            *v = v.max(s.eta_dot[i].abs());
        }
    }
    Ok((samples, speed))
}

/// Eq 29's inputs of a reference sample at k = 1: ‖ν‖, ‖J⁻¹J̇ν‖ and |cos θ|.
fn delta_inputs(r: &RefSample) -> [f64; 3] {
    let att = Attitude::from_eta(&r.eta);
    let nu = kinematics::jacobian_inv(&att) * r.eta_dot;
    let jjn = kinematics::jinv_jdot_nu(&att, &nu).unwrap_or_else(|_| Vector6::zeros());
    [nu.norm(), jjn.norm(), att.ctheta.abs()]
}

/// The currents the budget flies: the constant one, or a Gauss–Markov one's mean and its
/// ±[`CURRENT_SIGMAS`]σ corners on each axis whose σ is not zero (x, y and z: a vertical
/// current's wander changes the heave damping the lag's share is linearised at).
pub(super) fn current_corners(current: &CurrentModel) -> Vec<Vector3<f64>> {
    match current {
        CurrentModel::None => vec![Vector3::zeros()],
        CurrentModel::Constant(c) => vec![Vector3::from(*c)],
        CurrentModel::GaussMarkov { mean, sigma, .. } => {
            let offsets = |axis: usize| -> &'static [f64] {
                if sigma[axis] == 0.0 {
                    &[0.0]
                } else {
                    &[-1.0, 0.0, 1.0]
                }
            };
            let mut v = Vec::new();
            for sx in offsets(0) {
                for sy in offsets(1) {
                    for sz in offsets(2) {
                        v.push(Vector3::new(
                            mean[0] + sx * CURRENT_SIGMAS * sigma[0],
                            mean[1] + sy * CURRENT_SIGMAS * sigma[1],
                            mean[2] + sz * CURRENT_SIGMAS * sigma[2],
                        ));
                    }
                }
            }
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gauss_markov(sigma: [f64; 3]) -> CurrentModel {
        CurrentModel::GaussMarkov {
            mean: [0.1, -0.05, 0.02],
            sigma,
            tau: 300.0,
            seed: 1,
        }
    }

    fn timing(rate_hz: f64, outages: Vec<[f64; 2]>) -> Timing {
        Timing {
            rate_hz,
            latency: 0.0,
            outages,
        }
    }

    /// The sparse propagation (Choice 555) is the dense one bit for bit: on the loop with the
    /// board's estimator (disturbance state on) and without, at each axis's gains, under fixes,
    /// pings, outages, white noise, an acceleration bias, and nothing at all.
    #[test]
    fn the_sparse_propagation_is_the_dense_one_bit_for_bit() {
        let e = crate::scenario::navigation::real_chain_estimator();
        let c = controller_core::ControllerConfig::default();
        let mut loops = Vec::new();
        for axis in 0..AXES {
            let b = board_gain(&e, 100, axis).expect("the real chain's estimator has a gain");
            let gain = [f64::from(c.k1[axis]) + 13.7, f64::from(c.k2[axis]) + 5.3];
            let on = Loop {
                t: 0.01,
                gain,
                k: Some(b.k.cast::<f64>()),
                kd: RowVector2::new(f64::from(b.kd[0]), f64::from(b.kd[1])),
            };
            let off = Loop {
                k: None,
                kd: RowVector2::zeros(),
                ..on
            };
            loops.extend([on, off]);
        }
        let full = AxisNoise {
            fix: Some((0.004, 0.002, timing(1.0, vec![]))),
            ping: Some((0.005, 0.003, timing(5.0, vec![]))),
            accel_bias: 0.001,
            white: [0.001, 0.002],
        };
        let outages = AxisNoise {
            fix: Some((0.01, 0.0, timing(0.2, vec![[3.0, 17.5]]))),
            ping: Some((0.0, 0.004, timing(4.0, vec![[10.0, 12.0]]))),
            accel_bias: 0.0,
            white: [0.0; 2],
        };
        let no_fix = AxisNoise {
            fix: None,
            ..full.clone()
        };
        let white_only = AxisNoise {
            white: [0.003, 0.0],
            ..AxisNoise::default()
        };
        let noises = [full, outages, no_fix, white_only, AxisNoise::default()];
        for (l, lp) in loops.iter().enumerate() {
            for (j, noise) in noises.iter().enumerate() {
                for (steps, stop) in [(3_000, f64::INFINITY), (3_000, 0.004)] {
                    let sparse = noise_sigma(lp, noise, steps, stop);
                    let dense = noise_sigma_dense(lp, noise, steps, stop);
                    assert_eq!(
                        sparse.to_bits(),
                        dense.to_bits(),
                        "loop {l}, noise {j}, stop {stop}: {sparse} vs {dense}"
                    );
                }
            }
        }
    }

    /// Every axis with a wander is flown at its mean and both ±kσ corners: before, a vertical
    /// σ was dropped and the heave corners never flew.
    #[test]
    fn a_gauss_markov_current_is_cornered_on_every_axis_that_wanders() {
        for sigma in [[0.05, 0.05, 0.01], [0.0, 0.0, 0.01], [0.05, 0.0, 0.0]] {
            let corners = current_corners(&gauss_markov(sigma));
            let wandering = sigma.iter().filter(|s| **s != 0.0).count();
            assert_eq!(corners.len(), 3usize.pow(wandering as u32), "σ {sigma:?}");
            for axis in 0..3 {
                let mean = [0.1, -0.05, 0.02][axis];
                for k in [-CURRENT_SIGMAS, 0.0, CURRENT_SIGMAS] {
                    let want = mean + k * sigma[axis];
                    assert!(
                        corners.iter().any(|c| (c[axis] - want).abs() < 1e-15),
                        "σ {sigma:?}: no corner at {want} on axis {axis}"
                    );
                }
            }
        }
    }

    /// The board's estimator with its disturbance state (Choice 510) is unbiased under a
    /// steady unexplained acceleration d: d̂ → d, and the loop settles where the law's input on
    /// the true error cancels it, u = −G s = −d with ė = 0, so e = d/G₁ (closed form). The
    /// loop's model must carry d̂'s integration (Choice 512) to show it: with the rows of η and
    /// η̇ alone the estimate lags d and the error settles elsewhere (regression: it did).
    #[test]
    fn a_steady_disturbance_settles_at_the_closed_form_error() {
        let e = crate::scenario::navigation::real_chain_estimator();
        let b = board_gain(&e, 100, 0).expect("the real chain's estimator has a gain");
        assert!(
            b.kd.iter().any(|&x| x != 0.0),
            "the disturbance state is on"
        );
        let c = controller_core::ControllerConfig::default();
        let gain = [f64::from(c.k1[0]), f64::from(c.k2[0])];
        let lp = Loop {
            t: 0.01,
            gain,
            k: Some(b.k.cast::<f64>()),
            kd: RowVector2::new(f64::from(b.kd[0]), f64::from(b.kd[1])),
        };
        let d = 0.05;
        let (mut s, mut est) = (Vector2::zeros(), LoopEstimate::default());
        // 20 min: d̂'s own time constant is tens of seconds at σₐ 0.004, τ_d 60 s.
        for _ in 0..120_000 {
            let u = lp.input(&s, &est);
            let s_next = lp.f() * s + lp.g() * (u + d);
            est = lp.estimate_step(&est, u, &s_next);
            s = s_next;
        }
        let want = d / gain[0];
        assert!(
            (s[0] - want).abs() < 1e-6 * want,
            "e {} vs d/G₁ {want}",
            s[0]
        );
        assert!(s[1].abs() < 1e-9, "ė {}", s[1]);
        assert!((est.d - d).abs() < 1e-6 * d, "d̂ {} vs d {d}", est.d);
    }

    fn survey_with(change: impl FnOnce(&mut crate::scenario::SimConfig)) -> Scenario {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = crate::scenario::load_scenario(&path).expect("the shipped survey");
        survey.with(change).expect("the survey changed")
    }

    /// Choice 559's skip rests on |e_d(t)| ≤ ‖h‖₁·max|d| for the loop as flown (the lag in
    /// it): random sign-flipping d, the adversary of the ℓ₁ bound, never beats it.
    #[test]
    fn the_lag_loops_l1_gain_bounds_every_flight() {
        let scenario = survey_with(|c| c.thruster_lag = Some(0.4));
        let b = Budget::new(&scenario).expect("a budget").expect("a bound");
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..AXES {
            for delta in [1.0, 3.0, 8.0, 25.0] {
                let lp = b.loops[i].regained(&scenario, i, delta);
                let l1 = b.lag_l1(&lp).expect("a stable loop");
                for _ in 0..4 {
                    let hold = 1 + (next() * 40.0) as usize;
                    let mut d = Vec::new();
                    let mut sign = 1.0;
                    for j in 0..3_000 {
                        if j % hold == 0 && next() < 0.5 {
                            sign = -sign;
                        }
                        d.push([sign * (0.5 + 0.5 * next()); AXES]);
                    }
                    let most = d.iter().map(|x| x[i].abs()).fold(0.0, f64::max);
                    let mut peak = 0.0f64;
                    b.fly_lag((i, &lp), Some(&d), (1.0, 30_000), 0.0, |_, e| {
                        peak = peak.max(e);
                        true
                    });
                    assert!(
                        peak > 0.0 && peak <= l1 * most,
                        "axis {i} δ {delta}: {peak} > {l1}·{most}"
                    );
                }
            }
        }
    }

    /// The lag part with the skip is the max of every flight (brute force: each δ, each
    /// corner, flown), bit for bit, with an offset, a lag and a wandering current.
    #[test]
    fn skipping_flights_leaves_the_lag_part_as_flown() {
        let scenario = survey_with(|c| {
            c.thruster_lag = Some(0.3);
            c.initial_offset[0] = 0.02;
            c.current = gauss_markov([0.05, 0.05, 0.01]);
            c.duration = 200.0;
        });
        let b = Budget::new(&scenario).expect("a budget").expect("a bound");
        for k in [1.0, 1.7, MAX_TIME_SCALE] {
            let d = b.mismatch(k).expect("d");
            let deltas = b.lag_deltas(k);
            let duration = b.duration(k);
            for i in 0..AXES {
                let offset = scenario.config().initial_offset[i].abs();
                let mut want = offset;
                for &delta in &deltas {
                    let lp = b.loops[i].regained(&scenario, i, delta);
                    let steps = b.lag_steps(&lp, k, duration);
                    // The offset's transient as the budget keeps it: until 1 000 quiet periods.
                    let (mut off, mut quiet) = (Vec::new(), 0);
                    if offset > 0.0 {
                        b.fly_lag((i, &lp), None, (k, steps), offset, |_, e| {
                            off.push(e);
                            quiet = if e < 1e-9 * offset { quiet + 1 } else { 0 };
                            quiet < 1000
                        });
                    }
                    for c in &d {
                        b.fly_lag((i, &lp), Some(c), (k, steps), 0.0, |n, e| {
                            want = want.max(e + off.get(n).copied().unwrap_or(0.0));
                            true
                        });
                    }
                }
                let got = b.lag_part(i, &d, &deltas, k, duration);
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "k {k} axis {i}: {got} vs {want}"
                );
            }
        }
    }
}
