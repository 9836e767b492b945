//! Trim: the payload ballasted to neutral buoyancy (docs/real-vehicle.md#trim, **Choice 55**).

use controller_core::model::VehicleParams;

/// The parameters `p` with the payload trimmed (scenario key `variation.trimmed`,
/// docs/real-vehicle.md#trim): ballasted to neutral buoyancy, B = W = m g, while the mass, the inertia
/// and the CG shift stay as they are.
///
/// **Choice** (docs/real-vehicle.md#trim): the trim buoyancy B − B₀ acts at the centre of origin CO, so
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

/// The heel φ (rad) at which the vehicle with parameters `p`, pitched by θ = `theta`, floats
/// in roll equilibrium with no roll moment applied: the restoring roll moment of Eq (1)'s g(η),
/// g₄ = cθ (k₄ sφ − m_y cφ) with m_y = y_G W − y_B B and k₄ = z_G W − z_B,roll B, vanishes at
/// tan φ = m_y / k₄. The AUV-150's thrusters all sit on the centre line, so none of them rolls
/// the vehicle: this is where a lateral CG shift leaves it (docs/real-vehicle.md#the-attitude-the-vehicle-holds).
/// `None` when the vehicle has no roll stability (k₄ ≤ 0: no heel is an equilibrium it returns
/// to) or when |cos θ| is 0.
pub fn static_heel(p: &VehicleParams<f64>, theta: f64) -> Option<f64> {
    let (my, k4) = roll_moments(p);
    (k4 > 0.0 && theta.cos().abs() > 0.0).then(|| my.atan2(k4))
}

/// The two roll moments of g(η) (N m): the heeling moment m_y = y_G W − y_B B and the
/// righting coefficient k₄ = z_G W − z_B,roll B (`controller_core::model::restoring`).
pub fn roll_moments(p: &VehicleParams<f64>) -> (f64, f64) {
    let w = p.weight();
    let my = p.r_g[1] * w - p.r_b_xy[1] * p.buoyancy;
    let k4 = p.r_g[2] * w - p.z_b_roll * p.buoyancy;
    (my, k4)
}
