//! The preflight's contract (docs/real-vehicle.md#the-preflights-contract): a mission `check` calls feasible at the time
//! scale it proposes flies within the real vehicle's bound, under every thruster mounting of
//! the AUV-150 layout and for random missions — and the verdict it replaced did not hold.

use controller_core::effectiveness::ThrusterGeometry;
use host_sim::scenario::navigation::Preset;
use host_sim::scenario::real_vehicle;
use host_sim::sim::{self, bound};
use host_sim::studies::preflight::{self, Verdict, DEFAULT_MARGIN};
use host_sim::studies::validation::{self, Campaign, Measure};

/// Every mounting (all 32 masks) on the six real paths, and 200 random missions, on the exact
/// state: no mission the preflight called feasible misses the bound when flown at its
/// proposed scale. The same campaign on `survey` is the main job's (`validate-preflight`); it
/// does not hold there yet (docs/real-vehicle.md#the-preflights-contract).
#[test]
fn no_mission_called_feasible_misses_the_bound_when_flown() {
    let campaign = Campaign {
        navigation: vec![Preset::Ideal],
        ..Campaign::default()
    };
    let missions = campaign.missions().unwrap();
    assert_eq!(missions.len(), 32 * 6 + 200);
    let v = validation::validate(&missions, DEFAULT_MARGIN, Measure::Verdicts, || {}).unwrap();
    let broken: Vec<_> = v.missions.iter().filter(|m| m.false_feasible()).collect();
    assert!(broken.is_empty(), "false feasible: {broken:#?}");
    assert_eq!(v.per_preset.len(), 1, "{}", v.headline());
    // The campaign is not empty of decisions: scales above 1 were proposed, and flown.
    assert!(v.flown > 300, "{}", v.headline());
    assert!(
        v.missions.iter().filter(|m| m.proposed > Some(1.0)).count() > 50,
        "{}",
        v.headline()
    );
}

/// The real 20 m circle with the vertical pair both pushing up (the core's
/// default before). The old preflight called it feasible at time scale 1 and it flew 6.4 m
/// off; now `check` refuses time scale 1, proposes one, and the mission flies within the
/// bound there.
#[test]
fn the_both_up_circle_is_refused_at_its_speed_and_flies_at_the_proposed_scale() {
    let both_up = real_vehicle::real_scenarios().unwrap()[1]
        .with(|c| {
            c.controller.geometry = ThrusterGeometry::auv150(0b11110);
            // At the paper's pace (the file ships at the scale its own check proposes on its
            // navigation, Choice 544).
            c.time_scale = 1.0;
            c.duration = 70.0;
            // On the exact state, as when it was found (on `survey` the navigation's share
            // leaves this mounting no margin even at rest: statically infeasible).
            c.navigation = None;
            c.controller.estimator = controller_core::EstimatorConfig::default();
        })
        .unwrap();
    assert_eq!(both_up.config().time_scale, 1.0);
    let p = preflight::check(&both_up, DEFAULT_MARGIN).unwrap();
    assert_eq!(p.verdict, Verdict::NeedsTimeScale, "{p}");
    let fast = sim::run(&both_up);
    assert!(!bound::within_bound(&fast), "{:?}", fast.metrics);
    assert!(fast.missed(), "{}", fast.outcome);
    let k = p.smallest_time_scale.unwrap();
    let slow = both_up
        .with(|c| {
            c.time_scale = k as f32;
            c.duration *= k;
        })
        .unwrap();
    let run = sim::run(&slow);
    assert!(bound::within_bound(&run), "k = {k}: {:?}", run.metrics);
    assert!(!run.missed(), "{}", run.outcome);
}
