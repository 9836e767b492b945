//! Preflight benchmarks (docs/real-vehicle.md#how-the-check-is-made): `host-sim check`'s work —
//! the verdict over both scopes and, for a waypoint mission, the speed profile's search — on
//! the shipped survey, a 32-point route (a payload staircase, a current), a day-long circle
//! and the shipped real circle flown for a day (Choices 538–539); and the chatter term alone (its prediction and its search, Choices 500–504 and
//! 516–517) on the survey and on the tuning study's main-job sample (`tune::MAIN_JOB_TUNE`:
//! refused missions ask it up to scale 100). `cargo bench --profile host -p host-sim --bench
//! preflight`; one thread.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::scenario::{load_scenario, Scenario};
use host_sim::studies::preflight::{self, chatter, profile, Engine, DEFAULT_MARGIN};
use host_sim::studies::tune;

fn scenario(path: &str) -> Scenario {
    load_scenario(&Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).expect("the scenario")
}

/// What `host-sim check` computes, afresh (nothing kept from an earlier iteration, Choice 537).
fn check(s: &Scenario, engine: Engine) {
    preflight::forget_kept();
    preflight::check_with(s, DEFAULT_MARGIN, true, engine).expect("the check");
    profile::propose_with(s, DEFAULT_MARGIN, engine).expect("the profile");
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("check");
    group.sample_size(10);
    for (name, path) in [
        ("survey-200x100", "scenarios/real/survey-200x100.toml"),
        ("route32", "benches/route32.toml"),
        ("day-circle", "benches/day-circle.toml"),
        ("real-day-circle", "benches/real-day-circle.toml"),
    ] {
        let s = scenario(path);
        group.bench_function(name, |b| b.iter(|| check(black_box(&s), Engine::Fast)));
    }
    group.finish();
    let mut group = c.benchmark_group("chatter");
    group.sample_size(10);
    let survey = scenario("scenarios/real/survey-200x100.toml");
    group.bench_function("survey-200x100", |b| {
        b.iter(|| chatter::chatter(black_box(&survey)).expect("the term"))
    });
    let sample = tune::sample(&tune::MAIN_JOB_TUNE).expect("the sample");
    group.bench_function("tune-sample", |b| {
        b.iter(|| {
            for s in &sample.missions {
                chatter::chatter(black_box(s)).expect("the term");
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
