//! Configuration-time bounds over the Table-3 parameter box: the constants of δ(e,t) (Eq 29,
//! docs/law.md#the-uncertainty-bound-eq-29) and the feasibility checks of Assumption 2 (Eq 20) and Theorem 2 (Eq 25).
//!
//! Everything here runs once, when a configuration is validated, never inside `update`. The
//! suprema over the box are taken over its 2⁹ corners (every Δ at its lower or upper end). The
//! quantities are norms of M(p) − M₀, of M(p)⁻¹ and of g(p) − g₀; for the AUV-150's nearly
//! diagonal M their entries are monotone in each parameter, so the extremes sit at corners.
//! The tests check this against dense random sampling of the box's interior.

use nalgebra::{Matrix6, RealField, SymmetricEigen, Vector6};

use crate::model::{self, ParamVariation, VehicleParams};

pub use crate::model::VARIED_PARAMETERS;

/// A box of parameter variations: every Δ lies in [lower, upper], component by component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamBox<T> {
    pub lower: ParamVariation<T>,
    pub upper: ParamVariation<T>,
}

impl ParamBox<f64> {
    /// Table 3's box: from no variation up to the "max" column. **Choice**: the paper's
    /// variations are all additions (payload), so the lower end is zero, not −max.
    pub fn table3() -> Self {
        ParamBox {
            lower: ParamVariation::default(),
            upper: ParamVariation::TABLE3_MAX,
        }
    }
}

impl<T: RealField + Copy> ParamBox<T> {
    /// Converts to another scalar type.
    pub fn cast<U: RealField + Copy>(&self, f: impl Fn(T) -> U + Copy) -> ParamBox<U> {
        ParamBox {
            lower: self.lower.cast(f),
            upper: self.upper.cast(f),
        }
    }

    /// Corner `index` (0 ≤ index < 2⁹): bit i of `index` puts parameter i at its upper end.
    pub fn corner(&self, index: u32) -> ParamVariation<T> {
        let lo = self.lower.to_array();
        let hi = self.upper.to_array();
        let mut c = lo;
        for i in 0..VARIED_PARAMETERS {
            if index & (1 << i) != 0 {
                c[i] = hi[i];
            }
        }
        ParamVariation::from_array(c)
    }

    /// The point at fractions `f` ∈ \[0, 1\]⁹ of the way from lower to upper.
    pub fn lerp(&self, f: &[T; VARIED_PARAMETERS]) -> ParamVariation<T> {
        let lo = self.lower.to_array();
        let hi = self.upper.to_array();
        let mut c = lo;
        for i in 0..VARIED_PARAMETERS {
            c[i] = lo[i] + (hi[i] - lo[i]) * f[i];
        }
        ParamVariation::from_array(c)
    }

    /// Number of corners, 2⁹.
    pub const CORNERS: u32 = 1 << VARIED_PARAMETERS;

    /// Finite, and lower ≤ upper component by component.
    pub fn is_valid(&self) -> bool {
        let lo = self.lower.to_array();
        let hi = self.upper.to_array();
        lo.iter()
            .zip(hi.iter())
            .all(|(l, h)| l.is_finite() && h.is_finite() && l <= h)
    }
}

/// Why the bounds could not be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoundsError {
    /// Some M(p) in the box is not positive definite (its smallest eigenvalue is given).
    MassNotPositiveDefinite { corner: u32, min_eigenvalue: f64 },
    /// The symmetric eigen-solver did not converge (non-finite or absurd parameters).
    EigenSolver,
}

/// Theorem 2 (Eq 25 with Theorem 1) as printed: λmax_M λmin_M / (λmin_M − λmax_M) <
/// λmin_M + λmin(ΔM̄), with the eigenvalues of the nominal M (equal to those of M̄ at level
/// attitude, where J is orthogonal) and the smallest eigenvalue of ΔM over the box.
///
/// As printed the left side is negative whenever λmin_M < λmax_M, so the criterion only asks
/// that M₀ + ΔM keep its smallest eigenvalue above that negative number. We evaluate it exactly
/// as printed and report both sides; Assumption 2's β̂ is the binding check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Theorem2<T> {
    pub lambda_min_m: T,
    pub lambda_max_m: T,
    pub lambda_min_delta_m: T,
    pub lhs: T,
    pub rhs: T,
}

impl<T: RealField + Copy> Theorem2<T> {
    pub fn holds(&self) -> bool {
        self.lhs < self.rhs
    }
}

/// Suprema over the parameter box, computed once at configuration time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UncertaintyBounds<T> {
    /// ΔM = sup‖M(p) − M(p₀)‖₂.
    pub delta_m: T,
    /// Δg = sup over the box and every attitude of ‖g(p, η) − g(p₀, η)‖.
    pub delta_g: T,
    /// c_b = sup‖S₀ M(p)⁻¹‖₂, S₀ selecting the controlled rows u, v, w, q, r.
    pub b_controlled: T,
    /// sup‖M(p)⁻¹‖₂, the literal full bound (dominated by the unactuated roll inertia).
    pub b_full: T,
    /// β̂ = sup‖S₀ (M(p)⁻¹ M(p₀) − I)‖₂ (Assumption 2, Eq 20, controlled rows).
    pub beta_hat: T,
    /// Theorem 2 as printed.
    pub theorem2: Theorem2<T>,
}

fn eigenvalues<T: RealField + Copy>(m: Matrix6<T>) -> Result<Vector6<T>, BoundsError> {
    SymmetricEigen::try_new(m, T::default_epsilon(), 10_000)
        .map(|e| e.eigenvalues)
        .ok_or(BoundsError::EigenSolver)
}

/// ‖A‖₂ = √λmax(AᵀA).
pub fn spectral_norm<T: RealField + Copy>(a: &Matrix6<T>) -> Result<T, BoundsError> {
    let ev = eigenvalues(a.transpose() * a)?;
    Ok(ev.max().max(T::zero()).sqrt())
}

/// Zeroes the roll row: S₀ as a 6×6 selector (same norm as the 5×6 product).
fn controlled_rows<T: RealField + Copy>(mut a: Matrix6<T>) -> Matrix6<T> {
    a.row_mut(crate::axes::ROLL).fill(T::zero());
    a
}

/// sup over attitudes of ‖g(p, η) − g(p₀, η)‖, in closed form.
///
/// The force part is (W − W₀)·[sθ, −cθsφ, −cθcφ], a unit vector times |ΔW|. The moment part is
/// cθcφ·v₁ + cθsφ·v₂ + sθ·v₃ with v₁ = [−Δm_y, Δm_x, 0], v₂ = [Δk₄, 0, −Δm_x],
/// v₃ = [0, Δk₅, −Δm_y] (Δm_x = Δ(x_G W − x_B B), …); since (cθcφ, cθsφ, sθ) is a unit
/// vector, Cauchy–Schwarz bounds its norm by √(‖v₁‖² + ‖v₂‖² + ‖v₃‖²).
pub fn restoring_mismatch_bound<T: RealField + Copy>(
    p0: &VehicleParams<T>,
    p: &VehicleParams<T>,
) -> T {
    let (w0, w) = (p0.weight(), p.weight());
    let (b0, b) = (p0.buoyancy, p.buoyancy);
    let force = (w - b) - (w0 - b0);
    let dmx = (p.r_g[0] * w - p.r_b_xy[0] * b) - (p0.r_g[0] * w0 - p0.r_b_xy[0] * b0);
    let dmy = (p.r_g[1] * w - p.r_b_xy[1] * b) - (p0.r_g[1] * w0 - p0.r_b_xy[1] * b0);
    let dk4 = (p.r_g[2] * w - p.z_b_roll * b) - (p0.r_g[2] * w0 - p0.z_b_roll * b0);
    let dk5 = (p.r_g[2] * w - p.z_b_pitch * b) - (p0.r_g[2] * w0 - p0.z_b_pitch * b0);
    let two = T::one() + T::one();
    (force * force + two * dmx * dmx + two * dmy * dmy + dk4 * dk4 + dk5 * dk5).sqrt()
}

impl<T: RealField + Copy> UncertaintyBounds<T> {
    /// Evaluates every bound over the corners of `bx` around `nominal`.
    pub fn compute(nominal: &VehicleParams<T>, bx: &ParamBox<T>) -> Result<Self, BoundsError> {
        let m0 = model::mass_matrix(nominal);
        let ev0 = eigenvalues(m0)?;
        let (lmin0, lmax0) = (ev0.min(), ev0.max());
        if lmin0 <= T::zero() {
            return Err(BoundsError::MassNotPositiveDefinite {
                corner: 0,
                min_eigenvalue: nalgebra::try_convert(lmin0).unwrap_or(f64::NAN),
            });
        }
        let mut out = UncertaintyBounds {
            delta_m: T::zero(),
            delta_g: T::zero(),
            b_controlled: T::zero(),
            b_full: T::zero(),
            beta_hat: T::zero(),
            theorem2: Theorem2 {
                lambda_min_m: lmin0,
                lambda_max_m: lmax0,
                lambda_min_delta_m: T::zero(),
                lhs: lmax0 * lmin0 / (lmin0 - lmax0),
                rhs: T::zero(),
            },
        };
        let mut lmin_dm: Option<T> = None;
        for index in 0..ParamBox::<T>::CORNERS {
            let p = nominal.with_variation(&bx.corner(index));
            let m = model::mass_matrix(&p);
            let dm = m - m0;
            let ev = eigenvalues(m)?;
            if ev.min() <= T::zero() {
                return Err(BoundsError::MassNotPositiveDefinite {
                    corner: index,
                    min_eigenvalue: nalgebra::try_convert(ev.min()).unwrap_or(f64::NAN),
                });
            }
            let minv = m.try_inverse().ok_or(BoundsError::EigenSolver)?;
            let evd = eigenvalues(dm)?;
            let dm_norm = evd.amax();
            lmin_dm = Some(match lmin_dm {
                Some(l) => l.min(evd.min()),
                None => evd.min(),
            });
            out.delta_m = out.delta_m.max(dm_norm);
            out.delta_g = out.delta_g.max(restoring_mismatch_bound(nominal, &p));
            out.b_controlled = out.b_controlled.max(spectral_norm(&controlled_rows(minv))?);
            out.b_full = out.b_full.max(spectral_norm(&minv)?);
            let gamma = minv * m0 - Matrix6::identity();
            out.beta_hat = out.beta_hat.max(spectral_norm(&controlled_rows(gamma))?);
        }
        let lmin_dm = lmin_dm.unwrap_or(T::zero());
        out.theorem2.lambda_min_delta_m = lmin_dm;
        out.theorem2.rhs = lmin0 + lmin_dm;
        Ok(out)
    }
}
