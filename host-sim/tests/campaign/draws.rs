//! What run i draws: (seed, i) only, inside the boxes the campaign gives (Choice 130).

use std::path::PathBuf;

use controller_core::model::ParamVariation;
use host_sim::studies::campaign::Campaign;

use crate::support::*;

#[test]
fn a_run_depends_on_seed_and_index_only_not_on_the_run_count() {
    let dir = tempdir("independent");
    let small = write_campaign(&dir, &campaign_text(6, 9));
    ok(run_shard(&small, "0/1", &dir.join("small")));
    let big_dir = dir.join("big-campaign");
    std::fs::create_dir_all(&big_dir).unwrap();
    let big = write_campaign(&big_dir, &campaign_text(13, 9));
    ok(run_shard(&big, "0/1", &dir.join("big")));
    let sorted = |p: PathBuf| {
        let mut r = records(&p);
        r.sort_by_key(|r| r.index);
        r
    };
    let a = sorted(dir.join("small/records.csv"));
    let b = sorted(dir.join("big/records.csv"));
    assert_eq!(a.len(), 6);
    assert_eq!(a[..], b[..6]);
    // Another seed draws something else.
    let other_dir = dir.join("other-seed");
    std::fs::create_dir_all(&other_dir).unwrap();
    let other = write_campaign(&other_dir, &campaign_text(6, 10));
    ok(run_shard(&other, "0/1", &dir.join("other")));
    let c = sorted(dir.join("other/records.csv"));
    assert!(a.iter().zip(&c).all(|(x, y)| x.draw != y.draw));
}

#[test]
fn drawn_values_lie_in_their_boxes() {
    let dir = tempdir("boxes");
    let file = write_campaign(&dir, &campaign_text(50, 3));
    let c = Campaign::load(&file).unwrap();
    let max = ParamVariation::TABLE3_MAX.to_array();
    let corners_file = write_campaign(
        &dir,
        &campaign_text(50, 3).replace("\"uniform\"", "\"corners\""),
    );
    let corners = Campaign::load(&corners_file).unwrap();
    for i in 0..50 {
        let d = c.draw(i);
        for (x, m) in d.variation.iter().zip(max) {
            assert!((0.0..=m).contains(x), "run {i}: {x} outside [0, {m}]");
        }
        let speed = d.current[0].hypot(d.current[1]);
        assert!(speed <= 0.2 + 1e-15 && d.current[2] == 0.0);
        assert!(d.initial_offset[3] == 0.0 && d.initial_offset[4] == 0.0);
        assert!(d.initial_offset[0].abs() <= 0.02);
        assert!((1.0..=1.5).contains(&d.time_scale));
        // The two mountings: fore vertical and both horizontals reversed, or without the aft.
        assert!([0b11010, 0b01010].contains(&d.mounting), "{}", d.mounting);
        for (x, m) in corners.draw(i).variation.iter().zip(max) {
            assert!(
                *x == 0.0 || *x == m,
                "run {i}: {x} not a corner of [0, {m}]"
            );
        }
    }
}

/// Choice 460: the drawn noise seed seeds the navigation model too. Two runs told the same true
/// states are told different navigation solutions (before, every run of a real-chain campaign
/// flew the default preset's one realisation, seed 1), and a run's written scenario carries its
/// navigation seed, so `run` on it flies the campaign's run bit for bit.
#[test]
fn each_run_draws_its_navigation_noise_and_replays_it_from_its_file() {
    // Study-grade, as the shipped campaign flies (Choice 400): the file keeps its step.
    draws_and_replays("navigation-seed", "plant_step = \"control-period\"\n");
}

/// Choice 536: a campaign of study-grade noise (`noise_draws = "at-samples"`) writes the key
/// into each run's file, so `run` (and `pil`, which flies the same navigation) replays it bit
/// for bit; without it the file flew the default draws, other noise.
#[test]
fn a_run_of_study_grade_noise_replays_it_from_its_file() {
    draws_and_replays(
        "at-samples",
        "plant_step = \"control-period\"\nnoise_draws = \"at-samples\"\n",
    );
}

fn draws_and_replays(name: &str, keys: &str) {
    use host_sim::plant::PlantState;
    use host_sim::scenario::parse_scenario;
    use host_sim::sim::navigation::Navigation;
    use nalgebra::Vector6;

    let dir = tempdir(name);
    let text = campaign_text(2, 3).replace("metrics =", &format!("{keys}metrics ="));
    let file = write_campaign(&dir, &text);
    let c = Campaign::load(&file).unwrap();
    let told = |i: u64| {
        let s = c.scenario(i, &c.draw(i)).unwrap();
        let mut cfg = s.config().clone();
        assert!(
            cfg.navigation.is_some(),
            "the real chain flies a navigation model"
        );
        // The navigation model's noise alone: `[noise]` off.
        cfg.noise = None;
        let mut nav = Navigation::of(&cfg);
        let state = PlantState {
            eta: Vector6::new(1.0, 2.0, 5.0, 0.0, 0.0, 0.3),
            nu: Vector6::new(0.5, 0.0, 0.0, 0.0, 0.0, 0.05),
        };
        (0..200).map(|_| nav.measure(&state)).collect::<Vec<_>>()
    };
    let (a, b) = (told(0), told(1));
    assert_ne!(c.draw(0).noise_seed, c.draw(1).noise_seed);
    assert!(
        a.iter().zip(&b).any(|(x, y)| x != y),
        "two runs were told the same navigation solutions"
    );
    // The run's file: the same navigation model, and the same flight.
    for i in 0..2 {
        let d = c.draw(i);
        let flown = c.scenario(i, &d).unwrap();
        let text = c.scenario_text(i, &d).unwrap();
        let replay = parse_scenario(&text).unwrap();
        assert_eq!(
            replay.config().navigation,
            flown.config().navigation,
            "run {i}"
        );
        assert_eq!(
            replay.config().noise_draws,
            flown.config().noise_draws,
            "run {i}"
        );
        let record = c.fly(i).unwrap();
        let again = host_sim::sim::fly(
            &replay,
            &mut host_sim::sim::LocalController::new(&replay),
            &mut (),
            host_sim::sim::Recording::MetricsOnly,
        );
        let bits = |m: &[f64]| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&record.metrics),
            bits(&again.metrics.values()),
            "run {i}"
        );
    }
}
