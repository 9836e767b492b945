//! The paper's figures (Figs 2–5) for one case: XY path, the six errors, payload, heading,
//! thruster voltages and δ, drawn with [`super::plot`].

use std::f64::consts::{PI, TAU};
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use controller_core::DEFAULT_V_LIMIT;
use plotters::prelude::RGBColor;

use super::atomic::Pending;
use super::plot::{
    figure, min_max, render, usable, Line, Panel, Stroke, C_DESIRED, C_LIMIT, C_WITH, C_WITHOUT,
};
use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};

use crate::sim::chatter::DEAD_BAND;
use crate::sim::{RunResult, Sample};

const C_THRUSTERS: [RGBColor; THRUSTERS] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn series(run: &RunResult, f: impl Fn(&Sample) -> f64) -> Vec<(f64, f64)> {
    run.samples.iter().map(|s| (s.t, f(s))).collect()
}

/// Unwraps an angle series (removes 2π jumps between consecutive usable samples) so that a
/// heading wrapped to (−π, π] and one that is not plot alike. NaNs stay in place.
fn unwrap_angles(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut prev: Option<f64> = None;
    let mut offset = 0.0;
    pts.iter()
        .map(|&(t, a)| {
            if !usable(a) {
                return (t, a);
            }
            if let Some(p) = prev {
                let jump = ((a - p) / TAU).round();
                if (a - p).abs() > PI && jump.is_finite() {
                    offset -= jump * TAU;
                }
            }
            prev = Some(a);
            (t, a + offset)
        })
        .collect()
}

/// The time range covered by both runs.
fn time_range(with: &RunResult, without: Option<&RunResult>) -> Option<(f64, f64)> {
    let ts = with
        .samples
        .iter()
        .chain(without.map(|w| w.samples.as_slice()).unwrap_or(&[]))
        .map(|s| s.t);
    min_max(ts)
}

pub(super) fn file_stem(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.chars().all(|c| c == '.') {
        "run".to_string()
    } else {
        s
    }
}

/// The error panels in grid order (row-major, 3×2): translations left, rotations right.
const ERR_AXES: [(&str, &str, usize); 6] = [
    ("x error e_x", "e_x (m)", 0),
    ("roll error e_φ", "e_φ (rad)", 3),
    ("y error e_y", "e_y (m)", 1),
    ("pitch error e_θ", "e_θ (rad)", 4),
    ("z error e_z", "e_z (m)", 2),
    ("yaw error e_ψ", "e_ψ (rad)", 5),
];

fn plot_xy(path: &Path, with: &RunResult, without: Option<&RunResult>) -> Result<()> {
    let mut p = Panel::new("", "x (m, north)", "y (m, east)");
    p.equal_aspect = true;
    if let Some(wo) = without {
        p.lines.push(Line::new(
            format!("actual, {}", wo.du_label()),
            C_WITHOUT,
            Stroke::Solid,
            wo.samples.iter().map(|s| (s.eta[0], s.eta[1])).collect(),
        ));
    }
    p.lines.push(Line::new(
        format!("actual, {}", with.du_label()),
        C_WITH,
        Stroke::Solid,
        with.samples.iter().map(|s| (s.eta[0], s.eta[1])).collect(),
    ));
    // Last, so that it stays visible on top of a run that tracks it closely.
    p.lines.push(Line::new(
        "desired η_d",
        C_DESIRED,
        Stroke::Dashed,
        with.samples
            .iter()
            .map(|s| (s.eta_d[0], s.eta_d[1]))
            .collect(),
    ));
    let title = format!("{}: path in the XY plane (equal axis scales)", with.name);
    render(path, |root| {
        figure(root, &title, with, without, (1, 1), &[p])
    })
}

fn plot_errors(path: &Path, with: &RunResult, without: Option<&RunResult>) -> Result<()> {
    let t_range = time_range(with, without);
    let panels: Vec<Panel> = ERR_AXES
        .iter()
        .map(|&(name, unit, i)| {
            let mut p = Panel::new(name, "t (s)", unit);
            p.x_range = t_range;
            if let Some(wo) = without {
                p.lines.push(Line::new(
                    wo.du_label(),
                    C_WITHOUT,
                    Stroke::Solid,
                    series(wo, |s| s.error[i]),
                ));
            }
            p.lines.push(Line::new(
                with.du_label(),
                C_WITH,
                Stroke::Solid,
                series(with, |s| s.error[i]),
            ));
            p
        })
        .collect();
    let title = format!("{}: tracking errors e = η − η_d", with.name);
    render(path, |root| {
        figure(root, &title, with, without, (3, 2), &panels)
    })
}

fn plot_payload(path: &Path, with: &RunResult, without: Option<&RunResult>) -> Result<()> {
    let mut p = Panel::new("", "t (s)", "Δm (kg)");
    p.x_range = time_range(with, without);
    p.lines.push(Line {
        label: None,
        color: C_WITH,
        stroke: Stroke::Solid,
        pts: series(with, |s| s.payload),
    });
    let title = format!("{}: payload mass variation Δm", with.name);
    render(path, |root| {
        figure(root, &title, with, without, (1, 1), &[p])
    })
}

fn plot_heading(path: &Path, with: &RunResult, without: Option<&RunResult>) -> Result<()> {
    let mut p = Panel::new("", "t (s)", "ψ (rad)");
    p.x_range = time_range(with, without);
    if let Some(wo) = without {
        p.lines.push(Line::new(
            format!("ψ {}", wo.du_label()),
            C_WITHOUT,
            Stroke::Solid,
            unwrap_angles(&series(wo, |s| s.eta[5])),
        ));
    }
    p.lines.push(Line::new(
        format!("ψ {}", with.du_label()),
        C_WITH,
        Stroke::Solid,
        unwrap_angles(&series(with, |s| s.eta[5])),
    ));
    p.lines.push(Line::new(
        "desired ψ_d",
        C_DESIRED,
        Stroke::Dashed,
        unwrap_angles(&series(with, |s| s.eta_d[5])),
    ));
    let title = format!("{}: heading ψ_d and ψ (unwrapped)", with.name);
    render(path, |root| {
        figure(root, &title, with, without, (1, 1), &[p])
    })
}

fn voltage_panel(run: &RunResult, limit: f64, t_range: Option<(f64, f64)>) -> Panel {
    let mut p = Panel::new(
        format!("thruster voltages, {}", run.du_label()),
        "t (s)",
        "voltage (V)",
    );
    p.x_range = t_range;
    for (k, (name, color)) in THRUSTER_NAMES.iter().zip(C_THRUSTERS).enumerate() {
        p.lines.push(Line::new(
            *name,
            color,
            Stroke::Solid,
            series(run, |s| s.voltage[k]),
        ));
    }
    if let (Some((t0, t1)), true) = (t_range, usable(limit) && !run.samples.is_empty()) {
        let limit = limit.abs();
        p.lines.push(Line::new(
            format!("supply limit ±{limit} V"),
            C_LIMIT,
            Stroke::Dashed,
            vec![(t0, limit), (t1, limit)],
        ));
        p.lines.push(Line::new(
            format!("supply limit ±{limit} V"),
            C_LIMIT,
            Stroke::Dashed,
            vec![(t0, -limit), (t1, -limit)],
        ));
    }
    p
}

fn plot_actuators(
    path: &Path,
    with: &RunResult,
    without: Option<&RunResult>,
    limit: f64,
) -> Result<()> {
    let t_range = time_range(with, without);
    let mut panels = vec![voltage_panel(with, limit, t_range)];
    if let Some(wo) = without {
        panels.push(voltage_panel(wo, limit, t_range));
    }
    let mut d = Panel::new(
        format!("robust gain δ(e,t), {}", with.du_label()),
        "t (s)",
        "δ",
    );
    d.x_range = t_range;
    d.lines.push(Line::new(
        "δ(e,t)",
        C_DESIRED,
        Stroke::Solid,
        series(with, |s| s.delta),
    ));
    let clamped: Vec<(f64, f64)> = with
        .samples
        .iter()
        .filter(|s| s.delta_clamped)
        .map(|s| (s.t, s.delta))
        .collect();
    if !clamped.is_empty() {
        d.lines.push(Line::new(
            "δ clamp active",
            C_WITHOUT,
            Stroke::Dots,
            clamped,
        ));
    }
    panels.push(d);
    let title = format!("{}: actuators", with.name);
    let grid = (panels.len(), 1);
    render(path, |root| {
        figure(root, &title, with, without, grid, &panels)
    })
}

type PlotFn = fn(&Path, &RunResult, Option<&RunResult>) -> Result<()>;

/// PNG plots in the manner of the paper's Figs 2–5 for one case, comparing the run with Δu
/// (`with`) and without (`without`, optional). Writes 1200×900 PNGs into `dir` (created if
/// needed), file names prefixed by `with.name` (characters other than letters, digits, `-`,
/// `_`, `.` replaced by `_`), and returns them in this order:
///  - `{name}-xy.png`: XY plane, desired vs actual (both runs if given), equal axis scaling;
///  - `{name}-errors.png`: a 3×2 grid of errors vs time, x/y/z (m) in the left column and
///    roll/pitch/yaw (rad) in the right, with and without Δu overlaid;
///  - `{name}-payload.png`: payload Δm (kg) vs time (from `with`);
///  - `{name}-heading.png`: ψ_d and ψ vs time (rad; unwrapped, so a heading wrapped to
///    (−π, π] does not jump);
///  - `{name}-actuators.png`: the five thrusters' voltages vs time, one panel per run, with
///    the supply limit dashed (the board's ±[`DEFAULT_V_LIMIT`]; [`plot_case_with_limit`] for
///    another), and δ(e,t) of `with` vs time with the periods where the δ clamp was active
///    marked.
///
/// Each figure has a title, a subtitle naming each run's outcome (red if one diverged, with
/// its time and reason), and one legend under the subtitle; time axes span both runs. NaN
/// and ±∞ values (and magnitudes beyond 1e100) are skipped, breaking the line. A panel with
/// nothing to draw (an empty run, an all-NaN signal) says "no data", and a legend entry with
/// nothing drawn says "(no data)"; the files are written in every case.
pub fn plot_case(
    dir: &Path,
    with: &RunResult,
    without: Option<&RunResult>,
) -> Result<Vec<PathBuf>> {
    plot_case_with_limit(dir, with, without, f64::from(DEFAULT_V_LIMIT))
}

/// [`plot_case`] with the supply limit (V) drawn on the voltage plots given explicitly (the
/// run's `ControllerConfig::voltage_limit`); a non-finite limit draws no limit lines.
pub fn plot_case_with_limit(
    dir: &Path,
    with: &RunResult,
    without: Option<&RunResult>,
    voltage_limit: f64,
) -> Result<Vec<PathBuf>> {
    fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut files = Vec::with_capacity(PLOTS.len());
    for (name, (_, plot)) in plot_names(&with.name).into_iter().zip(PLOTS) {
        files.push(write_plot(&dir.join(name), |path| match plot {
            Plot::Figure(f) => f(path, with, without),
            Plot::Actuators => plot_actuators(path, with, without, voltage_limit),
        })?);
    }
    Ok(files)
}

/// The figures, in the order of [`plot_case`]'s files.
enum Plot {
    Figure(PlotFn),
    Actuators,
}

const PLOTS: [(&str, Plot); 5] = [
    ("xy", Plot::Figure(plot_xy)),
    ("errors", Plot::Figure(plot_errors)),
    ("payload", Plot::Figure(plot_payload)),
    ("heading", Plot::Figure(plot_heading)),
    ("actuators", Plot::Actuators),
];

/// The file names of the plots of a run called `name`, in the order [`plot_case`] writes them.
pub fn plot_names(name: &str) -> Vec<String> {
    let stem = file_stem(name);
    PLOTS
        .iter()
        .map(|(suffix, _)| format!("{stem}-{suffix}.png"))
        .collect()
}

/// Draws into a temporary file next to `dest` and renames it into place
/// ([`super::atomic`]): a failed plot leaves no file under its name.
pub(super) fn write_plot(dest: &Path, draw: impl FnOnce(&Path) -> Result<()>) -> Result<PathBuf> {
    let ctx = || format!("writing {}", dest.display());
    let (pending, file) = Pending::create(dest).with_context(ctx)?;
    drop(file);
    draw(pending.tmp_path()).with_context(ctx)?;
    pending.commit().with_context(ctx)
}

/// Length of the zoomed command trace (s): long enough for a few reversals of a thruster that
/// follows (≤ 2 a second), short enough to see each control period of one that does not.
pub const COMMANDS_WINDOW: f64 = 2.0;

/// The file name of [`plot_commands`]' figure of a run called `name`.
pub fn commands_plot_name(name: &str) -> String {
    format!("{}-commands.png", file_stem(name))
}

/// `{name}-commands.png`: the five thrusters' voltage commands over [`COMMANDS_WINDOW`] s in
/// the middle of `run` (after the start's transient), one point per control period kept for
/// the plots (every period of a run of up to [`crate::sim::decimate::PLOT_SAMPLES`]), with the
/// ±[`DEAD_BAND`] V band a sign reversal must cross dashed (docs/real-vehicle.md#chatter): where
/// a person sees the chatter the report's figures count.
pub fn plot_commands(dir: &Path, run: &RunResult) -> Result<PathBuf> {
    let (t0, t1) = match min_max(run.samples.iter().map(|s| s.t)) {
        Some((a, b)) => {
            let mid = 0.5 * (a + b);
            let half = (0.5 * COMMANDS_WINDOW).min(0.5 * (b - a));
            (mid - half, mid + half)
        }
        None => (0.0, COMMANDS_WINDOW),
    };
    let inside: Vec<&Sample> = run
        .samples
        .iter()
        .filter(|s| s.t >= t0 && s.t <= t1)
        .collect();
    let mut p = Panel::new(
        format!(
            "thruster commands, {}, t = {t0:.2}–{t1:.2} s (one point per control period)",
            run.du_label()
        ),
        "t (s)",
        "voltage (V)",
    );
    p.x_range = Some((t0, t1));
    for (k, (name, color)) in THRUSTER_NAMES.iter().zip(C_THRUSTERS).enumerate() {
        let c = run.metrics.chatter.0[k];
        p.lines.push(Line::new(
            format!(
                "{name}: {:.1} reversals/s, {:.0} V/s",
                c.reversals_per_s, c.command_tv
            ),
            color,
            Stroke::Solid,
            inside.iter().map(|s| (s.t, s.voltage[k])).collect(),
        ));
    }
    if !inside.is_empty() {
        for v in [DEAD_BAND, -DEAD_BAND] {
            p.lines.push(Line::new(
                format!("dead band ±{DEAD_BAND} V"),
                C_LIMIT,
                Stroke::Dashed,
                vec![(t0, v), (t1, v)],
            ));
        }
    }
    let title = format!("{}: thruster commands (chatter)", run.name);
    write_plot(&dir.join(commands_plot_name(&run.name)), |path| {
        render(path, |root| figure(root, &title, run, None, (1, 1), &[p]))
    })
}
