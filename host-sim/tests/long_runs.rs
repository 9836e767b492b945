//! Long runs in bounded memory: the plots keep a decimated series that still holds
//! every bucket's extremes, the CSV streams every period, and a mission long enough for the
//! heading to pass the controller's angle limit still flies.

use controller_core::effectiveness::THRUSTERS;
use host_sim::output::CsvStream;
use host_sim::scenario::parse_scenario;
use host_sim::sim;
use host_sim::sim::decimate::{Decimator, PLOTTED, PLOT_BUCKETS, PLOT_SAMPLES};
use host_sim::sim::record::{ControlStatus, Outcome, Sample};

fn sample(k: u64) -> Sample {
    // Signals that are not monotone, with a few isolated spikes and one NaN.
    let t = k as f64 * 0.01;
    let w = |f: f64, p: f64| (f * t + p).sin() * (1.0 + 0.001 * (k % 97) as f64);
    let mut s = Sample {
        t,
        eta: [w(0.3, 0.0), w(0.2, 1.0), 5.0, 0.0, 0.0, w(0.05, 2.0)],
        eta_d: [w(0.3, 0.1), w(0.2, 1.1), 5.0, 0.0, 0.0, w(0.05, 2.1)],
        error: [
            w(1.7, 0.0),
            w(2.3, 0.5),
            w(3.1, 1.0),
            w(0.7, 0.0),
            w(1.3, 0.0),
            w(0.9, 0.0),
        ],
        tau: [0.0; 6],
        tau_applied: [0.0; 6],
        thrust: [0.0; THRUSTERS],
        voltage: [
            w(5.0, 0.0),
            w(6.0, 0.0),
            w(7.0, 0.0),
            w(8.0, 0.0),
            w(9.0, 0.0),
        ],
        saturated: 0,
        delta: w(0.11, 0.0).abs(),
        delta_clamped: k.is_multiple_of(1013),
        w_norm: 0.0,
        payload: 30.0 * w(0.1, 0.0).abs(),
        status: ControlStatus::Law(controller_core::Status::Ok),
        signals: Default::default(),
    };
    if k % 40_009 == 17 {
        s.error[2] = 1e3; // a spike one period long
    }
    if k == 123_457 {
        s.voltage[3] = f64::NAN;
    }
    s
}

#[test]
fn decimation_is_bounded_and_keeps_every_buckets_extremes() {
    let n: u64 = 200_000;
    let mut d = Decimator::new(n);
    for k in 0..n {
        d.push(&sample(k));
    }
    let kept = d.finish();
    // Bounded: a fixed number of samples per bucket, whatever n is.
    let per_bucket = 3 + 2 * PLOTTED.len() as u64 + 1;
    assert!(
        kept.len() as u64 <= PLOT_BUCKETS * per_bucket + per_bucket,
        "{}",
        kept.len()
    );
    assert!((kept.len() as u64) < n / 4);
    // In time order, first and last period kept.
    assert!(kept.windows(2).all(|w| w[0].t < w[1].t));
    assert_eq!(kept[0].t, sample(0).t);
    assert_eq!(kept.last().unwrap().t, sample(n - 1).t);
    // Brute force over each bucket: every signal's min and max are among the kept samples.
    let bucket = n.div_ceil(PLOT_BUCKETS);
    for b in 0..n.div_ceil(bucket) {
        let range = b * bucket..((b + 1) * bucket).min(n);
        let all_samples: Vec<Sample> = range.clone().map(sample).collect();
        let (t0, t1) = (all_samples[0].t, all_samples.last().unwrap().t);
        let inside: Vec<&Sample> = kept.iter().filter(|s| s.t >= t0 && s.t <= t1).collect();
        for (i, signal) in PLOTTED.iter().enumerate() {
            let all: Vec<f64> = all_samples
                .iter()
                .map(signal)
                .filter(|v| v.is_finite())
                .collect();
            let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert!(
                inside.iter().any(|s| signal(s) == lo),
                "bucket {b} signal {i} min"
            );
            assert!(
                inside.iter().any(|s| signal(s) == hi),
                "bucket {b} signal {i} max"
            );
        }
    }
    // The one-period spike and the NaN are kept.
    assert!(kept.iter().any(|s| s.error[2] == 1e3));
    assert!(kept.iter().any(|s| s.voltage[3].is_nan()));
}

#[test]
fn a_short_run_keeps_every_sample() {
    let mut d = Decimator::new(PLOT_SAMPLES);
    for k in 0..PLOT_SAMPLES {
        d.push(&sample(k));
    }
    assert_eq!(d.finish().len() as u64, PLOT_SAMPLES);
}

/// A circle at 1 rad/s: the heading passes the controller's 1000 rad input limit at 1000 s.
fn fast_circle(duration: u32) -> String {
    format!(
        "name = \"fast-circle\"\nduration = {duration}\nplant_step = 0.01\n\
         [trajectory]\nkind = \"circle\"\nradius = 1\nomega = 1\n"
    )
}

#[test]
fn a_long_run_streams_every_period_and_keeps_a_bounded_plot_series() {
    let s = parse_scenario(&fast_circle(1_100)).unwrap();
    let dir = std::env::temp_dir().join(format!("host-sim-long-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("fast-circle-with.csv");
    let mut csv = CsvStream::create(&path).unwrap();
    let r = sim::fly(
        &s,
        &mut sim::LocalController::new(&s),
        &mut csv,
        sim::Recording::Plot,
    );
    csv.finish().unwrap();
    let periods = s.steps() + 1;
    assert!(periods > PLOT_SAMPLES);
    let rows = std::fs::read_to_string(&path).unwrap().lines().count() as u64;
    assert_eq!(rows, periods + 1, "header + one row per period");
    assert!(
        (r.samples.len() as u64) < periods / 2,
        "{}",
        r.samples.len()
    );

    // And the heading, past 1000 rad at t = 1000 s, never put the controller in fail-safe.
    assert_eq!(r.outcome, Outcome::Completed, "{}", r.outcome);
    assert!(r.faults.is_empty(), "{}", r.faults);
    assert!(r.samples.last().unwrap().eta[5] > 1_000.0);
    assert!(r.metrics.max_path < 0.05, "{}", r.metrics.max_path);
}
