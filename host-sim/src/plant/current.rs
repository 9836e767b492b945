//! The ocean current (docs/model.md#the-ocean-current-and-the-simulated-plant): its model, as a scenario gives it ([`CurrentModel`]),
//! and its state as a run steps it ([`OceanCurrent`]). The plant sees ν_r = ν − [Rᵀ v_c; 0] in
//! C_A and D.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// An earth-fixed ocean current v_c, as a scenario gives it.
#[derive(Clone, Debug, PartialEq)]
pub enum CurrentModel {
    None,
    /// Constant v_c (m/s, NED).
    Constant([f64; 3]),
    /// First-order Gauss–Markov per axis: v̇ = −(v − mean)/tau + sigma·√(2/tau)·w(t), seeded.
    GaussMarkov {
        mean: [f64; 3],
        sigma: [f64; 3],
        tau: f64,
        seed: u64,
    },
}

/// The exact transition of the Gauss–Markov process over one step h (**Choice 401**):
/// v(t + h) − mean = a·(v(t) − mean) + b·w with a = e^(−h/τ), b = σ√(1 − a²) and w ~ N(0, 1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Transition {
    /// The step it was formed for (s).
    h: f64,
    a: f64,
    b: [f64; 3],
}

impl Transition {
    fn new(h: f64, sigma: &[f64; 3], tau: f64) -> Self {
        let a = (-h / tau).exp();
        // 1 − a² = −expm1(−2h/τ), exact for h ≪ τ where 1 − a·a would cancel.
        let spread = (-(-2.0 * h / tau).exp_m1()).sqrt();
        Transition {
            h,
            a,
            b: sigma.map(|s| s * spread),
        }
    }
}

/// The ocean current as the plant meets it, step by step: a [`CurrentModel`]'s state
/// (Gauss–Markov is a random process, stepped with the plant).
pub struct OceanCurrent {
    model: CurrentModel,
    v: Vector3<f64>,
    rng: rand::rngs::StdRng,
    /// The Gauss–Markov transition of the last step length (formed once per run: the loop
    /// steps with one h).
    transition: Option<Transition>,
}

impl OceanCurrent {
    pub fn new(model: &CurrentModel) -> Self {
        let (v, seed) = match model {
            CurrentModel::None => (Vector3::zeros(), 0),
            CurrentModel::Constant(v) => (Vector3::from(*v), 0),
            CurrentModel::GaussMarkov { mean, seed, .. } => (Vector3::from(*mean), *seed),
        };
        OceanCurrent {
            model: model.clone(),
            v,
            rng: rand::rngs::StdRng::seed_from_u64(seed),
            transition: None,
        }
    }

    /// The current now (m/s, NED).
    pub fn velocity(&self) -> &Vector3<f64> {
        &self.v
    }

    /// Advances the current by `h` s. A Gauss–Markov current takes its exact transition
    /// (**Choice 401**): v ← mean + e^(−h/τ)(v − mean) + σ√(1 − e^(−2h/τ))·w per axis, so
    /// its stationary variance is σ² and its autocorrelation e^(−Δt/τ) at every step length
    /// (the plant step of a study-grade run, Choice 400, as much as the 1 ms one).
    pub fn step(&mut self, h: f64) {
        if let CurrentModel::GaussMarkov {
            mean, sigma, tau, ..
        } = &self.model
        {
            let tr = match self.transition {
                Some(tr) if tr.h == h => tr,
                _ => *self.transition.insert(Transition::new(h, sigma, *tau)),
            };
            for ((v, m), b) in self.v.iter_mut().zip(mean).zip(tr.b) {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                *v = m + tr.a * (*v - m) + b * w;
            }
        }
    }
}
