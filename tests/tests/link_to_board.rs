//! The simulator and the board share the link types: what host-sim sends, the firmware's
//! supervisor (built for the host) receives through real frames, and it flies exactly the law
//! the simulator runs — bit for bit.

use auv_link::{encode, Command, Envelope, FrameDecoder, Msg, MAX_FRAME, PROTOCOL_VERSION};
use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Status, Table1Case, Trajectory};
use firmware::supervisor::{trajectory_of, Supervisor};
use host_sim::link::{mission_spec, state_frame};
use nalgebra::Vector6;

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
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        let on_board = trajectory_of(&mission_spec(&tr.kind())).expect("valid mission");
        for k in [0u64, 777, 6999, 1 << 40] {
            assert_eq!(
                tr.sample(k, 100),
                on_board.sample(k, 100),
                "{}",
                case.name()
            );
        }
    }
}

#[test]
fn the_board_flies_the_simulators_law_bit_for_bit_through_frames() {
    let ctl = Controller::new(ControllerConfig::default()).unwrap();
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        let mut sup = Supervisor::new(Controller::new(ControllerConfig::default()).unwrap());
        let mut dec = FrameDecoder::new();
        deliver(&mut sup, &mut dec, 0, Msg::Command(Command::Arm));
        deliver(
            &mut sup,
            &mut dec,
            1,
            Msg::Command(Command::StartMission(mission_spec(&tr.kind()))),
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
            assert_eq!(step.voltages, direct.voltage, "{} at tick {k}", case.name());
            assert_eq!(step.telemetry.thrusts, direct.thrust);
            assert_eq!(step.telemetry.delta, direct.delta);
        }
    }
}
