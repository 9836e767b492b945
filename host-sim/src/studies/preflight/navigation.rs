//! The navigation's share of the demand (docs/real-vehicle.md#the-navigations-share,
//! **Choice 372**): the thrust the law spends on the noise of the navigation solution it is
//! told, per thruster, kept on each side of the margin envelope.
//!
//! Per controlled axis the loop is taken as the law sees it, one period T at a time: the
//! vehicle's error s = [e, ė] moves as the nominal model says, s⁺ = F s + g u
//! (F = [[1, T], [0, 1]], g = [T²/2, T]), and the law's input is u = −G ŝ with
//! G = [K₁ + (δ/μ)p₁₂, K₂ + (δ/μ)p₂₂] (Eq 25 and Δu of Eq 30 inside the boundary layer, δ at
//! its bound δ_max), ŝ being the solution as told (s + n) or the estimator's posterior
//! (x̂⁺ = (I − K)(F x̂ + g u) + K(s⁺ + n⁺), the steady-state gain K of
//! `controller_core::estimator`). With white solution noise n of covariance diag(σₚ², σᵥ²) that
//! is a linear system driven by white noise: its stationary covariance is the fixed point of
//! P = A P Aᵀ + B R Bᵀ, found by doubling, and σ_u follows. The loop being closed, noise the
//! vehicle can follow (below the loop's bandwidth) costs only the force of following it.
//! [`NOISE_SIGMAS`]·σ_u per axis (surge and sway each taking the larger of x and y) through the
//! nominal mass matrix and the allocation's B₅⁻¹, every entry at its worst sign (|M̂|, |B₅⁻¹|),
//! is a thrust per thruster.
//!
//! The noise taken per axis is the white part of the solution, the part that changes from one
//! period to the next: the fixes' and the pressure sensor's σ on the position, the INS's on the
//! attitude and the rates, the DVL's single-ping σ on the velocity, and the scenario's `[noise]`
//! on top. The biases (Gauss–Markov, random walk) move the solution slowly: the law follows
//! them as an offset of the path (the navigation's error, not a force), so they take no thrust.

use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};
use controller_core::estimator::EstimatorKind;
use controller_core::thruster::ThrustEnvelope;
use nalgebra::{Matrix2, Vector6};
use serde::{Deserialize, Serialize};

use crate::scenario::Scenario;

/// The noise force the margin keeps, in standard deviations of the noise.
pub const NOISE_SIGMAS: f64 = 3.0;
/// Doubling steps of the covariance's fixed point: Σₖ Aᵏ S Aᵀᵏ summed over 2⁶⁴ periods.
const DOUBLING_STEPS: usize = 64;
/// The velocity noise σ the "needs" statement searches up to (m/s).
const MAX_VELOCITY_SIGMA: f64 = 1.0;

/// What the check assumed of the navigation, and what the mission needs of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NavigationShare {
    /// The navigation assumed: the preset (`ideal`: the exact state), `+ [noise]` when the
    /// scenario adds white noise on top.
    pub assumed: String,
    /// Whether the law flies on the estimator's estimate (`controller.estimator`).
    pub estimator: bool,
    /// The solution's white noise per period taken, per axis of η (m, rad).
    pub position_sigma: [f64; 6],
    /// … and on η̇ (m/s, rad/s).
    pub velocity_sigma: [f64; 6],
    /// Per thruster (in the order of `THRUSTER_NAMES`), the thrust kept for the noise on each
    /// side of the margin envelope (N).
    pub thrust: [f64; THRUSTERS],
    /// The largest velocity noise σ (m/s, x y z alike) at which the mission as written still
    /// fits the margin at the time scale checked; `None` when it does not fit even on the exact
    /// state (or fits beyond 1 m/s: no velocity noise a navigation has matters).
    pub needs_velocity_sigma: Option<f64>,
}

impl NavigationShare {
    /// One line for `check`: the navigation assumed, what it costs, what the mission needs.
    pub fn describe(&self) -> String {
        if self.thrust.iter().all(|&x| x == 0.0) {
            return format!("navigation assumed: {} (no noise force)", self.assumed);
        }
        let (worst, n) = self
            .thrust
            .iter()
            .enumerate()
            .fold((0, 0.0f64), |a, (i, &x)| if x > a.1 { (i, x) } else { a });
        let mut s = format!(
            "navigation assumed: {}{} — keeps up to {n:.1} N of {}'s envelope for its noise ({NOISE_SIGMAS}σ)",
            self.assumed,
            if self.estimator { ", filtered by the estimator" } else { ", flown as told" },
            THRUSTER_NAMES[worst],
        );
        let v = self.velocity_sigma[0].max(self.velocity_sigma[1]);
        match self.needs_velocity_sigma {
            Some(x) => s.push_str(&format!(
                "; needs velocity noise ≤ {x:.4} m/s at this speed (assumed {v:.4} m/s)"
            )),
            None => s.push_str("; no velocity noise fits the margin at this speed"),
        }
        s
    }
}

/// The solution's white noise per period the check takes (see the module docs): position and
/// velocity σ per axis of η.
fn solution_noise(scenario: &Scenario) -> ([f64; 6], [f64; 6]) {
    let cfg = scenario.config();
    let mut p = [0.0; 6];
    let mut v = [0.0; 6];
    if let Some(m) = &cfg.navigation {
        if let Some(f) = &m.fix {
            p[0] = f.error.sigma[0];
            p[1] = f.error.sigma[1];
        }
        p[2] = m.depth.error.sigma[0];
        p[3..6].copy_from_slice(&m.ins.attitude.sigma);
        // The DVL measures in the body frame: either horizontal axis of η may carry surge's
        // or sway's noise.
        let s = &m.dvl.velocity.sigma;
        v[0] = s[0].max(s[1]);
        v[1] = v[0];
        v[2] = s[2];
        v[3..6].copy_from_slice(&m.ins.rates.sigma);
    }
    if let Some(n) = &cfg.noise {
        for i in 0..6 {
            p[i] = p[i].hypot(n.eta_sigma[i]);
            v[i] = v[i].hypot(n.nu_sigma[i]);
        }
    }
    (p, v)
}

/// The standard deviation of the law's input u on one axis (m/s², rad/s²) under solution
/// noise (σₚ, σᵥ), the loop closed (module docs): the vehicle's error s = [e, ė] over one
/// period, s⁺ = F s + g u, with u = −G ŝ, G = [K₁ + r p₁₂, K₂ + r p₂₂], and ŝ the solution as
/// told (s + n) or the estimator's posterior (x̂⁺ = (I − K)(F x̂ + g u) + K(s⁺ + n⁺)). The
/// stationary covariance of that linear system is its Lyapunov fixed point, found by
/// doubling; `None` when the loop is not stable at this gain.
fn input_sigma(scenario: &Scenario, axis: usize, gain: [f64; 2], sp: f64, sv: f64) -> Option<f64> {
    let c = &scenario.config().controller;
    let t = 1.0 / f64::from(c.rate_hz);
    let r = nalgebra::Matrix2::new(sp * sp, 0.0, 0.0, sv * sv);
    let f = Matrix2::new(1.0, t, 0.0, 1.0);
    let g = nalgebra::Vector2::new(0.5 * t * t, t);
    let gr = nalgebra::RowVector2::new(gain[0], gain[1]);
    let fix = |mut a: nalgebra::DMatrix<f64>, mut p: nalgebra::DMatrix<f64>| {
        for _ in 0..DOUBLING_STEPS {
            p += &a * &p * a.transpose();
            a = &a * &a;
            if !p.iter().all(|x| x.is_finite()) {
                return None;
            }
        }
        // A stable loop's Aⁿ has vanished.
        (a.amax() < 1e-9).then_some(p)
    };
    let dm = |m: &Matrix2<f64>| nalgebra::DMatrix::from_column_slice(2, 2, m.as_slice());
    if c.estimator.kind == EstimatorKind::Off {
        let a = f - g * gr;
        let b = g * gr;
        let p = fix(dm(&a), dm(&(b * r * b.transpose())))?;
        let pg = dm(&Matrix2::zeros()) + p;
        let var = (gr * Matrix2::from_iterator(pg.iter().copied()) * gr.transpose())[(0, 0)]
            + (gr * r * gr.transpose())[(0, 0)];
        return Some(var.max(0.0).sqrt());
    }
    let gain_k = super::path_budget::board_gain(&c.estimator, c.rate_hz, axis)?;
    let k = gain_k.k.cast::<f64>();
    let kd = nalgebra::RowVector2::new(f64::from(gain_k.kd[0]), f64::from(gain_k.kd[1]));
    // X = [s; x̂; d̂]: X⁺ = A X + B n⁺ (Choice 512: the prior x̂⁻ = (F − gG)x̂ + g d̂, the
    // innovation ν = s⁺ + n⁺ − x̂⁻, x̂⁺ = x̂⁻ + Kν, d̂⁺ = d̂ + kd·ν).
    let mut next = nalgebra::SMatrix::<f64, 2, 5>::zeros();
    next.fixed_view_mut::<2, 2>(0, 0).copy_from(&f);
    next.fixed_view_mut::<2, 2>(0, 2).copy_from(&(-(g * gr)));
    let mut prior = nalgebra::SMatrix::<f64, 2, 5>::zeros();
    prior.fixed_view_mut::<2, 2>(0, 2).copy_from(&(f - g * gr));
    prior.fixed_view_mut::<2, 1>(0, 4).copy_from(&g);
    let innovation = next - prior;
    let mut a = nalgebra::DMatrix::<f64>::zeros(5, 5);
    a.view_mut((0, 0), (2, 5)).copy_from(&next);
    a.view_mut((2, 0), (2, 5))
        .copy_from(&(prior + k * innovation));
    a.view_mut((4, 0), (1, 5)).copy_from(&(kd * innovation));
    a[(4, 4)] += 1.0;
    let mut b = nalgebra::DMatrix::<f64>::zeros(5, 2);
    b.view_mut((2, 0), (2, 2)).copy_from(&k);
    b.view_mut((4, 0), (1, 2)).copy_from(&kd);
    let rd = dm(&r);
    let p = fix(a, &b * rd * b.transpose())?;
    let mut cu = nalgebra::DMatrix::<f64>::zeros(1, 5);
    cu[(0, 2)] = -gain[0];
    cu[(0, 3)] = -gain[1];
    let var = (&cu * p * cu.transpose())[(0, 0)];
    Some(var.max(0.0).sqrt())
}

/// The thrust per thruster the law spends on solution noise (σₚ, σᵥ per axis).
fn noise_thrust(scenario: &Scenario, sp: &[f64; 6], sv: &[f64; 6]) -> [f64; THRUSTERS] {
    let controller = scenario.controller();
    let c = controller.config();
    let lyap = controller.lyapunov();
    // Inside the boundary layer Δu is the gain δ/μ on w, δ at most δ_max.
    let robust_gain = match (c.robust, c.law) {
        (false, _) => 0.0,
        (true, _) => f64::from(c.delta_max / c.mu),
    };
    let sigma_u = Vector6::from_fn(|i, _| {
        // No noise, or an axis the law does not control (roll: K₁ = K₂ = 0).
        if (sp[i] == 0.0 && sv[i] == 0.0) || (c.k1[i] == 0.0 && c.k2[i] == 0.0) {
            return 0.0;
        }
        let gain = [
            f64::from(c.k1[i]) + robust_gain * f64::from(lyap[i].p12),
            f64::from(c.k2[i]) + robust_gain * f64::from(lyap[i].p22),
        ];
        // An unstable sampled loop (which the configuration's loop-rate rule refuses) keeps
        // the whole envelope.
        NOISE_SIGMAS * input_sigma(scenario, i, gain, sp[i], sv[i]).unwrap_or(f64::INFINITY)
    });
    // The body frame: surge and sway may each carry either horizontal axis's noise.
    let mut body = sigma_u;
    body[0] = sigma_u[0].max(sigma_u[1]);
    body[1] = body[0];
    let m = controller.mass_matrix().cast::<f64>().abs();
    let tau = m * body;
    let alloc = controller.allocation();
    let mut out = [0.0; THRUSTERS];
    for axis in 0..6 {
        let mut unit = Vector6::<f32>::zeros();
        unit[axis] = 1.0;
        let column = alloc.thrusts(&unit);
        for (o, b) in out.iter_mut().zip(column) {
            *o += f64::from(b).abs() * tau[axis];
        }
    }
    out
}

/// The navigation's share for `scenario` (module docs); `peaks` (per thruster the reference's
/// smallest and largest demand, N) and `margin_envelope` give what the mission needs of it.
pub fn share(
    scenario: &Scenario,
    peaks: Option<(&[(f64, f64); THRUSTERS], &ThrustEnvelope)>,
) -> NavigationShare {
    let cfg = scenario.config();
    let (sp, sv) = solution_noise(scenario);
    let thrust = noise_thrust(scenario, &sp, &sv);
    let preset = cfg.navigation.as_ref().map_or("ideal", |m| m.preset.name());
    let assumed = match cfg.noise {
        Some(_) => format!("{preset} + [noise]"),
        None => preset.to_string(),
    };
    let needs_velocity_sigma = peaks.and_then(|(peaks, env)| {
        let fits = |x: f64| {
            let v = [x, x, x, sv[3], sv[4], sv[5]];
            let n = noise_thrust(scenario, &sp, &v);
            (0..THRUSTERS).all(|i| {
                let (lo, hi) = (f64::from(env.min[i]), f64::from(env.max[i]));
                peaks[i].1 + n[i] <= hi && peaks[i].0 - n[i] >= lo
            })
        };
        if !fits(0.0) || fits(MAX_VELOCITY_SIGMA) {
            return None;
        }
        let (mut lo, mut hi) = (0.0, MAX_VELOCITY_SIGMA);
        while hi - lo > 1e-5 {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(lo)
    });
    NavigationShare {
        assumed,
        estimator: cfg.controller.estimator.kind != EstimatorKind::Off,
        position_sigma: sp,
        velocity_sigma: sv,
        thrust,
        needs_velocity_sigma,
    }
}

/// The margin envelope with `thrust` kept on each side of every thruster (the one hook into
/// the check's sweep). A side the noise eats entirely is left a zero-width sliver at 0 N: any
/// demand there is a violation.
pub fn keep(envelope: ThrustEnvelope, thrust: &[f64; THRUSTERS]) -> ThrustEnvelope {
    let mut e = envelope;
    for (i, &t) in thrust.iter().enumerate() {
        if t == 0.0 {
            continue;
        }
        let n = t as f32;
        e.min[i] = (e.min[i] + n).min(0.0);
        e.max[i] = (e.max[i] - n).max(0.0);
        if e.max[i] <= e.min[i] {
            e.max[i] = e.min[i] + f32::EPSILON;
        }
    }
    e
}
