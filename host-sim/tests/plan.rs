//! QGroundControl `.plan` import and export (docs/missions.md#plans-from-qgroundcontrol): geodetic → NED against known
//! lengths of a degree, the round trip, the errors, and the shipped example as a scenario.

use host_sim::scenario::plan::{self, Origin};
use host_sim::scenario::{parse_scenario, ScenarioFile};
use std::path::Path;
use std::process::Command;

#[test]
fn geodetic_to_ned_matches_the_known_lengths_of_a_degree() {
    // On the equator a degree of longitude is a·π/180 = 111 319.491 m (WGS-84 a).
    let o = Origin {
        lat: 0.0,
        lon: 0.0,
        alt: 0.0,
    };
    let p = o.to_ned(0.0, 0.01, -5.0);
    assert!(
        (p[1] - 1113.19491).abs() < 1e-4 && p[0].abs() < 1e-9,
        "{p:?}"
    );
    assert_eq!(p[2], 5.0, "5 m below the origin is 5 m down");
    // At 45° a degree of latitude is 111 131.75 m (the meridian arc from 44.5° to 45.5°);
    // 0.01° across 45°.
    let o = Origin {
        lat: 44.995,
        lon: 10.0,
        alt: 0.0,
    };
    let p = o.to_ned(45.005, 10.0, 0.0);
    assert!((p[0] - 1111.3175).abs() < 0.01, "{p:?}");
}

#[test]
fn import_export_import_returns_the_same_points() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/plans/harbour-wall.plan"),
    )
    .unwrap();
    let (origin, points) = plan::import(&text).unwrap();
    assert_eq!(points.len(), 6);
    // The example was written from these NED points (to 1e-9° ≈ 0.1 mm).
    let want = [
        [0.0, 0.0, 3.0],
        [60.0, 20.0, 3.0],
        [120.0, 40.0, 6.0],
        [160.0, 90.0, 8.0],
        [160.0, 150.0, 8.0],
        [120.0, 190.0, 8.0],
    ];
    for (p, w) in points.iter().zip(want) {
        for c in 0..3 {
            assert!((p[c] - w[c]).abs() < 2e-4, "{p:?} vs {w:?}");
        }
    }
    let (o2, again) = plan::import(&plan::export(&origin, &points)).unwrap();
    assert_eq!(o2, origin);
    for (a, b) in again.iter().zip(&points) {
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 1e-6, "{a:?} vs {b:?}");
        }
    }
    // The GeoJSON of the path: [lon, lat, alt] per point.
    let g: serde_json::Value =
        serde_json::from_str(&plan::geojson_line(&origin, "wall", &points)).unwrap();
    let c = &g["geometry"]["coordinates"];
    assert_eq!(c.as_array().unwrap().len(), 6);
    assert_eq!(c[0][0].as_f64(), Some(origin.lon));
    assert_eq!(c[0][2].as_f64(), Some(-3.0));
}

#[test]
fn a_plan_with_other_items_is_refused_naming_the_item() {
    let text = r#"{"fileType": "Plan", "mission": {"plannedHomePosition": [1, 2, 0], "items": [
        {"type": "SimpleItem", "command": 16, "frame": 3, "params": [0, 0, 0, null, 1.0, 2.0, -3]},
        {"type": "SimpleItem", "command": 22, "frame": 3, "params": [0, 0, 0, null, 1.0, 2.0, 10]}]}}"#;
    let e = plan::import(text).unwrap_err().to_string();
    assert!(e.contains("mission.items[1]") && e.contains("22"), "{e}");
    let e = plan::import(r#"{"fileType": "Mission"}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("fileType"), "{e}");
}

/// A survey pattern (a `ComplexItem`, which has no command) used to be refused as
/// `this is "ComplexItem" command null`: it is named for what it is.
#[test]
fn a_complex_item_is_refused_for_what_it_is() {
    let e = plan::import(&plan_text(
        [43.0, 5.0, 0.0],
        &[
            waypoint(43.0, 5.0, -3.0, 3),
            r#"{"type": "ComplexItem", "complexItemType": "survey"}"#.into(),
        ],
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("mission.items[1]") && e.contains("ComplexItem (\"survey\""),
        "{e}"
    );
    assert!(!e.contains("null"), "{e}");
}

#[test]
fn the_shipped_plan_imports_as_a_valid_waypoint_scenario() {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["import-plan", "--speed", "0.4"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/plans/harbour-wall.plan"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = parse_scenario(&String::from_utf8(out.stdout).unwrap()).expect("a valid scenario");
    assert!(s.trajectory().route().length() > 300.0);
    // A file that is not a plan: exit 2, naming the file.
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["import-plan"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/real/survey-200x100.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("survey-200x100.toml"));
}

/// The imported plan flown (`run`, 40 s): the flown path is written as GeoJSON around the
/// plan's home, starting on the first waypoint; a bad origin names `trajectory.origin`.
#[test]
fn a_run_with_an_origin_writes_the_flown_path_as_geojson() {
    let dir = std::env::temp_dir().join(format!("host-sim-plan-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["import-plan", "--speed", "0.4", "--name", "wall"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/plans/harbour-wall.plan"))
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let scenario = dir.join("wall.toml");
    std::fs::write(&scenario, format!("duration = 40.0\n{text}")).unwrap();
    let run_dir = dir.join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["run", "--scenario"])
        .arg(&scenario)
        .arg("--out")
        .arg(&run_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let g: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("wall-flown.geojson")).unwrap())
            .unwrap();
    let c = g["geometry"]["coordinates"].as_array().unwrap();
    assert!(c.len() > 10);
    // The first waypoint is the plan's home, 3 m deep: [lon, lat, alt].
    let first = &c[0];
    assert!((first[0].as_f64().unwrap() - 5.362).abs() < 1e-6, "{first}");
    assert!(
        (first[1].as_f64().unwrap() - 43.295).abs() < 1e-6,
        "{first}"
    );
    assert!((first[2].as_f64().unwrap() + 3.0).abs() < 0.01, "{first}");
    let bad = text.replace("origin = [43.295", "origin = [143.295");
    match parse_scenario(&bad) {
        Err(host_sim::scenario::ScenarioError::Invalid { key, .. }) => {
            assert_eq!(key, "trajectory.origin")
        }
        other => panic!("{other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The shipped pipeline mission (docs/missions.md#the-shipped-waypoint-missions, Choice 174) is its plan, imported:
/// `import-plan` on the shipped `.plan` gives exactly the shipped scenario's points and origin
/// (so the two cannot drift apart), and those are the plan's geodetic points in the tangent
/// plane to the 3 decimals the import prints.
#[test]
fn the_shipped_pipeline_is_its_plan_imported() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["import-plan", "--speed", "0.5", "--name", "real-pipeline"])
        .arg(dir.join("plans/pipeline.plan"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let imported = parse_scenario(&String::from_utf8(out.stdout).unwrap()).unwrap();
    let shipped = host_sim::scenario::load_scenario(&dir.join("real/pipeline.toml")).unwrap();
    let waypoints = |s: &host_sim::scenario::Scenario| match &s.config().trajectory {
        controller_core::TrajectoryKind::Waypoints { points, speed, .. } => {
            (points.as_slice().to_vec(), *speed)
        }
        other => panic!("not a waypoint mission: {other:?}"),
    };
    let (points, speed) = waypoints(&shipped);
    assert_eq!((points.clone(), speed), waypoints(&imported));
    assert_eq!(shipped.config().origin, imported.config().origin);
    assert_eq!(shipped.config().name, imported.config().name);
    // Against the plan read directly: the same points to the printed millimetre.
    let text = std::fs::read_to_string(dir.join("plans/pipeline.plan")).unwrap();
    let (origin, raw) = plan::import(&text).unwrap();
    assert_eq!(
        shipped.config().origin,
        Some([origin.lat, origin.lon, origin.alt])
    );
    assert_eq!(raw.len(), points.len());
    for (p, r) in points.iter().zip(&raw) {
        for c in 0..3 {
            assert!((f64::from(p[c]) - r[c]).abs() <= 5.1e-4, "{p:?} vs {r:?}");
        }
        // Within 400 m of the home: the flat earth is good to d²/R < 3 cm there (Choice 159).
        assert!(r[0].hypot(r[1]) < 400.0, "{r:?}");
    }
}

/// `host-sim import-plan <plan> <args…>`.
fn import_plan(plan: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("import-plan")
        .arg(plan)
        .args(args)
        .output()
        .unwrap()
}

/// `import-plan` on a plan file named `file_name` holding `text`, in a scratch folder.
fn import_plan_named(file_name: &str, text: &str) -> std::process::Output {
    let dir = std::env::temp_dir().join(format!("host-sim-plan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plan = dir.join(file_name);
    std::fs::write(&plan, text).unwrap();
    let out = import_plan(&plan, &[]);
    let _ = std::fs::remove_file(&plan);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `import-plan <args…>` on a plan file named `file_name` holding `text`, in a scratch folder
/// of its own (the run test above removes the other one); whatever the exit.
fn import_plan_text(file_name: &str, text: &str, args: &[&str]) -> std::process::Output {
    let dir = std::env::temp_dir().join(format!("host-sim-plan-text-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plan = dir.join(file_name);
    std::fs::write(&plan, text).unwrap();
    let out = import_plan(&plan, args);
    let _ = std::fs::remove_file(&plan);
    out
}

/// A `.plan` text: the home [lat, lon, alt] and the items' JSON.
fn plan_text(home: [f64; 3], items: &[String]) -> String {
    format!(
        r#"{{"fileType": "Plan", "mission": {{"plannedHomePosition": [{}, {}, {}], "items": [{}]}}}}"#,
        home[0],
        home[1],
        home[2],
        items.join(", ")
    )
}

/// A waypoint item at (lat, lon, alt) in MAV_FRAME `frame`.
fn waypoint(lat: f64, lon: f64, alt: f64, frame: u32) -> String {
    format!(
        r#"{{"type": "SimpleItem", "command": 16, "frame": {frame}, "params": [0, 0, 0, null, {lat}, {lon}, {alt}]}}"#
    )
}

fn harbour_wall() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/plans/harbour-wall.plan")
}

/// A `--speed` the scenario would refuse (NaN, ∞, 0, negative, 1e308, or beyond the core's
/// 10 m/s) used to be written as given, exit 0 (NaN is not TOML; 1e308 printed 309 digits):
/// it is refused, exit 2, naming the flag and the value as written.
#[test]
fn import_plan_refuses_a_speed_the_scenario_would_refuse_naming_the_flag() {
    for speed in ["nan", "inf", "0", "-1", "1e308", "1e-300", "10.5"] {
        let out = import_plan(&harbour_wall(), &[&format!("--speed={speed}")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--speed {speed}: {err}");
        assert!(err.contains("--speed"), "{err}");
        assert!(out.stdout.is_empty(), "--speed {speed}");
    }
    // At 10 m/s the default corners (R = v²/0.1 m/s² = 1 km) do not fit this plan's legs: the
    // scenario would refuse it, and the import says so, naming the plan's items.
    let out = import_plan(&harbour_wall(), &["--speed", "10"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the leg from mission.items[") && err.contains("--speed 10"),
        "{err}"
    );
    // The largest speed is taken on a plan without corners, and read back as itself.
    let out = import_plan_text(
        "straight.plan",
        &plan_text(
            [43.0, 5.0, 0.0],
            &[waypoint(43.0, 5.0, -3.0, 3), waypoint(43.01, 5.0, -3.0, 3)],
        ),
        &["--speed", "10"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = ScenarioFile::from_toml(&String::from_utf8(out.stdout).unwrap()).unwrap();
    assert!(matches!(
        file.trajectory.path,
        controller_core::TrajectoryKind::Waypoints { speed: 10.0, .. }
    ));
}

/// A `--name` is data: with a quote it used to break the file; with a newline it injected
/// `[controller] k1 = …`. A quote is written escaped and reads back as the name; a newline (not
/// a file name) is refused, exit 2, naming the flag.
#[test]
fn import_plan_writes_a_name_as_data_and_refuses_one_that_is_no_file_name() {
    let name = "wall \"north\" 'b'";
    let out = import_plan(&harbour_wall(), &["--name", name]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = parse_scenario(&String::from_utf8(out.stdout).unwrap()).unwrap();
    assert_eq!(s.config().name, name);
    let out = import_plan(&harbour_wall(), &["--name", "x\n[controller]\nk1 = 1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--name"), "{err}");
}

/// A plan file named `w\nduration = 1 #.plan` made `run` fly 1 s: the name went into the
/// header comment unescaped, and its second line was a key. Now the header escapes it and the
/// scenario has no `duration` (the default: a waypoint mission's path time, Choice 312).
#[test]
fn import_plan_writes_the_plans_file_name_into_a_comment_that_cannot_end_early() {
    let wall = std::fs::read_to_string(harbour_wall()).unwrap();
    let out = import_plan_named("w\nduration = 1 #.plan", &wall);
    let text = String::from_utf8(out.stdout).unwrap();
    let s = parse_scenario(&text).unwrap();
    let default = host_sim::scenario::path_time::path_time(s.trajectory()).unwrap();
    assert_eq!(s.config().duration, default, "{text}");
    assert!(text.contains("w\\nduration = 1 #.plan"), "{text}");
}

/// A plan whose home is 10³⁰⁰ m up used to print its altitude as 301 digits in the header and
/// in `origin`: every number is written readable (`1e300`) and reads back as itself.
#[test]
fn import_plan_writes_huge_numbers_readable() {
    // Above mean sea level (frame 0), as high as the home: 0 m down.
    let item = |lat: f64| {
        format!(
            r#"{{"type": "SimpleItem", "command": 16, "frame": 0, "params": [0, 0, 0, null, {lat}, 5.0, 1e300]}}"#
        )
    };
    let out = import_plan_named(
        "high.plan",
        &format!(
            r#"{{"fileType": "Plan", "mission": {{"plannedHomePosition": [43.0, 5.0, 1e300],
            "items": [{}, {}]}}}}"#,
            item(43.0),
            item(43.001)
        ),
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().all(|l| l.len() < 200), "{text}");
    assert!(text.contains("alt 1e300 m"), "{text}");
    let file = ScenarioFile::from_toml(&text).unwrap();
    assert_eq!(file.trajectory.origin, Some([43.0, 5.0, 1e300]), "{text}");
}

/// The waypoints of `import-plan`'s output (NED, m) and its origin.
fn imported(out: &std::process::Output) -> (Vec<[f32; 3]>, [f64; 3]) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = parse_scenario(&String::from_utf8_lossy(&out.stdout)).expect("a valid scenario");
    match &s.config().trajectory {
        controller_core::TrajectoryKind::Waypoints { points, .. } => (
            points.as_slice().to_vec(),
            s.config().origin.expect("an origin"),
        ),
        other => panic!("not a waypoint mission: {other:?}"),
    }
}

/// One degree of longitude on the equator is a·π/180 = 111 319.491 m (WGS-84 a).
const EQUATOR_METRES_PER_DEGREE: f64 = 111_319.491;

/// A 22 m leg across the antimeridian (179.9999° → −179.9999°) used to become −40 074 km
/// (exit 0): the longitude difference is taken the short way round, 0.0002° east.
#[test]
fn import_plan_takes_a_leg_across_the_antimeridian_the_short_way() {
    let out = import_plan_text(
        "antimeridian.plan",
        &plan_text(
            [0.0, 179.9999, 0.0],
            &[
                waypoint(0.0, 179.9999, -3.0, 3),
                waypoint(0.0, -179.9999, -3.0, 3),
            ],
        ),
        &[],
    );
    let (points, _) = imported(&out);
    let east = f64::from(points[1][1]);
    assert!(
        (east - 0.0002 * EQUATOR_METRES_PER_DEGREE).abs() < 1e-3,
        "{points:?}"
    );
}

/// Latitude 91 (home or waypoint) used to pass, and longitude 500 landed in `origin` as 500:
/// a latitude outside [−90, 90] is refused naming the key, a longitude is wrapped (500° is
/// 140°), and the point is where the wrapped one is.
#[test]
fn import_plan_refuses_a_latitude_off_the_globe_and_wraps_a_longitude() {
    for (tag, home, items, key) in [
        (
            "home",
            [91.0, 5.0, 0.0],
            [waypoint(43.0, 5.0, -3.0, 3), waypoint(43.001, 5.0, -3.0, 3)],
            "mission.plannedHomePosition",
        ),
        (
            "item",
            [43.0, 5.0, 0.0],
            [waypoint(43.0, 5.0, -3.0, 3), waypoint(91.0, 5.0, -3.0, 3)],
            "mission.items[1].params[4] (latitude)",
        ),
    ] {
        let out = import_plan_text(&format!("lat-{tag}.plan"), &plan_text(home, &items), &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{tag}: {err}");
        assert!(err.contains(key) && err.contains("91"), "{tag}: {err}");
        assert!(out.stdout.is_empty(), "{tag}");
    }
    let out = import_plan_text(
        "lon-500.plan",
        &plan_text(
            [10.0, 500.0, 0.0],
            &[
                waypoint(10.0, 500.0, -3.0, 3),
                waypoint(10.0, 500.001, -3.0, 3),
            ],
        ),
        &[],
    );
    let (points, origin) = imported(&out);
    assert_eq!(origin, [10.0, 140.0, 0.0]);
    // 0.001° of longitude at 10°: a·π/180·cos φ/√(1 − e² sin² φ) (R_N cos φ).
    let phi = 10f64.to_radians();
    let want = 0.001 * EQUATOR_METRES_PER_DEGREE * phi.cos()
        / (1.0 - 6.694_379_990_14e-3 * phi.sin().powi(2)).sqrt();
    assert!(
        (f64::from(points[1][1]) - want).abs() < 1e-3,
        "{points:?} vs {want}"
    );
}

/// Each item's `frame` used to be ignored (every altitude read against the home's): frame 3
/// is relative to the home, 0 above mean sea level; terrain and local frames are refused by
/// item.
#[test]
fn import_plan_reads_each_items_altitude_in_its_frame() {
    // The home 100 m above sea level; 3 m below it (frame 3), then 95 m above sea level
    // (frame 0): 3 m and 5 m down.
    let out = import_plan_text(
        "frames.plan",
        &plan_text(
            [43.0, 5.0, 100.0],
            &[waypoint(43.0, 5.0, -3.0, 3), waypoint(43.001, 5.0, 95.0, 0)],
        ),
        &[],
    );
    let (points, _) = imported(&out);
    assert_eq!((points[0][2], points[1][2]), (3.0, 5.0), "{points:?}");
    for (frame, what) in [(10, "terrain"), (1, "not a global frame")] {
        let out = import_plan_text(
            &format!("frame-{frame}.plan"),
            &plan_text(
                [43.0, 5.0, 100.0],
                &[
                    waypoint(43.0, 5.0, -3.0, 3),
                    waypoint(43.001, 5.0, 95.0, frame),
                ],
            ),
            &[],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "frame {frame}: {err}");
        assert!(
            err.contains("mission.items[1].frame") && err.contains(what),
            "{err}"
        );
    }
}

/// Plans of 0, 1, 33 or 10 000 waypoints, a repeated point and a point beyond the controller's
/// reach used to exit 0 (or be refused in NED metres): each is refused, exit 2, naming the
/// plan's items.
#[test]
fn import_plan_refuses_what_the_scenario_would_refuse_naming_the_plan_items() {
    let line = |n: usize| -> Vec<String> {
        (0..n)
            .map(|i| waypoint(43.0, 5.0 + 0.0002 * i as f64, -3.0, 3))
            .collect()
    };
    let mut cases: Vec<(String, Vec<String>, &str)> = [0, 1, 33, 10_000]
        .into_iter()
        .map(|n| (format!("{n}"), line(n), "mission.items holds"))
        .collect();
    let mut repeated = line(3);
    repeated.push(repeated[2].clone());
    cases.push((
        "repeated".into(),
        repeated,
        "mission.items[3] repeats mission.items[2]",
    ));
    cases.push((
        "far".into(),
        vec![waypoint(43.0, 5.0, -3.0, 3), waypoint(43.2, 5.0, -3.0, 3)],
        "mission.items[1] is",
    ));
    for (tag, items, want) in cases {
        let out = import_plan_text(
            &format!("refuse-{tag}.plan"),
            &plan_text([43.0, 5.0, 0.0], &items),
            &[],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{tag}: {err}");
        assert!(err.contains(want), "{tag}: {err}");
        assert!(out.stdout.is_empty(), "{tag}");
    }
}

/// The flat earth's misplacement (Choice 302) against an independent reader: the WGS-84
/// point through ECEF into the true tangent plane at the origin (NED), the largest distance
/// over 360 bearings, at several latitudes and distances: the closed form holds to 1 % (its
/// next term is d/R smaller) and is reached.
#[test]
fn the_flat_earth_error_is_the_tangent_planes_in_closed_form() {
    const A: f64 = 6_378_137.0;
    const E2: f64 = 6.694_379_990_14e-3;
    let ecef = |[lat, lon, h]: [f64; 3]| {
        let (p, l) = (lat.to_radians(), lon.to_radians());
        let n = A / (1.0 - E2 * p.sin().powi(2)).sqrt();
        [
            (n + h) * p.cos() * l.cos(),
            (n + h) * p.cos() * l.sin(),
            (n * (1.0 - E2) + h) * p.sin(),
        ]
    };
    for lat0 in [0.0, 20.0, 43.0, 60.0, 80.0, -50.0] {
        let o = Origin {
            lat: lat0,
            lon: 10.0,
            alt: 0.0,
        };
        let x0 = ecef([o.lat, o.lon, o.alt]);
        let (p, l) = (lat0.to_radians(), 10f64.to_radians());
        for d in [250.0, 1000.0, 10_000.0] {
            let worst = (0..360)
                .map(|k| {
                    let th = f64::from(k).to_radians();
                    let ned = [d * th.cos(), d * th.sin(), 0.0];
                    let x = ecef(o.to_geodetic(ned));
                    let v = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
                    let true_ned = [
                        -p.sin() * l.cos() * v[0] - p.sin() * l.sin() * v[1] + p.cos() * v[2],
                        -l.sin() * v[0] + l.cos() * v[1],
                        -(p.cos() * l.cos() * v[0] + p.cos() * l.sin() * v[1] + p.sin() * v[2]),
                    ];
                    (0..3)
                        .map(|c| (true_ned[c] - ned[c]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(0.0, f64::max);
            let bound = o.flat_earth_error(d);
            assert!(
                (worst / bound - 1.0).abs() < 0.01,
                "lat {lat0}, d {d}: {worst} vs {bound}"
            );
        }
    }
}

/// A site so large that the flat earth misplaces its farthest waypoint by more than the
/// 0.05 m a run may miss its path by is imported with a warning naming the item and the error;
/// a site of a few hundred metres gets none.
#[test]
fn import_plan_warns_when_the_flat_earth_errs_beyond_the_bound() {
    let far = import_plan_text(
        "wide.plan",
        &plan_text(
            [10.0, 5.0, 0.0],
            &[waypoint(10.0, 5.0, -3.0, 3), waypoint(10.0, 5.05, -3.0, 3)],
        ),
        &[],
    );
    imported(&far);
    let err = String::from_utf8_lossy(&far.stderr);
    assert!(
        err.contains("warning") && err.contains("mission.items[1]") && err.contains("flat-earth"),
        "{err}"
    );
    let near = import_plan(&harbour_wall(), &["--speed", "0.4"]);
    imported(&near);
    assert!(
        near.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&near.stderr)
    );
}

/// An origin at a pole was accepted and the flown GeoJSON then had latitudes above 90: an
/// origin within 0.128° of a pole (the controller's reach, Choice 301) is refused naming
/// `trajectory.origin`; one just outside is taken.
#[test]
fn an_origin_at_a_pole_is_refused() {
    let text = |lat: f64| {
        format!(
            "name = \"p\"\n[trajectory]\nkind = \"waypoints\"\npoints = [[0, 0, 5], [40, 0, 5]]\n\
             speed = 0.5\norigin = [{lat}, 0, 0]\n"
        )
    };
    for lat in [90.0, -90.0, 89.9, -89.95] {
        match parse_scenario(&text(lat)) {
            Err(host_sim::scenario::ScenarioError::Invalid { key, message }) => {
                assert_eq!(key, "trajectory.origin", "{message}");
                assert!(message.contains("pole"), "{message}");
            }
            other => panic!("origin at {lat}: {other:?}"),
        }
    }
    parse_scenario(&text(89.8)).expect("0.2° from the pole: outside the controller's reach of it");
}

/// RFC 7946: every GeoJSON position has a latitude in [−90, 90] and a longitude in
/// [−180, 180]. A flown path near a pole and the antimeridian, running far past both (a
/// vehicle that left its mission), used to be written as it was computed (latitudes past 90,
/// longitudes past 180): every position written is on the globe.
#[test]
fn the_flown_geojson_stays_on_the_globe() {
    let origin = Origin {
        lat: 89.8,
        lon: 179.9,
        alt: 0.0,
    };
    let path: Vec<[f64; 3]> = (0..=400)
        .map(|k| {
            let s = f64::from(k) * 100.0;
            [s, 0.3 * s, 5.0]
        })
        .collect();
    let g: serde_json::Value =
        serde_json::from_str(&plan::geojson_line(&origin, "far", &path)).unwrap();
    let c = g["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(c.len(), path.len());
    for p in c {
        let (lon, lat) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        assert!(lat.abs() <= 90.0 && lon.abs() <= 180.0, "{p}");
    }
    // Near the origin the positions are the path's own.
    assert_eq!(c[0][1].as_f64(), Some(89.8));
}
