//! The per-period CSV of a run: one row per control period, columns [`CSV_COLUMNS`].

use std::fs;
use std::path::Path;

use anyhow::{Context, Result};

use crate::record::{RunResult, Sample};

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
