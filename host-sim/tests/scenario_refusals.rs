//! Scenario files refused: unknown keys and values, wrong types, out-of-range values and
//! checks of the run as a whole, each naming its key (or the file) and why.

mod common;

use host_sim::scenario::{load_scenario, parse_scenario, ScenarioError};

use common::{circle_with, invalid_key, scenarios_dir, toml_error};

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
fn wrong_type_is_a_toml_error_naming_the_key() {
    let msg = toml_error(&circle_with("[controller]\nmu = \"small\"\n"));
    assert!(msg.contains("mu"), "{msg}");
    assert!(msg.contains("line 6"), "{msg}");
    let msg = toml_error("duration = \"long\"\n[trajectory]\nkind = \"circle\"\nradius = 1\n");
    assert!(msg.contains("duration"), "{msg}");
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
fn other_bad_values_name_their_keys() {
    let cases: &[(&str, &str)] = &[
        ("duration = 0\n", "duration"),
        ("duration = 90000\n", "duration"),
        ("duration = inf\n", "duration"),
        ("plant_step = 0.2\n", "plant_step"),
        ("plant_step = 0.02\n", "plant_step"), // > the 10 ms control period
        ("plant_step = 0.003\n", "plant_step"), // does not divide 10 ms
        ("plant_integrator = \"euler\"\n", "plant_integrator"),
        ("noise_draws = \"sometimes\"\n", "noise_draws"),
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

/// `trajectory.origin` is three numbers exactly, like every array of the file: a fourth used
/// to be dropped without a word.
#[test]
fn an_origin_of_four_numbers_is_a_toml_error_naming_the_key() {
    let e = toml_error(&circle_with("origin = [43.0, 5.0, 0.0, 1.0]\n"));
    assert!(e.contains("origin") && e.contains("exactly 3"), "{e}");
}
