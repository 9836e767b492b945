//! The full nonlinear 6-DOF AUV-150 plant of Eq (1), in f64, with Fossen's current model:
//!
//! M_RB ν̇ + C_RB(ν) ν + M_A ν̇_r + C_A(ν_r) ν_r + D(ν_r) ν_r + g(η) = τ,  η̇ = J(η) ν,
//!
//! with ν_r = ν − ν_c, ν_c = [Rᵀ v_c; 0] for an earth-fixed current v_c (docs/model.md#the-ocean-current-and-the-simulated-plant). The
//! matrices come from `controller_core::model` with the plant's (varying) parameters, so the
//! plant and the controller share one implementation of Eq (1) and differ only in parameters.
//!
//! For a current that is constant over a step, ν̇_c = [−ω × Rᵀv_c; 0]. The payload's dm/dt
//! is not modelled (the paper's variations are parameter changes, not mass flow).

use controller_core::kinematics::{self, Attitude, GimbalLock, Kinematics};
use controller_core::model::{self, VehicleParams};
use nalgebra::{Matrix6, Vector3, Vector6};

mod current;
mod trim;
mod variation;

pub use current::{CurrentModel, OceanCurrent};
pub use trim::{roll_moments, static_heel, trimmed};
pub use variation::VariationProfile;

/// Position and velocity of the vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantState {
    /// η = [x y z φ θ ψ] (NED, m, rad).
    pub eta: Vector6<f64>,
    /// ν = [u v w p q r] (body, m/s, rad/s).
    pub nu: Vector6<f64>,
}

impl PlantState {
    pub fn is_finite(&self) -> bool {
        self.eta.iter().chain(self.nu.iter()).all(|x| x.is_finite())
    }
}

/// How the plant is stepped between control periods (scenario key `plant_integrator`).
///
/// **Choice 542** (docs/simulator.md#the-plant-step-and-the-current): classical RK4 is the
/// default and what Table 1 and the shipped missions fly; the explicit midpoint rule is the
/// study-grade integrator a campaign's `plant_step = "control-period"` flies with (two
/// derivatives a period instead of four), agreeing with the 1 ms RK4 within the study
/// tolerance (`studies::campaign::STUDY_PATH_TOLERANCE`, tests/study_step.rs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Classical fourth-order Runge–Kutta ([`Plant::rk4_step`]).
    #[default]
    Rk4,
    /// The explicit midpoint rule, second order ([`Plant::midpoint_step`]).
    Midpoint,
}

impl Integrator {
    /// Every integrator, in the order the scenario key lists them.
    pub const ALL: [Integrator; 2] = [Integrator::Rk4, Integrator::Midpoint];

    /// The scenario key's value.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Rk4 => "rk4",
            Integrator::Midpoint => "midpoint",
        }
    }

    /// The integrator named `name`, if any.
    pub fn from_name(name: &str) -> Option<Integrator> {
        Integrator::ALL.into_iter().find(|i| i.name() == name)
    }
}

/// Which physical terms the plant includes (all on for simulation; tests switch some off to
/// check invariants).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantTerms {
    pub damping: bool,
    pub restoring: bool,
}

impl Default for PlantTerms {
    fn default() -> Self {
        PlantTerms {
            damping: true,
            restoring: true,
        }
    }
}

/// The plant at one set of parameters: M = M_RB + M_A, its Cholesky factor and M⁻¹ are formed when
/// the parameters are set ([`Plant::new`], [`Plant::set_params`]) and reused by every
/// derivative until they change.
///
/// **Choice 80** (docs/model.md#evaluating-the-plant-fast): a simulation keeps one `Plant` and hands it the parameters of
/// every step; M is refactorised only when they differ from the last ones (`==` on every
/// field), so a constant or staircase profile factorises once per value, not once per step.
#[derive(Clone, Debug)]
pub struct Plant {
    params: VehicleParams<f64>,
    /// M = M_RB + M_A.
    m: Matrix6<f64>,
    m_rb: Matrix6<f64>,
    /// The diagonal of M_A (Eq 1's added mass is diagonal, `model::added_mass`).
    m_a: Vector6<f64>,
    /// M⁻¹, from M's Cholesky factor: ν̇ = M⁻¹ · rhs is 36 independent products, where the
    /// factor's two triangular solves are a chain of 12 dependent divisions.
    m_inv: Matrix6<f64>,
    terms: PlantTerms,
    factorisations: u64,
}

/// The plant cannot go on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlantError {
    /// M(p) is not positive definite for these parameters.
    MassNotPositiveDefinite,
    /// Pitch reached ±90°, where the Euler-angle kinematics are singular.
    GimbalLock,
}

impl From<GimbalLock> for PlantError {
    fn from(_: GimbalLock) -> Self {
        PlantError::GimbalLock
    }
}

impl std::fmt::Display for PlantError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlantError::MassNotPositiveDefinite => write!(f, "plant M(p) is not positive definite"),
            PlantError::GimbalLock => {
                write!(f, "plant pitch reached ±90° (Euler kinematics singular)")
            }
        }
    }
}

/// M = M_RB + M_A, M_RB, the diagonal of M_A, and M⁻¹ (from M's Cholesky factor) for
/// `params`.
type MassParts = (Matrix6<f64>, Matrix6<f64>, Vector6<f64>, Matrix6<f64>);

fn mass_parts(params: &VehicleParams<f64>) -> Result<MassParts, PlantError> {
    let m_rb = model::rigid_body_mass(params);
    let m_a = model::added_mass(params);
    let m = m_rb + m_a;
    let m_chol = m.cholesky().ok_or(PlantError::MassNotPositiveDefinite)?;
    Ok((m, m_rb, m_a.diagonal(), m_chol.inverse()))
}

/// Largest angle change (rad) between RK4 stages that [`attitude_near`] takes by series.
const NEAR_ANGLE: f64 = 1e-2;

/// (sin δ, cos δ) for |δ| ≤ [`NEAR_ANGLE`] by their Taylor series to δ⁷ and δ⁸: the first
/// terms left out, δ⁹/9! and δ¹⁰/10!, are below 3·10⁻²⁴ relative, far under an ulp.
fn sin_cos_small(d: f64) -> (f64, f64) {
    const S: [f64; 3] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0];
    const C: [f64; 4] = [-1.0 / 2.0, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0];
    let d2 = d * d;
    let sin = d + d * d2 * (S[0] + d2 * (S[1] + d2 * S[2]));
    let cos = 1.0 + d2 * (C[0] + d2 * (C[1] + d2 * (C[2] + d2 * C[3])));
    (sin, cos)
}

/// The [`Attitude`] of `eta` from `base`, the attitude of `base_eta`, when the angles moved
/// little: sin(a + δ) = sin a cos δ + cos a sin δ, cos(a + δ) = cos a cos δ − sin a sin δ with
/// δ = the difference of the angles ([`sin_cos_small`]); an angle that moved more than
/// [`NEAR_ANGLE`] is evaluated afresh.
///
/// **Choice 81** (docs/model.md#evaluating-the-plant-fast): an RK4 stage moves the angles by at most h/2·|rate| or
/// h·|rate| (below 10⁻³ rad for 1 rad/s at the 1 ms step), so the stages' sines and cosines
/// follow from the step's by two products and a sum each, within a few ulps of libm's (the
/// plant tests bound the difference), for three libm `sin_cos` calls per stage.
fn attitude_near(
    base: &Attitude<f64>,
    base_eta: &Vector6<f64>,
    eta: &Vector6<f64>,
) -> Attitude<f64> {
    let near = |s: f64, c: f64, from: f64, to: f64| {
        let d = to - from;
        if d.abs() <= NEAR_ANGLE {
            let (sd, cd) = sin_cos_small(d);
            (s * cd + c * sd, c * cd - s * sd)
        } else {
            to.sin_cos()
        }
    };
    let (sphi, cphi) = near(base.sphi, base.cphi, base_eta[3], eta[3]);
    let (stheta, ctheta) = near(base.stheta, base.ctheta, base_eta[4], eta[4]);
    let (spsi, cpsi) = near(base.spsi, base.cpsi, base_eta[5], eta[5]);
    Attitude {
        sphi,
        cphi,
        stheta,
        ctheta,
        spsi,
        cpsi,
    }
}

impl Plant {
    pub fn new(params: VehicleParams<f64>, terms: PlantTerms) -> Result<Self, PlantError> {
        let (m, m_rb, m_a, m_inv) = mass_parts(&params)?;
        Ok(Plant {
            params,
            m,
            m_rb,
            m_a,
            m_inv,
            terms,
            factorisations: 1,
        })
    }

    /// Sets the parameters for the next steps. M is formed and factorised again only if
    /// `params` differ from the current ones; on an error the plant keeps its old parameters.
    pub fn set_params(&mut self, params: VehicleParams<f64>) -> Result<(), PlantError> {
        if params == self.params {
            return Ok(());
        }
        let (m, m_rb, m_a, m_inv) = mass_parts(&params)?;
        *self = Plant {
            params,
            m,
            m_rb,
            m_a,
            m_inv,
            terms: self.terms,
            factorisations: self.factorisations + 1,
        };
        Ok(())
    }

    /// How many times M has been formed and factorised since [`Plant::new`] (1 after it).
    pub fn factorisations(&self) -> u64 {
        self.factorisations
    }

    pub fn params(&self) -> &VehicleParams<f64> {
        &self.params
    }

    /// M = M_RB + M_A.
    pub fn mass_matrix(&self) -> Matrix6<f64> {
        self.m
    }

    /// (η̇, ν̇) of Eqs (1)–(2) under body force `tau` and earth-fixed current `current`:
    ///
    /// ν̇ = M⁻¹ (τ − C_RB(ν) ν − C_A(ν_r) ν_r + M_A ν̇_c − D(ν_r) ν_r − g(η)).
    ///
    /// R is built once and serves η̇ = J ν and ν_c = [Rᵀ v_c; 0] (without a current ν_r = ν
    /// and the two Coriolis terms are one, C_M(ν)ν); C ν and D ν are formed as
    /// vectors ([`model::coriolis_force_of`], [`model::damping_force`]) and M⁻¹ is the cached inverse.
    pub fn derivative(
        &self,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Result<(Vector6<f64>, Vector6<f64>), PlantError> {
        self.derivative_at(s, &Attitude::from_eta(&s.eta), tau, current)
    }

    /// [`derivative`](Self::derivative) with the sines and cosines of s's Euler angles given.
    fn derivative_at(
        &self,
        s: &PlantState,
        att: &Attitude<f64>,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Result<(Vector6<f64>, Vector6<f64>), PlantError> {
        let kin = Kinematics::new(*att)?;
        let r = kin.r;
        let omega = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
        let eta_dot = kin.eta_dot(&s.nu);
        let (mut rhs, nu_r) = if *current == Vector3::zeros() {
            // ν_r = ν, ν̇_c = 0, and C is linear in the inertia: C_RB(ν)ν + C_A(ν)ν = C_M(ν)ν.
            (
                tau - model::coriolis_force_of(&(self.m * s.nu), &s.nu),
                s.nu,
            )
        } else {
            let vc_body = r.transpose() * current;
            let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
            let dvc = -omega.cross(&vc_body);
            let nu_c_dot = Vector6::new(dvc.x, dvc.y, dvc.z, 0.0, 0.0, 0.0);
            let nu_r = s.nu - nu_c;
            let rhs = tau
                - model::coriolis_force_of(&(self.m_rb * s.nu), &s.nu)
                - model::coriolis_force_of(&self.m_a.component_mul(&nu_r), &nu_r)
                + self.m_a.component_mul(&nu_c_dot);
            (rhs, nu_r)
        };
        if self.terms.damping {
            rhs -= model::damping_force(&self.params, &nu_r);
        }
        if self.terms.restoring {
            rhs -= model::restoring(&self.params, att);
        }
        Ok((eta_dot, self.m_inv * rhs))
    }

    /// The body force τ that gives the acceleration `nu_dot` in state `s` under the
    /// earth-fixed current `current`: Eq (1) solved for τ (the inverse of
    /// [`derivative`](Self::derivative)),
    ///
    /// τ = M ν̇ + C_RB(ν) ν + C_A(ν_r) ν_r − M_A ν̇_c + D(ν_r) ν_r + g(η).
    ///
    /// The preflight check ([`crate::studies::preflight`]) asks it for the force a reference needs.
    pub fn required_force(
        &self,
        s: &PlantState,
        nu_dot: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Vector6<f64> {
        self.required_force_at(s, &Attitude::from_eta(&s.eta), nu_dot, current)
    }

    /// [`required_force`](Self::required_force) with the attitude's sines and cosines given
    /// (`att` must be those of `s.eta`'s Euler angles): the same arithmetic, bit for bit, for
    /// a caller that holds them already (the preflight's sweep, Choice 390).
    pub fn required_force_at(
        &self,
        s: &PlantState,
        att: &Attitude<f64>,
        nu_dot: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Vector6<f64> {
        let att = *att;
        let omega = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
        let vc_body = kinematics::rotation(&att).transpose() * current;
        let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
        let dvc = -omega.cross(&vc_body);
        let nu_c_dot = Vector6::new(dvc.x, dvc.y, dvc.z, 0.0, 0.0, 0.0);
        let nu_r = s.nu - nu_c;
        let mut tau = self.mass_matrix() * nu_dot
            + model::coriolis_force_of(&(self.m_rb * s.nu), &s.nu)
            + model::coriolis_force_of(&self.m_a.component_mul(&nu_r), &nu_r)
            - self.m_a.component_mul(&nu_c_dot);
        if self.terms.damping {
            tau += model::damping_force(&self.params, &nu_r);
        }
        if self.terms.restoring {
            tau += model::restoring(&self.params, &att);
        }
        tau
    }

    /// The roll row τ₄ of [`required_force_at`](Self::required_force_at), bit for bit: each
    /// term's roll component by the operations, in the order, that the whole vector's
    /// arithmetic gives it — M ν̇'s row as nalgebra's matrix–vector product sums it (column by
    /// column), the two Coriolis terms' (ν₁ × a + ω × b)ₓ from the rows of M_RB ν and M_A ν_r
    /// they read, M_A ν̇_c's zero (the current's derivative, −ω × Rᵀv_c, has no angular part),
    /// the damping's and the restoring moment's roll rows (Eq 1). The preflight's heel reads
    /// this row alone, once per box corner and sample (**Choice 564**): about half the whole
    /// vector's work.
    pub fn required_roll_at(
        &self,
        s: &PlantState,
        att: &Attitude<f64>,
        nu_dot: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> f64 {
        const R: usize = 3;
        let vc_body = kinematics::rotation(att).transpose() * current;
        let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
        let nu_r = s.nu - nu_c;
        // Row i of a 6 × 6 product with `x`, summed as the product sums it.
        let row = |m: &Matrix6<f64>, i: usize, x: &Vector6<f64>| {
            (1..6).fold(m[(i, 0)] * x[0], |y, j| m[(i, j)] * x[j] + y)
        };
        let mass = row(&self.m, R, nu_dot);
        // (ν₁ × a + ω × b)ₓ of `coriolis_force_of(ab, ν)`, from ab's rows 1, 2, 4 and 5.
        let coriolis = |ab: [f64; 4], nu: &Vector6<f64>| {
            let [a1, a2, b1, b2] = ab;
            (nu[1] * a2 - nu[2] * a1) + (nu[4] * b2 - nu[5] * b1)
        };
        let rb = [1, 2, 4, 5].map(|i| row(&self.m_rb, i, &s.nu));
        let added = [1, 2, 4, 5].map(|i| self.m_a[i] * nu_r[i]);
        let mut tau = mass + coriolis(rb, &s.nu) + coriolis(added, &nu_r) - self.m_a[R] * 0.0;
        if self.terms.damping {
            tau += self.params.damping[R] * nu_r[R].abs() * nu_r[R];
        }
        if self.terms.restoring {
            let p = &self.params;
            let (w, b) = (p.weight(), p.buoyancy);
            let my = p.r_g[1] * w - p.r_b_xy[1] * b;
            let k4 = p.r_g[2] * w - p.z_b_roll * b;
            tau += -my * att.ctheta * att.cphi + k4 * att.ctheta * att.sphi;
        }
        tau
    }

    /// One classical RK4 step of length `h` with τ and the current held (zero-order hold).
    ///
    /// The sines and cosines of the Euler angles are evaluated (libm) at the step's start
    /// only; each later stage's come from them by the angle-addition formulas
    /// ([`attitude_near`]).
    pub fn rk4_step(
        &self,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
        h: f64,
    ) -> Result<PlantState, PlantError> {
        let at = |eta: Vector6<f64>, nu: Vector6<f64>| PlantState { eta, nu };
        let att = Attitude::from_eta(&s.eta);
        let stage = |st: &PlantState| {
            let a = attitude_near(&att, &s.eta, &st.eta);
            self.derivative_at(st, &a, tau, current)
        };
        let (k1e, k1n) = self.derivative_at(s, &att, tau, current)?;
        let s2 = at(s.eta + k1e * (h / 2.0), s.nu + k1n * (h / 2.0));
        let (k2e, k2n) = stage(&s2)?;
        let s3 = at(s.eta + k2e * (h / 2.0), s.nu + k2n * (h / 2.0));
        let (k3e, k3n) = stage(&s3)?;
        let s4 = at(s.eta + k3e * h, s.nu + k3n * h);
        let (k4e, k4n) = stage(&s4)?;
        Ok(at(
            s.eta + (k1e + k2e * 2.0 + k3e * 2.0 + k4e) * (h / 6.0),
            s.nu + (k1n + k2n * 2.0 + k3n * 2.0 + k4n) * (h / 6.0),
        ))
    }

    /// One explicit-midpoint step of length `h` (second-order Runge–Kutta) with τ and the
    /// current held: k₁ = f(s), k₂ = f(s + h/2·k₁), s + h·k₂: two derivatives where
    /// [`rk4_step`](Self::rk4_step) takes four.
    ///
    /// **Choice 542** (docs/simulator.md#the-plant-step-and-the-current): the study-grade
    /// integrator. The midpoint stage's sines and cosines come from the step's by
    /// [`attitude_near`], as RK4's stages do.
    pub fn midpoint_step(
        &self,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
        h: f64,
    ) -> Result<PlantState, PlantError> {
        let att = Attitude::from_eta(&s.eta);
        let (k1e, k1n) = self.derivative_at(s, &att, tau, current)?;
        let mid = PlantState {
            eta: s.eta + k1e * (h / 2.0),
            nu: s.nu + k1n * (h / 2.0),
        };
        let (k2e, k2n) =
            self.derivative_at(&mid, &attitude_near(&att, &s.eta, &mid.eta), tau, current)?;
        Ok(PlantState {
            eta: s.eta + k2e * h,
            nu: s.nu + k2n * h,
        })
    }

    /// One step of `method` ([`Integrator`]).
    pub fn step(
        &self,
        method: Integrator,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
        h: f64,
    ) -> Result<PlantState, PlantError> {
        match method {
            Integrator::Rk4 => self.rk4_step(s, tau, current, h),
            Integrator::Midpoint => self.midpoint_step(s, tau, current, h),
        }
    }

    /// Kinetic energy ½ νᵀ M ν.
    pub fn kinetic_energy(&self, nu: &Vector6<f64>) -> f64 {
        0.5 * nu.dot(&(self.mass_matrix() * nu))
    }
}
