//! Any sharding merges to the one-machine run's bytes (docs/campaigns.md#runs-and-shards, Choice 130).

use crate::support::*;

#[test]
fn one_three_and_seven_shards_merge_to_the_same_bytes() {
    let dir = tempdir("shards");
    let file = write_campaign(&dir, &campaign_text(21, 5));
    let one = report_files(&sharded(&dir, &file, 1));
    let names: Vec<&str> = one.iter().map(|f| f.0.as_str()).collect();
    for expected in [
        "records.csv",
        "report.md",
        "histograms.png",
        "scatter.png",
        "worst-max_path.toml",
        "worst-rms_path.toml",
        "worst-saturated_fraction.toml",
        "summary.json",
    ] {
        assert!(names.contains(&expected), "{expected} missing: {names:?}");
    }
    for n in [3, 7] {
        let other = report_files(&sharded(&dir, &file, n));
        assert_eq!(
            other.iter().map(|f| &f.0).collect::<Vec<_>>(),
            one.iter().map(|f| &f.0).collect::<Vec<_>>()
        );
        for (a, b) in one.iter().zip(&other) {
            assert!(a.1 == b.1, "{} differs between 1 and {n} shards", a.0);
        }
    }
    // The merged records are every index once, in order.
    let r = records(&dir.join("merged-1/records.csv"));
    assert_eq!(
        r.iter().map(|r| r.index).collect::<Vec<_>>(),
        (0..21).collect::<Vec<_>>()
    );
}
