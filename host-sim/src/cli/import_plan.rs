//! `host-sim import-plan`: a QGroundControl `.plan` as a waypoint scenario (docs/missions.md#plans-from-qgroundcontrol).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use controller_core::readable::Readable;
use controller_core::trajectory::{WaypointList, MAX_SPEED};
use controller_core::TrajectoryKind;

use super::Exit;
use crate::scenario::file::{HeadingName, ScenarioFile};
use crate::scenario::{check_name, plan, KeyPath, ScenarioError};

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
    let (origin, points) =
        plan::import(&text).map_err(|e| anyhow!("{}: {e}", args.plan.display()))?;
    let mission: Vec<[f32; 3]> = points.iter().map(|p| p.map(|x| x as f32)).collect();
    let points_list =
        WaypointList::new(&mission).map_err(|e| anyhow!("{}: {e}", args.plan.display()))?;
    let mut file = ScenarioFile::new(TrajectoryKind::Waypoints {
        points: points_list,
        speed,
        turn_radius: None,
        speeds: None,
        speed_change: None,
    });
    file.name = Some(args.name.clone());
    file.trajectory.heading = Some(HeadingName::Tangent);
    file.trajectory.origin = Some([origin.lat, origin.lon, origin.alt]);
    let mut doc = file.to_document()?;
    // The NED metres to the millimetre, from the f64s computed (readable when huge).
    let metres: Vec<f64> = points.iter().flatten().copied().collect();
    doc.set_numbers(KeyPath::POINTS, &metres, |x| match x.abs() < 1e6 {
        true => format!("{x:.3}"),
        false => Readable(x).to_string(),
    })?;
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
        format!(
            "position lat {lat}, lon {lon}, alt {alt} m (WGS-84 flat earth; error under 1 cm \
             within 250 m)."
        ),
    ]);
    write!(stdout, "{doc}")?;
    Ok(Exit::Success)
}
