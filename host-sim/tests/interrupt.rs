//! The interrupt's rules in process (`signals.rs` signals the binary): one request
//! delivered twice is one interrupt, a later second one quits, and what is being streamed is
//! kept under its partial name first. Its own test binary: [`interrupt::keep_streamed`]
//! renames every stream of the process.

use std::time::{Duration, Instant};

use host_sim::interrupt::{self, SignalAction, SAME_SIGNAL_WINDOW};
use host_sim::output::CsvStream;
use host_sim::scenario::parse_scenario;
use host_sim::sim;

#[test]
fn a_signal_within_the_window_is_the_same_and_a_later_one_quits() {
    let t0 = Instant::now();
    assert_eq!(interrupt::action(None, t0), SignalAction::Stop);
    assert_eq!(interrupt::action(Some(t0), t0), SignalAction::Same);
    let just_inside = SAME_SIGNAL_WINDOW - Duration::from_millis(1);
    assert_eq!(
        interrupt::action(Some(t0), t0 + just_inside),
        SignalAction::Same
    );
    assert_eq!(
        interrupt::action(Some(t0), t0 + SAME_SIGNAL_WINDOW),
        SignalAction::Quit
    );
}

/// A CSV stream that never finishes (a panic unwinding, or a second signal) keeps its rows
/// under `<name>.partial.csv`; it used to be removed with its temporary file.
#[test]
fn what_is_being_streamed_is_kept_as_partial() {
    let dir = std::env::temp_dir().join(format!("host-sim-int-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let s = parse_scenario(
        "name = \"c\"\nduration = 2\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    )
    .unwrap();
    let fly = |name: &str| {
        let mut csv = CsvStream::create(&dir.join(name)).unwrap();
        sim::fly(
            &s,
            &mut sim::LocalController::new(&s),
            &mut csv,
            sim::Recording::MetricsOnly,
        );
        csv
    };
    let rows = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .lines()
            .count()
    };
    // Dropped unfinished.
    drop(fly("dropped.csv"));
    assert_eq!(rows("dropped.partial.csv"), 1 + 201);
    assert!(!dir.join("dropped.csv").exists());
    // A second signal: the handler's rename, before it quits.
    let live = fly("live.csv");
    let kept = interrupt::keep_streamed();
    assert_eq!(kept, vec![dir.join("live.partial.csv")]);
    std::mem::forget(live);
    // The rows are on disk up to the writer's buffer; the header and most rows at least.
    assert!(rows("live.partial.csv") > 100);
    let tmp: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".host-sim-tmp"))
        .collect();
    assert!(tmp.is_empty(), "{tmp:?}");
}
