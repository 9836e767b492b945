//! The AUV-150 body-frame model of Eq (1): M ν̇ + C(ν) ν + D(ν) ν + g(η) = τ.
//!
//! Everything here is generic over the scalar (`nalgebra::RealField`) so that the f32 controller
//! (nominal parameters) and the f64 plant of `host-sim` (varying parameters) build their matrices
//! with the same code. Nothing here calls a transcendental function: the attitude enters g(η)
//! through precomputed sines and cosines ([`crate::kinematics::Attitude`]), so the math backend
//! of the f32 path stays in one place.
//!
//! Parameter values are Table 2 of the paper plus the choices of docs/model.md#parameters-table-2-and-the-inertia-m:
//! −Z_ẇ = −Y_v̇ (axisymmetric hull), −K_ṗ = 0, −M_q̇ = −N_ṙ = 1204 kg m² (inferred from the
//! printed M), d_p = 0, and buoyancy arms fixed so that the nominal g(η) is the printed one.

use nalgebra::{Matrix3, Matrix6, RealField, Vector3, Vector6};

use crate::kinematics::Attitude;

/// Gravitational acceleration used for W = m g (m/s²).
pub const GRAVITY: f64 = 9.81;
/// Printed roll restoring coefficient of g(η) at nominal: g₄ = 296.1 cθ sφ (N m).
pub const ROLL_RESTORING: f64 = 296.1;
/// Printed pitch restoring coefficient of g(η) at nominal: g₅ = 291.1 sθ (N m).
pub const PITCH_RESTORING: f64 = 291.1;

/// Rigid-body, added-mass, damping and hydrostatic parameters of Eq (1).
///
/// Added-mass fields hold the positive numbers −X_u̇, −Y_v̇, … (kg, kg m²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleParams<T> {
    /// Mass m (kg). Table 2: 490.
    pub mass: T,
    /// Centre of gravity r_G = (x_G, y_G, z_G) from CO (m). Table 2: (0, 0, 0.012).
    pub r_g: [T; 3],
    /// Principal inertias I_x, I_y, I_z about CO (kg m²). Table 2: 17.1, 632, 630.
    pub inertia: [T; 3],
    /// Added mass [−X_u̇, −Y_v̇, −Z_ẇ, −K_ṗ, −M_q̇, −N_ṙ]. Table 2 gives −X_u̇ = 49, −Y_v̇ = 836;
    /// **Choice** (docs/model.md#parameters-table-2-and-the-inertia-m): −Z_ẇ = −Y_v̇, −K_ṗ = 0, −M_q̇ = −N_ṙ = 1204.
    pub added_mass: [T; 6],
    /// Quadratic damping coefficients: D(ν) = diag(dᵢ |νᵢ|). Printed: 120, 1224, 1224, d_p, 2731,
    /// 2731 with **Choice** d_p = 0.
    pub damping: [T; 6],
    /// Buoyancy B (N). **Choice**: B = W₀ = 490 · 9.81 (neutral at nominal), fixed when the
    /// payload changes.
    pub buoyancy: T,
    /// Centre of buoyancy (x_B, y_B) in the horizontal plane (m). **Choice**: 0, 0.
    pub r_b_xy: [T; 2],
    /// Vertical buoyancy arm seen by the roll moment, z_B (m): chosen so that the nominal g₄ is
    /// the printed 296.1 cθ sφ, i.e. z_G W₀ − z_B B = 296.1.
    pub z_b_roll: T,
    /// Vertical buoyancy arm seen by the pitch moment (m): nominal g₅ = 291.1 sθ. The paper
    /// prints different roll and pitch coefficients; docs/model.md#restoring-forces keeps both.
    pub z_b_pitch: T,
    /// Gravitational acceleration (m/s²).
    pub gravity: T,
}

impl VehicleParams<f64> {
    /// Nominal AUV-150 parameters (Table 2 and the docs/model.md#parameters-table-2-and-the-inertia-m choices), in f64.
    pub fn auv150() -> Self {
        let w0 = 490.0 * GRAVITY;
        let z_g = 0.012;
        VehicleParams {
            mass: 490.0,
            r_g: [0.0, 0.0, z_g],
            inertia: [17.1, 632.0, 630.0],
            added_mass: [49.0, 836.0, 836.0, 0.0, 1204.0, 1204.0],
            damping: [120.0, 1224.0, 1224.0, 0.0, 2731.0, 2731.0],
            buoyancy: w0,
            r_b_xy: [0.0, 0.0],
            z_b_roll: (z_g * w0 - ROLL_RESTORING) / w0,
            z_b_pitch: (z_g * w0 - PITCH_RESTORING) / w0,
            gravity: GRAVITY,
        }
    }
}

impl<T: RealField + Copy> VehicleParams<T> {
    /// The parameters with a Table-3 variation added (plant only; docs/model.md#parameter-variation-table-3).
    ///
    /// The −Y_v̇ variation acts on −Z_ẇ as well (the hull is axisymmetric). Buoyancy and its
    /// arms do not change: a payload adds weight, not displacement.
    pub fn with_variation(&self, d: &ParamVariation<T>) -> Self {
        let mut p = *self;
        p.mass += d.mass;
        for i in 0..3 {
            p.r_g[i] += d.r_g[i];
            p.inertia[i] += d.inertia[i];
        }
        p.added_mass[0] += d.x_udot;
        p.added_mass[1] += d.y_vdot;
        p.added_mass[2] += d.y_vdot;
        p
    }

    /// Converts the parameter set to another scalar type (e.g. the f64 defaults to the
    /// controller's f32).
    ///
    /// The buoyancy is carried as the net weight W − B, not as B: W = m g is formed in `U`,
    /// and B = W − (W − B), so a neutrally buoyant vehicle stays exactly neutral. Casting B
    /// itself would leave the rounding difference of m·g in f32 and of B (one ulp of ≈ 4 800 N,
    /// 0.5 mN) as a spurious heave force in every step, the largest f32 error in τ
    /// (tests/precision.rs).
    pub fn cast<U: RealField + Copy>(&self, f: impl Fn(T) -> U) -> VehicleParams<U> {
        let mut out = VehicleParams {
            mass: f(self.mass),
            r_g: self.r_g.map(&f),
            inertia: self.inertia.map(&f),
            added_mass: self.added_mass.map(&f),
            damping: self.damping.map(&f),
            buoyancy: f(self.buoyancy),
            r_b_xy: self.r_b_xy.map(&f),
            z_b_roll: f(self.z_b_roll),
            z_b_pitch: f(self.z_b_pitch),
            gravity: f(self.gravity),
        };
        out.buoyancy = out.weight() - f(self.weight() - self.buoyancy);
        out
    }

    /// Weight W = m g (N).
    pub fn weight(&self) -> T {
        self.mass * self.gravity
    }

    /// True if every parameter is finite.
    pub fn is_finite(&self) -> bool {
        let scalars = [
            self.mass,
            self.buoyancy,
            self.z_b_roll,
            self.z_b_pitch,
            self.gravity,
        ];
        scalars
            .iter()
            .chain(self.r_g.iter())
            .chain(self.inertia.iter())
            .chain(self.added_mass.iter())
            .chain(self.damping.iter())
            .chain(self.r_b_xy.iter())
            .all(|x| x.is_finite())
    }
}

/// Number of varied parameters (Table 3): m, x_G, y_G, z_G, I_x, I_y, I_z, −X_u̇, −Y_v̇.
pub const VARIED_PARAMETERS: usize = 9;

/// The names of the nine Δ of a [`ParamVariation`], in the order of
/// [`ParamVariation::to_array`]: Δm, Δx_G, Δy_G, Δz_G, ΔI_x, ΔI_y, ΔI_z, Δ(−X_u̇), Δ(−Y_v̇). They
/// are the keys of a scenario's `[variation]` table and of each `[[variation.steps]]`.
pub const VARIED_PARAMETER_NAMES: [&str; VARIED_PARAMETERS] = [
    "mass", "x_g", "y_g", "z_g", "ix", "iy", "iz", "x_udot", "y_vdot",
];

/// A Table-3 parameter variation Δp, added to the nominal parameters of the plant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ParamVariation<T> {
    /// Δm (kg).
    pub mass: T,
    /// Δx_G, Δy_G, Δz_G (m).
    pub r_g: [T; 3],
    /// ΔI_x, ΔI_y, ΔI_z (kg m²).
    pub inertia: [T; 3],
    /// Δ(−X_u̇) (kg).
    pub x_udot: T,
    /// Δ(−Y_v̇) (kg), applied to −Z_ẇ as well.
    pub y_vdot: T,
}

impl<T: Copy> ParamVariation<T> {
    /// The nine Δ in the order of [`VARIED_PARAMETER_NAMES`].
    pub fn to_array(&self) -> [T; VARIED_PARAMETERS] {
        [
            self.mass,
            self.r_g[0],
            self.r_g[1],
            self.r_g[2],
            self.inertia[0],
            self.inertia[1],
            self.inertia[2],
            self.x_udot,
            self.y_vdot,
        ]
    }

    /// The variation whose nine Δ are `a`, in the order of [`VARIED_PARAMETER_NAMES`].
    pub fn from_array(a: [T; VARIED_PARAMETERS]) -> Self {
        ParamVariation {
            mass: a[0],
            r_g: [a[1], a[2], a[3]],
            inertia: [a[4], a[5], a[6]],
            x_udot: a[7],
            y_vdot: a[8],
        }
    }
}

impl<T: RealField + Copy> ParamVariation<T> {
    /// Converts to another scalar type.
    pub fn cast<U: RealField + Copy>(&self, f: impl Fn(T) -> U) -> ParamVariation<U> {
        ParamVariation {
            mass: f(self.mass),
            r_g: self.r_g.map(&f),
            inertia: self.inertia.map(&f),
            x_udot: f(self.x_udot),
            y_vdot: f(self.y_vdot),
        }
    }
}

impl ParamVariation<f64> {
    /// The "max" column of Table 3 (docs/model.md#parameter-variation-table-3): every Δ at its largest printed value.
    pub const TABLE3_MAX: ParamVariation<f64> = ParamVariation {
        mass: 30.0,
        r_g: [0.05, 0.02, 0.02],
        inertia: [2.0, 5.0, 10.0],
        x_udot: 3.0,
        y_vdot: 50.0,
    };

    /// Multiplies every component by `s` (the abs-sin and staircase profiles of Table 3 scale
    /// or replace this vector).
    pub fn scaled(&self, s: f64) -> Self {
        ParamVariation {
            mass: self.mass * s,
            r_g: self.r_g.map(|x| x * s),
            inertia: self.inertia.map(|x| x * s),
            x_udot: self.x_udot * s,
            y_vdot: self.y_vdot * s,
        }
    }
}

pub use crate::kinematics::skew;

/// Rigid-body inertia M_RB = [[m I₃, −m S(r_G)], [m S(r_G), diag(I_x, I_y, I_z)]]
/// (docs/model.md#parameters-table-2-and-the-inertia-m; Eq 1's M_RB).
pub fn rigid_body_mass<T: RealField + Copy>(p: &VehicleParams<T>) -> Matrix6<T> {
    let m = p.mass;
    let s = skew(&Vector3::from(p.r_g)) * m;
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * m));
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s));
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&s);
    out.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&Matrix3::from_diagonal(&Vector3::from(p.inertia)));
    out
}

/// Added mass M_A = diag(−X_u̇, −Y_v̇, −Z_ẇ, −K_ṗ, −M_q̇, −N_ṙ) (Eq 1's M_A).
pub fn added_mass<T: RealField + Copy>(p: &VehicleParams<T>) -> Matrix6<T> {
    Matrix6::from_diagonal(&Vector6::from(p.added_mass))
}

/// System inertia M = M_RB + M_A (Eq 1). At nominal this is the printed M of the paper:
/// diagonal 539, 1326, 1326, 17.1, 1836, 1834 and M₁₅ = M₅₁ = 5.88, M₂₄ = M₄₂ = −5.88.
pub fn mass_matrix<T: RealField + Copy>(p: &VehicleParams<T>) -> Matrix6<T> {
    rigid_body_mass(p) + added_mass(p)
}

/// M x for an inertia with [`mass_matrix`]'s structure, M = diag(M) + [[0, −m S(r_G)],
/// [m S(r_G), 0]]: each row's three structural non-zeros, the diagonal and the two of the skew
/// block (docs/model.md#parameters-table-2-and-the-inertia-m), 18 products where the dense
/// product makes 36 (Choice 521).
///
/// Each row sums its products in column order, as nalgebra's dense `m * x` does (column by
/// column), so the result has the dense product's bits: the dense one only adds the exact
/// zeros 0·xⱼ between, which change no non-zero sum (a sum that is exactly zero may differ in
/// its sign; `tests/model.rs` checks the bits over random parameters and vectors). Entries off
/// this structure are not read: call it only with a matrix [`mass_matrix`] built.
#[inline]
pub fn mass_mul<T: RealField + Copy>(m: &Matrix6<T>, x: &Vector6<T>) -> Vector6<T> {
    Vector6::from_fn(|i, _| {
        let [a, b, c] = MASS_COLUMNS[i];
        m[(i, a)] * x[a] + m[(i, b)] * x[b] + m[(i, c)] * x[c]
    })
}

/// The columns of each row's structural non-zeros in [`mass_matrix`]'s structure, in column
/// order: the diagonal and the two of the skew block.
const MASS_COLUMNS: [[usize; 3]; 6] = [
    [0, 4, 5],
    [1, 3, 5],
    [2, 3, 4],
    [1, 2, 3],
    [0, 2, 4],
    [0, 1, 5],
];

/// [`mass_mul`] of two vectors at once, (M x, M y): each entry of M is loaded once for both
/// (the law's M̂(J⁻¹u − J⁻¹J̇ν) and M̂ν, Choice 574); the same operations, so the same bits.
#[inline]
pub fn mass_mul_pair<T: RealField + Copy>(
    m: &Matrix6<T>,
    x: &Vector6<T>,
    y: &Vector6<T>,
) -> (Vector6<T>, Vector6<T>) {
    let r: [(T, T); 6] = core::array::from_fn(|i| {
        let [a, b, c] = MASS_COLUMNS[i];
        let (ma, mb, mc) = (m[(i, a)], m[(i, b)], m[(i, c)]);
        (
            ma * x[a] + mb * x[b] + mc * x[c],
            ma * y[a] + mb * y[b] + mc * y[c],
        )
    });
    (
        Vector6::from_fn(|i, _| r[i].0),
        Vector6::from_fn(|i, _| r[i].1),
    )
}

/// Coriolis–centripetal matrix of a symmetric inertia `m` in Kirchhoff form (docs/model.md#the-coriolis-and-centripetal-matrix):
/// C(ν) = [[0, −S(a)], [−S(a), −S(b)]] with [a; b] = M ν, so C(ν) ν = [ω × a; v × a + ω × b]
/// and νᵀ C(ν) ν = 0.
///
/// **Choice** (docs/model.md#the-coriolis-and-centripetal-matrix): the paper prints every entry with the opposite sign; with the
/// printed sign the closed loop diverges on the lawn-mower case.
///
/// Linear in `m`, so C_RB(ν) = `coriolis(&M_RB, ν)` and C_A(ν_r) = `coriolis(&M_A, ν_r)` for
/// the plant's current model. Fossen's `m2c` (C from M) for a 6×6 M.
#[doc(alias = "m2c")]
pub fn coriolis<T: RealField + Copy>(m: &Matrix6<T>, nu: &Vector6<T>) -> Matrix6<T> {
    let ab = m * nu;
    let sa = skew(&Vector3::new(ab[0], ab[1], ab[2]));
    let sb = skew(&Vector3::new(ab[3], ab[4], ab[5]));
    let mut c = Matrix6::zeros();
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-sa));
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-sa));
    c.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-sb));
    c
}

/// C(ν)ν without forming C (the force the law and the plant need): with [a; b] = Mν,
/// C(ν)ν = [ω × a; v × a + ω × b] ([`coriolis`] times ν; docs/model.md#the-coriolis-and-centripetal-matrix).
pub fn coriolis_force<T: RealField + Copy>(m: &Matrix6<T>, nu: &Vector6<T>) -> Vector6<T> {
    coriolis_force_of(&(m * nu), nu)
}

/// [`coriolis_force`] from a precomputed Mν (`ab`), for callers that form Mν their own way
/// (the plant's diagonal M_A).
pub fn coriolis_force_of<T: RealField + Copy>(ab: &Vector6<T>, nu: &Vector6<T>) -> Vector6<T> {
    let a = Vector3::new(ab[0], ab[1], ab[2]);
    let b = Vector3::new(ab[3], ab[4], ab[5]);
    let v = Vector3::new(nu[0], nu[1], nu[2]);
    let w = Vector3::new(nu[3], nu[4], nu[5]);
    let lin = w.cross(&a);
    let ang = v.cross(&a) + w.cross(&b);
    Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
}

/// D(ν)ν without forming D: d_i |ν_i| ν_i per axis ([`damping`] times ν).
pub fn damping_force<T: RealField + Copy>(p: &VehicleParams<T>, nu: &Vector6<T>) -> Vector6<T> {
    Vector6::from_fn(|i, _| p.damping[i] * nu[i].abs() * nu[i])
}

/// Quadratic damping D(ν) = diag(120|u|, 1224|v|, 1224|w|, d_p|p|, 2731|q|, 2731|r|) (Eq 1,
/// printed D(ν)).
pub fn damping<T: RealField + Copy>(p: &VehicleParams<T>, nu: &Vector6<T>) -> Matrix6<T> {
    Matrix6::from_fn(|i, j| {
        if i == j {
            p.damping[i] * nu[i].abs()
        } else {
            T::zero()
        }
    })
}

/// Restoring forces g(η) (Fossen's vector, docs/model.md#restoring-forces), from the attitude's sines/cosines:
///
/// g₁ = ΔW sθ, g₂ = −ΔW cθ sφ, g₃ = −ΔW cθ cφ, with ΔW = W − B;
/// g₄ = −(y_G W − y_B B) cθ cφ + k₄ cθ sφ, g₅ = k₅ sθ + (x_G W − x_B B) cθ cφ,
/// g₆ = −(x_G W − x_B B) cθ sφ − (y_G W − y_B B) sθ,
/// with k₄ = z_G W − z_B,roll B and k₅ = z_G W − z_B,pitch B.
///
/// At nominal this is the printed g(η) = [0, 0, 0, 296.1 cθ sφ, 291.1 sθ, 0]ᵀ. Fossen's `gvect`,
/// with separate roll and pitch buoyancy arms.
#[doc(alias = "gvect")]
pub fn restoring<T: RealField + Copy>(p: &VehicleParams<T>, att: &Attitude<T>) -> Vector6<T> {
    let w = p.weight();
    let b = p.buoyancy;
    let dw = w - b;
    let mx = p.r_g[0] * w - p.r_b_xy[0] * b;
    let my = p.r_g[1] * w - p.r_b_xy[1] * b;
    let k4 = p.r_g[2] * w - p.z_b_roll * b;
    let k5 = p.r_g[2] * w - p.z_b_pitch * b;
    let (sphi, cphi, sth, cth) = (att.sphi, att.cphi, att.stheta, att.ctheta);
    Vector6::new(
        dw * sth,
        -dw * cth * sphi,
        -dw * cth * cphi,
        -my * cth * cphi + k4 * cth * sphi,
        k5 * sth + mx * cth * cphi,
        -mx * cth * sphi - my * sth,
    )
}
