//! Scenario files read: the shipped Table-1 files and the example, the defaults, every knob
//! reaching its field, and a configuration built in code validated the same way.

mod common;

use controller_core::trajectory::{Circle, FigureEight, Helix};

use controller_core::model::ParamVariation;
use controller_core::{BBound, ControllerConfig, RobustLaw, Table1Case, TrajectoryKind};
use host_sim::plant::{CurrentModel, VariationProfile};
use host_sim::scenario::paper;
use host_sim::scenario::SimConfig;
use host_sim::scenario::{load_scenario, parse_scenario, Scenario, ScenarioError};

use common::{circle_with, invalid_key, scenarios_dir, toml_error};

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
    assert!(matches!(s.trajectory, TrajectoryKind::Helix(_)));
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
        TrajectoryKind::FigureEight(FigureEight {
            amplitude: 12.0,
            omega: 0.2,
            depth: 3.0
        })
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
        TrajectoryKind::Helix(Helix {
            radius: 5.0,
            omega: 0.1,
            depth: 5.0,
            depth_rate: -0.1
        })
    );
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
    c.trajectory = TrajectoryKind::Circle(Circle {
        radius: 10.0,
        omega: -1.0,
        depth: 5.0,
    });
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
