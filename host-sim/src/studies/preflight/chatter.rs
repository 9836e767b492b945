//! The chatter term (docs/real-vehicle.md#the-chatter-term, **Choices 500–504**): per
//! thruster, the sign reversals per second (through the ±[`DEAD_BAND`] V band of
//! [`crate::sim::chatter`]) and the command's total variation per second the mission will show
//! on its navigation, predicted before it flies, against the bound's chatter limits.
//!
//! **The command noise** (Choice 500). Per controlled axis the loop is the path-error budget's
//! ([`super::path_budget`]): the state X = [s, x̂, n] (the vehicle's error, the estimate, the
//! navigation's held fix and ping errors and their drift) moves one period at a time as
//! X⁺ = Aₖ X + εₖ (the loop's step, the drift, a fix or a ping replacing its state by a fresh
//! draw, the estimator's correction), εₖ independent of X. The law's input is u = c X (the
//! estimate's −G x̂, or −G(s + n) flown as told, plus −G w of the period's white noise w), so
//! var uₖ = c Pₖ cᵀ and cov(uₖ₊₁, uₖ) = c Aₖ Pₖ cᵀ (+ the white noise's terms). Only the draws
//! (fixes, pings, white noise) enter: a bias moves the solution slowly, which the law follows
//! as an offset of the path. The boundary layer's gain is δ/μ with δ the law's own Eq 29 along
//! the reference at the scale checked (its largest, with ‖e‖ at 3σ of the error the law sees;
//! at most δ_max), not δ_max: the law flies with the δ it computes (3.3–4 on the shipped
//! circle against δ_max = 25), and δ_max's gain predicted a noise step 8× the flown one. The
//! covariance is propagated until it repeats with its sources (the loop settled), and one cycle
//! of it (the least common multiple of the sources' periods) is kept. Rotational axes take the INS's white attitude and rate noise (no fixes). The axes'
//! noises are independent, and x and y alike (the larger of the two on surge and sway), so a
//! thruster's thrust noise is Σₐ c_ja uₐ with c = B⁺ M̂ (the allocation of the nominal mass
//! matrix's column a): var = Σₐ c_ja² var uₐ, and the same for the lag-1 covariance.
//!
//! **The mean command** (Choice 501): along the reference at the time scale checked (its
//! 20 Hz samples, linear in between at the control rate), the force the plant as written needs
//! at the heel it holds ([`super::attitude::heel`]: roll is not actuated, and the heel turns
//! the vertical pair's thrust into a sway force the horizontal pair answers) — its payload
//! profile; each current corner of the path-error budget, the worst taken — through the
//! allocation: what the thrusters are asked for without noise. The roll swing and the pitch
//! offset of the force check are not taken.
//!
//! **Reversals** (Choice 502). The band's edges are thrusts (the maps of Eqs 31–32 at ±0.5 V
//! in the scenario's unit). A reversal from below to above crosses the upper edge upwards, one
//! back crosses the lower edge downwards, and reversals alternate: over a run,
//! reversals ≤ min(C₊, C₋) + 2, C± the crossings of each edge (either way). For a Gaussian
//! command the expected crossings of a level L between two periods is
//! P(xₖ ≤ L < xₖ₊₁) + P(xₖ₊₁ ≤ L < xₖ), a bivariate normal orthant ([`bvn_upper`]; Rice's
//! formula is its limit for a smooth process), summed over the flight. The expected count
//! is raised to a one-sided [`CONFIDENCE_SIGMAS`]σ of a Poisson count (√ of the expectation):
//! the predicted reversals per second, against `max_reversals_per_s`.
//!
//! **Total variation** (Choice 503): E|Vₖ₊₁ − Vₖ| = V′(mₖ)·E|Δ| with Δ Gaussian (the mean's
//! step and the noise's step variance), summed over the flight per second, against
//! `max_command_tv`.
//!
//! **Joined** (Choice 504, [`super::check_with`]): feasible only when the force, the path-error
//! budget and this term fit at the scenario's time scale; otherwise the smallest scale where
//! all three do; infeasible when this term fits at no scale, naming the navigation noise it
//! needs (the fraction of the navigation's draws at which the mission fits at its own scale).

use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};
use controller_core::kinematics::{self, Attitude};
use controller_core::law::{uncertainty_bound, DeltaInputs};
use controller_core::thruster::{default_maps, ThrustUnit, ThrusterMap};
use controller_core::{Mission, Trajectory};
use nalgebra::{RowVector2, SMatrix, Vector3, Vector6};
use serde::{Deserialize, Serialize};

use super::bits::BitsMap;
use super::path_budget::{
    axis_noise, current_corners, period_maps, redraw, reference_samples, AxisNoise, Cov, Loop,
    PeriodMaps, PlantCache, RefSample, N,
};
use super::{period, CheckError, SAMPLE_PERIOD};
use crate::plant::PlantState;
use crate::scenario::navigation::Timing;
use crate::scenario::{Bound, Scenario};
use crate::sim::chatter::DEAD_BAND;

/// The predicted count is its expectation plus this many √(expectation) (a one-sided Poisson
/// bound at about 1 %), Choice 502.
pub const CONFIDENCE_SIGMAS: f64 = 2.33;
/// The longest the covariance is propagated before its cycle is kept (s): the loop and the
/// estimator settle in seconds.
const SETTLE: f64 = 30.0;
/// The longest cycle kept (periods): sources whose periods have no common multiple below it
/// are taken at the cycle's length.
const MAX_CYCLE: u64 = 100_000;
/// Beyond this many σ of a level, a period's crossing probability is taken as 0 (< 10⁻¹⁵).
const FAR: f64 = 8.5;
/// The grid of δ the command noise is computed on: δ rounded up to a power of 1.05 (5 %).
const DELTA_GRID: f64 = 1.05;
/// Periods between two looks at a stopping pass's partial sums (Choice 516).
const STOP_EVERY: u64 = 256;
/// The slowest time scale tried (the trajectory's own limit).
const MAX_TIME_SCALE: f64 = controller_core::Trajectory::MAX_TIME_SCALE as f64;

/// One thruster's predicted chatter at one time scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThrusterPrediction {
    pub thruster: String,
    /// The band's edges in thrust (N): the thrusts at −0.5 V and +0.5 V.
    pub band: [f64; 2],
    /// The largest σ of the thrust noise over a cycle (N), and of its step from one period to
    /// the next (N).
    pub sigma: f64,
    pub step_sigma: f64,
    /// Expected sign reversals per second, and the predicted (with the confidence) (1/s).
    pub expected_reversals_per_s: f64,
    pub reversals_per_s: f64,
    /// Expected total variation of the command per second (V/s).
    pub command_tv: f64,
}

/// The chatter term of one mission at one time scale (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChatterPrediction {
    /// The bound's limits: reversals per second, command total variation (V/s).
    pub max_reversals_per_s: f64,
    pub max_command_tv: f64,
    /// The time scale the figures are at.
    pub time_scale: f64,
    /// Per thruster, in the order of `THRUSTER_NAMES`.
    pub thrusters: Vec<ThrusterPrediction>,
    /// The smallest time scale at which the term fits (`None`: none up to the slowest).
    pub smallest_time_scale: Option<f64>,
    /// When no scale fits: what navigation the mission needs.
    pub needs: Option<String>,
}

impl ChatterPrediction {
    /// The worst thruster's predicted reversals per second and its index.
    pub fn worst_reversals(&self) -> (f64, usize) {
        worst(&self.thrusters, |t| t.reversals_per_s)
    }

    /// The worst thruster's predicted command total variation (V/s) and its index.
    pub fn worst_tv(&self) -> (f64, usize) {
        worst(&self.thrusters, |t| t.command_tv)
    }

    /// Fits the bound's chatter limits at its time scale.
    pub fn fits(&self) -> bool {
        self.worst_reversals().0 <= self.max_reversals_per_s
            && self.worst_tv().0 <= self.max_command_tv
    }

    /// One line for `check`.
    pub fn describe(&self) -> String {
        let (r, ri) = self.worst_reversals();
        let (tv, ti) = self.worst_tv();
        let per: Vec<String> = self
            .thrusters
            .iter()
            .map(|t| format!("{:.1}", t.reversals_per_s))
            .collect();
        let mut s = format!(
            "chatter at time scale {}: {} reverses up to {r:.1} times/s through ±{DEAD_BAND} V \
             (bound {}; per thruster {}), {}'s command varies by up to {tv:.0} V/s (bound {})",
            self.time_scale,
            THRUSTER_NAMES[ri],
            self.max_reversals_per_s,
            per.join(" / "),
            THRUSTER_NAMES[ti],
            self.max_command_tv,
        );
        match (self.smallest_time_scale, &self.needs) {
            (_, Some(n)) => s.push_str(&format!("; no time scale fits: {n}")),
            (Some(k), None) => s.push_str(&format!("; fits from time scale {k}")),
            (None, None) => {}
        }
        s
    }
}

fn worst(t: &[ThrusterPrediction], f: fn(&ThrusterPrediction) -> f64) -> (f64, usize) {
    t.iter()
        .enumerate()
        .fold((0.0, 0), |a, (i, x)| if f(x) > a.0 { (f(x), i) } else { a })
}

/// P(X > h, Y > k) for standard normals X, Y of correlation r (Genz's BVNU: Drezner and
/// Wesolowsky's integral of Sheppard's formula for |r| < 0.925, the expansion about r = ±1
/// beyond), by a 20-point Gauss–Legendre rule: absolute error below 10⁻¹⁴.
pub fn bvn_upper(h: f64, k: f64, r: f64) -> f64 {
    bvn_tail(&bvn_core(h, k, r), h, k, r, &phi)
}

/// [`bvn_upper`]`(h, k, r) + `[`bvn_upper`]`(−h, −k, r)`, bit for bit, at half the work
/// (Choice 534): the quadrature depends on h and k only through hk, h² + k² and (h − k′)²,
/// which the two share exactly (a sign flip is exact), so it is done once; the Φ of the
/// tails come in pairs Φ(x), Φ(−x) from one erfc ([`phi_pair`]).
pub fn bvn_upper_pair(h: f64, k: f64, r: f64) -> f64 {
    bvn_upper_pair_given(h, k, r, phi_pair(h), phi_pair(k))
}

/// [`bvn_upper_pair`] with [`phi_pair`]`(h)` and [`phi_pair`]`(k)` given (`ph`, `pk`): a
/// crossing's h is the negative of the previous period's k, bit for bit, so its pair is that
/// one swapped (Choice 517).
fn bvn_upper_pair_given(h: f64, k: f64, r: f64, ph: (f64, f64), pk: (f64, f64)) -> f64 {
    let core = bvn_core(h, k, r);
    let known = |x: f64| {
        let b = x.to_bits();
        if b == h.to_bits() {
            ph.0
        } else if b == (-h).to_bits() {
            ph.1
        } else if b == k.to_bits() {
            pk.0
        } else if b == (-k).to_bits() {
            pk.1
        } else {
            phi(x)
        }
    };
    bvn_tail(&core, h, k, r, &known) + bvn_tail(&core, -h, -k, r, &known)
}

/// What [`bvn_upper`] computes before its tail: the quadrature of Sheppard's formula (times
/// asr/2π) for |r| < 0.925, else the expansion about r = ±1 (with k′ = −k for r < 0). The
/// same bits for (h, k) and (−h, −k).
enum BvnCore {
    Sheppard(f64),
    Expansion(f64),
}

fn bvn_core(h: f64, k: f64, r: f64) -> BvnCore {
    use std::f64::consts::PI;
    let (x, w) = gauss_legendre_20();
    let hk = h * k;
    let mut bvn = 0.0;
    if r.abs() < 0.925 {
        let hs = 0.5 * (h * h + k * k);
        let asr = 0.5 * r.asin();
        for i in 0..20 {
            let sn = (asr * (1.0 + x[i])).sin();
            bvn += w[i] * ((sn * hk - hs) / (1.0 - sn * sn)).exp();
        }
        return BvnCore::Sheppard(bvn * asr / (2.0 * PI));
    }
    let (k, hk) = if r < 0.0 { (-k, -hk) } else { (k, hk) };
    if r.abs() < 1.0 {
        let a_s = (1.0 - r) * (1.0 + r);
        let mut a = a_s.sqrt();
        let bs = (h - k) * (h - k);
        let c = (4.0 - hk) / 8.0;
        let d = (12.0 - hk) / 16.0;
        let asr = -0.5 * (bs / a_s + hk);
        if asr > -100.0 {
            bvn = a
                * asr.exp()
                * (1.0 - c * (bs - a_s) * (1.0 - d * bs / 5.0) / 3.0 + c * d * a_s * a_s / 5.0);
        }
        if hk > -100.0 {
            let b = bs.sqrt();
            let sp = (2.0 * PI).sqrt() * phi(-b / a);
            bvn -= (-0.5 * hk).exp() * sp * b * (1.0 - c * bs * (1.0 - d * bs / 5.0) / 3.0);
        }
        a *= 0.5;
        for i in 0..20 {
            let xs = (a * (x[i] + 1.0)).powi(2);
            let rs = (1.0 - xs).sqrt();
            let asr = -0.5 * (bs / xs + hk);
            if asr > -100.0 {
                bvn += a
                    * w[i]
                    * asr.exp()
                    * ((-hk * xs / (2.0 * (1.0 + rs).powi(2))).exp() / rs
                        - (1.0 + c * xs * (1.0 + d * xs)));
            }
        }
        bvn = -bvn / (2.0 * PI);
    }
    BvnCore::Expansion(bvn)
}

/// [`bvn_upper`] from its core at (h, k, r), with Φ given (`phi`, or known values of it).
fn bvn_tail(core: &BvnCore, h: f64, k: f64, r: f64, phi: &dyn Fn(f64) -> f64) -> f64 {
    let mut bvn = match *core {
        BvnCore::Sheppard(s) => return (s + phi(-h) * phi(-k)).clamp(0.0, 1.0),
        BvnCore::Expansion(b) => b,
    };
    let k = if r < 0.0 { -k } else { k };
    if r > 0.0 {
        bvn += phi(-h.max(k));
    } else if h >= k {
        bvn = -bvn;
    } else {
        let l = if h < 0.0 {
            phi(k) - phi(h)
        } else {
            phi(-h) - phi(-k)
        };
        bvn = l - bvn;
    }
    bvn.clamp(0.0, 1.0)
}

/// (Φ(x), Φ(−x)) from one erfc, the bits [`phi`] gives each (its erfc of a negative argument
/// is 2 − erfc of the positive one).
fn phi_pair(x: f64) -> (f64, f64) {
    let y = x / std::f64::consts::SQRT_2;
    if y > 0.0 {
        let e = erfc(y);
        (0.5 * (2.0 - e), 0.5 * e)
    } else if y < 0.0 {
        let e = erfc(-y);
        (0.5 * e, 0.5 * (2.0 - e))
    } else {
        (phi(x), phi(-x))
    }
}

/// The standard normal distribution function Φ(x) (erfc, to double precision).
pub fn phi(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// erfc(x) by FreeBSD's rational approximations (the `libm` crate's port, within about an
/// ulp: one or two exp and a few polynomials), Choice 518; for x < 0 as 2 − erfc(−x), so
/// that [`phi_pair`]'s two values are [`phi`]'s bit for bit. The term's series below 2 and
/// continued fraction above (30–200 iterations, relative error 10⁻¹⁴) were 60 % of its time.
fn erfc(x: f64) -> f64 {
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    libm::erfc(x)
}

/// The 20-point Gauss–Legendre nodes and weights on [−1, 1] (Newton on P₂₀).
fn gauss_legendre_20() -> &'static ([f64; 20], [f64; 20]) {
    static RULE: std::sync::OnceLock<([f64; 20], [f64; 20])> = std::sync::OnceLock::new();
    RULE.get_or_init(|| {
        const M: usize = 20;
        let mut x = [0.0; M];
        let mut w = [0.0; M];
        for i in 0..M {
            let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (M as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, z);
                for n in 2..=M {
                    let n = n as f64;
                    (p0, p1) = (p1, ((2.0 * n - 1.0) * z * p1 - (n - 1.0) * p0) / n);
                }
                let dp = M as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    let (mut p0, mut p1) = (1.0, z);
                    for n in 2..=M {
                        let n = n as f64;
                        (p0, p1) = (p1, ((2.0 * n - 1.0) * z * p1 - (n - 1.0) * p0) / n);
                    }
                    let dp = M as f64 * (z * p1 - p0) / (z * z - 1.0);
                    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
                    break;
                }
            }
            x[i] = z;
        }
        (x, w)
    })
}

/// The probability that a Gaussian command crosses `level` (either way) between two periods:
/// means `m`, σ `s`, covariance `cov` of the two.
pub fn crossing_probability(m: [f64; 2], s: [f64; 2], cov: f64, level: f64) -> f64 {
    crossing_probability_carried(m, s, cov, level, &mut None)
}

/// [`crossing_probability`], the bits of the second period's standardised distance to the
/// level and its Φ pair carried to the next period (`carry`), where it is the first's
/// (Choice 517): one erfc of the two a crossing took.
fn crossing_probability_carried(
    m: [f64; 2],
    s: [f64; 2],
    cov: f64,
    level: f64,
    carry: &mut Option<(u64, (f64, f64))>,
) -> f64 {
    let last = carry.take();
    if s[0] <= 0.0 || s[1] <= 0.0 {
        // No noise: the mean crosses or it does not.
        let below = |x: f64| x <= level;
        return f64::from(u8::from(below(m[0]) != below(m[1])));
    }
    let a = (level - m[0]) / s[0];
    let b = (level - m[1]) / s[1];
    if a.abs() > FAR && b.abs() > FAR && a.signum() == b.signum() {
        return 0.0;
    }
    let r = (cov / (s[0] * s[1])).clamp(-1.0, 1.0);
    // P(x₀ ≤ L < x₁) = P(−x₀ ≥ −L, x₁ > L): standardised, −a and b at correlation −r.
    let ph = match last {
        // Φ(−a), Φ(a): the carried (Φ(b′), Φ(−b′)) swapped, b′ = a.
        Some((bits, (p, q))) if bits == a.to_bits() => (q, p),
        _ => phi_pair(-a),
    };
    let pk = phi_pair(b);
    *carry = Some((b.to_bits(), pk));
    bvn_upper_pair_given(-a, b, -r, ph, pk)
}

/// A crossing's inputs where the mean stands still (the mean, the two σ, the covariance, the
/// level), by their bits. Compared and hashed word by word: the array's own `==` is a call to
/// `memcmp` per probe and its hash one byte-slice write, ~5 % of `check` on the survey
/// between them (**Choice 578**); what a lookup finds is the same.
#[derive(Clone, Copy, Eq)]
struct CrossingKey([u64; 5]);

impl PartialEq for CrossingKey {
    fn eq(&self, other: &Self) -> bool {
        let (a, b) = (&self.0, &other.0);
        ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2]) | (a[3] ^ b[3]) | (a[4] ^ b[4])) == 0
    }
}

impl std::hash::Hash for CrossingKey {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        for w in self.0 {
            state.write_u64(w);
        }
    }
}
/// The Φ pair a crossing carries to the next period ([`crossing_probability_carried`]).
type Carry = Option<(u64, (f64, f64))>;

/// The crossings of one pass over the flight where the mean thrust stands still (its two
/// periods' bits equal), kept by their inputs' bits (**Choice 556**): on a leg flown at a
/// constant speed the mean thrusts stand still and the noise's statistics repeat with their
/// sources' cycle, so a pass asks the same crossing again and again. Exact: [`crossing_probability_carried`] gives the fresh crossing's bits whatever
/// it carried (Choice 517), and the carry it leaves is a function of the inputs alone (the
/// second period's standardised distance and its Φ pair, or nothing), so a kept crossing
/// gives back its probability and its carry. At most [`KEPT_CROSSINGS`] are kept. Hashed by
/// [`BitsHasher`](super::bits::BitsHasher) (Choice 562), not SipHash: the lookups were ~2 % of
/// `check` on the survey; what a lookup finds is the same.
#[derive(Default)]
struct Crossings(super::bits::BitsMap<CrossingKey, (f64, Carry)>);

/// The most crossings [`Crossings`] keeps in one pass (about 80 bytes each).
const KEPT_CROSSINGS: usize = 1 << 18;

impl Crossings {
    /// [`crossing_probability_carried`], kept by its inputs.
    fn crossing(
        &mut self,
        m: [f64; 2],
        s: [f64; 2],
        cov: f64,
        level: f64,
        carry: &mut Carry,
    ) -> f64 {
        // Only where the mean stands still (a leg at a constant speed): on a turn or a circle
        // it moves every period, and the key would cost without being asked again.
        if m[0].to_bits() != m[1].to_bits() {
            return crossing_probability_carried(m, s, cov, level, carry);
        }
        let key = CrossingKey([m[0], s[0], s[1], cov, level].map(f64::to_bits));
        if let Some(&(p, after)) = self.0.get(&key) {
            *carry = after;
            return p;
        }
        let p = crossing_probability_carried(m, s, cov, level, carry);
        if self.0.len() < KEPT_CROSSINGS {
            self.0.insert(key, (p, *carry));
        }
        p
    }
}

/// What one period of a still stretch adds ([`Still`]): each edge's crossing probability and
/// the total variation's term, and what it leaves for the next period (the carries, v₁).
#[derive(Clone, Copy)]
struct StillPeriod {
    crossings: [[f64; 2]; THRUSTERS],
    tv: [f64; THRUSTERS],
    carry: [[Carry; 2]; THRUSTERS],
    v1: [f64; THRUSTERS],
}

/// A stretch where every thruster's mean stands still (its bits equal from one period to the
/// next: a leg at a constant speed), replayed by the cycle of the noise's statistics
/// (**Choice 580**). There a period's inputs are the mean's bits and the statistics at its
/// phase n mod `cycle` (the lcm of the axes' cycles), so what it adds to the sums (each
/// crossing's probability, whatever it carried, Choice 517; the total variation's
/// slope·E|Δu| at Δm = 0) and what it carries are those of the period one cycle before:
/// the first cycle of a stretch is flown and recorded, the rest adds the recorded terms in
/// the same order — the same sums, bit for bit, without their square roots, Φ and exp
/// (and its σ and step maxima are the first cycle's).
struct Still {
    /// The statistics' cycle (periods); 0: too long to record ([`MAX_STILL_CYCLE`]).
    cycle: u64,
    /// The stretch's mean (bits) and first period; `None`: not in a still stretch.
    at: Option<([u64; THRUSTERS], u64)>,
    rec: Vec<StillPeriod>,
    /// The record the last replayed period read: its carries and v₁ are the flight's.
    replayed: Option<usize>,
}

/// The longest statistics' cycle [`Still`] records (periods, about 500 bytes each).
const MAX_STILL_CYCLE: u64 = 1 << 12;

#[cfg(test)]
thread_local! {
    /// Tests: fly every period and form every sample's mean thrusts (the reference
    /// Choices 579 and 580 are tested against).
    static NO_REPLAY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests: the periods replayed so far.
    static REPLAYED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    /// Tests: the samples whose mean thrusts were an alike one's.
    static ALIKE: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

impl Still {
    fn new(stats: &[AxisStats; 6]) -> Self {
        let cycle = stats
            .iter()
            .map(|s| s.var.len() as u64)
            .filter(|&l| l > 0)
            .try_fold(1u64, |c, l| {
                let c = c / gcd(c, l) * l;
                (c <= MAX_STILL_CYCLE).then_some(c)
            })
            .unwrap_or(0);
        #[cfg(test)]
        let cycle = if NO_REPLAY.with(std::cell::Cell::get) {
            0
        } else {
            cycle
        };
        Still {
            cycle,
            at: None,
            rec: Vec::new(),
            replayed: None,
        }
    }

    /// Period `n`, from mean `m0` to `m1`: the index of its record if the stretch has a whole
    /// cycle recorded (replay it), else `None` (fly it; [`Still::recording`] says whether to
    /// record it).
    fn replay(&mut self, n: u64, m0: &[f64; THRUSTERS], m1: &[f64; THRUSTERS]) -> Option<usize> {
        let bits = m0.map(f64::to_bits);
        if self.cycle == 0 || m1.map(f64::to_bits) != bits {
            self.at = None;
            return None;
        }
        match self.at {
            Some((b, start)) if b == bits => {
                let i = n - start;
                (i >= self.cycle).then(|| (i % self.cycle) as usize)
            }
            _ => {
                self.at = Some((bits, n));
                self.rec.clear();
                None
            }
        }
    }

    /// Whether period `n` (flown) is to be recorded: in a still stretch's first cycle.
    fn recording(&self, n: u64) -> bool {
        self.at.is_some_and(|(_, start)| n - start < self.cycle)
    }
}

/// One axis's command noise over one cycle of its sources: var u and cov(uₖ₊₁, uₖ) per period,
/// period k of the flight at index k mod the cycle.
#[derive(Clone, Debug, Default)]
struct AxisStats {
    var: Vec<f64>,
    lag: Vec<f64>,
    /// The largest variance of the error the law sees, position plus velocity (its ‖e‖ in δ).
    err_var: f64,
}

impl AxisStats {
    fn at(&self, k: u64) -> (f64, f64) {
        if self.var.is_empty() {
            return (0.0, 0.0);
        }
        let i = (k % self.var.len() as u64) as usize;
        (self.var[i], self.lag[i])
    }
}

/// Periods between a source's samples (as the navigation model samples it).
fn every(timing: &Timing, t: f64) -> u64 {
    (1.0 / (timing.rate_hz * t)).round().max(1.0) as u64
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The command noise of the loop `lp` under the draws of `noise` (module docs).
// Long: the propagation of one period is one sequence of steps; split, it would pass the
// same dozen matrices around.
fn axis_stats(lp: &Loop, noise: &AxisNoise) -> AxisStats {
    let t = lp.t;
    let fix = noise.fix.as_ref().map(|f| (f.0, every(&f.2, t)));
    let ping = noise.ping.as_ref().map(|p| (p.0, every(&p.2, t)));
    let quiet = fix.is_none_or(|f| f.0 == 0.0)
        && ping.is_none_or(|p| p.0 == 0.0)
        && noise.white.iter().all(|&w| w == 0.0);
    if quiet || (lp.gain[0] == 0.0 && lp.gain[1] == 0.0) {
        return AxisStats::default();
    }
    let cycle = [fix.map(|f| f.1), ping.map(|p| p.1)]
        .into_iter()
        .flatten()
        .fold(1u64, |c, e| (c / gcd(c, e) * e).min(MAX_CYCLE));
    let settle_periods = (SETTLE / t).ceil() as u64;
    let settle = settle_periods.div_ceil(cycle) * cycle;
    let PeriodMaps {
        loop_step,
        drift,
        correct,
        q_white,
    } = period_maps(lp, noise);
    let g = lp.g();
    let gr = RowVector2::new(lp.gain[0], lp.gain[1]);
    // u = c X (+ −G w with the estimator off); the error the law sees, e_pos X and e_vel X.
    let mut c = SMatrix::<f64, 1, N>::zeros();
    let mut e_pos = SMatrix::<f64, 1, N>::zeros();
    let mut e_vel = SMatrix::<f64, 1, N>::zeros();
    let white = nalgebra::Matrix2::new(noise.white[0].powi(2), 0.0, 0.0, noise.white[1].powi(2));
    let gwg = (gr * white * gr.transpose())[(0, 0)];
    let (w_var, w_lag) = match lp.k {
        Some(_) => {
            c[2] = -gr[0];
            c[3] = -gr[1];
            e_pos[2] = 1.0;
            e_vel[3] = 1.0;
            (0.0, 0.0)
        }
        None => {
            for (i, gi) in [(0, 0), (1, 1), (4, 0), (8, 0), (5, 1), (6, 1)] {
                c[i] = -gr[gi];
                if gi == 0 {
                    e_pos[i] = 1.0;
                } else {
                    e_vel[i] = 1.0;
                }
            }
            // cov(uₖ₊₁, uₖ) through sₖ₊₁'s −gG wₖ: (−G g)(G W Gᵀ).
            (gwg, -(gr * g)[(0, 0)] * gwg)
        }
    };
    let mut p = Cov::zeros();
    if let Some((s, _)) = fix {
        p[(4, 4)] = s * s;
    }
    if let Some((s, _)) = ping {
        p[(5, 5)] = s * s;
    }
    let zero_row = |a: &mut Cov, i: usize| {
        for j in 0..N {
            a[(i, j)] = 0.0;
        }
    };
    let mut out = AxisStats::default();
    for n in 0..settle + cycle {
        // Aₙ: X_{n+1} = Aₙ Xₙ + εₙ.
        let mut a = drift * loop_step;
        let fixed = fix.filter(|f| (n + 1).is_multiple_of(f.1));
        let pinged = ping.filter(|q| (n + 1).is_multiple_of(q.1));
        if fixed.is_some() {
            zero_row(&mut a, 4);
        }
        if pinged.is_some() {
            zero_row(&mut a, 5);
        }
        if let Some(cc) = &correct {
            a = cc * a;
        }
        if n >= settle {
            let var = (c * p * c.transpose())[(0, 0)] + w_var;
            let lag = (c * (a * p) * c.transpose())[(0, 0)] + w_lag;
            out.var.push(var.max(0.0));
            out.lag.push(lag);
            let ev = (e_pos * p * e_pos.transpose())[(0, 0)]
                + (e_vel * p * e_vel.transpose())[(0, 0)]
                + noise.white[0].powi(2)
                + noise.white[1].powi(2);
            out.err_var = out.err_var.max(ev);
        }
        // Pₙ₊₁, as the path-error budget propagates it.
        p = loop_step * p * loop_step.transpose();
        if lp.k.is_none() {
            p += q_white;
        }
        p = drift * p * drift.transpose();
        if let Some((s, _)) = fixed {
            redraw(&mut p, 4, s * s);
        }
        if let Some((s, _)) = pinged {
            redraw(&mut p, 5, s * s);
        }
        if let Some(cc) = &correct {
            p = cc * p * cc.transpose() + q_white;
        }
    }
    out
}

/// The white attitude and rate noise of rotational axis `i` (3..6) of `scenario` (the INS's
/// and `[noise]`'s), as an [`AxisNoise`] without fixes or pings.
fn rotational_noise(scenario: &Scenario, i: usize) -> AxisNoise {
    let cfg = scenario.config();
    let mut white = [0.0f64; 2];
    if let Some(m) = &cfg.navigation {
        white = [m.ins.attitude.sigma[i - 3], m.ins.rates.sigma[i - 3]];
    }
    if let Some(n) = &cfg.noise {
        white = [
            white[0].hypot(n.eta_sigma[i]),
            white[1].hypot(n.nu_sigma[i]),
        ];
    }
    AxisNoise {
        white,
        ..AxisNoise::default()
    }
}

/// The draws of `noise` (its biases zeroed).
fn draws(mut noise: AxisNoise) -> AxisNoise {
    noise.accel_bias = 0.0;
    for src in [&mut noise.fix, &mut noise.ping].into_iter().flatten() {
        src.1 = 0.0;
    }
    noise
}

/// What the term needs of a mission, computed once; evaluated at any time scale.
pub struct Chatter<'a> {
    scenario: &'a Scenario,
    bound: Bound,
    /// Per axis of η, the navigation's draws.
    noise: [AxisNoise; 6],
    /// Per δ of the boundary layer (on a grid of [`DELTA_GRID`] steps), per body axis, the
    /// command noise over its cycle.
    stats: std::cell::RefCell<Vec<(i32, std::rc::Rc<[AxisStats; 6]>)>>,
    /// Every prediction made, by the bits of its time scale and noise fraction (Choice 532):
    /// the search, the joined verdicts of both scopes and their rounding ask for the same
    /// scale more than once, and each is a pass over every control period of the flight.
    memo: std::cell::RefCell<Vec<([u64; 2], ChatterPrediction)>>,
    /// The (time scale, noise fraction) found past the bound by a pass stopped early
    /// (Choice 516), and the current corner that went past it last.
    refused: std::cell::RefCell<Vec<[u64; 2]>>,
    last_refused: std::cell::Cell<usize>,
    /// K_d of the path at k = 1, and the ‖e‖ δ takes (3σ of the error the law sees).
    accel_bound: f64,
    error_norm: f64,
    /// c_ja²: thruster j's thrust noise per unit variance of body axis a.
    coeff: [[f64; 6]; THRUSTERS],
    /// The band's edges per thruster (N), [at −0.5 V, at +0.5 V].
    band: [[f64; 2]; THRUSTERS],
    maps: [ThrusterMap; THRUSTERS],
    unit: ThrustUnit,
    samples: Vec<RefSample>,
    currents: Vec<Vector3<f64>>,
    /// How a periodic mission repeats (Choices 393, 538–539).
    reduction: Option<period::Reduction>,
    rate_hz: f64,
}

/// The control periods a flight of `periods` at scale `k` and `rate_hz` is flown over by the
/// terms (Choice 539): all of them, or for a long mission its window (at least `cycle`
/// periods past the repetition's start), and the period the repeating part starts at.
pub(super) fn window_periods(
    r: Option<&period::Reduction>,
    periods: u64,
    k: f64,
    rate_hz: f64,
    cycle: u64,
) -> (u64, u64) {
    match r.filter(|r| r.long) {
        Some(r) => {
            let from = (r.from * k * rate_hz).ceil() as u64;
            let window = ((r.window(k) * k * rate_hz).ceil() as u64).max(from + cycle.max(1));
            if window < periods {
                (window, from)
            } else {
                (periods, periods)
            }
        }
        None => (periods, periods),
    }
}

impl<'a> Chatter<'a> {
    /// The term's model of `scenario`; `None` when the scenario has no bound.
    ///
    /// # Errors
    /// [`CheckError::Invalid`] for a loop the term cannot model; [`CheckError::Interrupted`].
    pub fn new(scenario: &'a Scenario) -> Result<Option<Self>, CheckError> {
        Self::with_reduction(scenario, true)
    }

    /// [`Chatter::new`], or with `reduce` false the reference it is tested against: every
    /// control period of the flight, the reference sampled over all of it (no Choice 393, 538
    /// or 539).
    ///
    /// # Errors
    /// As [`Chatter::new`].
    pub fn with_reduction(
        scenario: &'a Scenario,
        reduce: bool,
    ) -> Result<Option<Self>, CheckError> {
        let cfg = scenario.config();
        let Some(bound) = cfg.bound() else {
            return Ok(None);
        };
        let controller = scenario.controller();
        let noise: [AxisNoise; 6] = std::array::from_fn(|i| {
            if i < 3 {
                draws(axis_noise(scenario, i, 0.0))
            } else {
                rotational_noise(scenario, i)
            }
        });
        let m = controller.mass_matrix();
        let alloc = controller.allocation();
        let columns: [[f32; THRUSTERS]; 6] = std::array::from_fn(|a| {
            let column: Vector6<f32> = m.column(a).into_owned();
            alloc.thrusts(&column)
        });
        let coeff: [[f64; 6]; THRUSTERS] =
            std::array::from_fn(|j| std::array::from_fn(|a| f64::from(columns[a][j]).powi(2)));
        let maps = default_maps();
        let unit = cfg.controller.thrust_unit;
        let band = maps.map(|map| {
            let at = |v: f32| f64::from(map.newtons_of_voltage(unit, v));
            let (lo, hi) = (at(-DEAD_BAND as f32), at(DEAD_BAND as f32));
            [lo.min(hi), lo.max(hi)]
        });
        let path = Trajectory::new(Mission {
            time_scale: 1.0,
            ..cfg.mission()
        })
        .map_err(|e| CheckError::Invalid(format!("the mission at time scale 1: {e}")))?;
        let span = cfg.duration / super::time_scale(cfg.time_scale);
        // A periodic mission's first period (Choice 393), a long one's window (Choice 539).
        let reduction = period::reduction(cfg).filter(|_| reduce);
        let checked = reduction
            .as_ref()
            .map_or(span, |r| span.min(r.reference_span() + SAMPLE_PERIOD));
        let (samples, _) = reference_samples(&path, checked)?;
        let mut out = Chatter {
            scenario,
            bound,
            noise,
            stats: std::cell::RefCell::new(Vec::new()),
            memo: std::cell::RefCell::new(Vec::new()),
            refused: std::cell::RefCell::new(Vec::new()),
            last_refused: std::cell::Cell::new(0),
            accel_bound: f64::from(path.accel_bound()),
            error_norm: 0.0,
            coeff,
            band,
            maps,
            unit,
            samples,
            currents: current_corners(&cfg.current),
            reduction,
            rate_hz: f64::from(cfg.controller.rate_hz),
        };
        // ‖e‖ in δ: 3σ of the error the law sees, at the δ of the fastest scale (k = 1) with
        // ‖e‖ = 0 (Choice 500).
        let (_, delta) = out.mean_thrusts(1.0)?;
        let stats = out.stats_at(delta)?;
        out.error_norm = 3.0
            * controller_core::axes::ACTUATED
                .iter()
                .map(|&a| stats[a].err_var)
                .sum::<f64>()
                .sqrt();
        Ok(Some(out))
    }

    /// The command noise per body axis with the boundary layer at δ (rounded up to the grid,
    /// at most δ_max), computed once per grid step.
    fn stats_at(&self, delta: f64) -> Result<std::rc::Rc<[AxisStats; 6]>, CheckError> {
        let c = self.scenario.controller().config();
        let delta_max = f64::from(c.delta_max);
        let step = (delta.max(1e-3).ln() / DELTA_GRID.ln()).ceil() as i32;
        let on_grid = DELTA_GRID.powi(step).min(delta_max);
        if let Some((_, s)) = self.stats.borrow().iter().find(|(k, _)| *k == step) {
            return Ok(s.clone());
        }
        let mut eta_stats: Vec<AxisStats> = Vec::with_capacity(6);
        for i in 0..6 {
            let lp = Loop::with_delta(self.scenario, i, on_grid)?;
            eta_stats.push(axis_stats(&lp, &self.noise[i]));
        }
        // Surge and sway each take the larger of x and y.
        let xy = |s: &AxisStats| s.var.iter().copied().fold(0.0, f64::max);
        let horizontal = if xy(&eta_stats[0]) >= xy(&eta_stats[1]) {
            eta_stats[0].clone()
        } else {
            eta_stats[1].clone()
        };
        let stats = std::rc::Rc::new([
            horizontal.clone(),
            horizontal,
            eta_stats[2].clone(),
            eta_stats[3].clone(),
            eta_stats[4].clone(),
            eta_stats[5].clone(),
        ]);
        self.stats.borrow_mut().push((step, stats.clone()));
        Ok(stats)
    }

    /// The mean thrust per thruster at each reference sample at time scale `k`, per current
    /// corner (module docs, Choice 501), and the largest δ of Eq 29 along the reference
    /// (clamped to δ_max) with ‖e‖ the term's error norm.
    // Long: one pass over the reference forms the state once for the force and for δ.
    fn mean_thrusts(&self, k: f64) -> Result<(MeanThrusts, f64), CheckError> {
        let cfg = self.scenario.config();
        let controller = self.scenario.controller();
        let alloc = controller.allocation();
        let constants = controller.delta_constants();
        let mut delta = 0.0f64;
        let mut out = vec![Vec::with_capacity(self.samples.len()); self.currents.len()];
        let mut plant = PlantCache::default();
        // The samples met so far with the same plant (the cache's), by the bits of what
        // their thrusts read besides it (Choice 579): their δ and index.
        let mut alike: BitsMap<[u64; 16], (f32, usize)> = BitsMap::default();
        let mut alike_params = None;
        for (j, r) in self.samples.iter().enumerate() {
            if j % 4096 == 0 {
                super::poll()?;
            }
            let params = cfg.plant_params_at(r.s * k);
            // The vehicle holds the heel of its payload (roll is not actuated), as the force
            // check evaluates it ([`super::attitude::heel`]).
            let level = crate::plant::static_heel(&params, r.eta[PITCH]).unwrap_or(0.0);
            if alike_params != Some(params) {
                alike.clear();
                alike_params = Some(params);
            }
            let mut key = [level.to_bits(); 16];
            for (w, x) in key[1..]
                .iter_mut()
                .zip(r.eta.iter().skip(ROLL).chain(&r.eta_dot).chain(&r.eta_ddot))
            {
                *w = x.to_bits();
            }
            #[cfg(test)]
            let reference = NO_REPLAY.with(std::cell::Cell::get);
            #[cfg(not(test))]
            let reference = false;
            if let Some(&(d, first)) = alike.get(&key).filter(|_| !reference) {
                delta = delta.max(f64::from(d));
                #[cfg(test)]
                ALIKE.with(|c| c.set(c.get() + 1));
                for o in out.iter_mut() {
                    let thrusts = o[first];
                    o.push(thrusts);
                }
                continue;
            }
            let (state, nu_dot) = state_at(r, k, level);
            let (att, nu) = (Attitude::from_eta(&state.eta), state.nu);
            let jjn = kinematics::jinv_jdot_nu(&att, &nu).unwrap_or_else(|_| Vector6::zeros());
            let d = uncertainty_bound(
                constants,
                &DeltaInputs {
                    accel_bound: (self.accel_bound / (k * k)) as f32,
                    error_norm: self.error_norm as f32,
                    nu_norm: nu.norm() as f32,
                    jinv_jdot_nu_norm: jjn.norm() as f32,
                    cos_theta_abs: att.ctheta.abs() as f32,
                },
            );
            delta = delta.max(f64::from(d));
            let truth = plant.at(params)?;
            for (c, o) in self.currents.iter().zip(out.iter_mut()) {
                let heel = super::attitude::heel(truth, &state, &nu_dot, c).unwrap_or(level);
                let (state, nu_dot) = state_at(r, k, heel);
                let tau = truth.required_force(&state, &nu_dot, c).cast::<f32>();
                o.push(alloc.thrusts(&tau).map(f64::from));
            }
            alike.insert(key, (d, j));
        }
        let delta_max = f64::from(controller.config().delta_max);
        Ok((
            out,
            if delta.is_finite() {
                delta.min(delta_max)
            } else {
                delta_max
            },
        ))
    }

    /// The flight's duration at time scale `k` (s): the same path.
    fn duration(&self, k: f64) -> f64 {
        let cfg = self.scenario.config();
        cfg.duration * k / super::time_scale(cfg.time_scale)
    }

    /// The term at time scale `k` with the navigation's draws scaled by `noise` (1: as
    /// configured), without the search.
    ///
    /// # Errors
    /// [`CheckError::Interrupted`]; [`CheckError::Invalid`] for a plant that cannot be built.
    pub fn at(&self, k: f64, noise: f64) -> Result<ChatterPrediction, CheckError> {
        let key = [k.to_bits(), noise.to_bits()];
        if let Some((_, p)) = self.memo.borrow().iter().find(|m| m.0 == key) {
            return Ok(p.clone());
        }
        let p = self.predict(k, noise)?;
        self.memo.borrow_mut().push((key, p.clone()));
        Ok(p)
    }

    /// Whether the term fits at time scale `k` with the navigation's draws scaled by `noise`:
    /// [`Chatter::at`]`(k, noise).fits()`, the same answer, stopping a pass over the flight as
    /// soon as a thruster's count or total variation is past the bound (Choice 516). Both are
    /// sums of non-negative terms in the flight's order, and the predicted rate and its share
    /// of the bound are non-decreasing in them (a rounded sum, square root, product and
    /// quotient never decrease when their operand grows), so a partial sum past the bound is a
    /// full one past it; a pass that reaches the end is the full prediction, and is kept.
    ///
    /// # Errors
    /// As [`Chatter::at`].
    pub fn fits_with(&self, k: f64, noise: f64) -> Result<bool, CheckError> {
        let key = [k.to_bits(), noise.to_bits()];
        if let Some((_, p)) = self.memo.borrow().iter().find(|m| m.0 == key) {
            return Ok(p.fits());
        }
        if self.refused.borrow().contains(&key) {
            return Ok(false);
        }
        let (means, delta) = self.mean_thrusts(k)?;
        let stats = self.stats_at(delta)?;
        let duration = self.duration(k);
        // The corner that last went past the bound first: it is likely to again.
        let first = self.last_refused.get().min(means.len().saturating_sub(1));
        let order = std::iter::once(first).chain((0..means.len()).filter(|&c| c != first));
        let mut per_corner = vec![None; means.len()];
        for c in order {
            match self.flown(&stats, &means[c], k, noise * noise, Some(duration), false)? {
                Some(r) => per_corner[c] = Some(r),
                None => {
                    self.last_refused.set(c);
                    self.refused.borrow_mut().push(key);
                    return Ok(false);
                }
            }
        }
        let per_corner: Vec<_> = per_corner.into_iter().flatten().collect();
        let p = self.assemble(k, duration, &per_corner);
        let fits = p.fits();
        self.memo.borrow_mut().push((key, p));
        Ok(fits)
    }

    /// A thruster's share of the bound at one corner: the larger of its predicted reversals
    /// per second and its total variation per second over their limits, from the expected
    /// count and the total variation over a flight of `duration` (the figures
    /// [`Chatter::assemble`] reports, by the same operations).
    fn share(&self, expected: f64, tv: f64, duration: f64) -> f64 {
        let predicted = expected + CONFIDENCE_SIGMAS * expected.sqrt() + 2.0;
        (predicted / duration / self.bound.max_reversals_per_s)
            .max(tv / duration / self.bound.max_command_tv)
    }

    /// The term at the slowest scale ([`MAX_TIME_SCALE`]) with the mean thrust held still
    /// between the reference's samples (**Choice 560**): each sample's mean for the stretch of
    /// the flight up to the next (a staircase, not the line between them), the noise and the
    /// stretch's length as [`Chatter::at`] flies them. Where the mean stands still the flight
    /// asks the same crossings again with the noise's cycle, which [`Crossings`] keeps, so
    /// the pass costs about one cycle per sample instead of every period; the mean's steps
    /// keep its total variation. Not [`Chatter::at`]`(MAX_TIME_SCALE, 1.0)`'s figures: its
    /// approximation at the slowest scale, for the refusal's score
    /// (`falsify::refusal`, Choice 551), which needs no verdict.
    ///
    /// # Errors
    /// As [`Chatter::at`].
    pub fn slowest_held(&self) -> Result<ChatterPrediction, CheckError> {
        self.predict_with(MAX_TIME_SCALE, 1.0, true)
    }

    /// [`Chatter::at`], evaluated.
    fn predict(&self, k: f64, noise: f64) -> Result<ChatterPrediction, CheckError> {
        self.predict_with(k, noise, false)
    }

    /// [`Chatter::predict`], the mean held between samples with `held`
    /// ([`Chatter::slowest_held`]).
    fn predict_with(
        &self,
        k: f64,
        noise: f64,
        held: bool,
    ) -> Result<ChatterPrediction, CheckError> {
        let (means, delta) = self.mean_thrusts(k)?;
        let stats = self.stats_at(delta)?;
        let duration = self.duration(k);
        let mut per_corner = Vec::with_capacity(means.len());
        for mean in &means {
            let flown = self.flown(&stats, mean, k, noise * noise, None, held)?;
            per_corner.push(flown.ok_or(CheckError::Interrupted)?);
        }
        Ok(self.assemble(k, duration, &per_corner))
    }

    /// The prediction at scale `k` from each current corner's flight (per thruster: σ, step
    /// σ, expected count, total variation): per thruster the corner with the largest share of
    /// the bound.
    fn assemble(&self, k: f64, duration: f64, per_corner: &[Flown]) -> ChatterPrediction {
        let thrusters = (0..THRUSTERS)
            .map(|j| {
                let mut best: Option<ThrusterPrediction> = None;
                for c in per_corner {
                    let (sigma, step, expected, tv) = c[j];
                    let predicted = expected + CONFIDENCE_SIGMAS * expected.sqrt() + 2.0;
                    let p = ThrusterPrediction {
                        thruster: THRUSTER_NAMES[j].to_string(),
                        band: self.band[j],
                        sigma,
                        step_sigma: step,
                        expected_reversals_per_s: expected / duration,
                        reversals_per_s: predicted / duration,
                        command_tv: tv / duration,
                    };
                    let worse = best.as_ref().is_none_or(|b| {
                        (p.reversals_per_s / self.bound.max_reversals_per_s)
                            .max(p.command_tv / self.bound.max_command_tv)
                            > (b.reversals_per_s / self.bound.max_reversals_per_s)
                                .max(b.command_tv / self.bound.max_command_tv)
                    });
                    if worse {
                        best = Some(p);
                    }
                }
                best.unwrap_or_else(|| ThrusterPrediction {
                    thruster: THRUSTER_NAMES[j].to_string(),
                    band: self.band[j],
                    sigma: 0.0,
                    step_sigma: 0.0,
                    expected_reversals_per_s: 0.0,
                    reversals_per_s: 0.0,
                    command_tv: 0.0,
                })
            })
            .collect();
        ChatterPrediction {
            max_reversals_per_s: self.bound.max_reversals_per_s,
            max_command_tv: self.bound.max_command_tv,
            time_scale: k,
            thrusters,
            smallest_time_scale: None,
            needs: None,
        }
    }

    /// Per thruster over the flight at scale `k` on the mean profile `mean` (one current
    /// corner), the noise's variance scaled by `scale2`: the largest σ, the largest step σ,
    /// the expected reversals (min of the two edges' crossings) and the expected total
    /// variation (V). With `stop` (the flight's duration), `None` as soon as a thruster's
    /// partial sums are past the bound ([`Chatter::fits_with`]). With `held`, the mean held
    /// still between samples ([`Chatter::slowest_held`]).
    // Long: one pass over the flight's periods, its sums carried from one to the next.
    fn flown(
        &self,
        stats: &[AxisStats; 6],
        mean: &[[f64; THRUSTERS]],
        k: f64,
        scale2: f64,
        stop: Option<f64>,
        held: bool,
    ) -> Result<Option<Flown>, CheckError> {
        let t = 1.0 / self.rate_hz;
        let periods = (self.duration(k) * self.rate_hz).round().max(1.0) as u64;
        let cycle = stats.iter().map(|s| s.var.len() as u64).max().unwrap_or(1);
        let (flown, from) =
            window_periods(self.reduction.as_ref(), periods, k, self.rate_hz, cycle);
        let at = |n: u64| self.mean_at(mean, n as f64 * t / k, held);
        let mut crossings = [[0.0f64; 2]; THRUSTERS];
        let mut tv = [0.0f64; THRUSTERS];
        let mut sigma = [0.0f64; THRUSTERS];
        let mut step = [0.0f64; THRUSTERS];
        let mut carry = [[None; 2]; THRUSTERS];
        let mut kept = Crossings::default();
        let mut m0 = at(0);
        let mut before = ([[0.0f64; 2]; THRUSTERS], [0.0f64; THRUSTERS]);
        let mut next: [(f64, f64); 6] = std::array::from_fn(|a| stats[a].at(0));
        let mut v_next: [f64; THRUSTERS] = std::array::from_fn(|j| {
            let c = &self.coeff[j];
            (0..6).map(|a| c[a] * next[a].0).sum::<f64>() * scale2
        });
        let mut slopes: [Option<(u64, f64)>; THRUSTERS] = [None; THRUSTERS];
        let mut still = Still::new(stats);
        for n in 0..flown {
            if n == from {
                before = (crossings, tv);
            }
            if n % 65_536 == 0 {
                super::poll()?;
            }
            if let Some(duration) = stop.filter(|_| n % STOP_EVERY == 0) {
                let past = (0..THRUSTERS).any(|j| {
                    let expected = crossings[j][0].min(crossings[j][1]);
                    self.share(expected, tv[j], duration) > 1.0
                });
                if past {
                    return Ok(None);
                }
            }
            let m1 = at(n + 1);
            if let Some(i) = still.replay(n, &m0, &m1) {
                let r = &still.rec[i];
                for j in 0..THRUSTERS {
                    for (sum, p) in crossings[j].iter_mut().zip(&r.crossings[j]) {
                        *sum += p;
                    }
                    tv[j] += r.tv[j];
                }
                still.replayed = Some(i);
                #[cfg(test)]
                REPLAYED.with(|c| c.set(c.get() + 1));
                continue;
            }
            if let Some(i) = still.replayed.take() {
                // Flying again after a replay: what the replayed period left.
                (carry, v_next) = (still.rec[i].carry, still.rec[i].v1);
                next = std::array::from_fn(|a| stats[a].at(n));
            }
            if held && m1 != m0 {
                // A step: the kept crossings were the last stretch's (their mean is gone).
                kept.0.clear();
            }
            // This period's statistics are the last one's `next`, and its v₀ the last one's v₁:
            // the same expressions of the same inputs, carried rather than formed twice.
            let now = next;
            next = std::array::from_fn(|a| stats[a].at(n + 1));
            let mut added = StillPeriod {
                crossings: [[0.0; 2]; THRUSTERS],
                tv: [0.0; THRUSTERS],
                carry: [[None; 2]; THRUSTERS],
                v1: [0.0; THRUSTERS],
            };
            for j in 0..THRUSTERS {
                let c = &self.coeff[j];
                let v0 = v_next[j];
                let v1: f64 = (0..6).map(|a| c[a] * next[a].0).sum::<f64>() * scale2;
                v_next[j] = v1;
                let cov: f64 = (0..6).map(|a| c[a] * now[a].1).sum::<f64>() * scale2;
                let s = [v0.sqrt(), v1.sqrt()];
                let dvar = (v0 + v1 - 2.0 * cov).max(0.0);
                sigma[j] = sigma[j].max(s[0]);
                step[j] = step[j].max(dvar.sqrt());
                for (e, level) in self.band[j].iter().enumerate() {
                    let p = kept.crossing([m0[j], m1[j]], s, cov, *level, &mut carry[j][e]);
                    crossings[j][e] += p;
                    added.crossings[j][e] = p;
                }
                let dm = m1[j] - m0[j];
                // The slope at the last period's mean again where the mean stands still.
                let slope = match slopes[j] {
                    Some((bits, v)) if bits == m0[j].to_bits() => v,
                    _ => self.slope(j, m0[j]),
                };
                slopes[j] = Some((m0[j].to_bits(), slope));
                added.tv[j] = slope * mean_abs(dm, dvar.sqrt());
                tv[j] += added.tv[j];
            }
            if still.recording(n) {
                (added.carry, added.v1) = (carry, v_next);
                still.rec.push(added);
            }
            m0 = m1;
        }
        if flown < periods {
            let factor = (periods - from) as f64 / (flown - from) as f64;
            extrapolate(&mut crossings, &mut tv, &before, factor);
        }
        Ok(Some(std::array::from_fn(|j| {
            (
                sigma[j],
                step[j],
                crossings[j][0].min(crossings[j][1]),
                tv[j],
            )
        })))
    }

    /// The mean thrusts at path time `s` (s, at k = 1), folded onto a periodic mission's
    /// checked span, linear between the reference's samples (`mean`, one a sample), or with
    /// `held` the last sample's.
    fn mean_at(&self, mean: &[[f64; THRUSTERS]], mut s: f64, held: bool) -> [f64; THRUSTERS] {
        let last = mean.len().saturating_sub(1);
        let span = last.max(1) as f64 * SAMPLE_PERIOD;
        if let Some(r) = &self.reduction {
            s = r.fold(s);
        }
        let x = (s / SAMPLE_PERIOD).min(span / SAMPLE_PERIOD);
        let j = (x.floor() as usize).min(last);
        let j1 = (j + 1).min(last);
        if held {
            return mean[j];
        }
        let w = x - j as f64;
        std::array::from_fn(|i| mean[j][i] * (1.0 - w) + mean[j1][i] * w)
    }

    /// |dV/dT| of thruster `j` at thrust `x` (V/N), 0 where the supply limit clamps it.
    fn slope(&self, j: usize, x: f64) -> f64 {
        let h = 0.05;
        let v = |x: f64| f64::from(self.maps[j].voltage_of_newtons(self.unit, x as f32));
        let limit = f64::from(self.scenario.config().controller.voltage_limit);
        if v(x).abs() >= limit {
            return 0.0;
        }
        ((v(x + h) - v(x - h)) / (2.0 * h)).abs()
    }

    /// Whether the term fits the bound at time scale `k`.
    ///
    /// # Errors
    /// As [`Chatter::at`].
    pub fn fits_at(&self, k: f64) -> Result<bool, CheckError> {
        self.fits_with(k, 1.0)
    }

    /// The term at the scenario's own scale, with the smallest scale that fits and, when none
    /// does, the navigation noise it needs.
    ///
    /// # Errors
    /// As [`Chatter::at`].
    pub fn evaluate(&self) -> Result<ChatterPrediction, CheckError> {
        let k0 = super::time_scale(self.scenario.config().time_scale);
        let mut out = self.at(k0, 1.0)?;
        if out.fits() {
            out.smallest_time_scale = Some(self.smallest(1.0, k0)?);
            return Ok(out);
        }
        let mut hi = k0;
        let mut found = None;
        while hi < MAX_TIME_SCALE {
            let lo = hi;
            hi = (2.0 * hi).min(MAX_TIME_SCALE);
            if self.fits_at(hi)? {
                found = Some(self.smallest(lo, hi)?);
                break;
            }
        }
        match found {
            Some(k) => out.smallest_time_scale = Some(k),
            None => out.needs = Some(self.needs(k0)?),
        }
        Ok(out)
    }

    /// The smallest k in [lo, hi] at which the term fits (it fits at hi), by bisection to
    /// [`super::TIME_SCALE_TOLERANCE`], rounded up to [`super::TIME_SCALE_STEP`].
    fn smallest(&self, lo: f64, hi: f64) -> Result<f64, CheckError> {
        if self.fits_at(lo)? {
            return Ok(lo);
        }
        let (mut lo, mut hi) = (lo, hi);
        while hi / lo > 1.0 + super::TIME_SCALE_TOLERANCE {
            let mid = (lo * hi).sqrt();
            if self.fits_at(mid)? {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let mut k =
            ((hi / super::TIME_SCALE_STEP).ceil() * super::TIME_SCALE_STEP * 100.0).round() / 100.0;
        while k < MAX_TIME_SCALE && !self.fits_at(k)? {
            k = ((k + super::TIME_SCALE_STEP) * 100.0).round() / 100.0;
        }
        Ok(k.min(MAX_TIME_SCALE))
    }

    /// What the navigation must deliver for the term to fit at the scenario's scale `k0`: the
    /// largest fraction of its draws' σ (fixes, pings, white noise) that fits.
    fn needs(&self, k0: f64) -> Result<String, CheckError> {
        let fits = |s: f64| self.fits_with(k0, s);
        if !fits(0.0)? {
            return Ok(
                "the mean command alone reverses beyond the bound (no navigation helps)"
                    .to_string(),
            );
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        while hi - lo > 0.01 {
            let mid = 0.5 * (lo + hi);
            if fits(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(self.needs_text(lo))
    }

    fn needs_text(&self, fraction: f64) -> String {
        let cfg = self.scenario.config();
        let mut s = format!(
            "needs the navigation's noise (fixes, pings, white) at most {:.0} % of the assumed",
            100.0 * fraction
        );
        if let Some(m) = &cfg.navigation {
            let v = &m.dvl.velocity.sigma;
            s.push_str(&format!(
                ": DVL single-ping σ ≤ {:.1} mm/s",
                1e3 * fraction * v[0].max(v[1])
            ));
            if let Some(f) = &m.fix {
                s.push_str(&format!(
                    ", fix σ ≤ {:.1} mm",
                    1e3 * fraction * f.error.sigma[0].max(f.error.sigma[1])
                ));
            }
        }
        s
    }
}

/// One current corner's flight, per thruster: the largest σ and step σ, the expected
/// reversals and the total variation ([`Chatter::flown`]).
type Flown = [(f64, f64, f64, f64); THRUSTERS];

/// Per current corner, per reference sample, the mean thrust per thruster (N).
type MeanThrusts = Vec<Vec<[f64; THRUSTERS]>>;

/// Index of roll and pitch in η.
const ROLL: usize = 3;
const PITCH: usize = 4;

/// A long mission's window (Eq L2): the repeating part's sums (past `before`, the sums at the
/// period it starts) extrapolated at their mean per period by `factor`, the flight's repeating
/// periods over the window's.
fn extrapolate(
    crossings: &mut [[f64; 2]; THRUSTERS],
    tv: &mut [f64; THRUSTERS],
    before: &([[f64; 2]; THRUSTERS], [f64; THRUSTERS]),
    factor: f64,
) {
    for j in 0..THRUSTERS {
        for (c, b) in crossings[j].iter_mut().zip(before.0[j]) {
            *c = b + (*c - b) * factor;
        }
        tv[j] = before.1[j] + (tv[j] - before.1[j]) * factor;
    }
}

/// The vehicle on the reference sample `r` at time scale `k` with roll `phi`: η, ν = J⁻¹η̇,
/// ν̇ = J⁻¹(η̈ − J̇ν).
fn state_at(r: &RefSample, k: f64, phi: f64) -> (PlantState, Vector6<f64>) {
    let mut eta = r.eta;
    eta[ROLL] = phi;
    let att = Attitude::from_eta(&eta);
    let jinv = kinematics::jacobian_inv(&att);
    let nu = jinv * (r.eta_dot / k);
    let jjn = kinematics::jinv_jdot_nu(&att, &nu).unwrap_or_else(|_| Vector6::zeros());
    let nu_dot = jinv * (r.eta_ddot / (k * k)) - jjn;
    (PlantState { eta, nu }, nu_dot)
}

/// E|x| for x ~ N(μ, s²).
fn mean_abs(mu: f64, s: f64) -> f64 {
    if s <= 0.0 {
        return mu.abs();
    }
    let z = mu / s;
    s * (2.0 / std::f64::consts::PI).sqrt() * (-0.5 * z * z).exp() + mu * (1.0 - 2.0 * phi(-z))
}

/// The term of `scenario` (module docs); `None` when it has no bound.
///
/// # Errors
/// As [`Chatter::new`] and [`Chatter::evaluate`].
pub fn chatter(scenario: &Scenario) -> Result<Option<ChatterPrediction>, CheckError> {
    match Chatter::new(scenario)? {
        Some(c) => Ok(Some(c.evaluate()?)),
        None => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// P(X > h, Y > k) by brute force: ∫_h^∞ φ(x) Φ((ρx − k)/√(1 − ρ²)) dx, Simpson's rule
    /// on 20 000 intervals out to h + 12.
    fn brute(h: f64, k: f64, r: f64) -> f64 {
        let n = 20_000;
        let (a, b) = (h.max(-12.0), h.max(-12.0) + 24.0);
        let dx = (b - a) / n as f64;
        let s = (1.0 - r * r).sqrt();
        let f = |x: f64| {
            (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt() * phi((r * x - k) / s)
        };
        let mut sum = f(a) + f(b);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            sum += w * f(a + i as f64 * dx);
        }
        sum * dx / 3.0
    }

    /// The term's erfc before Choice 518: erf's Taylor series below 2, the continued
    /// fraction above (Lentz), relative error about 10⁻¹⁴.
    fn erfc_series(x: f64) -> f64 {
        if x < 0.0 {
            return 2.0 - erfc_series(-x);
        }
        if x < 2.0 {
            // erf by its Taylor series: converges fast for x < 2.
            let mut sum = x;
            let mut term = x;
            let x2 = x * x;
            let mut n = 0.0;
            while term.abs() > 1e-17 * sum.abs() {
                n += 1.0;
                term *= -x2 / n;
                sum += term / (2.0 * n + 1.0);
            }
            return 1.0 - 2.0 / std::f64::consts::PI.sqrt() * sum;
        }
        // Continued fraction (Lentz): erfc x = e^{−x²}/√π · 1/(x + 1/2/(x + 1/(x + 3/2/(x + …)))).
        let tiny = 1e-300;
        let mut f = x;
        let mut c = x;
        let mut d = 0.0;
        for i in 1..200 {
            let a = i as f64 / 2.0;
            d = x + a * d;
            d = if d.abs() < tiny { tiny } else { d };
            c = x + a / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            let delta = c * d;
            f *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (-x * x).exp() / (std::f64::consts::PI.sqrt() * f)
    }

    /// The erfc of Choice 518 is the series and continued fraction it replaced within
    /// 5·10⁻¹³ (relative) over the arguments the term's Φ takes (|x| ≤ 8.5/√2 and beyond), on
    /// both sides of the series' edge at 2 and the rational pieces' at 0.84375, 1.25 and
    /// 1/0.35. The difference is the series' own error where 1 − erf cancels below 2:
    /// 2.2·10⁻¹³ at 1.956 against a 40-digit erfc, where the new one is within 10⁻¹⁶.
    #[test]
    fn the_erfc_is_the_series_it_replaced_to_its_precision() {
        let mut worst = 0.0f64;
        for i in -4000..=4000 {
            let x = f64::from(i) * 2e-3 + 1e-7;
            let (new, old) = (erfc(x), erfc_series(x));
            worst = worst.max(((new - old) / old).abs());
        }
        for x in [
            0.84375,
            1.25,
            2.0,
            1.0 / 0.35,
            6.0,
            8.5 / std::f64::consts::SQRT_2,
        ] {
            for y in [x, -x, x * (1.0 + 1e-12), x * (1.0 - 1e-12)] {
                worst = worst.max(((erfc(y) - erfc_series(y)) / erfc_series(y)).abs());
            }
        }
        assert!(worst < 5e-13, "{worst:e}");
    }

    /// Φ at known values (Abramowitz and Stegun's table, and Φ(−8) = 6.22·10⁻¹⁶).
    #[test]
    fn the_normal_distribution_function_matches_its_table() {
        for (x, p) in [
            (0.0, 0.5),
            (-1.0, 0.158_655_253_931_457_05),
            (-1.96, 0.024_997_895_148_220_435),
            (-3.0, 0.001_349_898_031_630_094_6),
            (2.5, 0.993_790_334_674_223_7),
            (-8.0, 6.220_960_574_271_785e-16),
        ] {
            let got = phi(x);
            assert!(((got - p) / p).abs() < 1e-12, "Φ({x}) = {got}, table {p}");
        }
    }

    /// The orthant at the origin has the closed form ¼ + asin(ρ)/(2π) (Sheppard), at every ρ,
    /// through both of the bivariate routine's branches; ρ = 0 is the product.
    #[test]
    fn the_bivariate_orthant_matches_its_closed_forms() {
        for r in [
            -0.999, -0.99, -0.95, -0.5, 0.0, 0.3, 0.9, 0.95, 0.99, 0.9999,
        ] {
            let want = 0.25 + f64::asin(r) / (2.0 * std::f64::consts::PI);
            let got = bvn_upper(0.0, 0.0, r);
            assert!((got - want).abs() < 1e-14, "ρ {r}: {got} vs {want}");
        }
        for (h, k) in [(1.0, -0.5), (-2.0, 0.7), (2.5, 2.5)] {
            let got = bvn_upper(h, k, 0.0);
            let want = phi(-h) * phi(-k);
            assert!((got - want).abs() < 1e-15, "{got} vs {want}");
        }
    }

    /// Away from the origin, against the brute-force integral, in both branches and at the
    /// correlations a filtered command has from one period to the next (0.95–0.9999).
    #[test]
    fn the_bivariate_orthant_matches_a_brute_force_integral() {
        for &(h, k) in &[
            (0.5, 1.0),
            (-1.0, 2.0),
            (2.0, 2.1),
            (-0.3, -0.2),
            (1.5, -1.5),
        ] {
            for r in [-0.99, -0.93, -0.6, 0.2, 0.8, 0.93, 0.99, 0.999, 0.9999] {
                let (got, want) = (bvn_upper(h, k, r), brute(h, k, r));
                assert!(
                    (got - want).abs() < 1e-9,
                    "h {h}, k {k}, ρ {r}: {got} vs {want}"
                );
            }
        }
    }

    /// The pair (Choice 534) is the sum of its two orthants bit for bit — the crossing
    /// probabilities the term sums are unchanged — over random arguments in both branches, at
    /// the branch edges and ±1, at zeros and at h = ±k; and against the brute-force integral.
    #[test]
    fn the_orthant_pair_is_the_sum_of_its_two_orthants() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(534);
        let mut cases: Vec<(f64, f64, f64)> = Vec::new();
        for _ in 0..4000 {
            let x: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
            let r = (x[2] * 0.6).tanh();
            let near_one = 1.0 - 10f64.powf(-1.0 - 3.0 * x[2].abs().min(1.0));
            cases.push((3.0 * x[0], 3.0 * x[1], r));
            cases.push((3.0 * x[0], 3.0 * x[1], near_one.copysign(x[2])));
        }
        for r in [-1.0, -0.925, -0.9249, 0.0, 0.9249, 0.925, 1.0] {
            for (h, k) in [
                (0.0, 0.0),
                (0.0, 1.3),
                (-0.7, 0.7),
                (0.7, 0.7),
                (-2.0, -0.0),
            ] {
                cases.push((h, k, r));
            }
        }
        for (h, k, r) in cases {
            let (pair, two) = (
                bvn_upper_pair(h, k, r),
                bvn_upper(h, k, r) + bvn_upper(-h, -k, r),
            );
            assert_eq!(pair.to_bits(), two.to_bits(), "h {h}, k {k}, ρ {r}");
        }
        for (h, k, r) in [(0.5, 1.0, 0.99), (-1.0, 2.0, -0.6), (1.5, -1.5, -0.999)] {
            let want = brute(h, k, r) + brute(-h, -k, r);
            assert!((bvn_upper_pair(h, k, r) - want).abs() < 2e-9);
        }
        for x in [-9.0, -2.5, -1e-3, -0.0, 0.0, 1e-3, 1.9, 2.1, 9.0] {
            let (p, q) = phi_pair(x);
            assert_eq!(
                (p.to_bits(), q.to_bits()),
                (phi(x).to_bits(), phi(-x).to_bits())
            );
        }
    }

    /// A crossing with the previous period's Φ pair carried (Choice 517) is the crossing
    /// computed afresh, bit for bit: over random means, σ and correlations period after period
    /// (near the level, far from it past [`FAR`], and without noise in between).
    #[test]
    fn a_carried_crossing_is_the_fresh_one() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(517);
        let level = 4.2;
        let mut carry = None;
        let (mut m0, mut s0) = (level, 2.0f64);
        let mut nonzero = 0;
        for n in 0..20_000 {
            let x: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
            let m1 = level
                + 6.0 * (n as f64 * 1e-3).sin() * (1.0 + 0.3 * x[0])
                + if n % 997 < 20 { 40.0 } else { 0.0 };
            let s1 = if n % 1500 < 3 {
                0.0
            } else {
                2.0 * (0.2 * x[1]).exp()
            };
            let cov = s0 * s1 * (0.9 + 0.0999 * x[2].tanh());
            let fresh = crossing_probability([m0, m1], [s0, s1], cov, level);
            let carried = crossing_probability_carried([m0, m1], [s0, s1], cov, level, &mut carry);
            assert_eq!(fresh.to_bits(), carried.to_bits(), "period {n}");
            nonzero += usize::from(fresh > 0.0);
            (m0, s0) = (m1, s1);
        }
        assert!(nonzero > 10_000);
    }

    /// A kept crossing (Choice 556) is the carried one, bit for bit, and leaves the same
    /// carry: over a pass whose means stand still on a leg (each level near, far, and with
    /// no noise) and whose σ repeat with a cycle of 7 periods, broken by turns where
    /// everything moves; most of the pass is kept.
    #[test]
    fn a_kept_crossing_is_the_carried_one() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(556);
        let mut kept = Crossings::default();
        let (mut carries, mut carries_kept) = ([None; 2], [None; 2]);
        let (mut m0, mut s0) = (4.0f64, 2.0f64);
        for n in 0..30_000u64 {
            let turn = n % 5000 < 300;
            let x: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
            let m1 = match (turn, (n / 5000) % 3) {
                (false, _) if n % 5000 == 4000 => m0 + 1e-9,
                (true, _) => 4.0 + 6.0 * x[0],
                (false, 0) => 4.5,
                (false, 1) => 40.0,
                _ => -3.0,
            };
            let s1 = match n % 7 {
                0 if (n / 5000) % 2 == 1 => 0.0,
                i => 1.0 + 0.25 * i as f64 + if turn { 0.1 * x[1].abs() } else { 0.0 },
            };
            let cov = s0 * s1 * 0.95;
            for (e, level) in [4.2, -4.2].into_iter().enumerate() {
                let (carry, carry_kept) = (&mut carries[e], &mut carries_kept[e]);
                let carried = crossing_probability_carried([m0, m1], [s0, s1], cov, level, carry);
                let k = kept.crossing([m0, m1], [s0, s1], cov, level, carry_kept);
                assert_eq!(carried.to_bits(), k.to_bits(), "period {n}");
                assert_eq!(carry.map(|c| c.0), carry_kept.map(|c| c.0), "period {n}");
                let pair = |c: Carry| c.map(|c| (c.1 .0.to_bits(), c.1 .1.to_bits()));
                assert_eq!(pair(*carry), pair(*carry_kept), "period {n}");
            }
            (m0, s0) = (m1, s1);
        }
        assert!(kept.0.len() < 10_000, "{} kept", kept.0.len());
    }

    /// Rice's formula: a stationary Gaussian process of σ and autocorrelation e^{−τ²/(2ℓ²)}
    /// crosses a level L (either way) (1/(πℓ))·e^{−L²/(2σ²)} times per unit time. Sampled
    /// every T ≪ ℓ, the per-period crossing probability over T tends to it.
    #[test]
    fn crossings_of_a_smooth_process_tend_to_rices_rate() {
        let (sigma, ell) = (3.0f64, 0.2f64);
        for level in [0.0f64, 2.0, 6.0] {
            let rice = (-0.5 * (level / sigma).powi(2)).exp() / (std::f64::consts::PI * ell);
            let t = ell / 2000.0;
            let cov = sigma * sigma * (-0.5 * (t / ell).powi(2)).exp();
            let p = crossing_probability([0.0, 0.0], [sigma, sigma], cov, level);
            let rate = p / t;
            assert!(
                (rate / rice - 1.0).abs() < 1e-3,
                "level {level}: {rate} /s vs Rice {rice} /s"
            );
        }
    }

    /// Counted on a simulated AR(1) command (fixed seed) passing through a band, the
    /// crossings of each edge are the sum of the per-period probabilities, and the reversals
    /// through the band (counted as `sim::chatter` counts them) are at most min(C₋, C₊) + 2.
    #[test]
    fn simulated_crossings_and_reversals_are_within_the_prediction() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let (rho, sigma, n) = (0.97f64, 2.0, 200_000u64);
        let band = [-1.0, 1.5];
        let mean = |k: u64| 3.0 * (k as f64 * 2e-4).sin();
        let z0: f64 = StandardNormal.sample(&mut rng);
        let mut x = sigma * z0;
        let mut counted = [0u64; 2];
        let mut predicted = [0.0f64; 2];
        let (mut side, mut reversals) = (0i8, 0u64);
        for k in 0..n {
            let e: f64 = StandardNormal.sample(&mut rng);
            let next = rho * x + sigma * (1.0 - rho * rho).sqrt() * e;
            let (v0, v1) = (mean(k) + x, mean(k + 1) + next);
            for (i, level) in band.iter().enumerate() {
                counted[i] += u64::from((v0 <= *level) != (v1 <= *level));
                predicted[i] += crossing_probability(
                    [mean(k), mean(k + 1)],
                    [sigma, sigma],
                    rho * sigma * sigma,
                    *level,
                );
            }
            if v1 > band[1] {
                reversals += u64::from(side == -1);
                side = 1;
            } else if v1 < band[0] {
                reversals += u64::from(side == 1);
                side = -1;
            }
            x = next;
        }
        for i in 0..2 {
            let (c, p) = (counted[i] as f64, predicted[i]);
            // A count of crossings of a correlated process: within 5 of its √.
            assert!((c - p).abs() < 5.0 * p.sqrt(), "edge {i}: {c} vs {p}");
        }
        let bound = predicted[0].min(predicted[1]) + 2.0;
        assert!(
            (reversals as f64) <= bound + CONFIDENCE_SIGMAS * bound.sqrt(),
            "{reversals} reversals vs {bound}"
        );
        assert!(reversals > 0);
    }

    /// Choices 579–580: the term with alike samples' mean thrusts formed once and still
    /// stretches replayed by the noise's cycle is the term formed sample by sample and flown
    /// period by period, bit for bit (the survey's legs and turns under its navigation, the
    /// mean moving and held, another scale and noise), and it does replay.
    #[test]
    fn replayed_still_stretches_are_the_flown_ones() {
        use std::cell::Cell;
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/real/survey-200x100.toml");
        let survey = crate::scenario::load_scenario(&path).expect("the survey");
        let survey = survey
            .with(|c| c.duration = 300.0)
            .expect("a shorter survey");
        let term = |replay: bool| {
            NO_REPLAY.with(|c| c.set(!replay));
            let chatter = Chatter::new(&survey).expect("a term").expect("a bound");
            let out = [
                chatter.evaluate().expect("the term"),
                chatter.slowest_held().expect("held"),
                chatter.predict_with(1.3, 0.7, false).expect("at 1.3"),
            ];
            NO_REPLAY.with(|c| c.set(false));
            format!("{out:?}")
        };
        let flown = term(false);
        let before = (REPLAYED.with(Cell::get), ALIKE.with(Cell::get));
        let replayed = term(true);
        assert!(
            REPLAYED.with(Cell::get) > before.0 + 10_000,
            "nothing replayed"
        );
        assert!(ALIKE.with(Cell::get) > before.1 + 100, "no sample alike");
        assert_eq!(replayed, flown);
    }

    /// E|x| of a Gaussian: σ√(2/π) at μ = 0, |μ| when σ → 0.
    #[test]
    fn mean_absolute_value_of_a_gaussian() {
        let s = 1.7;
        assert!((mean_abs(0.0, s) - s * (2.0 / std::f64::consts::PI).sqrt()).abs() < 1e-15);
        assert_eq!(mean_abs(-2.0, 0.0), 2.0);
        assert!((mean_abs(50.0, 1.0) - 50.0).abs() < 1e-12);
    }
}
