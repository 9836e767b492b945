//! The navigation computer of a `[navigation]` model (docs/navigation.md#the-solution): its
//! sources sample the plant's true state on the control periods at their own rates, each
//! sample enters the solution its latency later, and the solution the law is told each period
//! is, as a DVL-aided INS forms it (**Choice 332**):
//!
//! - attitude and rates: the last INS sample (truth at its time + its error); the solution
//!   holds at that sample's time ([`Solution::held_at`]);
//! - velocity: the truth at the same time plus the velocity error e_v, which each DVL ping with
//!   bottom lock resets to that ping's error and which, between pings and while the bottom is
//!   lost, integrates the INS's acceleration error (ė_v = b_a + w_a: the drift);
//! - position: dead reckoning (the trapezoid rule on R(Θ)·v of the solution, Fossen's Eq 2.18
//!   kinematics), shifted by each position fix (x, y) and each pressure depth (z) so that the
//!   solution passes through the measurement at its time: smooth and drifting in between, a
//!   jump at a fix.
//!
//! Everything is f64 and deterministic: each source draws from its own generator, seeded from
//! the model's seed and the source, so changing one source does not change another's noise.
//! How the errors are drawn is the scenario's `noise_draws` ([`NoiseDraws`]): every bias
//! stepped every period from ChaCha12 (the default), or each error drawn only when its source
//! samples, from Xoshiro256++ (study-grade flight).

use std::collections::VecDeque;

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::scenario::navigation::{ErrorModel, NavigationModel, Timing};

pub use crate::scenario::navigation::NoiseDraws;

/// A seeded generator of standard normals (the ziggurat of `rand_distr`) of a [`NoiseDraws`]
/// scheme: ChaCha12 (`StdRng`) or Xoshiro256++ (about a fifth of ChaCha12's cost a draw).
#[derive(Debug)]
pub enum Normals {
    /// Boxed: its 320 bytes of state would size every generator.
    ChaCha(Box<StdRng>),
    Xoshiro(Xoshiro256PlusPlus),
}

impl Normals {
    /// The generator of `draws` seeded from `seed`.
    pub fn new(draws: NoiseDraws, seed: u64) -> Self {
        match draws {
            NoiseDraws::EveryPeriod => Normals::ChaCha(Box::new(StdRng::seed_from_u64(seed))),
            NoiseDraws::AtSamples => Normals::Xoshiro(Xoshiro256PlusPlus::seed_from_u64(seed)),
        }
    }

    /// The next standard normal.
    #[inline]
    pub fn normal(&mut self) -> f64 {
        match self {
            Normals::ChaCha(r) => StandardNormal.sample(r.as_mut()),
            Normals::Xoshiro(r) => StandardNormal.sample(r),
        }
    }
}

/// What the navigation computer reports for one control period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution {
    /// η (x y z m, φ θ ψ rad) and ν (u v w m/s, p q r rad/s), f64.
    pub eta: [f64; 6],
    pub nu: [f64; 6],
    /// The control tick the solution holds at: its last INS sample's time. The state frame's
    /// `t_ticks` stays the period it is reported at (**Choice 334**,
    /// docs/navigation.md#stamps-and-latency).
    pub held_at: u64,
    /// The sample tick of the DVL ping the velocity was last reset to, if any yet.
    pub velocity_at: Option<u64>,
    /// The DVL had bottom lock at its last ping.
    pub bottom_lock: bool,
    /// The sample tick of the last position fix applied, if any.
    pub fix_at: Option<u64>,
    /// The measurements that reached the computer this period.
    pub arrived: Arrivals,
}

/// The measurements that reached the navigation computer in one control period, at most one
/// per source (none between a source's samples, in its outages, or before its latency has
/// passed): each source at its own rate, as the flight log's navigation channels show them
/// (**Choice 381**, docs/logs.md#channels).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Arrivals {
    /// Attitude (φ θ ψ rad) and rates (p q r rad/s) as the INS measured them.
    pub ins: Option<Measured<6>>,
    /// A DVL ping: its velocity over the bottom (u v w m/s) when it had bottom lock.
    pub dvl: Option<Ping>,
    /// The pressure depth (z m).
    pub depth: Option<Measured<1>>,
    /// A position fix (x y m).
    pub fix: Option<Measured<2>>,
}

/// A source's measurement and the control tick it was sampled at (it arrives its latency
/// later).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured<const N: usize> {
    pub sampled_at: u64,
    pub value: [f64; N],
}

/// A DVL ping: with bottom lock, the velocity it measured; without, none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ping {
    pub sampled_at: u64,
    pub velocity: Option<[f64; 3]>,
}

/// A source's error process: its generator and its bias's current value.
struct Stream<const N: usize> {
    model: ErrorModel<N>,
    rng: Normals,
    /// [`NoiseDraws::AtSamples`]: no normal is drawn for a zero σ.
    sparse: bool,
    /// The control tick the bias was last stepped to ([`Stream::advance_to`]).
    at: u64,
    gm: [f64; N],
    walk: [f64; N],
    /// The step [`Stream::advance`] formed its factors for, and the factors: e^(−dt/τ),
    /// σ_b·√(1 − a²) and σ_w·√dt per axis (**Choice 462**: formed once per run, the loop steps
    /// with one dt; the same products as before, so the same bits).
    step: Option<(f64, f64, [f64; N], [f64; N])>,
}

impl<const N: usize> Stream<N> {
    fn new(model: ErrorModel<N>, seed: u64, source: u64, draws: NoiseDraws) -> Self {
        // Distinct streams per source (a golden-ratio step between their seeds).
        let mut rng = Normals::new(
            draws,
            seed.wrapping_add(source.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        );
        let sparse = draws == NoiseDraws::AtSamples;
        let mut gm = [0.0; N];
        for (g, s) in gm.iter_mut().zip(model.bias_sigma) {
            if !(sparse && s == 0.0) {
                *g = s * rng.normal();
            }
        }
        Stream {
            model,
            rng,
            sparse,
            at: 0,
            gm,
            walk: [0.0; N],
            step: None,
        }
    }

    /// Advances the bias by `dt`: the Gauss–Markov part exactly (its discrete form keeps the
    /// steady σ), the walk by σ_w·√dt.
    fn advance(&mut self, dt: f64) {
        let (a, sb, sw) = match self.step {
            Some((h, a, sb, sw)) if h == dt => (a, sb, sw),
            _ => {
                let a = (-dt / self.model.bias_tau).exp();
                let b = (1.0 - a * a).sqrt();
                let sb = self.model.bias_sigma.map(|s| s * b);
                let sw = self.model.bias_walk.map(|w| w * dt.sqrt());
                self.step = Some((dt, a, sb, sw));
                (a, sb, sw)
            }
        };
        if self.sparse {
            for i in 0..N {
                self.gm[i] *= a;
                if sb[i] != 0.0 {
                    self.gm[i] += sb[i] * self.rng.normal();
                }
                if sw[i] != 0.0 {
                    self.walk[i] += sw[i] * self.rng.normal();
                }
            }
            return;
        }
        for i in 0..N {
            let n1 = self.rng.normal();
            let n2 = self.rng.normal();
            self.gm[i] = a * self.gm[i] + sb[i] * n1;
            self.walk[i] += sw[i] * n2;
        }
    }

    /// [`NoiseDraws::AtSamples`]: steps the bias from its last tick to tick `k` in one step of
    /// (k − last)·dt (Eq N1), nothing if it is there.
    fn advance_to(&mut self, k: u64, dt: f64) {
        let n = k.saturating_sub(self.at);
        if n > 0 {
            self.at = k;
            self.advance(n as f64 * dt);
        }
    }

    /// One sample's error: the bias plus white noise.
    fn sample(&mut self) -> [f64; N] {
        let mut e = [0.0; N];
        for (i, e) in e.iter_mut().enumerate() {
            let s = self.model.sigma[i];
            let white = if self.sparse && s == 0.0 {
                0.0
            } else {
                s * self.rng.normal()
            };
            *e = self.model.bias[i] + self.gm[i] + self.walk[i] + white;
        }
        e
    }
}

/// When a source's samples are taken and arrive, on control ticks (**Choice 335**,
/// docs/navigation.md#the-sources).
struct Clock {
    /// Samples per control period (≥ 1: every period).
    ratio: f64,
    latency: u64,
    /// Outages in ticks [from, to).
    outages: Vec<[f64; 2]>,
    rate_hz: f64,
}

impl Clock {
    fn new(t: &Timing, rate_hz: f64) -> Self {
        Clock {
            ratio: t.rate_hz / rate_hz,
            latency: latency_ticks(t.latency, rate_hz),
            outages: t.outages.clone(),
            rate_hz,
        }
    }

    /// The sample tick whose sample arrives at tick `k`, if one does (a sample is taken on the
    /// first period and whenever ⌊j·rate/rate_c⌋ steps; none in an outage).
    fn arrival(&self, k: u64) -> Option<u64> {
        let j = k.checked_sub(self.latency)?;
        let taken = self.ratio >= 1.0
            || j == 0
            || whole(j as f64 * self.ratio) != whole((j - 1) as f64 * self.ratio);
        if !taken {
            return None;
        }
        let t = j as f64 / self.rate_hz;
        let out = self.outages.iter().any(|[a, b]| *a <= t && t < *b);
        (!out).then_some(j)
    }
}

/// ⌊x⌋ of a sample count 0 ≤ x < 2⁶³ as an integer (**Choice 540**): the conversion truncates,
/// which for x ≥ 0 is the floor, so the ticks are `f64::floor`'s, without its library call on
/// a baseline x86-64 (and the signed conversion is one instruction there, the unsigned a few).
fn whole(x: f64) -> i64 {
    x as i64
}

/// A latency in whole control periods (rounded to the nearest).
pub fn latency_ticks(latency: f64, rate_hz: f64) -> u64 {
    (latency * rate_hz).round() as u64
}

/// A ring of the last values per tick.
struct History<T: Copy> {
    first: u64,
    values: VecDeque<T>,
    keep: usize,
}

impl<T: Copy> History<T> {
    fn new(keep: usize) -> Self {
        History {
            first: 0,
            values: VecDeque::with_capacity(keep + 1),
            keep: keep.max(1),
        }
    }

    fn push(&mut self, v: T) {
        self.values.push_back(v);
        if self.values.len() > self.keep {
            self.values.pop_front();
            self.first += 1;
        }
    }

    /// The value at tick `k` (the oldest kept before it, the newest after it).
    fn at(&self, k: u64) -> T {
        let i = k.saturating_sub(self.first) as usize;
        self.values[i.min(self.values.len() - 1)]
    }
}

/// Body-to-NED rotation of (φ, θ, ψ) applied to v (Fossen's R(Θ), zyx).
fn rotate(att: &[f64; 3], v: &[f64; 3]) -> [f64; 3] {
    let (sf, cf) = att[0].sin_cos();
    let (st, ct) = att[1].sin_cos();
    let (sp, cp) = att[2].sin_cos();
    [
        cp * ct * v[0] + (-sp * cf + cp * st * sf) * v[1] + (sp * sf + cp * cf * st) * v[2],
        sp * ct * v[0] + (cp * cf + sf * st * sp) * v[1] + (-cp * sf + st * sp * cf) * v[2],
        -st * v[0] + ct * sf * v[1] + ct * cf * v[2],
    ]
}

/// The navigation computer of one run.
pub struct NavComputer {
    model: NavigationModel,
    /// [`NoiseDraws::AtSamples`]: each stream is stepped when its source samples.
    at_samples: bool,
    dt: f64,
    k: u64,
    ins: (Clock, Stream<3>, Stream<3>),
    accel: Stream<3>,
    dvl: (Clock, Stream<3>),
    depth: (Clock, Stream<1>),
    fix: Option<(Clock, Stream<2>)>,
    truth: History<([f64; 6], [f64; 6])>,
    /// The dead-reckoned position per report tick.
    dr: History<[f64; 3]>,
    att: [f64; 3],
    rates: [f64; 3],
    e_v: [f64; 3],
    offset: [f64; 3],
    last_rv: [f64; 3],
    out: Solution,
}

impl NavComputer {
    /// The computer of `model` on a control loop at `rate_hz`, its errors drawn every period
    /// ([`NoiseDraws::EveryPeriod`]).
    pub fn new(model: &NavigationModel, rate_hz: f64) -> Self {
        Self::with_draws(model, rate_hz, NoiseDraws::EveryPeriod)
    }

    /// The computer of `model` on a control loop at `rate_hz`, its errors drawn as `draws`
    /// says.
    pub fn with_draws(model: &NavigationModel, rate_hz: f64, draws: NoiseDraws) -> Self {
        let seed = model.seed;
        let ins = Clock::new(&model.ins.timing, rate_hz);
        let dvl = Clock::new(&model.dvl.timing, rate_hz);
        let depth = Clock::new(&model.depth.timing, rate_hz);
        let fix = model.fix.as_ref().map(|f| {
            (
                Clock::new(&f.timing, rate_hz),
                Stream::new(f.error, seed, 6, draws),
            )
        });
        let longest = [&ins, &dvl, &depth]
            .into_iter()
            .chain(fix.as_ref().map(|f| &f.0))
            .map(|c| c.latency)
            .max()
            .unwrap_or(0);
        let keep = (longest + ins.latency + 2) as usize;
        NavComputer {
            at_samples: draws == NoiseDraws::AtSamples,
            dt: 1.0 / rate_hz,
            k: 0,
            ins: (
                ins,
                Stream::new(model.ins.attitude, seed, 1, draws),
                Stream::new(model.ins.rates, seed, 2, draws),
            ),
            accel: Stream::new(model.ins.accel, seed, 3, draws),
            dvl: (dvl, Stream::new(model.dvl.velocity, seed, 4, draws)),
            depth: (depth, Stream::new(model.depth.error, seed, 5, draws)),
            fix,
            truth: History::new(keep),
            dr: History::new(keep),
            att: [0.0; 3],
            rates: [0.0; 3],
            e_v: [0.0; 3],
            offset: [0.0; 3],
            last_rv: [0.0; 3],
            out: Solution {
                eta: [0.0; 6],
                nu: [0.0; 6],
                held_at: 0,
                velocity_at: None,
                bottom_lock: false,
                fix_at: None,
                arrived: Arrivals::default(),
            },
            model: model.clone(),
        }
    }

    /// Whether the DVL has bottom lock at the true depth `z` and sample tick `j`.
    fn lock(&self, z: f64) -> bool {
        let d = &self.model.dvl;
        d.seabed_depth.is_none_or(|s| {
            let altitude = s - z;
            d.min_altitude <= altitude && altitude <= d.max_altitude
        })
    }

    /// The solution of the next control period, given the plant's true η, ν at it.
    pub fn step(&mut self, eta: &[f64; 6], nu: &[f64; 6]) -> Solution {
        *self.measure(eta, nu)
    }

    /// The solution of the last period stepped ([`NavComputer::step`]), none before the first.
    pub fn solution(&self) -> Option<&Solution> {
        (self.k > 0).then_some(&self.out)
    }

    /// [`NavComputer::step`], the solution kept in place and lent (**Choice 540**: the loop
    /// reads it where it is, not through two copies of its arrivals a period).
    pub fn measure(&mut self, eta: &[f64; 6], nu: &[f64; 6]) -> &Solution {
        let k = self.k;
        self.k += 1;
        self.truth.push((*eta, *nu));
        self.out.arrived = Arrivals::default();
        if k > 0 {
            self.advance();
        }
        // The first period has the samples the computer took before the mission (the vehicle
        // at its start), stamped 0; a later sample of tick 0 is that one.
        let first = |clock: &Clock| match k {
            0 => Some(0),
            _ => clock.arrival(k).filter(|&j| j > 0),
        };
        if let Some(j) = first(&self.ins.0) {
            self.ins_sample(j);
        }
        if let Some(j) = first(&self.dvl.0) {
            self.ping(j);
        }
        let held = self.truth.at(self.out.held_at);
        let v: [f64; 3] = std::array::from_fn(|i| held.1[i] + self.e_v[i]);
        let p = self.dead_reckon(k, &held.0, &v);
        self.anchor(k);
        for i in 0..3 {
            self.out.eta[i] = p[i] + self.offset[i];
            self.out.eta[3 + i] = self.att[i];
            self.out.nu[i] = v[i];
            self.out.nu[3 + i] = self.rates[i];
        }
        &self.out
    }

    /// One period on: every bias steps, and the velocity error integrates the INS's
    /// acceleration error (reset only by a ping).
    fn advance(&mut self) {
        let dt = self.dt;
        if self.at_samples {
            // Only the acceleration error is integrated every period; the other sources' biases
            // are stepped when they sample (Choice 536).
            self.accel.advance_to(self.k - 1, dt);
            let a = self.accel.sample();
            for (e, a) in self.e_v.iter_mut().zip(a) {
                *e += a * dt;
            }
            return;
        }
        self.ins.1.advance(dt);
        self.ins.2.advance(dt);
        self.accel.advance(dt);
        self.dvl.1.advance(dt);
        self.depth.1.advance(dt);
        if let Some(f) = &mut self.fix {
            f.1.advance(dt);
        }
        let a = self.accel.sample();
        for (e, a) in self.e_v.iter_mut().zip(a) {
            *e += a * dt;
        }
    }

    /// The INS sample of tick `j`: attitude and rates; the solution now holds at `j`.
    fn ins_sample(&mut self, j: u64) {
        let (te, tn) = self.truth.at(j);
        if self.at_samples {
            self.ins.1.advance_to(self.k - 1, self.dt);
            self.ins.2.advance_to(self.k - 1, self.dt);
        }
        let ea = self.ins.1.sample();
        let er = self.ins.2.sample();
        for i in 0..3 {
            self.att[i] = te[3 + i] + ea[i];
            self.rates[i] = tn[3 + i] + er[i];
        }
        self.out.held_at = j;
        self.out.arrived.ins = Some(Measured {
            sampled_at: j,
            value: std::array::from_fn(|i| {
                if i < 3 {
                    self.att[i]
                } else {
                    self.rates[i - 3]
                }
            }),
        });
    }

    /// The DVL ping of tick `j`: with bottom lock it resets the velocity error to its own.
    fn ping(&mut self, j: u64) {
        let (te, tn) = self.truth.at(j);
        self.out.bottom_lock = self.lock(te[2]);
        let mut velocity = None;
        if self.out.bottom_lock {
            if self.at_samples {
                self.dvl.1.advance_to(self.k - 1, self.dt);
            }
            self.e_v = self.dvl.1.sample();
            self.out.velocity_at = Some(j);
            velocity = Some(std::array::from_fn(|i| tn[i] + self.e_v[i]));
        }
        self.out.arrived.dvl = Some(Ping {
            sampled_at: j,
            velocity,
        });
    }

    /// Dead reckoning (trapezoid) of period `k` on the velocity `v` and the solution's
    /// attitude, from the true start `start`.
    fn dead_reckon(&mut self, k: u64, start: &[f64; 6], v: &[f64; 3]) -> [f64; 3] {
        let rv = rotate(&self.att, v);
        let p = if k == 0 {
            [start[0], start[1], start[2]]
        } else {
            let last = self.dr.at(k - 1);
            std::array::from_fn(|i| last[i] + 0.5 * self.dt * (self.last_rv[i] + rv[i]))
        };
        self.last_rv = rv;
        self.dr.push(p);
        p
    }

    /// The pressure depth and the fixes arriving at period `k` shift the dead reckoning so
    /// that it passes through them at their time.
    fn anchor(&mut self, k: u64) {
        let ins_latency = self.ins.0.latency;
        let (at_samples, dt) = (self.at_samples, self.dt);
        if let Some(j) = self.depth.0.arrival(k).filter(|&j| j > 0) {
            if at_samples {
                self.depth.1.advance_to(k, dt);
            }
            let z = self.truth.at(j).0[2] + self.depth.1.sample()[0];
            self.offset[2] = z - self.dr.at((j + ins_latency).min(k))[2];
            self.out.arrived.depth = Some(Measured {
                sampled_at: j,
                value: [z],
            });
        }
        if let Some((clock, stream)) = &mut self.fix {
            if let Some(j) = clock.arrival(k).filter(|&j| j > 0) {
                if at_samples {
                    stream.advance_to(k, dt);
                }
                let e = stream.sample();
                let (te, _) = self.truth.at(j);
                let at = self.dr.at((j + ins_latency).min(k));
                self.offset[0] = te[0] + e[0] - at[0];
                self.offset[1] = te[1] + e[1] - at[1];
                self.out.fix_at = Some(j);
                self.out.arrived.fix = Some(Measured {
                    sampled_at: j,
                    value: [te[0] + e[0], te[1] + e[1]],
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(sigma: f64, bias_sigma: f64, tau: f64, walk: f64) -> ErrorModel<1> {
        ErrorModel {
            sigma: [sigma],
            bias: [0.0],
            bias_sigma: [bias_sigma],
            bias_tau: tau,
            bias_walk: [walk],
        }
    }

    /// Eq N1: a Gauss–Markov bias stepped only at its source's samples (every 12 or 13
    /// periods, as an 8 Hz DVL on a 100 Hz loop) has the process's steady σ_b² at the
    /// samples and its autocorrelation e^(−n·dt/τ) between them.
    #[test]
    fn a_bias_stepped_at_its_samples_keeps_the_gauss_markov_statistics() {
        let (sb, tau, dt) = (0.5, 0.3, 0.01);
        let mut s = Stream::new(model(0.0, sb, tau, 0.0), 7, 4, NoiseDraws::AtSamples);
        let (mut k, mut xs) = (0u64, Vec::new());
        for i in 0..100_000u64 {
            k += 12 + i % 2;
            s.advance_to(k, dt);
            xs.push(s.sample()[0]);
        }
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        assert!((var / (sb * sb) - 1.0).abs() < 0.03, "variance {var}");
        // Lag-one correlation against the mean of e^(−12dt/τ) and e^(−13dt/τ).
        let rho = xs
            .windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / (n * var);
        let expected = 0.5 * ((-0.12f64 / tau).exp() + (-0.13f64 / tau).exp());
        assert!((rho - expected).abs() < 0.01, "{rho} vs {expected}");
    }

    /// Eq N1: a random walk stepped at irregular samples has the variance σ_w²·t of one
    /// stepped every period.
    #[test]
    fn a_walk_stepped_at_its_samples_has_variance_sigma_squared_t() {
        let (sw, dt) = (0.2, 0.01);
        let ends: Vec<f64> = (0..4000u64)
            .map(|seed| {
                let mut s = Stream::new(model(0.0, 0.0, 600.0, sw), seed, 1, NoiseDraws::AtSamples);
                let mut k = 0;
                while k < 100 {
                    k = (k + 1 + (k * 7 + seed) % 13).min(100);
                    s.advance_to(k, dt);
                }
                s.sample()[0]
            })
            .collect();
        let var = ends.iter().map(|x| x * x).sum::<f64>() / ends.len() as f64;
        // t = 1 s; the estimate's standard error is √(2/4000) ≈ 2.2 %.
        assert!((var / (sw * sw) - 1.0).abs() < 0.08, "variance {var}");
    }

    /// At samples, a zero σ draws nothing: a source without white noise or bias leaves its
    /// generator where it was, so its error is exactly its constant bias.
    #[test]
    fn a_zero_sigma_draws_no_normal_at_samples() {
        let mut m = model(0.0, 0.0, 600.0, 0.0);
        m.bias = [0.25];
        let mut s = Stream::new(m, 3, 5, NoiseDraws::AtSamples);
        s.advance_to(40, 0.01);
        assert_eq!(s.sample(), [0.25]);
        let mut fresh = Normals::new(
            NoiseDraws::AtSamples,
            3u64.wrapping_add(5u64.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        );
        assert_eq!(s.rng.normal().to_bits(), fresh.normal().to_bits());
        // Every period, the same source draws one normal at the start and two per step.
        let mut e = Stream::new(m, 3, 5, NoiseDraws::EveryPeriod);
        e.advance(0.01);
        let mut chacha = Normals::new(
            NoiseDraws::EveryPeriod,
            3u64.wrapping_add(5u64.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        );
        for _ in 0..3 {
            chacha.normal();
        }
        assert_eq!(e.rng.normal().to_bits(), chacha.normal().to_bits());
    }

    #[test]
    fn the_scenario_key_names_each_scheme() {
        for d in NoiseDraws::ALL {
            assert_eq!(NoiseDraws::from_name(d.name()), Some(d));
        }
        assert_eq!(NoiseDraws::default(), NoiseDraws::EveryPeriod);
        assert_eq!(NoiseDraws::from_name("sometimes"), None);
    }
}
