//! A waypoint mission flown as a team flies it (issue 29 items 1, 4, 9, 13b): the run's
//! duration against its path (docs/missions.md#the-run-and-the-path), a corner the vehicle can
//! meet (docs/missions.md#the-corner-radius), `check` on a path longer than a day, and `run`'s
//! exit code against its companion without Δu (docs/simulator.md#the-companion-run).

mod common;

use std::path::{Path, PathBuf};

use common::{host_sim, run, scenario, scenarios_dir, stderr, tempdir};
use controller_core::TrajectoryKind;
use host_sim::scenario::{load_scenario, parse_scenario, path_time, ScenarioError};

/// The shipped harbour wall's plan imported at 0.8 m/s (its 307 m in about 6.5 min).
fn imported_wall(dir: &Path) -> String {
    let out = host_sim()
        .args(["import-plan", "--speed", "0.8", "--name", "wall"])
        .arg(scenarios_dir().join("plans/harbour-wall.plan"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    std::fs::write(dir.join("plan.toml"), &text).unwrap();
    text
}

/// The waypoints of a waypoint scenario's text.
fn points(text: &str) -> Vec<[f64; 3]> {
    match parse_scenario(text).unwrap().config().trajectory {
        TrajectoryKind::Waypoints { points, .. } => {
            points.as_slice().iter().map(|p| p.map(f64::from)).collect()
        }
        other => panic!("{other:?}"),
    }
}

/// Each row's desired position [x_d, y_d, z_d] from a run's CSV.
fn reference(csv: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (x, y, z) = (col("x_d"), col("y_d"), col("z_d"));
    lines
        .map(|l| {
            let f: Vec<f64> = l
                .split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect();
            [f[x], f[y], f[z]]
        })
        .collect()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// `run --json` of `text` in `dir/name`: its exit code and its JSON.
fn run_json(dir: &Path, name: &str, text: &str) -> (Option<i32>, serde_json::Value, PathBuf) {
    let s = scenario(dir, name, text);
    let out = dir.join(format!("out-{name}"));
    let o = run(&["--json"], &s, &out);
    let v = serde_json::from_slice(&o.stdout).unwrap_or_else(|_| panic!("{}", stderr(&o)));
    (o.status.code(), v, out)
}

/// Item 4: `import-plan` writes no duration, and `run` flew the 70 s default: 33 m of the
/// harbour wall's ~300 m, `completed`. Without a duration a waypoint mission flies its path to
/// the last waypoint: the reference's last sample is on it, and the run has no path note.
#[test]
fn a_plan_flown_without_a_duration_flies_the_whole_route() {
    let dir = tempdir("whole-route");
    let text = imported_wall(&dir);
    assert!(!text.contains("duration"), "{text}");
    let (code, v, out) = run_json(&dir, "wall", &text);
    assert_eq!(code, Some(0), "{v}");
    let last = *points(&text).last().unwrap();
    let flown = reference(&out.join("wall-with.csv"));
    let end = *flown.last().unwrap();
    assert!(distance(end, last) < 0.01, "{end:?} vs {last:?}");
    // Every waypoint passed within its stated tolerance (the route's `miss`) plus 0.1 m.
    let trajectory = *parse_scenario(&text).unwrap().trajectory();
    for (i, w) in points(&text).into_iter().enumerate() {
        let nearest = flown
            .iter()
            .map(|p| distance(*p, w))
            .fold(f64::INFINITY, f64::min);
        let miss = f64::from(trajectory.route().miss(i));
        assert!(nearest < miss + 0.1, "waypoint {i}: {nearest} m > {miss} m");
    }
    for case in v["cases"].as_array().unwrap() {
        assert!(case.get("path").is_none(), "{case}");
    }
}

/// Item 4: `duration = 1000` ended 410 m past the last waypoint and a short one far before it,
/// both `completed` with no word. The run now says which waypoints it never reached — those
/// its reference never came near, found here from its CSV — or when its path ended.
#[test]
fn a_run_shorter_or_longer_than_its_path_says_so() {
    let dir = tempdir("path-note");
    let text = imported_wall(&dir);
    let short = format!("duration = 100.0\n{text}");
    let (code, v, out) = run_json(&dir, "short", &short);
    assert_eq!(code, Some(0), "{v}");
    let flown = reference(&out.join("wall-with.csv"));
    let unreached: Vec<String> = points(&text)
        .into_iter()
        .enumerate()
        .filter(|(_, w)| flown.iter().all(|p| distance(*p, *w) > 5.0))
        .map(|(i, _)| i.to_string())
        .collect();
    assert!(!unreached.is_empty());
    let note = v["cases"][0]["path"]
        .as_str()
        .unwrap_or_else(|| panic!("{v}"));
    assert!(
        note.contains(&format!("waypoints {} never reached", unreached.join(", "))),
        "{note} ({unreached:?})"
    );
    let long = format!("duration = 500.0\n{text}");
    let (code, v, _) = run_json(&dir, "long", &long);
    assert_eq!(code, Some(0), "{v}");
    let note = v["cases"][0]["path"]
        .as_str()
        .unwrap_or_else(|| panic!("{v}"));
    assert!(
        note.contains("the path ended at its last waypoint") && note.contains("before the run"),
        "{note}"
    );
    // The text table says it beside the outcome.
    let s = scenario(&dir, "long-text", &long);
    let o = run(&[], &s, &dir.join("out-long-text"));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("completed; the path ended"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}

/// The shipped real waypoint missions fly exactly their path (no note); the CI's short
/// mission says it flies 60 s of a longer path, and the note says so.
#[test]
fn the_shipped_waypoint_missions_end_with_their_paths() {
    for name in ["survey-200x100", "harbour-wall", "pipeline"] {
        let s = load_scenario(&scenarios_dir().join(format!("real/{name}.toml"))).unwrap();
        let end = s.steps() as f64 * s.period();
        assert_eq!(path_time::run_note(s.trajectory(), end), None, "{name}");
    }
    let s = load_scenario(&scenarios_dir().join("waypoints-short.toml")).unwrap();
    let end = s.steps() as f64 * s.period();
    let note = path_time::run_note(s.trajectory(), end).unwrap();
    assert!(note.contains("never reached"), "{note}");
}

/// A 60 km leg at 0.5 m/s takes 33 h.
const DAY_LONG: &str = "name = \"long\"\n[trajectory]\nkind = \"waypoints\"\n\
     points = [[0, 0, 5], [30000, 0, 5], [30000, 30000, 5]]\nspeed = 0.5\n";

/// Item 9: `check` on a path longer than a day exited 2 blaming `duration`, a key not in the
/// file (the profile search builds its scenario with the path's duration). It names the key
/// that sets the path's pace, and so does loading the file without a duration.
#[test]
fn a_path_longer_than_a_day_is_blamed_on_its_pace_not_on_duration() {
    let dir = tempdir("day-long");
    let s = scenario(&dir, "given", &format!("duration = 100\n{DAY_LONG}"));
    let o = host_sim()
        .args(["check", "--scenario"])
        .arg(&s)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("`trajectory.speed`") && e.contains("longer than the one day"),
        "{e}"
    );
    assert!(!e.contains("`duration`"), "{e}");
    match parse_scenario(DAY_LONG) {
        Err(ScenarioError::Invalid { key, message }) => {
            assert_eq!(key, "trajectory.speed", "{message}");
        }
        other => panic!("{other:?}"),
    }
}

/// 10 s of the real 10 m circle with a path bound of `bound` m.
fn real_circle(bound: f64) -> String {
    format!(
        "name = \"c\"\nduration = 10\nideal_actuators = false\n[trajectory]\nkind = \"circle\"\n\
         radius = 10\nheading = \"tangent\"\n[bound]\nmax_path = {bound:e}\n"
    )
}

/// Item 13b: `run` exited 4 when only its companion without Δu missed its bound. The exit code
/// follows the controller the scenario configures; the companion's miss is reported beside
/// it. The bound is put between the two runs' own errors, measured first.
#[test]
fn run_exits_by_the_configured_controller_not_by_its_companion() {
    let dir = tempdir("companion");
    let (code, v, _) = run_json(&dir, "wide", &real_circle(1.0));
    assert_eq!(code, Some(0), "{v}");
    let error = |robust: bool| {
        v["cases"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["robust"] == robust)
            .unwrap()["max_path"]
            .as_f64()
            .unwrap()
    };
    let (with, without) = (error(true), error(false));
    assert!(with < without, "{with} {without}");
    let between = real_circle((with * without).sqrt());
    let (code, v, _) = run_json(&dir, "between", &between);
    assert_eq!(code, Some(0), "{v}");
    let companion = v["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["robust"] == false)
        .unwrap();
    assert!(companion["missed"].is_string(), "{companion}");
    let s = scenario(&dir, "between-text", &between);
    let o = run(&[], &s, &dir.join("out-between-text"));
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("the comparison run without Δu MISSED its bound")
            && text.contains("not the verdict"),
        "{text}"
    );
    // With Δu off in the scenario, its own run is the verdict: exit 4.
    let off = between.replace("[bound]", "[controller]\nrobust = false\n[bound]");
    let (code, v, _) = run_json(&dir, "off", &off);
    assert_eq!(code, Some(4), "{v}");
}

/// A 90° corner of the real vehicle at 0.5 m/s whose waypoint falls between control ticks,
/// turned on a radius `radius`.
fn real_corner(radius: &str, last: &str) -> String {
    format!(
        "name = \"corner\"\nideal_actuators = false\n[trajectory]\nkind = \"waypoints\"\n\
         points = [[0, 0, 5], [30.0013, 0, 5], {last}]\nspeed = 0.5\nturn_radius = {radius}\n"
    )
}

/// Item 1: `turn_radius = 1e-6` on a 90° corner passed `check` (FEASIBLE) and `run` flew it
/// with a π/2 yaw error: the blend lasts microseconds, between two control ticks and two of the
/// preflight's samples. Under the 1 m floor it is refused by both, naming the key and the floor.
#[test]
fn a_corner_under_the_floor_is_refused_by_check_and_run() {
    let dir = tempdir("floor");
    for radius in ["1e-6", "1e-9", "1e-30", "0.5"] {
        let s = scenario(&dir, "corner", &real_corner(radius, "[30.0013, 30, 5]"));
        for command in ["check", "run"] {
            let o = host_sim()
                .args([command, "--scenario"])
                .arg(&s)
                .arg("--json")
                .args(match command {
                    "run" => vec!["--out".to_string(), dir.join("out").display().to_string()],
                    _ => Vec::new(),
                })
                .output()
                .unwrap();
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{command} {radius}: {e}");
            assert!(
                e.contains("`trajectory.turn_radius`") && e.contains("outside [1, "),
                "{command} {radius}: {e}"
            );
        }
    }
}

/// The floor is a corner the vehicle meets: a 119° corner (near the sharpest the path allows)
/// at the 1 m floor is flown by the real vehicle as written at a time scale of at most 1.5
/// (at least two thirds of the planned speed), the corner's extremes checked in closed form.
#[test]
fn the_vehicle_meets_a_corner_at_the_floor() {
    use host_sim::studies::preflight::{check_as_written, Verdict, DEFAULT_MARGIN};
    let s = parse_scenario(&real_corner("1", "[10.1, 34.5, 5]")).unwrap();
    let p = check_as_written(&s, DEFAULT_MARGIN).unwrap();
    assert!(
        matches!(p.verdict, Verdict::Feasible | Verdict::NeedsTimeScale),
        "{p}"
    );
    let k = p.smallest_time_scale.unwrap();
    assert!(k <= 1.5, "{p}");
}

/// Cosmetic (issue 29): a waypoint refusal names the point or the part. `points = 1e6 is
/// outside …` did not say which, 1e39 was "not finite", `speed = 1e-300` was reported as 0,
/// and a bad `speeds` entry was blamed on `trajectory.heading`.
#[test]
fn waypoint_refusals_name_the_point_or_the_part() {
    use common::{invalid_key, toml_error};
    let path = |rest: &str| format!("[trajectory]\nkind = \"waypoints\"\n{rest}\n");
    let three = "points = [[0, 0, 5], [50, 0, 5], [50, 50, 5]]\nspeed = 0.5\n";
    let (key, message) = invalid_key(&path("points = [[0, 0, 5], [1e6, 0, 5]]\nspeed = 0.5"));
    assert_eq!(key, "trajectory.points");
    assert!(
        message.contains("waypoint 1's x = 1e6 m is outside"),
        "{message}"
    );
    let e = toml_error(&path("points = [[0, 0, 5], [50, 1e39, 5]]\nspeed = 0.5"));
    assert!(e.contains("waypoint 1's y = 1e39 m is outside"), "{e}");
    let e = toml_error(&path("points = [[0, 0, 5], [50, 0, 5]]\nspeed = 1e-300"));
    assert!(
        e.contains("speed = 1e-300 is below the smallest f32"),
        "{e}"
    );
    let e = toml_error(&path(&format!("{three}turn_radius = 1e39")));
    assert!(
        e.contains("turn_radius = 1e39 is beyond the largest f32"),
        "{e}"
    );
    for (speeds, says) in [
        ("[0.5, 1e-6, 0.5]", "speeds[1] (the turn at waypoint 1)"),
        (
            "[0.5, 0.5, 11]",
            "speeds[2] (leg 1) = 11 m/s is outside (0, 10]",
        ),
        (
            "[0.5, -1, 0.5]",
            "speeds[1] (the turn at waypoint 1) = -1 m/s",
        ),
    ] {
        let (key, message) = invalid_key(&path(&format!("{three}speeds = {speeds}")));
        assert_eq!(key, "trajectory.speeds", "{speeds}: {message}");
        assert!(message.contains(says), "{speeds}: {message}");
    }
    let e = toml_error(&path(&format!("{three}speeds = [0.5, 1e39, 0.5]")));
    assert!(
        e.contains("speeds[1] (the turn at waypoint 1) = 1e39 m/s"),
        "{e}"
    );
}
