//! The plotting layer over `plotters`: panels of lines on a 1200×900 PNG, with NaN-safe
//! ranges, readable tick labels, one legend per figure, and a figure frame (title, a subtitle
//! naming each run's outcome, the legend, a grid of panels). What to draw is
//! [`super::figures`]'s.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{anyhow, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::sim::{Outcome, RunResult};

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

pub(super) const C_WITH: RGBColor = RGBColor(31, 119, 180);
pub(super) const C_WITHOUT: RGBColor = RGBColor(214, 39, 40);
pub(super) const C_DESIRED: RGBColor = RGBColor(20, 20, 20);
pub(super) const C_LIMIT: RGBColor = RGBColor(120, 120, 120);
fn plot_err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("plotting: {e}")
}

pub(super) fn usable(v: f64) -> bool {
    v.is_finite() && v.abs() < PLOT_LIMIT
}

/// How a line is drawn.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Stroke {
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

pub(super) struct Line {
    /// Legend text; lines with the same label share one legend entry.
    pub label: Option<String>,
    pub color: RGBColor,
    pub stroke: Stroke,
    pub pts: Vec<(f64, f64)>,
}

impl Line {
    pub fn new(
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

pub(super) struct Panel {
    /// Chart caption (empty: none).
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub lines: Vec<Line>,
    /// Force the x range (the time axis shared by both runs and all panels of a figure).
    pub x_range: Option<(f64, f64)>,
    /// Same metres per pixel on both axes.
    pub equal_aspect: bool,
    /// Text written beside points of the data (a waypoint's number): (x, y, text).
    pub labels: Vec<(f64, f64, String)>,
}

impl Panel {
    pub fn new(title: impl Into<String>, x_desc: &str, y_desc: &str) -> Self {
        Panel {
            title: title.into(),
            x_desc: x_desc.to_string(),
            y_desc: y_desc.to_string(),
            lines: Vec::new(),
            x_range: None,
            equal_aspect: false,
            labels: Vec::new(),
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

pub(super) fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
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
    let Some(((x0, x1), (y0, y1))) = panel_ranges(area, panel) else {
        return draw_no_data(area, &panel.title);
    };
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
        draw_line(&mut chart, line)?;
    }
    let font = TextStyle::from((FONT, 17).into_font()).color(&C_DESIRED);
    chart
        .draw_series(
            panel
                .labels
                .iter()
                .filter(|(x, y, _)| usable(*x) && usable(*y))
                .map(|(x, y, text)| {
                    // Up and right of the point, clear of a marker drawn on it.
                    EmptyElement::at((*x, *y)) + Text::new(text.clone(), (7, -20), font.clone())
                }),
        )
        .map_err(plot_err)?;
    Ok(())
}

/// The panel's x and y ranges: its data's, padded (an equal-aspect panel widened to the
/// plotting area's aspect), or `None` without a usable point.
#[allow(clippy::type_complexity)]
fn panel_ranges(
    area: &DrawingArea<BitMapBackend, Shift>,
    panel: &Panel,
) -> Option<((f64, f64), (f64, f64))> {
    let all = || panel.lines.iter().flat_map(|l| l.pts.iter());
    let xs = min_max(all().filter(|p| usable(p.1)).map(|p| p.0))?;
    let ys = min_max(all().filter(|p| usable(p.0)).map(|p| p.1))?;
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
    Some(((x0, x1), (y0, y1)))
}

/// One line of a panel: its path (solid or dashed), its dots, and any isolated point.
fn draw_line(
    chart: &mut ChartContext<BitMapBackend, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    line: &Line,
) -> Result<()> {
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
pub(super) fn render(
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
pub(super) fn figure(
    root: &DrawingArea<BitMapBackend, Shift>,
    title: &str,
    with: &RunResult,
    without: Option<&RunResult>,
    grid: (usize, usize),
    panels: &[Panel],
) -> Result<()> {
    let area = root.titled(title, (FONT, 26)).map_err(plot_err)?;
    // A run's outcome, and the periods its thrusters were off, if any.
    let state = |r: &RunResult| {
        let mut s = format!("{}: {}", r.du_label(), r.outcome);
        if !r.faults.is_empty() {
            let _ = write!(s, ", fail-safe in {} periods", r.faults.total());
        }
        s
    };
    let alarming =
        |r: &RunResult| !matches!(r.outcome, Outcome::Completed) || r.faulted_unexpectedly();
    let mut sub = state(with);
    let mut diverged = alarming(with);
    if let Some(wo) = without {
        let _ = write!(sub, "   ·   {}", state(wo));
        diverged |= alarming(wo);
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

/// A 1200×900 PNG at `path` of `panels` in a `grid` (rows, columns) under `title`, without a
/// run's subtitle or legend (a campaign's histograms and scatter plots).
pub(super) fn panel_grid(
    path: &Path,
    title: &str,
    grid: (usize, usize),
    panels: &[Panel],
) -> Result<()> {
    render(path, |root| {
        let area = root.titled(title, (FONT, 24)).map_err(plot_err)?;
        for (cell, p) in area.split_evenly(grid).iter().zip(panels) {
            draw_panel(cell, p)?;
        }
        Ok(())
    })
}

/// A 1200×900 PNG at `path` of `panels` in a `grid` (rows, columns) under `title`, each with
/// its own legend above it (the views of a layout: `output::log::views`).
pub(super) fn panel_grid_with_legends(
    path: &Path,
    title: &str,
    grid: (usize, usize),
    panels: &[Panel],
) -> Result<()> {
    render(path, |root| {
        let area = root.titled(title, (FONT, 24)).map_err(plot_err)?;
        for (cell, p) in area.split_evenly(grid).iter().zip(panels) {
            let cell = legend_strip(cell, &[p])?;
            draw_panel(&cell, p)?;
        }
        Ok(())
    })
}

/// A 1200×900 PNG at `path` of one `panel` under `title`, with its legend (no run subtitle: a
/// plot of the mission, not of a run).
pub(super) fn panel_with_legend(path: &Path, title: &str, panel: &Panel) -> Result<()> {
    render(path, |root| {
        let area = root.titled(title, (FONT, 24)).map_err(plot_err)?;
        let area = legend_strip(&area, &[panel])?;
        draw_panel(&area, panel)
    })
}

/// One row of [`rows_with_legend`]: its share of the height, and its panels left to right,
/// each with its share of the width.
pub(super) struct Row<'p> {
    pub share: f64,
    pub cells: Vec<(f64, &'p Panel)>,
}

/// Splits `area` into parts of `shares` (their sum is the whole), along x (`across`) or y.
fn split_shares<'b>(
    area: &DrawingArea<BitMapBackend<'b>, Shift>,
    shares: &[f64],
    across: bool,
) -> Vec<DrawingArea<BitMapBackend<'b>, Shift>> {
    let (w, h) = area.dim_in_pixel();
    let size = f64::from(if across { w } else { h });
    let total: f64 = shares.iter().sum();
    let mut at = 0.0;
    let cuts: Vec<i32> = shares
        .iter()
        .take(shares.len().saturating_sub(1))
        .map(|s| {
            at += s / total;
            (size * at).round() as i32
        })
        .collect();
    match across {
        true => area.split_by_breakpoints(&cuts, &[] as &[i32]),
        false => area.split_by_breakpoints(&[] as &[i32], &cuts),
    }
}

/// A 1200×900 PNG at `path` of panels in `rows` (top to bottom, each split left to right)
/// under `title`, with one legend for all of them (no run subtitle: a plot of a mission).
pub(super) fn rows_with_legend(path: &Path, title: &str, rows: &[Row]) -> Result<()> {
    render(path, |root| {
        let area = root.titled(title, (FONT, 24)).map_err(plot_err)?;
        let refs: Vec<&Panel> = rows
            .iter()
            .flat_map(|r| r.cells.iter().map(|c| c.1))
            .collect();
        let area = legend_strip(&area, &refs)?;
        let heights: Vec<f64> = rows.iter().map(|r| r.share).collect();
        for (row, strip) in rows.iter().zip(split_shares(&area, &heights, false)) {
            let widths: Vec<f64> = row.cells.iter().map(|c| c.0).collect();
            for ((_, panel), cell) in row.cells.iter().zip(split_shares(&strip, &widths, true)) {
                draw_panel(&cell, panel)?;
            }
        }
        Ok(())
    })
}
