//! The state estimator on the target (docs/law.md#the-state-estimator): its golden vectors
//! ([`ESTIMATOR_GOLDEN`], the host's outputs of `update_from_solution` on the same steps) bit
//! for bit, and the instructions of `update_from_solution` with the estimator on at its
//! largest fixed work (a solution 15 periods late after 15 periods not flown, the
//! second of [`estimator_steps`]' cases), counted as the stages are
//! ([`Counter`]): the whole call, each of its [`EstimatorStage`]s, and `update`'s count on the
//! same inputs for the estimator's share. The whole call's largest count is held against
//! `firmware::budget` here (the self-test fails over it); the xtask holds each stage's.
//!
//! Each counted call that changes the estimator's memory starts from a copy of it; the copy
//! alone is counted the same way and subtracted.

use core::hint::black_box;

use controller_core::{
    Controller, ControllerConfig, Estimate, EstimatorKind, EstimatorStage, Table1Case, Trajectory,
};
use defmt::{error, info};

use crate::counter::Counter;
use crate::golden::{estimator_steps, ESTIMATOR_CASES, ESTIMATOR_GOLDEN, GOLDEN};

const STAGES: usize = EstimatorStage::ALL.len();

/// Checks and counts; false if a vector differs from the host's, none ran, or the largest
/// `update_from_solution` is over its budget.
// Long: each golden vector is checked, counted whole, then counted stage by stage on the
// intermediate values its own call made (the filter's state, the estimate), in one pass; a split
// would hand a dozen locals across, and moving counted code changes the snapshot's counts.
pub fn run(counter: &Counter) -> bool {
    let mut cfg = ControllerConfig::default();
    cfg.estimator.kind = EstimatorKind::Kalman;
    let Ok(c) = Controller::new(cfg) else {
        error!("the controller with the estimator is rejected on the target");
        return false;
    };
    let Some(parts) = c.estimator_parts().copied() else {
        error!("the estimator is off in a controller configured with it");
        return false;
    };
    let (mut exact, mut n) = (0usize, 0usize);
    let (mut max, mut sum, mut share) = (0u32, 0u32, 0u32);
    let (mut stage_max, mut stage_sum) = ([0u32; STAGES], [0u32; STAGES]);
    let mut case_max = [0u32; ESTIMATOR_CASES];
    // The largest whole call per Table-1 path (either heading): where the worst case flies.
    let mut mission_max = [0u32; Table1Case::ALL.len()];
    let mut tr = Trajectory::EMPTY;
    for e in &ESTIMATOR_GOLDEN {
        let g = &GOLDEN[e.vector];
        let Some(steps) = estimator_steps(g, e.case) else {
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
        // The copy as the counted calls make it: into a local, passed on by reference.
        let copy = counter.count(|| {
            let mut m = *black_box(&before);
            black_box(&mut m).stamp()
        });
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
        if let Some(m) = case_max.get_mut(e.case) {
            *m = (*m).max(count);
        }
        if let Some(m) = g.case().and_then(|i| mission_max.get_mut(i)) {
            *m = (*m).max(count);
        }
        sum += count;
        share = share.max(count.saturating_sub(plain));

        // The stages on this vector's own intermediate values, in order.
        let Ok(eta_dot) = c.estimator_solution_stage(&solution) else {
            continue;
        };
        // `memory` again: the memory after the filter, which the record stage starts from.
        memory = before;
        let (period, state) =
            Controller::estimator_filter_stage(&parts, &mut memory, ticks, &solution, &eta_dot);
        let Ok(est) = c.estimator_estimate_stage(state, &solution, &eta_dot) else {
            continue;
        };
        for (i, stage) in EstimatorStage::ALL.into_iter().enumerate() {
            let count = match stage {
                EstimatorStage::Solution => {
                    counter.count(|| c.estimator_solution_stage(black_box(&solution)))
                }
                EstimatorStage::Filter => counter
                    .count(|| {
                        let mut m = *black_box(&before);
                        Controller::estimator_filter_stage(
                            black_box(&parts),
                            black_box(&mut m),
                            black_box(ticks),
                            black_box(&solution),
                            black_box(&eta_dot),
                        )
                    })
                    .saturating_sub(copy),
                EstimatorStage::Estimate => counter.count(|| {
                    c.estimator_estimate_stage(
                        black_box(state),
                        black_box(&solution),
                        black_box(&eta_dot),
                    )
                }),
                EstimatorStage::Record => counter
                    .count(|| {
                        let mut m = *black_box(&memory);
                        Controller::estimator_record_stage(
                            black_box(&parts),
                            black_box(&mut m),
                            black_box(period),
                            black_box(&est),
                            black_box(&o),
                        );
                        m.stamp()
                    })
                    .saturating_sub(copy),
            };
            stage_max[i] = stage_max[i].max(count);
            stage_sum[i] += count;
        }
    }
    info!(
        "estimator golden vectors: {} of {} bit for bit",
        exact,
        ESTIMATOR_GOLDEN.len()
    );
    let mean = |s: u32| if n > 0 { s / n as u32 } else { 0 };
    for (i, stage) in EstimatorStage::ALL.into_iter().enumerate() {
        info!(
            "stage {=str}: max={} mean={} instructions",
            stage.name(),
            stage_max[i],
            mean(stage_sum[i])
        );
    }
    info!(
        "update_from_solution per case of estimator_steps (max): one period late {}, fifteen periods late after fifteen not flown {}",
        case_max[0],
        case_max[1]
    );
    info!(
        "update_from_solution per mission (max over both cases), {=[?]}: {=[?]}",
        Table1Case::ALL.map(|c| c.name()),
        mission_max
    );
    info!(
        "step update_from_solution (estimator on, late solutions): max={} mean={} instructions (the estimator's share over update: {})",
        max,
        mean(sum),
        share
    );
    let budget = firmware::budget::for_backend(controller_core::math::BACKEND)
        .map_or(0, |b| b.update_from_solution);
    let within = max <= budget;
    if !within {
        error!(
            "update_from_solution exceeds its budget of {} instructions",
            budget
        );
    }
    n > 0 && exact == ESTIMATOR_GOLDEN.len() && within
}
