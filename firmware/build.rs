//! Gives each image (binary) its board's memory map, computes the self-test's golden vectors
//! with the same `controller-core`, built for the host, and provisions the STM32 image's link
//! key (`link_key.rs`, see [`link_key`]).
//!
//! Memory maps: cortex-m-rt's `link.x` includes `memory.x` from the linker's search path. Each
//! image gets its own directory holding a copy of its map as `memory.x`, on its own link line
//! only (`cargo:rustc-link-arg-bin`), so one `cargo build` of several images links each with
//! its own map. No `memory.x` may sit at the workspace root: the linker searches the working
//! directory first, and a root copy would shadow every image's choice.

use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use auv_link::sign::LinkKey;
use auv_link::{MissionPlan, MissionUpload};
use controller_core::kinematics::{self, Attitude};
use controller_core::{
    Controller, ControllerConfig, HeadingMode, Mission, Status, Table1Case, Trajectory,
    TrajectoryKind,
};

// The images' table, shared with the library (bin names, memory maps).
use firmware_images::image;

// The golden vector's one definition, shared with the self-test that reads them.
#[path = "src/bin/qemu_selftest/vector.rs"]
mod vector;
use vector::{estimator_steps, EstimatorGolden, Golden, ESTIMATOR_CASES};

// The STM32 image's link key from the environment (host-tested in tests/provision.rs).
#[path = "src/provision.rs"]
mod provision;
use provision::{link_key, CI_TEST_KEY, KEY_VAR, UNSIGNED_VAR};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let root = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("..");
    for img in image::Image::ALL {
        let dir = out.join("memory").join(img.bin());
        fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("creating {}: {e}", dir.display()));
        let src = root.join(img.memory_map());
        fs::copy(&src, dir.join("memory.x"))
            .unwrap_or_else(|e| panic!("copying {}: {e}", src.display()));
        println!("cargo:rustc-link-arg-bin={}=-L{}", img.bin(), dir.display());
        println!("cargo:rerun-if-changed={}", src.display());
    }
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/bin/qemu_selftest/vector.rs");
    println!("cargo:rerun-if-changed=../controller-core/src");

    let survey = root.join(SURVEY);
    println!("cargo:rerun-if-changed={}", survey.display());
    fs::write(out.join("golden.rs"), golden(&survey)).expect("writing golden.rs");
    fs::write(out.join("kernel_golden.rs"), kernel_golden()).expect("writing kernel_golden.rs");
    fs::write(out.join("boot_bounds.rs"), boot_bounds()).expect("writing boot_bounds.rs");

    println!("cargo:rerun-if-env-changed={KEY_VAR}");
    println!("cargo:rerun-if-env-changed={UNSIGNED_VAR}");
    // CI_TEST_KEY is workspace-relative; cargo resolves a relative path against the package
    // folder, where it names no file and would keep this script (and all that links the
    // library) stale forever.
    println!(
        "cargo:rerun-if-changed={}",
        root.join(CI_TEST_KEY).display()
    );
    let ci_key = fs::read_to_string(root.join(CI_TEST_KEY))
        .ok()
        .and_then(|t| LinkKey::from_key_file(&t).ok());
    let stm32 = env::var_os("CARGO_FEATURE_STM32F405").is_some();
    let (code, warning) = link_key(
        env::var(KEY_VAR).ok().as_deref(),
        env::var(UNSIGNED_VAR).ok().as_deref(),
        ci_key.as_ref(),
    );
    if let (true, Some(w)) = (stm32, warning) {
        println!("cargo:warning={w}");
    }
    fs::write(out.join("link_key.rs"), code).expect("writing link_key.rs");
}

/// xorshift64: the kernels' deterministic inputs.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// An f32 of either sign with an exponent in [−40, 40] and a random mantissa.
    fn wide(&mut self) -> f32 {
        let r = self.next();
        let e = (r % 81) as i32 - 40;
        let m = ((r >> 8) as u32) & 0x007f_ffff;
        f32::from_bits(((((r >> 40) & 1) as u32) << 31) | (((e + 127) as u32) << 23) | m)
    }
}

/// `pub const KERNEL_<name>: [(u32, …); n] = [rows];`
fn kernel_table(s: &mut String, name: &str, tuple: &str, rows: &[String]) {
    writeln!(
        s,
        "pub const KERNEL_{name}: [{tuple}; {}] = [{}];",
        rows.len(),
        rows.join(", ")
    )
    .ok();
}

fn bits(x: f32) -> String {
    format!("{:#010x}", x.to_bits())
}

/// Inputs of every range of the math kernels (`controller_core::math::kernels`) and the host's
/// results, as bit patterns: the self-test checks that the target gives the same bits.
/// The suprema over the default configuration's parameter box, as the same f32 core computes
/// them, for the flying images to boot on (`firmware::boot`, Choice 363): every field by its
/// bits.
fn boot_bounds() -> String {
    let c = Controller::new(ControllerConfig::default()).expect("defaults");
    let b = c.bounds();
    let t = &b.theorem2;
    let f = |x: f32| format!("f32::from_bits({:#010x})", x.to_bits());
    format!(
        "/// The bounds over the default box, computed by firmware/build.rs (Choice 363).\n\
         pub const BOOT_BOUNDS: UncertaintyBounds<f32> = UncertaintyBounds {{\n\
         delta_m: {}, delta_g: {}, b_controlled: {}, b_full: {}, beta_hat: {},\n\
         theorem2: Theorem2 {{ lambda_min_m: {}, lambda_max_m: {}, lambda_min_delta_m: {}, lhs: {}, rhs: {} }},\n\
         }};\n",
        f(b.delta_m),
        f(b.delta_g),
        f(b.b_controlled),
        f(b.b_full),
        f(b.beta_hat),
        f(t.lambda_min_m),
        f(t.lambda_max_m),
        f(t.lambda_min_delta_m),
        f(t.lhs),
        f(t.rhs)
    )
}

fn kernel_golden() -> String {
    use controller_core::math::kernels;
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    let mut s = String::new();
    let rows: Vec<String> = sin_cos_inputs(&mut rng)
        .into_iter()
        .map(|x| {
            let (sn, cs) = kernels::sin_cos(x);
            format!("({}, {}, {})", bits(x), bits(sn), bits(cs))
        })
        .collect();
    kernel_table(&mut s, "SIN_COS", "(u32, u32, u32)", &rows);
    let rows: Vec<String> = (0..64)
        .map(|_| rng.next() as u32)
        .chain([0, 1 << 30, 1 << 31, 3 << 30, u32::MAX])
        .map(|p| {
            let (sn, cs) = kernels::sin_cos_turns(p);
            format!("({p:#010x}, {}, {})", bits(sn), bits(cs))
        })
        .collect();
    kernel_table(&mut s, "SIN_COS_TURNS", "(u32, u32, u32)", &rows);
    let rows: Vec<String> = (0..64)
        .map(|_| (rng.wide(), rng.wide()))
        .chain([
            (0.0, -0.0),
            (-0.0, 0.0),
            (f32::INFINITY, -f32::INFINITY),
            (1.0, 0.0),
        ])
        .map(|(y, x)| format!("({}, {}, {})", bits(y), bits(x), bits(kernels::atan2(y, x))))
        .collect();
    kernel_table(&mut s, "ATAN2", "(u32, u32, u32)", &rows);
    for (name, f) in [
        ("CBRT", kernels::cbrt as fn(f32) -> f32),
        ("SQRT", kernels::sqrt),
    ] {
        let rows: Vec<String> = (0..64)
            .map(|_| rng.wide().abs())
            .chain([0.0, -0.0, 1e-45, f32::MAX, 27.0, -8.0, f32::INFINITY])
            .map(|x| format!("({}, {})", bits(x), bits(f(x))))
            .collect();
        kernel_table(&mut s, name, "(u32, u32)", &rows);
    }
    s
}

/// sin_cos's inputs: no reduction, Cody–Waite, Payne–Hanek, and the special values.
fn sin_cos_inputs(rng: &mut XorShift) -> Vec<f32> {
    let mut xs: Vec<f32> = Vec::new();
    for (lo, hi) in [
        (0.0f32, 0.78f32),
        (0.79, 3.2),
        (3.2, 1599.0),
        (1600.0, 3e38),
    ] {
        for _ in 0..24 {
            // Uniform on [0, π/4], log-uniform on the others.
            let u = (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
            let (lo, hi) = (lo as f64, hi as f64);
            let x = if lo == 0.0 {
                u * hi
            } else {
                lo * (hi / lo).powf(u)
            } as f32;
            xs.push(if rng.next() & 1 == 1 { -x } else { x });
        }
    }
    xs.extend([
        0.0,
        -0.0,
        f32::MIN_POSITIVE,
        1e-40,
        f32::MAX,
        f32::INFINITY,
        f32::NAN,
    ]);
    xs
}

/// The waypoint mission of the self-test's golden vectors (workspace-relative): the shipped
/// survey, flown by the main job; the self-test rebuilds it on the target from its upload.
const SURVEY: &str = "host-sim/scenarios/real/survey-200x100.toml";

/// The `[trajectory]` of the scenario file at `path`, a waypoint path, as the core's path: its
/// `heading` key is the mission's, every other key the path's (`TrajectoryKind`'s serde form).
fn survey_path(path: &Path) -> TrajectoryKind {
    let text =
        fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let file: toml::Table =
        toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut trajectory = file
        .get("trajectory")
        .and_then(|t| t.as_table())
        .cloned()
        .unwrap_or_else(|| panic!("{}: no [trajectory]", path.display()));
    trajectory.remove("heading");
    trajectory
        .try_into()
        .unwrap_or_else(|e| panic!("{}: [trajectory]: {e}", path.display()))
}

/// The survey's upload as constants (`SURVEY_HEADER`, `SURVEY_CHUNKS`: the self-test takes
/// them as the board's supervisor would), and the golden vectors along it: two instants in
/// each of its first segments (a leg speeding up, its cruise, the turns and the leg after),
/// tangent heading, Δu on and off, keyed by the plan that names the upload.
fn survey_golden(path: &Path, c: &Controllers, vectors: &mut Vec<Golden>) -> String {
    let mission = Mission {
        path: survey_path(path),
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    };
    let up = MissionUpload::of(&mission).expect("a waypoint path");
    let plan = MissionPlan::from(mission);
    let tr = Trajectory::new(mission).expect("the shipped survey is a valid mission");
    let (route, law) = (tr.route(), tr.time_law());
    for i in 0..route.segment_count().min(5) {
        let (t0, t1) = (law.segment_time(i), law.segment_time(i + 1));
        for (k, f) in [0.2f32, 0.6].into_iter().enumerate() {
            let ticks = ((t0 + f * (t1 - t0)) * 100.0) as u64;
            let d = tr.sample(ticks, 100);
            let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
            let mut eta: [f32; 6] = d.eta.into();
            let mut nu: [f32; 6] = nu.into();
            let w = (2 * i + k) as f32;
            eta[0] += 0.04 * (w * 0.9).sin();
            eta[1] -= 0.03 * (w * 1.7).cos();
            eta[2] += 0.02;
            eta[5] += 0.02 * (w * 0.8).sin();
            nu[0] -= 0.03;
            let robust = k == 0 || i % 2 == 0;
            vectors.push(c.vector(plan, ticks, robust, eta, nu, &tr));
        }
    }
    let chunks: Vec<String> = (0..up.chunks())
        .map(|i| format!("    {:?},", up.chunk(i)))
        .collect();
    format!(
        "/// The shipped survey's upload ({SURVEY}).\npub const SURVEY_HEADER: UploadHeader = {:?};\npub const SURVEY_CHUNKS: [UploadChunk; {}] = [\n{}\n];\n",
        up.header(),
        up.chunks(),
        chunks.join("\n")
    )
}

/// The controllers the vectors run, Δu on and off, and one vector from each.
struct Controllers {
    with: Controller,
    without: Controller,
}

impl Controllers {
    fn new() -> Self {
        let with = Controller::new(ControllerConfig::default()).expect("defaults");
        let without = Controller::new(ControllerConfig {
            robust: false,
            ..ControllerConfig::default()
        })
        .expect("defaults without Δu");
        Controllers { with, without }
    }

    /// The host core's output for these inputs on `tr`, the mission `plan` names.
    fn vector(
        &self,
        plan: MissionPlan,
        ticks: u64,
        robust: bool,
        eta: [f32; 6],
        nu: [f32; 6],
        tr: &Trajectory,
    ) -> Golden {
        let c = if robust { &self.with } else { &self.without };
        let o = c.update(ticks, &eta, &nu, tr);
        Golden {
            plan,
            ticks,
            robust,
            eta,
            nu,
            voltage: o.voltage,
            tau: o.tau,
            delta: o.delta,
            w_norm: o.w_norm,
            status: match o.status {
                Status::Ok => 0,
                Status::Fault(_) => 1,
            },
        }
    }
}

/// The instants of each Table-1 mission's vectors (100 Hz ticks).
const TICKS: [u64; 4] = [0, 1234, 4567, 6999];

/// The inputs of Table-1 case `ci` at its instant `k`: the reference, off by a few
/// centimetres and degrees, differently per vector.
fn inputs(ci: usize, k: usize) -> ([f32; 6], [f32; 6]) {
    let tr = Trajectory::table1(Table1Case::ALL[ci]);
    let d = tr.sample(TICKS[k], 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    let mut eta: [f32; 6] = d.eta.into();
    let mut nu: [f32; 6] = nu.into();
    let w = (ci * 4 + k) as f32;
    eta[0] += 0.03 * (w * 0.7).sin();
    eta[1] -= 0.02 * (w * 1.3).cos();
    eta[2] += 0.01 * w / 24.0;
    eta[3] += 0.2 * (w * 0.5).sin();
    eta[4] += 0.05 * (w * 0.9).cos();
    eta[5] += 0.03 * (w * 1.1).sin();
    nu[0] += 0.05 * (w * 0.3).cos();
    nu[4] += 0.01 * (w * 0.4).sin();
    (eta, nu)
}

/// Each Table-1 mission at its four instants, Δu on and off, and with the tangent heading
/// (ψ_d = the path's course: one atan2 and its derivatives) at the middle two, Δu on.
fn table1_golden(c: &Controllers, vectors: &mut Vec<Golden>) {
    for (ci, case) in Table1Case::ALL.iter().enumerate() {
        let paper = Mission::paper(case.kind());
        let tangent = Mission {
            heading: HeadingMode::Tangent,
            ..paper
        };
        let tr = Trajectory::new(paper).expect("a Table-1 mission");
        let tr_tangent = Trajectory::new(tangent)
            .expect("every Table-1 path is fast enough for the tangent heading");
        for (k, &ticks) in TICKS.iter().enumerate() {
            let (eta, nu) = inputs(ci, k);
            for robust in [true, false] {
                vectors.push(c.vector(paper.into(), ticks, robust, eta, nu, &tr));
            }
            if k == 1 || k == 2 {
                vectors.push(c.vector(tangent.into(), ticks, true, eta, nu, &tr_tangent));
            }
        }
    }
}

/// Every closed-form kind of `TrajectoryKind::EXAMPLES` that no Table-1 mission flies (the
/// helix today) at the first Table-1 mission's inputs of its instants 1 and 3, Δu on and off:
/// a new kind has golden vectors without a line here.
fn example_golden(c: &Controllers, vectors: &mut Vec<Golden>) {
    let in_table1 =
        |k: &TrajectoryKind| Table1Case::ALL.iter().any(|c| c.kind().name() == k.name());
    for kind in TrajectoryKind::EXAMPLES {
        if in_table1(&kind) || MissionUpload::of(&Mission::paper(kind)).is_some() {
            continue;
        }
        let tr = Trajectory::new(kind).expect("every example is a valid mission");
        for k in [1, 3] {
            let (eta, nu) = inputs(0, k);
            for robust in [true, false] {
                vectors.push(c.vector(kind.into(), TICKS[k], robust, eta, nu, &tr));
            }
        }
    }
}

/// Two faults on the first Table-1 mission: pitch beyond the limit, and a NaN.
fn fault_golden(c: &Controllers, vectors: &mut Vec<Golden>) {
    let paper = Mission::paper(Table1Case::ALL[0].kind());
    let tr = Trajectory::new(paper).expect("a Table-1 mission");
    let nu = [1.0, 0.0, 0.0, 0.0, 0.0, 0.1];
    for eta in [
        [0.0, 10.0, 5.0, 0.0, 1.5, 0.0],
        [0.0, 10.0, f32::NAN, 0.0, 0.0, 0.0],
    ] {
        vectors.push(c.vector(paper.into(), 0, true, eta, nu, &tr));
    }
}

/// Deterministic inputs around each Table-1 mission (on and off the reference, with and
/// without Δu, and two fault cases), on each other closed-form kind's example and along the
/// shipped survey, and the host core's outputs for them: `GOLDEN`, and the survey's upload.
fn golden(survey: &Path) -> String {
    let c = Controllers::new();
    let mut vectors = Vec::new();
    table1_golden(&c, &mut vectors);
    example_golden(&c, &mut vectors);
    fault_golden(&c, &mut vectors);
    let mut s = survey_golden(survey, &c, &mut vectors);
    writeln!(s, "pub const GOLDEN: [Golden; {}] = [", vectors.len()).ok();
    for g in &vectors {
        writeln!(s, "    {},", rust(g)).ok();
    }
    s += "];\n";
    let estimator = estimator_golden(&vectors);
    writeln!(
        s,
        "pub const ESTIMATOR_GOLDEN: [EstimatorGolden; {}] = [",
        estimator.len()
    )
    .ok();
    for e in &estimator {
        writeln!(s, "    {e:?},").ok();
    }
    s += "];\n";
    s
}

/// The estimator's golden vectors: each case of [`estimator_steps`] on every closed-form vector
/// with Δu on that the law flies, by the default controller with the estimator on (Kalman).
fn estimator_golden(vectors: &[Golden]) -> Vec<EstimatorGolden> {
    let mut cfg = ControllerConfig::default();
    cfg.estimator.kind = controller_core::EstimatorKind::Kalman;
    let c = Controller::new(cfg).expect("the defaults with the estimator");
    let mut out = Vec::new();
    for (vector, g) in vectors.iter().enumerate() {
        let Ok(mission) = Mission::try_from(g.plan) else {
            continue;
        };
        if !g.robust || g.status != 0 {
            continue;
        }
        let tr = Trajectory::new(mission).expect("a golden vector's mission");
        for case in 0..ESTIMATOR_CASES {
            let Some(steps) = estimator_steps(g, case) else {
                continue;
            };
            let mut memory = controller_core::Estimate::new();
            let mut last = None;
            for (ticks, solution) in steps {
                last = Some(c.update_from_solution(&mut memory, ticks, &solution, &tr));
            }
            let o = last.expect("three steps");
            assert!(o.status == Status::Ok, "the estimator's case flies: {o:?}");
            out.push(EstimatorGolden {
                vector,
                case,
                voltage: o.voltage,
                tau: o.tau,
            });
        }
    }
    out
}

/// `g` as a Rust expression: its `Debug` form, whose every finite `f32` is the shortest
/// literal that parses back to its bits, and a non-finite one its constant (a NaN input is
/// `f32::NAN`).
fn rust(g: &Golden) -> String {
    format!("{g:?}")
        .replace("NaN", "f32::NAN")
        .replace("inf", "f32::INFINITY")
}
