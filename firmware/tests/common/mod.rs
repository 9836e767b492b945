//! Helpers of the firmware's host tests: a supervisor as the QEMU board makes it, the
//! navigation computer's end of the link, and state frames on the circle.

#![allow(dead_code)]

pub mod bench;

use auv_link::sign::{Direction, LinkKey, Signer};
use auv_link::{encode, encode_signed, Command, Envelope, MissionPlan, Msg, StateFrame, MAX_FRAME};
use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Table1Case, Trajectory};
use firmware::board::{self, LinkBuffers};
use firmware::supervisor::{BoardInfo, Supervisor};

/// The board's supply, as both boards state it.
pub const SUPPLY: f32 = controller_core::DEFAULT_V_LIMIT;

/// A key for the signed tests.
pub const KEY: LinkKey = LinkKey::new([0xA7; 32]);

pub fn board_info(signing: bool) -> BoardInfo {
    BoardInfo {
        supply_voltage: SUPPLY,
        signing,
    }
}

/// The default controller (built once: `Controller::new` takes the bounds over the box).
pub fn controller() -> Controller {
    static C: std::sync::OnceLock<Controller> = std::sync::OnceLock::new();
    C.get_or_init(|| Controller::new(ControllerConfig::default()).unwrap())
        .clone()
}

/// A supervisor with the default controller, as the boards boot (signing off).
pub fn supervisor() -> Supervisor {
    Supervisor::new(controller(), board_info(false))
}

/// The mission every test flies: the paper's 10 m circle, as the paper flies it (its heading,
/// time scale 1).
pub const CIRCLE: MissionPlan = MissionPlan::EXAMPLE;

/// A lawn-mower survey of 12 waypoints (60 m legs, 20 m apart), its speeds unset (two
/// upload chunks), flown with the tangent heading at the paper's speed.
pub fn survey() -> controller_core::Mission {
    let mut points = Vec::new();
    for row in 0..6 {
        let y = 20.0 * row as f32;
        let (a, b) = if row % 2 == 0 {
            (0.0, 60.0)
        } else {
            (60.0, 0.0)
        };
        points.push([a, y, 5.0]);
        points.push([b, y, 5.0]);
    }
    controller_core::Mission {
        path: controller_core::TrajectoryKind::Waypoints {
            points: controller_core::trajectory::WaypointList::new(&points).expect("12 points"),
            speed: 0.8,
            turn_radius: Some(3.5),
            speeds: None,
            speed_change: None,
        },
        heading: controller_core::HeadingMode::Tangent,
        time_scale: 1.0,
    }
}

/// A state frame on the circle at tick `k` (the vehicle exactly on its reference).
pub fn state(k: u64) -> StateFrame {
    let d = Trajectory::table1(Table1Case::Circular10R).sample(k, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    StateFrame {
        t_ticks: k,
        eta: d.eta.into(),
        nu: nu.into(),
    }
}

/// The navigation computer: numbers its frames (+1 each) and hands them to the supervisor,
/// directly or through real frames.
pub struct Host {
    pub seq: u16,
    pub signer: Option<Signer>,
}

impl Host {
    pub fn new() -> Self {
        Host {
            seq: 0,
            signer: None,
        }
    }

    /// A host that signs with `key`.
    pub fn signed(key: &LinkKey) -> Self {
        Host {
            seq: 0,
            signer: Some(Signer::new(key, Direction::ToBoard)),
        }
    }

    /// The next envelope.
    pub fn env(&mut self, msg: Msg) -> Envelope {
        self.seq = self.seq.wrapping_add(1);
        Envelope::new(self.seq, msg)
    }

    /// The next envelope, straight to the supervisor.
    pub fn give(&mut self, sup: &mut Supervisor, msg: Msg) {
        let e = self.env(msg);
        sup.on_envelope(&e);
    }

    pub fn command(&mut self, sup: &mut Supervisor, c: Command) {
        self.give(sup, Msg::Command(c));
    }

    /// The next envelope as a frame on the wire (signed if this host signs).
    pub fn wire(&mut self, msg: Msg) -> Vec<u8> {
        let e = self.env(msg);
        let mut out = [0u8; MAX_FRAME];
        let n = match &mut self.signer {
            None => encode(&e, &mut out),
            Some(s) => encode_signed(&e, s, &mut out),
        }
        .unwrap();
        out[..n].to_vec()
    }

    /// The next envelope through the board's end of the link.
    pub fn send(&mut self, sup: &mut Supervisor, link: &mut LinkBuffers, msg: Msg) {
        let w = self.wire(msg);
        board::receive(sup, link, &w);
    }
}

impl Default for Host {
    fn default() -> Self {
        Self::new()
    }
}

/// Armed, flying the circle, with a state frame for tick 0 waiting.
pub fn running() -> (Supervisor, Host) {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Arm);
    h.command(&mut s, Command::StartMission(CIRCLE));
    h.give(&mut s, Msg::State(state(0)));
    (s, h)
}

pub const NOW: &dyn Fn() -> u32 = &|| 0;
