//! The real vehicle in the simulator: trim, the thrust unit of the real chain, the
//! scenario keys, the preflight check against closed forms and against the flown outcome,
//! and `host-sim check`'s exit codes. Runs are short (seconds of simulated time).

use controller_core::trajectory::Circle;
use std::path::{Path, PathBuf};
use std::process::Command;

use controller_core::kinematics::Attitude;
use controller_core::model::{self, ParamVariation, VehicleParams, GRAVITY};
use controller_core::{HeadingMode, ThrustUnit, TrajectoryKind};
use host_sim::plant::{self, Plant, PlantState, PlantTerms, VariationProfile};
use host_sim::scenario::real_vehicle;
use host_sim::scenario::{load_scenario, parse_scenario, InitialAttitude, Scenario, ScenarioError};
use host_sim::sim::{self, bound, ControlOut, ControlSource, LocalController, Recording, Stop};
use host_sim::studies::preflight::{self, Verdict, DEFAULT_MARGIN};
use nalgebra::{Vector3, Vector6};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

fn real_file(name: &str) -> PathBuf {
    scenarios_dir().join("real").join(format!("{name}.toml"))
}

/// A small deterministic generator (no dependency on the draw order of a crate).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

#[test]
fn trim_makes_gs_force_rows_vanish_and_keeps_its_moments() {
    // Closed form (docs/real-vehicle.md#trim): W = B ⇒ g₁ = g₂ = g₃ = 0 for every attitude; the trim
    // buoyancy acts at CO, so the moments are the untrimmed payload's.
    let mut rng = Lcg(9);
    for corner in [0u32, 1, 0b1_1111_1111, 0b0_0000_1111, 0b1_0101_0101] {
        let bx = controller_core::uncertainty::ParamBox::table3();
        let p = VehicleParams::auv150().with_variation(&bx.corner(corner));
        let t = plant::trimmed(&p);
        assert_eq!(t.mass, p.mass);
        assert_eq!(t.r_g, p.r_g);
        assert_eq!(t.inertia, p.inertia);
        assert_eq!(t.weight(), t.buoyancy);
        for _ in 0..200 {
            let att = Attitude::from_euler(
                rng.range(-1.2, 1.2),
                rng.range(-1.2, 1.2),
                rng.range(-3.1, 3.1),
            );
            let g = model::restoring(&t, &att);
            let g0 = model::restoring(&p, &att);
            assert!(
                g.iter().take(3).all(|&f| f == 0.0),
                "corner {corner}: forces {g}"
            );
            for (m, m0) in g.iter().zip(g0.iter()).skip(3) {
                assert!(
                    (m - m0).abs() <= 1e-9 * (1.0 + m0.abs()),
                    "corner {corner}: moment {m} vs {m0}"
                );
            }
        }
    }
    // The untrimmed payload weighs Δm g in g₃ (the check above is not vacuous).
    let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let g = model::restoring(&p, &Attitude::from_euler(0.0, 0.0, 0.0));
    assert!((g[2] + 30.0 * GRAVITY).abs() < 1e-9, "{}", g[2]);
}

#[test]
fn required_force_inverts_the_plant() {
    let mut rng = Lcg(17);
    let p = VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX);
    let plant = Plant::new(p, PlantTerms::default()).unwrap();
    for _ in 0..200 {
        let eta = Vector6::from_fn(|i, _| {
            if i < 3 {
                rng.range(-10.0, 10.0)
            } else {
                rng.range(-0.8, 0.8)
            }
        });
        let nu = Vector6::from_fn(|_, _| rng.range(-1.5, 1.5));
        let a = Vector6::from_fn(|_, _| rng.range(-0.5, 0.5));
        let current = Vector3::new(rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), 0.1);
        let s = PlantState { eta, nu };
        let tau = plant.required_force(&s, &a, &current);
        let (_, nu_dot) = plant.derivative(&s, &tau, &current).unwrap();
        assert!((nu_dot - a).amax() < 1e-9, "{nu_dot} vs {a}");
    }
}

fn real(name: &str) -> Scenario {
    load_scenario(&real_file(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The shipped mission told the exact state: the force check alone decides its verdict (the
/// path-error budget on a navigation preset is tests/path_budget.rs's).
fn exact(name: &str) -> Scenario {
    real(name).with(|c| c.navigation = None).unwrap()
}

#[test]
fn the_real_chain_applies_the_commanded_wrench_in_the_configured_unit() {
    // Regression: the real chain turned voltages into thrust with Eqs 31-32 read in newtons
    // whatever the unit, so in kgf the plant got 1/9.81 of the allocated thrust. Where nothing
    // saturates the allocator gives B₅⁻¹τ, so the applied wrench is the commanded one.
    for unit in ["kgf", "newton"] {
        let s = real("circular-10R")
            .with(|c| {
                c.duration = 2.0;
                c.controller.thrust_unit = ThrustUnit::from_name(unit).unwrap();
            })
            .unwrap();
        let run = host_sim::sim::run(&s);
        let mut checked = 0;
        // The last sample keeps the previous period's thrust (the run ends there).
        let last = run.samples.len() - 1;
        for smp in run.samples[..last].iter().filter(|x| x.saturated == 0) {
            for r in [0usize, 1, 2, 4, 5] {
                let (cmd, applied) = (smp.tau[r], smp.tau_applied[r]);
                assert!(
                    (cmd - applied).abs() <= 1e-3 * (1.0 + cmd.abs()),
                    "{unit}, t = {}: row {r}: commanded {cmd}, applied {applied}",
                    smp.t
                );
            }
            checked += 1;
        }
        if unit == "kgf" {
            assert!(checked > 150, "{checked} unsaturated periods");
        }
    }
}

/// The law run on the host as a board runs it: the board's telemetry gives the plant its
/// voltages, never the thrust the law reported (host_sim::sim::ControlOut::thrust is `None`
/// from a board).
struct AsABoard<'a>(LocalController<'a>);

impl ControlSource for AsABoard<'_> {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, Stop> {
        let out = self.0.control(k, eta, nu)?;
        Ok(ControlOut {
            thrust: None,
            ..out
        })
    }
}

#[test]
fn the_plant_gives_a_voltage_one_thrust_whether_the_law_ran_here_or_on_a_board() {
    // Regression (Choice 525): SIL's plant took the law's reported thrust for a nonzero voltage
    // (Choice 402), which since Choice 526 (523 before it) is an unclamped tunnel's command, a
    // few ulps from the inverse map of its voltage that PIL's plant evaluates: PIL differed
    // from SIL in the last bits (the figure-eight's max path 0.013083055 against 0.013083053 m)
    // with the same law, the same commands and the same voltages. The same voltages must give
    // the same flight.
    let s = real("figure-eight-30x30")
        .with(|c| c.duration = 3.0)
        .unwrap();
    let sil = sim::fly(&s, &mut LocalController::new(&s), &mut (), Recording::Plot);
    let board = sim::fly(
        &s,
        &mut AsABoard(LocalController::new(&s)),
        &mut (),
        Recording::Plot,
    );
    assert_eq!(sil.samples.len(), board.samples.len());
    assert!(sil.samples.len() > 100);
    for (a, b) in sil.samples.iter().zip(&board.samples) {
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.thrust), bits(&b.thrust), "thrust at t = {}", a.t);
        assert_eq!(bits(&a.eta), bits(&b.eta), "η at t = {}", a.t);
    }
    assert_eq!(
        sil.metrics.max_path.to_bits(),
        board.metrics.max_path.to_bits()
    );
}

#[test]
fn scenario_keys_of_the_real_vehicle_are_read() {
    let s = parse_scenario(
        "[trajectory]\nkind = \"circle\"\nradius = 10\nheading = \"tangent\"\ntime_scale = 2\n\
         [variation]\nprofile = \"constant\"\ntrimmed = true\n\
         [controller]\nthrust_unit = \"newton\"\n\
         axis_priority = [\"depth\", \"pitch\", \"sway\", \"yaw\", \"surge\"]\n\
         reversed_thrusters = [\"vert fore\"]\n",
    )
    .unwrap();
    let c = s.config();
    assert_eq!(c.heading, HeadingMode::Tangent);
    assert_eq!(c.time_scale, 2.0);
    assert!(c.trimmed);
    assert_eq!(c.controller.thrust_unit, ThrustUnit::Newton);
    // X Y Z K M N ranks, highest 5.
    assert_eq!(c.controller.priority.rank, [1, 3, 5, 0, 4, 2]);
    assert_eq!(c.controller.geometry.auv150_reversed(), Some(0b0_0010));
    assert_eq!(s.trajectory().mission().time_scale, 2.0);
    // Defaults: the paper's heading, k = 1, untrimmed, kgf, the core's mounting.
    let d = parse_scenario("[trajectory]\nkind = \"circle\"\nradius = 10\n").unwrap();
    let c = d.config();
    assert_eq!(c.heading, HeadingMode::Paper);
    assert_eq!(c.time_scale, 1.0);
    assert!(!c.trimmed);
    assert_eq!(c.controller.thrust_unit, ThrustUnit::Kgf);
    assert_eq!(c.controller, controller_core::ControllerConfig::default());
}

fn invalid_key(text: &str) -> String {
    match parse_scenario(text) {
        Err(ScenarioError::Invalid { key, .. }) => key,
        other => panic!("expected an invalid value, got {other:?}"),
    }
}

#[test]
fn bad_real_vehicle_keys_are_named() {
    let circle = "[trajectory]\nkind = \"circle\"\nradius = 10\n";
    assert_eq!(
        invalid_key(&format!("{circle}time_scale = 0.5\n")),
        "trajectory.time_scale"
    );
    // A tangent mission too slow for a course (0.01 m/s) names the heading.
    assert_eq!(
        invalid_key("[trajectory]\nkind = \"circle\"\nradius = 0.1\nheading = \"tangent\"\n"),
        "trajectory.heading"
    );
    let ctl = |extra: &str| format!("{circle}[controller]\n{extra}\n");
    assert_eq!(
        invalid_key(&ctl(
            "axis_priority = [\"pitch\", \"depth\", \"yaw\", \"sway\"]"
        )),
        "controller.axis_priority"
    );
    assert_eq!(
        invalid_key(&ctl(
            "axis_priority = [\"pitch\", \"roll\", \"yaw\", \"sway\", \"surge\"]"
        )),
        "controller.axis_priority[1]"
    );
    assert_eq!(
        invalid_key(&ctl("reversed_thrusters = [\"vert fore\", \"vert fore\"]")),
        "controller.reversed_thrusters[1]"
    );
    assert_eq!(
        invalid_key(&ctl("reversed_thrusters = [\"bow\"]")),
        "controller.reversed_thrusters[0]"
    );
    for bad in [
        format!("{circle}heading = \"sideways\"\n"),
        ctl("thrust_unit = \"lbf\""),
        format!("{circle}[variation]\nprofile = \"none\"\ntrimmed = 1\n"),
    ] {
        assert!(
            matches!(parse_scenario(&bad), Err(ScenarioError::Toml(_))),
            "{bad}"
        );
    }
}

/// The compiled real missions are every file of `scenarios/real/` (the folder listed, not the
/// compiled list read back), each named for its file; the closed-form ones fly Table 1's paths
/// in `Table1Case::ALL`'s order with the real vehicle's settings, the waypoint ones to their
/// last waypoint.
#[test]
fn the_compiled_real_missions_are_the_folders_files_and_fly_the_paths_of_table_1() {
    let mut in_folder: Vec<String> = std::fs::read_dir(scenarios_dir().join("real"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    in_folder.sort();
    let mut compiled: Vec<String> = real_vehicle::REAL_SCENARIOS
        .iter()
        .chain(&real_vehicle::WAYPOINT_SCENARIOS)
        .map(|(file, _)| file.to_string())
        .collect();
    compiled.sort();
    assert_eq!(compiled, in_folder);
    let real = real_vehicle::real_scenarios().unwrap();
    let surveys = real_vehicle::waypoint_scenarios().unwrap();
    let files = real_vehicle::REAL_SCENARIOS
        .iter()
        .chain(&real_vehicle::WAYPOINT_SCENARIOS);
    for ((file, _), s) in files.zip(real.iter().chain(&surveys)) {
        assert_eq!(
            format!("real-{}", file.trim_end_matches(".toml")),
            s.config().name,
            "{file}"
        );
    }
    for (case, s) in controller_core::Table1Case::ALL.iter().zip(&real) {
        let c = s.config();
        assert_eq!(c.trajectory, case.kind(), "{}", c.name);
        assert_eq!(c.heading, HeadingMode::Tangent);
        assert!(c.trimmed && !c.ideal_actuators);
        assert_eq!(c.controller.thrust_unit, ThrustUnit::Kgf);
        assert_eq!(c.variation, host_sim::scenario::paper::variation(*case));
        // The whole 70 s path of the paper, at the mission's time scale.
        assert!((c.duration - 70.0 * f64::from(c.time_scale)).abs() < 0.01);
    }
    // The waypoint surveys, each flown to its last waypoint (its time law's duration).
    for s in &surveys {
        let c = s.config();
        assert!(c.trimmed && !c.ideal_actuators && c.heading == HeadingMode::Tangent);
        let law = s.trajectory().time_law();
        assert!(law.is_set(), "{}: the speed profile is pinned", c.name);
        assert!(
            (c.duration - f64::from(law.duration())).abs() < 0.1,
            "{}",
            c.name
        );
    }
}

/// Choices 543–544: every shipped real mission is one its own check calls feasible as written,
/// on the navigation it ships with (survey-grade), the path-error budget and the chatter term
/// included, and each closed form at the smallest scale the check proposes (the file says so).
/// Before, the files sat at the scales the force check alone proposed (the circle at 1, the
/// survey's legs at 2.11 m/s), which the budget and the term refuse: INFEASIBLE.
#[test]
fn every_shipped_real_mission_is_feasible_by_its_own_check_at_its_own_scale() {
    let real = real_vehicle::real_scenarios().unwrap();
    let surveys = real_vehicle::waypoint_scenarios().unwrap();
    for s in real.iter().chain(&surveys) {
        let c = s.config();
        let p = preflight::check_as_written(s, DEFAULT_MARGIN).unwrap();
        assert_eq!(p.verdict, Verdict::Feasible, "{}: {p}", c.name);
        assert!(p.path_budget.is_some() && p.chatter.is_some(), "{}", c.name);
        if matches!(c.trajectory, TrajectoryKind::Waypoints { .. }) {
            continue;
        }
        assert_eq!(
            p.smallest_time_scale,
            Some(f64::from(c.time_scale) * 1e6).map(|k| k.round() / 1e6),
            "{}: {p}",
            c.name
        );
    }
}

#[test]
fn the_static_demand_is_the_closed_form_of_weight_and_cg_moment() {
    // Untrimmed Table-3 payload (held constant), started in trim: the vehicle floats at its
    // static heel tan φ = y_G W / k₄ (k₄ = z_G W − z_B B₀ = z_G W + 296.1 − 0.012 W₀), and the
    // thrusters must hold the body-z part of ΔW = 30·9.81 N, ΔW cos φ, and the CG moment
    // x_G W cos φ (x_G W = 0.05·520·9.81 N m); the vertical pair shares them as
    // T_fore = (ΔW + M/1.8) cos φ / 2 = 211.3 N up, beyond its 80 % envelope of 157.7 N. The
    // loop's pitch offset moves it by k₅ |θ| / 3.6 at most, with k₅ ≈ 397 N m/rad and |θ| below
    // the proportional loop's M cos φ / (M̂₅₅ k₁) = 247 / 7344 rad: less than 4 N.
    let w = 520.0 * GRAVITY;
    let k4 = 0.032 * w + 296.1 - 0.012 * 490.0 * GRAVITY;
    let heel: f64 = (0.02 * w / k4).atan();
    let paper = host_sim::scenario::paper::scenario(controller_core::Table1Case::Circular10R, true)
        .unwrap()
        .with(|c| {
            c.variation = VariationProfile::Constant(ParamVariation::TABLE3_MAX);
            c.start_attitude = Some(InitialAttitude::Trim);
        })
        .unwrap();
    let p = preflight::check(&paper, DEFAULT_MARGIN).unwrap();
    assert_eq!(p.verdict, Verdict::StaticallyInfeasible);
    assert_eq!(p.smallest_time_scale, None);
    assert_eq!(
        p.whole_box.as_ref().map(|b| b.verdict),
        Some(Verdict::StaticallyInfeasible)
    );
    let v = p.static_violation.as_ref().unwrap();
    let dw = 30.0 * GRAVITY;
    let moment = 0.05 * 520.0 * GRAVITY;
    let fore = (dw + moment / 1.8) * heel.cos() / 2.0;
    assert_eq!(v.thruster, "vert fore");
    assert!((v.demand - fore).abs() < 4.0, "{} vs {fore}", v.demand);
    assert!(v.given_up.contains(&"depth".to_string()), "{v:?}");
    // Trimmed, on the real vehicle's mounting (fore up, aft down), at rest only the moment is
    // left, on the pair's strong sides: M cos φ / 3.6 on each. At speed the demand is larger
    // (the heel turns part of the turn's centripetal force into heave, the pitch offset brings
    // a Munk moment: docs/real-vehicle.md#the-attitude-the-vehicle-holds).
    let at_rest = moment * heel.cos() / 3.6;
    // The circle at the paper's pace (time scale 1; the file ships slower, Choice 544).
    let r = exact("circular-10R")
        .with(|c| {
            c.time_scale = 1.0;
            c.duration = 70.0;
        })
        .unwrap();
    // At k = 40 the circle's 2 m/s are 0.05 m/s (the tangent heading needs 0.02): the
    // velocity terms are 1/1600 of the mission's.
    let slow = r.with(|c| {
        c.time_scale = 40.0;
        c.duration *= 40.0;
    });
    let p = preflight::check_as_written(&slow.unwrap(), DEFAULT_MARGIN).unwrap();
    for t in &p.thrusters[1..3] {
        assert!((t.max - at_rest).abs() < 4.0, "{t:?} vs {at_rest}");
        assert!(t.min > -1.0, "{t:?}");
    }
    let p = preflight::check_as_written(&r, DEFAULT_MARGIN).unwrap();
    assert_eq!(p.verdict, Verdict::Feasible);
    // The heel turns the port turn's centripetal force partly into a downward body force:
    // less on the fore (pushing up), more on the aft (pushing down); the Munk moment adds to
    // both.
    let (fore, aft) = (&p.thrusters[1], &p.thrusters[2]);
    assert!(aft.max > at_rest + 4.0, "{aft:?}");
    assert!(fore.max + aft.max > 2.0 * at_rest + 4.0, "{fore:?} {aft:?}");
}

#[test]
fn the_newton_reading_shrinks_every_envelope_and_grounds_the_real_circle() {
    let kgf = real("circular-10R");
    let newton = kgf
        .with(|c| c.controller.thrust_unit = ThrustUnit::Newton)
        .unwrap();
    let (ek, en) = (kgf.controller().envelope(), newton.controller().envelope());
    let pairs = ek.max.iter().zip(&en.max).chain(ek.min.iter().zip(&en.min));
    for (k, n) in pairs {
        assert!((k / n - 9.80665).abs() < 1e-3, "{k} vs {n}");
    }
    // 255 N m of CG moment against tunnels of 20 N: no speed helps.
    let p = preflight::check(&newton, DEFAULT_MARGIN).unwrap();
    assert_eq!(p.verdict, Verdict::StaticallyInfeasible, "{p}");
}

#[test]
fn time_scale_cures_a_dynamic_infeasibility_and_the_proposal_is_tight() {
    // The real figure-eight 40×40 at the paper's speed asks more than 80 % of the fore
    // horizontal tunnel and of the main thruster; check proposes the smallest feasible scale.
    let fast = exact("figure-eight-40x40")
        .with(|c| {
            c.time_scale = 1.0;
            c.duration = 70.0;
        })
        .unwrap();
    let p = preflight::check(&fast, DEFAULT_MARGIN).unwrap();
    assert_eq!(p.verdict, Verdict::NeedsTimeScale, "{p}");
    let k = p.smallest_time_scale.unwrap();
    assert!(k > 1.0 && k < 2.0, "{k}");
    let at = |k: f64| {
        let s = fast
            .with(|c| {
                c.time_scale = k as f32;
                c.duration = 70.0 * k;
            })
            .unwrap();
        preflight::check(&s, DEFAULT_MARGIN).unwrap().verdict
    };
    assert_eq!(at(k), Verdict::Feasible);
    assert_eq!(at(k - 0.02), Verdict::NeedsTimeScale);
}

#[test]
fn what_check_calls_feasible_flies_within_the_bound_and_static_infeasibility_does_not() {
    // Short flights (20 s of each real mission, 8 s of each paper mission through the chain):
    // the verdict of the shortened scenario against its flown outcome.
    let real_missions = real_vehicle::real_scenarios().unwrap();
    for s in real_missions
        .iter()
        .filter(|s| {
            s.config().trajectory
                != TrajectoryKind::Circle(Circle {
                    radius: 10.0,
                    omega: 0.1,
                    depth: 5.0,
                })
        })
        .take(4)
    {
        let short = s.with(|c| c.duration = 20.0).unwrap();
        // On the exact state the force check calls it feasible; on the shipped navigation
        // (survey) the path-error budget may ask for a slower flight, and what it calls
        // feasible flies within the bound.
        let exact = short.with(|c| c.navigation = None).unwrap();
        let p = preflight::check(&exact, DEFAULT_MARGIN).unwrap();
        assert_eq!(p.verdict, Verdict::Feasible, "{p}");
        for flown in [&exact, &short] {
            if preflight::check(flown, DEFAULT_MARGIN).unwrap().verdict != Verdict::Feasible {
                continue;
            }
            let run = host_sim::sim::run(flown);
            assert!(
                bound::within_bound(&run),
                "{}: path {} m, saturated {}",
                run.name,
                run.metrics.max_path,
                run.metrics.saturated_fraction
            );
        }
    }
    let chain = real_vehicle::paper_real_chain_scenarios(&real_missions).unwrap();
    for s in chain.iter().step_by(2) {
        let short = s.with(|c| c.duration = 8.0).unwrap();
        let p = preflight::check(&short, DEFAULT_MARGIN).unwrap();
        assert_ne!(p.verdict, Verdict::Feasible, "{p}");
        assert_eq!(
            p.whole_box.as_ref().map(|b| b.verdict),
            Some(Verdict::StaticallyInfeasible),
            "{p}"
        );
        let run = host_sim::sim::run(&short);
        assert!(
            !bound::within_bound(&run),
            "{}: {:?}",
            run.name,
            run.metrics
        );
    }
}

fn host_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

#[test]
fn check_exits_0_feasible_1_infeasible_2_bad_input() {
    let code = |args: &[&str]| host_sim().arg("check").args(args).output().unwrap();
    // Feasible on the shipped navigation (survey) as written: the path-error budget leaves
    // this lawn-mower inside the bound at its shipped speed.
    let feasible = real_file("lawn-mower-20x10");
    let o = code(&["--scenario", feasible.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("FEASIBLE at time scale 1"));
    let paper = scenarios_dir().join("circular-10R.toml");
    let o = code(&["--scenario", paper.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["verdict"], "statically-infeasible");
    assert_eq!(v["thrusters"].as_array().unwrap().len(), 5);
    let o = code(&["--scenario", feasible.to_str().unwrap(), "--margin", "1.5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--margin"));
    let o = code(&["--scenario", "/nonexistent/x.toml"]);
    assert_eq!(o.status.code(), Some(2));
}

/// `check --json` printed nothing when it exited 2: now stdout is exactly one JSON object
/// on every exit 2 as well, `{"error": {"kind", "message", "key"?}}`, the kind from a closed
/// set (a command line the parser refuses, a flag out of range, a scenario unreadable, not
/// TOML, or a value out of range with its key).
#[test]
fn check_json_prints_one_error_object_on_exit_2() {
    let dir = std::env::temp_dir().join(format!("host-sim-check-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad_value = dir.join("bad-value.toml");
    std::fs::write(
        &bad_value,
        "name = \"x\"\n[trajectory]\nkind = \"circle\"\nradius = -1\n",
    )
    .unwrap();
    let bad_toml = dir.join("bad-toml.toml");
    std::fs::write(
        &bad_toml,
        "name = \"x\"\n[trajectory]\nkindd = \"circle\"\n",
    )
    .unwrap();
    let feasible = real_file("circular-10R");
    let cases: [(Vec<&str>, &str, Option<&str>); 5] = [
        (
            vec!["--margin", "abc", "--scenario", feasible.to_str().unwrap()],
            "usage",
            None,
        ),
        (
            vec!["--margin", "1.5", "--scenario", feasible.to_str().unwrap()],
            "flag",
            None,
        ),
        (
            vec!["--scenario", "/nonexistent/x.toml"],
            "scenario-unreadable",
            None,
        ),
        (
            vec!["--scenario", bad_toml.to_str().unwrap()],
            "scenario-syntax",
            None,
        ),
        (
            vec!["--scenario", bad_value.to_str().unwrap()],
            "scenario-value",
            Some("trajectory.radius"),
        ),
    ];
    for (args, kind, key) in cases {
        let o = host_sim()
            .args(["check", "--json"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        let text = String::from_utf8(o.stdout).unwrap();
        let mut objects =
            serde_json::Deserializer::from_str(&text).into_iter::<serde_json::Value>();
        let v = objects
            .next()
            .unwrap_or_else(|| panic!("{args:?}: nothing on stdout"))
            .unwrap();
        assert!(
            objects.next().is_none(),
            "{args:?}: more than one object: {text}"
        );
        assert_eq!(v["error"]["kind"], kind, "{args:?}: {v}");
        assert!(
            v["error"]["message"]
                .as_str()
                .is_some_and(|m| !m.is_empty()),
            "{v}"
        );
        assert_eq!(v["error"]["key"].as_str(), key, "{args:?}: {v}");
        assert!(!err.is_empty(), "{args:?}: stderr still says it");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The static heel is where g(η)'s roll moment (controller-core's `model::restoring`, Eq 1)
/// vanishes and restores: zero there, of opposite signs either side; the Table-3 corner,
/// trimmed, heels the vehicle by atan(y_G W / k₄) = 0.2485 rad.
#[test]
fn the_static_heel_is_the_roll_equilibrium_of_g() {
    let corner =
        plant::trimmed(&VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX));
    for (params, theta) in [
        (corner, 0.0),
        (corner, 0.3),
        (VehicleParams::auv150(), 0.0),
        (
            VehicleParams::auv150().with_variation(&ParamVariation::TABLE3_MAX),
            -0.2,
        ),
    ] {
        let heel = plant::static_heel(&params, theta).unwrap();
        let g4 = |phi: f64| {
            let eta = Vector6::new(0.0, 0.0, 0.0, phi, theta, 0.0);
            model::restoring(&params, &Attitude::from_eta(&eta))[3]
        };
        assert!(g4(heel).abs() < 1e-9, "{heel}: {}", g4(heel));
        assert!(g4(heel + 0.01) > 0.0 && g4(heel - 0.01) < 0.0, "{heel}");
    }
    let heel = plant::static_heel(&corner, 0.0).unwrap();
    assert!((heel - 0.2485).abs() < 1e-3, "{heel}");
    assert_eq!(plant::static_heel(&VehicleParams::auv150(), 0.0), Some(0.0));
}

/// Released in trim the vehicle floats at its heel; released level with the same payload it
/// swings (no roll damping) between level and twice the heel.
#[test]
fn a_trim_start_floats_at_the_heel_and_a_level_start_swings_to_twice_it() {
    let real = real("figure-eight-30x30"); // Table 3's maximum, held constant
    let heel = plant::static_heel(&real.config().plant_params_at(0.0), 0.0).unwrap();
    let fly = |attitude: InitialAttitude| {
        let s = real
            .with(|c| {
                c.start_attitude = Some(attitude);
                c.duration = 10.0;
            })
            .unwrap();
        assert_eq!(s.config().initial_attitude(), attitude);
        let start = s.initial_state();
        (start.eta[3], host_sim::sim::run(&s).metrics.max_roll)
    };
    let (phi0, trim) = fly(InitialAttitude::Trim);
    assert!((phi0 - heel).abs() < 1e-12, "{phi0} vs {heel}");
    assert!((trim - heel).abs() < 0.1 * heel, "{trim} vs {heel}");
    let (phi0, level) = fly(InitialAttitude::Level);
    assert_eq!(phi0, 0.0);
    assert!(
        (level - 2.0 * heel).abs() < 0.1 * heel,
        "{level} vs {}",
        2.0 * heel
    );
    // The real chain starts in trim unless told; ideal actuators level.
    assert_eq!(real.config().initial_attitude(), InitialAttitude::Trim);
    let paper = host_sim::scenario::paper::config(controller_core::Table1Case::Circular10R, true);
    assert_eq!(paper.initial_attitude(), InitialAttitude::Level);
}

/// Choice 570: the thrusters' four tunnel maps side by side are the scalar map, bit for bit,
/// on every 997th f32 (±0, subnormals, the supply range, beyond it, ±∞, NaN), every 257th
/// within ±1 V and every f32 within 2¹⁶ ulps of ±24 V, where the simulated voltages lie.
#[test]
fn the_tunnels_side_by_side_are_the_scalar_map_bit_for_bit() {
    use controller_core::thruster::{tunnel_thrusts, ThrusterMap};
    let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
    let stride = (0..=u32::MAX).step_by(997).map(f32::from_bits);
    let specials = [
        0.0,
        -0.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        24.0,
        -24.0,
    ];
    let near = |x: f32| {
        let b = x.to_bits();
        (b - (1 << 16)..=b + (1 << 16)).map(f32::from_bits)
    };
    let within_1v = (0..=1.0f32.to_bits())
        .step_by(257)
        .flat_map(|b| [f32::from_bits(b), -f32::from_bits(b)]);
    let all: Vec<f32> = stride
        .chain(specials)
        .chain(within_1v)
        .chain(near(24.0))
        .chain(near(-24.0))
        .collect();
    for lanes in all.chunks(4) {
        let mut v = [1.0; 4];
        v[..lanes.len()].copy_from_slice(lanes);
        for (got, v) in tunnel_thrusts(v).iter().zip(v) {
            let want = ThrusterMap::Tunnel.thrust(v);
            assert!(same(*got, want), "V = {v:e}: {got:e} against {want:e}");
        }
    }
}
