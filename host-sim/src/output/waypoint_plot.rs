//! The path over the waypoints of a waypoint mission (docs/simulator.md#plots-of-a-waypoint-mission, **Choice 170**): a
//! plan view as on a chart (east to the right, north up, equal scales) of the waypoints'
//! polyline, the desired path η_d that cuts its corners on the blends (Choice 150) and the
//! path flown, each waypoint marked and numbered as `check` names them (`turn at j`); beside
//! it a zoom on the corner the path passes farthest from, where the blend is plain; below them,
//! when the waypoints are not all at one depth, the depth profile along the path.
//! [`mission_plots`] writes it with the speed plot ([`super::speed_plot`]) for `run` and the
//! main job.

use std::path::{Path, PathBuf};

use anyhow::Result;
use controller_core::TrajectoryKind;
use plotters::prelude::RGBColor;

use super::dir::OutputDir;
use super::figures::{file_stem, write_plot};
use super::plot::{rows_with_legend, Line, Panel, Row, Stroke, C_DESIRED, C_LIMIT, C_WITH};
use super::speed_plot::{plot_speed_profile, speed_plot_name};
use crate::scenario::Scenario;
use crate::sim::RunResult;

/// The waypoints' marker colour (used by no other line of the plot).
pub const C_WAYPOINT: RGBColor = RGBColor(230, 110, 0);
/// Waypoints whose depths differ by more than this (m) get the depth profile.
const DEPTH_CHANGE: f64 = 0.01;
/// Height shares of the plan view and the depth profile.
const SHARES: [f64; 2] = [0.68, 0.32];
/// Width shares of the plan view and the zoom on one corner.
const ZOOM_SHARES: [f64; 2] = [0.62, 0.38];
/// The zoom's half-width, in cuts of its corner.
const ZOOM_CUTS: f64 = 1.6;
/// The legend's name of the waypoints.
const WAYPOINT_LABEL: &str = "waypoint j (check's turn at j)";

/// The waypoints of `scenario` (NED, m), if it is a waypoint mission.
fn waypoints(scenario: &Scenario) -> Option<Vec<[f64; 3]>> {
    match &scenario.config().trajectory {
        TrajectoryKind::Waypoints { points, .. } => {
            Some(points.as_slice().iter().map(|p| p.map(f64::from)).collect())
        }
        _ => None,
    }
}

/// The waypoint plot's file name for a run called after `scenario`, if it is a waypoint
/// mission.
pub fn waypoint_plot_name(scenario: &Scenario) -> Option<String> {
    waypoints(scenario).map(|_| format!("{}-waypoints.png", file_stem(&scenario.config().name)))
}

/// Writes the path over the waypoints of `scenario` (a waypoint mission; `None` otherwise) as
/// `run` flew it into `dir`, atomically under [`waypoint_plot_name`].
pub fn plot_waypoint_path(
    dir: &Path,
    scenario: &Scenario,
    run: &RunResult,
) -> Result<Option<PathBuf>> {
    let (Some(name), Some(points)) = (waypoint_plot_name(scenario), waypoints(scenario)) else {
        return Ok(None);
    };
    let plan = plan_view(&points, run);
    let zoom = corner_zoom(scenario, &points, run);
    let mut top = vec![(ZOOM_SHARES[0], &plan)];
    if let Some(z) = &zoom {
        top.push((ZOOM_SHARES[1], z));
    }
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[2]), hi.max(p[2]))
        });
    let depth = (hi - lo > DEPTH_CHANGE).then(|| depth_profile(&points, run));
    let mut rows = vec![Row {
        share: SHARES[0],
        cells: top,
    }];
    if let Some(d) = &depth {
        rows.push(Row {
            share: SHARES[1],
            cells: vec![(1.0, d)],
        });
    }
    let title = format!("{}: the path over its {} waypoints", run.name, points.len());
    let file = write_plot(&dir.join(name), |path| {
        rows_with_legend(path, &title, &rows)
    })?;
    Ok(Some(file))
}

/// The corner the path passes farthest from (its largest `Route::miss`, the sharpest turn),
/// zoomed to [`ZOOM_CUTS`] of its cut around the waypoint, equal scales: the blend leaving
/// the first leg a cut before the waypoint and joining the next a cut after it (Choice 150).
/// `None` for a path without a turn.
fn corner_zoom(scenario: &Scenario, points: &[[f64; 3]], run: &RunResult) -> Option<Panel> {
    let route = scenario.trajectory().route();
    let j = (1..points.len().saturating_sub(1))
        .max_by(|&a, &b| route.miss(a).total_cmp(&route.miss(b)))?;
    let (w, cut) = (points[j], f64::from(route.cut(j)));
    let h = ZOOM_CUTS * cut;
    if !(h > 0.0 && h.is_finite()) {
        return None;
    }
    let inside = |p: &[f64]| (p[0] - w[0]).abs() <= h && (p[1] - w[1]).abs() <= h;
    // East right, north up; a point outside the window breaks the line.
    let en = |p: &[f64]| match inside(p) {
        true => (p[1], p[0]),
        false => (f64::NAN, f64::NAN),
    };
    // The legs to and from the waypoint, to the window's edge (or their other end).
    let towards = |other: &[f64; 3]| -> (f64, f64) {
        let (dn, de) = (other[0] - w[0], other[1] - w[1]);
        let len = dn.hypot(de);
        let t = (h / dn.abs().max(de.abs()).max(1e-12) * len).min(len);
        (w[1] + de / len * t, w[0] + dn / len * t)
    };
    let miss = f64::from(route.miss(j));
    let mut p = Panel::new(
        "",
        &format!("east y (m): waypoint {j}, passed {miss:.2} m inside"),
        "north x (m)",
    );
    p.equal_aspect = true;
    let polyline = vec![
        towards(&points[j - 1]),
        (w[1], w[0]),
        towards(&points[j + 1]),
    ];
    plan_lines(&mut p, polyline, run, &en, vec![(w[1], w[0])]);
    p.labels = vec![(w[1], w[0], j.to_string())];
    Some(p)
}

/// The plan view: east (y) right, north (x) up, equal scales.
fn plan_view(points: &[[f64; 3]], run: &RunResult) -> Panel {
    let mut p = Panel::new("", "east y (m)", "north x (m)");
    p.equal_aspect = true;
    let en = |v: &[f64]| (v[1], v[0]);
    let marks: Vec<_> = points.iter().map(|w| en(w)).collect();
    plan_lines(&mut p, marks.clone(), run, &en, marks);
    p.labels = points
        .iter()
        .enumerate()
        .map(|(j, w)| (w[1], w[0], j.to_string()))
        .collect();
    p
}

/// The four lines of a plan panel, in drawing order: the waypoints' polyline, the flown path,
/// the desired path over it (which it tracks to centimetres), the waypoints; `en` maps a pose
/// to (east, north).
fn plan_lines(
    p: &mut Panel,
    polyline: Vec<(f64, f64)>,
    run: &RunResult,
    en: &dyn Fn(&[f64]) -> (f64, f64),
    waypoints: Vec<(f64, f64)>,
) {
    p.lines.push(Line::new(
        "waypoints' polyline",
        C_LIMIT,
        Stroke::Dashed,
        polyline,
    ));
    p.lines.push(Line::new(
        format!("flown, {}", run.du_label()),
        C_WITH,
        Stroke::Solid,
        run.samples.iter().map(|s| en(&s.eta)).collect(),
    ));
    p.lines.push(Line::new(
        "desired η_d (blends cut the corners)",
        C_DESIRED,
        Stroke::Dashed,
        run.samples.iter().map(|s| en(&s.eta_d)).collect(),
    ));
    p.lines.push(Line::new(
        WAYPOINT_LABEL,
        C_WAYPOINT,
        Stroke::Dots,
        waypoints,
    ));
}

/// The depth profile: −z (m, up) against the distance along the desired path, the flown depth
/// at the same times, each waypoint at the distance where η_d passes nearest to it.
fn depth_profile(points: &[[f64; 3]], run: &RunResult) -> Panel {
    let mut p = Panel::new(
        "depth along the path",
        "distance along η_d (m)",
        "−z (m, up)",
    );
    let mut along = Vec::with_capacity(run.samples.len());
    let mut s = 0.0;
    for (i, sample) in run.samples.iter().enumerate() {
        if i > 0 {
            let prev = &run.samples[i - 1].eta_d;
            let d = (0..3)
                .map(|k| (sample.eta_d[k] - prev[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            // A NaN step (a broken run) adds nothing.
            s += Some(d).filter(|d| d.is_finite()).unwrap_or(0.0);
        }
        along.push(s);
    }
    p.lines.push(Line::new(
        format!("flown, {}", run.du_label()),
        C_WITH,
        Stroke::Solid,
        run.samples
            .iter()
            .zip(&along)
            .map(|(x, &a)| (a, -x.eta[2]))
            .collect(),
    ));
    p.lines.push(Line::new(
        "desired η_d (blends cut the corners)",
        C_DESIRED,
        Stroke::Dashed,
        run.samples
            .iter()
            .zip(&along)
            .map(|(x, &a)| (a, -x.eta_d[2]))
            .collect(),
    ));
    let nearest = |w: &[f64; 3]| -> Option<f64> {
        let dist =
            |x: &crate::sim::Sample| (0..3).map(|k| (x.eta_d[k] - w[k]).powi(2)).sum::<f64>();
        run.samples
            .iter()
            .zip(&along)
            .filter(|(x, _)| dist(x).is_finite())
            .min_by(|a, b| dist(a.0).total_cmp(&dist(b.0)))
            .map(|(_, &a)| a)
    };
    // A waypoint the run did not reach (a run cut short) has no place on the profile.
    let marks: Vec<(f64, f64, String)> = points
        .iter()
        .enumerate()
        .filter_map(|(j, w)| Some((nearest(w)?, -w[2], j.to_string())))
        .collect();
    p.lines.push(Line::new(
        WAYPOINT_LABEL,
        C_WAYPOINT,
        Stroke::Dots,
        marks.iter().map(|m| (m.0, m.1)).collect(),
    ));
    p.labels = marks;
    p
}

/// The plots of a waypoint mission `scenario` flown as `run` — its speed over time
/// ([`plot_speed_profile`], Choice 162) and its path over the waypoints
/// ([`plot_waypoint_path`]) — claimed in `dir`'s manifest first; none for a closed-form
/// mission. A plot that cannot be drawn is listed in `incomplete` and left out.
///
/// # Errors
/// A name the output folder cannot claim.
pub fn mission_plots(
    dir: &OutputDir,
    scenario: &Scenario,
    run: &RunResult,
    incomplete: &mut Vec<String>,
) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let name = &scenario.config().name;
    if let Some(file) = waypoint_plot_name(scenario) {
        dir.claim(&file)?;
        match plot_waypoint_path(dir.path(), scenario, run) {
            Ok(f) => files.extend(f),
            Err(e) => incomplete.push(format!("waypoint plot of {name}: {e:#}")),
        }
    }
    if let Some(file) = speed_plot_name(scenario) {
        dir.claim(&file)?;
        match plot_speed_profile(dir.path(), scenario) {
            Ok(f) => files.extend(f),
            Err(e) => incomplete.push(format!("speed plot of {name}: {e:#}")),
        }
    }
    Ok(files)
}
