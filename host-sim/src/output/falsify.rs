//! What `host-sim falsify` leaves on disk (docs/search.md#what-it-writes): the robustness over
//! the evaluations of both searches as a plot, and the report.

use std::path::Path;

use anyhow::Result;

use super::plot::{self, Line, Panel, Stroke, C_WITH, C_WITHOUT};
use crate::studies::falsify::{Evaluation, Method, Restart};
use crate::studies::rate_bound;

fn color(m: Method) -> plotters::style::RGBColor {
    match m {
        Method::CrossEntropy => C_WITH,
        Method::Random => C_WITHOUT,
    }
}

/// The least robustness of `method`'s restarts after each count of evaluations (the running
/// minimum of each restart, then the minimum over the restarts; NaN until one counted).
pub fn best_so_far(restarts: &[Restart], method: Method) -> Vec<f64> {
    let mine: Vec<&Restart> = restarts.iter().filter(|r| r.method == method).collect();
    let len = mine.iter().map(|r| r.trace.len()).max().unwrap_or(0);
    let mut running = vec![f64::INFINITY; mine.len()];
    (0..len)
        .map(|e| {
            for (k, r) in mine.iter().enumerate() {
                if let Some(Some(v)) = r.trace.get(e) {
                    running[k] = running[k].min(*v);
                }
            }
            let m = running.iter().copied().fold(f64::INFINITY, f64::min);
            if m.is_finite() {
                m
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// The plot: above, the least robustness found after each count of evaluations per restart,
/// for each method (0 dashed: below it, a false feasible); below, every evaluation's
/// robustness.
pub fn plot_robustness(path: &Path, restarts: &[Restart]) -> Result<()> {
    let mut best = Panel::new(
        "least robustness so far (min over restarts)",
        "evaluations per restart",
        "robustness",
    );
    let mut each = Panel::new(
        "each evaluation (candidates the preflight refused are not drawn)",
        "evaluations per restart",
        "robustness",
    );
    let mut span = 0usize;
    for m in Method::ALL {
        let b = best_so_far(restarts, m);
        span = span.max(b.len());
        best.lines.push(Line::new(
            m.name(),
            color(m),
            Stroke::Solid,
            b.iter()
                .enumerate()
                .map(|(e, v)| ((e + 1) as f64, *v))
                .collect(),
        ));
        let pts = restarts
            .iter()
            .filter(|r| r.method == m)
            .flat_map(|r| {
                r.trace
                    .iter()
                    .enumerate()
                    .filter_map(|(e, v)| v.map(|v| ((e + 1) as f64, v.max(-1.0))))
            })
            .collect();
        each.lines
            .push(Line::new(m.name(), color(m), Stroke::Dots, pts));
    }
    let zero = vec![(1.0, 0.0), (span.max(1) as f64, 0.0)];
    for p in [&mut best, &mut each] {
        p.lines.push(Line::new(
            "bound (robustness 0)",
            plot::C_LIMIT,
            Stroke::Dashed,
            zero.clone(),
        ));
    }
    plot::panel_grid(
        path,
        "host-sim falsify: robustness over the evaluations",
        (2, 1),
        &[best, each],
    )
}

/// A falsifying mission written for replay: its file name and the restart it came from.
pub struct Written {
    pub file: String,
    pub restart: usize,
}

/// The report: the spec, each method's least robustness and false feasibles, the contract's
/// statistics from this search, each restart, and each falsifying mission with the commands
/// that replay it.
pub fn report_markdown(
    spec: &crate::studies::falsify::Spec,
    restarts: &[Restart],
    missing: &[String],
    written: &[Written],
    seconds: f64,
) -> String {
    let mut s = format!(
        "# host-sim falsify\n\n\
         Candidates: the {:?} mission space (docs/search.md#the-mission-space){}, {} s at time \
         scale 1, preflight margin {}, seed {}; {} restarts of each method at {} evaluations \
         each; {:.1} s of wall time{}.\n\n",
        spec.reach,
        spec.navigation.map_or(String::new(), |p| format!(
            ", every candidate on the `{}` navigation preset",
            p.name()
        )),
        spec.duration,
        spec.margin,
        spec.seed,
        spec.restarts,
        spec.budget,
        seconds,
        if missing.is_empty() {
            String::new()
        } else {
            format!(" (**PARTIAL**: missing {})", missing.join(", "))
        }
    );
    s += &methods_table(restarts);
    s += &format!(
        "\n**The contract over this space** (the random search's flown candidates are independent \
         uniform draws of it, the cross-entropy method's are adversarial): {}.\n\n",
        counts(restarts).sentence()
    );
    s += &restarts_table(restarts, written);
    if !written.is_empty() {
        s += "\n## Replaying a falsifying mission\n\nEach file is the mission at the time scale the preflight proposed; these fly it bit for bit (metrics as the search measured them):\n\n```text\n";
        for x in written {
            s += &format!(
                "host-sim run --scenario {f}\nhost-sim pil --scenario {f}\n",
                f = x.file
            );
        }
        s += "```\n";
    }
    s += "\n![robustness over the evaluations](robustness.png)\n";
    s
}

/// The contract's counts of a search: the random search's flown candidates are the sampled
/// evaluations, the cross-entropy method's the adversarial ones.
pub fn counts(restarts: &[Restart]) -> rate_bound::Counts {
    let of = |m: Method, ff: bool| -> u64 {
        restarts
            .iter()
            .filter(|r| r.method == m)
            .map(|r| {
                r.trace
                    .iter()
                    .flatten()
                    .filter(|v| !ff || Evaluation::is_false_feasible(**v))
                    .count() as u64
            })
            .sum()
    };
    rate_bound::Counts {
        sampled: of(Method::Random, false),
        sampled_false_feasible: of(Method::Random, true),
        adversarial: of(Method::CrossEntropy, false),
        adversarial_false_feasible: of(Method::CrossEntropy, true),
    }
}

/// Per method: evaluations, counted, false feasibles, the restarts that found one, the least robustness.
fn methods_table(restarts: &[Restart]) -> String {
    let mut s = String::new();
    s += "| method | evaluations | counted (flown) | false feasible | restarts that found one | least robustness | first false feasible (evaluations into its restart) |\n|---|---:|---:|---:|---:|---:|---|\n";
    for m in Method::ALL {
        let mine: Vec<&Restart> = restarts.iter().filter(|r| r.method == m).collect();
        let evals: usize = mine.iter().map(|r| r.trace.len()).sum();
        let counted: usize = mine.iter().map(|r| r.trace.iter().flatten().count()).sum();
        let ff: usize = mine
            .iter()
            .map(|r| {
                r.trace
                    .iter()
                    .flatten()
                    .filter(|v| Evaluation::is_false_feasible(**v))
                    .count()
            })
            .sum();
        let found = mine.iter().filter(|r| r.first_falsified.is_some()).count();
        let least = mine
            .iter()
            .filter_map(|r| r.min_robustness())
            .fold(f64::INFINITY, f64::min);
        let firsts: Vec<String> = mine
            .iter()
            .filter_map(|r| r.first_falsified.map(|e| format!("r{}: {e}", r.index)))
            .collect();
        s += &format!(
            "| {} | {evals} | {counted} | {ff} | {found} of {} | {least:.4} | {} |\n",
            m.name(),
            mine.len(),
            if firsts.is_empty() {
                "—".to_string()
            } else {
                firsts.join(", ")
            }
        );
    }
    s
}

/// A row per restart: its least robustness, which limit, its falsifying mission's file.
fn restarts_table(restarts: &[Restart], written: &[Written]) -> String {
    use crate::sim::bound::LIMITS;
    let mut s = String::new();
    s += "## Restarts\n\nRobustness: per limit 1 − value / bound (docs/search.md#robustness), the least of them; below 0 the mission flew outside its bound at the scale the preflight called feasible.\n\n| method | restart | evaluations | least robustness | its limit | proposed scale | falsifying mission |\n|---|---:|---:|---:|---|---:|---|\n";
    for (i, r) in restarts.iter().enumerate() {
        let w = r.worst.as_ref();
        let limit = w.and_then(|e| {
            let t = e.terms?;
            let j = (0..4).min_by(|&a, &b| t[a].total_cmp(&t[b]))?;
            Some(LIMITS[j])
        });
        s += &format!(
            "| {} | {} | {}{} | {} | {} | {} | {} |\n",
            r.method.name(),
            r.index,
            r.trace.len(),
            if r.partial { " (partial)" } else { "" },
            r.min_robustness()
                .map_or("—".to_string(), |v| format!("{v:.4}")),
            limit.unwrap_or("—"),
            w.and_then(|e| e.proposed)
                .map_or("—".to_string(), |k| format!("{k}")),
            written
                .iter()
                .find(|x| x.restart == i)
                .map_or("—".to_string(), |x| format!("`{}`", x.file)),
        );
    }
    s
}
