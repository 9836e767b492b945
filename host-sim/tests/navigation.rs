//! The navigation model (`[navigation]`, docs/navigation.md) against independent facts: the
//! white noise's σ (a χ² bound), the DVL's ping rate and latency seen in the solution's stamps,
//! dead reckoning under a known velocity bias (drift = bias·t), a fix (the position within the
//! fix's noise), bottom-lock loss (the velocity drifts with the INS bias, b·t), the `ideal`
//! preset (the exact state, the run bit for bit), and determinism from the seed.

mod common;

use host_sim::scenario::navigation::{ErrorModel, NavigationModel, Preset, Source, Timing};
use host_sim::scenario::{parse_scenario, ScenarioFile};
use host_sim::sim::nav_model::NavComputer;

use common::{circle_with, invalid_key, scenarios_dir};

const RATE: f64 = 100.0;

/// The survey preset with every error and latency 0 and every source at the control rate:
/// tests switch on only what they measure.
fn exact() -> NavigationModel {
    let mut m = NavigationModel::preset(Preset::Survey, 7).unwrap();
    for t in [&mut m.ins.timing, &mut m.dvl.timing, &mut m.depth.timing] {
        *t = Timing {
            rate_hz: RATE,
            latency: 0.0,
            outages: Vec::new(),
        };
    }
    m.ins.attitude = ErrorModel::EXACT;
    m.ins.rates = ErrorModel::EXACT;
    m.ins.accel = ErrorModel::EXACT;
    m.dvl.velocity = ErrorModel::EXACT;
    m.depth.error = ErrorModel::EXACT;
    m.fix = None;
    m
}

/// The truth of a vehicle at `u` m/s on heading ψ, depth `z`, at tick k.
fn straight(k: u64, u: f64, psi: f64, z: f64) -> ([f64; 6], [f64; 6]) {
    let t = k as f64 / RATE;
    (
        [u * t * psi.cos(), u * t * psi.sin(), z, 0.0, 0.0, psi],
        [u, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
}

/// Sample variance of white noise of σ over n samples, (n−1)s²/σ² ~ χ²(n−1): within five of
/// its standard deviations √(2(n−1)) of n−1.
fn assert_chi2(sum_sq: f64, n: usize, sigma: f64, what: &str) {
    let dof = (n - 1) as f64;
    let stat = sum_sq / (sigma * sigma);
    assert!(
        (stat - dof).abs() < 5.0 * (2.0 * dof).sqrt(),
        "{what}: χ² {stat:.0} for {dof} degrees of freedom"
    );
}

#[test]
fn white_attitude_and_rate_noise_have_the_configured_sigma() {
    let mut m = exact();
    let sigma = [0.001, 0.002, 0.004];
    m.ins.attitude.sigma = sigma;
    m.ins.rates.sigma = [3e-4; 3];
    let mut nav = NavComputer::new(&m, RATE);
    let n = 20_000;
    let mut att: [Vec<f64>; 3] = Default::default();
    let mut rates: [Vec<f64>; 3] = Default::default();
    for k in 0..n as u64 {
        let (eta, nu) = straight(k, 0.0, 0.3, 5.0);
        let s = nav.step(&eta, &nu);
        for i in 0..3 {
            att[i].push(s.eta[3 + i] - eta[3 + i]);
            rates[i].push(s.nu[3 + i] - nu[3 + i]);
        }
    }
    let centred = |xs: &[f64]| {
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>()
    };
    for i in 0..3 {
        assert_chi2(centred(&att[i]), n, sigma[i], &format!("attitude {i}"));
        assert_chi2(centred(&rates[i]), n, 3e-4, &format!("rate {i}"));
    }
}

#[test]
fn the_dvl_ping_rate_and_latency_are_seen_in_the_solution() {
    let mut m = exact();
    m.dvl.timing = Timing {
        rate_hz: 8.0,
        latency: 0.03,
        outages: Vec::new(),
    };
    m.dvl.velocity.sigma = [0.005; 3];
    let mut nav = NavComputer::new(&m, RATE);
    let seconds = 20.0;
    let (mut pings, mut last_u, mut last_at) = (0, None, None);
    for k in 0..(seconds * RATE) as u64 {
        let (eta, nu) = straight(k, 0.5, 0.0, 5.0);
        let s = nav.step(&eta, &nu);
        if k > 0 && s.velocity_at != last_at {
            pings += 1;
            // A ping enters the solution 30 ms = 3 periods after it was taken.
            assert_eq!(k - s.velocity_at.unwrap(), 3, "tick {k}");
        }
        // The velocity changes only when a ping arrives (constant truth, no INS error).
        if let Some(u) = last_u {
            assert_eq!(s.nu[0] != u, s.velocity_at != last_at, "tick {k}");
        }
        last_u = Some(s.nu[0]);
        last_at = s.velocity_at;
    }
    // 8 pings a second for 20 s (the one at t = 0 taken at the start).
    assert!((pings as f64 - 8.0 * seconds).abs() <= 1.0, "{pings} pings");
}

/// A source whose rate does not divide the control rate samples uniformly on the control
/// ticks: rate·T samples in T seconds (within one), each gap ⌊f_c/f⌋ or ⌈f_c/f⌉ periods, the
/// ticks taken where the sample count j·f/f_c passes a whole number (Choice 335, Choice 540).
#[test]
fn a_source_at_any_rate_arrives_rate_times_t_times_with_gaps_of_whole_periods() {
    for rate_hz in [2.0, 3.0, 7.5, 8.0, 30.0, 64.0] {
        let mut m = exact();
        m.depth.timing = Timing {
            rate_hz,
            latency: 0.0,
            outages: Vec::new(),
        };
        let mut nav = NavComputer::new(&m, RATE);
        assert!(
            nav.solution().is_none(),
            "a solution before the first period"
        );
        let periods = 5_000u64;
        let mut ticks = Vec::new();
        for k in 0..periods {
            let (eta, nu) = straight(k, 0.5, 0.0, 5.0);
            if let Some(d) = nav.measure(&eta, &nu).arrived.depth {
                ticks.push(d.sampled_at);
            }
        }
        // The sample at tick 0 is the one taken before the mission (stamped 0, every source).
        let expected = rate_hz * periods as f64 / RATE;
        assert!(
            (ticks.len() as f64 + 1.0 - expected).abs() <= 1.0,
            "{rate_hz} Hz: {} samples in {periods} periods",
            ticks.len() + 1
        );
        let (lo, hi) = ((RATE / rate_hz).floor(), (RATE / rate_hz).ceil());
        for w in ticks.windows(2) {
            let gap = (w[1] - w[0]) as f64;
            assert!(
                lo <= gap && gap <= hi,
                "{rate_hz} Hz: a gap of {gap} periods"
            );
        }
    }
}

#[test]
fn dead_reckoning_under_a_known_velocity_bias_drifts_by_bias_times_t() {
    let mut m = exact();
    let bias = 0.01;
    m.dvl.velocity.bias = [bias, 0.0, 0.0];
    let psi: f64 = 0.7;
    let mut nav = NavComputer::new(&m, RATE);
    for k in 0..6001 {
        let (eta, nu) = straight(k, 0.5, psi, 5.0);
        let s = nav.step(&eta, &nu);
        let t = k as f64 / RATE;
        // The bias is along the body x axis: in the NED frame along ψ.
        let expected = [bias * t * psi.cos(), bias * t * psi.sin()];
        for i in 0..2 {
            assert!(
                (s.eta[i] - eta[i] - expected[i]).abs() < 1e-9,
                "t = {t}: {} vs {}",
                s.eta[i] - eta[i],
                expected[i]
            );
        }
        assert!(
            (s.eta[2] - eta[2]).abs() < 1e-12,
            "depth from the pressure sensor"
        );
    }
}

#[test]
fn a_fix_jumps_the_position_to_within_its_noise() {
    let mut m = exact();
    m.dvl.velocity.bias = [0.05, 0.0, 0.0];
    let sigma = 0.1;
    m.fix = Some(Source {
        timing: Timing {
            rate_hz: 1.0,
            latency: 0.0,
            outages: Vec::new(),
        },
        error: ErrorModel {
            sigma: [sigma; 2],
            ..ErrorModel::EXACT
        },
    });
    let mut nav = NavComputer::new(&m, RATE);
    let (mut fixes, mut sum_sq, mut last_fix) = (0usize, 0.0, None);
    for k in 0..40_001 {
        let (eta, nu) = straight(k, 0.5, 0.0, 5.0);
        let s = nav.step(&eta, &nu);
        if s.fix_at != last_fix {
            fixes += 1;
            sum_sq += (s.eta[0] - eta[0]).powi(2) + (s.eta[1] - eta[1]).powi(2);
            last_fix = s.fix_at;
        } else if last_fix.is_some() {
            // Between fixes the solution dead-reckons: its x drifts by the bias, smoothly.
            let since = (k - last_fix.unwrap()) as f64 / RATE;
            assert!(since <= 1.0 + 1e-9, "a fix a second");
        }
    }
    assert_eq!(fixes, 400, "one fix a second for 400 s");
    // Right at a fix the error is the fix's own: 2·400 normal components of σ.
    let dof = (2 * fixes) as f64;
    let stat = sum_sq / (sigma * sigma);
    assert!(
        (stat - dof).abs() < 5.0 * (2.0 * dof).sqrt(),
        "χ² {stat:.0} for {dof}"
    );
}

#[test]
fn bottom_lock_lost_above_the_dvls_range_drifts_with_the_ins_bias_and_comes_back() {
    let mut m = exact();
    m.dvl.timing.rate_hz = 5.0;
    m.dvl.seabed_depth = Some(100.0);
    m.dvl.max_altitude = 50.0;
    let b = 0.002;
    m.ins.accel.bias = [b, 0.0, 0.0];
    let mut nav = NavComputer::new(&m, RATE);
    // Altitude 40 m (lock) for 10 s, 60 m (lost) until 30 s, then 40 m again.
    let z = |t: f64| {
        if (10.0..30.0).contains(&t) {
            40.0
        } else {
            60.0
        }
    };
    let mut last_ping = 0.0;
    for k in 0..4000 {
        let t = k as f64 / RATE;
        let (eta, nu) = straight(k, 0.5, 0.0, z(t));
        let s = nav.step(&eta, &nu);
        if let Some(j) = s.velocity_at {
            last_ping = j as f64 / RATE;
        }
        let err = s.nu[0] - nu[0];
        // The velocity error is the INS bias integrated since the last ping with lock.
        assert!((err - b * (t - last_ping)).abs() < 1e-12, "t = {t}: {err}");
        if (10.2..30.0).contains(&t) {
            assert!(!s.bottom_lock, "t = {t}");
            assert!(last_ping < 10.0);
        }
        if t >= 30.2 {
            assert!(s.bottom_lock && err.abs() <= b * 0.2 + 1e-12, "t = {t}");
        }
    }
    // Just before the lock came back, the drift was b·(30 − 9.8) s.
}

#[test]
fn the_model_without_errors_tells_the_exact_state() {
    let mut m = exact();
    m.fix = Some(Source {
        timing: Timing {
            rate_hz: RATE,
            latency: 0.0,
            outages: Vec::new(),
        },
        error: ErrorModel::EXACT,
    });
    let mut nav = NavComputer::new(&m, RATE);
    for k in 0..3000 {
        // A turning, diving vehicle: the solution follows it to rounding.
        let t = k as f64 / RATE;
        let eta = [
            10.0 * t.sin(),
            10.0 * (1.0 - t.cos()),
            0.1 * t,
            0.01,
            -0.02,
            t,
        ];
        let nu = [1.0, 0.1, 0.05, 0.0, 0.0, 1.0];
        let s = nav.step(&eta, &nu);
        for i in 0..6 {
            assert!((s.eta[i] - eta[i]).abs() < 1e-9, "eta[{i}] at t = {t}");
            assert_eq!(s.nu[i], nu[i], "nu[{i}] at t = {t}");
        }
    }
}

#[test]
fn the_solution_is_determined_by_the_seed() {
    let run = |seed| {
        let mut m = NavigationModel::preset(Preset::LowCost, seed).unwrap();
        m.dvl.seabed_depth = Some(30.0);
        let mut nav = NavComputer::new(&m, RATE);
        (0..2000)
            .map(|k| {
                let (eta, nu) = straight(k, 0.5, 0.2, 5.0);
                nav.step(&eta, &nu)
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(3), run(3));
    assert_ne!(run(3), run(4));
}

/// The `ideal` preset is the exact state: Table 1's circle with `[navigation] preset = "ideal"`
/// flies bit for bit as without the table, and so does a real mission with `[noise]`.
#[test]
fn the_ideal_preset_flies_bit_for_bit_as_without_navigation() {
    for (file, extra) in [
        ("circular-10R.toml", ""),
        (
            "real/circular-10R.toml",
            "\n[noise]\neta_sigma = [0.005, 0.005, 0.005, 0.001, 0.001, 0.001]\n",
        ),
    ] {
        let text = std::fs::read_to_string(scenarios_dir().join(file)).unwrap() + extra;
        // Without navigation (a real-chain file without the table flies `survey`: the
        // exact state set here).
        let plain = parse_scenario(&text)
            .unwrap()
            .with(|c| c.navigation = None)
            .unwrap();
        let ideal = parse_scenario(&format!("{text}\n[navigation]\npreset = \"ideal\"\n")).unwrap();
        assert!(ideal.config().navigation.is_none());
        let (a, b) = (host_sim::sim::run(&plain), host_sim::sim::run(&ideal));
        assert_eq!(a.samples, b.samples, "{file}");
        assert_eq!(
            format!("{:?}", a.metrics),
            format!("{:?}", b.metrics),
            "{file}"
        );
    }
}

#[test]
fn a_preset_takes_keys_over_it_and_is_written_back_whole() {
    let text = circle_with(
        "[navigation]\npreset = \"survey\"\nseed = 9\n[navigation.dvl]\nrate_hz = 4\n\
         seabed_depth = 30\n[navigation.fix]\nsigma = [0.5, 0.5]\n",
    );
    let s = parse_scenario(&text).unwrap();
    let m = s.config().navigation.clone().unwrap();
    let survey = NavigationModel::preset(Preset::Survey, 9).unwrap();
    assert_eq!(m.dvl.timing.rate_hz, 4.0);
    assert_eq!(m.dvl.seabed_depth, Some(30.0));
    assert_eq!(m.ins, survey.ins);
    assert_eq!(m.fix.as_ref().unwrap().error.sigma, [0.5, 0.5]);
    let written = ScenarioFile::try_from(s.config())
        .unwrap()
        .to_toml()
        .unwrap();
    let back = parse_scenario(&written).unwrap();
    assert_eq!(back.config().navigation, Some(m));
}

#[test]
fn bad_navigation_values_are_refused_by_key() {
    for (extra, key) in [
        (
            "[navigation]\n[navigation.dvl]\nrate_hz = 4\n",
            "navigation.dvl",
        ),
        (
            "[navigation]\npreset = \"survey\"\n[navigation.dvl]\nrate_hz = 0\n",
            "navigation.dvl.rate_hz",
        ),
        (
            "[navigation]\npreset = \"survey\"\n[navigation.ins.attitude]\nsigma = [0, -1, 0]\n",
            "navigation.ins.attitude.sigma[1]",
        ),
        (
            "[navigation]\npreset = \"low-cost\"\n[navigation.depth]\nlatency = 11\n",
            "navigation.depth.latency",
        ),
        (
            "[navigation]\npreset = \"survey\"\n[navigation.fix]\noutages = [[5, 1]]\n",
            "navigation.fix.outages[0]",
        ),
    ] {
        assert_eq!(invalid_key(&circle_with(extra)).0, key, "{extra}");
    }
}
