//! The simulator and the board share the link types: what host-sim sends, the firmware's
//! supervisor (built for the host) receives through real frames, and it flies exactly the law
//! the simulator runs — bit for bit. Every mission kind crosses the link, the helix included.

use auv_link::{
    encode, Command, Envelope, FrameDecoder, MissionSpec, Msg, MAX_FRAME, PROTOCOL_VERSION,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::trajectory::Helix;
use controller_core::{
    Controller, ControllerConfig, Status, Table1Case, Trajectory, TrajectoryKind,
};
use firmware::supervisor::{BoardInfo, Supervisor};
use host_sim::board::frames::state_frame;
use nalgebra::Vector6;

/// The six Table-1 missions and a descending helix (not in the paper; the one kind no
/// Table-1 case uses).
fn missions() -> Vec<(String, Trajectory)> {
    let mut m: Vec<(String, Trajectory)> = Table1Case::ALL
        .iter()
        .map(|&c| (c.name().to_string(), Trajectory::table1(c)))
        .collect();
    let helix = TrajectoryKind::Helix(Helix {
        radius: 12.0,
        omega: 0.08,
        depth: 4.0,
        depth_rate: 0.15,
    });
    m.push((
        "helix".into(),
        Trajectory::new(helix).expect("a valid helix"),
    ));
    m
}

fn deliver(sup: &mut Supervisor, dec: &mut FrameDecoder, seq: u16, msg: Msg) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(
        &Envelope {
            version: PROTOCOL_VERSION,
            seq,
            msg,
        },
        &mut buf,
    )
    .expect("every message fits MAX_FRAME");
    for &b in &buf[..n] {
        match dec.push(b) {
            Some(Ok(env)) => sup.on_envelope(&env),
            Some(Err(e)) => panic!("a frame host-sim encoded did not decode: {e}"),
            None => {}
        }
    }
}

#[test]
fn the_board_builds_the_same_mission_from_the_link() {
    for (name, tr) in missions() {
        let spec = MissionSpec::from(tr.kind());
        let on_board = Trajectory::new(TrajectoryKind::try_from(spec).expect("a closed form"))
            .expect("valid mission");
        assert_eq!(on_board, tr, "{name}");
        for k in [0u64, 777, 6999, 1 << 40] {
            assert_eq!(tr.sample(k, 100), on_board.sample(k, 100), "{name}");
        }
    }
}

#[test]
fn the_board_flies_the_simulators_law_bit_for_bit_through_frames() {
    let ctl = Controller::new(ControllerConfig::default()).unwrap();
    for (name, tr) in missions() {
        let mut sup = Supervisor::new(
            Controller::new(ControllerConfig::default()).unwrap(),
            BoardInfo {
                supply_voltage: controller_core::DEFAULT_V_LIMIT,
                signing: false,
            },
        );
        let mut dec = FrameDecoder::new();
        deliver(&mut sup, &mut dec, 0, Msg::Command(Command::Arm));
        deliver(
            &mut sup,
            &mut dec,
            1,
            Msg::Command(Command::StartMission(tr.kind().into())),
        );
        for k in 0..50u64 {
            // A plant state near the reference, in f64 as the simulator holds it.
            let d = tr.sample(k, 100);
            let mut eta: Vector6<f64> = d.eta.cast();
            eta[0] += 0.01 * (k as f64 * 0.3).sin();
            eta[3] += 0.1;
            let nu = kinematics::jacobian_inv(&Attitude::from_eta(&eta)) * d.eta_dot.cast::<f64>();
            let frame = state_frame(k, &eta, &nu);
            deliver(&mut sup, &mut dec, 2 + k as u16, Msg::State(frame));
            let step = sup.step(false, &|| 0);
            let direct = ctl.update(k, &frame.eta, &frame.nu, &tr);
            assert_eq!(direct.status, Status::Ok);
            assert_eq!(
                step.telemetry.status,
                auv_link::BoardStatus::Running,
                "{name}"
            );
            assert_eq!(step.voltages, direct.voltage, "{name} at tick {k}");
            assert_eq!(step.telemetry.thrusts, direct.thrust);
            assert_eq!(step.telemetry.delta, direct.delta);
        }
    }
}
