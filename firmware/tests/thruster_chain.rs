//! Protocol 3 on the board: `SetConfig` carries the thruster chain (thrust unit of Eqs 31–32,
//! mounting, axis priority) and `StartMission` the heading and time scale (docs/link.md#what-crosses-the-link).
//! Each is applied whole or refused with its reason, the chain only while disarmed, and every
//! telemetry frame names the unit and mounting the board flies. What the board then flies is
//! checked against a controller and trajectory built on the host from the same settings.

use auv_link::{
    AxisPriority, BoardStatus, Command, ConfigPatch, Heading, MissionPlan, MissionSpec, Msg,
    Refusal, ThrustUnit,
};
use controller_core::allocation;
use controller_core::effectiveness::{ThrusterGeometry, AUV150_REVERSED, THRUSTERS};
use controller_core::{Controller, ControllerConfig, Mission, Trajectory};
use firmware::supervisor::{Mode, Supervisor, NOT_AUV150};

mod common;
use common::{state, supervisor, Host, CIRCLE, NOW};

/// A priority unlike the default (surge first, then sway …), with unequal weights.
fn surge_first() -> allocation::AxisPriority {
    allocation::AxisPriority {
        rank: [5, 4, 2, 0, 1, 3],
        weight: [1.0, 2.0, 0.5, 1.0, 4.0, 0.25],
    }
}

/// The whole chain in one patch: newton, no thruster reversed, surge first.
fn chain() -> ConfigPatch {
    ConfigPatch {
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(0),
        priority: Some(surge_first().into()),
        ..ConfigPatch::EMPTY
    }
}

fn refusal_count(s: &Supervisor) -> (u32, Option<Refusal>) {
    (s.refused_commands(), s.last_refusal())
}

#[test]
fn the_board_boots_on_the_default_chain_and_says_so() {
    let mut s = supervisor();
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.thrust_unit, ThrustUnit::Kgf);
    assert_eq!(t.reversed_thrusters, AUV150_REVERSED);
    assert_eq!(
        ThrusterGeometry::auv150(t.reversed_thrusters),
        ControllerConfig::default().geometry
    );
}

#[test]
fn set_config_applies_the_chain_whole_and_every_frame_reports_it() {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::SetConfig(chain()));
    assert_eq!(refusal_count(&s), (0, None));
    let cfg = s.controller().config();
    assert_eq!(cfg.thrust_unit, controller_core::ThrustUnit::Newton);
    assert_eq!(cfg.geometry, ThrusterGeometry::auv150(0));
    assert_eq!(cfg.priority, surge_first());
    // Disarmed, armed, running, fail-safe: every frame names the unit and mounting.
    let mut frames = vec![s.step(false, NOW).telemetry];
    h.command(&mut s, Command::Arm);
    frames.push(s.step(false, NOW).telemetry);
    h.command(&mut s, Command::StartMission(CIRCLE));
    h.give(&mut s, Msg::State(state(0)));
    frames.push(s.step(false, NOW).telemetry);
    frames.push(s.step(true, NOW).telemetry);
    let statuses: Vec<_> = frames.iter().map(|t| t.status).collect();
    assert_eq!(
        statuses[..3],
        [
            BoardStatus::Disarmed,
            BoardStatus::Armed,
            BoardStatus::Running
        ]
    );
    assert!(matches!(statuses[3], BoardStatus::FailSafe(_)));
    for t in &frames {
        assert_eq!(
            (t.thrust_unit, t.reversed_thrusters),
            (ThrustUnit::Newton, 0)
        );
    }
}

#[test]
fn the_board_flies_the_chain_it_reports() {
    // The board after SetConfig and a host controller built from the same settings give the
    // same voltages, bit for bit; the default chain gives different ones (the unit and the
    // mounting both change what reaches the thrusters).
    let host_cfg = ControllerConfig {
        thrust_unit: controller_core::ThrustUnit::Newton,
        geometry: ThrusterGeometry::auv150(0),
        priority: surge_first(),
        ..ControllerConfig::default()
    };
    let fly = |patch: Option<ConfigPatch>| {
        let mut s = supervisor();
        let mut h = Host::new();
        if let Some(p) = patch {
            h.command(&mut s, Command::SetConfig(p));
            // The rebuild is its period's long job (Choice 226): the board flies from the
            // next period on, as its link's next frames wait for it.
            s.step(false, NOW);
        }
        h.command(&mut s, Command::Arm);
        h.command(&mut s, Command::StartMission(CIRCLE));
        (0..20u64)
            .map(|k| {
                h.give(&mut s, Msg::State(state(k)));
                s.step(false, NOW).telemetry.voltages
            })
            .collect::<Vec<_>>()
    };
    let tr = Trajectory::new(Mission::try_from(CIRCLE).expect("a closed form")).unwrap();
    for (patch, cfg) in [
        (Some(chain()), host_cfg),
        (None, ControllerConfig::default()),
    ] {
        let c = Controller::new(cfg).unwrap();
        let want: Vec<_> = (0..20u64)
            .map(|k| {
                let st = state(k);
                c.update(k, &st.eta, &st.nu, &tr).voltage
            })
            .collect();
        let got = fly(patch);
        let bits = |v: &Vec<[f32; THRUSTERS]>| -> Vec<[u32; THRUSTERS]> {
            v.iter().map(|a| a.map(f32::to_bits)).collect()
        };
        assert_eq!(bits(&got), bits(&want));
    }
    assert_ne!(fly(Some(chain())), fly(None));
}

#[test]
fn the_chain_is_refused_while_armed_and_nothing_changes() {
    for running in [false, true] {
        let mut s = supervisor();
        let mut h = Host::new();
        h.command(&mut s, Command::Arm);
        if running {
            h.command(&mut s, Command::StartMission(CIRCLE));
            h.give(&mut s, Msg::State(state(0)));
        }
        let before = *s.controller().config();
        for p in [
            chain(),
            ConfigPatch {
                thrust_unit: Some(ThrustUnit::Newton),
                ..ConfigPatch::EMPTY
            },
            ConfigPatch {
                reversed_thrusters: Some(0),
                ..ConfigPatch::EMPTY
            },
        ] {
            let (n, _) = refusal_count(&s);
            h.command(&mut s, Command::SetConfig(p));
            assert_eq!(refusal_count(&s), (n + 1, Some(Refusal::WhileArmed)));
        }
        assert_eq!(*s.controller().config(), before);
        let t = s.step(false, NOW).telemetry;
        assert_eq!(
            (t.thrust_unit, t.reversed_thrusters),
            (ThrustUnit::Kgf, AUV150_REVERSED)
        );
        assert_eq!(
            t.status,
            if running {
                BoardStatus::Running
            } else {
                BoardStatus::Armed
            }
        );
    }
}

#[test]
fn an_invalid_mounting_or_priority_is_refused_with_its_reason_and_nothing_changes() {
    let mut s = supervisor();
    let mut h = Host::new();
    let before = *s.controller().config();
    let weight = |axis: usize, w: f32| {
        let mut p = allocation::AxisPriority::default();
        p.weight[axis] = w;
        AxisPriority::from(p)
    };
    let cases = [
        // A sixth thruster, with a valid unit beside it: the unit must not be applied.
        (
            ConfigPatch {
                thrust_unit: Some(ThrustUnit::Newton),
                reversed_thrusters: Some(1 << 5),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidMounting,
        ),
        (
            ConfigPatch {
                reversed_thrusters: Some(NOT_AUV150),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidMounting,
        ),
        (
            ConfigPatch {
                rate_hz: Some(50),
                priority: Some(weight(0, f32::NAN)),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidPriority,
        ),
        (
            ConfigPatch {
                thrust_unit: Some(ThrustUnit::Newton),
                priority: Some(weight(4, 0.0)),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidPriority,
        ),
        (
            ConfigPatch {
                priority: Some(weight(5, -1.0)),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidPriority,
        ),
        (
            ConfigPatch {
                priority: Some(weight(1, f32::INFINITY)),
                ..ConfigPatch::EMPTY
            },
            Refusal::InvalidPriority,
        ),
    ];
    let refused = cases.len() as u32;
    for (i, (p, why)) in cases.into_iter().enumerate() {
        h.command(&mut s, Command::SetConfig(p));
        assert_eq!(refusal_count(&s), (i as u32 + 1, Some(why)), "{p:?}");
        assert_eq!(*s.controller().config(), before, "{p:?}");
        let t = s.step(false, NOW).telemetry;
        assert_eq!(
            (t.thrust_unit, t.reversed_thrusters),
            (ThrustUnit::Kgf, AUV150_REVERSED)
        );
        assert_eq!(t.last_refusal, Some(why));
    }
    // Every mask of five bits is a valid mounting.
    for m in 0..32u8 {
        h.command(
            &mut s,
            Command::SetConfig(ConfigPatch {
                reversed_thrusters: Some(m),
                ..ConfigPatch::EMPTY
            }),
        );
        assert_eq!(s.refused_commands(), refused, "mask {m:#b}");
        assert_eq!(s.step(false, NOW).telemetry.reversed_thrusters, m);
    }
}

#[test]
fn start_mission_carries_heading_and_time_scale_and_the_board_flies_them() {
    for (heading, time_scale) in [(Heading::Tangent, 2.0), (Heading::Paper, 3.5)] {
        let plan = MissionPlan {
            heading,
            time_scale,
            ..CIRCLE
        };
        let mut s = supervisor();
        let mut h = Host::new();
        h.command(&mut s, Command::Arm);
        h.command(&mut s, Command::StartMission(plan));
        assert_eq!((s.mode(), s.refused_commands()), (Mode::Running, 0));
        let tr = Trajectory::new(Mission {
            path: CIRCLE.path.try_into().expect("a closed form"),
            heading: heading.into(),
            time_scale,
        })
        .unwrap();
        let c = Controller::new(ControllerConfig::default()).unwrap();
        for k in 0..10u64 {
            let st = state(k);
            h.give(&mut s, Msg::State(st));
            let t = s.step(false, NOW).telemetry;
            let want = c.update(k, &st.eta, &st.nu, &tr);
            assert_eq!(
                t.tau.map(f32::to_bits),
                want.tau.map(f32::to_bits),
                "{plan:?} tick {k}"
            );
        }
    }
    // What the board was given is the mission the host meant: on the circle x = R sin ωt,
    // y = R cos ωt the course is −ωt/k (the paper's heading is +ωt/k), at k = 2 and t = 5 s
    // −0.25 rad.
    let on_board = Trajectory::new(
        Mission::try_from(MissionPlan {
            heading: Heading::Tangent,
            time_scale: 2.0,
            ..CIRCLE
        })
        .expect("a closed form"),
    )
    .unwrap();
    let psi = on_board.sample(500, 100).eta[5];
    assert!((psi + 0.25).abs() < 1e-5, "{psi}");
}

#[test]
fn an_invalid_heading_or_time_scale_is_refused_with_its_reason() {
    let plan = |heading, time_scale| MissionPlan {
        heading,
        time_scale,
        ..CIRCLE
    };
    let cases = [
        (plan(Heading::Paper, 0.5), Refusal::InvalidTimeScale),
        (plan(Heading::Paper, 0.0), Refusal::InvalidTimeScale),
        (plan(Heading::Paper, -2.0), Refusal::InvalidTimeScale),
        (plan(Heading::Tangent, f32::NAN), Refusal::InvalidTimeScale),
        (
            plan(Heading::Paper, f32::INFINITY),
            Refusal::InvalidTimeScale,
        ),
        (
            plan(Heading::Paper, 2.0 * Trajectory::MAX_TIME_SCALE),
            Refusal::InvalidTimeScale,
        ),
        // 10 m at 0.1 rad/s is 1 m/s; slowed 100 times, 0.01 m/s: below the tangent
        // heading's threshold (the paper's heading flies it).
        (plan(Heading::Tangent, 100.0), Refusal::TangentTooSlow),
        (
            MissionPlan {
                path: MissionSpec::Circle {
                    radius: -1.0,
                    omega: 0.1,
                    depth: 5.0,
                },
                ..plan(Heading::Tangent, 2.0)
            },
            Refusal::InvalidMission,
        ),
    ];
    const { assert!(0.01 < Trajectory::MIN_TANGENT_SPEED) };
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Arm);
    for (i, (p, why)) in cases.into_iter().enumerate() {
        h.command(&mut s, Command::StartMission(p));
        assert_eq!(refusal_count(&s), (i as u32 + 1, Some(why)), "{p:?}");
        assert_eq!(s.mode(), Mode::Armed, "{p:?}");
        assert_eq!(s.step(false, NOW).telemetry.last_refusal, Some(why));
    }
    h.command(&mut s, Command::StartMission(plan(Heading::Paper, 100.0)));
    assert_eq!((s.mode(), s.refused_commands()), (Mode::Running, 8));
}
