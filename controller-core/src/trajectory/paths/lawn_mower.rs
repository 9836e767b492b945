//! The lawn-mower (docs/missions.md#closed-form-paths): x_d = s(0.25 t + 2.5 sin 2ωt), y_d = 15 s cos ωt,
//! z_d = depth, ψ_d the trapezoid series of base ω (`series.rs`; paper: ω = 0.05, so 2ω = 0.1
//! in x_d; s = 1 is the paper's 30×15 case).

use super::kind::{ClosedForm, PathKind, DEPTH, OMEGA};
use crate::math;
use crate::phase::{LinearRate, MissionTime};
use crate::trajectory::error::{Parameter, ParameterRange};
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::series::Series;
use crate::trajectory::Trajectory;

/// x = s(0.25 t + 2.5 sin 2ωt), y = 15 s cos ωt, z = depth,
/// ψ = (8/π) Σ_{n ≤ N} [sin(nπ/4) + sin(3nπ/4)] sin(nωt)/n² (a trapezoid of amplitude π;
/// paper: ω = 0.05, so 2ω = 0.1; s = 1 is the paper's 30×15 case).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LawnMower {
    /// s (dimensionless): loop height 30 s m, loop width ≈ 15.7 s m.
    pub scale: f32,
    /// ω (rad/s).
    #[cfg_attr(feature = "serde", serde(default = "paper_lawn_mower_omega"))]
    pub omega: f32,
    /// z_d (m, positive down).
    #[cfg_attr(feature = "serde", serde(default = "super::kind::paper_depth"))]
    pub depth: f32,
}

/// The lawn-mower's advance, x_d = s(0.25 t + …): 0.25 m/s per unit scale.
const ADVANCE: f32 = 0.25;

/// s in (0, [`Trajectory::MAX_SIZE`]/15] (y_d's amplitude is 15 s).
const SCALE: Parameter = Parameter {
    name: "scale",
    range: ParameterRange::Positive(Trajectory::MAX_SIZE / 15.0),
};

/// The serde default of `omega`: the paper's lawn-mower ω.
#[cfg(feature = "serde")]
fn paper_lawn_mower_omega() -> f32 {
    Trajectory::PAPER_LAWN_MOWER_OMEGA
}

impl ClosedForm for LawnMower {
    /// The paper's 30 m × 15 m lawn-mower (its printed equations).
    const EXAMPLE: LawnMower = LawnMower {
        scale: 1.0,
        omega: Trajectory::PAPER_LAWN_MOWER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    };
}

impl PathKind for LawnMower {
    fn parameters(&mut self, visit: &mut dyn FnMut(&Parameter, &mut f32)) {
        visit(&SCALE, &mut self.scale);
        visit(&OMEGA, &mut self.omega);
        visit(&DEPTH, &mut self.depth);
    }

    /// ω, and the advance per unit scale (m/s).
    fn rates(&self) -> (f32, f32) {
        (self.omega, ADVANCE)
    }

    /// The advance times the scale.
    fn position_rate(&self, rate: f64) -> LinearRate {
        LinearRate::new(rate * self.scale as f64)
    }

    fn heading_series(&self) -> Option<Series> {
        Some(Series::Trapezoid)
    }

    /// Σ |amplitude|·frequency² of ẍ_d (2.5 s (2ω)²) and of ÿ_d (15 s ω²).
    fn accel(&self, omega: f32) -> (f32, f32) {
        let two = 2.0 * omega;
        (
            2.5 * self.scale * two * two,
            15.0 * self.scale * omega * omega,
        )
    }

    /// ẋ = s(a − b u), ẏ² = s² c u with u = sin²θ ∈ [0, 1], a = 0.25/k + 5ω, b = 10ω,
    /// c = 225ω² (0.25/k = `t.rate`, ω = ω/k): a convex quadratic in u, least at
    /// u* = (2ab − c)/(2b²) clamped to [0, 1].
    fn min_speed(&self, t: &Trajectory) -> f32 {
        let w = t.omega;
        let a = t.rate + 5.0 * w;
        let b = 10.0 * w;
        let c = 225.0 * w * w;
        let u = ((2.0 * a * b - c) / (2.0 * b * b)).clamp(0.0, 1.0);
        let f = (a - b * u) * (a - b * u) + c * u;
        self.scale * math::exact_sqrt(f)
    }

    /// The derivatives have period 2π in θ.
    fn course_period_phases(&self, a: u32) -> Option<Phases> {
        Some(Phases {
            half: 0,
            h: Harmonics::of(a),
            time: MissionTime::new(0, 1),
        })
    }

    /// The advance s·(0.25/k)·t rounded once
    /// ([`MissionTime::linear`](crate::phase::MissionTime::linear)) plus the wave.
    #[inline]
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar {
        let (scale, omega) = (self.scale, t.omega);
        let Harmonics { s1, c1, s2, c2 } = ph.h;
        let two = 2.0 * omega;
        let wave = 2.5 * scale * s2;
        let amp_y = 15.0 * scale;
        Planar {
            x: ph.time.linear(&t.position_rate, wave),
            y: amp_y * c1,
            z: self.depth,
            z_dot: 0.0,
            z_ddot: 0.0,
            d: [
                [scale * (t.rate + 2.5 * two * c2), -amp_y * omega * s1],
                [-2.5 * scale * two * two * s2, -amp_y * omega * omega * c1],
                [
                    -2.5 * scale * two * two * two * c2,
                    amp_y * omega * omega * omega * s1,
                ],
            ],
        }
    }
}
