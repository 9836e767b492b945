//! `host-sim campaign plan|run|merge`: Monte Carlo campaigns in shards (docs/campaigns.md).
//!
//! ```text
//! host-sim campaign plan FILE [--workers N]
//! host-sim campaign run FILE [--shard I/N] [--shards N] --out DIR
//! host-sim campaign merge SHARD_DIR… --out DIR [--json]
//! ```
//!
//! `run` without `--shard` takes the shard from the engine (**Choice 137**): Slurm's
//! `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN` of `SLURM_ARRAY_TASK_COUNT`, or Kubernetes'
//! `JOB_COMPLETION_INDEX` of `--shards N` (or `HOST_SIM_SHARDS`); with none of them it is the
//! whole campaign, 0/1. `{shard}` in `--out` is replaced by the shard's index. A shard exits 0
//! when it has recorded all its runs, whatever they did (the verdict is the merge's); 130 if
//! interrupted (rerun it: it skips the runs recorded). `merge` exits 2 when the shards do not
//! make the campaign exactly (each problem named), 4 when fewer runs than `bound.fraction` are
//! within bound, else 0.

use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};

use super::Exit;
use crate::interrupt;
use crate::output::campaign::{self as out, RecordLog};
use crate::output::OutputDir;
use crate::sim::progress::duration_text;
use crate::studies::campaign::merge::{self, Manifest};
use crate::studies::campaign::{shard_indices, Campaign};

/// `campaign`: plan, run a shard, merge.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct CampaignArgs {
    #[command(subcommand)]
    pub command: CampaignCommand,
}

#[derive(Subcommand, Clone, Debug, PartialEq)]
pub enum CampaignCommand {
    /// The run count, the CPU time from a calibration run, and a shard layout for N workers.
    Plan(PlanArgs),
    /// Runs one shard: the runs whose index ≡ I (mod N); restartable.
    Run(ShardArgs),
    /// Checks the shards make the campaign exactly once, and writes one report.
    Merge(MergeArgs),
}

#[derive(Args, Clone, Debug, PartialEq)]
pub struct PlanArgs {
    pub file: PathBuf,
    /// Workers (cores) the campaign will have.
    #[arg(long, default_value_t = 1)]
    pub workers: u64,
}

#[derive(Args, Clone, Debug, PartialEq)]
pub struct ShardArgs {
    pub file: PathBuf,
    /// This shard, I/N (0 ≤ I < N); default from the engine's environment.
    #[arg(long)]
    pub shard: Option<String>,
    /// The shard count with JOB_COMPLETION_INDEX (else HOST_SIM_SHARDS).
    #[arg(long)]
    pub shards: Option<u64>,
    /// The shard's folder (`{shard}` is replaced by I). Rerun into the same folder to resume.
    #[arg(long)]
    pub out: String,
}

#[derive(Args, Clone, Debug, PartialEq)]
pub struct MergeArgs {
    /// The shard folders.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    #[arg(long)]
    pub out: PathBuf,
    /// Print the summary (summary.json) on stdout instead of the text.
    #[arg(long)]
    pub json: bool,
}

/// `campaign`.
pub fn campaign(args: &CampaignArgs, stdout: &mut dyn Write) -> Result<Exit> {
    match &args.command {
        CampaignCommand::Plan(a) => plan(a, stdout),
        CampaignCommand::Run(a) => run_shard(a, stdout),
        CampaignCommand::Merge(a) => merge_shards(a, stdout),
    }
}

fn load(path: &Path) -> Result<Campaign> {
    Campaign::load(path).map_err(anyhow::Error::new)
}

/// The shard I/N from `--shard`, else the engine's environment (`env`), else 0/1.
pub fn resolve_shard(
    flag: Option<&str>,
    count: Option<u64>,
    env: impl Fn(&str) -> Option<String>,
) -> Result<(u64, u64)> {
    let num = |what: &str, s: &str| -> Result<u64> {
        s.trim()
            .parse()
            .with_context(|| format!("{what} must be a whole number ≥ 0, got {s:?}"))
    };
    let (i, n) = if let Some(s) = flag {
        let (a, b) = s
            .split_once('/')
            .with_context(|| format!("--shard must be I/N, got {s:?}"))?;
        (num("--shard's I", a)?, num("--shard's N", b)?)
    } else if let Some(id) = env("SLURM_ARRAY_TASK_ID") {
        let min = match env("SLURM_ARRAY_TASK_MIN") {
            Some(m) => num("SLURM_ARRAY_TASK_MIN", &m)?,
            None => 0,
        };
        let n = env("SLURM_ARRAY_TASK_COUNT").context(
            "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; give --shard I/N",
        )?;
        let id = num("SLURM_ARRAY_TASK_ID", &id)?;
        let i = id
            .checked_sub(min)
            .context("SLURM_ARRAY_TASK_ID < SLURM_ARRAY_TASK_MIN")?;
        (i, num("SLURM_ARRAY_TASK_COUNT", &n)?)
    } else if let Some(idx) = env("JOB_COMPLETION_INDEX") {
        let n = match (count, env("HOST_SIM_SHARDS")) {
            (Some(n), _) => n,
            (None, Some(s)) => num("HOST_SIM_SHARDS", &s)?,
            (None, None) => bail!(
                "JOB_COMPLETION_INDEX is set but not the shard count: give --shards N (the \
                 Job's completions) or HOST_SIM_SHARDS"
            ),
        };
        (num("JOB_COMPLETION_INDEX", &idx)?, n)
    } else {
        (0, count.unwrap_or(1))
    };
    if n == 0 || i >= n {
        bail!("shard {i}/{n}: need 0 ≤ I < N");
    }
    Ok((i, n))
}

/// `campaign run`.
fn run_shard(a: &ShardArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let c = load(Path::new(&a.file))?;
    let (shard, shards) = resolve_shard(a.shard.as_deref(), a.shards, |k| std::env::var(k).ok())?;
    if shards > c.runs() {
        bail!("{shards} shards for {} runs: some would be empty", c.runs());
    }
    let out = PathBuf::from(a.out.replace("{shard}", &shard.to_string()));
    let (dir, done) = resume_shard(&c, shard, shards, &out)?;
    let todo: Vec<u64> = shard_indices(c.runs(), shard, shards)
        .filter(|i| !done.contains(i))
        .collect();
    out::write_manifest(&dir, &Manifest::of(&c, shard, shards, done.len() as u64))?;
    eprintln!(
        "host-sim: campaign {} shard {shard}/{shards}: {} runs to do ({} recorded before), \
         {} thread(s)",
        c.spec.name(),
        todo.len(),
        done.len(),
        rayon::current_num_threads()
    );
    let log = RecordLog::open(&dir)?;
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let new = fly_logged(&c, &todo, &log, &format!("{shard}/{shards}"));
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    log.finish()?;
    let m = Manifest::of(&c, shard, shards, done.len() as u64 + new);
    out::write_manifest(&dir, &m)?;
    writeln!(
        stdout,
        "shard {shard}/{shards}: {new} runs in {} ({:.1} runs/s; {:.1} runs per CPU-second, \
         {:.2} ms of CPU per run); {} of {} recorded{}\nrecords: {}",
        duration_text(wall),
        new as f64 / wall.max(1e-9),
        new as f64 / cpu.max(1e-9),
        1e3 * cpu / (new.max(1) as f64),
        m.done,
        m.owned,
        if m.complete {
            ""
        } else {
            " (PARTIAL: rerun to finish)"
        },
        out.join(out::RECORDS).display()
    )?;
    Ok(if m.complete && !interrupt::requested() {
        Exit::Success
    } else {
        Exit::Interrupted
    })
}

/// The shard folder `out`, locked and kept (Choice 135): it must hold nothing or this shard of
/// this campaign; its records read (a torn last line cut, Choice 136) and checked to be this
/// shard's. Returns the folder and the indices recorded.
fn resume_shard(
    c: &Campaign,
    shard: u64,
    shards: u64,
    out: &Path,
) -> Result<(OutputDir, HashSet<u64>)> {
    let dir = OutputDir::resume(out)?;
    if let Some(m) = out::read_manifest(out)? {
        if (m.campaign_hash.as_str(), m.shard, m.shards) != (c.hash.as_str(), shard, shards) {
            bail!(
                "{} holds shard {}/{} of campaign {} (hash {}…), not shard {shard}/{shards} of \
                 this one; give another --out",
                out.display(),
                m.shard,
                m.shards,
                m.name,
                &m.campaign_hash[..12.min(m.campaign_hash.len())]
            );
        }
    }
    let done = out::read_records(&out.join(out::RECORDS), true)?;
    if let Some(r) = done.iter().find(|r| r.index % shards != shard) {
        bail!(
            "{} records run {}, which is not shard {shard}/{shards}'s",
            out.display(),
            r.index
        );
    }
    Ok((dir, done.iter().map(|r| r.index).collect()))
}

/// Flies `todo` in parallel into `log`, with a progress line on stderr every 5 % (a batch
/// job's log has no terminal for a bar); returns how many runs were recorded.
fn fly_logged(c: &Campaign, todo: &[u64], log: &RecordLog, shard: &str) -> u64 {
    let new = AtomicU64::new(0);
    let t0 = Instant::now();
    let every = (todo.len() as u64).div_ceil(20).max(1);
    c.run_indices(todo, |r| {
        log.push(&r);
        let k = new.fetch_add(1, Ordering::Relaxed) + 1;
        if k.is_multiple_of(every) && k < todo.len() as u64 {
            let s = t0.elapsed().as_secs_f64();
            eprintln!(
                "host-sim: shard {shard}: {k} of {} runs, {} ({:.1} runs/s)",
                todo.len(),
                duration_text(s),
                k as f64 / s.max(1e-9)
            );
        }
    });
    new.into_inner()
}

/// CPU time of this process so far (user + system, every thread), s: the per-run cost on a
/// machine shared with others, where the wall time is not ours.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given, nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return f64::NAN;
    }
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// `campaign merge`.
fn merge_shards(a: &MergeArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let mut shards = a
        .shards
        .iter()
        .map(|d| out::read_shard(d))
        .collect::<Result<Vec<_>>>()?;
    let records = merge::check(&mut shards).map_err(|e| anyhow::anyhow!("cannot merge:\n{e}"))?;
    let m = &shards[0].manifest;
    let c = Campaign::from_manifest(m)
        .with_context(|| format!("the campaign kept in {}", shards[0].label))?;
    if c.hash != m.campaign_hash {
        bail!(
            "the shards were made by {} and this is {}: a different program flies the runs \
             differently; merge with the host-sim that made them",
            m.program_version,
            crate::studies::campaign::PROGRAM_VERSION
        );
    }
    let dir = OutputDir::prepare(&a.out)?;
    let merged = out::write_report(&dir, &c, &records)?;
    for e in &merged.incomplete {
        eprintln!("host-sim: error: {e}");
    }
    let missed = merged
        .required
        .is_some_and(|f| (merged.within as f64) < f * merged.runs as f64);
    let exit = Exit::of(!merged.incomplete.is_empty(), false, false, false, missed);
    if a.json {
        let text = std::fs::read_to_string(a.out.join(out::SUMMARY))
            .with_context(|| format!("reading {}", a.out.join(out::SUMMARY).display()))?;
        writeln!(stdout, "{}", text.trim_end())?;
        return Ok(exit);
    }
    writeln!(
        stdout,
        "campaign {}: {} runs from {} shard(s); within bound {} ({:.4} %), diverged {}",
        c.spec.name(),
        merged.runs,
        shards.len(),
        merged.within,
        100.0 * merged.within as f64 / merged.runs.max(1) as f64,
        merged.diverged
    )?;
    for s in &merged.stats {
        writeln!(
            stdout,
            "  {:<20} p50 {:.6}  p99 {:.6}  max {:.6}  worst run {}",
            s.name,
            s.p50,
            s.p99,
            s.max,
            s.worst.map_or("—".into(), |i| i.to_string())
        )?;
    }
    writeln!(stdout, "report: {}", merged.report.display())?;
    Ok(exit)
}

/// `campaign plan`.
fn plan(a: &PlanArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let c = load(&a.file)?;
    if a.workers == 0 {
        bail!("--workers must be at least 1");
    }
    let per_run = c.calibrate()?;
    let total = per_run * c.runs() as f64;
    let workers = a.workers;
    // Shards of at most about an hour of one core each (a preempted or failed shard costs at
    // most that), and a multiple of the workers so that every worker has as many.
    let hour_shards = (total / 3600.0).ceil().max(1.0) as u64;
    let shards = hour_shards.div_ceil(workers).max(1) * workers;
    let shards = shards.min(c.runs());
    writeln!(
        stdout,
        "campaign {} ({} base(s), hash {}…)\n\
         runs: {}\n\
         per run: {:.4} s of CPU ({:.1} runs/s per core; calibration run of {} s simulated, \
         scaled by plant steps)\n\
         total: {} of CPU; on {workers} worker(s): about {}\n\
         suggested shards: {shards} (≤ about an hour of one core each, {} per worker), e.g.\n  \
         sbatch --array=0-{}%{workers} deploy/slurm/campaign.sbatch {}\n  \
         host-sim campaign run {} --shard I/{shards} --out DIR/shard-I",
        c.spec.name(),
        c.bases.len(),
        &c.hash[..12],
        c.runs(),
        per_run,
        1.0 / per_run.max(1e-12),
        crate::studies::montecarlo::CALIBRATION_SECONDS,
        duration_text(total),
        duration_text(total / workers as f64),
        shards / workers,
        shards - 1,
        a.file.display(),
        a.file.display()
    )?;
    Ok(Exit::Success)
}
