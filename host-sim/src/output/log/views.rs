//! host-sim's own drawing of a Foxglove layout's plot panels from a flight
//! (docs/logs.md#layouts, **Choice 383**): each `Plot` panel of the layout is drawn from the
//! flight's series it names (a message path `/topic.field.member`), over time or, for a panel
//! with a custom x axis, one path against another (`examples/layout_views.rs`): the layout's
//! views from a real log without a browser; the README's picture is Foxglove's own
//! (`scripts/viewer-screenshot.sh`, Choice 482). Text panels (state transitions) are not drawn.

use std::path::Path;

use anyhow::{anyhow, Result};
use plotters::style::RGBColor;
use serde_json::Value;

use super::read::{Flight, Point, Series};
use super::schema::CHANNELS;
use crate::output::plot::{self, Line, Panel, Stroke};

/// Line colours, in a panel's path order.
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(23, 190, 207),
];

/// The flight's series of a Foxglove message path (`/plant/truth.eta.x` → `/plant/truth
/// eta.x`): the longest channel topic that prefixes it.
fn series<'f>(flight: &'f Flight, path: &str) -> Option<&'f Series> {
    let topic = CHANNELS
        .iter()
        .map(|c| c.topic)
        .filter(|t| path.strip_prefix(t).is_some_and(|r| r.starts_with('.')))
        .max_by_key(|t| t.len())?;
    flight
        .series
        .get(&format!("{topic} {}", &path[topic.len() + 1..]))
}

fn numbers(s: &Series) -> impl Iterator<Item = (u64, f64)> + '_ {
    s.times.iter().zip(&s.values).map(|(&t, v)| match v {
        Point::Num(x) => (t, *x),
        Point::Text(_) => (t, f64::NAN),
    })
}

/// One layout panel as a plot panel, or `None` when the flight has none of its series.
fn panel(config: &Value, flight: &Flight) -> Option<Panel> {
    let title = config["title"].as_str().unwrap_or("");
    let x_path = (config["xAxisVal"] == "custom")
        .then(|| config["xAxisPath"]["value"].as_str())
        .flatten();
    let x_series = x_path.and_then(|p| series(flight, p));
    let mut p = Panel::new(title, x_path.unwrap_or("t (s)"), "");
    for (i, path) in config["paths"].as_array()?.iter().enumerate() {
        let Some(y) = path["value"].as_str().and_then(|v| series(flight, v)) else {
            continue;
        };
        let pts: Vec<(f64, f64)> = match x_series {
            // One path against the other, at the times both have.
            Some(x) => {
                let xs: std::collections::BTreeMap<u64, f64> = numbers(x).collect();
                numbers(y)
                    .filter_map(|(t, v)| xs.get(&t).map(|&u| (u, v)))
                    .collect()
            }
            None => numbers(y).map(|(t, v)| (t as f64 * 1e-9, v)).collect(),
        };
        let label = path["label"].as_str().unwrap_or("").to_string();
        let stroke = if y.times.len() * 10 < flight_periods(flight) {
            // A source at a low rate: its samples, not a line between them.
            Stroke::Dots
        } else {
            Stroke::Solid
        };
        p.lines
            .push(Line::new(label, PALETTE[i % PALETTE.len()], stroke, pts));
    }
    (!p.lines.is_empty()).then_some(p)
}

/// The number of control periods of the flight (its `/law` messages).
fn flight_periods(flight: &Flight) -> usize {
    flight
        .series
        .get("/law lyapunov")
        .map_or(0, |s| s.times.len())
}

/// Draws every `Plot` panel of the Foxglove layout `layout` that `flight` has data for, in a
/// grid, as a PNG at `path`; returns the titles of the panels left out (no data: a SIL
/// flight has no board).
pub fn draw(layout: &Value, flight: &Flight, title: &str, path: &Path) -> Result<Vec<String>> {
    let configs = layout["configById"]
        .as_object()
        .ok_or_else(|| anyhow!("the layout has no configById"))?;
    let mut ids = Vec::new();
    in_layout_order(&layout["layout"], &mut ids);
    let mut panels = Vec::new();
    let mut left_out = Vec::new();
    for id in ids.into_iter().filter(|id| id.starts_with("Plot!")) {
        let Some(config) = configs.get(id) else {
            continue;
        };
        match panel(config, flight) {
            Some(p) => panels.push(p),
            None => left_out.push(config["title"].as_str().unwrap_or(id).to_string()),
        }
    }
    let cols = 3;
    let rows = panels.len().div_ceil(cols).max(1);
    plot::panel_grid_with_legends(path, title, (rows, cols), &panels)?;
    Ok(left_out)
}

/// The panel ids of a Foxglove layout tree (a panel's id, or a split of `first` and
/// `second`), first to last.
fn in_layout_order<'l>(node: &'l Value, out: &mut Vec<&'l str>) {
    match node {
        Value::String(id) => out.push(id),
        Value::Object(split) => {
            in_layout_order(&split["first"], out);
            in_layout_order(&split["second"], out);
        }
        _ => {}
    }
}
