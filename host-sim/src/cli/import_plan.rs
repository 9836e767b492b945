//! `host-sim import-plan`: a QGroundControl `.plan` as a waypoint scenario (docs/missions.md#plans-from-qgroundcontrol).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, Context, Result};
use clap::Args;

use super::Exit;
use crate::scenario::plan;

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
/// file that is not a plan of waypoints, naming what is wrong).
pub fn import_plan(args: &ImportPlanArgs, stdout: &mut dyn Write) -> Result<Exit> {
    let text = std::fs::read_to_string(&args.plan)
        .with_context(|| format!("cannot read {}", args.plan.display()))?;
    let (origin, points) =
        plan::import(&text).map_err(|e| anyhow!("{}: {e}", args.plan.display()))?;
    let pts: Vec<String> = points
        .iter()
        .map(|p| format!("    [{:.3}, {:.3}, {:.3}],", p[0], p[1], p[2]))
        .collect();
    writeln!(
        stdout,
        "# Imported from {} (docs/missions.md#plans-from-qgroundcontrol): NED in the tangent plane at the plan's home\n\
         # position lat {}, lon {}, alt {} m (WGS-84 flat earth; error under 1 cm within 250 m).\n\
         name = \"{}\"\n\n[trajectory]\nkind = \"waypoints\"\npoints = [\n{}\n]\nspeed = {}\n\
         heading = \"tangent\"\norigin = [{}, {}, {}]",
        args.plan.display(),
        origin.lat,
        origin.lon,
        origin.alt,
        args.name,
        pts.join("\n"),
        args.speed,
        origin.lat,
        origin.lon,
        origin.alt
    )?;
    Ok(Exit::Success)
}
