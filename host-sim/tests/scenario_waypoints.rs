//! Waypoint missions in scenario files (docs/missions.md#waypoint-paths): the tangent heading by default,
//! the pinned speed profile, the per-leg caps, lost upload chunks, and errors that name the
//! key and the point, leg or chunk.

mod common;

use controller_core::TrajectoryKind;
use host_sim::scenario::{parse_scenario, ScenarioError};

use common::{invalid_key, toml_error};

/// A waypoint `[trajectory]` with `points` and `extra` keys.
fn waypoints_with(points: &str, extra: &str) -> String {
    format!("name = \"w\"\n[trajectory]\nkind = \"waypoints\"\npoints = {points}\n{extra}")
}

#[test]
fn waypoint_missions_parse_with_the_tangent_heading_by_default() {
    let s = parse_scenario(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]",
        "speed = 0.5\n",
    ))
    .expect("valid");
    let c = s.config();
    assert_eq!(c.heading, controller_core::HeadingMode::Tangent);
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        ..
    } = c.trajectory
    else {
        panic!("{:?}", c.trajectory)
    };
    assert_eq!(
        points.as_slice(),
        &[[0.0, 0.0, 5.0], [60.0, 0.0, 5.0], [60.0, 30.0, 5.0]]
    );
    assert_eq!((speed, turn_radius), (0.5, None));
    // turn_radius and an explicit paper heading are taken.
    let s = parse_scenario(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]",
        "speed = 0.5\nturn_radius = 3\nheading = \"paper\"\n",
    ))
    .expect("valid");
    assert!(matches!(
        s.config().trajectory,
        TrajectoryKind::Waypoints {
            turn_radius: Some(3.0),
            ..
        }
    ));
}

#[test]
fn waypoint_errors_name_their_key_and_reason() {
    // Repeated point, sharp turn, short leg: `trajectory.points`, with the waypoint's index.
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 0, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(msg.contains("waypoint 2 repeats waypoint 1"), "{msg}");
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [10, 5, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(
        msg.contains("turn at waypoint 1") && msg.contains("120"),
        "{msg}"
    );
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 5, 5], [0, 5, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(
        msg.contains("leg 1") && msg.contains("turn_radius"),
        "{msg}"
    );
    let (key, _) = invalid_key(&waypoints_with("[[0, 0, 5]]", "speed = 0.5\n"));
    assert_eq!(key, "trajectory.points");
    let (key, _) = invalid_key(&waypoints_with("[[0, 0, 5], [9, 0, 5]]", "speed = 0\n"));
    assert_eq!(key, "trajectory.speed");
    let (key, _) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [9, 0, 5]]",
        "speed = 1\nturn_radius = -2\n",
    ));
    assert_eq!(key, "trajectory.turn_radius");
    // More than 32 points: the TOML error says the limit; a missing speed names the field.
    let many: Vec<String> = (0..33).map(|i| format!("[{}, 0, 5]", 10 * i)).collect();
    let msg = toml_error(&waypoints_with(
        &format!("[{}]", many.join(", ")),
        "speed = 1\n",
    ));
    assert!(msg.contains("more than 32 waypoints"), "{msg}");
    let msg = toml_error(&waypoints_with("[[0, 0, 5], [9, 0, 5]]", ""));
    assert!(msg.contains("missing field `speed`"), "{msg}");
    let msg = toml_error(&waypoints_with(
        "[[0, 0, 5], [9, 0, 5]]",
        "speed = 1\nradius = 3\n",
    ));
    assert!(msg.contains("unknown field `radius`"), "{msg}");
}

#[test]
fn a_pinned_speed_profile_parses_and_its_errors_name_speeds() {
    let three = "[[0, 0, 5], [80, 0, 5], [80, 60, 5]]";
    let s = parse_scenario(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [1.2, 0.5, 1.0]\nspeed_change = 0.04\n",
    ))
    .expect("valid");
    assert!(s.trajectory().time_law().is_set());
    let (key, msg) = invalid_key(&waypoints_with(three, "speed = 0.5\nspeeds = [1.2, 0.5]\n"));
    assert_eq!(key, "trajectory.speeds");
    assert!(msg.contains("2 speeds") && msg.contains("3 parts"), "{msg}");
    let (key, _) = invalid_key(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [1.2, 0.5, 1.0]\nspeed_change = 0\n",
    ));
    assert_eq!(key, "trajectory.speed_change");
    // A 6 m/s leg needs ≈ 1 000 m to slow to 0.5 at 0.04 m/s²: the 80 m leg cannot.
    let (key, msg) = invalid_key(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [6, 0.5, 1.0]\nspeed_change = 0.04\n",
    ));
    assert_eq!(key, "trajectory.speeds");
    assert!(msg.contains("part 0"), "{msg}");
}

/// `trajectory.speed_limits` (Choice 161): one cap per leg, each in (0, MAX_SPEED]; a wrong
/// count, a bad value (naming its leg) or a closed-form kind is refused under the key.
#[test]
fn speed_limits_are_one_cap_per_leg_and_refused_by_key_and_leg() {
    let points = "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]";
    let ok = parse_scenario(&waypoints_with(
        points,
        "speed = 0.5\nspeed_limits = [1.5, 0.75]\n",
    ))
    .expect("valid");
    assert_eq!(ok.config().speed_limits, Some(vec![1.5, 0.75]));
    let refused = |extra: &str, leg_text: &str| {
        let e = parse_scenario(&waypoints_with(points, &format!("speed = 0.5\n{extra}")))
            .expect_err(extra);
        match &e {
            ScenarioError::Invalid { key, message } => {
                assert_eq!(key, "trajectory.speed_limits", "{e}");
                assert!(message.contains(leg_text), "{extra}: {e}");
            }
            other => panic!("{extra}: {other}"),
        }
    };
    refused("speed_limits = [1.0]", "(2 for 3 points), got 1");
    refused("speed_limits = [1.0, 1.0, 1.0]", "got 3");
    refused("speed_limits = [1.0, 0.0]", "leg 1");
    refused("speed_limits = [-1.0, 1.0]", "leg 0");
    refused("speed_limits = [1.0, 10.5]", "leg 1");
    refused("speed_limits = [nan, 1.0]", "leg 0");
    refused("speed_limits = [1.0, inf]", "leg 1");
    // Not a waypoint mission: the key is not used.
    let e = parse_scenario(
        "name = \"c\"\n[trajectory]\nkind = \"circle\"\nradius = 10\nspeed_limits = [1.0]\n",
    )
    .expect_err("circle");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, .. } if key == "trajectory.speed_limits"),
        "{e}"
    );
}

/// `link_faults.lose_upload_chunks` (Choice 166): chunks of a waypoint mission's upload; a
/// closed-form mission (nothing uploaded) or a chunk past the upload's last is refused under
/// the key.
#[test]
fn lost_upload_chunks_are_a_waypoint_missions_and_within_its_upload() {
    let points = "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]";
    let with = |faults: &str| {
        parse_scenario(&format!(
            "{}[link_faults]\n{faults}\n",
            waypoints_with(points, "speed = 0.5\n")
        ))
    };
    let ok = with("lose_upload_chunks = [0]").expect("valid");
    assert_eq!(ok.config().link_faults.lose_upload_chunks, vec![0]);
    // Three points are 9 words: one chunk, so chunk 1 does not exist.
    let e = with("lose_upload_chunks = [1]").expect_err("chunk 1");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, message }
            if key == "link_faults.lose_upload_chunks" && message.contains("1 chunks")),
        "{e}"
    );
    let e = parse_scenario(
        "name = \"c\"\n[trajectory]\nkind = \"circle\"\nradius = 10\n[link_faults]\nlose_upload_chunks = [0]\n",
    )
    .expect_err("circle");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, .. } if key == "link_faults.lose_upload_chunks"),
        "{e}"
    );
}
