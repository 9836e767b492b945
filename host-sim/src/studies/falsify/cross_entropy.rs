//! The cross-entropy method on the unit cube, minimising (docs/search.md#the-search).
//!
//! **Choice 413:** a Gaussian N(μ, σ²) over [0, 1]ⁿ, points folded back into the cube at its
//! faces; each generation draws λ = 4 + ⌊3 ln n⌋ points (CMA-ES's default population), keeps
//! the ⌈λ/2⌉ of least score (candidates that do not count score +∞ and are never kept) and
//! moves μ a fraction [`SMOOTHING`] of the way to their mean. σ follows a success rule: ×[`WIDEN`]
//! after a generation whose elites score better on average than the last one's, ×[`WIDEN`]^−½
//! otherwise, within [[`MIN_SIGMA`], [`INITIAL_SIGMA`]] (the elites' own spread, the textbook
//! update, collapsed σ long before μ arrived: on a 12-D sphere it did worse than random
//! search). When its best score has not improved for [`STALL_GENERATIONS`] generations it
//! starts again from a uniform μ. Written here rather than taken from the `cmaes` crate: no
//! new dependency, its draws from the caller's seeded generator (a restart is one stream), and
//! with coordinates that are indices (path kind, mounting, preset) a covariance adds little.

use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

/// The initial σ of every coordinate.
pub const INITIAL_SIGMA: f64 = 0.25;
/// The fraction of the way μ moves to the elites' mean each generation.
pub const SMOOTHING: f64 = 0.7;
/// σ's factor after a successful generation (its inverse square root after one that was not).
pub const WIDEN: f64 = 1.2;
/// σ never falls below this (a coordinate stays explorable).
pub const MIN_SIGMA: f64 = 0.01;
/// Generations without a better score after which it starts again.
pub const STALL_GENERATIONS: usize = 10;

/// The search's state: the sampling distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct Search {
    pub mean: Vec<f64>,
    pub sigma: Vec<f64>,
    lambda: usize,
    /// The best score since the last start, and the generations since it improved.
    best: f64,
    stalled: usize,
    /// The last generation's mean elite score.
    last_elites: f64,
}

/// `x` folded into [0, 1] (reflected at the faces).
pub fn fold(x: f64) -> f64 {
    let y = x.rem_euclid(2.0);
    if y > 1.0 {
        2.0 - y
    } else {
        y
    }
}

impl Search {
    /// A search of `n` coordinates from a uniform μ drawn from `rng`.
    pub fn new(n: usize, rng: &mut impl rand::Rng) -> Self {
        Search {
            mean: (0..n).map(|_| rng.random::<f64>()).collect(),
            sigma: vec![INITIAL_SIGMA; n],
            lambda: 4 + (3.0 * (n.max(1) as f64).ln()).floor() as usize,
            best: f64::INFINITY,
            stalled: 0,
            last_elites: f64::INFINITY,
        }
    }

    /// Points a generation.
    pub fn population(&self) -> usize {
        self.lambda
    }

    /// How many a generation keeps.
    pub fn elites(&self) -> usize {
        self.lambda.div_ceil(2)
    }

    /// A generation's points.
    pub fn ask(&self, rng: &mut impl rand::Rng) -> Vec<Vec<f64>> {
        (0..self.lambda)
            .map(|_| {
                self.mean
                    .iter()
                    .zip(&self.sigma)
                    .map(|(m, s)| {
                        let z: f64 = StandardNormal.sample(rng);
                        fold(m + s * z)
                    })
                    .collect()
            })
            .collect()
    }

    /// Moves the distribution towards the elites of `points` by `scores` (lower is better;
    /// +∞ never an elite); restarts it when it has converged.
    pub fn tell(&mut self, points: &[Vec<f64>], scores: &[f64], rng: &mut impl rand::Rng) {
        let mut order: Vec<usize> = (0..points.len())
            .filter(|&i| scores[i].is_finite() || scores[i] == f64::NEG_INFINITY)
            .collect();
        order.sort_by(|&a, &b| scores[a].total_cmp(&scores[b]));
        order.truncate(self.elites());
        if !order.is_empty() {
            let k = order.len() as f64;
            for (j, mean) in self.mean.iter_mut().enumerate() {
                let m = order.iter().map(|&i| points[i][j]).sum::<f64>() / k;
                *mean += SMOOTHING * (m - *mean);
            }
        }
        let best = scores.iter().copied().fold(f64::INFINITY, f64::min);
        // The success rule: σ widens after a generation whose elites score better on average
        // than the last one's, and narrows otherwise (the elites' own spread collapses σ
        // before the mean arrives).
        let elite_mean = if order.is_empty() {
            f64::INFINITY
        } else {
            order.iter().map(|&i| scores[i]).sum::<f64>() / order.len() as f64
        };
        let factor = if elite_mean < self.last_elites {
            WIDEN
        } else {
            WIDEN.powf(-0.5)
        };
        self.last_elites = elite_mean;
        for s in &mut self.sigma {
            *s = (*s * factor).clamp(MIN_SIGMA, INITIAL_SIGMA);
        }
        if best < self.best {
            (self.best, self.stalled) = (best, 0);
        } else {
            self.stalled += 1;
        }
        if self.stalled >= STALL_GENERATIONS {
            *self = Search::new(self.mean.len(), rng);
        }
    }
}
