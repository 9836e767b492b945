//! The state estimator on the target (docs/law.md#the-state-estimator): its golden vectors
//! ([`ESTIMATOR_GOLDEN`], the host's outputs of `update_from_solution` on the same steps) bit
//! for bit, and the instructions of `update_from_solution` with the estimator on at its
//! largest fixed work (a late solution corrected at its old stamp), counted as the stages are
//! ([`Counter`]): the estimator's share is that count less `update`'s on the same inputs.
//!
//! Each counted call starts from a copy of the estimator's memory (the call changes it); the
//! copy alone is counted the same way and subtracted.

use core::hint::black_box;

use controller_core::{Controller, ControllerConfig, Estimate, EstimatorKind, Trajectory};
use defmt::{error, info};

use crate::counter::Counter;
use crate::golden::{estimator_steps, ESTIMATOR_GOLDEN, GOLDEN};

/// Checks and counts; false if a vector differs from the host's or none ran.
pub fn run(counter: &Counter) -> bool {
    let mut cfg = ControllerConfig::default();
    cfg.estimator.kind = EstimatorKind::Kalman;
    let Ok(c) = Controller::new(cfg) else {
        error!("the controller with the estimator is rejected on the target");
        return false;
    };
    let (mut exact, mut n) = (0usize, 0usize);
    let (mut max, mut sum, mut share) = (0u32, 0u32, 0u32);
    let mut tr = Trajectory::EMPTY;
    for e in &ESTIMATOR_GOLDEN {
        let g = &GOLDEN[e.vector];
        let Some(steps) = estimator_steps(g) else {
            continue;
        };
        if !g.set(&mut tr) {
            continue;
        }
        n += 1;
        let mut memory = Estimate::new();
        for (ticks, solution) in &steps[..2] {
            c.update_from_solution(&mut memory, *ticks, solution, &tr);
        }
        let (ticks, solution) = steps[2];
        let before = memory;
        let o = c.update_from_solution(&mut memory, ticks, &solution, &tr);
        if o.voltage.map(f32::to_bits) == e.voltage.map(f32::to_bits)
            && o.tau.map(f32::to_bits) == e.tau.map(f32::to_bits)
        {
            exact += 1;
        } else {
            error!(
                "estimator golden vector on vector {}: target tau {} vs host tau {}",
                e.vector, o.tau, e.tau
            );
        }
        let copy = counter.count(|| black_box(*black_box(&before)));
        let with = counter.count(|| {
            let mut m = *black_box(&before);
            c.update_from_solution(
                black_box(&mut m),
                black_box(ticks),
                black_box(&solution),
                black_box(&tr),
            )
        });
        let plain = counter.count(|| {
            c.update(
                black_box(ticks),
                black_box(&solution.eta),
                black_box(&solution.nu),
                black_box(&tr),
            )
        });
        let count = with.saturating_sub(copy);
        max = max.max(count);
        sum += count;
        share = share.max(count.saturating_sub(plain));
    }
    info!(
        "estimator golden vectors: {} of {} bit for bit",
        exact,
        ESTIMATOR_GOLDEN.len()
    );
    let mean = if n > 0 { sum / n as u32 } else { 0 };
    info!(
        "step update_from_solution (estimator on, a late solution): max={} mean={} instructions (the estimator's share over update: {})",
        max, mean, share
    );
    n > 0 && exact == ESTIMATOR_GOLDEN.len()
}
