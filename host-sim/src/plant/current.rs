//! The ocean current (docs/model.md#the-ocean-current-and-the-simulated-plant): its model, as a scenario gives it ([`CurrentModel`]),
//! and its state as a run steps it ([`OceanCurrent`]). The plant sees ν_r = ν − [Rᵀ v_c; 0] in
//! C_A and D.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// An earth-fixed ocean current v_c, as a scenario's `[current]` gives it.
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

/// The ocean current as the plant meets it, step by step: a [`CurrentModel`]'s state
/// (Gauss–Markov is a random process, stepped with the plant).
pub struct OceanCurrent {
    model: CurrentModel,
    v: Vector3<f64>,
    rng: rand::rngs::StdRng,
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
        }
    }

    /// The current now (m/s, NED).
    pub fn velocity(&self) -> &Vector3<f64> {
        &self.v
    }

    /// Euler–Maruyama step of v̇ = −(v − mean)/τ + σ√(2/τ)·w: stationary std σ.
    pub fn step(&mut self, h: f64) {
        if let CurrentModel::GaussMarkov {
            mean, sigma, tau, ..
        } = &self.model
        {
            for i in 0..3 {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                self.v[i] +=
                    -(self.v[i] - mean[i]) / tau * h + sigma[i] * (2.0 * h / tau).sqrt() * w;
            }
        }
    }
}
