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
