//! The board's state estimator (docs/law.md#the-state-estimator, **Choice 340**): a per-axis
//! steady-state Kalman filter that filters the navigation solution the board is told and
//! predicts it forward over the solution's age, with the nominal model and the thrust the
//! board applied.
//!
//! Per axis i of η (all six; roll too, which the law leaves uncontrolled but whose angle enters
//! J), the state is x = [ηᵢ, η̇ᵢ] and one period T of the model is
//!
//! x⁺ = F x + g aᵢ,  F = [[1, T], [0, 1]],  g = [T²/2, T],
//!
//! with aᵢ the η-frame acceleration the nominal model gives for the thrust the board applied
//! over that period ([`applied_acceleration`]). The model's error is white acceleration noise
//! of standard deviation σₐ per period (Q = σₐ² g gᵀ); the solution measures both components,
//! z = x + n, R = diag(σₚ², σᵥ²). The gain K = P⁻(P⁻ + R)⁻¹ is the steady state of the
//! discrete Riccati equation, solved once at configuration ([`steady_state_gain`]); per period
//! the work is fixed: one correction at the solution's stamp and two sums over the last
//! [`HORIZON`] applied accelerations.
//!
//! **Choice 341:** the filter's state is kept at the stamp of the newest solution taken (the
//! delayed horizon), and the estimate the law uses is that state predicted forward to the
//! current period with the accelerations applied since ([`Estimate::step`]). A solution older
//! than [`HORIZON`] periods, not newer than the last one taken, stamped in the future, or not
//! finite is refused: the state is held and predicted, never corrected by it.

use nalgebra::{Matrix2, Vector6};

use crate::axes::YAW;
use crate::kinematics::Kinematics;

/// How many periods of applied acceleration the estimator keeps: the oldest solution it can
/// correct at its stamp and predict forward (Choice 341: 16 periods, 160 ms at 100 Hz, covers a
/// DVL-aided INS's latency of some tens of milliseconds with room).
pub const HORIZON: usize = 16;

/// Fixed number of doubling steps of [`steady_state_gain`]: the error of the structure-preserving
/// doubling algorithm falls like ρ^(2^k) with ρ < 1 the filter's closed-loop spectral radius,
/// so 32 steps cover every ρ below 1 − 10⁻⁹.
const DOUBLING_STEPS: usize = 32;

/// Whether the law flies on the solution as told or on the estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EstimatorKind {
    /// The law is given the solution as it arrives (the default: Table 1 and every shipped
    /// output are flown so).
    Off,
    /// The per-axis steady-state Kalman filter of this module.
    Kalman,
}

/// The estimator's settings, per axis of η = [x y z φ θ ψ] (m, rad and their rates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig {
    pub kind: EstimatorKind,
    /// σₚ: the solution's position/angle noise (m, rad).
    pub position_sigma: [f32; 6],
    /// σᵥ: the noise of the solution's η̇ = J(η)ν (m/s, rad/s).
    pub velocity_sigma: [f32; 6],
    /// σₐ: the model's acceleration error per period (m/s², rad/s²): what the nominal model
    /// and the applied thrust do not explain (parameter mismatch, current, thruster lag).
    /// Smaller trusts the model more: a smoother estimate that lags a mismatch longer.
    pub accel_sigma: [f32; 6],
}

impl Default for EstimatorConfig {
    /// Off, with the noise of the shipped campaigns' `[noise]` table (5 mm, 1 mrad;
    /// 2 mm/s, 0.5 mrad/s) and the model error measured to fly the real chain best
    /// (docs/law.md#the-state-estimator, Choice 343).
    fn default() -> Self {
        EstimatorConfig {
            kind: EstimatorKind::Off,
            position_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
            velocity_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
            accel_sigma: [0.02, 0.02, 0.02, 0.004, 0.004, 0.004],
        }
    }
}

/// One axis's steady-state gain K (2×2) and the prior covariance P⁻ it comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisGain {
    pub k: Matrix2<f32>,
    pub p_prior: Matrix2<f32>,
}

impl AxisGain {
    /// The gain that takes no measurement (K = 0): an axis of an estimator that is off.
    pub const ZERO: AxisGain = AxisGain {
        k: Matrix2::new(0.0, 0.0, 0.0, 0.0),
        p_prior: Matrix2::new(0.0, 0.0, 0.0, 0.0),
    };
}

/// Why [`steady_state_gain`] has no gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoSteadyState;

/// The steady-state gain of the filter of this module for one axis: period `period` (s),
/// σₚ, σᵥ, σₐ all finite and > 0 (checked by the configuration).
///
/// P⁻ solves the filter's discrete algebraic Riccati equation
/// P⁻ = F P⁻ Fᵀ − F P⁻ (P⁻ + R)⁻¹ P⁻ Fᵀ + Q, which is the control-form equation
/// X = AᵀXA − AᵀX(R + X)⁻¹XA + Q with A = Fᵀ (B = I); it is found by the structure-preserving
/// doubling algorithm (Chu, Fan & Lin 2005), a fixed [`DOUBLING_STEPS`] steps:
/// W = I + GₖHₖ, Aₖ₊₁ = AₖW⁻¹Aₖ, Gₖ₊₁ = Gₖ + AₖW⁻¹GₖAₖᵀ, Hₖ₊₁ = Hₖ + AₖᵀHₖW⁻¹Aₖ from
/// A₀ = A, G₀ = R⁻¹, H₀ = Q; Hₖ → P⁻. Then K = P⁻(P⁻ + R)⁻¹. Configuration time only.
pub fn steady_state_gain(
    period: f32,
    position_sigma: f32,
    velocity_sigma: f32,
    accel_sigma: f32,
) -> Result<AxisGain, NoSteadyState> {
    let t = period;
    let (g0, g1) = (0.5 * t * t, t);
    let qa = accel_sigma * accel_sigma;
    let q = M2([[qa * g0 * g0, qa * g0 * g1], [qa * g1 * g0, qa * g1 * g1]]);
    let (rp, rv) = (
        position_sigma * position_sigma,
        velocity_sigma * velocity_sigma,
    );
    let r = M2([[rp, 0.0], [0.0, rv]]);
    let mut a = M2([[1.0, 0.0], [t, 1.0]]); // Fᵀ
    let mut gk = r.inverse().ok_or(NoSteadyState)?;
    let mut h = q;
    for _ in 0..DOUBLING_STEPS {
        let w_inv = M2::IDENTITY
            .add(&gk.mul(&h))
            .inverse()
            .ok_or(NoSteadyState)?;
        let a_w = a.mul(&w_inv);
        let a_next = a_w.mul(&a);
        let g_next = gk.add(&a_w.mul(&gk).mul(&a.transpose()));
        let h_next = h.add(&a.transpose().mul(&h).mul(&w_inv).mul(&a));
        a = a_next;
        gk = g_next;
        h = h_next;
    }
    // Symmetric by construction; average the rounding away.
    let p = h.add(&h.transpose()).scale(0.5);
    let k = p.mul(&p.add(&r).inverse().ok_or(NoSteadyState)?);
    let positive = p.0[0][0] > 0.0 && p.det() > 0.0;
    let finite =
        k.0.iter()
            .chain(p.0.iter())
            .flatten()
            .all(|x| x.is_finite());
    if positive && finite {
        Ok(AxisGain {
            k: k.matrix(),
            p_prior: p.matrix(),
        })
    } else {
        Err(NoSteadyState)
    }
}

/// A 2×2 matrix by rows, with the few operations the doubling algorithm needs (written out:
/// the generic ones cost the board's flash more than the budget allows).
#[derive(Clone, Copy)]
struct M2([[f32; 2]; 2]);

impl M2 {
    const IDENTITY: M2 = M2([[1.0, 0.0], [0.0, 1.0]]);

    fn mul(&self, b: &M2) -> M2 {
        let (a, b) = (&self.0, &b.0);
        M2(core::array::from_fn(|i| {
            core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j])
        }))
    }

    fn add(&self, b: &M2) -> M2 {
        M2(core::array::from_fn(|i| {
            core::array::from_fn(|j| self.0[i][j] + b.0[i][j])
        }))
    }

    fn scale(&self, s: f32) -> M2 {
        M2(self.0.map(|row| row.map(|x| x * s)))
    }

    fn transpose(&self) -> M2 {
        let a = &self.0;
        M2([[a[0][0], a[1][0]], [a[0][1], a[1][1]]])
    }

    fn det(&self) -> f32 {
        let a = &self.0;
        a[0][0] * a[1][1] - a[0][1] * a[1][0]
    }

    /// The inverse, if the determinant is finite and not zero.
    fn inverse(&self) -> Option<M2> {
        let d = self.det();
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let a = &self.0;
        Some(M2([
            [a[1][1] / d, -a[0][1] / d],
            [-a[1][0] / d, a[0][0] / d],
        ]))
    }

    fn matrix(&self) -> Matrix2<f32> {
        let a = &self.0;
        Matrix2::new(a[0][0], a[0][1], a[1][0], a[1][1])
    }
}

/// The six axes' gains and the period, computed once from an [`EstimatorConfig`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorGains {
    pub axes: [AxisGain; 6],
    /// T (s).
    pub period: f32,
}

impl EstimatorGains {
    /// The gains of `config` at `rate_hz`; `Err(axis)` names an axis without a steady state.
    pub fn new(config: &EstimatorConfig, rate_hz: u32) -> Result<Self, usize> {
        let period = 1.0 / rate_hz.max(1) as f32;
        let mut axes = [AxisGain::ZERO; 6];
        for (i, axis) in axes.iter_mut().enumerate() {
            *axis = steady_state_gain(
                period,
                config.position_sigma[i],
                config.velocity_sigma[i],
                config.accel_sigma[i],
            )
            .map_err(|_| i)?;
        }
        Ok(EstimatorGains { axes, period })
    }
}

/// The η-frame acceleration the nominal model gives for the thrust the board applied:
/// η̈ = J ν̇ + J̇ ν with ν̇ = M̂⁻¹(τₐ − ĥ); the law chose τ so that the nominal η̈ is u, so
/// η̈ = u − J M̂⁻¹(τ − τₐ) (τₐ the achieved wrench, B times the thrusts the voltages give).
/// The shortfall τ − τₐ (zero unless the thrusters saturate) goes through M̂'s diagonal,
/// `m_diag_inv` = 1/M̂ᵢᵢ: no 6×6 inverse in the flying image (Choice 340).
pub fn applied_acceleration(
    u: &Vector6<f32>,
    kin: &Kinematics<f32>,
    m_diag_inv: &[f32; 6],
    tau: &Vector6<f32>,
    tau_achieved: &Vector6<f32>,
) -> Vector6<f32> {
    let shortfall = Vector6::from_fn(|i, _| m_diag_inv[i] * (tau[i] - tau_achieved[i]));
    u - kin.eta_dot(&shortfall)
}

/// The board's estimator memory: the filter's state at its stamp and the accelerations
/// applied over the last [`HORIZON`] periods. Owned by whoever flies the controller
/// ([`crate::Controller::update_from_solution`]); a new mission starts from [`Estimate::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// η at `stamp` is `anchor + offset` (valid only when `valid`): the anchor is the last
    /// solution taken, the offset the filter's small departure from it. **Choice 342:** a
    /// correction of a position near 10 km is far below its f32 ulp (0.98 mm) and would be
    /// lost; kept apart, the offset carries it exactly (tests/estimator.rs measures both).
    anchor: [f32; 6],
    offset: [f32; 6],
    /// η̇ at `stamp`.
    velocity: [f32; 6],
    stamp: u64,
    valid: bool,
    /// a of period t at index t mod HORIZON; `accel_tick` says which t (u64::MAX: none).
    accel: [[f32; 6]; HORIZON],
    accel_tick: [u64; HORIZON],
}

impl Default for Estimate {
    fn default() -> Self {
        Self::new()
    }
}

/// Weights of the accelerations applied in [from, to) for a prediction from `from` to `to`:
/// Δη = Σ aₜ T² (to − t − ½), Δη̇ = Σ aₜ T over the periods held; an entry outside the range
/// weighs 0. Fixed work: every entry is visited.
fn weights(
    accel_tick: &[u64; HORIZON],
    from: u64,
    to: u64,
    t: f32,
) -> ([f32; HORIZON], [f32; HORIZON]) {
    let mut w_pos = [0.0f32; HORIZON];
    let mut w_vel = [0.0f32; HORIZON];
    for j in 0..HORIZON {
        let tick = accel_tick[j];
        let held = tick >= from && tick < to;
        let lead = to.wrapping_sub(tick) as f32 - 0.5;
        w_pos[j] = if held { t * t * lead } else { 0.0 };
        w_vel[j] = if held { t } else { 0.0 };
    }
    (w_pos, w_vel)
}

impl Estimate {
    /// No estimate yet: the first solution taken becomes it.
    pub const fn new() -> Self {
        Estimate {
            anchor: [0.0; 6],
            offset: [0.0; 6],
            velocity: [0.0; 6],
            stamp: 0,
            valid: false,
            accel: [[0.0; 6]; HORIZON],
            accel_tick: [u64::MAX; HORIZON],
        }
    }

    /// Whether a solution has been taken.
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// The stamp (ticks) of the newest solution taken.
    pub fn stamp(&self) -> u64 {
        self.stamp
    }

    /// The filter's state [η, η̇] at its stamp.
    pub fn at_stamp(&self) -> ([f32; 6], [f32; 6]) {
        (
            core::array::from_fn(|i| self.anchor[i] + self.offset[i]),
            self.velocity,
        )
    }

    /// The state predicted from `from` (the stamp) to `to` with the accelerations applied
    /// since: the position as its offset from the anchor, and the velocity.
    fn predicted(&self, gains: &EstimatorGains, from: u64, to: u64) -> ([f32; 6], [f32; 6]) {
        let (w_pos, w_vel) = weights(&self.accel_tick, from, to, gains.period);
        let dt = to.saturating_sub(from) as f32 * gains.period;
        let mut p = self.offset;
        let mut v = self.velocity;
        for i in 0..6 {
            let mut dp = 0.0f32;
            let mut dv = 0.0f32;
            for j in 0..HORIZON {
                dp += w_pos[j] * self.accel[j][i];
                dv += w_vel[j] * self.accel[j][i];
            }
            p[i] += v[i] * dt + dp;
            v[i] += dv;
        }
        (p, v)
    }

    /// Period `ticks`: takes the solution `z` = (η, η̇) stamped `stamp` if it is usable
    /// (finite, not newer than `ticks`, newer than the last taken, at most [`HORIZON`] periods
    /// old), correcting the state at that stamp; returns the estimate (η̂, η̂̇) at `ticks`, or
    /// `None` before any solution was taken. A yaw innovation is wrapped to (−π, π], so the
    /// yaw state stays within half a turn of the solution's heading (its anchor).
    pub fn step(
        &mut self,
        gains: &EstimatorGains,
        ticks: u64,
        stamp: u64,
        eta: &[f32; 6],
        eta_dot: &[f32; 6],
    ) -> Option<([f32; 6], [f32; 6])> {
        if self.valid && ticks < self.stamp {
            // Time went back: a new mission.
            *self = Estimate::new();
        }
        let finite = eta.iter().chain(eta_dot.iter()).all(|x| x.is_finite());
        let in_window = stamp <= ticks && ticks - stamp <= HORIZON as u64;
        if finite && in_window {
            if !self.valid {
                self.anchor = *eta;
                self.offset = [0.0; 6];
                self.velocity = *eta_dot;
                self.stamp = stamp;
                self.valid = true;
            } else if stamp > self.stamp {
                // The prior at the stamp, its position as an offset from the old anchor.
                let (o, v) = self.predicted(gains, self.stamp, stamp);
                let mut offset = [0.0f32; 6];
                let mut vel = v;
                for i in 0..6 {
                    // z − prior = (z − anchor) − offset: near each other, so exact first.
                    let mut dz = (eta[i] - self.anchor[i]) - o[i];
                    if i == YAW {
                        dz = crate::math::wrap_pi(dz);
                    }
                    let dv = eta_dot[i] - v[i];
                    let k = &gains.axes[i].k;
                    // Posterior − z, with z the new anchor: (prior − z) + K₀·[dz, dv].
                    offset[i] = (k[(0, 0)] - 1.0) * dz + k[(0, 1)] * dv;
                    vel[i] = v[i] + k[(1, 0)] * dz + k[(1, 1)] * dv;
                }
                let sum_finite = (0..6).all(|i| (eta[i] + offset[i]).is_finite());
                if sum_finite && vel.iter().all(|x| x.is_finite()) {
                    self.anchor = *eta;
                    self.offset = offset;
                    self.velocity = vel;
                    self.stamp = stamp;
                }
            }
        }
        if !self.valid {
            return None;
        }
        let (o, v) = self.predicted(gains, self.stamp, ticks);
        Some((core::array::from_fn(|i| self.anchor[i] + o[i]), v))
    }

    /// Records the acceleration `a` applied over period `ticks` (a non-finite one is recorded
    /// as zero: unknown), after moving the state's stamp past the period whose entry it
    /// replaces, so that the prediction from the stamp never loses an acceleration it used.
    /// Period `ticks` recorded again (lock-step: the board ran it once without a fresh frame,
    /// then on the frame, Choice 362) replaces its own entry: the state at the stamp does not
    /// depend on it, so the stamp stays (moved, the next solution would be refused as old).
    pub fn applied(&mut self, gains: &EstimatorGains, ticks: u64, a: &[f32; 6]) {
        let j = (ticks % HORIZON as u64) as usize;
        let old = self.accel_tick[j];
        if self.valid && old != u64::MAX && old != ticks && old == self.stamp {
            let (o, v) = self.predicted(gains, self.stamp, self.stamp + 1);
            self.offset = o;
            self.velocity = v;
            self.stamp += 1;
        }
        let finite = a.iter().all(|x| x.is_finite());
        self.accel[j] = if finite { *a } else { [0.0; 6] };
        self.accel_tick[j] = ticks;
    }
}
