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
        {"type": "SimpleItem", "command": 16, "params": [0, 0, 0, null, 1.0, 2.0, -3]},
        {"type": "SimpleItem", "command": 22, "params": [0, 0, 0, null, 1.0, 2.0, 10]}]}}"#;
    let e = plan::import(text).unwrap_err();
    assert!(e.contains("mission.items[1]") && e.contains("22"), "{e}");
    let e = plan::import(r#"{"fileType": "Mission"}"#).unwrap_err();
    assert!(e.contains("fileType"), "{e}");
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
    // The largest speed is taken, and read back as itself (the file's shape: at 10 m/s the
    // default corners do not fit this plan's legs, which the scenario then says).
    let out = import_plan(&harbour_wall(), &["--speed", "10"]);
    assert!(out.status.success());
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
    let item = |lat: f64| {
        format!(
            r#"{{"type": "SimpleItem", "command": 16, "params": [0, 0, 0, null, {lat}, 5.0, 1e300]}}"#
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
