//! Host benchmark of one `Controller::update` (and of configuration, which runs once).
//!
//! `cargo bench -p controller-core --bench update`. Target instruction counts are measured
//! under QEMU by the firmware, not here.

use std::hint::black_box;

use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Table1Case, Trajectory};
use criterion::{criterion_group, criterion_main, Criterion};

fn bench_update(c: &mut Criterion) {
    let ctl = Controller::new(ControllerConfig::default()).expect("defaults");
    let tr = Trajectory::table1(Table1Case::LawnMower30x15);
    let d = tr.sample(2500, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    let mut eta: [f32; 6] = d.eta.into();
    eta[0] += 0.05;
    eta[3] = 0.1;
    let nu: [f32; 6] = nu.into();
    c.bench_function("update (lawn-mower 30x15, Theorem 4)", |b| {
        b.iter(|| {
            ctl.update(
                black_box(2500),
                black_box(&eta),
                black_box(&nu),
                black_box(&tr),
            )
        })
    });
    c.bench_function("Controller::new (bounds over 2^9 box corners)", |b| {
        b.iter(|| Controller::new(black_box(ControllerConfig::default())))
    });
}

criterion_group!(benches, bench_update);
criterion_main!(benches);
