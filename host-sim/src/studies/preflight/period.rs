//! A periodic mission is checked over one period (docs/real-vehicle.md#how-the-check-is-made,
//! **Choice 393**): when nothing the check evaluates changes with time but the reference, and
//! the reference repeats — a circle (period 2π/ω) or a figure-eight (4π/ω: y_d has the half
//! phase), held at its depth — every later period asks the thrusters for what the first asks,
//! so the check samples the path over the first period only (at its 20 Hz, and the first
//! sample of the next). A day-long circle is then ~1 300 samples, not 1.7·10⁶.
//!
//! What must not change with time: the payload (no variation, or a constant one) — the
//! current is always taken constant (its value, or the corners of a Gauss–Markov current's
//! ±3σ). The positions x_d, y_d, z_d do not enter the force (Eq 1 depends on the attitude,
//! the velocities and the accelerations only).
//!
//! Not bit for bit the exhaustive sweep: a later period's samples fall on other phases of the
//! path, between the first period's, 0.05 s apart like every sample of the check. Over the
//! contract's missions (tests/preflight_engines.rs) the verdicts and proposed scales are the
//! same.
//!
//! **Long missions** (**Choice 538**): a periodic path flown for at least [`LONG_PERIODS`]
//! periods with a payload that varies is reduced too, so that its check costs what
//! [`WINDOW_PERIODS`] periods cost, whatever its length:
//!
//! - a **staircase** holds its last row after its last step t_N (the end of the row before it;
//!   real time, at most t_N of path time at any scale k ≥ 1): from then on the mission repeats like a constant one, so the
//!   force is checked over the path up to t_N + P (Eq 1 as written before, one period after);
//! - an **abs-sin** payload Δp(t) = s(t)·Δp_max, s = |sin ω_p t| ∈ [0, 1], of period π/ω_p
//!   incommensurate with the path's: over a long mission (path phase φ, payload level s) fills
//!   the torus [0, P) × [0, 1], so the force is checked over one period of the path at each of
//!   [`LEVELS`] constant levels s = 0, ¼, ½, ¾, 1, every one with the largest roll swing the
//!   payload can drive ([`swing_bound`]). At a fixed attitude Eq (1) is affine in Δp (M, C, g
//!   are linear in the mass, the CG and the inertia), so the demand at any s lies between its
//!   values at s = 0 and s = 1 (Eq L1); the heel, the trim and the swing bend it slightly,
//!   which the three inner levels catch. A superset of every time of the mission (tight when the
//!   periods are incommensurate); a violation's time is that of its path phase in the first
//!   period, and the payload there is the level's, not the one the mission flies at that time.
//!
//! Short missions (the contract's: one to three periods) keep the sweep of the payload as
//! written, so their verdicts do not move. The chatter term and the path budget of a long mission
//! ([`Reduction::window`], **Choice 539**) fly the first whole periods past the staircase's last
//! step that last [`WINDOW`] s, and extrapolate the rest at the window's mean (Eq L2).

use controller_core::model::ParamVariation;
use controller_core::TrajectoryKind;

use crate::plant::VariationProfile;
use crate::scenario::SimConfig;

/// A mission at least this many path periods long, with a varying payload, is reduced
/// (Choice 538).
pub const LONG_PERIODS: f64 = 10.0;
/// The payload levels of an abs-sin mission's torus: s = i/(LEVELS − 1).
pub const LEVELS: usize = 5;
/// The least real time (s) a long mission's chatter term and path budget fly before they
/// extrapolate, in whole path periods (Choice 539).
pub const WINDOW: f64 = 900.0;

/// How a periodic mission is checked (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Reduction {
    /// Path time (s, at k = 1) from which the reference and the payload repeat with `period`.
    pub from: f64,
    /// The path's period (s of path time, at k = 1).
    pub period: f64,
    /// The mission is at least [`LONG_PERIODS`] periods long (the terms fly a window).
    pub long: bool,
    /// An abs-sin payload's torus: the constant levels checked at every phase, and the
    /// payload's period (s, real time). `None`: the payload as written.
    pub levels: Option<(Vec<ParamVariation<f64>>, f64)>,
}

impl Reduction {
    /// The path time the force check samples (s, at k = 1): up to the first repetition.
    pub fn checked(&self) -> f64 {
        self.from + self.period
    }

    /// The path time a long mission's chatter term and budget fly at time scale `k` (s, at
    /// k = 1): from [`Reduction::from`], the fewest whole periods that last at least
    /// [`WINDOW`] s (at least one). The longest at k = 1, the fastest scale the check tries.
    pub fn window(&self, k: f64) -> f64 {
        let periods = (WINDOW / (self.period * k.max(1.0))).ceil().max(1.0);
        self.from + periods * self.period
    }

    /// The path time the terms (chatter, budget) sample the reference over (s, at k = 1): to
    /// the first repetition, or a torus's window (its payload does not repeat).
    pub fn reference_span(&self) -> f64 {
        match (self.long, &self.levels) {
            (true, Some(_)) => self.window(1.0),
            _ => self.checked(),
        }
    }

    /// Path time `s` folded onto the checked span: itself before [`Reduction::from`], then
    /// `from + (s − from) mod P` (for `from` = 0, `s mod P`, as Choice 393 always did).
    /// Meaningless for a torus (its payload does not repeat): `s` itself.
    pub fn fold(&self, s: f64) -> f64 {
        if self.levels.is_some() || s < self.from {
            s
        } else {
            self.from + (s - self.from) % self.period
        }
    }
}

/// The path's period (s of path time, at time scale 1), if it repeats.
fn path_period(cfg: &SimConfig) -> Option<f64> {
    let tau = std::f64::consts::TAU;
    let p = match cfg.trajectory {
        TrajectoryKind::Circle(c) => tau / f64::from(c.omega),
        TrajectoryKind::FigureEight(f) => 2.0 * tau / f64::from(f.omega),
        _ => return None,
    };
    (p.is_finite() && p > 0.0).then_some(p)
}

/// The period (s of path time, at time scale 1) after which every input of the check repeats,
/// if there is one (a constant payload: see the module docs).
pub fn period(cfg: &SimConfig) -> Option<f64> {
    reduction(cfg)
        .filter(|r| r.from == 0.0 && r.levels.is_none())
        .map(|r| r.period)
}

/// How the check reduces `cfg`'s mission, if it does (see the module docs).
pub fn reduction(cfg: &SimConfig) -> Option<Reduction> {
    let period = path_period(cfg)?;
    let k = super::time_scale(cfg.time_scale);
    let span = cfg.duration / k;
    let long = span >= LONG_PERIODS * period;
    let repeat = |from: f64| Reduction {
        from,
        period,
        long,
        levels: None,
    };
    match &cfg.variation {
        VariationProfile::None | VariationProfile::Constant(_) => Some(repeat(0.0)),
        VariationProfile::Staircase(steps) if long => {
            // The payload is the last row's after the step before it ends (the last row's own
            // `until` is the end of time), in path time at the fastest scale tried (k ≥ 1).
            let n = steps.len().saturating_sub(1);
            let last = steps[..n].iter().map(|s| s.0).fold(0.0, f64::max) / k.min(1.0);
            (last.is_finite() && last + period < span).then(|| repeat(last))
        }
        VariationProfile::AbsSin { max, omega } if long && omega.abs() > 0.0 => {
            let payload_period = std::f64::consts::PI / omega.abs();
            let levels = (0..LEVELS)
                .map(|i| max.scaled(i as f64 / (LEVELS - 1) as f64))
                .collect();
            payload_period.is_finite().then_some(Reduction {
                from: 0.0,
                period,
                long,
                levels: Some((levels, payload_period)),
            })
        }
        _ => None,
    }
}

/// The largest amplitude the undamped roll swing φ̈ = −ω² (φ − φ_eq(t)) ever reaches when its
/// equilibrium repeats with `period` (s), from `start` (as
/// [`super::attitude::swing_amplitudes`]: the level start's 0, or none from trim). With the
/// phase vector z = (φ − φ_eq) + i φ̇/ω, one period maps zₙ ↦ zₙ₊₁ = R zₙ + c (R = e^{−iωT},
/// c the response from rest), so zₙ circles z* = c/(1 − R) at the radius ρ = |z₀ − z*|, and
/// inside a period z(nT + τ) = R(τ) zₙ + c(τ): the amplitude never exceeds
/// maxτ |R(τ) z* + c(τ)| + ρ (Eq L3; reached as n grows when ωT/2π is irrational). `None`
/// at resonance (|1 − R| < 10⁻⁶: the swing grows without bound).
pub fn swing_bound(
    omega: f64,
    start: Option<f64>,
    equilibrium: &dyn Fn(f64) -> f64,
    period: f64,
) -> Option<f64> {
    /// Longest step of the phase rotation (s), as the swing's own.
    const DT: f64 = 0.01;
    let steps = (period / DT).ceil().max(1.0) as usize;
    let h = period / steps as f64;
    let eq0 = equilibrium(0.0);
    let rotate = |(re, im): (f64, f64), angle: f64| {
        let (s, c) = angle.sin_cos();
        (re * c + im * s, im * c - re * s)
    };
    // c(τ): the response from z = 0 at each step of one period.
    let mut c = Vec::with_capacity(steps + 1);
    let (mut z, mut eq) = ((0.0, 0.0), eq0);
    c.push(z);
    for i in 1..=steps {
        z = rotate(z, omega * h);
        let next = equilibrium(i as f64 * h);
        z.0 -= next - eq;
        eq = next;
        c.push(z);
    }
    // R = e^{−iωT}; z* = c(T)/(1 − R).
    let (rs, rc) = (omega * period).sin_cos();
    let (dre, dim) = (1.0 - rc, rs);
    let den = dre * dre + dim * dim;
    if den.sqrt() < 1e-6 {
        return None;
    }
    let (cre, cim) = z;
    let star = ((cre * dre + cim * dim) / den, (cim * dre - cre * dim) / den);
    let z0 = (start.map_or(0.0, |s| s - eq0), 0.0);
    let rho = (z0.0 - star.0).hypot(z0.1 - star.1);
    let mut worst = 0.0f64;
    for (i, ci) in c.iter().enumerate() {
        let r = rotate(star, omega * h * i as f64);
        worst = worst.max((r.0 + ci.0).hypot(r.1 + ci.1));
    }
    Some(worst + rho)
}
