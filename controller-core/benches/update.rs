//! Host benchmark of one `Controller::update` (and of configuration, which runs once).
//!
//! `cargo bench -p controller-core --bench update`. Target instruction counts are measured
//! under QEMU by the firmware, not here.

use std::hint::black_box;

use controller_core::kinematics::{self, Attitude};
use controller_core::trajectory::{SpeedList, WaypointList};
use controller_core::{
    Controller, ControllerConfig, HeadingMode, Mission, Table1Case, Trajectory, TrajectoryKind,
};
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
    // A waypoint path of 32 points (61 segments, a time law of 61 parts): the sample's two
    // fixed binary searches at their largest, and building it in place (docs/missions.md#built-in-place).
    let survey = survey32();
    let wp = Trajectory::new(survey).expect("a valid 32-point survey");
    let t = 4000;
    let d = wp.sample(t, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    let mut eta: [f32; 6] = d.eta.into();
    eta[1] += 0.05;
    let nu: [f32; 6] = nu.into();
    c.bench_function("update (waypoints, 32 points with a time law)", |b| {
        b.iter(|| {
            ctl.update(
                black_box(t),
                black_box(&eta),
                black_box(&nu),
                black_box(&wp),
            )
        })
    });
    let mut slot = Trajectory::EMPTY;
    c.bench_function(
        "Trajectory::set (waypoints, 32 points with a time law)",
        |b| b.iter(|| slot.set(black_box(&survey))),
    );
    c.bench_function("Controller::new (bounds over 2^9 box corners)", |b| {
        b.iter(|| Controller::new(black_box(ControllerConfig::default())))
    });
}

/// A lawn-mower of 32 waypoints: 16 rows of 60 m, 20 m apart, tangent heading, 0.8 m/s on the
/// rows and 0.5 m/s in the turns and on the short legs.
fn survey32() -> Mission {
    let mut points = Vec::new();
    for row in 0..16 {
        let y = 20.0 * row as f32;
        let (a, b) = if row % 2 == 0 {
            (0.0, 60.0)
        } else {
            (60.0, 0.0)
        };
        points.push([a, y, 5.0]);
        points.push([b, y, 5.0]);
    }
    let parts = 2 * points.len() - 3;
    let speeds: Vec<f32> = (0..parts)
        .map(|i| if i % 4 == 0 { 0.8 } else { 0.5 })
        .collect();
    Mission {
        path: TrajectoryKind::Waypoints {
            points: WaypointList::new(&points).expect("32 points"),
            speed: 0.5,
            turn_radius: Some(3.0),
            speeds: Some(SpeedList::new(&speeds).expect("61 speeds")),
            speed_change: None,
        },
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    }
}

criterion_group!(benches, bench_update);
criterion_main!(benches);
