//! The law's inside for the log, computed on the host from what the law was given
//! (**Choice 353**, docs/logs.md#the-laws-inside): e₁, e₂ from the state told and the
//! reference by the core's own functions (its kinematics stage and
//! [`law::tracking_errors`]), V = eᵀPe with the core's per-axis P, and the radius of the ball
//! of Eq 40. The core's tick path is untouched: `update` computes none of V and the radius, and
//! gives neither e₂ nor P·e out; recomputing them here from the same inputs and formulas costs
//! the board nothing. ‖w‖ and δ are the law's own (its output).

use controller_core::axes::ACTUATED;
use controller_core::law;
use controller_core::Controller;

use crate::scenario::ultimate_bound::ball_radius;
use nalgebra::Vector6;

use crate::sim::Sample;

/// The law's inside at one control period; `None` where it is not defined (the state told
/// was refused by the law's input checks: the kinematics had nothing to give).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LawInside {
    /// e₁ = η − η_d (Eq 12), yaw wrapped.
    pub e: Option<[f32; 6]>,
    /// e₂ = η̇ − η̇_d (Eq 13).
    pub e_dot: Option<[f32; 6]>,
    /// ‖[e₁; e₂]‖ over the controlled axes (as δ's Eq 29 takes it).
    pub e_norm: Option<f64>,
    /// V = eᵀPe = Σᵢ p₁₁e₁ᵢ² + 2p₁₂e₁ᵢe₂ᵢ + p₂₂e₂ᵢ² over the controlled axes (roll's P is zero).
    pub lyapunov: Option<f64>,
    /// Eq 40: X = √(μδ / (2 λ_min(Q))), Q = diag(q₁, q₂) per axis; 0 for the discontinuous
    /// law (Theorem 3: V decreases everywhere outside e = 0); `None` without Δu (no theorem).
    pub ball_radius: Option<f64>,
}

/// What the inside needs of the controller, taken once per run.
pub struct InsideOf<'c> {
    controller: &'c Controller,
}

impl<'c> InsideOf<'c> {
    pub fn new(controller: &'c Controller) -> Self {
        InsideOf { controller }
    }

    /// The inside at `s`.
    pub fn at(&self, s: &Sample) -> LawInside {
        let ball_radius = ball_radius(self.controller.config(), s.delta);
        let Ok(kin) = self
            .controller
            .kinematics_stage(&s.signals.eta_told, &s.signals.nu_told)
        else {
            return LawInside {
                ball_radius,
                ..LawInside::default()
            };
        };
        let eta_d = Vector6::from(s.eta_d.map(|x| x as f32));
        let eta_d_dot = Vector6::from(s.signals.eta_d_dot);
        let (e1, e2) = law::tracking_errors(&kin.eta, &kin.eta_dot, &eta_d, &eta_d_dot);
        let p = self.controller.lyapunov();
        let mut v = 0.0;
        let mut e_sq = 0.0;
        for i in ACTUATED {
            let (a, b) = (f64::from(e1[i]), f64::from(e2[i]));
            let pi = &p[i];
            v += f64::from(pi.p11) * a * a
                + 2.0 * f64::from(pi.p12) * a * b
                + f64::from(pi.p22) * b * b;
            e_sq += a * a + b * b;
        }
        LawInside {
            e: Some(e1.into()),
            e_dot: Some(e2.into()),
            e_norm: Some(e_sq.sqrt()),
            lyapunov: Some(v),
            ball_radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::parse_scenario;
    use crate::sim;

    /// The e₁, e₂ recomputed here are the law's: w = BᵀPe from them has the norm the law
    /// reported, in every period of a noisy flight (the state told is not the truth).
    #[test]
    fn the_recomputed_errors_give_the_laws_own_w_norm() {
        let s = parse_scenario(
            "duration = 3\n[trajectory]\nkind = \"circle\"\nradius = 10\n\
             [noise]\neta_sigma = [0.05, 0.05, 0.05, 0.01, 0.01, 0.01]\n\
             nu_sigma = [0.05, 0.05, 0.05, 0.01, 0.01, 0.01]\nseed = 3\n",
        )
        .expect("a scenario");
        let run = sim::run(&s);
        assert_eq!(run.samples.len(), 301);
        let inside = InsideOf::new(s.controller());
        for sample in &run.samples {
            let i = inside.at(sample);
            let (e1, e2) = (
                Vector6::from(i.e.expect("e₁")),
                Vector6::from(i.e_dot.expect("e₂")),
            );
            let w = law::switching_signal(s.controller().lyapunov(), &e1, &e2);
            let w_norm = controller_core::math::norm(&w.into());
            assert_eq!(f64::from(w_norm), sample.w_norm, "t = {}", sample.t);
            // V is a positive-definite form: zero only at e = 0.
            assert!(i.lyapunov.expect("V") > 0.0 || i.e_norm == Some(0.0));
        }
    }
}
