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
use std::path::PathBuf;

use auv_link::sign::LinkKey;
use auv_link::MissionUpload;
use controller_core::kinematics::{self, Attitude};
use controller_core::{
    Controller, ControllerConfig, HeadingMode, Mission, Status, Table1Case, Trajectory,
    TrajectoryKind,
};

// The images' table, shared with the library (bin names, memory maps).
use firmware_images::image;

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
    println!("cargo:rerun-if-changed=../controller-core/src");

    let survey = root.join(SURVEY);
    println!("cargo:rerun-if-changed={}", survey.display());
    fs::write(out.join("golden.rs"), golden(&survey)).expect("writing golden.rs");
    fs::write(out.join("kernel_golden.rs"), kernel_golden()).expect("writing kernel_golden.rs");

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

/// Inputs of every range of the math kernels (`controller_core::math::kernels`) and the host's
/// results, as bit patterns: the self-test checks that the target gives the same bits.
fn kernel_golden() -> String {
    use controller_core::math::kernels;
    // xorshift64: deterministic inputs.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut s = String::new();
    // sin_cos: no reduction, Cody–Waite, Payne–Hanek, and the special values.
    let mut xs: Vec<f32> = Vec::new();
    for (lo, hi) in [
        (0.0f32, 0.78f32),
        (0.79, 3.2),
        (3.2, 1599.0),
        (1600.0, 3e38),
    ] {
        for _ in 0..24 {
            // Uniform on [0, π/4], log-uniform on the others.
            let u = (next() >> 11) as f64 / (1u64 << 53) as f64;
            let (lo, hi) = (lo as f64, hi as f64);
            let x = if lo == 0.0 {
                u * hi
            } else {
                lo * (hi / lo).powf(u)
            } as f32;
            xs.push(if next() & 1 == 1 { -x } else { x });
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
    let rows: Vec<String> = xs
        .iter()
        .map(|&x| {
            let (sn, cs) = kernels::sin_cos(x);
            format!(
                "({:#010x}, {:#010x}, {:#010x})",
                x.to_bits(),
                sn.to_bits(),
                cs.to_bits()
            )
        })
        .collect();
    writeln!(
        s,
        "pub const KERNEL_SIN_COS: [(u32, u32, u32); {}] = [{}];",
        rows.len(),
        rows.join(", ")
    )
    .ok();
    let rows: Vec<String> = (0..64)
        .map(|_| next() as u32)
        .chain([0, 1 << 30, 1 << 31, 3 << 30, u32::MAX])
        .map(|p| {
            let (sn, cs) = kernels::sin_cos_turns(p);
            format!(
                "({p:#010x}, {:#010x}, {:#010x})",
                sn.to_bits(),
                cs.to_bits()
            )
        })
        .collect();
    writeln!(
        s,
        "pub const KERNEL_SIN_COS_TURNS: [(u32, u32, u32); {}] = [{}];",
        rows.len(),
        rows.join(", ")
    )
    .ok();
    let wide = |next: &mut dyn FnMut() -> u64| {
        let r = next();
        let e = (r % 81) as i32 - 40;
        let m = ((r >> 8) as u32) & 0x007f_ffff;
        f32::from_bits(((((r >> 40) & 1) as u32) << 31) | (((e + 127) as u32) << 23) | m)
    };
    let rows: Vec<String> = (0..64)
        .map(|_| (wide(&mut next), wide(&mut next)))
        .chain([
            (0.0, -0.0),
            (-0.0, 0.0),
            (f32::INFINITY, -f32::INFINITY),
            (1.0, 0.0),
        ])
        .map(|(y, x)| {
            let a = kernels::atan2(y, x);
            format!(
                "({:#010x}, {:#010x}, {:#010x})",
                y.to_bits(),
                x.to_bits(),
                a.to_bits()
            )
        })
        .collect();
    writeln!(
        s,
        "pub const KERNEL_ATAN2: [(u32, u32, u32); {}] = [{}];",
        rows.len(),
        rows.join(", ")
    )
    .ok();
    for (name, f) in [
        ("CBRT", kernels::cbrt as fn(f32) -> f32),
        ("SQRT", kernels::sqrt),
    ] {
        let rows: Vec<String> = (0..64)
            .map(|_| wide(&mut next).abs())
            .chain([0.0, -0.0, 1e-45, f32::MAX, 27.0, -8.0, f32::INFINITY])
            .map(|x| format!("({:#010x}, {:#010x})", x.to_bits(), f(x).to_bits()))
            .collect();
        writeln!(
            s,
            "pub const KERNEL_{name}: [(u32, u32); {}] = [{}];",
            rows.len(),
            rows.join(", ")
        )
        .ok();
    }
    s
}

/// The waypoint mission of the self-test's golden vectors (workspace-relative): the shipped
/// survey, flown by the main job; the self-test rebuilds it on the target from its upload.
const SURVEY: &str = "host-sim/scenarios/real/survey-200x100.toml";

/// The `[trajectory]` of the scenario file at `path`, a waypoint path, as the core's path: its
/// `heading` key is the mission's, every other key the path's (`TrajectoryKind`'s serde form).
fn survey_path(path: &std::path::Path) -> TrajectoryKind {
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

/// The survey's upload as constants: its header and chunks (the self-test takes them as the
/// board's supervisor would), and the golden vectors along it: two instants in each of its
/// first segments (a leg speeding up, its cruise, the turns and the leg after), tangent
/// heading, Δu on and off.
fn survey_golden(
    path: &std::path::Path,
    with: &Controller,
    without: &Controller,
    body: &mut String,
    n: &mut usize,
) -> String {
    let mission = Mission {
        path: survey_path(path),
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    };
    let up = MissionUpload::of(&mission).expect("a waypoint path");
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
            let c = if robust { with } else { without };
            let o = c.update(ticks, &eta, &nu, &tr);
            let id = Id {
                case: 0,
                ticks,
                robust,
                tangent: true,
                helix: None,
                waypoints: true,
            };
            push(body, id, &eta, &nu, &o);
            *n += 1;
        }
    }
    let h = up.header();
    let opt = |v: Option<f32>| v.map_or("None".to_string(), |x| format!("Some({})", f(x)));
    let mut s = format!(
        "/// The shipped survey's upload ({SURVEY}).\npub const SURVEY_HEADER: UploadHeader = UploadHeader {{ points: {}, speeds: {:?}, speed: {}, turn_radius: {}, speed_change: {}, heading: Heading::{:?}, time_scale: {}, crc: {:#010x} }};\n",
        h.points,
        h.speeds,
        f(h.speed),
        opt(h.turn_radius),
        opt(h.speed_change),
        h.heading,
        f(h.time_scale),
        h.crc
    );
    let chunks: Vec<String> = (0..up.chunks())
        .map(|i| {
            let c = up.chunk(i);
            format!(
                "    UploadChunk {{ index: {}, words: {} }},",
                c.index,
                arr(&c.words)
            )
        })
        .collect();
    writeln!(
        s,
        "pub const SURVEY_CHUNKS: [UploadChunk; {}] = [\n{}\n];",
        up.chunks(),
        chunks.join("\n")
    )
    .ok();
    s
}

/// Deterministic inputs around each Table-1 mission (on and off the reference, with and
/// without Δu, and two fault cases) and along the shipped survey, and the host core's outputs
/// for them.
fn golden(survey: &std::path::Path) -> String {
    let with = Controller::new(ControllerConfig::default()).expect("defaults");
    let without = Controller::new(ControllerConfig {
        robust: false,
        ..ControllerConfig::default()
    })
    .expect("defaults without Δu");
    let mut s = String::new();
    let mut n = 0usize;
    let mut body = String::new();
    for (ci, case) in Table1Case::ALL.iter().enumerate() {
        let tr = Trajectory::table1(*case);
        for (k, ticks) in [0u64, 1234, 4567, 6999].iter().enumerate() {
            let d = tr.sample(*ticks, 100);
            let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
            let mut eta: [f32; 6] = d.eta.into();
            let mut nu: [f32; 6] = nu.into();
            // Off the reference by a few centimetres and degrees, different per vector.
            let w = (ci * 4 + k) as f32;
            eta[0] += 0.03 * (w * 0.7).sin();
            eta[1] -= 0.02 * (w * 1.3).cos();
            eta[2] += 0.01 * w / 24.0;
            eta[3] += 0.2 * (w * 0.5).sin();
            eta[4] += 0.05 * (w * 0.9).cos();
            eta[5] += 0.03 * (w * 1.1).sin();
            nu[0] += 0.05 * (w * 0.3).cos();
            nu[4] += 0.01 * (w * 0.4).sin();
            for robust in [true, false] {
                let c = if robust { &with } else { &without };
                let o = c.update(*ticks, &eta, &nu, &tr);
                let id = Id {
                    case: ci,
                    ticks: *ticks,
                    robust,
                    tangent: false,
                    helix: None,
                    waypoints: false,
                };
                push(&mut body, id, &eta, &nu, &o);
                n += 1;
            }
            // The tangent heading (ψ_d = the path's course: one atan2 and its derivatives)
            // on the same inputs, at two of the four instants, Δu on.
            if k == 1 || k == 2 {
                let tangent = Trajectory::new(Mission {
                    heading: HeadingMode::Tangent,
                    ..Mission::paper(case.kind())
                })
                .expect("every Table-1 path is fast enough for the tangent heading");
                let o = with.update(*ticks, &eta, &nu, &tangent);
                let id = Id {
                    case: ci,
                    ticks: *ticks,
                    robust: true,
                    tangent: true,
                    helix: None,
                    waypoints: false,
                };
                push(&mut body, id, &eta, &nu, &o);
                n += 1;
            }
            // The helix (the fourth path kind: the circle's radius, a descent rate, so z_d
            // grows with t) at the circle's inputs, Δu on and off.
            if ci == 0 && (k == 1 || k == 3) {
                let helix = (10.0, 0.05);
                let tr = Trajectory::helix(helix.0, helix.1).expect("a valid helix");
                for robust in [true, false] {
                    let c = if robust { &with } else { &without };
                    let o = c.update(*ticks, &eta, &nu, &tr);
                    let id = Id {
                        case: ci,
                        ticks: *ticks,
                        robust,
                        tangent: false,
                        helix: Some(helix),
                        waypoints: false,
                    };
                    push(&mut body, id, &eta, &nu, &o);
                    n += 1;
                }
            }
        }
    }
    // Faults: pitch beyond the limit, and a NaN.
    let fault = || Id {
        case: 0,
        ticks: 0,
        robust: true,
        tangent: false,
        helix: None,
        waypoints: false,
    };
    let tr = Trajectory::table1(Table1Case::Circular10R);
    let eta = [0.0, 10.0, 5.0, 0.0, 1.5, 0.0];
    let nu = [1.0, 0.0, 0.0, 0.0, 0.0, 0.1];
    push(
        &mut body,
        fault(),
        &eta,
        &nu,
        &with.update(0, &eta, &nu, &tr),
    );
    let eta = [0.0, 10.0, f32::NAN, 0.0, 0.0, 0.0];
    push(
        &mut body,
        fault(),
        &eta,
        &nu,
        &with.update(0, &eta, &nu, &tr),
    );
    n += 2;
    s += &survey_golden(survey, &with, &without, &mut body, &mut n);
    writeln!(s, "pub const GOLDEN: [Golden; {n}] = [\n{body}];").ok();
    s
}

fn f(x: f32) -> String {
    if x.is_nan() {
        "f32::NAN".into()
    } else {
        format!("f32::from_bits({:#010x})", x.to_bits())
    }
}

fn arr(a: &[f32]) -> String {
    let items: Vec<String> = a.iter().map(|x| f(*x)).collect();
    format!("[{}]", items.join(", "))
}

/// Which vector: its Table-1 case, tick, Δu on or off, and whether the mission flies the
/// tangent heading (the self-test's `Golden` fields of the same names).
struct Id {
    case: usize,
    ticks: u64,
    robust: bool,
    tangent: bool,
    /// A helix (radius, depth rate) flown instead of the case's path.
    helix: Option<(f32, f32)>,
    /// The shipped survey (`SURVEY`) flown instead of the case's path.
    waypoints: bool,
}

fn push(body: &mut String, id: Id, eta: &[f32; 6], nu: &[f32; 6], o: &controller_core::Output) {
    let Id {
        case,
        ticks,
        robust,
        tangent,
        helix,
        waypoints,
    } = id;
    let helix = match helix {
        Some((r, rate)) => format!("Some(({}, {}))", f(r), f(rate)),
        None => "None".to_string(),
    };
    let status = match o.status {
        Status::Ok => 0,
        Status::Fault(_) => 1,
    };
    writeln!(
        body,
        "    Golden {{ case: {case}, ticks: {ticks}, robust: {robust}, tangent: {tangent}, helix: {helix}, waypoints: {waypoints}, eta: {}, nu: {}, voltage: {}, tau: {}, delta: {}, w_norm: {}, status: {status} }},",
        arr(eta),
        arr(nu),
        arr(&o.voltage),
        arr(&o.tau),
        f(o.delta),
        f(o.w_norm)
    )
    .ok();
}
