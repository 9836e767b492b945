//! What `host-sim tune` leaves on disk (docs/tune.md#what-it-writes): the Pareto front as a
//! table (`front.csv`, `study.json`), its 2-D projections (`front.png`), the chosen point as
//! a `[controller]` block (`chosen.toml`) and the report.

use std::path::Path;

use anyhow::Result;
use plotters::style::RGBColor;
use serde::Serialize;

use super::plot::{self, Line, Panel, Stroke, C_WITH, C_WITHOUT};
use crate::scenario::f32_decimal;
use crate::scenario::file::ControllerTable;
use crate::studies::tune::{worst_ratio, Candidate, Study, NAMES, OBJECTIVES};

const C_CHOSEN: RGBColor = RGBColor(44, 160, 44);

/// The projections drawn: pairs of objectives (indices into [`OBJECTIVES`]).
const PAIRS: [(usize, usize); 4] = [(0, 1), (0, 4), (0, 3), (1, 4)];

/// `front.png`: the front's p95s projected on pairs of objectives, the shipped gains and the
/// chosen point marked.
pub fn plot_front(path: &Path, study: &Study) -> Result<()> {
    let panels: Vec<Panel> = PAIRS
        .iter()
        .map(|&(a, b)| {
            let mut p = Panel::new(
                format!("{} vs {} (p95)", OBJECTIVES[b], OBJECTIVES[a]),
                OBJECTIVES[a],
                OBJECTIVES[b],
            );
            let pt = |c: &Candidate| (c.scores.p95[a], c.scores.p95[b]);
            p.lines.push(Line::new(
                "Pareto front",
                C_WITH,
                Stroke::Dots,
                study.front.iter().map(pt).collect(),
            ));
            p.lines.push(Line::new(
                "shipped (paper's) gains",
                C_WITHOUT,
                Stroke::Dots,
                vec![pt(&study.shipped)],
            ));
            if let Some(c) = study.chosen.map(|i| &study.front[i]) {
                p.lines
                    .push(Line::new("chosen", C_CHOSEN, Stroke::Dots, vec![pt(c)]));
            }
            p
        })
        .collect();
    plot::panel_grid(
        path,
        "host-sim tune: the Pareto front's 2-D projections",
        (2, 2),
        &panels,
    )
}

/// `front.csv`: one row per front member (and the shipped gains first): its settings, then
/// each objective's p95 and worst, refused and failed missions, flights within the bound.
pub fn front_csv(study: &Study) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = vec!["who".into()];
    header.extend(NAMES.iter().map(|s| s.to_string()));
    for o in OBJECTIVES {
        header.push(format!("p95 {o}"));
        header.push(format!("worst {o}"));
    }
    header.extend(["refused", "failed", "within"].map(String::from));
    w.write_record(&header)?;
    let rows = std::iter::once(("shipped".to_string(), &study.shipped)).chain(
        study.front.iter().enumerate().map(|(i, c)| {
            let who = if study.chosen == Some(i) {
                format!("front-{i} (chosen)")
            } else {
                format!("front-{i}")
            };
            (who, c)
        }),
    );
    for (who, c) in rows {
        let mut r = vec![who];
        r.extend(c.gains.0.iter().map(|g| format!("{g:.6}")));
        for k in 0..OBJECTIVES.len() {
            r.push(format!("{:.6}", c.scores.p95[k]));
            r.push(format!("{:.6}", c.scores.worst[k]));
        }
        r.extend([c.scores.refused, c.scores.failed, c.scores.within].map(|n| n.to_string()));
        w.write_record(&r)?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

/// The `[controller]` block of `c`'s settings on the shipped configuration `base`.
pub fn controller_block(c: &Candidate, base: &controller_core::ControllerConfig) -> Result<String> {
    let mut cfg = *base;
    c.gains.apply(&mut cfg);
    #[derive(Serialize)]
    struct Block {
        controller: ControllerTable,
    }
    let table = ControllerTable {
        k1: Some(cfg.k1.map(f32_decimal)),
        k2: Some(cfg.k2.map(f32_decimal)),
        mu: Some(f32_decimal(cfg.mu)),
        delta_max: Some(f32_decimal(cfg.delta_max)),
        estimator_accel_sigma: Some(cfg.estimator.accel_sigma.map(f32_decimal)),
        ..ControllerTable::default()
    };
    Ok(toml::to_string(&Block { controller: table })?)
}

fn scores_row(who: &str, c: &Candidate, shipped: &Candidate) -> String {
    let s = &c.scores;
    format!(
        "| {who} | {:.4} / {:.4} | {:.2} / {:.2} | {:.1} / {:.1} | {:.4} / {:.4} | {:.3} / {:.3} | {} | {} | {:.3} |\n",
        s.p95[0], s.worst[0], s.p95[1], s.worst[1], s.p95[2], s.worst[2], s.p95[3], s.worst[3],
        s.p95[4], s.worst[4], s.refused, s.within, worst_ratio(c, shipped)
    )
}

/// The report: what was searched, the chosen point and the shipped gains scored on the same
/// sample, the chosen block, the front.
pub fn report_markdown(study: &Study, chosen_block: Option<&str>, heading: &str) -> String {
    let sp = &study.spec;
    let missions = sp.missions * crate::studies::tune::PRESETS.len();
    let mut s = format!(
        "{heading} host-sim tune\n\n\
         NSGA-II over K₁, K₂ (surge; sway/yaw; heave/pitch), μ, δ_max and the estimator's σₐ \
         factor (docs/tune.md): {} restarts × population {} × {} generations, seed {}; each \
         candidate scored on the same {missions} missions ({} random missions with their realities × \
         ideal and survey navigation, {} s at time scale 1, study-grade flight, margin {}). \
         {} evaluations ({} candidates refused by the law's conditions, never flown), {:.1} s \
         of wall time, {:.2} evaluations/s{}.\n\n",
        sp.restarts,
        sp.population,
        sp.generations,
        sp.seed,
        sp.missions,
        sp.duration,
        sp.margin,
        study.evaluations,
        study.refused_by_law,
        study.seconds,
        study.evaluations as f64 / study.seconds.max(1e-9),
        if study.missing.is_empty() {
            String::new()
        } else {
            format!(" (**PARTIAL**: missing {})", study.missing.join(", "))
        }
    );
    s += "Scores are p95 / worst over the sample; time scale: the one the preflight proposes (a refused mission counts as 100); ratio: the worst over the five p95s of (candidate + floor) / (shipped + floor), below 1 better on every one.\n\n";
    s += "| gains | max path (m) | reversals (1/s) | command TV (V/s) | saturated | time scale | refused | within bound | ratio |\n|---|---|---|---|---|---|---:|---:|---:|\n";
    s += &scores_row("shipped (paper's)", &study.shipped, &study.shipped);
    if let Some(i) = study.chosen {
        s += &scores_row("**chosen**", &study.front[i], &study.shipped);
    }
    s += "\n";
    match (study.chosen, chosen_block) {
        (Some(i), Some(b)) => {
            s += &format!(
                "The chosen point (front member {i}; its settings: {}):\n\n```toml\n{b}```\n\n",
                gains_text(&study.front[i])
            );
        }
        _ => s += "No front member qualifies as the chosen point (none without failed flights and with no more refusals than the shipped gains).\n\n",
    }
    s += &format!(
        "## The Pareto front ({} members)\n\n| # | {} | max path p95 | reversals p95 | TV p95 | saturated p95 | scale p95 |\n|---:|{}---:|---:|---:|---:|---:|\n",
        study.front.len(),
        NAMES.join(" | "),
        "---:|".repeat(NAMES.len())
    );
    for (i, c) in study.front.iter().enumerate() {
        s += &format!(
            "| {i}{} | {} | {:.4} | {:.2} | {:.1} | {:.4} | {:.3} |\n",
            if study.chosen == Some(i) { "*" } else { "" },
            c.gains
                .0
                .iter()
                .map(|g| format!("{g:.3}"))
                .collect::<Vec<_>>()
                .join(" | "),
            c.scores.p95[0],
            c.scores.p95[1],
            c.scores.p95[2],
            c.scores.p95[3],
            c.scores.p95[4],
        );
    }
    s
}

fn gains_text(c: &Candidate) -> String {
    NAMES
        .iter()
        .zip(c.gains.0)
        .map(|(n, g)| format!("{n} {g:.3}"))
        .collect::<Vec<_>>()
        .join(", ")
}
