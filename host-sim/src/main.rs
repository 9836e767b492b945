//! `host-sim`: software-in-the-loop runs of the AUV-150 controller against the 6-DOF plant.
//! Parses the command line, installs the Ctrl-C/SIGTERM handler ([`host_sim::interrupt`]) and
//! maps the outcome to the exit code; the commands are [`host_sim::cli`]'s, which documents
//! the codes (0 done, 1 a run diverged or lost its board, or PIL ≠ SIL, or `check` found the
//! mission infeasible, 2 bad input, I/O error or an incomplete output, 3 an unexpected
//! controller fault, 4 a run missed its bound or `diff`'s flights differ, 130 interrupted).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use host_sim::cli::{
    self, CampaignArgs, CheckArgs, DiffArgs, FalsifyArgs, HilArgs, ImportPlanArgs, MonteCarloArgs,
    PilArgs, RunArgs, Table1Args, TuneArgs, ValidateArgs,
};

#[derive(Parser)]
#[command(
    name = "host-sim",
    version,
    about = "AUV-150 robust controller: software-in-the-loop simulator"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// The paper's six Table-1 missions with and without Δu, side by side with the paper.
    Table1(Table1Args),
    /// One scenario from a TOML file (and its companion without Δu, for comparison).
    ///
    /// The exit code follows the run of the controller the scenario configures; the companion
    /// without Δu is reported beside it (table, report, JSON), never as the verdict.
    Run(RunArgs),
    /// Processor in the loop: the firmware ELF in QEMU flies the simulated vehicle over a
    /// loopback socket, lock-stepped; compared with SIL. Link faults by tick range (A..B).
    Pil(PilArgs),
    /// Hardware in the loop: the board on a serial port (USB-serial adapter, or QEMU's
    /// `-serial pty`) flies the simulated vehicle, lock-stepped or in real time; compared
    /// with SIL. Link faults as `pil`.
    Hil(HilArgs),
    /// Preflight: can the real thrusters fly this scenario (every corner of the parameter box,
    /// the board's allocator, a margin of the envelope), and if not, at what time scale?
    /// Simulates nothing. Exit 0 feasible, 1 infeasible, 2 bad input.
    Check(CheckArgs),
    /// Draws the Table-3 parameters uniformly in their box, runs in parallel, reports
    /// percentiles and the worst case. Deterministic per seed.
    MonteCarlo(MonteCarloArgs),
    /// Does the preflight's verdict hold? The real paths under every thruster mounting and
    /// random missions, each checked, then flown at the proposed time scale; reports the
    /// false-feasible count (exit 1 if any) and how conservative the verdict is.
    ValidatePreflight(ValidateArgs),
    /// Monte Carlo campaigns beyond one machine: `plan` a campaign file, `run` one shard of it
    /// (Slurm array task, Kubernetes Indexed Job, laptop; restartable), `merge` the shards into
    /// one report whose worst cases replay bit for bit.
    Campaign(CampaignArgs),
    /// Searches for a mission the preflight calls feasible that flies outside its bound: the
    /// cross-entropy method and random search at the same budget, in restarts (sharded as a
    /// campaign, `--merge` keeps the worst); writes each falsifying mission as a scenario
    /// file. Exit 1 if one was found.
    Falsify(FalsifyArgs),
    /// A multi-objective study (NSGA-II) of the controller's gains, K₁, K₂ by axis group, μ,
    /// δ_max and the estimator's σₐ, each candidate scored on one fixed sample of missions
    /// (sharded as a campaign, `--merge` unions the fronts); writes the Pareto front, its
    /// projections and the chosen point as a `[controller]` block beside the shipped gains.
    Tune(TuneArgs),
    /// A QGroundControl `.plan` (its waypoints) as a waypoint scenario on stdout, in the NED
    /// frame of the plan's home position, each altitude in its item's frame. Exit 2 if the file
    /// is not a plan of waypoints, on what the scenario would refuse (named by plan item:
    /// `mission.items[i]`), or on a flag it would refuse (`--speed` outside (0, 10] m/s, a
    /// `--name` that is not a file name); a warning when the flat earth misplaces a waypoint by
    /// more than the 0.05 m path bound.
    ImportPlan(ImportPlanArgs),
    /// Two flights (MCAP logs or runs' CSVs) compared series by series: the first time they
    /// diverge beyond the tolerance and where, the largest difference of each series, a plot
    /// of those that differ most. Exit 0 the same, 4 they differ, 2 bad input.
    Diff(DiffArgs),
}

fn main() -> ExitCode {
    // A file-size limit (`ulimit -f`) makes a write fail with EFBIG, which the outputs report as
    // incomplete (exit 2), instead of killing the process with SIGXFSZ (Choice 121).
    // SAFETY: setting a signal's disposition to "ignore" before any thread is started.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    if let Err(e) = host_sim::interrupt::install() {
        eprintln!("host-sim: warning: no Ctrl-C handler ({e}): an interrupt loses the run");
    }
    let cli = Cli::try_parse().unwrap_or_else(|e| {
        // `check --json` prints one JSON object on every exit, a refused command line included.
        if e.use_stderr() {
            let args: Vec<_> = std::env::args_os().collect();
            if let Some(json) = cli::usage_error_json(&args, &e.to_string()) {
                println!("{json}");
            }
        }
        e.exit()
    });
    let command = cli
        .command
        .unwrap_or_else(|| Command::Table1(Table1Args::default()));
    let stdout = &mut std::io::stdout().lock();
    let result = match command {
        Command::Table1(args) => cli::table1(&args, stdout),
        Command::Run(args) => cli::run(&args, stdout),
        Command::Pil(args) => cli::pil(&args, stdout),
        Command::Hil(args) => cli::hil(&args, stdout),
        Command::MonteCarlo(args) => cli::monte_carlo(&args, stdout),
        Command::Check(args) => cli::check(&args, stdout),
        Command::ValidatePreflight(args) => cli::validate_preflight(&args, stdout),
        Command::Campaign(args) => cli::campaign(&args, stdout),
        Command::Falsify(args) => cli::falsify(&args, stdout),
        Command::Tune(args) => cli::tune(&args, stdout),
        Command::ImportPlan(args) => cli::import_plan(&args, stdout),
        Command::Diff(args) => cli::diff(&args, stdout),
    };
    match result {
        Ok(exit) => ExitCode::from(exit.code()),
        Err(e) => {
            eprintln!("host-sim: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
