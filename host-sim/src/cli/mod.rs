//! The `host-sim` commands as library functions: each takes its arguments ([`clap::Args`], so
//! the binary only parses and dispatches) and a writer for what it prints on stdout, writes its
//! outputs, and returns how it ended ([`Exit`]). Errors (bad input, I/O) are `Err`: the binary
//! prints them once and exits 2.
//!
//! ```text
//! host-sim                                   # = host-sim table1
//! host-sim table1 [--json] [--out DIR] [--contract full|team|none] [--tune main|none]
//! host-sim run --scenario FILE.toml [--json] [--out DIR] [--allow-long-run]
//! host-sim pil (--scenario FILE | --table1) [--duration S] [--drop A..B …] [--link-key-file F] [--json] [--out DIR]
//! host-sim hil --port PATH [--baud N] [--pacing lockstep|realtime] [--reply-timeout S] (--scenario FILE | --table1) [the pil flags] [--json] [--out DIR]
//! host-sim monte-carlo --runs N --seed S [--scenario FILE] [--current V] [--json] [--out DIR]
//! host-sim check --scenario FILE.toml [--margin 0.8] [--json]
//! host-sim validate-preflight [--mountings team|all] [--random N] [--seed S] [--margin 0.8] [--json] [--out DIR] [--allow-long-run]
//! host-sim falsify [--budget B] [--restarts R] [--seed S] [--margin M] [--duration D] [--reach contract|realities] [--navigation PRESET] [--refused graded|flat] [--shard I/N] --out DIR | --merge DIR… --out DIR
//! host-sim tune [--missions M] [--duration D] [--population P] [--generations G] [--restarts R] [--seed S] [--shard I/N] --out DIR | --merge DIR… --out DIR
//! host-sim campaign plan FILE [--workers N] | run FILE [--shard I/N] --out DIR | merge DIR… --out DIR
//! host-sim import-plan FILE.plan [--speed 0.5] [--name NAME]    # the scenario TOML on stdout
//! host-sim diff A B [--abs X] [--rel Y] [--out DIR]              # two flights (MCAP or CSV)
//! ```
//!
//! `check` is the preflight feasibility check ([`crate::studies::preflight`]): it simulates nothing, and
//! exits 0 when the mission is feasible at its time scale, 1 when it is not (the verdict says
//! whether a time scale helps), 2 on bad input. `run` and `table1` print the same verdict for
//! each mission, one line each, and put it in the report; they never refuse to run.
//!
//! `--json` prints one JSON object, `{"cases": [...]}` of [`RunSummary`](crate::sim::record::RunSummary) (table1, run) or of
//! [`BoardComparison`](crate::board::BoardComparison) (pil, hil), or the Monte Carlo [`Summary`](crate::studies::montecarlo::Summary); its
//! keys come out sorted. `check --json` prints one object on every exit, errors and interrupts
//! included ([`check`]).
//!
//! Every command, before it computes anything: validates its input (scenario, flags, the step
//! cap), checks and prepares the output folder ([`OutputDir::prepare`](crate::output::OutputDir::prepare): a folder, not a symlink,
//! writable, not in use by another run (its lock is held for the command's life); the previous
//! run's files removed), and for `pil` checks the firmware image. Then
//! the runs stream their CSVs ([`CsvStream`](crate::output::CsvStream)) and show progress ([`Progress`](crate::sim::progress::Progress)), and the plots
//! and the report follow. An output that cannot be written completely (a full disk, the
//! file-size limit) is named on stderr, in the report and in the JSON (`incomplete`), once,
//! and the command exits 2; the other outputs are still written. An interrupt acts in every
//! phase ([`crate::interrupt`]); one that comes before the runs (during the preflight check)
//! leaves a report saying nothing was simulated.
//!
//! # Exit codes
//!
//! | code | meaning |
//! |---|---|
//! | 0 | every run completed, the controller never in fail-safe unless expected (and PIL agreed with SIL) |
//! | 1 | a run diverged (or lost its board), or PIL disagreed with SIL; `check`: the mission is infeasible |
//! | 2 | bad input (scenario, flags, output folder, firmware image) or an I/O error; or an output could not be written completely |
//! | 3 | a run had the controller in fail-safe (thrusters off) for some periods and its scenario does not say `expect_faults = true` |
//! | 4 | a run completed outside its bound (`[bound]`; the real chain's default 0.05 m, 1 % saturated) and its scenario does not say `expect_missed = true`; `diff`: the two flights differ |
//! | 130 | interrupted (Ctrl-C, SIGTERM): what was done is written and marked partial |
//!
//! When several apply, the first of 2, 130, 1, 3, 4 is the exit code. In `run`, the code follows
//! the run of the controller the scenario configures: its companion without Δu is reported
//! beside it (a line says when it ended otherwise), never as the verdict (Choice 313). In `pil`, a run with link
//! faults injected (flags or `[link_faults]`) expects the board's fail-safe. In `table1`, the
//! paper's missions flown through the real chain are there to show what happens when the
//! preflight says infeasible: their divergence and faults are reported, not an exit code.

mod board_loop;
mod campaign;
mod check;
mod common;
mod diff;
mod falsify;
mod hil;
mod import_plan;
mod json;
mod monte_carlo;
mod pil;
mod run;
mod table1;
mod tune;
mod validate;

pub use board_loop::LoopArgs;
pub use campaign::{campaign, resolve_shard, CampaignArgs, CampaignCommand};
pub use check::{check, usage_error_json, CheckArgs};
pub use diff::{diff, DiffArgs};
pub use falsify::{falsify, FalsifyArgs};
pub use hil::{hil, HilArgs, DEFAULT_HIL_BAUD, DEFAULT_HIL_REPLY_TIMEOUT};
pub use import_plan::{import_plan, ImportPlanArgs};
pub use json::Cases;
pub use monte_carlo::{monte_carlo, MonteCarloArgs};
pub use pil::{pil, PilArgs};
pub use run::{run, RunArgs};
pub use table1::{table1, ContractRun, Table1Args, TuneRun, DEFAULT_TABLE1_OUT};
pub use tune::{tune, write_study as write_tune_study, TuneArgs};
pub use validate::{validate_preflight, Mountings, ValidateArgs};

/// How a command ended, as the process's exit code (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Every run completed, no unexpected controller fault (and PIL agreed with SIL): exit 0.
    Success,
    /// A run diverged or lost its board, or PIL disagreed with SIL: exit 1 (the outputs are
    /// written).
    RunFailed,
    /// An output could not be written completely (named on stderr and in the report): exit 2.
    OutputIncomplete,
    /// The controller was in fail-safe in some period of a run that does not expect faults:
    /// exit 3 (the outputs are written).
    Faulted,
    /// A run completed outside its bound, and its scenario does not expect it: exit 4 (the
    /// outputs are written, the reason is in the outcome).
    Missed,
    /// Interrupted (Ctrl-C, SIGTERM); what was done is written, marked partial: exit 130.
    Interrupted,
    /// `check`: the mission is not feasible at its time scale: exit 1.
    Infeasible,
    /// `diff`: the two flights differ beyond the tolerance: exit 4.
    Differ,
}

impl Exit {
    /// The process exit code (0, 1, 2, 3, 4 or 130; 2 is also the binary's for an `Err`).
    pub fn code(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::RunFailed | Exit::Infeasible => 1,
            Exit::OutputIncomplete => 2,
            Exit::Faulted => 3,
            Exit::Missed | Exit::Differ => 4,
            Exit::Interrupted => 130,
        }
    }

    /// The exit of a command from what happened, in the order of precedence 2, 130, 1, 3, 4.
    fn of(incomplete: bool, interrupted: bool, failed: bool, faulted: bool, missed: bool) -> Self {
        if incomplete {
            Exit::OutputIncomplete
        } else if interrupted {
            Exit::Interrupted
        } else if failed {
            Exit::RunFailed
        } else if faulted {
            Exit::Faulted
        } else if missed {
            Exit::Missed
        } else {
            Exit::Success
        }
    }
}
