//! `host-sim import-plan`: a QGroundControl `.plan` as a waypoint scenario (docs/missions.md#plans-from-qgroundcontrol).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use controller_core::controller::MAX_POSITION;
use controller_core::readable::Readable;
use controller_core::trajectory::{
    TrajectoryError, WaypointList, MAX_SLOPE, MAX_SPEED, MAX_TURN_DEGREES, MAX_WAYPOINTS, MIN_LEG,
};
use controller_core::{HeadingMode, Mission, Trajectory, TrajectoryKind};

use super::Exit;
use crate::scenario::file::{HeadingName, ScenarioFile};
use crate::scenario::{check_name, parse_scenario, plan, KeyPath, ScenarioError};
use crate::sim::bound::MAX_PATH_ERROR;

/// `import-plan`: the waypoints of a `.plan` in the mission's NED frame, printed as a scenario.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct ImportPlanArgs {
    /// The QGroundControl `.plan` file (JSON mission items: waypoints).
    pub plan: PathBuf,
    /// The path speed of the scenario (m/s; `host-sim check` on the result proposes a profile).
    #[arg(long, default_value_t = 0.5)]
    pub speed: f64,
    /// The scenario's name.
    #[arg(long, default_value = "imported-plan")]
    pub name: String,
}

/// `import-plan`: prints a scenario TOML with `[trajectory] kind = "waypoints"` (exit 2 on a
/// file that is not a plan of waypoints, naming what is wrong, and on a flag the scenario
/// would refuse, naming the flag). The file is a [`ScenarioFile`], serialized: the flags and
/// the plan's path are written as TOML values and comments, never pasted into the text.
pub fn import_plan(args: &ImportPlanArgs, stdout: &mut dyn Write) -> Result<Exit> {
    // The flags first, with the rules the scenario applies to its keys.
    if let Err(ScenarioError::Invalid { message, .. }) = check_name(&args.name) {
        bail!("--name {message}");
    }
    let speed = args.speed as f32;
    if !(speed > 0.0 && speed <= MAX_SPEED) {
        bail!(
            "--speed must be a path speed in (0, {}] m/s, got {}",
            Readable(MAX_SPEED),
            Readable(args.speed)
        );
    }
    let text = std::fs::read_to_string(&args.plan)
        .with_context(|| format!("cannot read {}", args.plan.display()))?;
    let refused = |why: String| anyhow!("{}: {why}", args.plan.display());
    let (origin, points) = plan::import(&text).map_err(|e| refused(e.to_string()))?;
    let path = waypoint_path(&points, speed).map_err(refused)?;
    // The flat earth's error at the farthest waypoint (Choice 302).
    let (far, d) =
        points
            .iter()
            .map(|p| p[0].hypot(p[1]))
            .enumerate()
            .fold(
                (0, 0.0),
                |best, (i, d)| if d > best.1 { (i, d) } else { best },
            );
    let flat_error = origin.flat_earth_error(d);
    let at_farthest = format!(
        "{} is {d:.0} m from the home, where the flat-earth plane misplaces a point by up to \
         {flat_error:.3} m",
        plan::item(far)
    );
    if flat_error > MAX_PATH_ERROR {
        eprintln!(
            "host-sim: import-plan: warning: {at_farthest}, more than the {MAX_PATH_ERROR} m a \
             run may miss its path by (docs/missions.md#plans-from-qgroundcontrol)"
        );
    }
    let mut file = ScenarioFile::new(path);
    file.name = Some(args.name.clone());
    file.trajectory.heading = Some(HeadingName::Tangent);
    file.trajectory.origin = Some([origin.lat, origin.lon, origin.alt]);
    let mut doc = file.to_document()?;
    // The NED metres to the millimetre, from the f64s computed (within the controller's reach).
    let metres: Vec<f64> = points.iter().flatten().copied().collect();
    doc.set_numbers(KeyPath::POINTS, &metres, |x| format!("{x:.3}"))?;
    let (lat, lon, alt) = (
        Readable(origin.lat),
        Readable(origin.lon),
        Readable(origin.alt),
    );
    doc.set_header(&[
        format!(
            "Imported from {} (docs/missions.md#plans-from-qgroundcontrol): NED in the tangent plane at the plan's home",
            args.plan.display()
        ),
        format!("position lat {lat}, lon {lon}, alt {alt} m (WGS-84 flat earth: {at_farthest})."),
    ]);
    // Whatever else the scenario refuses, refused here, not by the `run` that reads it.
    parse_scenario(&doc.to_string())
        .map_err(|e| refused(format!("the imported scenario is refused: {e}")))?;
    write!(stdout, "{doc}")?;
    Ok(Exit::Success)
}

/// The waypoint path of the plan's `points` (NED, m; point i is `mission.items[i]`) at
/// `speed`, or what the scenario would refuse in it, said of the plan's items (Choice 300).
fn waypoint_path(points: &[[f64; 3]], speed: f32) -> Result<TrajectoryKind, String> {
    if !(2..=MAX_WAYPOINTS).contains(&points.len()) {
        return Err(count_refused(points.len()));
    }
    let reach = f64::from(MAX_POSITION);
    if let Some((i, p)) = points
        .iter()
        .enumerate()
        .find(|(_, p)| p.iter().any(|x| x.abs() > reach))
    {
        return Err(format!(
            "{} is {} m north, {} m east and {} m down of the home: beyond the ±{reach} m \
             (along each axis) the controller accepts from the mission origin",
            plan::item(i),
            Readable(p[0].round()),
            Readable(p[1].round()),
            Readable(p[2].round())
        ));
    }
    let mission: Vec<[f32; 3]> = points.iter().map(|p| p.map(|x| x as f32)).collect();
    let path = TrajectoryKind::Waypoints {
        points: WaypointList::new(&mission).map_err(|e| e.to_string())?,
        speed,
        turn_radius: None,
        speeds: None,
        speed_change: None,
    };
    Trajectory::new(Mission {
        path,
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    })
    .map_err(|e| in_plan_items(&e, speed))?;
    Ok(path)
}

/// A plan of `n` waypoints, refused: a mission has 2 to [`MAX_WAYPOINTS`].
fn count_refused(n: usize) -> String {
    let s = if n == 1 { "" } else { "s" };
    format!("mission.items holds {n} waypoint{s}; a waypoint mission needs 2 to {MAX_WAYPOINTS}")
}

/// A refusal of the core's ([`Trajectory::new`]) said of the plan's items: waypoint i is
/// `mission.items[i]` (Choice 300).
fn in_plan_items(e: &TrajectoryError, speed: f32) -> String {
    let item = plan::item;
    let leg = |j: usize| format!("the leg from {} to {}", item(j), item(j + 1));
    match *e {
        TrajectoryError::WaypointCount { count } => count_refused(count),
        TrajectoryError::RepeatedWaypoint { index } => format!(
            "{} repeats {} (closer than {MIN_LEG} m to it)",
            item(index),
            item(index.saturating_sub(1))
        ),
        TrajectoryError::TurnTooSharp { index, degrees } => format!(
            "{}: the turn there is {}°, sharper than the {MAX_TURN_DEGREES}° a waypoint mission \
             allows (add a waypoint to split it)",
            item(index),
            Readable(degrees)
        ),
        TrajectoryError::LegTooShort { leg: j, needs, has } => format!(
            "{} is {} m long but the turns at its ends need {} m at --speed {} (lower --speed, \
             or space the waypoints)",
            leg(j),
            Readable(has),
            Readable(needs),
            Readable(speed)
        ),
        TrajectoryError::TooSteep { leg: j, slope } => format!(
            "{} climbs or dives at slope {}, steeper than {MAX_SLOPE} (the heading needs \
             horizontal motion)",
            leg(j),
            Readable(slope)
        ),
        TrajectoryError::TooSlowForTangent { .. } => format!("--speed {}: {e}", Readable(speed)),
        _ => format!("the plan's waypoints: {e}"),
    }
}
