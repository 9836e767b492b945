//! Instructions per call, exact: each stage of `update` on the golden vectors' own inputs, the
//! whole `update`, and the math kernels.
//!
//! SysTick counts 40 instructions a count under `-icount shift=0` (`firmware::qemu_clock`), too
//! coarse for one call of a stage. So each call is repeated `counter::REPS` = 40 times back to
//! back on the same inputs (every call does the same work: the core keeps no state), the loop's own
//! cost (an empty loop, counted the same way) is subtracted, and the total of 40 calls in
//! instructions divided by 40 is one call's count (quantised to one instruction; what remains
//! of the loop is passing the inputs and taking the result's address). Inputs and results pass
//! through [`black_box`], so the compiler can neither hoist the work out of the loop nor drop it.
//!
//! The lines this prints are what `cargo xtask firmware` budgets (`firmware::budget`): one
//! `stage NAME: max=N mean=N instructions` line per [`Stage`] and one `step update: …` line.

use core::hint::black_box;

use controller_core::{Controller, ControllerConfig, Stage, Table1Case, Trajectory};
use defmt::{error, info};

use crate::counter::Counter;
use crate::golden::{Golden, GOLDEN};

/// Largest and mean count.
#[derive(Clone, Copy, Default)]
struct Stat {
    max: u32,
    sum: u32,
    n: u32,
}

impl Stat {
    fn add(&mut self, count: u32) {
        self.max = self.max.max(count);
        self.sum += count;
        self.n += 1;
    }

    fn mean(&self) -> u32 {
        self.sum.checked_div(self.n).unwrap_or(0)
    }
}

const STAGES: usize = Stage::ALL.len();

/// One stage's count per call on one golden vector's inputs, in [`Stage::ALL`]'s order, and
/// `update`'s; `None` for a vector that `update` rejects (its stages do not all run).
fn step_counts(
    counter: &Counter,
    c: &Controller,
    tr: &Trajectory,
    g: &Golden,
) -> Option<([u32; STAGES], u32)> {
    // The intermediate values each stage takes, from the stages before it.
    let kin = c.kinematics_stage(&g.eta, &g.nu).ok()?;
    let desired = c.trajectory_stage(g.ticks, tr);
    let law = c.law_stage(&kin, &desired, tr).ok()?;
    let demand = c.allocation_stage(&law.tau).thrusts;
    let mut counts = [0u32; STAGES];
    for (slot, stage) in counts.iter_mut().zip(Stage::ALL) {
        *slot = match stage {
            Stage::Kinematics => {
                counter.count(|| c.kinematics_stage(black_box(&g.eta), black_box(&g.nu)))
            }
            Stage::Trajectory => {
                counter.count(|| c.trajectory_stage(black_box(g.ticks), black_box(tr)))
            }
            Stage::Law => {
                counter.count(|| c.law_stage(black_box(&kin), black_box(&desired), black_box(tr)))
            }
            Stage::Allocation => counter.count(|| c.allocation_stage(black_box(&law.tau))),
            Stage::Maps => counter.count(|| c.maps_stage(black_box(&demand))),
        };
    }
    let update = counter.count(|| {
        c.update(
            black_box(g.ticks),
            black_box(&g.eta),
            black_box(&g.nu),
            black_box(tr),
        )
    });
    Some((counts, update))
}

/// Per-stage cost of `update` over the golden vectors: one line per Table-1 case (the largest
/// count of each stage over its vectors, Δu on and off), then per stage the largest and the
/// mean over all vectors. Returns the largest count per stage and of `update`.
pub fn stages(
    counter: &Counter,
    with: &Controller,
    without: &Controller,
    golden: &[Golden],
) -> ([u32; STAGES], u32) {
    let mut stage = [Stat::default(); STAGES];
    let mut update = Stat::default();
    // One row per Table-1 case, then the survey's.
    let mut per_case = [[0u32; STAGES + 1]; Table1Case::ALL.len() + 1];
    let mut tr = Trajectory::EMPTY;
    for g in golden {
        if !g.set(&mut tr) {
            continue;
        }
        let c = if g.robust { with } else { without };
        let Some((counts, total)) = step_counts(counter, c, &tr, g) else {
            continue;
        };
        // The per-mission rows are the Table-1 paths (either heading) and the survey; the other
        // kinds' examples count in the per-stage maxima below only.
        let row = if g.is_survey() {
            Some(Table1Case::ALL.len())
        } else {
            g.case()
        };
        for (i, &n) in counts.iter().enumerate() {
            stage[i].add(n);
            if let Some(r) = row {
                per_case[r][i] = per_case[r][i].max(n);
            }
        }
        update.add(total);
        if let Some(r) = row {
            per_case[r][STAGES] = per_case[r][STAGES].max(total);
        }
    }
    info!(
        "step cost per call (instructions, the largest over each mission's golden vectors), stages {=[?]}:",
        Stage::ALL.map(|s| s.name())
    );
    let names = Table1Case::ALL.map(|c| c.name());
    for (name, row) in names
        .iter()
        .chain(["survey (waypoints)"].iter())
        .zip(per_case.iter())
    {
        info!(
            "  {=str}: {=[?]} = update {} instructions",
            name,
            row[..STAGES],
            row[STAGES]
        );
    }
    for (s, st) in Stage::ALL.iter().zip(stage.iter()) {
        info!(
            "stage {=str}: max={} mean={} instructions",
            s.name(),
            st.max,
            st.mean()
        );
    }
    let sum_of_max: u32 = stage.iter().map(|s| s.max).sum();
    info!(
        "step update: max={} mean={} instructions (the stages' maxima add up to {})",
        update.max,
        update.mean(),
        sum_of_max
    );
    (stage.map(|s| s.max), update.max)
}

/// The counts of this module and of the math kernels (`crate::kernels`), after `update`'s own
/// count (`update_max`, one call at a time, in whole SysTick counts) has been checked against
/// its budget. Returns false if `update` is over budget or a kernel differs from the host (the
/// xtask checks the stages' budgets from the log).
pub fn run(update_max: u32) -> bool {
    let backend = controller_core::math::BACKEND;
    let Some(budget) = firmware::budget::for_backend(backend) else {
        error!(
            "no instruction budget for the {=str} backend (firmware::budget)",
            backend
        );
        return false;
    };
    let update_ok = update_max <= budget.update;
    if !update_ok {
        error!(
            "update exceeds its budget of {} instructions",
            budget.update
        );
    }
    let with = Controller::new(ControllerConfig::default());
    let without = Controller::new(ControllerConfig {
        robust: false,
        ..ControllerConfig::default()
    });
    let (Ok(with), Ok(without)) = (with, without) else {
        error!("controller configuration rejected on the target");
        return false;
    };
    let counter = Counter::new();
    stages(&counter, &with, &without, &GOLDEN);
    let estimator_ok = crate::estimator::run(&counter);
    let kernels_ok = crate::kernels::run(&counter);
    update_ok && estimator_ok && kernels_ok
}
