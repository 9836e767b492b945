//! Two flights compared field by field (docs/logs.md#comparing-two-flights): for every series
//! of either, the largest difference at the times both have, the first time they differ
//! beyond the tolerance, and the times one has and the other does not.
//!
//! **Choice 355:** two values differ beyond the tolerance when |a − b| > abs + rel·max(|a|,
//! |b|); NaN equals NaN and differs from any number; two texts differ when they are not equal.
//! A series only one flight has, or a time only one has, is a difference at its first such
//! time. The flight's first divergence is the earliest over every series (ties: the series
//! that differs most, relative to its size, is named).

use std::path::Path;

use super::read::{Flight, Point, Series};
use crate::output::plot::{self, Line, Panel, Stroke, C_WITH, C_WITHOUT};

/// The tolerance of [`compare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub abs: f64,
    pub rel: f64,
}

impl Tolerance {
    /// Identical flights, bit for bit, up to the decimal a log writes (none).
    pub const EXACT: Tolerance = Tolerance { abs: 0.0, rel: 0.0 };

    fn allows(&self, a: f64, b: f64) -> bool {
        if a.is_nan() || b.is_nan() {
            return a.is_nan() && b.is_nan();
        }
        (a - b).abs() <= self.abs + self.rel * a.abs().max(b.abs())
    }
}

/// How one series differs between the flights.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesDiff {
    /// `"{channel} {field}"`.
    pub name: String,
    /// The largest |a − b| at a time both have (∞ for a NaN against a number or two texts
    /// that differ), and that time (s).
    pub max: f64,
    pub max_at: Option<f64>,
    /// The largest |a − b| relative to the series' largest magnitude (its ranking).
    pub relative: f64,
    /// The first time (s) they differ beyond the tolerance, if they do.
    pub first: Option<f64>,
    /// Times one flight has and the other does not.
    pub unmatched: usize,
    /// `Some("A")`/`Some("B")`: only that flight has the series.
    pub only_in: Option<&'static str>,
}

impl SeriesDiff {
    pub fn differs(&self) -> bool {
        self.first.is_some()
    }
}

/// Every series of either flight compared, in name order.
pub fn compare(a: &Flight, b: &Flight, tol: Tolerance) -> Vec<SeriesDiff> {
    let names: std::collections::BTreeSet<&String> =
        a.series.keys().chain(b.series.keys()).collect();
    names
        .into_iter()
        .map(|name| match (a.series.get(name), b.series.get(name)) {
            (Some(sa), Some(sb)) => series_diff(name, sa, sb, tol),
            (Some(s), None) | (None, Some(s)) => SeriesDiff {
                name: name.clone(),
                max: f64::INFINITY,
                max_at: None,
                relative: f64::INFINITY,
                first: s.times.first().map(|&t| t as f64 * 1e-9),
                unmatched: s.times.len(),
                only_in: Some(if a.series.contains_key(name) {
                    "A"
                } else {
                    "B"
                }),
            },
            (None, None) => unreachable!("a name of one of the two maps"),
        })
        .collect()
}

fn series_diff(name: &str, a: &Series, b: &Series, tol: Tolerance) -> SeriesDiff {
    let mut d = SeriesDiff {
        name: name.to_string(),
        max: 0.0,
        max_at: None,
        relative: 0.0,
        first: None,
        unmatched: 0,
        only_in: None,
    };
    let mut scale = 0.0f64;
    let (mut i, mut j) = (0, 0);
    let first = |d: &mut SeriesDiff, t: u64| {
        let t = t as f64 * 1e-9;
        if d.first.is_none_or(|f| t < f) {
            d.first = Some(t);
        }
    };
    while i < a.times.len() || j < b.times.len() {
        let (ta, tb) = (a.times.get(i), b.times.get(j));
        match (ta, tb) {
            (Some(&x), Some(&y)) if x == y => {
                let gap = match (&a.values[i], &b.values[j]) {
                    (Point::Num(p), Point::Num(q)) => {
                        scale = scale.max(p.abs()).max(q.abs());
                        if tol.allows(*p, *q) {
                            (p - q).abs()
                        } else {
                            first(&mut d, x);
                            if p.is_nan() || q.is_nan() {
                                f64::INFINITY
                            } else {
                                (p - q).abs()
                            }
                        }
                    }
                    (p, q) if p == q => 0.0,
                    _ => {
                        first(&mut d, x);
                        f64::INFINITY
                    }
                };
                if gap > d.max || (gap > 0.0 && d.max_at.is_none()) {
                    d.max = gap;
                    d.max_at = Some(x as f64 * 1e-9);
                }
                i += 1;
                j += 1;
            }
            (Some(&x), Some(&y)) => {
                d.unmatched += 1;
                first(&mut d, x.min(y));
                if x < y {
                    i += 1;
                } else {
                    j += 1;
                }
            }
            (Some(&x), None) | (None, Some(&x)) => {
                d.unmatched += 1;
                first(&mut d, x);
                if ta.is_some() {
                    i += 1;
                } else {
                    j += 1;
                }
            }
            (None, None) => break,
        }
    }
    d.relative = if scale > 0.0 {
        d.max / scale
    } else if d.max > 0.0 {
        f64::INFINITY
    } else {
        0.0
    };
    d
}

/// The series that first differs beyond the tolerance (ties: the one that differs most,
/// relative to its size), if any does.
pub fn first_divergence(diffs: &[SeriesDiff]) -> Option<&SeriesDiff> {
    diffs.iter().filter(|d| d.differs()).min_by(|x, y| {
        let (tx, ty) = (
            x.first.unwrap_or(f64::INFINITY),
            y.first.unwrap_or(f64::INFINITY),
        );
        tx.total_cmp(&ty).then(y.relative.total_cmp(&x.relative))
    })
}

/// The series that differ, those that differ most (relative to their size) first.
pub fn ranked(diffs: &[SeriesDiff]) -> Vec<&SeriesDiff> {
    let mut v: Vec<&SeriesDiff> = diffs.iter().filter(|d| d.differs()).collect();
    v.sort_by(|x, y| {
        y.relative
            .total_cmp(&x.relative)
            .then(x.first.unwrap_or(0.0).total_cmp(&y.first.unwrap_or(0.0)))
    });
    v
}

/// How many series the plot of [`plot_most_different`] shows.
pub const PLOTTED_SERIES: usize = 4;

/// A PNG at `path` of the numeric series that differ most (up to [`PLOTTED_SERIES`]), A and B
/// over time, each in its panel.
pub fn plot_most_different(
    path: &Path,
    a: &Flight,
    b: &Flight,
    diffs: &[SeriesDiff],
) -> anyhow::Result<()> {
    let pts = |s: Option<&Series>| -> Vec<(f64, f64)> {
        s.map(|s| {
            s.times
                .iter()
                .zip(&s.values)
                .filter_map(|(t, v)| match v {
                    Point::Num(x) => Some((*t as f64 * 1e-9, *x)),
                    Point::Text(_) => None,
                })
                .collect()
        })
        .unwrap_or_default()
    };
    let panels: Vec<Panel> = ranked(diffs)
        .into_iter()
        .filter(|d| {
            !pts(a.series.get(&d.name)).is_empty() || !pts(b.series.get(&d.name)).is_empty()
        })
        .take(PLOTTED_SERIES)
        .map(|d| {
            let mut p = Panel::new(
                format!(
                    "{}: max |A − B| {:.3e}, first beyond tolerance at t = {:.3} s",
                    d.name,
                    d.max,
                    d.first.unwrap_or(f64::NAN)
                ),
                "t (s)",
                &d.name,
            );
            p.lines.push(Line::new(
                "A",
                C_WITH,
                Stroke::Solid,
                pts(a.series.get(&d.name)),
            ));
            p.lines.push(Line::new(
                "B",
                C_WITHOUT,
                Stroke::Dashed,
                pts(b.series.get(&d.name)),
            ));
            p
        })
        .collect();
    let rows = panels.len().max(1);
    plot::panel_grid(
        path,
        "host-sim diff: the series that differ most",
        (rows, 1),
        &panels,
    )
}
