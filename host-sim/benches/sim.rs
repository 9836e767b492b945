//! Plant and mission benchmarks: `cargo bench -p host-sim --bench sim`.
//! The real-time factor is 70 s divided by the mission time reported here.

use std::hint::black_box;

use controller_core::model::{ParamVariation, VehicleParams};
use controller_core::Table1Case;
use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::plant::{CurrentModel, Plant, PlantState, PlantTerms};
use host_sim::scenario::paper;
use nalgebra::{Vector3, Vector6};

fn bench(c: &mut Criterion) {
    let params = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let s = PlantState {
        eta: Vector6::new(1.0, 2.0, 5.0, 0.1, 0.05, 0.3),
        nu: Vector6::new(1.5, 0.1, 0.05, 0.02, 0.01, 0.1),
    };
    let tau = Vector6::new(500.0, 100.0, -50.0, 0.0, 20.0, 30.0);
    let current = Vector3::new(0.2, 0.0, 0.0);
    c.bench_function("plant RK4 step (incl. M and its Cholesky)", |b| {
        b.iter(|| {
            let plant = Plant::new(black_box(params), PlantTerms::default()).unwrap();
            plant.rk4_step(black_box(&s), black_box(&tau), black_box(&current), 0.001)
        })
    });
    let plant = Plant::new(params, PlantTerms::default()).unwrap();
    c.bench_function("plant RK4 step (M cached)", |b| {
        b.iter(|| plant.rk4_step(black_box(&s), black_box(&tau), black_box(&current), 0.001))
    });
    c.bench_function("plant derivative", |b| {
        b.iter(|| plant.derivative(black_box(&s), black_box(&tau), black_box(&current)))
    });
    // Choice 80: ν̇ from the cached M⁻¹ against the solve with M's Cholesky factor.
    let m = controller_core::model::mass_matrix(&params);
    let chol = m.cholesky().unwrap();
    let m_inv = chol.inverse();
    c.bench_function("nu_dot: Cholesky solve", |b| {
        b.iter(|| chol.solve(black_box(&tau)))
    });
    c.bench_function("nu_dot: M⁻¹ product", |b| {
        b.iter(|| m_inv * black_box(tau))
    });
    missions(c);
    currents(c);
}

/// Whole missions: the paper's lawn-mower and one run of the shipped real-chain campaign.
fn missions(c: &mut Criterion) {
    let scenario = paper::scenario(Table1Case::LawnMower30x15, true).expect("the paper's case");
    let mut group = c.benchmark_group("mission");
    group.sample_size(20);
    group.bench_function("lawn-mower-30x15, 70 s, 1 ms plant, 100 Hz loop", |b| {
        b.iter(|| host_sim::sim::run(black_box(&scenario)))
    });
    group.finish();
    // The per-run cost that sizes a cluster (docs/campaigns.md): one run of the shipped
    // real-chain campaign (70 s, real thrusters, current, noise), as a shard flies it.
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("campaigns/real-circle.campaign.toml");
    let campaign = host_sim::studies::campaign::Campaign::load(&file).expect("the campaign");
    // The shipped campaign flies study-grade (Choice 400); the same runs at each base's 1 ms
    // step beside it.
    let mut spec = campaign.spec.clone();
    spec.plant_step = None;
    let at_1ms = host_sim::studies::campaign::Campaign::new(
        campaign.text.clone(),
        spec,
        campaign.bases.clone(),
    );
    // Its noise drawn every period from ChaCha12 (before Choice 536) beside the study-grade
    // draws it declares.
    let mut spec = campaign.spec.clone();
    spec.noise_draws = None;
    let every_period = host_sim::studies::campaign::Campaign::new(
        campaign.text.clone(),
        spec,
        campaign.bases.clone(),
    );
    let mut group = c.benchmark_group("campaign");
    group.sample_size(20);
    for (name, campaign) in [
        (
            "real-circle run (70 s, real chain, drawn Δp, current, noise), study-grade step",
            &campaign,
        ),
        (
            "real-circle run (70 s, real chain, drawn Δp, current, noise), study-grade step, noise drawn every period",
            &every_period,
        ),
        (
            "real-circle run (70 s, real chain, drawn Δp, current, noise), 1 ms step",
            &at_1ms,
        ),
    ] {
        let mut i = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                i += 1;
                campaign.fly(black_box(i))
            })
        });
    }
    group.finish();
}

/// A wandering current against a constant one on the same route.
fn currents(c: &mut Criterion) {
    // A wandering current against a constant one (Choice 401): 100 s of the shipped waypoint
    // route, flown as `run` flies it (plot series kept), the preflight aside.
    let route =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/waypoints-short.toml");
    let route = host_sim::scenario::load_scenario(&route).expect("the route");
    let constant = route
        .with(|c| {
            c.duration = 100.0;
            c.current = CurrentModel::Constant([0.1, 0.05, 0.0]);
        })
        .expect("constant current");
    let wandering = route
        .with(|c| {
            c.duration = 100.0;
            c.current = CurrentModel::GaussMarkov {
                mean: [0.1, 0.05, 0.0],
                sigma: [0.03, 0.03, 0.01],
                tau: 20.0,
                seed: 7,
            };
        })
        .expect("Gauss–Markov current");
    let mut group = c.benchmark_group("current");
    group.sample_size(10);
    for (name, s) in [("constant", &constant), ("gauss-markov", &wandering)] {
        group.bench_function(format!("waypoints-short 100 s, {name} current"), |b| {
            b.iter(|| host_sim::sim::run(black_box(s)))
        });
    }
    group.finish();
    real_chain_currents(c);
}

/// Choice 461: the flying cost of a wandering current on the full real chain (survey
/// navigation, estimator, Eqs 31–32, metrics only as a campaign flies), at the 1 ms plant and
/// at the study-grade step (Choice 400): the ratio of each pair is the cost.
fn real_chain_currents(c: &mut Criterion) {
    let circle =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/real/circular-10R.toml");
    let circle = host_sim::scenario::load_scenario(&circle).expect("the real circle");
    let mut group = c.benchmark_group("current (real chain)");
    group.sample_size(10);
    for (step, study) in [("1 ms plant", false), ("study-grade plant", true)] {
        for (name, current) in [
            ("constant", CurrentModel::Constant([0.1, 0.05, 0.0])),
            (
                "gauss-markov",
                CurrentModel::GaussMarkov {
                    mean: [0.1, 0.05, 0.0],
                    sigma: [0.03, 0.03, 0.01],
                    tau: 20.0,
                    seed: 7,
                },
            ),
        ] {
            let s = circle
                .with(|c| {
                    if study {
                        // Choice 400 with Choice 542: one midpoint step per control period.
                        host_sim::studies::campaign::PlantStep::ControlPeriod.apply(c);
                    }
                    c.current = current;
                })
                .expect("the circle with a current");
            group.bench_function(format!("real circle 70 s, {step}, {name} current"), |b| {
                b.iter(|| {
                    host_sim::sim::fly(
                        black_box(&s),
                        &mut host_sim::sim::LocalController::new(&s),
                        &mut (),
                        host_sim::sim::Recording::MetricsOnly,
                    )
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
