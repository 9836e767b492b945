//! The shipped real missions (`scenarios/real/`) flown on each navigation preset, and on the
//! shipped campaign's white `[noise]`: max path, saturation, and the thrusters' chatter (sign
//! reversals per second through a ±0.5 V dead band, command total variation per second), per
//! thruster. `cargo run --profile host -p host-sim --example navigation_presets [filter]`
//! (docs/navigation.md#what-the-shipped-missions-do). The controller is the scenario's (the real
//! chain's default: the estimator on); `EST=0` flies the solution as told, `EST=1` the core's
//! default estimator, `ESTP=`/`ESTV=`/`ESTA=` set its σ on x y (x y z), `NOFIX=1` drops the
//! preset's fixes and `FIX=rate,σ,latency` sets them. The thruster columns are main, vert
//! fore, vert aft, horz fore, horz aft.

use host_sim::scenario::navigation::{NavigationModel, Preset};
use host_sim::scenario::{load_scenario, Scenario, SensorNoise, SimConfig};
use host_sim::sim::{
    fly, ControlOut, ControlSource, LocalController, Observer, Outcome, Recording, Sample, Stop,
};

/// The law on the host, keeping the position it is told each period.
struct Told<'a> {
    law: LocalController<'a>,
    positions: Vec<[f64; 3]>,
}

impl ControlSource for Told<'_> {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, Stop> {
        self.positions
            .push(std::array::from_fn(|i| f64::from(eta[i])));
        self.law.control(k, eta, nu)
    }
}

/// Half-width of the dead band a reversal must cross (V).
const BAND: f64 = 0.5;

#[derive(Default)]
struct Chatter {
    state: [i8; 5],
    reversals: [u64; 5],
    variation: [f64; 5],
    last: Option<[f64; 5]>,
    t: f64,
    truth: Vec<[f64; 3]>,
}

impl Observer for Chatter {
    fn sample(&mut self, s: &Sample) {
        for i in 0..5 {
            let v = s.voltage[i];
            let sign = if v > BAND {
                1
            } else if v < -BAND {
                -1
            } else {
                0
            };
            if sign != 0 && self.state[i] != 0 && sign != self.state[i] {
                self.reversals[i] += 1;
            }
            if sign != 0 {
                self.state[i] = sign;
            }
            if let Some(last) = self.last {
                self.variation[i] += (v - last[i]).abs();
            }
        }
        self.last = Some(std::array::from_fn(|i| s.voltage[i]));
        self.t = s.t;
        self.truth.push([s.eta[0], s.eta[1], s.eta[2]]);
    }
}

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/real");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().contains(&filter))
        .collect();
    files.sort();
    println!("| mission | navigation | outcome | max path (mm) | max navigation position error (mm) | saturated (%) | peak V | reversals/s main/vf/va/hf/ha | TV (V/s) main/vf/va/hf/ha |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for f in files {
        let base = load_scenario(&f).unwrap();
        for (label, preset, noise) in [
            ("ideal", None, false),
            ("survey", Some(Preset::Survey), false),
            ("survey, no bias", Some(Preset::Survey), false),
            ("low-cost", Some(Preset::LowCost), false),
            ("[noise] campaign", None, true),
        ] {
            let s = base.with(|c| configure(c, label, preset, noise)).unwrap();
            println!("{}", row(&s, label));
        }
    }
}

/// The mission's configuration for one case: the preset (without its biases for a "no bias"
/// case), the shipped campaign's white noise if `noise`.
fn configure(c: &mut SimConfig, label: &str, preset: Option<Preset>, noise: bool) {
    c.navigation = preset.and_then(|p| NavigationModel::preset(p, 1));
    match std::env::var("EST").as_deref() {
        Ok("1") => c.controller.estimator.kind = controller_core::estimator::EstimatorKind::Kalman,
        Ok("0") => c.controller.estimator = controller_core::EstimatorConfig::default(),
        _ => {}
    }
    if let (Ok("1"), Some(m)) = (std::env::var("NOFIX").as_deref(), &mut c.navigation) {
        m.fix = None;
    }
    if let Ok(v) = std::env::var("ESTV") {
        let v: f32 = v.parse().unwrap();
        c.controller.estimator.velocity_sigma[0] = v;
        c.controller.estimator.velocity_sigma[1] = v;
        c.controller.estimator.velocity_sigma[2] = v;
    }
    if let Ok(v) = std::env::var("ESTA") {
        let v: f32 = v.parse().unwrap();
        c.controller.estimator.accel_sigma[0] = v;
        c.controller.estimator.accel_sigma[1] = v;
        c.controller.estimator.accel_sigma[2] = v;
    }
    if let Ok(v) = std::env::var("ESTP") {
        let v: f32 = v.parse().unwrap();
        c.controller.estimator.position_sigma[0] = v;
        c.controller.estimator.position_sigma[1] = v;
    }
    if let (Ok(f), Some(m)) = (std::env::var("FIX"), &mut c.navigation) {
        let v: Vec<f64> = f.split(',').map(|x| x.parse().unwrap()).collect();
        m.fix = Some(host_sim::scenario::navigation::Source {
            timing: host_sim::scenario::navigation::Timing {
                rate_hz: v[0],
                latency: v[2],
                outages: Vec::new(),
            },
            error: host_sim::scenario::navigation::ErrorModel::white_gm([v[1]; 2], [0.0; 2], 600.0),
        });
    }
    if let (Some(m), true) = (&mut c.navigation, label.ends_with("no bias")) {
        // The white noise and the latencies alone: every bias σ 0.
        m.ins.attitude.bias_sigma = [0.0; 3];
        m.ins.rates.bias_sigma = [0.0; 3];
        m.ins.accel.bias_sigma = [0.0; 3];
        m.dvl.velocity.bias_sigma = [0.0; 3];
        m.depth.error.bias_sigma = [0.0];
    }
    if noise {
        c.noise = Some(SensorNoise {
            eta_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
            nu_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
            seed: 1,
        });
    }
}

/// One table row: the run of `s` and its chatter.
fn row(s: &Scenario, label: &str) -> String {
    let mut chatter = Chatter::default();
    let mut told = Told {
        law: LocalController::new(s),
        positions: Vec::new(),
    };
    let r = fly(s, &mut told, &mut chatter, Recording::MetricsOnly);
    let t = chatter.t.max(1e-9);
    let nav_error = told
        .positions
        .iter()
        .zip(&chatter.truth)
        .map(|(a, b)| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .fold(0.0f64, f64::max);
    let rev: Vec<String> = chatter
        .reversals
        .iter()
        .map(|n| format!("{:.1}", *n as f64 / t))
        .collect();
    let tv: Vec<String> = chatter
        .variation
        .iter()
        .map(|v| format!("{:.0}", v / t))
        .collect();
    let outcome = match &r.outcome {
        Outcome::Completed => "completed".to_string(),
        Outcome::Missed { reason } => format!("missed: {reason}"),
        other => format!("{other:?}"),
    };
    format!(
        "| {} | {label} | {outcome} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} |",
        r.name,
        r.metrics.max_path * 1000.0,
        nav_error * 1000.0,
        r.metrics.saturated_fraction * 100.0,
        r.metrics.peak_voltage,
        rev.join(" / "),
        tv.join(" / ")
    )
}
