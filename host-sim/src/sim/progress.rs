//! Progress of long commands, counted in control periods (so that one long run shows progress
//! inside it, and parallel runs add up), or in the whole things a study does ([`Unit`]:
//! missions checked and flown, evaluations of a search).
//!
//! The runs add to a shared counter ([`Progress::observer`], one atomic add a period); a
//! thread shows it: on a terminal an `indicatif` bar on stderr (hidden with `--json`), and
//! without a terminal (CI, a log file) a line on stderr every [`LINE_INTERVAL`]:
//! `host-sim: Table 1: 43.2 % (36292 of 84012 control periods), 2 s elapsed, about 3 s left`.
//! A command shorter than the interval prints no line. The remaining time is the elapsed time
//! scaled by the periods left, so it assumes the rest goes as fast.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

use super::observer::Observer;
use super::record::Sample;

/// Time between two progress lines when stderr is not a terminal.
pub const LINE_INTERVAL: Duration = Duration::from_secs(5);

/// What a [`Progress`] counts, named in its bar and lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Control periods flown (runs count them through [`Progress::observer`]).
    Periods,
    /// Missions checked and flown ([`Counter::add`]).
    Missions,
    /// Evaluations of a search or a study ([`Counter::add`]).
    Evaluations,
}

impl Unit {
    /// The unit's name in a progress line, plural.
    pub const fn name(self) -> &'static str {
        match self {
            Unit::Periods => "control periods",
            Unit::Missions => "missions",
            Unit::Evaluations => "evaluations",
        }
    }
}

/// A running progress display; [`Progress::finish`] ends it.
pub struct Progress {
    done: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

/// Counts the periods of one run into its [`Progress`].
#[derive(Clone)]
pub struct Counter(Arc<AtomicU64>);

impl Counter {
    /// Counts `n` more (for work counted in other units than periods, e.g. missions).
    pub fn add(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
}

impl Observer for Counter {
    fn sample(&mut self, _: &Sample) {
        self.0.fetch_add(1, Ordering::Relaxed);
    }
}

impl Progress {
    /// Starts showing the progress of `what`, `total` control periods in all. `bar`: whether a
    /// terminal may get a bar (false for `--json`).
    pub fn start(what: &str, total: u64, bar: bool) -> Self {
        Self::counting(what, total, Unit::Periods, bar)
    }

    /// [`Progress::start`] for `total` of `unit`.
    pub fn counting(what: &str, total: u64, unit: Unit, bar: bool) -> Self {
        let done = Arc::new(AtomicU64::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let terminal = std::io::stderr().is_terminal();
        let (d, s, what) = (done.clone(), stop.clone(), what.to_string());
        let thread = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                if terminal {
                    if bar {
                        show_bar(&what, total, unit, &d, &s);
                    }
                } else {
                    show_lines(&what, total, unit, &d, &s);
                }
            })
            .ok();
        Progress { done, stop, thread }
    }

    /// The observer a run adds its periods with.
    pub fn observer(&self) -> Counter {
        Counter(self.done.clone())
    }

    /// Ends the display (clears the bar).
    pub fn finish(mut self) {
        self.end();
    }

    fn end(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.end();
    }
}

const POLL: Duration = Duration::from_millis(100);

fn show_bar(what: &str, total: u64, unit: Unit, done: &AtomicU64, stop: &AtomicBool) {
    let pb = ProgressBar::new(total);
    pb.set_style(
        ProgressStyle::with_template(&format!(
            "{{msg}} [{{bar:40}}] {{percent}}% of {{len}} {}, {{elapsed}} (eta {{eta}})",
            unit.name()
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    while !stop.load(Ordering::SeqCst) {
        pb.set_position(done.load(Ordering::Relaxed));
        std::thread::sleep(POLL);
    }
    pb.finish_and_clear();
}

fn show_lines(what: &str, total: u64, unit: Unit, done: &AtomicU64, stop: &AtomicBool) {
    let t0 = Instant::now();
    let mut next = LINE_INTERVAL;
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(POLL);
        let elapsed = t0.elapsed();
        if elapsed < next {
            continue;
        }
        next += LINE_INTERVAL;
        eprintln!(
            "{}",
            line(what, done.load(Ordering::Relaxed), total, unit, elapsed)
        );
    }
}

/// One progress line (see the module doc).
pub fn line(what: &str, done: u64, total: u64, unit: Unit, elapsed: Duration) -> String {
    let fraction = if total == 0 {
        1.0
    } else {
        done.min(total) as f64 / total as f64
    };
    let secs = elapsed.as_secs_f64();
    let left = if done == 0 {
        "time left unknown".to_string()
    } else {
        format!(
            "about {} left",
            duration_text(secs * (1.0 - fraction) / fraction)
        )
    };
    format!(
        "host-sim: {what}: {:.1} % ({done} of {total} {}), {} elapsed, {left}",
        100.0 * fraction,
        unit.name(),
        duration_text(secs)
    )
}

/// "12 s", "3 min 20 s", "2 h 05 min".
pub fn duration_text(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line names what it counts, and half done in 10 s leaves about 10 s.
    #[test]
    fn a_line_names_its_unit_and_scales_the_time_left() {
        let l = line("tune", 5, 10, Unit::Evaluations, Duration::from_secs(10));
        assert_eq!(
            l,
            "host-sim: tune: 50.0 % (5 of 10 evaluations), 10 s elapsed, about 10 s left"
        );
        let l = line("Table 1", 0, 7, Unit::Periods, Duration::ZERO);
        assert!(l.contains("(0 of 7 control periods)"), "{l}");
        assert!(l.ends_with("time left unknown"), "{l}");
    }
}
