//! The thruster characteristic: force → voltage (Eqs 31–32 of Roy et al. 2013), its closed-form
//! inverse, the thrust envelope at a supply limit, and saturation (docs/thrusters.md#saturation, docs/thrusters.md#the-chain-end-to-end).
//!
//! This module knows what one thruster does with a voltage; it knows nothing about where the
//! thrusters sit (that is [`crate::effectiveness`]) or how a wrench is split among them (that
//! is [`crate::allocation`]). In the manner of PX4, it is the actuator-output stage after the
//! control allocation:
//!
//! * [`ThrusterMap`]: Eq 31 (tunnel) and Eq 32 (main), V(T), and the inverse T(V) in closed form;
//! * [`ThrusterMap::thrust_range`]: the envelope [T_min, T_max] reachable within ±V_limit;
//! * [`actuate`]: the supply clamp, the main thruster's fold, and the thrust the clamped voltage
//!   actually gives ([`Actuation`]) — the saturation-honesty signal of docs/thrusters.md#saturation.
//!
//! # Units
//!
//! The paper does not state the thrust unit of Eqs 31–32. [`ThrusterMap::voltage`] and
//! [`ThrusterMap::thrust`] are the polynomials as printed, in *polynomial units*; which unit
//! that is, is configuration: [`ThrustUnit`], default [`ThrustUnit::Kgf`] (docs/thrusters.md#the-thrust-unit
//! **Choice**: under the paper's own damping only the kgf reading reaches the vehicle's
//! published 2–4 kn, and a wrong kgf guess under-drives the thrusters instead of over-driving
//! them 9.81×). Everything else in the workspace is newtons: [`ThrusterMap::voltage_of_newtons`],
//! [`ThrusterMap::newtons_of_voltage`], [`ThrustEnvelope`] and [`actuate`] convert at this one
//! seam.
//! 1 kgf = [`KGF_IN_NEWTONS`] = 9.80665 N, the standard kilogram-force (docs/thrusters.md#the-thrust-unit
//! **Choice**: the paper gives no sign that its fits use its model's g = 9.81; the two differ by
//! 0.03 %). Voltage is in volts.
//!
//! Everything here is fixed work: no loops that depend on data, no iteration to convergence,
//! no heap, no panics.
//!
//! # Square roots in the inverse maps
//!
//! The inverse maps call [`crate::math::exact_sqrt`] (correctly rounded: the FPU's `vsqrt.f32`
//! on the board, libm's `sqrtf` on the host) instead of [`crate::math::sqrt`]. Under the
//! `micromath` feature `math::sqrt` has up to ≈ 6 % relative error; measured through the
//! inverse maps over the ±24 V range when this choice was made, that is a thrust error of up
//! to 1.85 N (4.5 %) on the main thruster and 0.46 N (2.3 %) on a tunnel thruster (Cardano's
//! square root feeds a cancellation), whose whole ±24 V range is only −9.2…+20.1 N. The
//! reported thrust is the saturation-honesty signal, so it must not depend on the backend; the
//! cost is five `vsqrt.f32` per tick. With it the inverse is within 1.2e-5 N of the exact root
//! over ±24 V in every backend (asserted by `tests/thruster.rs`). `cbrt` goes through
//! [`crate::math::cbrt`]: libm's with `libm-math`, the kernels' otherwise (micromath has none).

use crate::effectiveness::THRUSTERS;
use crate::math;

/// Default supply limit of the board, V (docs/thrusters.md#envelopes-at-the-supply-limit: ±24 V).
pub const DEFAULT_V_LIMIT: f32 = 24.0;

/// One kilogram-force in newtons: the standard value, 9.80665 N (docs/thrusters.md#the-thrust-unit **Choice**).
pub const KGF_IN_NEWTONS: f32 = 9.806_65;

/// The thrust unit of the polynomials of Eqs 31–32 (docs/thrusters.md#the-thrust-unit **Choice**: kgf by
/// default, newtons one setting away). It is part of the controller's validated configuration
/// ([`ControllerConfig::thrust_unit`](crate::ControllerConfig::thrust_unit)), crosses the link
/// in `SetConfig` and is reported in every telemetry frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ThrustUnit {
    /// Eqs 31–32 take and give kilogram-force (1 kgf = [`KGF_IN_NEWTONS`] N). The default.
    #[default]
    Kgf,
    /// Eqs 31–32 take and give newtons.
    Newton,
}

impl ThrustUnit {
    /// Both units, [`ThrustUnit::Kgf`] first.
    pub const ALL: [ThrustUnit; 2] = [ThrustUnit::Kgf, ThrustUnit::Newton];

    /// Newtons per polynomial unit: 9.80665 for kgf, 1 for newtons.
    pub const fn newtons(self) -> f32 {
        match self {
            ThrustUnit::Kgf => KGF_IN_NEWTONS,
            ThrustUnit::Newton => 1.0,
        }
    }

    /// Polynomial units per newton, 1/[`newtons`](Self::newtons) (exactly 1 for newtons).
    pub const fn per_newton(self) -> f32 {
        match self {
            ThrustUnit::Kgf => 1.0 / KGF_IN_NEWTONS,
            ThrustUnit::Newton => 1.0,
        }
    }

    /// `"kgf"` or `"newton"`: the scenario files' `controller.thrust_unit` and the reports.
    pub const fn as_str(self) -> &'static str {
        match self {
            ThrustUnit::Kgf => "kgf",
            ThrustUnit::Newton => "newton",
        }
    }

    /// The unit whose [`as_str`](Self::as_str) is `name`.
    pub fn from_name(name: &str) -> Option<ThrustUnit> {
        Self::ALL.into_iter().find(|u| u.as_str() == name)
    }
}

impl core::fmt::Display for ThrustUnit {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

// Eq 31, tunnel: V = A T³ + B T² + C T + D.
const TUN_A: f64 = 0.0005;
const TUN_B: f64 = -0.0468;
const TUN_C: f64 = 2.0;
const TUN_D: f64 = -1.354;
// Shifted and scaled form used by the inverse: with T = T₀ + σ y,
//   V = V₀ + K (y³ + 3 y),
// T₀ = −B/(3A) (inflection, 31.2 N), P = C − B²/(3A) = V'(T₀) = 0.53984 V/N > 0 (so the cubic
// is strictly increasing and has exactly one real root), σ = √(P/(3A)) and K = A σ³.
// The shift removes the quadratic term, the scale makes the linear coefficient exactly 3, so
// Cardano's intermediate quantities stay O(1)·|V| instead of 2000·|V|.
const TUN_T0: f64 = -TUN_B / (3.0 * TUN_A);
const TUN_P: f64 = TUN_C - TUN_B * TUN_B / (3.0 * TUN_A);
const TUN_V0: f64 = ((TUN_A * TUN_T0 + TUN_B) * TUN_T0 + TUN_C) * TUN_T0 + TUN_D;
/// σ = √(P/(3A)) = √359.893… (no const sqrt; checked below).
const TUN_SIGMA: f64 = 18.970_854_839_287_906;
const TUN_K: f64 = TUN_A * TUN_SIGMA * TUN_SIGMA * TUN_SIGMA;
const _: () = {
    let rel = (3.0 * TUN_A * TUN_SIGMA * TUN_SIGMA - TUN_P) / TUN_P;
    assert!(rel < 1e-14 && rel > -1e-14);
    assert!(TUN_P > 0.0);
};

// Eq 32, main: V = A T² + B T + C.
const MAIN_A: f64 = -0.003;
const MAIN_B: f64 = -0.1048;
const MAIN_C: f64 = -0.1962;
const MAIN_T_FOLD_F64: f64 = -MAIN_B / (2.0 * MAIN_A);
const MAIN_V_FOLD_F64: f64 = (MAIN_A * MAIN_T_FOLD_F64 + MAIN_B) * MAIN_T_FOLD_F64 + MAIN_C;

/// Thrust at the fold of the main thruster's parabola (Eq 32), N: T_fold = −0.1048/(2·0.003)
/// = −17.4667 N. Eq 32 is decreasing for T ≥ T_fold; reverse thrust below T_fold does not
/// exist.
pub const MAIN_T_FOLD: f32 = MAIN_T_FOLD_F64 as f32;
/// Voltage at the fold of Eq 32, V: V_fold = V(T_fold) = 0.719053 V, the largest voltage the
/// main map produces.
pub const MAIN_V_FOLD: f32 = MAIN_V_FOLD_F64 as f32;

/// Force→voltage characteristic of one thruster (thrust T in N, voltage V in V).
///
/// Both maps are the paper's experimental curve fits, used as printed (docs/thrusters.md#force-to-voltage).
/// Their value at T = 0 is not 0 V (tunnel −1.354 V, main −0.1962 V): that offset is a
/// curve-fit artefact, and 0 V means power off (see [`Actuation::OFF`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ThrusterMap {
    /// Tunnel thruster, Eq 31: V = 0.0005 T³ − 0.0468 T² + 2 T − 1.354.
    /// Strictly increasing (V′ ≥ 0.53984 V/N at T = 31.2 N), defined for every T.
    Tunnel,
    /// Stern main thruster, Eq 32: V = −0.003 T² − 0.1048 T − 0.1962.
    /// Valid branch T ≥ [`MAIN_T_FOLD`] (= −17.47 N), on which it is strictly decreasing from
    /// [`MAIN_V_FOLD`] (= 0.719 V); forward thrust needs negative voltage.
    Main,
}

impl ThrusterMap {
    /// Voltage (V) that the map assigns to thrust `t` (N): the polynomial of Eq 31 or Eq 32,
    /// in Horner form, for every `t` (for the main thruster also below T_fold, where the
    /// polynomial is outside its valid branch — [`actuate`] never commands that).
    #[inline]
    pub fn voltage(self, t: f32) -> f32 {
        match self {
            ThrusterMap::Tunnel => {
                ((TUN_A as f32 * t + TUN_B as f32) * t + TUN_C as f32) * t + TUN_D as f32
            }
            ThrusterMap::Main => (MAIN_A as f32 * t + MAIN_B as f32) * t + MAIN_C as f32,
        }
    }

    /// Thrust (N) that voltage `v` (V) gives: the inverse of [`voltage`](Self::voltage) on the
    /// valid branch, in closed form with fixed work.
    ///
    /// * Tunnel (Eq 31): Cardano's formula for the monotonic cubic, which has exactly one real
    ///   root. Written for the depressed, scaled cubic y³ + 3y + 2h = 0 with T = 31.2 + σ y,
    ///   σ = 18.97 N, h = (V₀ − V)/(2K), V₀ = 30.6747 V, K = 3.4137 V: with
    ///   s = √(h² + 1), w = −h − sign(h)·s (no cancellation) and u = ∛w, y = u − 1/u.
    ///   ±∞ gives ±∞.
    /// * Main (Eq 32): the quadratic formula's root on the branch T ≥ T_fold, in the
    ///   cancellation-free form T = −2(V + 0.1962)/(0.1048 + √(0.012 (V_fold − V))).
    ///   A voltage at or above [`MAIN_V_FOLD`] returns [`MAIN_T_FOLD`]; −∞ gives +∞.
    ///
    /// NaN gives NaN. Accuracy (asserted by `tests/thruster.rs` against an f64 root of the
    /// same f32 voltage): within 1.2e-5 N over ±24 V, within 4 ulps of max(|T|, 32 N) over
    /// tunnel V ∈ [−400, 60] V and main V ∈ [−300, 0.6] V. The round trip
    /// `thrust(voltage(T))` adds the error of evaluating the polynomial in f32 divided by the
    /// slope; next to the main fold the inverse is ill-conditioned, ΔT ≈ √(ΔV/0.003).
    #[inline]
    pub fn thrust(self, v: f32) -> f32 {
        match self {
            ThrusterMap::Tunnel => tunnel_thrust(v),
            ThrusterMap::Main => main_thrust(v),
        }
    }

    /// The thrust envelope at a supply limit in polynomial units: the range of thrust
    /// reachable with voltages in [−`v_limit`, +`v_limit`], as (lowest, highest). In newtons:
    /// [`ThrustEnvelope::new`].
    ///
    /// In closed form: the tunnel map is increasing, so (T(−V), T(+V)); the main map is
    /// decreasing on its branch and folds, so (T_fold, T(−V)) once V ≥ V_fold = 0.719 V (the
    /// fold of Eq 32), T(+V) below that. The envelope is asymmetric: at ±24 V a tunnel thruster
    /// gives −9.165 … +20.102, the main thruster −17.467 … +73.306 (docs/thrusters.md#envelopes-at-the-supply-limit).
    #[inline]
    pub fn thrust_range(self, v_limit: f32) -> (f32, f32) {
        match self {
            ThrusterMap::Tunnel => (self.thrust(-v_limit), self.thrust(v_limit)),
            ThrusterMap::Main => (self.thrust(v_limit), self.thrust(-v_limit)),
        }
    }

    /// Voltage (V) for a thrust of `newtons` (N) when the polynomial reads `unit`:
    /// [`voltage`](Self::voltage)(`newtons` · [`ThrustUnit::per_newton`]).
    #[inline]
    pub fn voltage_of_newtons(self, unit: ThrustUnit, newtons: f32) -> f32 {
        self.voltage(newtons * unit.per_newton())
    }

    /// Thrust (N) that voltage `v` gives when the polynomial reads `unit`:
    /// [`thrust`](Self::thrust)(`v`) · [`ThrustUnit::newtons`].
    #[inline]
    pub fn newtons_of_voltage(self, unit: ThrustUnit, v: f32) -> f32 {
        self.thrust(v) * unit.newtons()
    }
}

/// The per-thruster thrust envelope [T_min, T_max] in **newtons** at a supply limit
/// (docs/thrusters.md#envelopes-at-the-supply-limit, docs/thrusters.md#the-thrust-unit): what each thruster can give with voltages in ±V_limit, in closed
/// form from the maps ([`ThrusterMap::thrust_range`]; the main thruster's lower end is the
/// fold of Eq 32) times the unit. Computed once at configuration time
/// ([`Controller::new`](crate::Controller::new)); the allocator keeps every thrust inside it.
///
/// At ±24 V, kgf (the default): main −171.29 … +718.89 N, tunnels −89.88 … +197.13 N;
/// newtons: main −17.47 … +73.31 N, tunnels −9.17 … +20.10 N.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThrustEnvelope {
    /// T_min per thruster (N), thruster order.
    pub min: [f32; THRUSTERS],
    /// T_max per thruster (N), thruster order.
    pub max: [f32; THRUSTERS],
}

impl ThrustEnvelope {
    /// The envelope of `maps` (thruster order) read in `unit` at ±`v_limit`.
    pub fn new(maps: &[ThrusterMap; THRUSTERS], unit: ThrustUnit, v_limit: f32) -> ThrustEnvelope {
        let mut e = ThrustEnvelope {
            min: [0.0; THRUSTERS],
            max: [0.0; THRUSTERS],
        };
        for (i, map) in maps.iter().enumerate() {
            let (lo, hi) = map.thrust_range(v_limit);
            e.min[i] = lo * unit.newtons();
            e.max[i] = hi * unit.newtons();
        }
        e
    }

    /// This envelope shrunk to `fraction` of itself about 0 N (each bound times `fraction`;
    /// every default envelope contains 0 N): the preflight check's margin (docs/thrusters.md#envelopes-at-the-supply-limit).
    pub fn scaled(&self, fraction: f32) -> ThrustEnvelope {
        ThrustEnvelope {
            min: self.min.map(|x| x * fraction),
            max: self.max.map(|x| x * fraction),
        }
    }

    /// True if every thrust lies in [min, max] (false for NaN).
    pub fn contains(&self, thrusts: &[f32; THRUSTERS]) -> bool {
        (0..THRUSTERS).all(|i| thrusts[i] >= self.min[i] && thrusts[i] <= self.max[i])
    }
}

fn tunnel_thrust(v: f32) -> f32 {
    if v.is_nan() || v.is_infinite() {
        // NaN → NaN, ±∞ → ±∞ (the map is increasing and unbounded).
        return v;
    }
    // y³ + 3y + 2h = 0.
    let h = 0.5 * ((TUN_V0 as f32 - v) / TUN_K as f32);
    // s = √(h² + 1) without overflow of h²: scale by m = max(|h|, 1).
    let m = if h.abs() > 1.0 { h.abs() } else { 1.0 };
    let hm = h / m;
    let im = 1.0 / m;
    let s = m * math::exact_sqrt(hm * hm + im * im);
    // Pick the sign that adds magnitudes: |w| ≥ s ≥ 1, so u ≠ 0.
    let w = if h >= 0.0 { -h - s } else { s - h };
    let u = math::cbrt(w);
    let y = u - 1.0 / u;
    TUN_T0 as f32 + TUN_SIGMA as f32 * y
}

/// [`ThrusterMap::Tunnel`]'s thrust of four voltages (Eq 31 inverted, polynomial units), bit
/// for bit `tunnel_thrust` of each: every lane takes the same f32 operations in the same order,
/// a step at a time over the four, so the four chains of divisions, a square root and a cube
/// root overlap (**Choice 570**: the simulator's four tunnels each period; nothing on the
/// target calls it). A lane that is not finite sends the four through the scalar map.
pub fn tunnel_thrusts(v: [f32; 4]) -> [f32; 4] {
    if !v.iter().all(|v| v.is_finite()) {
        return v.map(tunnel_thrust);
    }
    let h = lanes(|i| 0.5 * ((TUN_V0 as f32 - v[i]) / TUN_K as f32));
    let m = lanes(|i| if h[i].abs() > 1.0 { h[i].abs() } else { 1.0 });
    let hm = lanes(|i| h[i] / m[i]);
    let im = lanes(|i| 1.0 / m[i]);
    let s = lanes(|i| m[i] * math::exact_sqrt(hm[i] * hm[i] + im[i] * im[i]));
    let w = lanes(|i| {
        if h[i] >= 0.0 {
            -h[i] - s[i]
        } else {
            s[i] - h[i]
        }
    });
    let u = lanes(|i| math::cbrt(w[i]));
    lanes(|i| TUN_T0 as f32 + TUN_SIGMA as f32 * (u[i] - 1.0 / u[i]))
}

/// The four lanes of one step of [`tunnel_thrusts`].
#[inline(always)]
fn lanes(f: impl FnMut(usize) -> f32) -> [f32; 4] {
    core::array::from_fn(f)
}

fn main_thrust(v: f32) -> f32 {
    if v.is_nan() {
        return v;
    }
    if v >= MAIN_V_FOLD {
        // Above the fold no thrust gives this voltage; the closest is the fold itself.
        return MAIN_T_FOLD;
    }
    if v == f32::NEG_INFINITY {
        return f32::INFINITY;
    }
    // 0.003 T² + 0.1048 T + γ = 0 with γ = 0.1962 + V; discriminant
    // Δ = 0.1048² − 0.012 γ = 0.012 (V_fold − V) ≥ 0 (Sterbenz-exact near the fold).
    let gamma = v - MAIN_C as f32;
    let disc = (-4.0 * MAIN_A) as f32 * (MAIN_V_FOLD - v);
    let root = math::exact_sqrt(disc);
    // T = (−β + √Δ)/(2α) = −2γ/(β + √Δ); divide before doubling so huge |V| cannot overflow.
    -2.0 * (gamma / (-MAIN_B as f32 + root))
}

/// The AUV-150 layout of maps in thruster order ([`crate::effectiveness`]):
/// `[Main, Tunnel, Tunnel, Tunnel, Tunnel]`.
pub const fn default_maps() -> [ThrusterMap; THRUSTERS] {
    [
        ThrusterMap::Main,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
    ]
}

/// What the thrusters are actually driven with, and what that gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuation {
    /// Voltage applied to each thruster, V, within ±v_limit.
    pub voltages: [f32; THRUSTERS],
    /// Thrust each applied voltage actually gives (inverse map of the applied voltage), N.
    pub thrusts: [f32; THRUSTERS],
    /// Bit i set ⇔ thruster i did not get its command: voltage clamped at ±v_limit, main
    /// thruster commanded below T_fold, or a non-finite command.
    pub saturated: u8,
}

impl Actuation {
    /// Fail-safe "all thrusters off": 0 V and 0 N on every thruster, no saturation bit.
    ///
    /// 0 V is power off, so 0 N is reported — not the maps' value at 0 V (tunnel ≈ +0.68 N,
    /// main ≈ −1.98 N), which comes from the curve fits' offset (Eq 31 gives V(0) = −1.354 V,
    /// Eq 32 V(0) = −0.1962 V) and is an artefact of the fits.
    pub const OFF: Actuation = Actuation {
        voltages: [0.0; THRUSTERS],
        thrusts: [0.0; THRUSTERS],
        saturated: 0,
    };

    /// True if thruster `i` is saturated (false for `i` ≥ 5).
    pub const fn is_saturated(&self, i: usize) -> bool {
        i < THRUSTERS && self.saturated & (1 << i) != 0
    }
}

/// Mask with every thruster's saturation bit set.
pub const ALL_SATURATED: u8 = (1 << THRUSTERS) - 1;

/// Turns thrust commands (N) into voltages (V) within ±`v_limit` and reports the thrust (N)
/// those voltages actually give (docs/thrusters.md#saturation), with Eqs 31–32 read in
/// `unit`.
///
/// Per thruster i, with map `maps[i]` and c = cmd · [`ThrustUnit::per_newton`] (polynomial
/// units):
/// 1. a non-finite command → 0 V (power off), 0 N reported, bit i set;
/// 2. main thruster commanded below [`MAIN_T_FOLD`] → voltage [`MAIN_V_FOLD`] (the closest
///    thrust Eq 32 can give), bit i set;
/// 3. otherwise V = `maps[i].voltage(c)` (Eq 31/32);
/// 4. V clamped to [−`v_limit`, +`v_limit`], bit i set if the clamp acted;
/// 5. reported thrust: what the applied voltage gives, `maps[i].thrust(V)` ·
///    [`ThrustUnit::newtons`] — also when nothing saturated, so the report is always what the
///    applied voltage gives — except for a tunnel thruster whose voltage was not clamped, which
///    reports its command: the thrust its voltage gives to within the f32 rounding of Eq 31
///    (≤ 4.3 ulps of max(|T|, 1 N) against the f64 root, where the round trip through the
///    inverse is off by up to ≈ 1e-5 N; Choice 526). A clamped tunnel's is the thrust at the
///    limit, its envelope's bound.
///
/// The controller's commands come from the saturation-aware allocator
/// ([`crate::allocation::Allocator`]), which keeps them inside the [`ThrustEnvelope`]: then
/// nothing is clipped here beyond the f32 rounding of a thrust that sits exactly on its
/// envelope. Called with arbitrary commands it clips each thruster on its own.
///
/// `v_limit` must be finite and > 0; otherwise every thruster is switched off (0 V, 0 N) with
/// every bit set. Fixed work, never panics; for finite `v_limit` > 0 every output is finite
/// and |V| ≤ `v_limit`.
pub fn actuate(
    maps: &[ThrusterMap; THRUSTERS],
    unit: ThrustUnit,
    thrust_cmd: &[f32; THRUSTERS],
    v_limit: f32,
) -> Actuation {
    actuate_within(
        maps,
        unit,
        thrust_cmd,
        v_limit,
        &ThrustEnvelope::new(maps, unit, v_limit),
    )
}

/// [`actuate`] with the envelope of `maps` in `unit` at ±`v_limit` given
/// ([`ThrustEnvelope::new`], which the controller keeps): a clamped tunnel thruster reports its
/// bound (the thrust at the limit, the same bits), so the step never evaluates a tunnel's
/// inverse map (Choice 526).
#[inline]
pub fn actuate_within(
    maps: &[ThrusterMap; THRUSTERS],
    unit: ThrustUnit,
    thrust_cmd: &[f32; THRUSTERS],
    v_limit: f32,
    envelope: &ThrustEnvelope,
) -> Actuation {
    if !(v_limit.is_finite() && v_limit > 0.0) {
        return Actuation {
            saturated: ALL_SATURATED,
            ..Actuation::OFF
        };
    }
    let mut out = Actuation::OFF;
    for i in 0..THRUSTERS {
        let cmd = thrust_cmd[i];
        let (v, clamp) = command_voltage(maps[i], cmd * unit.per_newton(), v_limit);
        out.voltages[i] = v;
        out.thrusts[i] = match (maps[i], clamp) {
            (_, Clamp::Off) => 0.0,
            (ThrusterMap::Tunnel, Clamp::None) => cmd,
            (ThrusterMap::Tunnel, Clamp::Low) => envelope.min[i],
            (ThrusterMap::Tunnel, Clamp::High) => envelope.max[i],
            (ThrusterMap::Main, _) => maps[i].thrust(v) * unit.newtons(),
        };
        if clamp != Clamp::None {
            out.saturated |= 1 << i;
        }
    }
    out
}

/// Whether the thrust [`actuate`] reports for a thruster of map `map`, saturation bit
/// `saturated` and applied voltage `v` is the inverse map of that voltage to the bit
/// ([`ThrusterMap::newtons_of_voltage`]) for a simulator to take: for a voltage other than 0 V
/// (off reports 0 N, the map its fit's offset), on the main thruster only (Choice 498). An
/// unclamped tunnel reports its command (Choice 526); a clamped one its envelope's bound, and
/// a saturation mask that flags a tunnel (the law's `saturated`) does not say its voltage map
/// clamped it, so a tunnel is never taken.
///
/// A simulator that drives its thrusters with the law's report instead of evaluating the
/// inverse map of the voltage again (host-sim's Choice 402) may do so only where this is true:
/// a board in the loop is read by its voltages, and the same voltage must give the same thrust
/// whether the law ran on the host or on the board (PIL = SIL, Choice 525).
#[inline]
pub fn reports_inverse_map(map: ThrusterMap, _saturated: bool, v: f32) -> bool {
    v != 0.0 && map == ThrusterMap::Main
}

/// How a command's voltage was limited.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Clamp {
    /// Not at all: V is Eq 31/32 of the command.
    None,
    /// A non-finite command: 0 V.
    Off,
    /// At −v_limit.
    Low,
    /// At +v_limit, or the main thruster at its fold.
    High,
}

/// The voltage of one thruster's command `cmd` (polynomial units), `v_limit` finite and > 0,
/// and how it was limited (steps 1–4 of [`actuate`]).
#[inline]
fn command_voltage(map: ThrusterMap, cmd: f32, v_limit: f32) -> (f32, Clamp) {
    if !cmd.is_finite() {
        return (0.0, Clamp::Off);
    }
    let (v, clamp) = match map {
        ThrusterMap::Main if cmd < MAIN_T_FOLD => (MAIN_V_FOLD, Clamp::High),
        _ => (map.voltage(cmd), Clamp::None),
    };
    // voltage() of a finite command is never NaN (Horner steps are inf ∘ finite at worst),
    // and ±∞ is clamped here.
    if v > v_limit {
        (v_limit, Clamp::High)
    } else if v < -v_limit {
        (-v_limit, Clamp::Low)
    } else {
        (v, clamp)
    }
}
