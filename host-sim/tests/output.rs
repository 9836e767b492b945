//! CSV, plots, tables and report of `host_sim::output`, on small hand-built runs.

use controller_core::effectiveness::THRUSTERS;
use std::path::{Path, PathBuf};

use auv_link::{BoardStatus, FailSafeReason};
use controller_core::Table1Case;
use controller_core::{Fault, Status};
use host_sim::output::{
    plot_case, plot_case_with_limit, table_markdown, table_text, write_csv, write_report,
    ReportRow, CSV_COLUMNS,
};
use host_sim::sim::record::{ControlStatus, Metrics, Outcome, RunResult, Sample};
use host_sim::studies::table1::{table1_row, PaperRow};

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];

/// A fresh, empty scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("output-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A circle of radius 10 m at 10 Hz for `n` samples, tracking error shrinking with `gain`.
fn synthetic(name: &str, robust: bool, n: usize, gain: f64) -> RunResult {
    let samples = (0..n)
        .map(|k| {
            let t = k as f64 * 0.1;
            let eta_d = [
                10.0 * (0.1 * t).sin(),
                10.0 * (0.1 * t).cos(),
                5.0,
                0.0,
                0.0,
                0.1 * t,
            ];
            let error = [
                gain * 0.4 * (0.3 * t).sin(),
                gain * 0.15 * (0.2 * t).cos(),
                gain * 0.02 * (0.5 * t).sin(),
                gain * 0.01 * (0.7 * t).sin(),
                gain * 0.005 * (0.4 * t).cos(),
                gain * 0.03 * (0.1 * t).sin(),
            ];
            let mut eta = [0.0; 6];
            for i in 0..6 {
                eta[i] = eta_d[i] + error[i];
            }
            // The plant's heading wrapped to (−π, π], as a sim may record it.
            eta[5] = (eta[5] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            let voltage = [
                -20.0 * (0.2 * t).sin().abs() - 1.0,
                24.0_f64.min(30.0 * (0.3 * t).sin()),
                (-24.0_f64).max(-30.0 * (0.3 * t).sin()),
                8.0 * (0.5 * t).cos(),
                -8.0 * (0.5 * t).cos() + 0.125,
            ];
            Sample {
                t,
                eta,
                eta_d,
                error,
                tau: [100.0 + t, -3.5, 2.25, 0.0, 1.0 / 3.0, -7.0 * t],
                tau_applied: [99.0 + t, -3.5, 2.25, 0.0, 0.3, -7.0 * t],
                thrust: [100.0 + t, 1.5, -2.5, 3.0, -4.0],
                voltage,
                saturated: if voltage[1].abs() >= 24.0 {
                    0b0000_0110
                } else {
                    0
                },
                delta: 4.0 + (0.2 * t).sin(),
                delta_clamped: (0.2 * t).sin() > 0.95,
                w_norm: 1.0e-3 * t,
                payload: if t < 25.0 { 0.0 } else { 30.0 },
                status: match k % 50 {
                    49 => ControlStatus::Law(Status::Fault(Fault::PitchLimit)),
                    24 => ControlStatus::Board(BoardStatus::FailSafe(FailSafeReason::StaleState)),
                    23 => ControlStatus::Board(BoardStatus::Running),
                    _ => ControlStatus::Law(Status::Ok),
                },
                signals: Default::default(),
            }
        })
        .collect();
    RunResult {
        name: name.to_string(),
        case: None,
        robust,
        outcome: Outcome::Completed,
        metrics: Metrics {
            max_x: 0.4 * gain,
            max_y: 0.15 * gain,
            max_z: 0.02 * gain,
            max_path: (0.16f64 + 0.0225 + 0.0004).sqrt() * gain,
            rms_path: 0.2 * gain,
            max_roll: 0.01 * gain,
            max_pitch: 0.005 * gain,
            max_yaw: 0.03 * gain,
            peak_voltage: 24.0,
            saturated_fraction: 0.25,
            reversals_per_s: 0.5,
            command_tv: 12.0,
            hf_share: 0.05,
            chatter: host_sim::sim::chatter::Chatter(
                [host_sim::sim::chatter::ThrusterChatter {
                    reversals_per_s: 0.5,
                    command_tv: 12.0,
                    hf_share: 0.05,
                }; 5],
            ),
        },
        faults: Default::default(),
        faults_expected: false,
        miss_expected: false,
        path: None,
        samples,
        plant_factorisations: 0,
    }
}

fn diverged(mut run: RunResult, t: f64, reason: &str) -> RunResult {
    run.samples.retain(|s| s.t <= t);
    run.outcome = Outcome::Diverged {
        t,
        reason: reason.to_string(),
    };
    run
}

/// The CSV columns of a sample as numbers, in the documented order (independent of the
/// implementation's own list), status excluded.
fn expected_numbers(s: &Sample) -> Vec<f64> {
    let mut v = vec![s.t];
    v.extend(s.eta);
    v.extend(s.eta_d);
    v.extend(s.error);
    v.extend(s.tau);
    v.extend(s.tau_applied);
    v.extend(s.thrust);
    v.extend(s.voltage);
    v.push(f64::from(s.saturated));
    v.push(s.delta);
    v.push(if s.delta_clamped { 1.0 } else { 0.0 });
    v.push(s.w_norm);
    v.push(s.payload);
    v
}

const DOCUMENTED_COLUMNS: &str = "t, x, y, z, roll, pitch, yaw, x_d, y_d, z_d, roll_d, pitch_d, \
    yaw_d, e_x, e_y, e_z, e_roll, e_pitch, e_yaw, tau_X, tau_Y, tau_Z, tau_K, tau_M, tau_N, \
    tau_applied_X, tau_applied_Y, tau_applied_Z, tau_applied_K, tau_applied_M, tau_applied_N, \
    thrust_main, thrust_vert_fore, thrust_vert_aft, thrust_horz_fore, thrust_horz_aft, \
    volt_main, volt_vert_fore, volt_vert_aft, volt_horz_fore, volt_horz_aft, saturated, delta, \
    delta_clamped, w_norm, payload, status";

#[test]
fn csv_header_rows_and_values_round_trip() {
    let dir = scratch("csv");
    let mut run = synthetic("circular-10R", true, 120, 1.0);
    run.samples[7].eta[2] = f64::NAN;
    run.samples[8].tau[0] = f64::INFINITY;
    run.samples[9].w_norm = 1e-300;
    let path = dir.join("nested/run.csv");
    write_csv(&path, &run).unwrap();

    let mut reader = csv::Reader::from_path(&path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let documented: Vec<&str> = DOCUMENTED_COLUMNS.split(',').map(str::trim).collect();
    assert_eq!(header, documented);
    assert_eq!(CSV_COLUMNS.to_vec(), documented);

    let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(records.len(), run.samples.len());
    let status_col = header.iter().position(|h| h == "status").unwrap();
    for (rec, s) in records.iter().zip(&run.samples) {
        assert_eq!(rec.len(), header.len());
        let want = expected_numbers(s);
        for (i, w) in want.iter().enumerate() {
            let got: f64 = rec[i]
                .parse()
                .unwrap_or_else(|_| panic!("column {}", header[i]));
            assert!(
                got == *w || (got.is_nan() && w.is_nan()),
                "t = {}: column {} read {got}, wrote {w}",
                s.t,
                header[i]
            );
            // Bit-exact, not just close.
            if w.is_finite() {
                assert_eq!(got.to_bits(), w.to_bits());
            }
        }
        assert_eq!(rec[status_col], s.status.to_string());
    }
    // Spot checks by name.
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(
        &records[3][col("saturated")],
        run.samples[3].saturated.to_string()
    );
    let clamped = run.samples.iter().position(|s| s.delta_clamped).unwrap();
    assert_eq!(&records[clamped][col("delta_clamped")], "1");
    assert_eq!(&records[0][col("delta_clamped")], "0");
    // The status column's names (the core's and the board's, one token each).
    assert_eq!(&records[49][col("status")], "fault:pitch-limit");
    assert_eq!(&records[24][col("status")], "board:fail-safe:stale-state");
    assert_eq!(&records[23][col("status")], "ok");
    assert_eq!(&records[0][col("status")], "ok");
    let y: f64 = records[10][col("y")].parse().unwrap();
    assert_eq!(y, run.samples[10].eta[1]);
}

#[test]
fn csv_empty_run_is_header_only_and_errors_name_the_file() {
    let dir = scratch("csv-empty");
    let run = synthetic("empty", true, 0, 1.0);
    let path = dir.join("empty.csv");
    write_csv(&path, &run).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().count(), 1);
    assert!(text.starts_with("t,x,y,z,"));

    // A path under a regular file cannot be written; the error names it.
    let blocker = dir.join("not-a-dir");
    std::fs::write(&blocker, "x").unwrap();
    let bad = blocker.join("run.csv");
    let err = write_csv(&bad, &run).unwrap_err();
    assert!(
        format!("{err:#}").contains(&bad.display().to_string()),
        "{err:#}"
    );
}

fn assert_pngs(files: &[PathBuf], dir: &Path, name: &str) {
    let suffixes = ["xy", "errors", "payload", "heading", "actuators"];
    assert_eq!(files.len(), suffixes.len());
    for (f, suffix) in files.iter().zip(suffixes) {
        assert_eq!(f, &dir.join(format!("{name}-{suffix}.png")));
        let bytes = std::fs::read(f).unwrap();
        assert!(
            bytes.len() > 1000,
            "{} is {} bytes",
            f.display(),
            bytes.len()
        );
        assert_eq!(bytes[..8], PNG_SIGNATURE, "{} is not a PNG", f.display());
    }
}

#[test]
fn plot_case_writes_five_pngs_with_and_without() {
    let dir = scratch("plots-both").join("created/by/plot_case");
    let with = synthetic("circular-10R", true, 700, 0.05);
    let without = diverged(
        synthetic("circular-10R", false, 700, 1.0),
        52.3,
        "position error 50.2 m > limit",
    );
    let files = plot_case(&dir, &with, Some(&without)).unwrap();
    assert_pngs(&files, &dir, "circular-10R");
}

#[test]
fn plot_case_without_the_comparison_run() {
    let dir = scratch("plots-with-only");
    let with = synthetic("figure-eight-30x30", true, 300, 0.1);
    let files = plot_case(&dir, &with, None).unwrap();
    assert_pngs(&files, &dir, "figure-eight-30x30");
}

/// A figure's panels as drawn, read from its pixels (independently of the plotting code):
/// a panel is a **chart** when its cell holds the mesh's light grid lines, and says **no
/// data** when it has no mesh and its centre holds the message's grey text.
#[derive(Clone, Debug, PartialEq)]
enum Drawn {
    Chart,
    NoData,
    Neither,
}

/// A PNG decoded to RGB.
struct Image {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

/// The light grid of a chart's mesh and the grey of the "no data" message (plot.rs).
const GRID: [u8; 3] = [238, 238, 238];
const MESSAGE_GREY: [u8; 3] = [120, 120, 120];
/// The figures' title, subtitle and legend: the panels share the rows below (measured on the
/// 900-pixel figures; a panel's centre is found within ±40 px of it).
const HEADER: usize = 84;

impl Image {
    fn read(path: &Path) -> Image {
        let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.bit_depth, png::BitDepth::Eight, "{}", path.display());
        let rgb: Vec<[u8; 3]> = buf[..info.buffer_size()]
            .chunks(info.color_type.samples())
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        Image {
            width: info.width as usize,
            height: rgb.len() / info.width as usize,
            rgb,
        }
    }

    /// Pixels of exactly `colour` in columns `xs` and rows `ys`.
    fn count(
        &self,
        colour: [u8; 3],
        xs: std::ops::Range<usize>,
        ys: std::ops::Range<usize>,
    ) -> usize {
        ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| self.rgb[y * self.width + x] == colour)
            .count()
    }

    /// The panels of a `rows` × `cols` grid below the header, row by row.
    fn panels(&self, rows: usize, cols: usize) -> Vec<Drawn> {
        let (w, h) = (self.width / cols, (self.height - HEADER) / rows);
        let mut out = Vec::new();
        for r in 0..rows {
            for c in 0..cols {
                let (x0, y0) = (c * w, HEADER + r * h);
                let grid = self.count(GRID, x0..x0 + w, y0..y0 + h);
                let (cx, cy) = (x0 + w / 2, y0 + h / 2);
                let grey = self.count(MESSAGE_GREY, cx - 80..cx + 80, cy - 40..cy + 40);
                out.push(match (grid > 2000, grey > 60) {
                    (true, _) => Drawn::Chart,
                    (false, true) => Drawn::NoData,
                    (false, false) => Drawn::Neither,
                });
            }
        }
        out
    }
}

/// The panels of each of `plot_case`'s five figures (its documentation): the XY plane, the
/// errors' 3 × 2 grid, the payload, the heading, and the actuators (a voltage panel per run,
/// then δ).
fn drawn(files: &[PathBuf], with_comparison: bool) -> Vec<Vec<Drawn>> {
    let layout = [
        (1, 1),
        (3, 2),
        (1, 1),
        (1, 1),
        (if with_comparison { 3 } else { 2 }, 1),
    ];
    files
        .iter()
        .zip(layout)
        .map(|(f, (rows, cols))| Image::read(f).panels(rows, cols))
        .collect()
}

#[test]
fn plot_case_survives_empty_single_and_nan_runs() {
    use Drawn::{Chart, NoData};
    let dir = scratch("plots-degenerate");
    let charts = |n: usize| vec![Chart; n];
    // Empty: every panel of every figure says "no data".
    let empty = synthetic("empty", true, 0, 1.0);
    let files = plot_case(&dir, &empty, Some(&empty)).unwrap();
    assert_pngs(&files, &dir, "empty");
    for (f, panels) in files.iter().zip(drawn(&files, true)) {
        assert!(
            panels.iter().all(|p| *p == NoData),
            "{}: {panels:?}",
            f.display()
        );
    }

    // One sample against an empty comparison: charts, but the comparison's voltages say
    // "no data".
    let one = synthetic("one", true, 1, 1.0);
    let files = plot_case(&dir, &one, Some(&empty)).unwrap();
    assert_pngs(&files, &dir, "one");
    let want = [
        charts(1),
        charts(6),
        charts(1),
        charts(1),
        vec![Chart, NoData, Chart],
    ];
    assert_eq!(drawn(&files, true), want);

    // NaN and infinities scattered through, and a comparison run that is all NaN: the run's
    // curves are drawn (broken at the holes), the comparison's voltages say "no data".
    let mut holes = synthetic("holes", true, 200, 1.0);
    for (k, s) in holes.samples.iter_mut().enumerate() {
        if k % 7 == 3 {
            s.eta = [f64::NAN; 6];
            s.error[0] = f64::INFINITY;
            s.voltage[2] = f64::NAN;
            s.delta = f64::NEG_INFINITY;
            s.payload = f64::NAN;
        }
        if k == 100 {
            s.t = f64::NAN;
            s.error[1] = 1e300;
        }
    }
    let mut all_nan = synthetic("holes", false, 50, 1.0);
    for s in &mut all_nan.samples {
        s.eta = [f64::NAN; 6];
        s.error = [f64::NAN; 6];
        s.voltage = [f64::NAN; THRUSTERS];
    }
    let files = plot_case_with_limit(&dir, &holes, Some(&all_nan), f64::NAN).unwrap();
    assert_pngs(&files, &dir, "holes");
    assert_eq!(drawn(&files, true), want);

    // Constant signals (zero span) and a name that is not a file name: charts everywhere.
    let mut flat = synthetic("a/b c", true, 50, 0.0);
    for s in &mut flat.samples {
        s.eta = [3.0; 6];
        s.eta_d = [3.0; 6];
        s.t = 1.0;
    }
    let files = plot_case(&dir, &flat, None).unwrap();
    assert_pngs(&files, &dir, "a_b_c");
    let want = [charts(1), charts(6), charts(1), charts(1), charts(2)];
    assert_eq!(drawn(&files, false), want);
}

#[test]
fn paper_table1_matches_the_spec() {
    // docs/simulator.md#table-1, [without, with] Δu.
    let table: [(&str, [f64; 8]); 6] = [
        (
            "circular-10R",
            [0.485, 0.020, 0.145, 0.002, 0.015, 0.001, 0.506, 0.022],
        ),
        (
            "circular-20R",
            [3.992, 0.021, 1.205, 0.002, 0.320, 0.011, 4.187, 0.023],
        ),
        (
            "figure-eight-30x30",
            [1.465, 0.031, 0.895, 0.002, 0.270, 0.003, 1.738, 0.031],
        ),
        (
            "figure-eight-40x40",
            [2.368, 0.036, 1.580, 0.003, 0.543, 0.001, 2.897, 0.036],
        ),
        (
            "lawn-mower-20x10",
            [0.746, 0.001, 1.491, 0.001, 0.391, 0.102, 1.712, 0.102],
        ),
        (
            "lawn-mower-30x15",
            [1.092, 0.001, 3.205, 0.011, 0.452, 0.121, 3.420, 0.162],
        ),
    ];
    assert_eq!(table.len(), Table1Case::ALL.len());
    for (case, v) in table {
        let want = PaperRow {
            x: [v[0], v[1]],
            y: [v[2], v[3]],
            z: [v[4], v[5]],
            path: [v[6], v[7]],
        };
        let case = Table1Case::from_name(case).unwrap();
        assert_eq!(table1_row(case), want, "{}", case.name());
    }
    let c10 = table1_row(Table1Case::Circular10R);
    assert_eq!(c10.x, [0.485, 0.020]);
    assert_eq!(c10.y, [0.145, 0.002]);
    assert_eq!(c10.z, [0.015, 0.001]);
    assert_eq!(c10.path, [0.506, 0.022]);
}

#[test]
fn tables_name_every_case_and_never_hide_a_divergence() {
    let a_with = synthetic("circular-10R", true, 10, 0.05);
    let a_without = diverged(
        synthetic("circular-10R", false, 200, 1.0),
        12.34,
        "position error | 50 m",
    );
    let b_with = synthetic("lawn-mower-30x15", true, 10, 0.1);
    let c_with = diverged(synthetic("my-custom", true, 100, 1.0), 7.5, "pitch fault");
    let rows = [
        ReportRow {
            with: &a_with,
            without: Some(&a_without),
            case: Some(Table1Case::Circular10R),
        },
        ReportRow {
            with: &b_with,
            without: None,
            case: Some(Table1Case::LawnMower30x15),
        },
        ReportRow {
            with: &c_with,
            without: None,
            case: None,
        },
    ];

    let md = table_markdown(&rows);
    for name in ["circular-10R", "lawn-mower-30x15", "my-custom"] {
        assert!(md.contains(name), "{name} missing:\n{md}");
    }
    let row = md
        .lines()
        .find(|l| l.contains("circular-10R") && l.contains("without"))
        .unwrap();
    assert!(row.contains("DIVERGED at t = 12.34 s"), "{row}");
    // The reason is kept, with the table's cell separator escaped.
    assert!(row.contains("position error \\| 50 m"), "{row}");
    assert!(row.contains("(0.485)") && row.contains("(0.506)"), "{row}");
    let row = md.lines().find(|l| l.contains("my-custom")).unwrap();
    assert!(row.contains("DIVERGED at t = 7.50 s: pitch fault"), "{row}");
    // The missing without-Δu run of a paper case is shown as not run, with the paper's number.
    let row = md
        .lines()
        .find(|l| l.contains("lawn-mower-30x15") && l.contains("without"))
        .unwrap();
    assert!(row.contains("not run") && row.contains("(3.420)"), "{row}");
    // Every table line has the same number of cells (escaped pipes aside).
    let cells = |l: &str| l.replace("\\|", "").matches('|').count();
    let lines: Vec<&str> = md.lines().collect();
    assert_eq!(lines.len(), 2 + 2 + 2 + 1);
    assert!(lines.iter().all(|l| cells(l) == cells(lines[0])), "{md}");

    let text = table_text(&rows);
    for name in ["circular-10R", "lawn-mower-30x15", "my-custom"] {
        assert!(text.contains(name), "{name} missing:\n{text}");
    }
    assert!(
        text.contains("DIVERGED at t = 12.34 s: position error | 50 m"),
        "{text}"
    );
    assert!(text.contains("DIVERGED at t = 7.50 s"), "{text}");
    // Aligned: the Δu column starts under its header in every body line; then the footer.
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2 + 5 + 1, "{text}");
    let col = |l: &str, pat: &str| l.find(pat).map(|i| l[..i].chars().count());
    let du = col(lines[0], "Δu").unwrap();
    for l in &lines[2..7] {
        assert_eq!(col(l, " with").map(|c| c + 1), Some(du), "{text}");
    }
    assert!(lines[1].starts_with("---"), "{text}");
    assert!(lines[7].contains("paper's Table 1"), "{text}");
}

#[test]
fn write_report_embeds_the_plots_and_keeps_the_notes() {
    let dir = scratch("report");
    let with = synthetic("circular-20R", true, 200, 0.05);
    let without = synthetic("circular-20R", false, 200, 1.0);
    let plots = plot_case(&dir, &with, Some(&without)).unwrap();
    let rows = [ReportRow {
        with: &with,
        without: Some(&without),
        case: Some(Table1Case::Circular20R),
    }];
    let notes = "Ideal actuators.\n\n- a *note* | verbatim";
    let report = write_report(&dir, "Table 1 reproduction", &rows, &plots, notes).unwrap();
    assert_eq!(report, dir.join("report.md"));
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(md.starts_with("# Table 1 reproduction\n"), "{md}");
    assert!(md.contains(&table_markdown(&rows)));
    for p in &plots {
        let file = p.file_name().unwrap().to_str().unwrap();
        assert!(
            md.contains(&format!("]({file})")),
            "{file} not embedded:\n{md}"
        );
    }
    assert!(md.contains(notes));
    assert!(!md.contains("DIVERGED"));

    // A diverged run is flagged above the table too; plots outside dir keep their path.
    let bad = diverged(synthetic("circular-20R", false, 200, 1.0), 3.0, "runaway");
    let rows = [ReportRow {
        with: &with,
        without: Some(&bad),
        case: None,
    }];
    let elsewhere = PathBuf::from("/elsewhere/fig.png");
    let report = write_report(&dir.join("sub"), "t", &rows, &[elsewhere], "").unwrap();
    let md = std::fs::read_to_string(report).unwrap();
    assert!(md.contains("Warning: 1 run(s) diverged"), "{md}");
    assert!(md.contains("DIVERGED at t = 3.00 s: runaway"), "{md}");
    assert!(md.contains("](/elsewhere/fig.png)"), "{md}");
    assert!(!md.contains("## Notes"));
}

#[test]
fn the_paper_column_follows_the_case_not_the_name() {
    // A run named like a paper case but not made as one gets no paper numbers; a run of the
    // case under another name gets them (ReportRow::new takes the run's case).
    let lookalike = synthetic("circular-10R", true, 10, 0.05);
    let mut renamed = synthetic("my-circle", true, 10, 0.05);
    renamed.case = Some(Table1Case::Circular10R);
    let md = table_markdown(&[ReportRow::new(&lookalike, None)]);
    assert!(!md.contains("(0.506)") && !md.contains("not run"), "{md}");
    let md = table_markdown(&[ReportRow::new(&renamed, None)]);
    assert!(md.contains("my-circle") && md.contains("(0.022)"), "{md}");
    // …and the missing run without Δu is listed with the paper's number for it.
    assert!(md.contains("not run") && md.contains("(0.506)"), "{md}");
}

/// Regression: the manifest listed the files in the order the parallel runs claimed them, so
/// two runs of `table1` into one folder wrote different manifests (found comparing outputs
/// byte for byte before and after the crate's restructure). The same files claimed in any
/// order now give the same manifest.
#[test]
fn the_manifest_does_not_depend_on_the_order_files_were_claimed() {
    let names = ["b-with.csv", "a-with.csv", "report.md", "a-without.csv"];
    let manifest = |order: &[usize]| {
        let path = scratch(&format!("manifest-order-{order:?}"));
        let dir = host_sim::output::OutputDir::prepare(&path).unwrap();
        for &i in order {
            dir.claim(names[i]).unwrap();
        }
        std::fs::read_to_string(path.join(host_sim::output::dir::MANIFEST)).unwrap()
    };
    let forward = manifest(&[0, 1, 2, 3]);
    assert_eq!(forward, manifest(&[3, 2, 1, 0]));
    assert_eq!(forward, manifest(&[2, 0, 3, 1]));
    for name in names {
        assert!(
            forward.lines().any(|l| l == name),
            "{name} missing:\n{forward}"
        );
    }
}

/// A run that recorded no period (it stopped at t = 0) has no metrics; they
/// used to print as 0.000 beside the DIVERGED flag, which read as a perfect run.
#[test]
fn a_run_with_no_sample_shows_no_metric_as_a_number() {
    use host_sim::sim::metrics::compute;
    use host_sim::sim::record::RunSummary;

    let m = compute(&[]);
    assert!(!m.recorded());
    for v in [
        m.max_x,
        m.max_path,
        m.rms_path,
        m.peak_voltage,
        m.saturated_fraction,
    ] {
        assert!(v.is_nan(), "{m:?}");
    }
    let mut empty = synthetic("stopped-at-0", true, 0, 1.0);
    empty.metrics = m;
    let empty = diverged(empty, 0.0, "plant state is not finite");
    let rows = [ReportRow {
        with: &empty,
        without: None,
        case: None,
    }];
    for table in [table_markdown(&rows), table_text(&rows)] {
        let row = table.lines().find(|l| l.contains("stopped-at-0")).unwrap();
        assert!(row.contains("DIVERGED at t = 0.00 s"), "{row}");
        assert!(row.contains('—') && !row.contains("0.000"), "{row}");
        assert!(!row.contains("NaN"), "{row}");
    }
    // The JSON says null, and reads back.
    let json = serde_json::to_value(empty.summary()).unwrap();
    assert!(
        json["max_path"].is_null() && json["rms_path"].is_null(),
        "{json}"
    );
    let back: RunSummary = serde_json::from_value(json).unwrap();
    assert!(back.metrics.max_path.is_nan() && back.diverged.is_some());
    // A run with samples keeps its numbers.
    let run = synthetic("flew", true, 10, 0.1);
    let json = serde_json::to_value(run.summary()).unwrap();
    assert!(json["max_path"].is_f64(), "{json}");
    let back: RunSummary = serde_json::from_value(json).unwrap();
    assert_eq!(back.metrics, run.metrics);
}
