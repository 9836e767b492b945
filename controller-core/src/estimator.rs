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
//! the work is fixed: one correction at the solution's stamp and two predictions, each a
//! difference of running sums of the applied accelerations (Choice 430, [`Estimate`]).
//!
//! **Choice 510:** with `disturbance_time` τ_d > 0 each axis carries a third state, the
//! acceleration dᵢ the nominal model does not explain and that varies slowly (a water current's
//! drag on the relative velocity, a payload's weight): x = [ηᵢ, η̇ᵢ, dᵢ],
//!
//! x⁺ = F x + g aᵢ,  F = [[1, T, T²/2], [0, 1, T], [0, 0, 1]],  g = [T²/2, T, 0],
//!
//! d a random walk of variance σₐ²·2T/τ_d per period (a Gauss–Markov process of standard
//! deviation σₐ and time τ_d, its decay left out so that a steady disturbance leaves no
//! steady error). Without it a steady current is a constant acceleration the two-state filter
//! does not know: its estimate lags by a constant offset and the prediction over the
//! solution's age adds d·(age)²/2. The steady-state gain (3×2) comes from the same doubling
//! algorithm ([`steady_state_gain_with_disturbance`]); a prediction adds d·Δt²/2 and d·Δt in
//! closed form (d is constant over it), so the work stays fixed.
//!
//! **Choice 341:** the filter's state is kept at the stamp of the newest solution taken (the
//! delayed horizon), and the estimate the law uses is that state predicted forward to the
//! current period with the accelerations applied since ([`Estimate::step`]). A solution older
//! than [`MAX_AGE`] periods (or, after periods the board did not run, stamped before the first
//! of them, Choice 554), not newer than the last one taken, stamped in the future, or not
//! finite is refused: the state is held and predicted, never corrected by it.

use nalgebra::{Matrix2, Vector6};

use crate::axes::YAW;
use crate::kinematics::Kinematics;
use crate::math::times_zero;

/// How many periods of applied acceleration the estimator keeps, the current one included:
/// the oldest solution it can correct at its stamp and predict forward is [`MAX_AGE`] periods
/// old (Choice 341: 16 periods; Choice 554: 15 periods, 150 ms at 100 Hz, covers a DVL-aided
/// INS's latency of some tens of milliseconds with room).
pub const HORIZON: usize = 16;

/// The oldest a solution may be, in periods, to be taken: [`HORIZON`] − 1 (**Choice 554**: the
/// record of the period it arrives in then keeps every period after its stamp, so the state
/// taken is never predicted again, a third time, by that record; 150 ms at 100 Hz).
pub const MAX_AGE: u64 = HORIZON as u64 - 1;

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
    /// τ_d (s): the time scale of the slowly varying model error the filter estimates as a
    /// disturbance state per axis (Choice 510; 0: none, the two-state filter). Not a
    /// scenario key nor on the wire: every board and SIL fly [`DISTURBANCE_TIME`].
    pub disturbance_time: f32,
}

/// The disturbance state's time scale (s) every estimator flies (Choice 510): the Gauss–Markov
/// time of the simulator's current (60 s), the slowest model error the board meets.
pub const DISTURBANCE_TIME: f32 = 60.0;

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
            disturbance_time: DISTURBANCE_TIME,
        }
    }
}

/// One axis's steady-state gain and the prior covariance P⁻ it comes from: K's rows of η and
/// η̇ (2×2, P⁻'s block of them), and its row of the disturbance (zero without one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisGain {
    pub k: Matrix2<f32>,
    pub kd: [f32; 2],
    pub p_prior: Matrix2<f32>,
}

impl AxisGain {
    /// The gain that takes no measurement (K = 0): an axis of an estimator that is off.
    pub const ZERO: AxisGain = AxisGain {
        k: Matrix2::new(0.0, 0.0, 0.0, 0.0),
        kd: [0.0; 2],
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
            kd: [0.0; 2],
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

/// The steady-state gain of the filter with a disturbance state (Choice 510) for one axis:
/// as [`steady_state_gain`] on x = [η, η̇, d] with F, g of the module's docs, the measurement
/// C = [I₂ 0], R = diag(σₚ², σᵥ²) and Q = σₐ² g gᵀ + diag(0, 0, σₐ²·2T/τ_d); the doubling
/// algorithm from A₀ = Fᵀ, G₀ = Cᵀ R⁻¹ C, H₀ = Q, then K = P⁻Cᵀ(C P⁻ Cᵀ + R)⁻¹ (3×2: rows
/// η, η̇ in [`AxisGain::k`], d in [`AxisGain::kd`]). `disturbance_time` finite and > 0.
/// Configuration time only.
pub fn steady_state_gain_with_disturbance(
    period: f32,
    position_sigma: f32,
    velocity_sigma: f32,
    accel_sigma: f32,
    disturbance_time: f32,
) -> Result<AxisGain, NoSteadyState> {
    let t = period;
    let g = [0.5 * t * t, t, 0.0];
    let qa = accel_sigma * accel_sigma;
    let mut q = M3(core::array::from_fn(|i| {
        core::array::from_fn(|j| qa * g[i] * g[j])
    }));
    q.0[2][2] = qa * 2.0 * t / disturbance_time;
    let (rp, rv) = (
        position_sigma * position_sigma,
        velocity_sigma * velocity_sigma,
    );
    let mut a = M3([[1.0, 0.0, 0.0], [t, 1.0, 0.0], [0.5 * t * t, t, 1.0]]); // Fᵀ
    let mut gk = M3([[1.0 / rp, 0.0, 0.0], [0.0, 1.0 / rv, 0.0], [0.0, 0.0, 0.0]]);
    let mut h = q;
    for _ in 0..DOUBLING_STEPS {
        let w_inv = M3::IDENTITY
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
    let p = h.add(&h.transpose()).scale(0.5).0;
    // S = C P⁻ Cᵀ + R and K = P⁻ Cᵀ S⁻¹.
    let s = M2([[p[0][0] + rp, p[0][1]], [p[1][0], p[1][1] + rv]])
        .inverse()
        .ok_or(NoSteadyState)?;
    let k: [[f32; 2]; 3] = core::array::from_fn(|i| {
        core::array::from_fn(|j| p[i][0] * s.0[0][j] + p[i][1] * s.0[1][j])
    });
    let block = M2([[p[0][0], p[0][1]], [p[1][0], p[1][1]]]);
    let positive = p[0][0] > 0.0 && block.det() > 0.0 && M3(p).det() > 0.0;
    let finite = k
        .iter()
        .flatten()
        .chain(p.iter().flatten())
        .all(|x| x.is_finite());
    if positive && finite {
        Ok(AxisGain {
            k: M2([k[0], k[1]]).matrix(),
            kd: k[2],
            p_prior: block.matrix(),
        })
    } else {
        Err(NoSteadyState)
    }
}

/// A 3×3 matrix by rows, as [`M2`] (the disturbance filter's doubling algorithm).
#[derive(Clone, Copy)]
struct M3([[f32; 3]; 3]);

impl M3 {
    const IDENTITY: M3 = M3([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    fn mul(&self, b: &M3) -> M3 {
        let (a, b) = (&self.0, &b.0);
        M3(core::array::from_fn(|i| {
            core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
        }))
    }

    fn add(&self, b: &M3) -> M3 {
        M3(core::array::from_fn(|i| {
            core::array::from_fn(|j| self.0[i][j] + b.0[i][j])
        }))
    }

    fn scale(&self, s: f32) -> M3 {
        M3(self.0.map(|row| row.map(|x| x * s)))
    }

    fn transpose(&self) -> M3 {
        M3(core::array::from_fn(|i| {
            core::array::from_fn(|j| self.0[j][i])
        }))
    }

    /// The cofactor of (i, j).
    fn cofactor(&self, i: usize, j: usize) -> f32 {
        let a = &self.0;
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
    }

    fn det(&self) -> f32 {
        (0..3).map(|j| self.0[0][j] * self.cofactor(0, j)).sum()
    }

    /// The inverse (the adjugate over the determinant), if the determinant is finite and
    /// not zero.
    fn inverse(&self) -> Option<M3> {
        let d = self.det();
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        Some(M3(core::array::from_fn(|i| {
            core::array::from_fn(|j| self.cofactor(j, i) / d)
        })))
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
    /// The gains of `config` at `rate_hz`; `Err(axis)` names an axis without a steady state
    /// (axis 0 also for a `disturbance_time` not finite and ≥ 0).
    pub fn new(config: &EstimatorConfig, rate_hz: u32) -> Result<Self, usize> {
        let period = 1.0 / rate_hz.max(1) as f32;
        let mut axes = [AxisGain::ZERO; 6];
        let tau_d = config.disturbance_time;
        if !(tau_d.is_finite() && tau_d >= 0.0) {
            // No filter of that time scale: the first axis has no gain.
            return Err(0);
        }
        for (i, axis) in axes.iter_mut().enumerate() {
            let (sp, sv, sa) = (
                config.position_sigma[i],
                config.velocity_sigma[i],
                config.accel_sigma[i],
            );
            let gain = if tau_d > 0.0 {
                steady_state_gain_with_disturbance(period, sp, sv, sa, tau_d)
            } else {
                steady_state_gain(period, sp, sv, sa)
            };
            *axis = gain.map_err(|_| i)?;
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

/// No period recorded yet.
const NONE: u32 = u32::MAX;

/// **Choice 499:** the estimator keeps its periods as u32 counts from an anchor period
/// (`Estimate::epoch`), below this bound: u64 arithmetic is a pair of instructions or a call
/// on the 32-bit board, and a prediction's bookkeeping is all such comparisons and
/// differences. A period 2³¹ or more past the anchor (248 days at 100 Hz) moves the anchor on
/// (`Estimate::now`).
const SPAN: u64 = 1 << 31;

/// The ring slot of period `t` (relative to the anchor, a multiple of [`HORIZON`] periods).
fn slot(t: u32) -> usize {
    (t % HORIZON as u32) as usize
}

/// A count of periods as f32 (exact below 2²⁴; a u32's conversion is one instruction on the
/// board).
fn periods(n: u32) -> f32 {
    n as f32
}

/// Sums of the accelerations applied in the periods [b, τ) of one set of running sums (base
/// b, **Choice 430**), per axis: `a` = Σ aₜ and `b` = Σ aₜ (τ − t − ½). A prediction from s
/// to τ (b ≤ s ≤ τ) adds T²·(B(τ) − B(s) − (τ − s)·A(s)) to η and T·(A(τ) − A(s)) to η̇; one
/// period on, A′ = A + a and B′ = B + A + a/2.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sums {
    a: [f32; 6],
    b: [f32; 6],
}

impl Sums {
    const ZERO: Sums = Sums {
        a: [0.0; 6],
        b: [0.0; 6],
    };
}

/// A state (η, η̇) at a period: what [`Estimate::step`] returns.
pub type StateAt = ([f32; 6], [f32; 6]);

/// A period as an [`Estimate`] counts it (`Estimate::period`, Choice 568): the tick, and
/// the tick in periods from the memory's anchor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Period {
    ticks: u64,
    now: u32,
}

/// Where a set's sums at a period are: the sums at a held period, and how many periods past
/// it (0: the sums themselves; m > 0: the last period recorded, its acceleration added, then
/// m − 1 periods without one, B′ = B + (m − 1)·A).
struct At<'a> {
    sums: &'a Sums,
    past: u32,
}

/// The board's estimator memory: the filter's state at its stamp and the accelerations
/// applied over the last [`HORIZON`] periods, as running sums. Owned by whoever flies the
/// controller ([`crate::Controller::update_from_solution`]); a new mission starts from
/// [`Estimate::new`].
///
/// **Choice 430:** a prediction is fixed O(1) work: two sets of running sums ([`Sums`]) of
/// the applied accelerations, each kept per period of the ring, give the sums over any range
/// of held periods as a difference. A running sum kept for ever would lose the small
/// difference to the large sum (and drift); each set instead starts again from exact zeros
/// every 2·[`HORIZON`] periods, the two staggered by [`HORIZON`], so that one of them always
/// starts at or before the oldest period a prediction may start from and no sum ever spans
/// more than 2·[`HORIZON`] periods: the error is that of ≤ 32 additions, for ever
/// (tests/estimator.rs flies against an f64 reference, and a day of periods opt-in).
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
    /// The disturbance acceleration d (Choice 510; zero without the state).
    disturbance: [f32; 6],
    /// The period every period below counts from (Choice 499): a multiple of [`HORIZON`],
    /// so a period's ring slot is that of its count.
    epoch: u64,
    /// The stamp, in periods from `epoch`.
    stamp: u32,
    valid: bool,
    /// The latest period recorded ([`NONE`]: none). The ring holds every period of
    /// (last − HORIZON, last], a period the board did not run as a zero acceleration.
    last: u32,
    /// The acceleration of period `last`.
    accel: [f32; 6],
    /// The period each set of sums starts from (its sums are zero there).
    base: [u32; 2],
    /// Each set's sums before period t (over [base, t)) at slot t mod HORIZON.
    before: [[Sums; 2]; HORIZON],
}

impl Default for Estimate {
    fn default() -> Self {
        Self::new()
    }
}

impl Estimate {
    /// No estimate yet: the first solution taken becomes it.
    pub const fn new() -> Self {
        Estimate {
            anchor: [0.0; 6],
            offset: [0.0; 6],
            velocity: [0.0; 6],
            disturbance: [0.0; 6],
            epoch: 0,
            stamp: 0,
            valid: false,
            last: NONE,
            accel: [0.0; 6],
            base: [0; 2],
            before: [[Sums::ZERO; 2]; HORIZON],
        }
    }

    /// Whether a solution has been taken.
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// The stamp (ticks) of the newest solution taken.
    pub fn stamp(&self) -> u64 {
        self.epoch + u64::from(self.stamp)
    }

    /// The filter's state [η, η̇] at its stamp.
    pub fn at_stamp(&self) -> ([f32; 6], [f32; 6]) {
        (
            core::array::from_fn(|i| self.anchor[i] + self.offset[i]),
            self.velocity,
        )
    }

    /// The disturbance acceleration d the filter holds (Choice 510; zero without the state).
    pub fn disturbance(&self) -> [f32; 6] {
        self.disturbance
    }

    /// Forgets everything, in place (as [`Estimate::new`]: the ring's sums are read only
    /// for periods recorded after this).
    fn reset(&mut self) {
        self.valid = false;
        self.stamp = 0;
        self.last = NONE;
        self.base = [0; 2];
    }

    /// Period `ticks` in periods from the anchor (Choice 499). Before the anchor (time went
    /// back past it), everything is forgotten and the anchor is period 0 again; 2³¹ periods or
    /// more past it, the anchor moves on by whole rings to 2³⁰ periods or so before `ticks`,
    /// and what it holds moves with it, unless some of it was more than that old (2³⁰
    /// periods, 124 days at 100 Hz: a solution not renewed for as long is forgotten, as in a
    /// new mission). Below 2³¹ periods from 0 the anchor never moves.
    #[inline]
    fn now(&mut self, ticks: u64) -> u32 {
        let d = ticks.wrapping_sub(self.epoch);
        if d < SPAN {
            return d as u32;
        }
        self.move_epoch(ticks)
    }

    /// [`Estimate::now`]'s rare case: time went back past the anchor or ran 2³¹ past it.
    #[cold]
    #[inline(never)]
    fn move_epoch(&mut self, ticks: u64) -> u32 {
        if ticks < self.epoch {
            self.reset();
            self.epoch = 0;
            if ticks < SPAN {
                return ticks as u32;
            }
        }
        let h = HORIZON as u64;
        let shift = (ticks - self.epoch - SPAN / 2) / h * h;
        let held = [
            (self.valid, self.stamp),
            (self.last != NONE, self.last),
            (self.last != NONE, self.base[0]),
            (self.last != NONE, self.base[1]),
        ];
        if held.iter().any(|&(kept, t)| kept && u64::from(t) < shift) {
            self.reset();
        } else {
            // All held periods are ≥ shift (< 2³¹), so the shift fits a u32.
            let s = shift as u32;
            if self.valid {
                self.stamp -= s;
            }
            if self.last != NONE {
                self.last -= s;
                self.base = self.base.map(|b| b - s);
            }
        }
        self.epoch += shift;
        (ticks - self.epoch) as u32
    }

    /// The oldest period the ring holds (0 before any is recorded).
    fn oldest(&self) -> u32 {
        match self.last {
            NONE => 0,
            last => (last + 1).saturating_sub(HORIZON as u32),
        }
    }

    /// Set `k`'s sums over [base, t), for t ≥ the set's base and t ≥ [`Estimate::oldest`]
    /// (zero at or before its base: nothing is counted there).
    fn at(&self, k: usize, t: u32) -> At<'_> {
        if self.last == NONE || t <= self.base[k] {
            At {
                sums: &Sums::ZERO,
                past: 0,
            }
        } else if t <= self.last {
            At {
                sums: &self.before[slot(t)][k],
                past: 0,
            }
        } else {
            At {
                sums: &self.before[slot(self.last)][k],
                past: t - self.last,
            }
        }
    }

    /// Axis `i` of the sums `at` points to: (A, B).
    fn sums_at(&self, at: &At, i: usize) -> (f32, f32) {
        let (a, b) = (at.sums.a[i], at.sums.b[i]);
        if at.past == 0 {
            return (a, b);
        }
        let a1 = a + self.accel[i];
        (a1, b + a + 0.5 * self.accel[i] + (at.past - 1) as f32 * a1)
    }

    /// The state predicted from `from` (the stamp) to `to` with the accelerations applied
    /// since and the disturbance (constant over it, Choice 510): the position as its offset
    /// from the anchor (`ANCHORED`: the position itself, the anchor added axis by axis as the
    /// loop goes, Choice 568), and the velocity. Periods older than the ring weigh zero. Fixed
    /// work (Choice 430).
    fn predicted<const ANCHORED: bool>(
        &self,
        gains: &EstimatorGains,
        from: u32,
        to: u32,
    ) -> ([f32; 6], [f32; 6]) {
        let t = gains.period;
        let dt = periods(to.saturating_sub(from)) * t;
        let lo = from.max(self.oldest());
        let hi = to.max(lo);
        let n = periods(hi - lo);
        // The set that starts latest at or before `lo` (either, when neither does: then
        // nothing was recorded before `lo` and both count from zero).
        let k = match (self.base[0] <= lo, self.base[1] <= lo) {
            (true, true) => usize::from(self.base[1] > self.base[0]),
            (false, true) => 1,
            _ => 0,
        };
        let (s, e) = (self.at(k, lo), self.at(k, hi));
        let mut p = self.offset;
        let mut v = self.velocity;
        // η += (η̇ + d·Δt/2)·Δt + T²·(B(τ) − B(s) − n·A(s)), η̇ += d·Δt + T·(A(τ) − A(s)).
        let mut advance = |i: usize, (sa, sb): (f32, f32), (ea, eb): (f32, f32)| {
            let d = self.disturbance[i];
            p[i] += (v[i] + 0.5 * d * dt) * dt + t * t * (eb - sb - n * sa);
            v[i] += d * dt + t * (ea - sa);
            if ANCHORED {
                // anchor + offset (IEEE addition commutes: the same bits).
                p[i] += self.anchor[i];
            }
        };
        if s.past > 0 && e.past > 0 {
            // Both ends past the last period recorded (the prediction to the current period
            // from a stamp after it): one set of sums, the last period's acceleration added
            // once for both (`Estimate::sums_at`'s operations, shared; Choice 568).
            let (ms, me) = (periods(s.past - 1), periods(e.past - 1));
            for i in 0..6 {
                let (a, b) = (e.sums.a[i], e.sums.b[i]);
                let a1 = a + self.accel[i];
                let c = b + a + 0.5 * self.accel[i];
                advance(i, (a1, c + ms * a1), (a1, c + me * a1));
            }
        } else {
            for i in 0..6 {
                advance(i, self.sums_at(&s, i), self.sums_at(&e, i));
            }
        }
        (p, v)
    }

    /// Period `ticks`: takes the solution `z` = (η, η̇) stamped `stamp` if it is usable
    /// (finite, not newer than `ticks`, newer than the last taken, at most [`MAX_AGE`] periods
    /// old and, after periods not run, not before the first of them: Choice 554), correcting
    /// the state at that stamp; returns the estimate (η̂, η̂̇) at `ticks`, or
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
        let period = self.period(ticks);
        self.step_in(gains, period, stamp, eta, eta_dot)
    }

    /// Period `ticks` as this memory counts it (Choice 499), for [`Estimate::step_in`] and
    /// [`Estimate::applied_in`] in the same period. **Choice 568:** the controller converts
    /// its u64 tick once a period, not once in each (the conversion may move the anchor, which
    /// nothing else does, so the count holds until the next period's).
    pub(crate) fn period(&mut self, ticks: u64) -> Period {
        Period {
            ticks,
            now: self.now(ticks),
        }
    }

    /// [`Estimate::step`] in `period` (made by [`Estimate::period`] of this memory for this
    /// period).
    #[inline]
    pub(crate) fn step_in(
        &mut self,
        gains: &EstimatorGains,
        period: Period,
        stamp: u64,
        eta: &[f32; 6],
        eta_dot: &[f32; 6],
    ) -> Option<([f32; 6], [f32; 6])> {
        let Period { ticks, now } = period;
        if self.valid && now < self.stamp {
            // Time went back: a new mission.
            self.reset();
        }
        // Choice 527: finiteness as Σ x·0 (±0 when all are finite, NaN otherwise).
        let finite = times_zero(eta) + times_zero(eta_dot) == 0.0;
        // Choice 554: only a stamp the period's record keeps (`Estimate::kept_from`): at most
        // MAX_AGE old and, after periods not run (`ticks` more than one past the last
        // recorded; never with none recorded, `last` = NONE = u32::MAX), after the last
        // recorded. The age, as u64 (the inputs), then all in periods from the anchor, which
        // is at least MAX_AGE before `now` or period 0 (Choice 499).
        let age = ticks.wrapping_sub(stamp);
        let young = age <= MAX_AGE && age as u32 <= now;
        let stamp = now.wrapping_sub(age as u32);
        let after_gap_too_old = stamp <= self.last && now.saturating_sub(1) > self.last;
        let in_window = young && !after_gap_too_old;
        if finite && in_window {
            if !self.valid {
                self.anchor = *eta;
                self.offset = [0.0; 6];
                self.velocity = *eta_dot;
                self.disturbance = [0.0; 6];
                self.stamp = stamp;
                self.valid = true;
            } else if stamp > self.stamp {
                // The prior at the stamp, its position as an offset from the old anchor.
                let (o, v) = self.predicted::<false>(gains, self.stamp, stamp);
                // Corrected in place (Choice 566), the state held for a posterior that is
                // not finite (Choice 527), which is not kept.
                let held = (self.offset, self.velocity, self.disturbance);
                let mut zero = 0.0f32;
                for i in 0..6 {
                    // z − prior = (z − anchor) − offset: near each other, so exact first.
                    let mut dz = (eta[i] - self.anchor[i]) - o[i];
                    if i == YAW {
                        dz = crate::math::wrap_pi(dz);
                    }
                    let dv = eta_dot[i] - v[i];
                    let k = &gains.axes[i].k;
                    // Posterior − z, with z the new anchor: (prior − z) + K₀·[dz, dv].
                    let offset = (k[(0, 0)] - 1.0) * dz + k[(0, 1)] * dv;
                    let vel = v[i] + k[(1, 0)] * dz + k[(1, 1)] * dv;
                    let kd = &gains.axes[i].kd;
                    let dist = self.disturbance[i] + (kd[0] * dz + kd[1] * dv);
                    // Finiteness as Σ x·0 (Choice 527) over the posterior.
                    zero += (eta[i] + offset) * 0.0 + vel * 0.0 + dist * 0.0;
                    self.offset[i] = offset;
                    self.velocity[i] = vel;
                    self.disturbance[i] = dist;
                }
                if zero == 0.0 {
                    self.anchor = *eta;
                    self.stamp = stamp;
                } else {
                    (self.offset, self.velocity, self.disturbance) = held;
                }
            }
        }
        if !self.valid {
            return None;
        }
        Some(self.predicted::<true>(gains, self.stamp, now))
    }

    /// The oldest period the record of period `ticks` keeps for a prediction to start from:
    /// the ring's oldest once `ticks` is recorded, and after periods not run (`ticks` more than
    /// one past the last recorded) not before the first of them ([`Estimate::applied`]).
    fn kept_from(&self, ticks: u32) -> u32 {
        let oldest = (ticks + 1).saturating_sub(HORIZON as u32);
        match self.last {
            NONE => oldest,
            last if ticks > last && ticks - last > 1 => (last + 1).max(oldest),
            _ => oldest,
        }
    }

    /// Records the acceleration `a` applied over period `ticks` (a non-finite one is recorded
    /// as zero: unknown). The state's stamp is first moved, predicted, to the oldest period
    /// a prediction may start from once `ticks` is recorded, so that a prediction from the
    /// stamp never loses an acceleration it used. Period `ticks` recorded again (lock-step: the
    /// board ran it once without a fresh frame, then on the frame, Choice 362) replaces its own
    /// entry: the state at the stamp does not depend on it, so the stamp stays (moved, the next
    /// solution would be refused as old). A period older than the last recorded is dropped.
    ///
    /// Fixed work (**Choice 492**): `ticks` either follows the last period recorded (every
    /// period the board flies: one period of sums) or not. Periods the board did not run
    /// between (a lock-step frame's `t_ticks` that jumps, a period given to a long job) are
    /// zero accelerations; rather than sixteen periods of sums (2 600 instructions on the
    /// target), the state's stamp moves to the first of them (one prediction, which takes in
    /// the last period recorded) and both sets of sums start afresh at `ticks`: every
    /// period before it then weighs zero, which is what the missed ones are. A solution
    /// stamped before that first missed period is then refused as not newer than the last
    /// taken.
    pub fn applied(&mut self, gains: &EstimatorGains, ticks: u64, a: &[f32; 6]) {
        let period = self.period(ticks);
        self.applied_in(gains, period, a);
    }

    /// [`Estimate::applied`] in `period` (made by [`Estimate::period`] of this memory for this
    /// period).
    pub(crate) fn applied_in(&mut self, gains: &EstimatorGains, period: Period, a: &[f32; 6]) {
        let finite = times_zero(a) == 0.0;
        let ticks = period.now;
        if self.last != NONE && ticks <= self.last {
            if ticks == self.last {
                self.accel = if finite { *a } else { [0.0; 6] };
            }
            return;
        }
        let h = HORIZON as u32;
        // Nothing recorded yet, or periods not run since the last recorded.
        let fresh = self.last == NONE || ticks - self.last > 1;
        let keep_from = self.kept_from(ticks);
        if self.valid && self.stamp < keep_from {
            let (o, v) = self.predicted::<false>(gains, self.stamp, keep_from);
            self.offset = o;
            self.velocity = v;
            self.stamp = keep_from;
        }
        let j = slot(ticks);
        if fresh {
            // Both sets start afresh here: the periods before it weigh zero (the sums are
            // zero up to their base).
            self.base = [ticks; 2];
            self.before[j] = [Sums::ZERO; 2];
        } else {
            // The set that started earlier starts again once the other is HORIZON old.
            let newer = usize::from(self.base[1] > self.base[0]);
            if ticks - self.base[newer] >= h {
                self.base[1 - newer] = ticks;
            }
            // Each set's sums before `ticks`: zero at its base, else one period on from the
            // last's (whose acceleration is `accel`).
            let p = slot(self.last);
            for k in 0..2 {
                if ticks <= self.base[k] {
                    self.before[j][k] = Sums::ZERO;
                } else {
                    for i in 0..6 {
                        let (a0, b0) = (self.before[p][k].a[i], self.before[p][k].b[i]);
                        let acc = self.accel[i];
                        self.before[j][k].a[i] = a0 + acc;
                        self.before[j][k].b[i] = b0 + a0 + 0.5 * acc;
                    }
                }
            }
        }
        self.last = ticks;
        self.accel = if finite { *a } else { [0.0; 6] };
    }
}
