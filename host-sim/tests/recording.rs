//! What a simulation keeps, and what it recomputes: the plant's M(p) factorised once per
//! parameter set the run meets, and the metrics-only recording of Monte Carlo, whose summary
//! is that of the full recording.

use controller_core::Table1Case;
use host_sim::plant::VariationProfile;
use host_sim::sim::record::Sample;
use host_sim::sim::{self, LocalController, Observer, Recording};

/// The paper's lawn-mower holds three parameter sets (its Table-3 staircase) and the figure
/// eight one: a run factorises M once per set, not once per plant step (70 000).
#[test]
fn a_run_factorises_m_once_per_parameter_set() {
    for case in [Table1Case::LawnMower30x15, Table1Case::FigureEight30x30] {
        let scenario = host_sim::scenario::paper::scenario(case, true).unwrap();
        let sets = match &scenario.config().variation {
            VariationProfile::Staircase(steps) => {
                let mut values: Vec<_> = steps.iter().map(|s| s.1).collect();
                values.dedup();
                values.len() as u64
            }
            VariationProfile::Constant(_) => 1,
            other => panic!("unexpected profile {other:?}"),
        };
        let run = sim::run(&scenario);
        assert!(!run.diverged(), "{}", run.outcome);
        assert_eq!(run.plant_factorisations, sets, "{}", case.name());
    }
}

#[derive(Default)]
struct Count(u64);

impl Observer for Count {
    fn sample(&mut self, _: &Sample) {
        self.0 += 1;
    }
}

/// Monte Carlo's recording keeps no samples, and its summary (metrics, faults, outcome) is
/// exactly that of the run that keeps the plot series; the observer (progress) sees every
/// period either way.
#[test]
fn metrics_only_recording_keeps_no_samples_and_the_same_summary() {
    // A draw as Monte Carlo makes it (constant Δp), and a run that faults and diverges.
    let circle = host_sim::scenario::paper::scenario(Table1Case::Circular10R, true).unwrap();
    let circle = circle
        .with(|c| {
            c.variation = VariationProfile::Constant(
                controller_core::model::ParamVariation::TABLE3_MAX.scaled(0.7),
            )
        })
        .unwrap();
    let real = host_sim::scenario::paper::scenario(Table1Case::FigureEight30x30, false)
        .unwrap()
        .with(|c| {
            c.ideal_actuators = false;
            c.divergence_limit = 2.0;
        })
        .unwrap();
    for scenario in [circle.clone(), real.clone()] {
        let (mut seen_full, mut seen_lean) = (Count::default(), Count::default());
        let full = sim::fly(
            &scenario,
            &mut LocalController::new(&scenario),
            &mut seen_full,
            Recording::Plot,
        );
        let lean = sim::fly(
            &scenario,
            &mut LocalController::new(&scenario),
            &mut seen_lean,
            Recording::MetricsOnly,
        );
        assert_eq!(lean.summary(), full.summary());
        assert_eq!(lean.outcome, full.outcome);
        assert_eq!(full.samples.len() as u64, seen_full.0);
        assert!(
            lean.samples.is_empty(),
            "{} samples kept",
            lean.samples.len()
        );
        assert_eq!(seen_lean.0, seen_full.0);
    }
    unwatched_runs_fly_as_watched_ones(&[circle, real]);
}

/// Choice 569: a metrics-only run that no observer watches takes the law's η_d for the loop's
/// reference and stops after the control it would have preceded; its outcome, metrics, fault
/// counts and plant factorisations are those of the run that keeps everything, bit for bit,
/// whether it completes or diverges.
fn unwatched_runs_fly_as_watched_ones(scenarios: &[host_sim::scenario::Scenario]) {
    for scenario in scenarios {
        let full = sim::fly(
            scenario,
            &mut LocalController::new(scenario),
            &mut Count::default(),
            Recording::Plot,
        );
        let lean = sim::fly(
            scenario,
            &mut LocalController::new(scenario),
            &mut (),
            Recording::MetricsOnly,
        );
        assert_eq!(lean.outcome, full.outcome, "{}", scenario.config().name);
        assert_eq!(
            format!("{:?}", lean.metrics),
            format!("{:?}", full.metrics),
            "{}",
            scenario.config().name
        );
        assert_eq!(lean.faults, full.faults);
        assert_eq!(lean.plant_factorisations, full.plant_factorisations);
    }
}

/// The shipped real-circle campaign's runs (study-grade step and draws, the survey navigation,
/// the estimator, a drawn current and payload) fly unwatched as they fly watched (Choice 569).
#[test]
fn the_shipped_campaigns_runs_fly_unwatched_as_watched() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("campaigns/real-circle.campaign.toml");
    let campaign = host_sim::studies::campaign::Campaign::load(&file).unwrap();
    let runs: Vec<_> = (0..3)
        .map(|i| {
            let scenario = campaign.scenario(i, &campaign.draw(i)).unwrap();
            scenario.with(|c| c.duration = 20.0).unwrap()
        })
        .collect();
    unwatched_runs_fly_as_watched_ones(&runs);
}
