//! Ctrl-C (SIGINT) and SIGTERM: finish what is running, keep what is done.
//!
//! The binary [`install`]s the handler. The first signal only sets a flag that the runs read
//! once per control period ([`requested`]): each run stops at the period it is in
//! ([`Outcome::Interrupted`](crate::sim::Outcome::Interrupted)), its CSV is flushed and put
//! in place, runs not started are not started, and the command writes its plots and report,
//! saying they are partial, and exits 130 ([`crate::cli::Exit::Interrupted`]). A second signal
//! exits at once (130), leaving only the files already completed (never a half-written file
//! under a final name: they are written to a temporary name and renamed).

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Installs the SIGINT/SIGTERM handler (once per process).
pub fn install() -> Result<(), ctrlc::Error> {
    ctrlc::set_handler(|| {
        if REQUESTED.swap(true, Ordering::SeqCst) {
            eprintln!("host-sim: interrupted again: exiting now");
            std::process::exit(130);
        }
        eprintln!(
            "host-sim: interrupted: finishing the current period of each run and writing what \
             is done (interrupt again to quit at once)"
        );
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
