//! The speed profile of a waypoint mission over time (docs/simulator.md#plots-of-a-waypoint-mission, **Choice 162**): the
//! reference speed |η̇_d| the law is given, each part's own speed (the pinned `speeds`, else the
//! constant `speed`) and each leg's cap (`trajectory.speed_limits`) as steps.

use std::path::{Path, PathBuf};

use anyhow::Result;
use controller_core::TrajectoryKind;

use super::figures::{file_stem, write_plot};
use super::plot::{panel_with_legend, Line, Panel, Stroke, C_DESIRED, C_LIMIT, C_WITH};
use crate::scenario::Scenario;

/// Samples of |η̇_d| per second of mission time.
const SPEED_PLOT_RATE_HZ: u32 = 10;

/// The speed plot's file name for a run called `name`, if `scenario` is a waypoint mission.
pub fn speed_plot_name(scenario: &Scenario) -> Option<String> {
    matches!(
        scenario.config().trajectory,
        TrajectoryKind::Waypoints { .. }
    )
    .then(|| format!("{}-speed.png", file_stem(&scenario.config().name)))
}

/// Writes the speed plot of `scenario` (a waypoint mission; `None` otherwise) into `dir`,
/// atomically under [`speed_plot_name`].
pub fn plot_speed_profile(dir: &Path, scenario: &Scenario) -> Result<Option<PathBuf>> {
    let Some(name) = speed_plot_name(scenario) else {
        return Ok(None);
    };
    let cfg = scenario.config();
    let TrajectoryKind::Waypoints { speed, speeds, .. } = cfg.trajectory else {
        return Ok(None);
    };
    let t = scenario.trajectory();
    let (route, law) = (t.route(), t.time_law());
    let k = f64::from(cfg.time_scale);
    // Each segment's start and end time (s, at the mission's time scale).
    let count = route.segment_count();
    let bounds = |i: usize| -> (f64, f64) {
        match law.is_set() {
            true => {
                let end = match i + 1 < count {
                    true => law.segment_time(i + 1),
                    false => law.duration(),
                };
                (k * f64::from(law.segment_time(i)), k * f64::from(end))
            }
            false => {
                let s = f64::from(route.segment_start(i));
                let l = f64::from(route.segment_length(i));
                let v = f64::from(speed);
                (k * s / v, k * (s + l) / v)
            }
        }
    };
    let steps = |value: &dyn Fn(usize) -> Option<f64>| -> Vec<(f64, f64)> {
        let mut pts = Vec::new();
        for i in 0..count {
            let (a, b) = bounds(i);
            // NaN breaks the line where a segment has no value (a turn has no cap).
            let v = value(route.segment_part(i)).map_or(f64::NAN, |v| v / k);
            pts.extend([(a, v), (b, v), (b, f64::NAN)]);
        }
        pts
    };
    let part_speed = |p: usize| {
        Some(f64::from(match speeds {
            Some(list) => list.as_slice()[p],
            None => speed,
        }))
    };
    let cap = |p: usize| match (p % 2, &cfg.speed_limits) {
        (0, Some(caps)) => caps.get(p / 2).copied(),
        _ => None,
    };
    let mut panel = Panel::new("", "t (s)", "speed (m/s)");
    panel.lines.push(Line::new(
        "reference speed |dη_d/dt| (dσ/dt on the legs)",
        C_WITH,
        Stroke::Solid,
        reference_speed(scenario),
    ));
    panel.lines.push(Line::new(
        "each part's speed (speeds, else speed)",
        C_DESIRED,
        Stroke::Dashed,
        steps(&part_speed),
    ));
    if cfg.speed_limits.is_some() {
        panel.lines.push(Line::new(
            "leg caps (speed_limits)",
            C_LIMIT,
            Stroke::Dashed,
            steps(&cap),
        ));
    }
    let title = format!("{}: speed along the path", cfg.name);
    let file = write_plot(&dir.join(name), |path| {
        panel_with_legend(path, &title, &panel)
    })?;
    Ok(Some(file))
}

/// The reference speed |η̇_d| at [`SPEED_PLOT_RATE_HZ`] over the run: σ̇ on the legs, σ̇·|p′|
/// (≥ σ̇·cos(Δ/2)) in the turns (Choice 150).
fn reference_speed(scenario: &Scenario) -> Vec<(f64, f64)> {
    let n = (scenario.config().duration * f64::from(SPEED_PLOT_RATE_HZ)).floor() as u64;
    (0..=n)
        .map(|i| {
            let d = scenario.trajectory().sample(i, SPEED_PLOT_RATE_HZ);
            let v = d.eta_dot.fixed_rows::<3>(0).norm();
            (i as f64 / f64::from(SPEED_PLOT_RATE_HZ), f64::from(v))
        })
        .collect()
}
