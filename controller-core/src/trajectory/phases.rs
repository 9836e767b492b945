//! What one sample is made of: the phases of the mission time (exact integer turns, one
//! `sin_cos_turns` for the first harmonic and the double-angle formulas for the second), and
//! the horizontal path with its derivatives that every path kind returns.

use crate::math;
use crate::phase::MissionTime;

/// The phases a sample needs, in 2⁻³² turns: θ = (ω/k)·t and, for the figure-eight, the half
/// phase; the first two harmonics of θ; the mission time for the terms linear in time.
#[derive(Clone, Copy)]
pub(super) struct Phases {
    pub(super) half: u32,
    pub(super) h: Harmonics,
    pub(super) time: MissionTime,
}

/// (sin θ, cos θ) from one exact-phase `sin_cos_turns`, and (sin 2θ, cos 2θ) from them by the
/// double-angle formulas: what the paths (x_d, y_d) and the heading series share.
#[derive(Clone, Copy)]
pub(super) struct Harmonics {
    pub(super) s1: f32,
    pub(super) c1: f32,
    pub(super) s2: f32,
    pub(super) c2: f32,
}

impl Harmonics {
    #[inline]
    pub(super) fn of(theta: u32) -> Harmonics {
        let (s1, c1) = math::sin_cos_turns(theta);
        Harmonics {
            s1,
            c1,
            s2: 2.0 * s1 * c1,
            c2: (c1 - s1) * (c1 + s1),
        }
    }
}

/// The horizontal path and its first three derivatives, and z_d, ż_d, z̈_d.
#[derive(Clone, Copy)]
pub(super) struct Planar {
    pub(super) x: f32,
    pub(super) y: f32,
    pub(super) z: f32,
    pub(super) z_dot: f32,
    pub(super) z_ddot: f32,
    /// (ẋ, ẏ), (ẍ, ÿ), (x⃛, y⃛).
    pub(super) d: [[f32; 2]; 3],
}

/// The tangent heading of a path sample (see [`HeadingMode::Tangent`](crate::trajectory::HeadingMode::Tangent)): ψ_d = atan2(ẏ, ẋ),
/// ψ̇_d = N/D, ψ̈_d = (Ṅ − ψ̇_d Ḋ)/D. One `atan2` and one division.
#[inline]
pub(super) fn tangent(p: &Planar) -> (f32, f32, f32) {
    let [[xd, yd], [xdd, ydd], [xddd, yddd]] = p.d;
    let d = xd * xd + yd * yd;
    let inv_d = 1.0 / d;
    let n = xd * ydd - yd * xdd;
    let n_dot = xd * yddd - yd * xddd;
    let d_dot = 2.0 * (xd * xdd + yd * ydd);
    let rate = n * inv_d;
    let accel = (n_dot - rate * d_dot) * inv_d;
    (math::atan2(yd, xd), rate, accel)
}
