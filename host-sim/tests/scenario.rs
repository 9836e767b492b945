//! Scenario files: the shipped Table-1 files, the example, unknown keys and bad values.

use std::path::{Path, PathBuf};

use controller_core::model::ParamVariation;
use controller_core::{BBound, ControllerConfig, RobustLaw, Table1Case, TrajectoryKind};
use host_sim::plant::{CurrentModel, VariationProfile};
use host_sim::scenario::paper;
use host_sim::scenario::SimConfig;
use host_sim::scenario::{load_scenario, parse_scenario, Scenario, ScenarioError};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

/// A minimal valid scenario followed by `extra` (tables appended after [trajectory]).
fn circle_with(extra: &str) -> String {
    format!("name = \"t\"\n[trajectory]\nkind = \"circle\"\nradius = 10.0\n{extra}")
}

#[track_caller]
fn invalid_key(text: &str) -> (String, String) {
    match parse_scenario(text) {
        Err(ScenarioError::Invalid { key, message }) => (key, message),
        other => panic!("expected Invalid, got {other:?}"),
    }
}

#[track_caller]
fn toml_error(text: &str) -> String {
    match parse_scenario(text) {
        Err(e @ ScenarioError::Toml(_)) => e.to_string(),
        other => panic!("expected a Toml error, got {other:?}"),
    }
}

#[test]
fn shipped_table1_files_equal_the_papers_runs() {
    for case in Table1Case::ALL {
        let path = scenarios_dir().join(format!("{}.toml", case.name()));
        let loaded = load_scenario(&path).unwrap_or_else(|e| panic!("{e}"));
        let expected = paper::scenario(case, true).unwrap();
        assert_eq!(loaded, expected, "{}", path.display());
        assert_eq!(loaded.config(), &paper::config(case, true));
        assert_eq!(loaded.config().name, case.name());
        assert_eq!(loaded.config().case, Some(case));
        assert_eq!(loaded.config().trajectory, case.kind());
    }
}

#[test]
fn a_paper_run_without_du_differs_only_in_robust() {
    for case in Table1Case::ALL {
        let mut without = paper::config(case, false);
        assert!(!without.controller.robust);
        without.controller.robust = true;
        assert_eq!(without, paper::config(case, true));
    }
}

#[test]
fn table1_profiles_are_the_papers() {
    let c = paper::config(Table1Case::Circular20R, true);
    assert_eq!(
        c.variation,
        VariationProfile::AbsSin {
            max: ParamVariation::TABLE3_MAX,
            omega: 0.1
        }
    );
    let f = paper::config(Table1Case::FigureEight30x30, true);
    assert_eq!(
        f.variation,
        VariationProfile::Constant(ParamVariation::TABLE3_MAX)
    );
    let l = paper::config(Table1Case::LawnMower20x10, true);
    assert_eq!(l.variation, paper::table3_staircase());
    // Table 3's lawn-mower column, row by row (docs/model.md#parameter-variation-table-3).
    let VariationProfile::Staircase(steps) = &l.variation else {
        panic!("{:?}", l.variation)
    };
    assert_eq!(steps.len(), 3);
    assert_eq!((steps[0].0, steps[0].1), (25.0, ParamVariation::TABLE3_MAX));
    assert_eq!(steps[1].0, 50.0);
    assert_eq!(
        steps[1].1,
        ParamVariation {
            mass: 20.0,
            r_g: [0.03, 0.01, 0.018],
            inertia: [1.5, 3.5, 7.0],
            x_udot: 2.0,
            y_vdot: 35.0,
        }
    );
    assert_eq!(steps[2].0, f64::INFINITY);
    assert_eq!(
        steps[2].1,
        ParamVariation {
            mass: 10.0,
            r_g: [0.02, 0.005, 0.015],
            inertia: [1.0, 2.5, 5.0],
            x_udot: 1.5,
            y_vdot: 25.0,
        }
    );
    for s in [c, f, l] {
        assert_eq!(s.duration, 70.0);
        assert_eq!(s.plant_step, 0.001);
        assert_eq!(s.controller, ControllerConfig::default());
        assert!(s.ideal_actuators);
        assert_eq!(s.current, CurrentModel::None);
        assert_eq!(s.noise, None);
        assert_eq!(s.thruster_lag, None);
    }
}

#[test]
fn example_file_parses_with_every_section() {
    let path = scenarios_dir().join("example-all-knobs.toml");
    let s = load_scenario(&path).unwrap_or_else(|e| panic!("{e}"));
    let s = s.config();
    assert_eq!(s.name, "example-all-knobs");
    assert_eq!(s.case, None);
    assert!(matches!(s.trajectory, TrajectoryKind::Helix { .. }));
    assert!(matches!(s.current, CurrentModel::GaussMarkov { .. }));
    assert!(s.noise.is_some());
    assert_eq!(s.thruster_lag, Some(0.02));
    match &s.variation {
        VariationProfile::Staircase(steps) => {
            assert_eq!(steps.len(), 2);
            assert_eq!(steps[0].0, 35.0);
            assert_eq!(steps[1], (f64::INFINITY, ParamVariation::default()));
        }
        other => panic!("expected a staircase, got {other:?}"),
    }
    // Its [controller] spells out the defaults.
    assert_eq!(s.controller, ControllerConfig::default());
}

#[test]
fn example_file_runs() {
    // The example, shortened: noise, current, lag and staircase through the SIL loop.
    let s = load_scenario(&scenarios_dir().join("example-all-knobs.toml"))
        .unwrap()
        .with(|c| c.duration = 5.0)
        .unwrap();
    let result = host_sim::sim::run(&s);
    assert_eq!(result.outcome, host_sim::sim::record::Outcome::Completed);
}

#[test]
fn minimal_scenario_takes_defaults() {
    let s = parse_scenario("[trajectory]\nkind = \"lawn-mower\"\nscale = 1\n").unwrap();
    assert_eq!(
        s.config(),
        &SimConfig::new("scenario", Table1Case::LawnMower30x15.kind())
    );
}

#[test]
fn missing_name_takes_the_file_stem() {
    let dir = std::env::temp_dir().join(format!("host-sim-scenario-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("my-run.toml");
    std::fs::write(&path, "[trajectory]\nkind = \"circle\"\nradius = 5\n").unwrap();
    let s = load_scenario(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(s.unwrap().config().name, "my-run");
}

#[test]
fn every_knob_is_read() {
    let text = r#"
        name = "all"
        duration = 12.5
        plant_step = 0.002
        ideal_actuators = false
        initial_offset = [0.1, 0.2, 0.3, 0.0, 0.01, -0.02]
        divergence_limit = 20
        thruster_lag = 0.1
        [trajectory]
        kind = "figure-eight"
        amplitude = 12.0
        omega = 0.2
        depth = 3.0
        [variation]
        profile = "abs-sin"
        omega = 0.3
        mass = 10.0
        [current]
        model = "constant"
        velocity = [0.3, -0.1, 0.0]
        [noise]
        nu_sigma = [0.1, 0.1, 0.1, 0.0, 0.0, 0.0]
        seed = 9
        [controller]
        robust = false
        law = "discontinuous"
        k1 = [1.0, 2.0, 3.0, 0.0, 4.0, 5.0]
        k2 = [2.0, 3.0, 4.0, 0.0, 5.0, 6.0]
        q = [2.0, 3.0]
        beta = 0.9
        mu = 0.2
        delta_max = 10.0
        rate_hz = 50
        pitch_limit_deg = 60.0
        voltage_limit = 12.0
        b_bound = "literal"
    "#;
    let s = parse_scenario(text).unwrap_or_else(|e| panic!("{e}"));
    let s = s.config();
    assert_eq!(s.name, "all");
    assert_eq!(s.duration, 12.5);
    assert_eq!(s.plant_step, 0.002);
    assert!(!s.ideal_actuators);
    assert_eq!(s.initial_offset, [0.1, 0.2, 0.3, 0.0, 0.01, -0.02]);
    assert_eq!(s.divergence_limit, 20.0);
    assert_eq!(s.thruster_lag, Some(0.1));
    assert_eq!(
        s.trajectory,
        TrajectoryKind::FigureEight {
            amplitude: 12.0,
            omega: 0.2,
            depth: 3.0
        }
    );
    let max = ParamVariation {
        mass: 10.0,
        ..ParamVariation::default()
    };
    assert_eq!(s.variation, VariationProfile::AbsSin { max, omega: 0.3 });
    assert_eq!(s.current, CurrentModel::Constant([0.3, -0.1, 0.0]));
    let noise = s.noise.clone().unwrap();
    assert_eq!(noise.eta_sigma, [0.0; 6]);
    assert_eq!(noise.nu_sigma, [0.1, 0.1, 0.1, 0.0, 0.0, 0.0]);
    assert_eq!(noise.seed, 9);
    let c = s.controller;
    assert!(!c.robust);
    assert_eq!(c.law, RobustLaw::Discontinuous);
    assert_eq!(c.k1, [1.0, 2.0, 3.0, 0.0, 4.0, 5.0]);
    assert_eq!(c.k2, [2.0, 3.0, 4.0, 0.0, 5.0, 6.0]);
    assert_eq!(c.q, [2.0, 3.0]);
    assert_eq!(c.beta, 0.9);
    assert_eq!(c.mu, 0.2);
    assert_eq!(c.delta_max, 10.0);
    assert_eq!(c.rate_hz, 50);
    assert_eq!(c.pitch_limit, 60.0_f32.to_radians());
    assert_eq!(c.voltage_limit, 12.0);
    assert_eq!(c.b_bound, BBound::Literal);
}

#[test]
fn variation_defaults_to_table3_max_only_when_no_delta_is_given() {
    let s = parse_scenario(&circle_with("[variation]\nprofile = \"constant\"\n")).unwrap();
    assert_eq!(
        s.config().variation,
        VariationProfile::Constant(ParamVariation::TABLE3_MAX)
    );
    let s = parse_scenario(&circle_with("[variation]\nprofile = \"abs-sin\"\n")).unwrap();
    assert_eq!(
        s.config().variation,
        VariationProfile::AbsSin {
            max: ParamVariation::TABLE3_MAX,
            omega: 0.1
        }
    );
    let s = parse_scenario(&circle_with(
        "[variation]\nprofile = \"constant\"\ny_g = 0.01\n",
    ))
    .unwrap();
    let expected = ParamVariation {
        r_g: [0.0, 0.01, 0.0],
        ..ParamVariation::default()
    };
    assert_eq!(s.config().variation, VariationProfile::Constant(expected));
}

#[test]
fn gauss_markov_current_defaults() {
    let s = parse_scenario(&circle_with(
        "[current]\nmodel = \"gauss-markov\"\nsigma = [0.1, 0.1, 0.0]\ntau = 10\n",
    ))
    .unwrap();
    assert_eq!(
        s.config().current,
        CurrentModel::GaussMarkov {
            mean: [0.0; 3],
            sigma: [0.1, 0.1, 0.0],
            tau: 10.0,
            seed: 1
        }
    );
}

#[test]
fn unknown_top_level_key_is_named() {
    let msg = toml_error(&circle_with("").replace("name = \"t\"", "name = \"t\"\nspeed = 3"));
    assert!(msg.contains("speed"), "{msg}");
    assert!(msg.contains("line 2"), "{msg}");
}

#[test]
fn unknown_controller_key_is_named() {
    let msg = toml_error(&circle_with("[controller]\nmu = 0.1\ngain_k3 = 2.0\n"));
    assert!(msg.contains("gain_k3"), "{msg}");
}

#[test]
fn unknown_keys_in_every_table_are_errors() {
    for table in [
        "[trajectory]\nkind = \"circle\"\nradius = 1\nradiu = 2\n",
        "[trajectory]\nkind = \"circle\"\nradius = 1\n[variation]\nprofile = \"none\"\nbogus = 1\n",
        "[trajectory]\nkind = \"circle\"\nradius = 1\n[variation]\nprofile = \"staircase\"\n\
         [[variation.steps]]\nbogus = 1\n",
        "[trajectory]\nkind = \"circle\"\nradius = 1\n[current]\nmodel = \"none\"\nbogus = 1\n",
        "[trajectory]\nkind = \"circle\"\nradius = 1\n[noise]\nbogus = 1\n",
    ] {
        let msg = toml_error(table);
        assert!(msg.contains("bogus") || msg.contains("radiu"), "{msg}");
    }
}

#[test]
fn unknown_enum_value_is_a_toml_error() {
    let msg = toml_error("[trajectory]\nkind = \"square\"\nradius = 1\n");
    assert!(msg.contains("square"), "{msg}");
}

#[test]
fn missing_trajectory_is_a_toml_error() {
    let msg = toml_error("name = \"x\"\n");
    assert!(msg.contains("trajectory"), "{msg}");
}

#[test]
fn negative_mu_names_the_key() {
    let (key, message) = invalid_key(&circle_with("[controller]\nmu = -1\n"));
    assert_eq!(key, "controller.mu");
    // The core's own check, under the file's key.
    assert_eq!(message, "mu must be a finite number > 0, got -1");
    let e = parse_scenario(&circle_with("[controller]\nmu = -1\n")).unwrap_err();
    assert!(e.to_string().contains("controller.mu"), "{e}");
}

#[test]
fn negative_radius_names_the_key() {
    let (key, message) = invalid_key("[trajectory]\nkind = \"circle\"\nradius = -5\n");
    assert_eq!(key, "trajectory.radius");
    assert!(message.contains("radius"), "{message}");
}

#[test]
fn trajectory_parameters_are_checked() {
    let (key, _) = invalid_key("[trajectory]\nkind = \"lawn-mower\"\nscale = 1\nomega = 0\n");
    assert_eq!(key, "trajectory.omega");
    let (key, _) = invalid_key("[trajectory]\nkind = \"circle\"\nradius = nan\n");
    assert_eq!(key, "trajectory.radius");
    // The table is the core's TrajectoryKind: a key the kind has not, or a missing one, is the
    // TOML error of that table, naming the key (and what the kind expects).
    let msg = toml_error("[trajectory]\nkind = \"helix\"\nradius = 5\n");
    assert!(msg.contains("missing field `depth_rate`"), "{msg}");
    assert!(
        msg.contains("[trajectory]") && msg.contains("line 1"),
        "{msg}"
    );
    let msg = toml_error("[trajectory]\nkind = \"circle\"\nradius = 1\namplitude = 5\n");
    assert!(msg.contains("unknown field `amplitude`"), "{msg}");
    assert!(msg.contains("`radius`"), "{msg}");
    let msg = toml_error("[trajectory]\nkind = \"figure-eight\"\n");
    assert!(msg.contains("missing field `amplitude`"), "{msg}");
}

#[test]
fn trajectory_defaults_are_the_papers_per_kind() {
    let kind = |text: &str| parse_scenario(text).unwrap().config().trajectory;
    assert_eq!(
        kind("[trajectory]\nkind = \"circle\"\nradius = 10\n"),
        Table1Case::Circular10R.kind()
    );
    assert_eq!(
        kind("[trajectory]\nkind = \"figure-eight\"\namplitude = 15\n"),
        Table1Case::FigureEight30x30.kind()
    );
    // The lawn-mower's own ω = 0.05.
    assert_eq!(
        kind("[trajectory]\nkind = \"lawn-mower\"\nscale = 1\n"),
        Table1Case::LawnMower30x15.kind()
    );
    assert_eq!(
        kind("[trajectory]\nkind = \"helix\"\nradius = 5\ndepth_rate = -0.1\n"),
        TrajectoryKind::Helix {
            radius: 5.0,
            omega: 0.1,
            depth: 5.0,
            depth_rate: -0.1
        }
    );
}

#[test]
fn slow_loop_is_refused_by_the_controller_check() {
    let (key, message) = invalid_key(&circle_with("[controller]\nrate_hz = 5\n"));
    assert_eq!(key, "controller");
    assert!(message.contains("loop period"), "{message}");
}

#[test]
fn decreasing_staircase_times_are_refused() {
    let text = circle_with(
        "[variation]\nprofile = \"staircase\"\n\
         [[variation.steps]]\nuntil = 30.0\nmass = 10\n\
         [[variation.steps]]\nuntil = 20.0\nmass = 5\n\
         [[variation.steps]]\nmass = 0\n",
    );
    let (key, message) = invalid_key(&text);
    assert_eq!(key, "variation.steps[1].until");
    assert!(message.contains("increase"), "{message}");
}

#[test]
fn staircase_needs_until_on_all_but_the_last_step() {
    let text = circle_with(
        "[variation]\nprofile = \"staircase\"\n\
         [[variation.steps]]\nmass = 10\n[[variation.steps]]\nmass = 5\n",
    );
    let (key, _) = invalid_key(&text);
    assert_eq!(key, "variation.steps[0].until");
}

#[test]
fn wrong_type_is_a_toml_error_naming_the_key() {
    let msg = toml_error(&circle_with("[controller]\nmu = \"small\"\n"));
    assert!(msg.contains("mu"), "{msg}");
    assert!(msg.contains("line 6"), "{msg}");
    let msg = toml_error("duration = \"long\"\n[trajectory]\nkind = \"circle\"\nradius = 1\n");
    assert!(msg.contains("duration"), "{msg}");
}

#[test]
fn other_bad_values_name_their_keys() {
    let cases: &[(&str, &str)] = &[
        ("duration = 0\n", "duration"),
        ("duration = 90000\n", "duration"),
        ("duration = inf\n", "duration"),
        ("plant_step = 0.2\n", "plant_step"),
        ("plant_step = 0.02\n", "plant_step"), // > the 10 ms control period
        ("plant_step = 0.003\n", "plant_step"), // does not divide 10 ms
        ("divergence_limit = 0\n", "divergence_limit"),
        ("thruster_lag = 0\n", "thruster_lag"),
        (
            "initial_offset = [0, 0, nan, 0, 0, 0]\n",
            "initial_offset[2]",
        ),
        ("name = \"a/b\"\n", "name"),
        ("name = \"\"\n", "name"),
    ];
    for (top, expected) in cases {
        let text = format!("{top}[trajectory]\nkind = \"circle\"\nradius = 10\n");
        let (key, _) = invalid_key(&text);
        assert_eq!(&key, expected, "{top}");
    }
    let tables: &[(&str, &str)] = &[
        ("[controller]\nrate_hz = 0\n", "controller.rate_hz"),
        ("[controller]\nbeta = 1.0\n", "controller.beta"),
        ("[controller]\ndelta_max = 0\n", "controller.delta_max"),
        (
            "[controller]\npitch_limit_deg = 90\n",
            "controller.pitch_limit_deg",
        ),
        (
            "[controller]\nvoltage_limit = -24\n",
            "controller.voltage_limit",
        ),
        (
            "[controller]\nk1 = [4, 4, 4, 1, 4, 4]\n",
            "controller.k1[3]",
        ),
        (
            "[controller]\nk2 = [4, 0, 4, 0, 4, 4]\n",
            "controller.k2[1]",
        ),
        ("[controller]\nq = [1, -1]\n", "controller.q[1]"),
        ("[controller]\nmu = 0.001\n", "controller"), // δ_max/μ too high for 100 Hz
        (
            "[noise]\neta_sigma = [0, 0, -0.1, 0, 0, 0]\n",
            "noise.eta_sigma[2]",
        ),
        (
            "[current]\nmodel = \"gauss-markov\"\nsigma = [0, 0, 0]\ntau = 0\n",
            "current.tau",
        ),
        (
            "[current]\nmodel = \"gauss-markov\"\ntau = 1\n",
            "current.sigma",
        ),
        ("[current]\nmodel = \"constant\"\n", "current.velocity"),
        ("[current]\nmodel = \"none\"\ntau = 1\n", "current.tau"),
        (
            "[variation]\nprofile = \"abs-sin\"\nomega = -1\n",
            "variation.omega",
        ),
        (
            "[variation]\nprofile = \"constant\"\nomega = 1\n",
            "variation.omega",
        ),
        (
            "[variation]\nprofile = \"none\"\nmass = 1\n",
            "variation.mass",
        ),
        (
            "[variation]\nprofile = \"constant\"\nmass = -600\n",
            "variation",
        ),
        ("[variation]\nprofile = \"staircase\"\n", "variation.steps"),
    ];
    for (table, expected) in tables {
        let (key, _) = invalid_key(&circle_with(table));
        assert_eq!(&key, expected, "{table}");
    }
}

#[test]
fn missing_file_error_names_the_path() {
    let path = scenarios_dir().join("no-such-scenario.toml");
    let e = load_scenario(&path).unwrap_err();
    assert!(matches!(e, ScenarioError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("no-such-scenario.toml"), "{e}");
    assert!(std::error::Error::source(&e).is_some());
}

#[test]
fn link_faults_section_parses_and_names_bad_ranges() {
    let base = "[trajectory]\nkind = \"circle\"\nradius = 10\n";
    let cfg = host_sim::scenario::parse_scenario(&format!(
        "{base}[link_faults]\ndrop = [\"5..7\"]\nsilent = [\"300..310\", \"400..401\"]\n"
    ))
    .unwrap();
    let f = &cfg.config().link_faults;
    assert_eq!(f.drop.len(), 1);
    assert!(f.drop[0].contains(5) && f.drop[0].contains(6) && !f.drop[0].contains(7));
    assert_eq!(f.silent.len(), 2);
    assert_eq!(f.delay_ticks, 5);
    let err =
        host_sim::scenario::parse_scenario(&format!("{base}[link_faults]\ncorrupt = [\"9..3\"]\n"))
            .unwrap_err()
            .to_string();
    assert!(err.contains("link_faults.corrupt[0]"), "{err}");
    let err = host_sim::scenario::parse_scenario(&format!("{base}[link_faults]\nstall = []\n"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("stall"), "{err}");
}

#[test]
fn each_variation_key_sets_its_parameter() {
    // The nine keys, each with the field it must set (written out here, independently of the
    // core's list), and the core's list names exactly these, in this order.
    type Get = fn(&ParamVariation<f64>) -> f64;
    let keys: [(&str, Get); 9] = [
        ("mass", |d| d.mass),
        ("x_g", |d| d.r_g[0]),
        ("y_g", |d| d.r_g[1]),
        ("z_g", |d| d.r_g[2]),
        ("ix", |d| d.inertia[0]),
        ("iy", |d| d.inertia[1]),
        ("iz", |d| d.inertia[2]),
        ("x_udot", |d| d.x_udot),
        ("y_vdot", |d| d.y_vdot),
    ];
    assert_eq!(
        controller_core::model::VARIED_PARAMETER_NAMES,
        keys.map(|k| k.0)
    );
    for (key, get) in keys {
        for table in [
            format!("[variation]\nprofile = \"constant\"\n{key} = 0.125\n"),
            format!("[variation]\nprofile = \"staircase\"\n[[variation.steps]]\n{key} = 0.125\n"),
        ] {
            let s = parse_scenario(&circle_with(&table)).unwrap_or_else(|e| panic!("{e}"));
            let d = s.config().variation.at(1.0);
            assert_eq!(get(&d), 0.125, "{key}");
            let total: f64 = d.to_array().iter().sum();
            assert_eq!(total, 0.125, "{key}: only that parameter is set");
        }
        // Not finite: the error names the key.
        let (k, _) = invalid_key(&circle_with(&format!(
            "[variation]\nprofile = \"constant\"\n{key} = nan\n"
        )));
        assert_eq!(k, format!("variation.{key}"));
    }
    let msg = toml_error(&circle_with(
        "[variation]\nprofile = \"constant\"\nx_gg = 1\n",
    ));
    assert!(msg.contains("x_gg") && msg.contains("y_vdot"), "{msg}");
    let msg = toml_error(&circle_with("[variation]\nmass = 1\n"));
    assert!(msg.contains("profile"), "{msg}");
}

#[test]
fn table1_case_names_a_paper_case() {
    let s = parse_scenario(&circle_with("")).unwrap();
    assert_eq!(s.config().case, None);
    let s = parse_scenario(&circle_with("").replace(
        "name = \"t\"",
        "name = \"t\"\ntable1_case = \"circular-20R\"",
    ))
    .unwrap();
    assert_eq!(s.config().case, Some(Table1Case::Circular20R));
    let (key, message) = invalid_key(
        &circle_with("").replace("name = \"t\"", "name = \"t\"\ntable1_case = \"circle\""),
    );
    assert_eq!(key, "table1_case");
    assert!(message.contains("circular-10R"), "{message}");
}

#[test]
fn a_scenario_built_in_code_is_validated_the_same_way() {
    // One pipeline: the checks of a file apply to a SimConfig made in code.
    let base = SimConfig::new("code", Table1Case::Circular10R.kind());
    let key = |c: SimConfig| match Scenario::new(c) {
        Err(ScenarioError::Invalid { key, .. }) => key,
        other => panic!("expected Invalid, got {other:?}"),
    };
    let mut c = base.clone();
    c.plant_step = 0.003;
    assert_eq!(key(c), "plant_step");
    let mut c = base.clone();
    c.duration = f64::NAN;
    assert_eq!(key(c), "duration");
    let mut c = base.clone();
    c.controller.pitch_limit = 2.0;
    assert_eq!(key(c), "controller.pitch_limit_deg");
    let mut c = base.clone();
    c.controller.k2[5] = 0.0;
    assert_eq!(key(c), "controller.k2[5]");
    let mut c = base.clone();
    c.trajectory = TrajectoryKind::Circle {
        radius: 10.0,
        omega: -1.0,
        depth: 5.0,
    };
    assert_eq!(key(c), "trajectory.omega");
    let mut c = base.clone();
    c.name = "a/b".into();
    assert_eq!(key(c), "name");

    // The step counts: 70 s at 100 Hz with a 1 ms plant step.
    let s = Scenario::new(base).unwrap();
    assert_eq!((s.steps(), s.substeps()), (7000, 10));
    assert_eq!(s.period(), 0.01);
    // `with` validates the changed configuration and rebuilds what changed.
    let e = s.with(|c| c.duration = -1.0).unwrap_err();
    assert!(e.to_string().contains("`duration`"), "{e}");
    let short = s.with(|c| c.duration = 2.5).unwrap();
    assert_eq!(short.steps(), 250);
    assert_eq!(short.controller().config(), s.controller().config());
    let without = s.with(|c| c.controller.robust = false).unwrap();
    assert!(!without.controller().config().robust);
    let slow = s.with(|c| c.controller.rate_hz = 5);
    assert!(matches!(slow, Err(ScenarioError::Invalid { key, .. }) if key == "controller"));
}

/// Every key a TOML text names, commented out or not, as `table.key` (`key` at the top level):
/// a line `[table]`/`[[table]]` (after any `#`) opens a table, a line `key = …` (after any `#`,
/// `key` in lower case) names a key.
fn keys_named(text: &str) -> std::collections::BTreeSet<String> {
    let mut keys = std::collections::BTreeSet::new();
    let mut table = String::new();
    for line in text.lines() {
        let line = line.trim_start_matches(|c: char| c == '#' || c.is_whitespace());
        if let Some(rest) = line.strip_prefix('[') {
            let name = rest.trim_start_matches('[');
            table = name[..name.find(']').unwrap_or(name.len())].to_string();
            continue;
        }
        let Some((key, _)) = line.split_once('=') else {
            continue;
        };
        let key = key.trim_end();
        let is_key = !key.is_empty()
            && key
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if is_key {
            keys.insert(match table.as_str() {
                "" => key.to_string(),
                t => format!("{t}.{key}"),
            });
        }
    }
    keys
}

/// The schema of `host_sim::scenario`'s module documentation (its TOML block) and the example
/// that shows every knob, `scenarios/example-all-knobs.toml`, name the same keys: neither may
/// gain a key the other does not document.
#[test]
fn the_schema_and_the_all_knobs_example_name_the_same_keys() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let module = std::fs::read_to_string(root.join("src/scenario/mod.rs")).unwrap();
    let block: String = module
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .skip_while(|l| l.trim() != "```toml")
        .skip(1)
        .take_while(|l| l.trim() != "```")
        .map(|l| format!("{l}\n"))
        .collect();
    let schema = keys_named(&block);
    let example = keys_named(
        &std::fs::read_to_string(scenarios_dir().join("example-all-knobs.toml")).unwrap(),
    );
    assert!(
        schema.len() > 50,
        "the schema block was not found: {schema:?}"
    );
    let only_schema: Vec<_> = schema.difference(&example).collect();
    let only_example: Vec<_> = example.difference(&schema).collect();
    assert!(
        only_schema.is_empty() && only_example.is_empty(),
        "keys only in the schema: {only_schema:?}; only in example-all-knobs.toml: {only_example:?}"
    );
    // Every key the example shows is one the parser takes: the example parses as written.
    load_scenario(&scenarios_dir().join("example-all-knobs.toml")).unwrap();
}

/// A waypoint `[trajectory]` with `points` and `extra` keys.
fn waypoints_with(points: &str, extra: &str) -> String {
    format!("name = \"w\"\n[trajectory]\nkind = \"waypoints\"\npoints = {points}\n{extra}")
}

#[test]
fn waypoint_missions_parse_with_the_tangent_heading_by_default() {
    let s = parse_scenario(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]",
        "speed = 0.5\n",
    ))
    .expect("valid");
    let c = s.config();
    assert_eq!(c.heading, controller_core::HeadingMode::Tangent);
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        ..
    } = c.trajectory
    else {
        panic!("{:?}", c.trajectory)
    };
    assert_eq!(
        points.as_slice(),
        &[[0.0, 0.0, 5.0], [60.0, 0.0, 5.0], [60.0, 30.0, 5.0]]
    );
    assert_eq!((speed, turn_radius), (0.5, None));
    // turn_radius and an explicit paper heading are taken.
    let s = parse_scenario(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]",
        "speed = 0.5\nturn_radius = 3\nheading = \"paper\"\n",
    ))
    .expect("valid");
    assert!(matches!(
        s.config().trajectory,
        TrajectoryKind::Waypoints {
            turn_radius: Some(3.0),
            ..
        }
    ));
}

#[test]
fn waypoint_errors_name_their_key_and_reason() {
    // Repeated point, sharp turn, short leg: `trajectory.points`, with the waypoint's index.
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 0, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(msg.contains("waypoint 2 repeats waypoint 1"), "{msg}");
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [10, 5, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(
        msg.contains("turn at waypoint 1") && msg.contains("120"),
        "{msg}"
    );
    let (key, msg) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [60, 0, 5], [60, 5, 5], [0, 5, 5]]",
        "speed = 0.5\n",
    ));
    assert_eq!(key, "trajectory.points");
    assert!(
        msg.contains("leg 1") && msg.contains("turn_radius"),
        "{msg}"
    );
    let (key, _) = invalid_key(&waypoints_with("[[0, 0, 5]]", "speed = 0.5\n"));
    assert_eq!(key, "trajectory.points");
    let (key, _) = invalid_key(&waypoints_with("[[0, 0, 5], [9, 0, 5]]", "speed = 0\n"));
    assert_eq!(key, "trajectory.speed");
    let (key, _) = invalid_key(&waypoints_with(
        "[[0, 0, 5], [9, 0, 5]]",
        "speed = 1\nturn_radius = -2\n",
    ));
    assert_eq!(key, "trajectory.turn_radius");
    // More than 32 points: the TOML error says the limit; a missing speed names the field.
    let many: Vec<String> = (0..33).map(|i| format!("[{}, 0, 5]", 10 * i)).collect();
    let msg = toml_error(&waypoints_with(
        &format!("[{}]", many.join(", ")),
        "speed = 1\n",
    ));
    assert!(msg.contains("more than 32 waypoints"), "{msg}");
    let msg = toml_error(&waypoints_with("[[0, 0, 5], [9, 0, 5]]", ""));
    assert!(msg.contains("missing field `speed`"), "{msg}");
    let msg = toml_error(&waypoints_with(
        "[[0, 0, 5], [9, 0, 5]]",
        "speed = 1\nradius = 3\n",
    ));
    assert!(msg.contains("unknown field `radius`"), "{msg}");
}

#[test]
fn a_pinned_speed_profile_parses_and_its_errors_name_speeds() {
    let three = "[[0, 0, 5], [80, 0, 5], [80, 60, 5]]";
    let s = parse_scenario(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [1.2, 0.5, 1.0]\nspeed_change = 0.04\n",
    ))
    .expect("valid");
    assert!(s.trajectory().time_law().is_set());
    let (key, msg) = invalid_key(&waypoints_with(three, "speed = 0.5\nspeeds = [1.2, 0.5]\n"));
    assert_eq!(key, "trajectory.speeds");
    assert!(msg.contains("2 speeds") && msg.contains("3 parts"), "{msg}");
    let (key, _) = invalid_key(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [1.2, 0.5, 1.0]\nspeed_change = 0\n",
    ));
    assert_eq!(key, "trajectory.speed_change");
    // A 6 m/s leg needs ≈ 1 000 m to slow to 0.5 at 0.04 m/s²: the 80 m leg cannot.
    let (key, msg) = invalid_key(&waypoints_with(
        three,
        "speed = 0.5\nspeeds = [6, 0.5, 1.0]\nspeed_change = 0.04\n",
    ));
    assert_eq!(key, "trajectory.speeds");
    assert!(msg.contains("part 0"), "{msg}");
}

/// `trajectory.speed_limits` (Choice 161): one cap per leg, each in (0, MAX_SPEED]; a wrong
/// count, a bad value (naming its leg) or a closed-form kind is refused under the key.
#[test]
fn speed_limits_are_one_cap_per_leg_and_refused_by_key_and_leg() {
    let points = "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]";
    let ok = parse_scenario(&waypoints_with(
        points,
        "speed = 0.5\nspeed_limits = [1.5, 0.75]\n",
    ))
    .expect("valid");
    assert_eq!(ok.config().speed_limits, Some(vec![1.5, 0.75]));
    let refused = |extra: &str, leg_text: &str| {
        let e = parse_scenario(&waypoints_with(points, &format!("speed = 0.5\n{extra}")))
            .expect_err(extra);
        match &e {
            ScenarioError::Invalid { key, message } => {
                assert_eq!(key, "trajectory.speed_limits", "{e}");
                assert!(message.contains(leg_text), "{extra}: {e}");
            }
            other => panic!("{extra}: {other}"),
        }
    };
    refused("speed_limits = [1.0]", "(2 for 3 points), got 1");
    refused("speed_limits = [1.0, 1.0, 1.0]", "got 3");
    refused("speed_limits = [1.0, 0.0]", "leg 1");
    refused("speed_limits = [-1.0, 1.0]", "leg 0");
    refused("speed_limits = [1.0, 10.5]", "leg 1");
    refused("speed_limits = [nan, 1.0]", "leg 0");
    refused("speed_limits = [1.0, inf]", "leg 1");
    // Not a waypoint mission: the key is not used.
    let e = parse_scenario(
        "name = \"c\"\n[trajectory]\nkind = \"circle\"\nradius = 10\nspeed_limits = [1.0]\n",
    )
    .expect_err("circle");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, .. } if key == "trajectory.speed_limits"),
        "{e}"
    );
}

/// `link_faults.lose_upload_chunks` (Choice 166): chunks of a waypoint mission's upload; a
/// closed-form mission (nothing uploaded) or a chunk past the upload's last is refused under
/// the key.
#[test]
fn lost_upload_chunks_are_a_waypoint_missions_and_within_its_upload() {
    let points = "[[0, 0, 5], [60, 0, 5], [60, 30, 5]]";
    let with = |faults: &str| {
        parse_scenario(&format!(
            "{}[link_faults]\n{faults}\n",
            waypoints_with(points, "speed = 0.5\n")
        ))
    };
    let ok = with("lose_upload_chunks = [0]").expect("valid");
    assert_eq!(ok.config().link_faults.lose_upload_chunks, vec![0]);
    // Three points are 9 words: one chunk, so chunk 1 does not exist.
    let e = with("lose_upload_chunks = [1]").expect_err("chunk 1");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, message }
            if key == "link_faults.lose_upload_chunks" && message.contains("1 chunks")),
        "{e}"
    );
    let e = parse_scenario(
        "name = \"c\"\n[trajectory]\nkind = \"circle\"\nradius = 10\n[link_faults]\nlose_upload_chunks = [0]\n",
    )
    .expect_err("circle");
    assert!(
        matches!(&e, ScenarioError::Invalid { key, .. } if key == "link_faults.lose_upload_chunks"),
        "{e}"
    );
}
