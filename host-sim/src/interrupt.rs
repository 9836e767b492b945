//! Ctrl-C (SIGINT) and SIGTERM: finish what is running, keep what is done.
//!
//! The binary [`install`]s the handler. The first signal only sets a flag that every long
//! phase reads ([`requested`]): the runs once per control period
//! ([`Outcome::Interrupted`](crate::sim::Outcome::Interrupted)), the preflight check once per
//! sample of the path, the board's set-up while it waits. Each run stops at the period it is
//! in, its CSV is flushed and put in place, runs not started are not started, and the command
//! writes its plots and report, saying they are partial, and exits 130
//! ([`crate::cli::Exit::Interrupted`]).
//!
//! **Choice 125**: two deliveries of a signal within [`SAME_SIGNAL_WINDOW`] of the first are
//! one interrupt (GNU `timeout` and batch schedulers signal the process and then its group, so
//! one request arrives twice). A second signal later quits at once (130), and before it quits
//! it renames every file still being streamed ([`keep_on_exit`]) to its partial name, so what
//! was streamed is kept, visibly marked; nothing else is left under a temporary name that
//! would hide it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// When the first signal came (`None`: none yet; [`request`] is not a signal).
static FIRST_SIGNAL: Mutex<Option<Instant>> = Mutex::new(None);

/// A signal this soon after the first is the same request delivered twice (Choice 125).
pub const SAME_SIGNAL_WINDOW: Duration = Duration::from_secs(1);

/// What a signal does, given when the first one came.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SignalAction {
    /// The first: ask every phase to stop.
    Stop,
    /// The first delivered again (within [`SAME_SIGNAL_WINDOW`]): nothing more.
    Same,
    /// A deliberate second signal: keep what was streamed and quit at once.
    Quit,
}

/// What a signal arriving at `now` does when the first came at `first`.
pub fn action(first: Option<Instant>, now: Instant) -> SignalAction {
    match first {
        None => SignalAction::Stop,
        Some(t) if now.saturating_duration_since(t) < SAME_SIGNAL_WINDOW => SignalAction::Same,
        Some(_) => SignalAction::Quit,
    }
}

/// Installs the SIGINT/SIGTERM handler (once per process).
pub fn install() -> Result<(), ctrlc::Error> {
    ctrlc::set_handler(|| {
        let now = Instant::now();
        let act = {
            let mut first = FIRST_SIGNAL.lock().unwrap_or_else(|e| e.into_inner());
            let act = action(*first, now);
            first.get_or_insert(now);
            act
        };
        match act {
            SignalAction::Stop => {
                REQUESTED.store(true, Ordering::SeqCst);
                eprintln!(
                    "host-sim: interrupted: finishing the current period of each run and \
                     writing what is done (interrupt again to quit at once)"
                );
            }
            SignalAction::Same => {}
            SignalAction::Quit => {
                let kept = keep_streamed();
                eprintln!("host-sim: interrupted again: exiting now");
                for p in kept {
                    eprintln!("host-sim: kept what was streamed as {}", p.display());
                }
                std::process::exit(130);
            }
        }
    })
}

/// Asks every run to stop, as the first signal does.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether a stop was requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// The files being streamed: (id, temporary name, partial name).
static STREAMING: Mutex<Vec<(u64, PathBuf, PathBuf)>> = Mutex::new(Vec::new());
static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// A file registered with [`keep_on_exit`]; dropping it unregisters the file.
#[derive(Debug)]
pub struct Streaming(u64);

/// Registers a file being written at `tmp`: if the process quits at once (a second signal),
/// it is first renamed to `partial`. Drop the guard once the file is in place (or removed).
pub fn keep_on_exit(tmp: &Path, partial: &Path) -> Streaming {
    let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
    STREAMING.lock().unwrap_or_else(|e| e.into_inner()).push((
        id,
        tmp.to_path_buf(),
        partial.to_path_buf(),
    ));
    Streaming(id)
}

impl Drop for Streaming {
    fn drop(&mut self) {
        STREAMING
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .retain(|(id, ..)| *id != self.0);
    }
}

/// Renames every file still being streamed to its partial name (what a second signal does
/// before it quits); returns the names it made.
pub fn keep_streamed() -> Vec<PathBuf> {
    let files = std::mem::take(&mut *STREAMING.lock().unwrap_or_else(|e| e.into_inner()));
    files
        .into_iter()
        .filter(|(_, tmp, partial)| std::fs::rename(tmp, partial).is_ok())
        .map(|(_, _, partial)| partial)
        .collect()
}
