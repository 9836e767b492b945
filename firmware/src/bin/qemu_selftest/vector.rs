//! One golden vector ([`Golden`]): the mission as the board receives it, the inputs, and the
//! host core's outputs. The one definition: build.rs computes the vectors with it (through
//! `#[path]`) and writes them out, the self-test reads them back.

use auv_link::MissionPlan;
use controller_core::effectiveness::THRUSTERS;

/// One golden vector: its mission, inputs and the host core's outputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Golden {
    /// The mission, as `StartMission` carries it: a closed-form path by its parameters, the
    /// shipped survey by its upload's CRC (the self-test resolves it from the upload, as the
    /// board does).
    pub plan: MissionPlan,
    /// The control tick (100 Hz).
    pub ticks: u64,
    /// Δu on.
    pub robust: bool,
    /// The navigation solution η.
    pub eta: [f32; 6],
    /// The navigation solution ν.
    pub nu: [f32; 6],
    /// The host's voltages.
    pub voltage: [f32; THRUSTERS],
    /// The host's τ.
    pub tau: [f32; 6],
    /// The host's δ.
    pub delta: f32,
    /// The host's ‖w‖.
    pub w_norm: f32,
    /// 0: `Status::Ok`, 1: a fault.
    pub status: u8,
}

/// One golden vector of the state estimator (docs/law.md#the-state-estimator): the host's
/// output of the last of [`estimator_steps`] (case `case`) on `GOLDEN[vector]`'s inputs, the
/// controller the default with the estimator on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorGolden {
    /// The index of the golden vector whose mission and inputs it flies.
    pub vector: usize,
    /// The case of [`estimator_steps`].
    pub case: usize,
    /// The host's voltages.
    pub voltage: [f32; THRUSTERS],
    /// The host's τ.
    pub tau: [f32; 6],
}

/// How many cases [`estimator_steps`] has.
pub const ESTIMATOR_CASES: usize = 2;

/// The estimator's cases on a golden vector's inputs at tick k (≥ 17), each three
/// `(ticks, solution)` in order, the last counted; `None` before tick 17 or past the cases.
///
/// - Case 0, one period late: the solution of tick k − 3 taken; tick k − 2 flown on it
///   predicted (the navigation computer repeats its stamp); then at tick k the solution stamped
///   k − 1, 3 mm further in x: its correction at an old stamp, with both predictions and the
///   recorded accelerations.
/// - Case 1, the estimator's largest fixed work: the solution of tick k − 17 taken, tick k − 16
///   flown on it predicted, then no period flown until tick k (a lock-step frame's `t_ticks`
///   may jump so), whose solution is stamped k − 15, the first period not flown (the oldest
///   taken after them, Choice 554; [`controller_core::estimator::MAX_AGE`] old): the correction
///   at k − 15 and the prediction to k, both past the last period recorded, then the record
///   starts the ring's sums afresh at k (the stamp it keeps: no third prediction).
pub fn estimator_steps(g: &Golden, case: usize) -> Option<[(u64, controller_core::Solution); 3]> {
    let k = g.ticks;
    if k < 17 {
        return None;
    }
    let at = |stamp: u64, dx: f32| {
        let mut eta = g.eta;
        eta[0] += dx;
        controller_core::Solution {
            stamp,
            eta,
            nu: g.nu,
        }
    };
    match case {
        0 => Some([
            (k - 3, at(k - 3, 0.0)),
            (k - 2, at(k - 3, 0.0)),
            (k, at(k - 1, 0.003)),
        ]),
        1 => Some([
            (k - 17, at(k - 17, 0.0)),
            (k - 16, at(k - 17, 0.0)),
            (k, at(k - 15, 0.003)),
        ]),
        _ => None,
    }
}
