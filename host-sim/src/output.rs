//! What a run leaves on disk: the per-period CSV, PNG plots in the manner of the paper's
//! Figs 2–5, and the Table-1 report (Markdown file and terminal text).
//!
//! Nothing here panics on data: NaN and ±∞ values (and magnitudes beyond 1e100) are skipped in
//! plots (a line is broken at them), written as `NaN`/`inf` in the CSV and in tables, and an
//! empty run gives plots that say "no data". A diverged run is always named as such, with its
//! time and reason, in plot subtitles and in the tables.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::record::{Outcome, RunResult, Sample};

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

/// The columns of [`write_csv`], in order.
pub const CSV_COLUMNS: [&str; 47] = [
    "t",
    "x",
    "y",
    "z",
    "roll",
    "pitch",
    "yaw",
    "x_d",
    "y_d",
    "z_d",
    "roll_d",
    "pitch_d",
    "yaw_d",
    "e_x",
    "e_y",
    "e_z",
    "e_roll",
    "e_pitch",
    "e_yaw",
    "tau_X",
    "tau_Y",
    "tau_Z",
    "tau_K",
    "tau_M",
    "tau_N",
    "tau_applied_X",
    "tau_applied_Y",
    "tau_applied_Z",
    "tau_applied_K",
    "tau_applied_M",
    "tau_applied_N",
    "thrust_main",
    "thrust_vert_fore",
    "thrust_vert_aft",
    "thrust_horz_fore",
    "thrust_horz_aft",
    "volt_main",
    "volt_vert_fore",
    "volt_vert_aft",
    "volt_horz_fore",
    "volt_horz_aft",
    "saturated",
    "delta",
    "delta_clamped",
    "w_norm",
    "payload",
    "status",
];

/// One CSV record for a sample, in [`CSV_COLUMNS`] order. Floats use Rust's shortest
/// round-trip formatting, so a value read back with `str::parse::<f64>` is bit-identical
/// (NaN is written `NaN`, infinities `inf`/`-inf`).
fn csv_record(s: &Sample, rec: &mut Vec<String>) {
    rec.clear();
    rec.push(s.t.to_string());
    for block in [&s.eta, &s.eta_d, &s.error, &s.tau, &s.tau_applied] {
        rec.extend(block.iter().map(f64::to_string));
    }
    for block in [&s.thrust, &s.voltage] {
        rec.extend(block.iter().map(f64::to_string));
    }
    rec.push(s.saturated.to_string());
    rec.push(s.delta.to_string());
    rec.push(u8::from(s.delta_clamped).to_string());
    rec.push(s.w_norm.to_string());
    rec.push(s.payload.to_string());
    rec.push(s.status.to_string());
}

/// Writes the per-period time series of one run as CSV, header row first. Columns
/// ([`CSV_COLUMNS`]):
/// t, x, y, z, roll, pitch, yaw, x_d, y_d, z_d, roll_d, pitch_d, yaw_d, e_x, e_y, e_z, e_roll,
/// e_pitch, e_yaw, tau_X, tau_Y, tau_Z, tau_K, tau_M, tau_N, tau_applied_X … tau_applied_N,
/// thrust_main, thrust_vert_fore, thrust_vert_aft, thrust_horz_fore, thrust_horz_aft,
/// volt_main, … (same five), saturated (bitmask integer), delta, delta_clamped (0/1), w_norm,
/// payload, status.
///
/// Units as in [`Sample`] (s, m, rad, N, N m, V, kg). The parent directory is created if
/// needed. An empty run writes the header only.
pub fn write_csv(path: &Path, run: &RunResult) -> Result<()> {
    let ctx = || format!("writing {}", path.display());
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).with_context(ctx)?;
    }
    let mut w = csv::Writer::from_path(path).with_context(ctx)?;
    w.write_record(CSV_COLUMNS).with_context(ctx)?;
    let mut rec = Vec::with_capacity(CSV_COLUMNS.len());
    for s in &run.samples {
        csv_record(s, &mut rec);
        w.write_record(&rec).with_context(ctx)?;
    }
    w.flush().with_context(ctx)?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Plots
// ---------------------------------------------------------------------------------------------

const WIDTH: u32 = 1200;
const HEIGHT: u32 = 900;
const FONT: &str = "sans-serif";
/// Chart margin and label-area sizes (pixels); the equal-aspect XY plot relies on them.
const MARGIN: u32 = 12;
const X_LABEL_AREA: u32 = 48;
const Y_LABEL_AREA: u32 = 78;
/// Values with a larger magnitude are treated like NaN in plots (a runaway would otherwise
/// squash everything else into a line, and overflow the axis arithmetic).
const PLOT_LIMIT: f64 = 1e100;

const C_WITH: RGBColor = RGBColor(31, 119, 180);
const C_WITHOUT: RGBColor = RGBColor(214, 39, 40);
const C_DESIRED: RGBColor = RGBColor(20, 20, 20);
const C_LIMIT: RGBColor = RGBColor(120, 120, 120);
const C_THRUSTERS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];
const THRUSTER_NAMES: [&str; 5] = ["main", "vert fore", "vert aft", "horz fore", "horz aft"];

/// The default supply limit (V) drawn by [`plot_case`] (AUV150.md §5, ±24 V).
pub const DEFAULT_VOLTAGE_LIMIT: f64 = controller_core::allocation::DEFAULT_V_LIMIT as f64;

fn plot_err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("plotting: {e}")
}

fn usable(v: f64) -> bool {
    v.is_finite() && v.abs() < PLOT_LIMIT
}

/// How a line is drawn.
#[derive(Clone, Copy, PartialEq)]
enum Stroke {
    Solid,
    Dashed,
    /// A dot per point, no line.
    Dots,
}

impl Stroke {
    fn style(color: RGBColor) -> ShapeStyle {
        ShapeStyle::from(color).stroke_width(2)
    }
}

struct Line {
    /// Legend text; lines with the same label share one legend entry.
    label: Option<String>,
    color: RGBColor,
    stroke: Stroke,
    pts: Vec<(f64, f64)>,
}

impl Line {
    fn new(
        label: impl Into<String>,
        color: RGBColor,
        stroke: Stroke,
        pts: Vec<(f64, f64)>,
    ) -> Self {
        Line {
            label: Some(label.into()),
            color,
            stroke,
            pts,
        }
    }
}

struct Panel {
    /// Chart caption (empty: none).
    title: String,
    x_desc: String,
    y_desc: String,
    lines: Vec<Line>,
    /// Force the x range (the time axis shared by both runs and all panels of a figure).
    x_range: Option<(f64, f64)>,
    /// Same metres per pixel on both axes.
    equal_aspect: bool,
}

impl Panel {
    fn new(title: impl Into<String>, x_desc: &str, y_desc: &str) -> Self {
        Panel {
            title: title.into(),
            x_desc: x_desc.to_string(),
            y_desc: y_desc.to_string(),
            lines: Vec::new(),
            x_range: None,
            equal_aspect: false,
        }
    }
}

/// Consecutive runs of usable points; a NaN/∞ breaks the line.
fn segments(pts: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for &(x, y) in pts {
        if usable(x) && usable(y) {
            cur.push((x, y));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// A segment that would draw as nothing: one point, or the same point repeated.
fn is_point(seg: &[(f64, f64)]) -> bool {
    seg.iter().all(|p| *p == seg[0])
}

fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    vals.filter(|v| usable(*v)).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// A non-degenerate range around [lo, hi], widened by `pad` of its span on each side.
fn padded(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let mag = lo.abs().max(hi.abs());
    let span = hi - lo;
    // Too small a span (relative or absolute) gives unreadable tick labels.
    let min_span = (mag * 1e-6).max(1e-9);
    if span < min_span {
        let half = if mag > 0.0 {
            (mag * 0.05).max(min_span)
        } else {
            1.0
        };
        let mid = 0.5 * (lo + hi);
        return (mid - half, mid + half);
    }
    (lo - pad * span, hi + pad * span)
}

/// A tick label for `v` on an axis spanning [lo, hi]: one digit finer than the tick spacing,
/// trailing zeros trimmed, no "-0", scientific for large magnitudes or very fine spacing.
fn tick_label(v: f64, lo: f64, hi: f64) -> String {
    let step = (hi - lo) / 10.0;
    if !v.is_finite() || !step.is_finite() || step <= 0.0 {
        return format!("{v}");
    }
    if v.abs() < step * 1e-6 {
        return "0".to_string();
    }
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    let mag = lo.abs().max(hi.abs());
    let e_step = step.log10().floor();
    if mag >= 1e5 || e_step < -5.0 {
        let digits = (mag.log10().floor() - e_step + 1.0).clamp(1.0, 10.0) as usize;
        let s = format!("{v:.digits$e}");
        return match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m)),
            None => s,
        };
    }
    let decimals = (1.0 - e_step).max(0.0) as usize;
    let s = trim(&format!("{v:.decimals$}"));
    if s == "-0" {
        "0".to_string()
    } else {
        s
    }
}

/// The panel's title with a centred "no data" message.
fn draw_no_data(area: &DrawingArea<BitMapBackend, Shift>, title: &str) -> Result<()> {
    let area = if title.is_empty() {
        area.clone()
    } else {
        area.titled(title, (FONT, 20)).map_err(plot_err)?
    };
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 28).into_font())
        .color(&C_LIMIT)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text("no data", &style, (w as i32 / 2, h as i32 / 2))
        .map_err(plot_err)?;
    Ok(())
}

fn draw_panel(area: &DrawingArea<BitMapBackend, Shift>, panel: &Panel) -> Result<()> {
    let all = || panel.lines.iter().flat_map(|l| l.pts.iter());
    let xs = min_max(all().filter(|p| usable(p.1)).map(|p| p.0));
    let ys = min_max(all().filter(|p| usable(p.0)).map(|p| p.1));
    let (Some(xs), Some(ys)) = (xs, ys) else {
        return draw_no_data(area, &panel.title);
    };
    let (mut x0, mut x1) = match panel.x_range {
        Some((a, b)) => padded(a, b, 0.0),
        None if panel.equal_aspect => padded(xs.0, xs.1, 0.05),
        None => padded(xs.0, xs.1, 0.0),
    };
    let (mut y0, mut y1) = padded(ys.0, ys.1, 0.05);

    if panel.equal_aspect && panel.title.is_empty() {
        // Plotting area in pixels, from the fixed margin and label-area sizes.
        let (w, h) = area.dim_in_pixel();
        let pw = f64::from(w.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1));
        let ph = f64::from(h.saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1));
        let scale = ((x1 - x0) / pw).max((y1 - y0) / ph);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        x0 = cx - 0.5 * scale * pw;
        x1 = cx + 0.5 * scale * pw;
        y0 = cy - 0.5 * scale * ph;
        y1 = cy + 0.5 * scale * ph;
    }

    let mut builder = ChartBuilder::on(area);
    builder
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, 20));
    }
    let mut chart = builder
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_err)?;
    let x_fmt = |v: &f64| tick_label(*v, x0, x1);
    let y_fmt = |v: &f64| tick_label(*v, y0, y1);
    chart
        .configure_mesh()
        .x_desc(panel.x_desc.as_str())
        .y_desc(panel.y_desc.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 17))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()
        .map_err(plot_err)?;

    for line in &panel.lines {
        let style = Stroke::style(line.color);
        let segs = segments(&line.pts);
        match line.stroke {
            Stroke::Solid => {
                chart
                    .draw_series(
                        segs.iter()
                            .filter(|s| !is_point(s))
                            .map(|s| PathElement::new(s.clone(), style)),
                    )
                    .map_err(plot_err)?;
            }
            Stroke::Dashed => {
                chart
                    .draw_series(
                        segs.iter()
                            .filter(|s| !is_point(s))
                            .map(|s| DashedPathElement::new(s.clone(), 12, 7, style)),
                    )
                    .map_err(plot_err)?;
            }
            Stroke::Dots => {}
        }
        // Dots, and an isolated point of a line (a one-sample run, a point between two NaNs,
        // a signal that does not move), which a path would not show.
        let dots = segs.iter().flat_map(|s| match line.stroke {
            Stroke::Dots => &s[..],
            _ if is_point(s) => &s[..1],
            _ => &[],
        });
        chart
            .draw_series(dots.map(|p| Circle::new(*p, 3, style.filled())))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// The sample of a legend entry, 30 px wide, starting at (x, y).
fn draw_legend_sample(
    area: &DrawingArea<BitMapBackend, Shift>,
    (x, y): (i32, i32),
    color: RGBColor,
    stroke: Stroke,
) -> Result<()> {
    let style = Stroke::style(color);
    match stroke {
        Stroke::Solid => area.draw(&PathElement::new(vec![(x, y), (x + 30, y)], style)),
        Stroke::Dashed => area.draw(&DashedPathElement::new(
            vec![(x, y), (x + 30, y)],
            8,
            5,
            style,
        )),
        Stroke::Dots => area.draw(&Circle::new((x + 15, y), 4, style.filled())),
    }
    .map_err(plot_err)
}

/// Draws one legend for the whole figure at the top of `area`, from the labelled lines of
/// `panels` (one entry per label, in order), wrapped into centred rows; returns the rest.
fn legend_strip<'b>(
    area: &DrawingArea<BitMapBackend<'b>, Shift>,
    panels: &[&Panel],
) -> Result<DrawingArea<BitMapBackend<'b>, Shift>> {
    let lines = || panels.iter().flat_map(|p| &p.lines);
    let mut entries: Vec<(String, RGBColor, Stroke)> = Vec::new();
    let mut seen: Vec<&str> = Vec::new();
    for line in lines() {
        let Some(label) = line.label.as_deref() else {
            continue;
        };
        if seen.contains(&label) {
            continue;
        }
        seen.push(label);
        // Say so when nothing of it can be drawn (an empty or all-NaN run).
        let drawn = lines()
            .filter(|l| l.label.as_deref() == Some(label))
            .flat_map(|l| &l.pts)
            .any(|p| usable(p.0) && usable(p.1));
        let text = if drawn {
            label.to_string()
        } else {
            format!("{label} (no data)")
        };
        entries.push((text, line.color, line.stroke));
    }
    if entries.is_empty() {
        return Ok(area.clone());
    }
    let font = TextStyle::from((FONT, 17).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    const SAMPLE: i32 = 30;
    const GAP: i32 = 8;
    const SPACING: i32 = 34;
    const ROW_H: i32 = 26;
    let (w, _) = area.dim_in_pixel();
    let avail = w as i32 - 40;
    // Greedy rows of (entry, width).
    let mut rows: Vec<Vec<(usize, i32)>> = vec![Vec::new()];
    let mut row_w = 0;
    for (i, e) in entries.iter().enumerate() {
        let text_w = area.estimate_text_size(&e.0, &font).map_err(plot_err)?.0 as i32;
        let ew = SAMPLE + GAP + text_w;
        let extra = if row_w == 0 { ew } else { SPACING + ew };
        if row_w > 0 && row_w + extra > avail {
            rows.push(Vec::new());
            row_w = ew;
        } else {
            row_w += extra;
        }
        if let Some(r) = rows.last_mut() {
            r.push((i, ew));
        }
    }
    for (r, row) in rows.iter().enumerate() {
        let total: i32 = row.iter().map(|e| e.1).sum::<i32>() + SPACING * (row.len() as i32 - 1);
        let mut x = (w as i32 - total) / 2;
        let y = ROW_H / 2 + 2 + r as i32 * ROW_H;
        for &(i, ew) in row {
            let (label, color, stroke) = &entries[i];
            draw_legend_sample(area, (x, y), *color, *stroke)?;
            area.draw_text(label, &font, (x + SAMPLE + GAP, y))
                .map_err(plot_err)?;
            x += ew + SPACING;
        }
    }
    let used = rows.len() as i32 * ROW_H + 6;
    Ok(area.split_vertically(used).1)
}

/// A 1200×900 PNG at `path`: `f` draws on the white root area.
fn render(
    path: &Path,
    f: impl FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<()> {
    let root = BitMapBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    f(&root)?;
    root.present().map_err(plot_err)?;
    Ok(())
}

/// Draws the figure title, a subtitle naming each run's outcome (red if one diverged), and the
/// legend of `panels`; then the panels in a `grid` (rows, columns) below.
fn figure(
    root: &DrawingArea<BitMapBackend, Shift>,
    title: &str,
    with: &RunResult,
    without: Option<&RunResult>,
    grid: (usize, usize),
    panels: &[Panel],
) -> Result<()> {
    let area = root.titled(title, (FONT, 26)).map_err(plot_err)?;
    let mut sub = format!("with Δu: {}", outcome_text(&with.outcome));
    let mut diverged = matches!(with.outcome, Outcome::Diverged { .. });
    if let Some(wo) = without {
        let _ = write!(sub, "   ·   without Δu: {}", outcome_text(&wo.outcome));
        diverged |= matches!(wo.outcome, Outcome::Diverged { .. });
    }
    if with.samples.is_empty() || without.is_some_and(|w| w.samples.is_empty()) {
        sub.push_str("   ·   (a run has no samples)");
    }
    if sub.chars().count() > 140 {
        // A long divergence reason would run off the image; the tables carry it in full.
        sub = sub.chars().take(139).chain(std::iter::once('…')).collect();
    }
    let color = if diverged { C_WITHOUT } else { C_DESIRED };
    let style = TextStyle::from((FONT, 17).into_font()).color(&color);
    let area = area.titled(&sub, style).map_err(plot_err)?;
    let refs: Vec<&Panel> = panels.iter().collect();
    let area = legend_strip(&area, &refs)?;
    for (cell, p) in area.split_evenly(grid).iter().zip(panels) {
        draw_panel(cell, p)?;
    }
    Ok(())
}

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

fn file_stem(name: &str) -> String {
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
            "actual, without Δu",
            C_WITHOUT,
            Stroke::Solid,
            wo.samples.iter().map(|s| (s.eta[0], s.eta[1])).collect(),
        ));
    }
    p.lines.push(Line::new(
        "actual, with Δu",
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
                    "without Δu",
                    C_WITHOUT,
                    Stroke::Solid,
                    series(wo, |s| s.error[i]),
                ));
            }
            p.lines.push(Line::new(
                "with Δu",
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
            "ψ without Δu",
            C_WITHOUT,
            Stroke::Solid,
            unwrap_angles(&series(wo, |s| s.eta[5])),
        ));
    }
    p.lines.push(Line::new(
        "ψ with Δu",
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

fn voltage_panel(run: &RunResult, which: &str, limit: f64, t_range: Option<(f64, f64)>) -> Panel {
    let mut p = Panel::new(
        format!("thruster voltages, {which} Δu"),
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
    let mut panels = vec![voltage_panel(with, "with", limit, t_range)];
    if let Some(wo) = without {
        panels.push(voltage_panel(wo, "without", limit, t_range));
    }
    let mut d = Panel::new("robust gain δ(e,t), with Δu", "t (s)", "δ");
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
///    the supply limit dashed ([`DEFAULT_VOLTAGE_LIMIT`]; [`plot_case_with_limit`] for
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
    plot_case_with_limit(dir, with, without, DEFAULT_VOLTAGE_LIMIT)
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
    let stem = file_stem(&with.name);
    let mut files = Vec::with_capacity(5);
    let plots: [(&str, PlotFn); 4] = [
        ("xy", plot_xy),
        ("errors", plot_errors),
        ("payload", plot_payload),
        ("heading", plot_heading),
    ];
    for (suffix, plot) in plots {
        let path = dir.join(format!("{stem}-{suffix}.png"));
        plot(&path, with, without).with_context(|| format!("writing {}", path.display()))?;
        files.push(path);
    }
    let path = dir.join(format!("{stem}-actuators.png"));
    plot_actuators(&path, with, without, voltage_limit)
        .with_context(|| format!("writing {}", path.display()))?;
    files.push(path);
    Ok(files)
}

// ---------------------------------------------------------------------------------------------
// Tables and report
// ---------------------------------------------------------------------------------------------

/// One row of a report table: a case, its run with Δu, optionally its run without Δu, and
/// optionally the paper's numbers for it.
#[derive(Clone, Copy, Debug)]
pub struct ReportRow<'a> {
    pub with: &'a RunResult,
    pub without: Option<&'a RunResult>,
    pub paper: Option<PaperRow>,
}

/// The paper's Table 1 numbers for a case (max errors, metres), each `[without, with]` Δu.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperRow {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub z: [f64; 2],
    pub path: [f64; 2],
}

/// The paper's Table 1 (AUV150.md §7) by case name: "circular-10R", "circular-20R",
/// "figure-eight-30x30", "figure-eight-40x40", "lawn-mower-20x10", "lawn-mower-30x15"; None
/// for other names.
pub fn paper_table1(case: &str) -> Option<PaperRow> {
    let row = |x: [f64; 2], y: [f64; 2], z: [f64; 2], path: [f64; 2]| PaperRow { x, y, z, path };
    Some(match case {
        "circular-10R" => row(
            [0.485, 0.020],
            [0.145, 0.002],
            [0.015, 0.001],
            [0.506, 0.022],
        ),
        "circular-20R" => row(
            [3.992, 0.021],
            [1.205, 0.002],
            [0.320, 0.011],
            [4.187, 0.023],
        ),
        "figure-eight-30x30" => row(
            [1.465, 0.031],
            [0.895, 0.002],
            [0.270, 0.003],
            [1.738, 0.031],
        ),
        "figure-eight-40x40" => row(
            [2.368, 0.036],
            [1.580, 0.003],
            [0.543, 0.001],
            [2.897, 0.036],
        ),
        "lawn-mower-20x10" => row(
            [0.746, 0.001],
            [1.491, 0.001],
            [0.391, 0.102],
            [1.712, 0.102],
        ),
        "lawn-mower-30x15" => row(
            [1.092, 0.001],
            [3.205, 0.011],
            [0.452, 0.121],
            [3.420, 0.162],
        ),
        _ => return None,
    })
}

/// "completed" or "DIVERGED at t = … s: reason".
fn outcome_text(o: &Outcome) -> String {
    match o {
        Outcome::Completed => "completed".to_string(),
        Outcome::Diverged { t, reason } => {
            let reason = reason.split_whitespace().collect::<Vec<_>>().join(" ");
            format!("DIVERGED at t = {t:.2} s: {reason}")
        }
    }
}

/// A length or angle: 3 decimals as in the paper, scientific when that would hide it.
fn fmt_err(v: f64) -> String {
    if !v.is_finite() {
        format!("{v}")
    } else if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e6) {
        format!("{v:.3}")
    } else {
        format!("{v:.2e}")
    }
}

fn fmt_fixed(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        format!("{v}")
    }
}

const TABLE_HEADER: [&str; 13] = [
    "case",
    "Δu",
    "max x (m)",
    "max y (m)",
    "max z (m)",
    "path (m)",
    "rms path (m)",
    "max roll (rad)",
    "max pitch (rad)",
    "max yaw (rad)",
    "peak |V| (V)",
    "saturated",
    "outcome",
];

/// The table's cells: per case the run without Δu (if run or if the paper has numbers), then
/// the run with Δu. Max errors read "ours (paper)".
fn table_cells(rows: &[ReportRow]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for row in rows {
        let runs = [(row.without, 0usize, false), (Some(row.with), 1usize, true)];
        for (run, col, robust) in runs {
            if run.is_none() && row.paper.is_none() {
                continue;
            }
            let mut du = if robust { "with" } else { "without" }.to_string();
            if run.is_some_and(|r| r.robust != robust) {
                let _ = write!(du, " (run.robust = {}!)", !robust);
            }
            let name = run.map_or(row.with.name.as_str(), |r| r.name.as_str());
            let m = run.map(|r| r.metrics);
            let ours_vs = |ours: Option<f64>, paper: Option<f64>| -> String {
                let ours = ours.map_or("—".to_string(), fmt_err);
                match paper {
                    Some(p) => format!("{ours} ({})", fmt_err(p)),
                    None => ours,
                }
            };
            let p = row.paper;
            let ours = |f: fn(&crate::record::Metrics) -> f64| m.as_ref().map(f);
            let other = |f: fn(&crate::record::Metrics) -> f64, fmt: &dyn Fn(f64) -> String| {
                m.as_ref().map_or("—".to_string(), |m| fmt(f(m)))
            };
            out.push(vec![
                name.to_string(),
                du,
                ours_vs(ours(|m| m.max_x), p.map(|p| p.x[col])),
                ours_vs(ours(|m| m.max_y), p.map(|p| p.y[col])),
                ours_vs(ours(|m| m.max_z), p.map(|p| p.z[col])),
                ours_vs(ours(|m| m.max_path), p.map(|p| p.path[col])),
                other(|m| m.rms_path, &fmt_err),
                other(|m| m.max_roll, &fmt_err),
                other(|m| m.max_pitch, &fmt_err),
                other(|m| m.max_yaw, &fmt_err),
                other(|m| m.peak_voltage, &|v| fmt_fixed(v, 1)),
                other(|m| m.saturated_fraction, &|v| {
                    format!("{} %", fmt_fixed(100.0 * v, 1))
                }),
                run.map_or("not run".to_string(), |r| outcome_text(&r.outcome)),
            ]);
        }
    }
    out
}

fn md_escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('|', "\\|")
}

/// Markdown table: per case one row without Δu and one with, each giving x, y, z and path max
/// errors as "ours (paper)" (the paper's value only where [`ReportRow::paper`] is given), rms
/// path, max roll/pitch/yaw error, peak voltage, saturated fraction, and the outcome (a
/// diverged run says "DIVERGED at t = … s: reason"). A missing `without` run with paper
/// numbers gets a row with "—" and "not run".
pub fn table_markdown(rows: &[ReportRow]) -> String {
    let mut s = String::new();
    let line = |cells: &mut dyn Iterator<Item = String>| {
        let mut l = String::from("|");
        for c in cells {
            l.push(' ');
            l.push_str(&c);
            l.push_str(" |");
        }
        l.push('\n');
        l
    };
    s.push_str(&line(&mut TABLE_HEADER.iter().map(|h| md_escape(h))));
    s.push_str(&line(&mut TABLE_HEADER.iter().enumerate().map(|(i, _)| {
        if i < 2 || i == TABLE_HEADER.len() - 1 {
            "---".to_string()
        } else {
            "---:".to_string()
        }
    })));
    for row in table_cells(rows) {
        s.push_str(&line(&mut row.iter().map(|c| md_escape(c))));
    }
    s
}

/// The same table as [`table_markdown`] for the terminal: plain text, columns aligned (by
/// characters), numbers right-aligned, and a line saying what the parentheses hold when any
/// row has the paper's numbers.
pub fn table_text(rows: &[ReportRow]) -> String {
    let header: Vec<String> = TABLE_HEADER.iter().map(|h| h.to_string()).collect();
    let body = table_cells(rows);
    let n = header.len();
    let width = |i: usize| {
        std::iter::once(&header)
            .chain(&body)
            .map(|r| r[i].chars().count())
            .max()
            .unwrap_or(0)
    };
    let widths: Vec<usize> = (0..n).map(width).collect();
    let fmt_row = |r: &[String]| {
        let mut l = String::new();
        for (i, c) in r.iter().enumerate() {
            if i > 0 {
                l.push_str("  ");
            }
            let pad = widths[i].saturating_sub(c.chars().count());
            let numeric = (2..n - 1).contains(&i);
            if numeric {
                l.extend(std::iter::repeat_n(' ', pad));
                l.push_str(c);
            } else {
                l.push_str(c);
                l.extend(std::iter::repeat_n(' ', pad));
            }
        }
        l.truncate(l.trim_end().len());
        l.push('\n');
        l
    };
    let mut s = fmt_row(&header);
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
    s.push_str(&fmt_row(&rule));
    for r in &body {
        s.push_str(&fmt_row(r));
    }
    if rows.iter().any(|r| r.paper.is_some()) {
        s.push_str("max errors as ours (paper's Table 1, AUV150.md §7)\n");
    }
    s
}

/// A Markdown link target for `plot`: relative to `dir` when it lies inside it (compared as
/// given, then canonicalised), else the path as given.
fn link_target(dir: &Path, plot: &Path) -> String {
    let canonical = || {
        let (d, p) = (dir.canonicalize().ok()?, plot.canonicalize().ok()?);
        p.strip_prefix(d).ok().map(Path::to_path_buf)
    };
    let rel = match plot.strip_prefix(dir) {
        Ok(r) => r.to_path_buf(),
        Err(_) => canonical().unwrap_or_else(|| plot.to_path_buf()),
    };
    let s = rel.to_string_lossy().replace('\\', "/");
    if s.contains([' ', '(', ')', '<', '>']) {
        format!("<{s}>")
    } else {
        s
    }
}

/// Writes `dir/report.md` (creating `dir`): `# title`, a line on how to read the table,
/// a warning if any run diverged, [`table_markdown`], each plot embedded as
/// `![file](path)` (relative to `dir` when inside it) under its file name, and `notes`
/// verbatim under "## Notes" (omitted if empty). Returns the report's path.
pub fn write_report(
    dir: &Path,
    title: &str,
    rows: &[ReportRow],
    plots: &[PathBuf],
    notes: &str,
) -> Result<PathBuf> {
    let path = dir.join("report.md");
    let mut s = String::new();
    let _ = writeln!(s, "# {title}\n");
    s.push_str(
        "Maximum errors over each run in metres as **ours (paper)**, the paper's numbers from \
         its Table 1 (AUV150.md §7) where the case is one of its six; path = \
         √(max|e_x|² + max|e_y|² + max|e_z|²), rms path = √mean(e_x² + e_y² + e_z²). Angles in \
         rad. Peak |V| is the largest thruster voltage commanded; saturated is the fraction of \
         control periods with at least one thruster at the supply limit.\n\n",
    );
    let diverged: Vec<String> = rows
        .iter()
        .flat_map(|r| std::iter::once(r.with).chain(r.without))
        .filter_map(|r| match &r.outcome {
            Outcome::Diverged { .. } => Some(format!(
                "{} ({} Δu): {}",
                r.name,
                if r.robust { "with" } else { "without" },
                outcome_text(&r.outcome)
            )),
            Outcome::Completed => None,
        })
        .collect();
    if !diverged.is_empty() {
        let _ = writeln!(
            s,
            "**Warning: {} run(s) diverged** — their metrics cover only the time before \
             they stopped:\n",
            diverged.len()
        );
        for d in &diverged {
            let _ = writeln!(s, "- {}", md_escape(d));
        }
        s.push('\n');
    }
    s.push_str(&table_markdown(rows));
    if !plots.is_empty() {
        s.push_str("\n## Plots\n");
        for p in plots {
            let name = p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let _ = write!(s, "\n### {name}\n\n![{name}]({})\n", link_target(dir, p));
        }
    }
    if !notes.is_empty() {
        let _ = write!(s, "\n## Notes\n\n{notes}");
        if !notes.ends_with('\n') {
            s.push('\n');
        }
    }
    fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    fs::write(&path, s).with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}
