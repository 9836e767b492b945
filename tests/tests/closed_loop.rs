//! Closed loop across crates: the f32 controller-core around the f64 host-sim plant, on the
//! paper's missions (docs/missions.md#closed-form-paths, docs/simulator.md#table-1).

use controller_core::trajectory::Helix;
use controller_core::{Table1Case, TrajectoryKind};
use host_sim::plant::CurrentModel;
use host_sim::scenario::paper;
use host_sim::scenario::Scenario;
use host_sim::scenario::SimConfig;
use host_sim::sim;
use host_sim::sim::record::Outcome;

fn run(config: SimConfig) -> host_sim::sim::record::RunResult {
    sim::run(&Scenario::new(config).expect("valid scenario"))
}

/// Each Table-1 mission with Δu at the paper's defaults stays under 0.05 m max path error, and
/// without Δu it is worse.
#[test]
fn table1_missions_track_within_5_cm_with_delta_u_and_worse_without() {
    for case in Table1Case::ALL {
        let with = run(paper::config(case, true));
        let without = run(paper::config(case, false));
        assert_eq!(with.outcome, Outcome::Completed, "{}", case.name());
        assert!(
            with.metrics.max_path < 0.05,
            "{}: max path error with Δu {:.4} m",
            case.name(),
            with.metrics.max_path
        );
        assert!(
            without.metrics.max_path > with.metrics.max_path,
            "{}: without Δu {:.4} m is not worse than with {:.4} m",
            case.name(),
            without.metrics.max_path,
            with.metrics.max_path
        );
    }
}

/// A constant 0.2 m/s current (not in the model, not in γ) is still rejected by the robust
/// term: the error converges.
#[test]
fn a_mission_in_a_current_still_converges() {
    let mut cfg = paper::config(Table1Case::Circular10R, true);
    cfg.current = CurrentModel::Constant([0.2, 0.0, 0.0]);
    let r = run(cfg);
    assert_eq!(r.outcome, Outcome::Completed);
    let late = r.samples.iter().filter(|s| s.t > 40.0);
    let worst_late = late
        .map(|s| (s.error[0].powi(2) + s.error[1].powi(2) + s.error[2].powi(2)).sqrt())
        .fold(0.0, f64::max);
    assert!(
        worst_late < 0.1,
        "position error after 40 s: {worst_late:.4} m"
    );
}

/// The helix descends at a constant rate; depth is tracked.
#[test]
fn helix_mission_tracks_depth() {
    let mut cfg = SimConfig::new(
        "helix",
        TrajectoryKind::Helix(Helix {
            radius: 10.0,
            omega: 0.1,
            depth: 5.0,
            depth_rate: 0.2,
        }),
    );
    cfg.duration = 60.0;
    let r = run(cfg);
    assert_eq!(r.outcome, Outcome::Completed);
    let last = r.samples.last().unwrap();
    // z_d(60) = 5 + 0.2·60 = 17 m, and the vehicle is there.
    assert!((last.eta_d[2] - 17.0).abs() < 1e-3);
    assert!(
        r.metrics.max_z < 0.02,
        "max depth error {}",
        r.metrics.max_z
    );
}

/// Starting 1 m off the path, δ is clamped at first (docs/law.md#the-δ-clamp) and the error converges.
#[test]
fn off_path_start_clamps_delta_then_converges() {
    let mut cfg = paper::config(Table1Case::FigureEight30x30, true);
    cfg.initial_offset = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    cfg.duration = 20.0;
    let r = run(cfg);
    assert!(r.samples[0].delta_clamped || r.samples[0].delta > 10.0);
    let end = r.samples.last().unwrap();
    assert!(
        end.error[0].abs() < 0.05,
        "x error at 20 s: {}",
        end.error[0]
    );
}
