//! The speed profile of a waypoint mission (docs/missions.md#the-speed-profile): `check`'s proposal beats the
//! uniform time scale, and flown as pinned it stays within the real vehicle's bound.

use controller_core::trajectory::SpeedList;
use controller_core::TrajectoryKind;
use host_sim::scenario::real_vehicle;
use host_sim::sim::{self, bound};
use host_sim::studies::preflight::{self, profile, Verdict, DEFAULT_MARGIN};

/// The shipped survey's vehicle on a short path: a 90 m leg, a 90° turn, a 20 m leg, a 90° turn,
/// a 90 m leg back (constant speed 0.5 m/s; three legs and two turns), told the exact state:
/// the force's search (steps 1–3 of the profile) alone decides it.
fn short_survey() -> host_sim::scenario::Scenario {
    navigated_short_survey()
        .with(|c| c.navigation = None)
        .unwrap()
}

/// [`short_survey`] on the navigation the survey ships with (survey-grade, filtered): the
/// path-error budget and the chatter term join the search (step 4, Choice 543).
fn navigated_short_survey() -> host_sim::scenario::Scenario {
    let base = real_vehicle::waypoint_scenarios().unwrap().remove(0);
    base.with(|c| {
        let points = controller_core::WaypointList::new(&[
            [0.0, 0.0, 5.0],
            [90.0, 0.0, 5.0],
            [90.0, 20.0, 5.0],
            [0.0, 20.0, 5.0],
        ])
        .unwrap();
        c.trajectory = TrajectoryKind::Waypoints {
            points,
            speed: 0.5,
            turn_radius: None,
            speeds: None,
            speed_change: None,
        };
        c.duration = 400.0;
    })
    .unwrap()
}

/// `s` with the profile `p` pinned (its speeds, speed change and duration).
fn pinned(
    s: &host_sim::scenario::Scenario,
    p: &profile::SpeedProfile,
) -> host_sim::scenario::Scenario {
    let speeds: Vec<f32> = p.speeds.iter().map(|&v| v as f32).collect();
    s.with(|c| {
        if let TrajectoryKind::Waypoints {
            speeds: ref mut sp,
            speed_change: ref mut a,
            ..
        } = c.trajectory
        {
            *sp = Some(SpeedList::new(&speeds).unwrap());
            *a = Some(p.speed_change as f32);
        }
        c.duration = p.total_time;
    })
    .unwrap()
}

/// Choice 543: on its navigation, the profile the thrusters allow is one the path-error budget
/// refuses (the check as written calls it INFEASIBLE, which is what `check` printed to pin
/// before); the proposal caps the parts the budget limits, names it, and its own check calls
/// the pinned mission FEASIBLE.
#[test]
fn on_its_navigation_the_profile_is_one_its_own_check_calls_feasible() {
    let force_only = profile::propose(&short_survey(), DEFAULT_MARGIN)
        .unwrap()
        .expect("a waypoint mission");
    let s = navigated_short_survey();
    let before = preflight::check_as_written(&pinned(&s, &force_only), DEFAULT_MARGIN).unwrap();
    assert_ne!(before.verdict, Verdict::Feasible, "{before}");
    let p = profile::propose(&s, DEFAULT_MARGIN)
        .unwrap()
        .expect("a waypoint mission");
    assert!(
        p.parts.iter().any(|t| t.limiting == profile::BUDGET),
        "{p:?}"
    );
    // Only lowered: no part faster than the force allows.
    for (v, f) in p.speeds.iter().zip(&force_only.speeds) {
        assert!(v <= f, "{p:?} vs {force_only:?}");
    }
    let after = preflight::check_as_written(&pinned(&s, &p), DEFAULT_MARGIN).unwrap();
    assert_eq!(after.verdict, Verdict::Feasible, "{after}");
}

#[test]
fn the_profile_beats_the_uniform_scale_and_flies_within_the_bound() {
    let s = short_survey();
    let p = profile::propose(&s, DEFAULT_MARGIN)
        .unwrap()
        .expect("a waypoint mission");
    assert_eq!(p.speeds.len(), 5);
    // Legs faster than turns, and faster than the slowest part (the uniform speed).
    assert!(
        p.speeds[0] > p.speeds[1] && p.speeds[4] > p.speeds[3],
        "{:?}",
        p.speeds
    );
    assert!(p.total_time < p.uniform_time, "{p:?}");
    // The times add up to the total (each part's from the flown law).
    let sum: f64 = p.parts.iter().map(|t| t.time).sum();
    assert!(
        (sum - p.total_time).abs() < 1e-3 * p.total_time,
        "{sum} vs {}",
        p.total_time
    );
    // Flown as pinned: within the real vehicle's bound.
    let pinned = pinned(&s, &p);
    let run = sim::run(&pinned);
    assert!(bound::within_bound(&run), "{:?}", run.metrics);
    assert!(!run.missed(), "{}", run.outcome);
}

/// Two legs (40 m, 20 m) and one 90° turn, no payload: small enough for three proposals in a
/// test.
fn one_turn(caps: Option<Vec<f64>>) -> host_sim::scenario::Scenario {
    short_survey()
        .with(|c| {
            c.trajectory = TrajectoryKind::Waypoints {
                points: controller_core::WaypointList::new(&[
                    [0.0, 0.0, 5.0],
                    [40.0, 0.0, 5.0],
                    [40.0, 20.0, 5.0],
                ])
                .unwrap(),
                speed: 0.5,
                turn_radius: None,
                speeds: None,
                speed_change: None,
            };
            c.duration = 150.0;
            c.speed_limits = caps;
            // No payload: the check as flown passes without the 3 % rounds (the cap exact).
            c.variation = host_sim::plant::VariationProfile::None;
        })
        .unwrap()
}

/// Choice 161: a cap below a leg's free speed is the leg's speed (rounded down to the profile's
/// 0.01 m/s) and named as its limit; a cap above the free speed changes nothing at all.
#[test]
fn a_leg_cap_bounds_its_leg_and_a_loose_cap_changes_nothing() {
    let propose = |caps| {
        profile::propose(&one_turn(caps), DEFAULT_MARGIN)
            .unwrap()
            .expect("a waypoint mission")
    };
    let free = propose(None);
    assert_eq!(free.speeds.len(), 3, "{free:?}");
    assert!(free.parts.iter().all(|p| p.limiting != profile::CAP));
    // The free leg 0 is well above the cap below (2.11 m/s on the survey's legs, Choice 158).
    assert!(free.speeds[0] > 1.2, "{free:?}");

    // A cap of 0.987 m/s on leg 0 only: leg 0 at 0.98, the rest as free (their own searches).
    let capped = propose(Some(vec![
        0.987,
        f64::from(controller_core::trajectory::MAX_SPEED),
    ]));
    assert_eq!(capped.shrink_rounds, 0, "{capped:?}");
    assert_eq!(capped.speeds[0], 0.98, "{capped:?}");
    assert_eq!(capped.parts[0].limiting, profile::CAP);
    assert_ne!(capped.parts[2].limiting, profile::CAP);
    assert!(capped.speeds[2] <= free.speeds[2]);
    // Slower on leg 0, so the mission takes longer.
    assert!(
        capped.total_time > free.total_time,
        "{capped:?} vs {free:?}"
    );

    // Caps above the free speeds (the largest speed allowed, which no leg holds): the same
    // proposal, byte for byte.
    let max = f64::from(controller_core::trajectory::MAX_SPEED);
    let loose = propose(Some(vec![max, max]));
    assert_eq!(
        serde_json::to_string(&loose).unwrap(),
        serde_json::to_string(&free).unwrap()
    );
}

/// The files `host-sim run` leaves in `out` for `scenario` (a TOML text), with the run's name
/// replaced by `NAME`.
fn run_files(
    scenario: &str,
    name: &str,
    out: &std::path::Path,
) -> std::collections::BTreeSet<String> {
    std::fs::create_dir_all(out).unwrap();
    let file = out.with_extension("toml");
    std::fs::write(&file, scenario).unwrap();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["run", "--scenario"])
        .arg(&file)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    std::fs::read_dir(out)
        .unwrap()
        .map(|e| {
            e.unwrap()
                .file_name()
                .to_string_lossy()
                .replace(name, "NAME")
        })
        .collect()
}

/// Choices 162 and 170: `run` draws a waypoint mission's speed over time and its path over the
/// waypoints (PNGs, in the manifest) and nothing more; a closed-form mission gets neither, and
/// the other files are the same.
#[test]
fn run_plots_the_speed_of_a_waypoint_mission_only() {
    let dir = std::env::temp_dir().join(format!("host-sim-speed-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let waypoints = run_files(
        "name = \"wp\"\nduration = 10.0\n[trajectory]\nkind = \"waypoints\"\n\
         points = [[0, 0, 5], [20, 0, 5], [20, 10, 5]]\nspeed = 0.5\nspeed_limits = [0.4, 0.3]\n",
        "wp",
        &dir.join("wp"),
    );
    let png = std::fs::read(dir.join("wp/wp-speed.png")).expect("the speed plot");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let manifest =
        std::fs::read_to_string(dir.join("wp").join(host_sim::output::dir::MANIFEST)).unwrap();
    assert!(manifest.lines().any(|l| l == "wp-speed.png"), "{manifest}");
    let circle = run_files(
        "name = \"ci\"\nduration = 10.0\n[trajectory]\nkind = \"circle\"\nradius = 10.0\n",
        "ci",
        &dir.join("ci"),
    );
    assert!(!circle.iter().any(|f| f.contains("speed")), "{circle:?}");
    let mut others = waypoints.clone();
    assert!(others.remove("NAME-speed.png"), "{waypoints:?}");
    // And its path over the waypoints (Choice 170), in the manifest too.
    assert!(others.remove("NAME-waypoints.png"), "{waypoints:?}");
    assert!(
        manifest.lines().any(|l| l == "wp-waypoints.png"),
        "{manifest}"
    );
    assert_eq!(others, circle);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A bad cap stops `check` with exit 2 and names the key and the leg (Choice 161).
#[test]
fn check_refuses_a_bad_cap_with_exit_2() {
    let dir = std::env::temp_dir().join(format!("host-sim-cap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad.toml");
    std::fs::write(
        &file,
        "[trajectory]\nkind = \"waypoints\"\npoints = [[0, 0, 5], [20, 0, 5], [20, 10, 5]]\n\
         speed = 0.5\nspeed_limits = [0.4, -1]\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["check", "--scenario"])
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("trajectory.speed_limits") && err.contains("leg 1"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two 150 m legs joined by a 20 m one between two 90° turns (6.7 m of straight between their
/// blends), no payload, no caps.
fn short_leg_between_turns() -> host_sim::scenario::Scenario {
    one_turn(None)
        .with(|c| {
            if let TrajectoryKind::Waypoints { ref mut points, .. } = c.trajectory {
                *points = controller_core::WaypointList::new(&[
                    [0.0, 0.0, 5.0],
                    [150.0, 0.0, 5.0],
                    [150.0, 20.0, 5.0],
                    [0.0, 20.0, 5.0],
                ])
                .unwrap();
            }
            c.duration = 700.0;
        })
        .unwrap()
}

/// Choice 171 (a regression: it read the thruster of its search, or `cap` with caps): a short
/// leg between two turns, with no `speed_limits`, is slowed by the room for its speed changes
/// and is labelled `changes`. Its speed is the fastest whose two changes, each
/// (v + v_turn)/2 · (15/8)|v − v_turn|/A long (Choice 156's closed form), fit in it.
#[test]
fn a_short_leg_between_two_turns_is_limited_by_its_speed_changes() {
    let s = short_leg_between_turns();
    let p = profile::propose(&s, DEFAULT_MARGIN)
        .unwrap()
        .expect("a waypoint mission");
    assert_eq!(p.speeds.len(), 5, "{p:?}");
    assert_eq!(p.parts[2].limiting, profile::CHANGES, "{p:?}");
    // The long legs reach their thruster's limit, and are labelled by it.
    for leg in [0, 4] {
        assert!(
            controller_core::effectiveness::THRUSTER_NAMES
                .contains(&p.parts[leg].limiting.as_str()),
            "{p:?}"
        );
        assert!(p.speeds[leg] > 1.5 * p.speeds[2], "{p:?}");
    }
    let a = p.speed_change;
    let change = |v: f64, w: f64| 0.5 * (v + w) * 15.0 / 8.0 * (v - w).abs() / a;
    let need = |v: f64| change(v, p.speeds[1]) + change(v, p.speeds[3]);
    let length = p.parts[2].length;
    assert!(length < 7.0, "{p:?}");
    assert!(
        need(p.speeds[2]) <= length,
        "{} > {length}",
        need(p.speeds[2])
    );
    assert!(
        need(p.speeds[2] + 0.02) > length,
        "{} ≤ {length}",
        need(p.speeds[2] + 0.02)
    );
}

/// Choice 172: `check --json` on a waypoint mission prints the proposed profile (parts,
/// speeds, times, limits, total and uniform time) under `speed_profile`, beside the check's
/// own keys; a closed-form mission has no `speed_profile`.
#[test]
fn check_json_prints_the_speed_profile_of_a_waypoint_mission() {
    let dir = std::env::temp_dir().join(format!("host-sim-check-json-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The real vehicle without payload, trimmed (untrimmed, the parameter box is statically
    // infeasible on it).
    let vehicle = "ideal_actuators = false\n[variation]\nprofile = \"none\"\ntrimmed = true\n\
                   [controller]\n\
                   thrust_unit = \"kgf\"\n\
                   reversed_thrusters = [\"vert fore\", \"horz fore\", \"horz aft\"]\n";
    let check = |name: &str, trajectory: &str| -> serde_json::Value {
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(
            &file,
            format!("name = \"{name}\"\nduration = 100.0\n{vehicle}{trajectory}"),
        )
        .unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
            .args(["check", "--json", "--scenario"])
            .arg(&file)
            .output()
            .unwrap();
        assert!(
            matches!(out.status.code(), Some(0 | 1)),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
    };
    let v = check(
        "wp",
        "[trajectory]\nkind = \"waypoints\"\npoints = [[0, 0, 5], [40, 0, 5], [40, 20, 5]]\n\
         speed = 0.5\n",
    );
    assert_eq!(v["name"], "wp");
    assert!(v["verdict"].is_string() && v["thrusters"].is_array(), "{v}");
    let p = &v["speed_profile"];
    let parts = p["parts"].as_array().expect("the profile's parts");
    let names: Vec<&str> = parts.iter().map(|x| x["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["leg 0", "turn at 1", "leg 1"]);
    let speeds = p["speeds"].as_array().unwrap();
    assert_eq!(speeds.len(), 3);
    let mut sum = 0.0;
    for (part, speed) in parts.iter().zip(speeds) {
        assert_eq!(part["speed"], *speed);
        assert!(part["limiting"].is_string() && part["length"].as_f64().unwrap() > 0.0);
        sum += part["time"].as_f64().unwrap();
    }
    let total = p["total_time"].as_f64().unwrap();
    assert!((sum - total).abs() < 1e-3 * total, "{sum} vs {total}");
    // The turn is the slowest part, so one speed for the whole path takes longer.
    assert!(p["uniform_time"].as_f64().unwrap() > total, "{p}");
    // The uniform speed is the turn's before the profile's rounding down to 0.01 m/s.
    let (uniform, turn) = (
        p["uniform_speed"].as_f64().unwrap(),
        speeds[1].as_f64().unwrap(),
    );
    assert!(uniform >= turn && uniform < turn + 0.01, "{p}");
    let circle = check("ci", "[trajectory]\nkind = \"circle\"\nradius = 10.0\n");
    assert!(circle["verdict"].is_string(), "{circle}");
    assert!(circle.get("speed_profile").is_none(), "{circle}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The pixels of `colour` in a PNG.
fn pixels_of(file: &std::path::Path, colour: [u8; 3]) -> usize {
    let decoder = png::Decoder::new(std::fs::File::open(file).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", file.display());
    buf[..info.buffer_size()]
        .chunks_exact(3)
        .filter(|p| *p == colour)
        .count()
}

/// Choice 170: the path over the waypoints marks each waypoint (in the plan view, the zoom on
/// a corner, and the depth profile when the depth changes, each a filled dot in the waypoints'
/// own colour): a mission that changes depth shows its waypoints in one more panel than the
/// same mission at one depth.
#[test]
fn the_waypoint_plot_marks_the_waypoints_and_adds_the_depth_when_it_changes() {
    use host_sim::output::waypoint_plot::{plot_waypoint_path, C_WAYPOINT};
    let dir = std::env::temp_dir().join(format!("host-sim-wp-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let marks = |name: &str, depth: f32| -> usize {
        let s = one_turn(None)
            .with(|c| {
                c.name = name.to_string();
                c.duration = 20.0;
                if let TrajectoryKind::Waypoints { ref mut points, .. } = c.trajectory {
                    *points = controller_core::WaypointList::new(&[
                        [0.0, 0.0, 5.0],
                        [40.0, 0.0, 5.0],
                        [40.0, 20.0, depth],
                    ])
                    .unwrap();
                }
            })
            .unwrap();
        let run = sim::run(&s);
        let file = plot_waypoint_path(&dir, &s, &run).unwrap().expect("a plot");
        assert_eq!(file, dir.join(format!("{name}-waypoints.png")));
        let c = C_WAYPOINT;
        pixels_of(&file, [c.0, c.1, c.2])
    };
    let flat = marks("flat", 5.0);
    let descending = marks("descending", 8.0);
    // Five dots at one depth (three waypoints, the zoom's one, the legend's): a dot of radius 3
    // is at least 20 pixels.
    assert!(flat >= 5 * 20, "{flat}");
    // Three more in the depth profile.
    assert!(descending >= flat + 3 * 20, "{descending} vs {flat}");
    // A closed-form mission has no waypoint plot.
    let circle = short_survey()
        .with(|c| {
            c.trajectory = controller_core::Table1Case::Circular10R.kind();
            c.duration = 1.0;
        })
        .unwrap();
    let run = sim::run(&circle);
    assert_eq!(plot_waypoint_path(&dir, &circle, &run).unwrap(), None);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Choice 175 (a regression: `check` exited 2 with "the profiled mission: tangent heading needs
/// a horizontal speed of at least 0.02 m/s"): a waypoint mission whose box cannot be held even
/// at rest (the real vehicle with its payload untrimmed) has no speed profile. `propose` names
/// the part and the thruster, and `check` prints the verdict, says so, and exits 1
/// (infeasible), not 2.
#[test]
fn a_mission_the_box_cannot_hold_at_rest_has_no_profile_and_check_says_infeasible() {
    // The shipped survey's vehicle (Table-3 payload) on one_turn's path, untrimmed.
    let path = one_turn(None).config().trajectory;
    let untrimmed = short_survey()
        .with(|c| {
            c.trajectory = path;
            c.duration = 150.0;
            c.trimmed = false;
        })
        .unwrap();
    match profile::propose(&untrimmed, DEFAULT_MARGIN) {
        Err(host_sim::studies::preflight::CheckError::NoProfile { part, thruster }) => {
            assert_eq!(part, "leg 0");
            assert!(!thruster.is_empty());
        }
        other => panic!("expected no profile, got {other:?}"),
    }
    let dir = std::env::temp_dir().join(format!("host-sim-noprofile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("untrimmed.toml");
    std::fs::write(
        &file,
        "name = \"untrimmed\"\nduration = 150\nideal_actuators = false\n\
         [trajectory]\nkind = \"waypoints\"\npoints = [[0, 0, 5], [40, 0, 5], [40, 20, 5]]\n\
         speed = 0.5\n[variation]\nprofile = \"table3-staircase\"\ntrimmed = false\n\
         [controller]\nthrust_unit = \"kgf\"\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["check", "--scenario"])
        .arg(&file)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("INFEASIBLE"), "{text}");
    assert!(text.contains("no speed profile: leg 0"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}
