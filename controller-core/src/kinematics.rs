//! Kinematics of Eq (2): η̇ = J(η) ν, J = diag(R(φ,θ,ψ), T(φ,θ)), and the terms of Eq (3).
//!
//! Fossen's zyx convention (docs/model.md#frames-and-state): R = R_z(ψ) R_y(θ) R_x(φ) and
//! T = [[1, sφ tθ, cφ tθ], [0, cφ, −sφ], [0, sφ/cθ, cφ/cθ]]. J is singular at θ = ±90°: every
//! function that divides by cos θ returns [`GimbalLock`] there instead of a non-finite number.
//! J⁻¹ = diag(Rᵀ, T⁻¹) needs no division and is always defined.
//!
//! Generic over the scalar; the attitude enters as precomputed sines and cosines
//! ([`Attitude`]) so the f32 path decides its own math backend ([`Attitude::from_eta_f32`]).

use nalgebra::{Matrix3, Matrix6, RealField, Vector3, Vector6};

/// θ is within numerical reach of ±90°: T(φ, θ) and J(η) do not exist.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GimbalLock;

/// Sines and cosines of the Euler angles (φ, θ, ψ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attitude<T> {
    pub sphi: T,
    pub cphi: T,
    pub stheta: T,
    pub ctheta: T,
    pub spsi: T,
    pub cpsi: T,
}

impl<T: RealField + Copy> Attitude<T> {
    /// From Euler angles, with the scalar type's own sin/cos (f64 plant, tests).
    pub fn from_euler(phi: T, theta: T, psi: T) -> Self {
        let (sphi, cphi) = phi.sin_cos();
        let (stheta, ctheta) = theta.sin_cos();
        let (spsi, cpsi) = psi.sin_cos();
        Attitude {
            sphi,
            cphi,
            stheta,
            ctheta,
            spsi,
            cpsi,
        }
    }

    /// From η = [x y z φ θ ψ].
    pub fn from_eta(eta: &Vector6<T>) -> Self {
        Self::from_euler(eta[3], eta[4], eta[5])
    }

    /// |cos θ| below which T(φ, θ) is treated as singular: ≈ 0.006° from ±90°, far beyond the
    /// controller's pitch fault (80° by default, docs/law.md#the-sampled-f32-loop).
    pub fn gimbal_threshold() -> T {
        nalgebra::convert(1e-4)
    }

    fn sec_theta(&self) -> Result<T, GimbalLock> {
        if self.ctheta.abs() < Self::gimbal_threshold() {
            Err(GimbalLock)
        } else {
            Ok(T::one() / self.ctheta)
        }
    }
}

impl Attitude<f32> {
    /// From η with the crate's math backend ([`crate::math`]): what the controller uses.
    pub fn from_eta_f32(eta: &Vector6<f32>) -> Self {
        let (sphi, cphi) = crate::math::sin_cos(eta[3]);
        let (stheta, ctheta) = crate::math::sin_cos(eta[4]);
        let (spsi, cpsi) = crate::math::sin_cos(eta[5]);
        Attitude {
            sphi,
            cphi,
            stheta,
            ctheta,
            spsi,
            cpsi,
        }
    }
}

/// Rotation R(φ,θ,ψ) = R_z(ψ) R_y(θ) R_x(φ), body → earth (Eq 2's J₁; Fossen's `Rzyx`).
#[doc(alias = "Rzyx")]
pub fn rotation<T: RealField + Copy>(a: &Attitude<T>) -> Matrix3<T> {
    let (sf, cf, st, ct, sp, cp) = (a.sphi, a.cphi, a.stheta, a.ctheta, a.spsi, a.cpsi);
    Matrix3::new(
        cp * ct,
        -sp * cf + cp * st * sf,
        sp * sf + cp * cf * st,
        sp * ct,
        cp * cf + sf * st * sp,
        -cp * sf + st * sp * cf,
        -st,
        ct * sf,
        ct * cf,
    )
}

/// Euler-rate matrix T(φ,θ) of Eq 2's J₂: [φ̇ θ̇ ψ̇]ᵀ = T ω (Fossen's `Tzyx`).
#[doc(alias = "Tzyx")]
pub fn euler_rate_matrix<T: RealField + Copy>(a: &Attitude<T>) -> Result<Matrix3<T>, GimbalLock> {
    let sec = a.sec_theta()?;
    Ok(t_matrix(a, sec, a.stheta * sec))
}

/// T(φ,θ) from sec θ and tan θ = sθ·sec θ.
#[inline]
fn t_matrix<T: RealField + Copy>(a: &Attitude<T>, sec: T, tth: T) -> Matrix3<T> {
    let (o, z) = (T::one(), T::zero());
    Matrix3::new(
        o,
        a.sphi * tth,
        a.cphi * tth,
        z,
        a.cphi,
        -a.sphi,
        z,
        a.sphi * sec,
        a.cphi * sec,
    )
}

/// T(φ,θ)⁻¹ = [[1, 0, −sθ], [0, cφ, cθ sφ], [0, −sφ, cθ cφ]]: ω = T⁻¹ [φ̇ θ̇ ψ̇]ᵀ. Defined for
/// every attitude.
pub fn euler_rate_matrix_inv<T: RealField + Copy>(a: &Attitude<T>) -> Matrix3<T> {
    let (o, z) = (T::one(), T::zero());
    Matrix3::new(
        o,
        z,
        -a.stheta,
        z,
        a.cphi,
        a.ctheta * a.sphi,
        z,
        -a.sphi,
        a.ctheta * a.cphi,
    )
}

/// J(η) = diag(R, T) of Eq (2) (Fossen's `eulerang`, which returns J with R and T).
#[doc(alias = "eulerang")]
pub fn jacobian<T: RealField + Copy>(a: &Attitude<T>) -> Result<Matrix6<T>, GimbalLock> {
    let mut j = Matrix6::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&rotation(a));
    j.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&euler_rate_matrix(a)?);
    Ok(j)
}

/// J(η)⁻¹ = diag(Rᵀ, T⁻¹) (Eq 3), in closed form: no inversion, no division.
pub fn jacobian_inv<T: RealField + Copy>(a: &Attitude<T>) -> Matrix6<T> {
    let mut j = Matrix6::zeros();
    j.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&rotation(a).transpose());
    j.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&euler_rate_matrix_inv(a));
    j
}

/// η̇ = J(η) ν (Eq 2).
pub fn eta_dot<T: RealField + Copy>(
    a: &Attitude<T>,
    nu: &Vector6<T>,
) -> Result<Vector6<T>, GimbalLock> {
    Ok(Kinematics::new(*a)?.eta_dot(nu))
}

/// Ṫ(φ,θ) along the motion, given sec θ, tan θ and the Euler rates (φ̇, θ̇).
#[inline]
fn t_dot_matrix<T: RealField + Copy>(
    a: &Attitude<T>,
    sec: T,
    tth: T,
    phi_dot: T,
    theta_dot: T,
) -> Matrix3<T> {
    let sec2 = sec * sec;
    let z = T::zero();
    let (sf, cf) = (a.sphi, a.cphi);
    Matrix3::new(
        z,
        cf * tth * phi_dot + sf * sec2 * theta_dot,
        -sf * tth * phi_dot + cf * sec2 * theta_dot,
        z,
        -sf * phi_dot,
        -cf * phi_dot,
        z,
        cf * sec * phi_dot + sf * tth * sec * theta_dot,
        -sf * sec * phi_dot + cf * tth * sec * theta_dot,
    )
}

/// J̇(η, ν) = diag(Ṙ, Ṫ) with Ṙ = R S(ω) (Eq 3's J̇).
pub fn jacobian_dot<T: RealField + Copy>(
    a: &Attitude<T>,
    nu: &Vector6<T>,
) -> Result<Matrix6<T>, GimbalLock> {
    let k = Kinematics::new(*a)?;
    let omega = Vector3::new(nu[3], nu[4], nu[5]);
    let rates = k.euler_rates(&omega);
    let mut jd = Matrix6::zeros();
    jd.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(k.r * skew(&omega)));
    jd.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&t_dot_matrix(a, k.sec, k.tan, rates.x, rates.y));
    Ok(jd)
}

/// J⁻¹ J̇ ν in closed form (docs/model.md#frames-and-state): [ω × v; T⁻¹ Ṫ ω]. This is the term of Eq (3)
/// (ν̇ = J⁻¹(η̈ − J̇ν)) that the inversion-free law needs.
pub fn jinv_jdot_nu<T: RealField + Copy>(
    a: &Attitude<T>,
    nu: &Vector6<T>,
) -> Result<Vector6<T>, GimbalLock> {
    Ok(Kinematics::new(*a)?.jinv_jdot_nu(nu))
}

/// Skew-symmetric S(a) with S(a) b = a × b (Fossen's `Smtrx`).
#[doc(alias = "Smtrx")]
pub fn skew<T: RealField + Copy>(a: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -a.z, a.y, a.z, z, -a.x, -a.y, a.x, z)
}

/// The kinematics of one attitude, formed once per step and shared by everything that needs
/// them (docs/numerics.md#one-kinematics-value-per-step): R, sec θ and tan θ, with η̇ = Jν (Eq 2), J⁻¹J̇ν (Eq 3) and
/// J⁻¹u as methods. T and T⁻¹ are applied to vectors directly (their zeros and ones cost
/// nothing). Building it is the one place the gimbal-lock check runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics<T> {
    /// The attitude's sines and cosines.
    pub att: Attitude<T>,
    /// R(φ,θ,ψ), body → earth.
    pub r: Matrix3<T>,
    /// sec θ.
    pub sec: T,
    /// tan θ.
    pub tan: T,
}

impl<T: RealField + Copy> Kinematics<T> {
    /// R, sec θ and tan θ of `att`; [`GimbalLock`] at θ = ±90°.
    #[inline]
    pub fn new(att: Attitude<T>) -> Result<Self, GimbalLock> {
        let sec = att.sec_theta()?;
        Ok(Kinematics {
            att,
            r: rotation(&att),
            sec,
            tan: att.stheta * sec,
        })
    }

    /// T(φ,θ) ω: the Euler rates [φ̇ θ̇ ψ̇] of the body rates ω.
    #[inline]
    pub fn euler_rates(&self, omega: &Vector3<T>) -> Vector3<T> {
        let a = &self.att;
        let s = omega.y * a.sphi + omega.z * a.cphi;
        Vector3::new(
            omega.x + s * self.tan,
            omega.y * a.cphi - omega.z * a.sphi,
            s * self.sec,
        )
    }

    /// T(φ,θ)⁻¹ x (defined for every attitude).
    #[inline]
    pub fn euler_rates_inv(&self, x: &Vector3<T>) -> Vector3<T> {
        let a = &self.att;
        Vector3::new(
            x.x - a.stheta * x.z,
            a.cphi * x.y + a.ctheta * a.sphi * x.z,
            -a.sphi * x.y + a.ctheta * a.cphi * x.z,
        )
    }

    /// η̇ = J(η) ν (Eq 2).
    #[inline]
    pub fn eta_dot(&self, nu: &Vector6<T>) -> Vector6<T> {
        let v = self.r * Vector3::new(nu[0], nu[1], nu[2]);
        let e = self.euler_rates(&Vector3::new(nu[3], nu[4], nu[5]));
        Vector6::new(v.x, v.y, v.z, e.x, e.y, e.z)
    }

    /// J(η)⁻¹ u = [Rᵀ u₁; T⁻¹ u₂] (Eq 3).
    #[inline]
    pub fn jinv_mul(&self, u: &Vector6<T>) -> Vector6<T> {
        let v = self.r.tr_mul(&Vector3::new(u[0], u[1], u[2]));
        let e = self.euler_rates_inv(&Vector3::new(u[3], u[4], u[5]));
        Vector6::new(v[0], v[1], v[2], e.x, e.y, e.z)
    }

    /// J⁻¹ J̇ ν in closed form (docs/model.md#frames-and-state): [ω × v; T⁻¹ Ṫ ω]. This is the term of
    /// Eq (3) (ν̇ = J⁻¹(η̈ − J̇ν)) that the inversion-free law needs.
    #[inline]
    pub fn jinv_jdot_nu(&self, nu: &Vector6<T>) -> Vector6<T> {
        let v = Vector3::new(nu[0], nu[1], nu[2]);
        let omega = Vector3::new(nu[3], nu[4], nu[5]);
        let rates = self.euler_rates(&omega);
        let lin = omega.cross(&v);
        let t_dot = t_dot_matrix(&self.att, self.sec, self.tan, rates.x, rates.y);
        let ang = self.euler_rates_inv(&(t_dot * omega));
        Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
    }
}
