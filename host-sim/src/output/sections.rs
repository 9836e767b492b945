//! Report sections built from the studies' and the board's results: the preflight verdicts,
//! the real vehicle's introduction, and the board against SIL.

use auv_link::NOT_AUV150;
use controller_core::effectiveness::Mounting;

use crate::board::{BoardComparison, Mode};
use crate::sim::RunResult;
use crate::studies::preflight::{Preflight, DEFAULT_MARGIN};

/// What the report says about the real-vehicle table.
pub const REAL_NOTES: &str = "\
## The real vehicle (docs/real-vehicle.md#the-real-missions)

The missions of `scenarios/real/` fly the Table-1 paths as a vehicle team would: heading along
the course, the Table-3 payload trimmed to neutral buoyancy, Eqs 31–32 in kgf, and the real
actuator chain (the board's voltages, clamped at ±24 V, turned back into thrust by Eqs 31–32),
each at the time scale the preflight check proposes; then missions planned as waypoints, on
the speed profile the check proposes (docs/missions.md#the-speed-profile): `survey-200x100`, a 200 m × 100 m
lawn-mower at 5 m depth, `harbour-wall`, a descending inspection, and `pipeline`, a pipeline
route descending from 4 m to 10 m, both imported from QGroundControl plans; each with its path
over the waypoints and its speed over time among the plots. Below them, the
paper's own six missions
(its headings, untrimmed payload, time scale 1) through the same real chain: what the preflight
calls infeasible, flown anyway.
";

/// The report section of preflight verdicts: one line each.
pub fn preflight<'a>(
    checks: &[Preflight],
    runs: impl IntoIterator<Item = &'a RunResult>,
) -> String {
    let mut s = format!(
        "## Preflight (docs/real-vehicle.md#preflight-feasibility)\n\nWhether the real thrusters can fly each mission \
         (`host-sim check --scenario FILE`): the force the reference needs along the path at \
         the attitude the vehicle holds (heel, pitch offset), through the board's allocator, \
         against {:.0} % of each thruster's envelope; for the mission as written (its payload \
         and current), and over the whole configured parameter box.\n\n",
        100.0 * DEFAULT_MARGIN
    );
    for c in checks {
        s.push_str(&format!("- {}\n", c.to_string().replace('|', "\\|")));
    }
    let broken: Vec<String> = runs
        .into_iter()
        .filter(|r| r.missed())
        .filter_map(|r| {
            let c = checks.iter().find(|c| c.name == r.name && c.feasible())?;
            Some(format!(
                "- {} ({}): the preflight said FEASIBLE at time scale {}, and the run {}\n",
                r.name,
                r.du_label(),
                c.time_scale,
                r.outcome
            ))
        })
        .collect();
    if !broken.is_empty() {
        s += &format!(
            "\n**The preflight's verdict did not hold for {} run(s)** (called feasible, missed \
             the bound when flown):\n\n{}",
            broken.len(),
            broken.concat()
        );
    }
    s
}

/// The report's PIL-vs-SIL section (HIL's too), and the timing of real-time runs.
pub fn board_vs_sil(cases: &[BoardComparison]) -> String {
    let mut notes = String::from(
        "## Board in the loop vs software in the loop\n\n\
         | case | link | pacing | board max path (m) | SIL max path (m) | board − SIL (m) | frames/s | \
         worst update (PIL: instructions; HIL: board timer ticks) | fail-safe events | re-arms | signed | board drops (old / auth) | \
         board refusals | board's mounting (strong side) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cases {
        notes += &format!(
            "| {} | {} | {} | {} | {} | {} | {:.0} | {} | {} | {} | {} | {} / {} | {} | {} |\n",
            c.run.name,
            c.pil.link,
            c.pil.pacing.as_str(),
            // A run that recorded no period has no metric (NaN, Choice 129).
            metric(c.run.metrics.max_path, |v| format!("{v:.5}")),
            metric(c.sil_max_path, |v| format!("{v:.5}")),
            metric(c.pil_minus_sil_max_path, |v| format!("{v:+.2e}")),
            c.pil.frames_per_second,
            match c.mode {
                Mode::Pil => c.pil.worst_update_instructions,
                // The board's own unit: QEMU's SysTick counts, the STM32's CPU cycles.
                Mode::Hil => c.pil.worst_update_board_ticks,
            },
            c.pil.failsafe_events.len(),
            c.pil.rearms,
            if c.pil.signed { "yes" } else { "no" },
            c.pil.board_rx_stale,
            c.pil.board_rx_auth_errors,
            match &c.pil.board_last_refusal {
                Some(r) => format!("{} (last: {r})", c.pil.board_refused_commands),
                None => c.pil.board_refused_commands.to_string(),
            },
            match c.pil.board_reversed_thrusters {
                Some(NOT_AUV150) => "not the AUV-150 layout".to_string(),
                Some(mask) => Mounting(mask).to_string(),
                None => "—".to_string(),
            },
        );
    }
    let uploads: Vec<_> = cases
        .iter()
        .filter_map(|c| c.pil.upload.as_ref().map(|u| (c, u)))
        .collect();
    if !uploads.is_empty() {
        notes += "\n### Mission uploads (docs/link.md#the-mission-upload)\n\n";
        for (c, u) in uploads {
            notes += &format!(
                "- {}: CRC {:#010x}, {} chunks in {} frames, {} bytes on the wire ({:.1} ms at \
                 {} baud), verified after {} round(s), {} chunk(s) resent, {:.3} s\n",
                c.run.name,
                u.crc,
                u.chunks,
                u.frames,
                u.bytes,
                firmware_images::wire_seconds(u.bytes) * 1e3,
                firmware_images::LinkBaud,
                u.rounds,
                u.resent,
                u.seconds
            );
        }
    }
    let realtime: Vec<_> = cases
        .iter()
        .filter_map(|c| c.pil.realtime.as_ref().map(|r| (c, r)))
        .collect();
    if !realtime.is_empty() {
        notes += "\n### Real-time pacing (docs/board.md#pacing)\n\n";
        for (c, r) in realtime {
            notes += &format!("- {}: {r}\n", c.run.name);
        }
    }
    notes
}

/// A metric's cell: `—` for none (NaN: a run that recorded no period).
fn metric(v: f64, fmt: impl Fn(f64) -> String) -> String {
    if v.is_nan() {
        "—".to_string()
    } else {
        fmt(v)
    }
}
