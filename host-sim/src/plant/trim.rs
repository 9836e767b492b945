//! Trim: the payload ballasted to neutral buoyancy (docs/design.md §9, **Choice 55**).

use controller_core::model::VehicleParams;

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
