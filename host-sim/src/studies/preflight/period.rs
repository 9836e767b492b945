//! A periodic mission is checked over one period (docs/real-vehicle.md#how-the-check-is-made,
//! **Choice 393**): when nothing the check evaluates changes with time but the reference, and
//! the reference repeats — a circle (period 2π/ω) or a figure-eight (4π/ω: y_d has the half
//! phase), held at its depth — every later period asks the thrusters for what the first asks,
//! so the check samples the path over the first period only (at its 20 Hz, and the first
//! sample of the next). A day-long circle is then ~1 300 samples, not 1.7·10⁶.
//!
//! What must not change with time: the payload (no variation, or a constant one) — the
//! current is always taken constant (its value, or the corners of a Gauss–Markov current's
//! ±3σ). The positions x_d, y_d, z_d do not enter the force (Eq 1 depends on the attitude,
//! the velocities and the accelerations only).
//!
//! Not bit for bit the exhaustive sweep: a later period's samples fall on other phases of the
//! path, between the first period's, 0.05 s apart like every sample of the check. Over the
//! contract's missions (tests/preflight_engines.rs) the verdicts and proposed scales are the
//! same.

use controller_core::TrajectoryKind;

use crate::plant::VariationProfile;
use crate::scenario::SimConfig;

/// The period (s of path time, at time scale 1) after which every input of the check repeats,
/// if there is one (see the module docs).
pub fn period(cfg: &SimConfig) -> Option<f64> {
    let constant_payload = matches!(
        cfg.variation,
        VariationProfile::None | VariationProfile::Constant(_)
    );
    if !constant_payload {
        return None;
    }
    let tau = std::f64::consts::TAU;
    let p = match cfg.trajectory {
        TrajectoryKind::Circle(c) => tau / f64::from(c.omega),
        TrajectoryKind::FigureEight(f) => 2.0 * tau / f64::from(f.omega),
        _ => return None,
    };
    (p.is_finite() && p > 0.0).then_some(p)
}
