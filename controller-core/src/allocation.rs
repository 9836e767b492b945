//! Thrust allocation and thruster maps (AUV150.md §5, Eqs 31–32 of Roy et al. 2013).
//!
//! This module owns everything between the control law's body-frame wrench
//! τ = [X Y Z K M N]ᵀ (N, N·m) and the five thruster voltages (V):
//!
//! * the thruster layout [`ThrusterGeometry`] (positions in m, unit directions, body frame) — the
//!   geometry is **not in the paper**; its [`Default`] is AUV150.md §5 **Choice**;
//! * the allocation [`Allocation`]: the 6×5 matrix B (τ = B·T), and the inverse of its 5×5
//!   sub-matrix over the actuated rows (X, Y, Z, M, N) — roll K is not actuated and τ_K is
//!   dropped;
//! * the force→voltage maps [`ThrusterMap`] (Eq 31 tunnel, Eq 32 main) and their closed-form
//!   inverses;
//! * saturation [`actuate`]: voltage clamp at the supply limit, the main thruster's fold, and the
//!   thrust the clamped voltage actually gives ([`Actuation`]).
//!
//! Thruster order everywhere: `[main, vertical fore, vertical aft, horizontal fore,
//! horizontal aft]` (indices [`MAIN`], [`VERT_FORE`], [`VERT_AFT`], [`HORZ_FORE`],
//! [`HORZ_AFT`]). Thrust is in newtons (AUV150.md §8: the paper does not state the unit of
//! Eqs 31–32; we read newtons).
//!
//! Everything on the per-tick path ([`Allocation::thrusts`], [`Allocation::wrench`],
//! [`ThrusterMap::voltage`], [`ThrusterMap::thrust`], [`actuate`]) is fixed work: no loops that
//! depend on data, no iteration to convergence, no heap, no panics.
//!
//! # Square roots in the inverse maps
//!
//! The inverse maps call [`libm::sqrtf`] directly instead of [`crate::math::sqrt`]. Under the
//! `micromath` feature `math::sqrt` has up to ≈ 6 % relative error; measured through the
//! inverse maps over the ±24 V range that is a thrust error of up to 1.85 N (4.5 %) on the main
//! thruster and 0.46 N (2.3 %) on a tunnel thruster (Cardano's square root feeds a
//! cancellation), whose whole ±24 V range is only −9.2…+20.1 N; the round trip
//! `thrust(voltage(T))` is off by up to 11.7 N at T = 218 N. The reported thrust is the
//! saturation-honesty signal (AUV150.md §5), so it must not depend on the backend; the cost is
//! five `sqrtf` per tick. With libm the inverse is within 1.2e-5 N of the exact root over
//! ±24 V (both backends, since this module does not switch). `cbrt` is libm in both backends
//! and goes through [`crate::math::cbrt`].

use core::fmt;

use nalgebra::{Matrix5, Matrix6x5, Vector5, Vector6};

use crate::math;

/// Number of thrusters.
pub const THRUSTERS: usize = 5;
/// Index of the stern main thruster (along +x).
pub const MAIN: usize = 0;
/// Index of the fore vertical tunnel thruster (along +z).
pub const VERT_FORE: usize = 1;
/// Index of the aft vertical tunnel thruster (along +z).
pub const VERT_AFT: usize = 2;
/// Index of the fore horizontal tunnel thruster (along +y).
pub const HORZ_FORE: usize = 3;
/// Index of the aft horizontal tunnel thruster (along +y).
pub const HORZ_AFT: usize = 4;

/// Default supply limit of the board, V (AUV150.md §5: ±24 V).
pub const DEFAULT_V_LIMIT: f32 = 24.0;

/// Largest accepted ∞-norm condition number κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ of the 5×5 allocation
/// matrix (f32 has ≈ 7 digits; κ = 10⁴ leaves ≈ 3). The AUV-150 default has κ∞ = 3.6.
pub const MAX_CONDITION: f32 = 1.0e4;

/// Allowed deviation of a direction's norm from 1: |‖d‖ − 1| ≤ this.
pub const UNIT_TOLERANCE: f32 = 1.0e-3;

// ---------------------------------------------------------------------------------------------
// Thruster maps (Eqs 31–32)
// ---------------------------------------------------------------------------------------------

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
/// √(P/(3A)) = √119.9644… (no const sqrt; checked below).
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
/// Both maps are the paper's experimental curve fits, used as printed (AUV150.md §5).
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
    /// NaN gives NaN. Accuracy (measured against an f64 root of the same f32 voltage): within
    /// 1.2e-5 N over ±24 V, within 2e-5 N over tunnel V ∈ [−400, 60] V (T ∈ [−60, 60] N) and
    /// main V ∈ [−30, 0.6] V, and within 4 ulps of max(|T|, 32 N) beyond. The round trip
    /// `thrust(voltage(T))` adds the error of evaluating the polynomial in f32 divided by the
    /// slope (tests/allocation.rs); next to the main fold the inverse is ill-conditioned,
    /// ΔT ≈ √(ΔV/0.003).
    #[inline]
    pub fn thrust(self, v: f32) -> f32 {
        match self {
            ThrusterMap::Tunnel => tunnel_thrust(v),
            ThrusterMap::Main => main_thrust(v),
        }
    }

    /// Range of thrust (N) reachable with voltages in [−`v_limit`, +`v_limit`], as
    /// (lowest, highest).
    #[inline]
    pub fn thrust_range(self, v_limit: f32) -> (f32, f32) {
        match self {
            ThrusterMap::Tunnel => (self.thrust(-v_limit), self.thrust(v_limit)),
            ThrusterMap::Main => (self.thrust(v_limit), self.thrust(-v_limit)),
        }
    }
}

/// Exact square root for the inverse maps (see the module docs, "Square roots in the inverse
/// maps": micromath's ≈ 6 % error is not acceptable for the reported thrust).
#[inline]
fn exact_sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
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
    let s = m * exact_sqrt(hm * hm + im * im);
    // Pick the sign that adds magnitudes: |w| ≥ s ≥ 1, so u ≠ 0.
    let w = if h >= 0.0 { -h - s } else { s - h };
    let u = math::cbrt(w);
    let y = u - 1.0 / u;
    TUN_T0 as f32 + TUN_SIGMA as f32 * y
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
    let root = exact_sqrt(disc);
    // T = (−β + √Δ)/(2α) = −2γ/(β + √Δ); divide before doubling so huge |V| cannot overflow.
    -2.0 * (gamma / (-MAIN_B as f32 + root))
}

/// The AUV-150 layout of maps in thruster order: `[Main, Tunnel, Tunnel, Tunnel, Tunnel]`.
pub const fn default_maps() -> [ThrusterMap; THRUSTERS] {
    [
        ThrusterMap::Main,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
        ThrusterMap::Tunnel,
    ]
}

// ---------------------------------------------------------------------------------------------
// Saturation
// ---------------------------------------------------------------------------------------------

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

    /// Fail-safe "all thrusters off" (same as [`Actuation::OFF`]).
    pub const fn off() -> Actuation {
        Actuation::OFF
    }

    /// True if any thruster is saturated.
    pub const fn any_saturated(&self) -> bool {
        self.saturated != 0
    }

    /// True if thruster `i` is saturated (false for `i` ≥ 5).
    pub const fn is_saturated(&self, i: usize) -> bool {
        i < THRUSTERS && self.saturated & (1 << i) != 0
    }
}

/// Mask with every thruster's saturation bit set.
pub const ALL_SATURATED: u8 = (1 << THRUSTERS) - 1;

/// Turns thrust commands (N) into voltages (V) within ±`v_limit` and reports the thrust those
/// voltages actually give (AUV150.md §5, "Saturation").
///
/// Per thruster i, with map `maps[i]`:
/// 1. a non-finite command → 0 V (power off), 0 N reported, bit i set;
/// 2. main thruster commanded below [`MAIN_T_FOLD`] → voltage [`MAIN_V_FOLD`] (the closest
///    thrust Eq 32 can give), bit i set;
/// 3. otherwise V = `maps[i].voltage(cmd)` (Eq 31/32);
/// 4. V clamped to [−`v_limit`, +`v_limit`], bit i set if the clamp acted;
/// 5. reported thrust = `maps[i].thrust(V)` of the clamped voltage — also when nothing
///    saturated, so the report is always what the applied voltage gives (within the inverse
///    map's f32 round trip, ~1e-5 N).
///
/// `v_limit` must be finite and > 0; otherwise every thruster is switched off (0 V, 0 N) with
/// every bit set. Fixed work, never panics; for finite `v_limit` > 0 every output is finite
/// and |V| ≤ `v_limit`.
pub fn actuate(
    maps: &[ThrusterMap; THRUSTERS],
    thrust_cmd: &[f32; THRUSTERS],
    v_limit: f32,
) -> Actuation {
    if !(v_limit.is_finite() && v_limit > 0.0) {
        return Actuation {
            saturated: ALL_SATURATED,
            ..Actuation::OFF
        };
    }
    let mut out = Actuation::OFF;
    for i in 0..THRUSTERS {
        let (v, t, sat) = actuate_one(maps[i], thrust_cmd[i], v_limit);
        out.voltages[i] = v;
        out.thrusts[i] = t;
        if sat {
            out.saturated |= 1 << i;
        }
    }
    out
}

/// One thruster of [`actuate`]; `v_limit` is finite and > 0.
#[inline]
fn actuate_one(map: ThrusterMap, cmd: f32, v_limit: f32) -> (f32, f32, bool) {
    if !cmd.is_finite() {
        return (0.0, 0.0, true);
    }
    let (mut v, mut sat) = match map {
        ThrusterMap::Main if cmd < MAIN_T_FOLD => (MAIN_V_FOLD, true),
        _ => (map.voltage(cmd), false),
    };
    // voltage() of a finite command is never NaN (Horner steps are inf ∘ finite at worst),
    // and ±∞ is clamped here.
    if v > v_limit {
        v = v_limit;
        sat = true;
    } else if v < -v_limit {
        v = -v_limit;
        sat = true;
    }
    (v, map.thrust(v), sat)
}

// ---------------------------------------------------------------------------------------------
// Geometry and allocation
// ---------------------------------------------------------------------------------------------

/// Thruster positions (m) and unit thrust directions, body frame (origin CO, x forward,
/// y starboard, z down), in thruster order.
///
/// The geometry is not in the paper: [`Default`] is AUV150.md §5 **Choice** — main at
/// x = −2.43 m along +x; vertical tunnels at x = +1.8 m (fore) and −1.8 m (aft) along +z;
/// horizontal tunnels at x = +1.8 m (fore) and −1.8 m (aft) along +y; all on the centre line.
/// It is configuration: [`Allocation::new`] accepts any geometry that passes its checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThrusterGeometry {
    /// Position rᵢ of thruster i, m.
    pub position: [[f32; 3]; THRUSTERS],
    /// Unit thrust direction dᵢ of thruster i (positive thrust pushes the vehicle along dᵢ).
    pub direction: [[f32; 3]; THRUSTERS],
}

impl ThrusterGeometry {
    /// The AUV150.md §5 **Choice** layout (see the type's docs).
    pub const AUV150: ThrusterGeometry = ThrusterGeometry {
        position: [
            [-2.43, 0.0, 0.0],
            [1.8, 0.0, 0.0],
            [-1.8, 0.0, 0.0],
            [1.8, 0.0, 0.0],
            [-1.8, 0.0, 0.0],
        ],
        direction: [
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
    };
}

impl Default for ThrusterGeometry {
    fn default() -> Self {
        ThrusterGeometry::AUV150
    }
}

/// Why a thruster geometry was rejected by [`Allocation::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AllocationError {
    /// A position or direction component is NaN or infinite.
    NonFinite {
        /// Thruster index.
        thruster: usize,
    },
    /// |‖dᵢ‖ − 1| > [`UNIT_TOLERANCE`], checked as ‖dᵢ‖² outside [(1 − tol)², (1 + tol)²].
    NotUnitDirection {
        /// Thruster index.
        thruster: usize,
        /// ‖dᵢ‖².
        norm_squared: f32,
    },
    /// The 5×5 matrix over (X, Y, Z, M, N) has no inverse (`try_inverse` failed or gave a
    /// non-finite matrix).
    Singular,
    /// κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ exceeds the limit.
    IllConditioned {
        /// κ∞(B₅).
        condition: f32,
        /// The limit, [`MAX_CONDITION`].
        limit: f32,
    },
}

impl fmt::Display for AllocationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            AllocationError::NonFinite { thruster } => write!(
                f,
                "thruster geometry check failed: thruster {thruster} has a non-finite position or direction"
            ),
            AllocationError::NotUnitDirection {
                thruster,
                norm_squared,
            } => write!(
                f,
                "thruster geometry check failed: direction of thruster {thruster} is not a unit vector: |d|^2 = {norm_squared}, need ||d| - 1| <= {UNIT_TOLERANCE}"
            ),
            AllocationError::Singular => write!(
                f,
                "allocation check failed: the 5x5 matrix over (X, Y, Z, M, N) is singular"
            ),
            AllocationError::IllConditioned { condition, limit } => write!(
                f,
                "allocation check failed: condition number (inf-norm) of the 5x5 matrix over (X, Y, Z, M, N) is {condition}, limit {limit}"
            ),
        }
    }
}

impl core::error::Error for AllocationError {}

/// Rows of τ = [X Y Z K M N] that are actuated (K, roll, is not).
const ACTUATED_ROWS: [usize; 5] = [0, 1, 2, 4, 5];

/// Thrust allocation τ ↔ T for a fixed thruster geometry, built once at configuration time.
///
/// B is the 6×5 matrix with column i = [dᵢ; rᵢ × dᵢ] (rows X Y Z K M N), so τ = B·T.
/// Roll is not actuated: the K row is dropped, the remaining 5×5 matrix B₅ (rows X, Y, Z, M, N)
/// is inverted once in [`new`](Self::new), and [`thrusts`](Self::thrusts) is B₅⁻¹·[X Y Z M N]ᵀ.
///
/// For the default geometry (AUV150.md §5 **Choice**) this is the closed form, N:
///
/// ```text
/// T_main      = X
/// T_vert,fore = (Z − M/1.8)/2      T_vert,aft = (Z + M/1.8)/2
/// T_horz,fore = (Y + N/1.8)/2      T_horz,aft = (Y − N/1.8)/2
/// ```
///
/// (a downward (+z) tunnel thrust at x = +1.8 m gives M = −1.8·T, a starboard (+y) one gives
/// N = +1.8·T), and the K row of B is zero (all thrusters on the centre line).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allocation {
    b: Matrix6x5<f32>,
    b5_inv: Matrix5<f32>,
    condition: f32,
}

impl Allocation {
    /// Builds B and inverts B₅. Rejects (with the check and its numbers): non-finite geometry,
    /// a direction with |‖d‖ − 1| > [`UNIT_TOLERANCE`], a singular B₅, and
    /// κ∞(B₅) > [`MAX_CONDITION`].
    pub fn new(geometry: &ThrusterGeometry) -> Result<Allocation, AllocationError> {
        let lo = (1.0 - UNIT_TOLERANCE) * (1.0 - UNIT_TOLERANCE);
        let hi = (1.0 + UNIT_TOLERANCE) * (1.0 + UNIT_TOLERANCE);
        let mut b = Matrix6x5::<f32>::zeros();
        for i in 0..THRUSTERS {
            let r = geometry.position[i];
            let d = geometry.direction[i];
            if !r.iter().chain(d.iter()).all(|x| x.is_finite()) {
                return Err(AllocationError::NonFinite { thruster: i });
            }
            let n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if !(lo..=hi).contains(&n2) {
                return Err(AllocationError::NotUnitDirection {
                    thruster: i,
                    norm_squared: n2,
                });
            }
            let m = [
                r[1] * d[2] - r[2] * d[1],
                r[2] * d[0] - r[0] * d[2],
                r[0] * d[1] - r[1] * d[0],
            ];
            for k in 0..3 {
                b[(k, i)] = d[k];
                b[(k + 3, i)] = m[k];
            }
        }
        let b5 = Matrix5::<f32>::from_fn(|row, col| b[(ACTUATED_ROWS[row], col)]);
        let b5_inv = b5.try_inverse().ok_or(AllocationError::Singular)?;
        if !b5_inv.iter().all(|x| x.is_finite()) {
            return Err(AllocationError::Singular);
        }
        let condition = inf_norm(&b5) * inf_norm(&b5_inv);
        if condition.is_nan() || condition > MAX_CONDITION {
            return Err(AllocationError::IllConditioned {
                condition,
                limit: MAX_CONDITION,
            });
        }
        Ok(Allocation {
            b,
            b5_inv,
            condition,
        })
    }

    /// Thrusts T (N, thruster order) = B₅⁻¹·[X Y Z M N]ᵀ for the wrench `tau` = [X Y Z K M N]
    /// (N, N·m). τ_K is ignored (roll is not actuated). Fixed work; a non-finite τ gives
    /// non-finite thrusts, which [`actuate`] turns into 0 V with the bits set.
    #[inline]
    pub fn thrusts(&self, tau: &Vector6<f32>) -> [f32; THRUSTERS] {
        let tau5 = Vector5::new(tau[0], tau[1], tau[2], tau[4], tau[5]);
        let t = self.b5_inv * tau5;
        [t[0], t[1], t[2], t[3], t[4]]
    }

    /// Wrench τ = B·T (N, N·m) that `thrusts` (N) produce, all six rows including K (zero for
    /// the default geometry).
    #[inline]
    pub fn wrench(&self, thrusts: &[f32; THRUSTERS]) -> Vector6<f32> {
        self.b * Vector5::from(*thrusts)
    }

    /// The 6×5 allocation matrix B (rows X Y Z K M N, column i = [dᵢ; rᵢ × dᵢ]).
    pub fn matrix(&self) -> Matrix6x5<f32> {
        self.b
    }

    /// B₅⁻¹, the 5×5 inverse over the rows (X, Y, Z, M, N).
    pub fn inverse(&self) -> Matrix5<f32> {
        self.b5_inv
    }

    /// κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ (3.6 for the default geometry: 3.6 · 1).
    pub fn condition(&self) -> f32 {
        self.condition
    }
}

impl Default for Allocation {
    /// Allocation for [`ThrusterGeometry::AUV150`] (always accepted: checked in the tests).
    fn default() -> Self {
        // The default geometry is fixed and passes every check (tests/allocation.rs); the
        // fallback is the same matrix in closed form, so this never panics.
        Allocation::new(&ThrusterGeometry::AUV150).unwrap_or_else(|_| closed_form_auv150())
    }
}

/// The default geometry's B and B₅⁻¹ written out (see [`Allocation`]'s docs).
fn closed_form_auv150() -> Allocation {
    let l = 1.8f32;
    #[rustfmt::skip]
    let b = Matrix6x5::new(
        1.0, 0.0, 0.0, 0.0, 0.0, // X
        0.0, 0.0, 0.0, 1.0, 1.0, // Y
        0.0, 1.0, 1.0, 0.0, 0.0, // Z
        0.0, 0.0, 0.0, 0.0, 0.0, // K
        0.0, -l, l, 0.0, 0.0,    // M
        0.0, 0.0, 0.0, l, -l,    // N
    );
    let h = 0.5f32;
    let g = 0.5 / l;
    #[rustfmt::skip]
    let b5_inv = Matrix5::new(
        //X   Y    Z    M    N
        1.0, 0.0, 0.0, 0.0, 0.0, // main
        0.0, 0.0, h, -g, 0.0,    // vertical fore
        0.0, 0.0, h, g, 0.0,     // vertical aft
        0.0, h, 0.0, 0.0, g,     // horizontal fore
        0.0, h, 0.0, 0.0, -g,    // horizontal aft
    );
    Allocation {
        b,
        b5_inv,
        // ‖B₅‖∞ = 2l (M and N rows), ‖B₅⁻¹‖∞ = 1 (main row; h + g = 0.78 < 1).
        condition: 2.0 * l,
    }
}

/// ∞-norm (largest absolute row sum) of a 5×5 matrix.
fn inf_norm(m: &Matrix5<f32>) -> f32 {
    let mut best = 0.0f32;
    for r in 0..5 {
        let mut s = 0.0f32;
        for c in 0..5 {
            s += m[(r, c)].abs();
        }
        if s > best {
            best = s;
        }
    }
    best
}
