//! The full nonlinear 6-DOF AUV-150 plant of Eq (1), in f64, with Fossen's current model:
//!
//! M_RB ν̇ + C_RB(ν) ν + M_A ν̇_r + C_A(ν_r) ν_r + D(ν_r) ν_r + g(η) = τ,  η̇ = J(η) ν,
//!
//! with ν_r = ν − ν_c, ν_c = [Rᵀ v_c; 0] for an earth-fixed current v_c (docs/design.md §2). The
//! matrices come from `controller_core::model` with the plant's (varying) parameters, so the
//! plant and the controller share one implementation of Eq (1) and differ only in parameters.
//!
//! For a current that is constant over a step, ν̇_c = [−ω × Rᵀv_c; 0]. The payload's dm/dt
//! is not modelled (the paper's variations are parameter changes, not mass flow).

use controller_core::kinematics::{self, Attitude, GimbalLock};
use controller_core::model::{self, VehicleParams};
use nalgebra::{Matrix6, Vector3, Vector6};

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

/// The parameters `p` with the payload trimmed (scenario key `variation.trimmed`,
/// docs/design.md §9): ballasted to neutral buoyancy, B = W = m g, while the mass, the inertia
/// and the CG shift stay as they are.
///
/// **Choice** (docs/design.md §9): the trim buoyancy B − B₀ acts at the centre of origin CO, so
/// it adds a force and no moment: the buoyancy arms are scaled by B₀/B, which keeps every
/// buoyancy moment (x_B B, y_B B, z_B B) as it was. Then g's force rows vanish (ΔW = 0) and its
/// moment rows are those of the untrimmed payload: the CG shift still pitches and heels the
/// vehicle.
pub fn trimmed(p: &VehicleParams<f64>) -> VehicleParams<f64> {
    let w = p.weight();
    let scale = p.buoyancy / w;
    VehicleParams {
        buoyancy: w,
        r_b_xy: p.r_b_xy.map(|x| x * scale),
        z_b_roll: p.z_b_roll * scale,
        z_b_pitch: p.z_b_pitch * scale,
        ..*p
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

/// The plant at one set of parameters: M = M_RB + M_A and its Cholesky factor are formed when
/// the parameters are set ([`Plant::new`], [`Plant::set_params`]) and reused by every
/// derivative until they change.
///
/// **Choice** (docs/design.md §2): a simulation keeps one `Plant` and hands it the parameters of
/// every step; M is refactorised only when they differ from the last ones (`==` on every
/// field), so a constant or staircase profile factorises once per value, not once per step.
#[derive(Clone, Debug)]
pub struct Plant {
    params: VehicleParams<f64>,
    m_rb: Matrix6<f64>,
    /// The diagonal of M_A (Eq 1's added mass is diagonal, `model::added_mass`).
    m_a: Vector6<f64>,
    m_chol: nalgebra::Cholesky<f64, nalgebra::U6>,
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

/// M_RB, the diagonal of M_A, and the Cholesky factor of M = M_RB + M_A for `params`.
type MassParts = (
    Matrix6<f64>,
    Vector6<f64>,
    nalgebra::Cholesky<f64, nalgebra::U6>,
);

fn mass_parts(params: &VehicleParams<f64>) -> Result<MassParts, PlantError> {
    let m_rb = model::rigid_body_mass(params);
    let m_a = model::added_mass(params);
    let m_chol = (m_rb + m_a)
        .cholesky()
        .ok_or(PlantError::MassNotPositiveDefinite)?;
    Ok((m_rb, m_a.diagonal(), m_chol))
}

/// C(ν) ν of `controller_core::model::coriolis` (Kirchhoff form) without forming the matrix:
/// with [a₁; a₂] = M ν (`m_nu`) and ν = [v; ω], C(ν) ν = [ω × a₁; v × a₁ + ω × a₂].
fn coriolis_force(m_nu: &Vector6<f64>, nu: &Vector6<f64>) -> Vector6<f64> {
    let a1 = Vector3::new(m_nu[0], m_nu[1], m_nu[2]);
    let a2 = Vector3::new(m_nu[3], m_nu[4], m_nu[5]);
    let v = Vector3::new(nu[0], nu[1], nu[2]);
    let omega = Vector3::new(nu[3], nu[4], nu[5]);
    let f = omega.cross(&a1);
    let m = v.cross(&a1) + omega.cross(&a2);
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}

/// D(ν) ν of `controller_core::model::damping` without forming the matrix: dᵢ |νᵢ| νᵢ.
fn damping_force(p: &VehicleParams<f64>, nu: &Vector6<f64>) -> Vector6<f64> {
    Vector6::from_fn(|i, _| p.damping[i] * nu[i].abs() * nu[i])
}

impl Plant {
    pub fn new(params: VehicleParams<f64>, terms: PlantTerms) -> Result<Self, PlantError> {
        let (m_rb, m_a, m_chol) = mass_parts(&params)?;
        Ok(Plant {
            params,
            m_rb,
            m_a,
            m_chol,
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
        let (m_rb, m_a, m_chol) = mass_parts(&params)?;
        *self = Plant {
            params,
            m_rb,
            m_a,
            m_chol,
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
        self.m_rb + Matrix6::from_diagonal(&self.m_a)
    }

    /// (η̇, ν̇) of Eqs (1)–(2) under body force `tau` and earth-fixed current `current`:
    ///
    /// ν̇ = M⁻¹ (τ − C_RB(ν) ν − C_A(ν_r) ν_r + M_A ν̇_c − D(ν_r) ν_r − g(η)).
    ///
    /// R is built once and serves η̇ = J ν and ν_c = [Rᵀ v_c; 0]; C ν and D ν are formed as
    /// vectors ([`coriolis_force`], [`damping_force`]) and M⁻¹ is the cached factor's solve.
    pub fn derivative(
        &self,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Result<(Vector6<f64>, Vector6<f64>), PlantError> {
        let att = Attitude::from_eta(&s.eta);
        let r = kinematics::rotation(&att);
        let v = Vector3::new(s.nu[0], s.nu[1], s.nu[2]);
        let omega = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
        let p_dot = r * v;
        let theta_dot = kinematics::euler_rate_matrix(&att)? * omega;
        let eta_dot = Vector6::new(
            p_dot.x,
            p_dot.y,
            p_dot.z,
            theta_dot.x,
            theta_dot.y,
            theta_dot.z,
        );
        let vc_body = r.transpose() * current;
        let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
        let dvc = -omega.cross(&vc_body);
        let nu_c_dot = Vector6::new(dvc.x, dvc.y, dvc.z, 0.0, 0.0, 0.0);
        let nu_r = s.nu - nu_c;
        let mut rhs = tau
            - coriolis_force(&(self.m_rb * s.nu), &s.nu)
            - coriolis_force(&self.m_a.component_mul(&nu_r), &nu_r)
            + self.m_a.component_mul(&nu_c_dot);
        if self.terms.damping {
            rhs -= damping_force(&self.params, &nu_r);
        }
        if self.terms.restoring {
            rhs -= model::restoring(&self.params, &att);
        }
        Ok((eta_dot, self.m_chol.solve(&rhs)))
    }

    /// The body force τ that gives the acceleration `nu_dot` in state `s` under the
    /// earth-fixed current `current`: Eq (1) solved for τ (the inverse of
    /// [`derivative`](Self::derivative)),
    ///
    /// τ = M ν̇ + C_RB(ν) ν + C_A(ν_r) ν_r − M_A ν̇_c + D(ν_r) ν_r + g(η).
    ///
    /// The preflight check ([`crate::preflight`]) asks it for the force a reference needs.
    pub fn required_force(
        &self,
        s: &PlantState,
        nu_dot: &Vector6<f64>,
        current: &Vector3<f64>,
    ) -> Vector6<f64> {
        let att = Attitude::from_eta(&s.eta);
        let omega = Vector3::new(s.nu[3], s.nu[4], s.nu[5]);
        let vc_body = kinematics::rotation(&att).transpose() * current;
        let nu_c = Vector6::new(vc_body.x, vc_body.y, vc_body.z, 0.0, 0.0, 0.0);
        let dvc = -omega.cross(&vc_body);
        let nu_c_dot = Vector6::new(dvc.x, dvc.y, dvc.z, 0.0, 0.0, 0.0);
        let nu_r = s.nu - nu_c;
        let mut tau = self.mass_matrix() * nu_dot
            + coriolis_force(&(self.m_rb * s.nu), &s.nu)
            + coriolis_force(&self.m_a.component_mul(&nu_r), &nu_r)
            - self.m_a.component_mul(&nu_c_dot);
        if self.terms.damping {
            tau += damping_force(&self.params, &nu_r);
        }
        if self.terms.restoring {
            tau += model::restoring(&self.params, &att);
        }
        tau
    }

    /// One classical RK4 step of length `h` with τ and the current held (zero-order hold).
    pub fn rk4_step(
        &self,
        s: &PlantState,
        tau: &Vector6<f64>,
        current: &Vector3<f64>,
        h: f64,
    ) -> Result<PlantState, PlantError> {
        let at = |eta: Vector6<f64>, nu: Vector6<f64>| PlantState { eta, nu };
        let (k1e, k1n) = self.derivative(s, tau, current)?;
        let s2 = at(s.eta + k1e * (h / 2.0), s.nu + k1n * (h / 2.0));
        let (k2e, k2n) = self.derivative(&s2, tau, current)?;
        let s3 = at(s.eta + k2e * (h / 2.0), s.nu + k2n * (h / 2.0));
        let (k3e, k3n) = self.derivative(&s3, tau, current)?;
        let s4 = at(s.eta + k3e * h, s.nu + k3n * h);
        let (k4e, k4n) = self.derivative(&s4, tau, current)?;
        Ok(at(
            s.eta + (k1e + k2e * 2.0 + k3e * 2.0 + k4e) * (h / 6.0),
            s.nu + (k1n + k2n * 2.0 + k3n * 2.0 + k4n) * (h / 6.0),
        ))
    }

    /// Kinetic energy ½ νᵀ M ν.
    pub fn kinetic_energy(&self, nu: &Vector6<f64>) -> f64 {
        0.5 * nu.dot(&(self.mass_matrix() * nu))
    }
}
