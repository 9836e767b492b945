//! `host-sim campaign plan|run|merge`: Monte Carlo campaigns in shards (docs/campaigns.md).
//!
//! ```text
//! host-sim campaign plan FILE [--workers N]
//! host-sim campaign run FILE [--shard I/N] [--shards N] --out DIR
//! host-sim campaign merge SHARD_DIR… --out DIR [--json]
//! ```
//!
//! `run` without `--shard` takes the shard from the engine (**Choice 137**, **Choice 246**):
//! Slurm's (`SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN`) / `SLURM_ARRAY_TASK_STEP` of
//! `SLURM_ARRAY_TASK_COUNT`, or Kubernetes' `JOB_COMPLETION_INDEX` of `--shards N` (or
//! `HOST_SIM_SHARDS`); with none of them it is the whole campaign, 0/1. What is ambiguous is
//! refused with the reason: a count without an index, counts that disagree, both engines, an
//! array whose indices are not evenly spaced. `{shard}` in `--out` is replaced by the shard's
//! index. A shard exits 0 when it has recorded all its runs, whatever they did (the verdict is
//! the merge's); 130 if interrupted (rerun it: it skips the runs recorded). `merge` exits 2 when
//! the shards do not make the campaign exactly (each problem named), 1 when no run flew, 4 when
//! fewer runs than `bound.fraction` are within bound, else 0.

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
use crate::studies::campaign::{Campaign, Done, Shard};

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
    /// The shard count with JOB_COMPLETION_INDEX (else HOST_SIM_SHARDS); with Slurm or
    /// --shard it must agree with theirs.
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

/// A sharded search's restarts (`falsify`, `tune`): this shard's, or the merge of shards'
/// folders; the shards' unit is the restart (r ≡ I mod N).
#[derive(clap::Args, Clone, Debug, PartialEq)]
pub struct RestartShards {
    /// This shard, I/N: restarts r ≡ I (mod N); default from the engine's environment.
    #[arg(long)]
    pub shard: Option<String>,
    /// The shard count with JOB_COMPLETION_INDEX (as `campaign run`).
    #[arg(long)]
    pub shards: Option<u64>,
    /// Merge these shard folders (their `shard.json`) instead of searching.
    #[arg(long, num_args = 1..)]
    pub merge: Vec<PathBuf>,
}

impl RestartShards {
    /// The shard I/N these flags and the engine's environment name ([`resolve_shard`]).
    pub fn resolve(&self) -> Result<(u64, u64)> {
        resolve_shard(self.shard.as_deref(), self.shards, |k| {
            std::env::var(k).ok()
        })
    }

    /// Each `--merge` folder's `shard.json`, read as a shard of `what` (named in the error).
    pub fn read_merged<T: serde::de::DeserializeOwned>(&self, what: &str) -> Result<Vec<T>> {
        self.merge
            .iter()
            .map(|d| {
                let p = d.join("shard.json");
                let text = std::fs::read_to_string(&p)
                    .with_context(|| format!("reading {}", p.display()))?;
                serde_json::from_str::<T>(&text)
                    .with_context(|| format!("{} is not a {what} shard", p.display()))
            })
            .collect()
    }
}

/// The shard I/N from `--shard`, else the engine's environment (`env`), else 0/1
/// (**Choice 137**); what is ambiguous is refused with the reason (**Choice 246**).
pub fn resolve_shard(
    flag: Option<&str>,
    count: Option<u64>,
    env: impl Fn(&str) -> Option<String>,
) -> Result<(u64, u64)> {
    let (i, n) = match (
        flag,
        env("SLURM_ARRAY_TASK_ID"),
        env("JOB_COMPLETION_INDEX"),
    ) {
        (Some(s), _, _) => {
            let (a, b) = s
                .split_once('/')
                .with_context(|| format!("--shard must be I/N, got {s:?}"))?;
            let (i, n) = (number("--shard's I", a)?, number("--shard's N", b)?);
            if count.is_some_and(|c| c != n) {
                bail!(
                    "--shard {s} and --shards {} disagree on the shard count; give one of them",
                    count.unwrap_or_default()
                );
            }
            (i, n)
        }
        (None, Some(_), Some(_)) => bail!(
            "both SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX are set: which engine's index \
             this shard is, is not known; give --shard I/N"
        ),
        (None, Some(id), None) => slurm_shard(&id, count, &env)?,
        (None, None, Some(idx)) => {
            let n = match (count, env("HOST_SIM_SHARDS")) {
                (Some(n), None) => n,
                (Some(n), Some(s)) if number("HOST_SIM_SHARDS", &s)? == n => n,
                (Some(n), Some(s)) => bail!(
                    "--shards {n} and HOST_SIM_SHARDS={s} disagree on the shard count; give one \
                     of them"
                ),
                (None, Some(s)) => number("HOST_SIM_SHARDS", &s)?,
                (None, None) => bail!(
                    "JOB_COMPLETION_INDEX is set but not the shard count: give --shards N (the \
                     Job's completions) or HOST_SIM_SHARDS"
                ),
            };
            (number("JOB_COMPLETION_INDEX", &idx)?, n)
        }
        (None, None, None) => match count {
            None | Some(1) => (0, 1),
            Some(n) => bail!(
                "--shards {n} without this shard's index: give --shard I/{n} (or run it as a \
                 Slurm array task or a Kubernetes Indexed Job, which give the index)"
            ),
        },
    };
    if n == 0 || i >= n {
        bail!("shard {i}/{n}: need 0 ≤ I < N");
    }
    Ok((i, n))
}

fn number(what: &str, s: &str) -> Result<u64> {
    s.trim()
        .parse()
        .with_context(|| format!("{what} must be a whole number ≥ 0, got {s:?}"))
}

/// The shard of Slurm array task `id`: (id − MIN) / STEP of COUNT, for an array of evenly
/// spaced indices (`--array=A-B`, `--array=A-B:S`); a list that is not (`--array=0,2,3`: MAX is
/// not MIN + (COUNT − 1)·STEP) has no shard numbering to read, and is refused.
fn slurm_shard(
    id: &str,
    count: Option<u64>,
    env: &impl Fn(&str) -> Option<String>,
) -> Result<(u64, u64)> {
    let var = |k: &str, default: Option<u64>| -> Result<Option<u64>> {
        env(k)
            .map(|v| number(k, &v))
            .transpose()
            .map(|v| v.or(default))
    };
    let id = number("SLURM_ARRAY_TASK_ID", id)?;
    let min = var("SLURM_ARRAY_TASK_MIN", Some(0))?.unwrap_or_default();
    let step = var("SLURM_ARRAY_TASK_STEP", Some(1))?.unwrap_or(1);
    let n = var("SLURM_ARRAY_TASK_COUNT", None)?.context(
        "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; give --shard I/N",
    )?;
    if step == 0 {
        bail!("SLURM_ARRAY_TASK_STEP is 0; give --shard I/N");
    }
    let spaced = n
        .checked_sub(1)
        .and_then(|k| k.checked_mul(step))
        .and_then(|k| k.checked_add(min));
    if let Some(max) = var("SLURM_ARRAY_TASK_MAX", None)? {
        if spaced != Some(max) {
            bail!(
                "the array's task indices are not evenly spaced (MIN {min}, MAX {max}, STEP \
                 {step}, COUNT {n}: a list such as --array=0,2,3), so they do not number the \
                 shards; submit --array=0-{} or give --shard I/N",
                n.saturating_sub(1)
            );
        }
    }
    let offset = id
        .checked_sub(min)
        .context("SLURM_ARRAY_TASK_ID < SLURM_ARRAY_TASK_MIN")?;
    if offset % step != 0 {
        bail!("SLURM_ARRAY_TASK_ID {id} is not MIN {min} plus a multiple of STEP {step}");
    }
    if let Some(c) = count.filter(|c| *c != n) {
        bail!(
            "SLURM_ARRAY_TASK_COUNT is {n} but --shards {c}: the array has {n} tasks, one a \
             shard; drop --shards, or submit the array with {c} tasks"
        );
    }
    Ok((offset / step, n))
}

/// `campaign run`.
fn run_shard(a: &ShardArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let c = load(Path::new(&a.file))?;
    let (shard, shards) = resolve_shard(a.shard.as_deref(), a.shards, |k| std::env::var(k).ok())?;
    if shards > c.runs() {
        bail!("{shards} shards for {} runs: some would be empty", c.runs());
    }
    let out = PathBuf::from(a.out.replace("{shard}", &shard.to_string()));
    let part = c.shard(shard, shards);
    let (dir, done) = resume_shard(&c, part, &out)?;
    out::write_manifest(&dir, &Manifest::of(&c, shard, shards, done.len()))?;
    let todo = part.len() - done.len();
    eprintln!(
        "host-sim: campaign {} shard {shard}/{shards}: {todo} runs to do ({} recorded before), \
         {} thread(s)",
        c.spec.name(),
        done.len(),
        rayon::current_num_threads()
    );
    let log = RecordLog::open(&dir)?;
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let new = fly_logged(&c, part, &done, todo, &log);
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    log.finish()?;
    let m = Manifest::of(&c, shard, shards, done.len() + new);
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
/// this campaign (a manifest host-sim wrote whole, Choice 241); its records read one by one (a
/// torn last line cut, Choice 136) and checked to be this shard's. Returns the folder and the
/// runs recorded, a bit each (Choice 244).
fn resume_shard(c: &Campaign, part: Shard, out: &Path) -> Result<(OutputDir, Done)> {
    let (shard, shards) = (part.index, part.count);
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
    let mut done = Done::new(part);
    out::for_each_record(&out.join(out::RECORDS), true, |r| {
        if !part.owns(r.index) {
            bail!(
                "{} records run {}, which is not shard {shard}/{shards}'s",
                out.display(),
                r.index
            );
        }
        done.insert(r.index);
        Ok(())
    })?;
    Ok((dir, done))
}

/// Flies the `todo` runs of `part` not `done` in parallel into `log`, with a progress line on
/// stderr every 5 % (a batch job's log has no terminal for a bar); returns how many runs were
/// recorded.
fn fly_logged(c: &Campaign, part: Shard, done: &Done, todo: u64, log: &RecordLog) -> u64 {
    let new = AtomicU64::new(0);
    let t0 = Instant::now();
    let every = todo.div_ceil(20).max(1);
    c.run_shard(part, done, |r| {
        log.push(&r);
        let k = new.fetch_add(1, Ordering::Relaxed) + 1;
        if k.is_multiple_of(every) && k < todo {
            let s = t0.elapsed().as_secs_f64();
            eprintln!(
                "host-sim: shard {}/{}: {k} of {todo} runs, {} ({:.1} runs/s)",
                part.index,
                part.count,
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
    out_apart(&a.out, &a.shards)?;
    let mut shards = a
        .shards
        .iter()
        .map(|d| out::read_shard(d))
        .collect::<Result<Vec<_>>>()?;
    let cannot = |e: String| anyhow::anyhow!("cannot merge:\n{e}");
    merge::same_campaign(&shards).map_err(cannot)?;
    let c = kept_campaign(&shards[0])?;
    let records = merge::check(&c, &mut shards).map_err(cannot)?;
    let dir = OutputDir::prepare(&a.out)?;
    let merged = out::write_report(&dir, &c, &records)?;
    for e in &merged.incomplete {
        eprintln!("host-sim: error: {e}");
    }
    // No run flew (every draw invalid): the report says nothing of the controller (Choice 245).
    let none_flew = merged.invalid == merged.runs;
    if none_flew {
        eprintln!(
            "host-sim: error: no run flew: each of the {} draws made a scenario that does not \
             validate (each reason is on its shard's stderr); the report says nothing of the \
             controller",
            merged.runs
        );
    }
    let missed = merged
        .required
        .is_some_and(|f| (merged.within as f64) < f * merged.runs as f64);
    let exit = Exit::of(
        !merged.incomplete.is_empty(),
        false,
        none_flew,
        false,
        missed,
    );
    if a.json {
        let text = std::fs::read_to_string(a.out.join(out::SUMMARY))
            .with_context(|| format!("reading {}", a.out.join(out::SUMMARY).display()))?;
        writeln!(stdout, "{}", text.trim_end())?;
        return Ok(exit);
    }
    writeln!(
        stdout,
        "campaign {}: {} runs from {} shard(s); within bound {} ({:.4} %), diverged {}{}",
        c.spec.name(),
        merged.runs,
        shards.len(),
        merged.within,
        100.0 * merged.within as f64 / merged.runs.max(1) as f64,
        merged.diverged,
        match merged.invalid {
            0 => String::new(),
            k => format!(", invalid {k} (not flown)"),
        }
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

/// The campaign shard `s` keeps, rebuilt from its texts: it must hash to the manifest's
/// campaign hash. When it does not, the manifest of this program's version was edited (its
/// hash recomputed: Choice 241 catches the rest), or another version made it.
fn kept_campaign(s: &merge::ShardInput) -> Result<Campaign> {
    let m = &s.manifest;
    let c =
        Campaign::from_manifest(m).with_context(|| format!("the campaign kept in {}", s.label))?;
    if c.hash == m.campaign_hash {
        return Ok(c);
    }
    let ours = crate::studies::campaign::PROGRAM_VERSION;
    if m.program_version == ours {
        bail!(
            "the campaign kept in {}/{} does not give its campaign_hash: the manifest was \
             edited; run the shard again into a new folder",
            s.label,
            out::SHARD_MANIFEST
        );
    }
    bail!(
        "the shards were made by {} and this is {ours}: a different program flies the runs \
         differently; merge with the host-sim that made them",
        m.program_version
    )
}

/// The merge's `--out` must be apart from every shard folder (**Choice 243**): not one of them,
/// not inside one, not holding one (the merge clears its output folder first). Compared as the
/// file system resolves them (symlinks, `..`), the part of `--out` not yet made as written.
fn out_apart(out: &Path, shards: &[PathBuf]) -> Result<()> {
    let o = resolved(out)?;
    for s in shards {
        let d = resolved(s)?;
        let how = if o == d {
            "is"
        } else if d.starts_with(&o) {
            "holds"
        } else if o.starts_with(&d) {
            "is inside"
        } else {
            continue;
        };
        bail!(
            "--out {} {how} the shard folder {}: the merge would overwrite its records; give an \
             output folder apart from the shards",
            out.display(),
            s.display()
        );
    }
    Ok(())
}

/// `p` absolute, each existing prefix resolved as the file system does (symlinks, then `..`
/// from where they lead), the rest taken as written.
fn resolved(p: &Path) -> Result<PathBuf> {
    use std::path::Component;
    let abs = std::path::absolute(p).with_context(|| format!("cannot resolve {}", p.display()))?;
    let mut r = PathBuf::new();
    for part in abs.components() {
        match part {
            Component::ParentDir => {
                r.pop();
            }
            Component::CurDir => {}
            other => r.push(other),
        }
        if let Ok(real) = r.canonicalize() {
            r = real;
        }
    }
    Ok(r)
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
