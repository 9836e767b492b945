//! Scenario values that used to load and then run badly: arrays of the wrong
//! length, numerically unsafe values, runs too long for the step cap. Each is refused at load,
//! naming its key and the reason.

use host_sim::scenario::SimConfig;
use host_sim::scenario::{parse_scenario, Scenario, ScenarioError, MAX_CONTROL_PERIODS};

fn circle_with(extra: &str) -> String {
    format!("[trajectory]\nkind = \"circle\"\nradius = 10\n{extra}")
}

fn toml_error(text: &str) -> String {
    match parse_scenario(text) {
        Err(ScenarioError::Toml(m)) => m,
        other => panic!("expected a TOML error, got {other:?}"),
    }
}

fn invalid(text: &str) -> (String, String) {
    match parse_scenario(text) {
        Err(ScenarioError::Invalid { key, message }) => (key, message),
        other => panic!("expected an invalid value, got {other:?}"),
    }
}

#[test]
fn fixed_length_arrays_take_exactly_their_length() {
    // Seven gains for six axes, and a third entry (a string) in the two-entry q.
    let e = toml_error(&circle_with("[controller]\nk1 = [4, 4, 4, 0, 4, 4, 9]\n"));
    assert!(
        e.contains("k1") && e.contains("length 7") && e.contains("6"),
        "{e}"
    );
    let e = toml_error(&circle_with("[controller]\nq = [1.0, 1.0, \"x\"]\n"));
    assert!(e.contains("q") && e.contains("length 3"), "{e}");
    let e = toml_error(&circle_with("[controller]\nq = [\"x\", 1.0]\n"));
    assert!(e.contains("q") && e.contains("string"), "{e}");
    let e = toml_error(&format!(
        "initial_offset = [0, 0, 0, 0, 0]\n{}",
        circle_with("")
    ));
    assert!(
        e.contains("initial_offset") && e.contains("length 5"),
        "{e}"
    );
    let e = toml_error(&circle_with(
        "[current]\nmodel = \"constant\"\nvelocity = [0.1, 0, 0, 0]\n",
    ));
    assert!(e.contains("velocity") && e.contains("length 4"), "{e}");
    let e = toml_error(&circle_with("[noise]\nnu_sigma = [0, 0, 0, 0, 0, 0, 0]\n"));
    assert!(e.contains("nu_sigma"), "{e}");
    // The right lengths still load.
    parse_scenario(&circle_with(
        "[controller]\nk1 = [4, 4, 4, 0, 4, 4]\nq = [1, 2]\n",
    ))
    .unwrap();
}

#[test]
fn a_gauss_markov_tau_below_the_plant_step_is_refused() {
    let gm = |tau: &str| {
        circle_with(&format!(
            "[current]\nmodel = \"gauss-markov\"\nsigma = [0.1, 0.1, 0]\ntau = {tau}\n"
        ))
    };
    let (key, message) = invalid(&gm("0.0005"));
    assert_eq!(key, "current.tau");
    assert!(message.contains("plant step"), "{message}");
    // At the plant step it is accepted (the discrete process is stable).
    parse_scenario(&gm("0.001")).unwrap();
}

#[test]
fn a_variation_omega_the_plant_cannot_resolve_or_that_overflows_is_refused() {
    let abs_sin = |omega: &str| {
        circle_with(&format!(
            "[variation]\nprofile = \"abs-sin\"\nomega = {omega}\n"
        ))
    };
    for omega in ["1e308", "1000"] {
        let (key, message) = invalid(&abs_sin(omega));
        assert_eq!(key, "variation.omega", "{omega}");
        assert!(message.contains("plant step"), "{message}");
    }
    parse_scenario(&abs_sin("100")).unwrap();
}

#[test]
fn gains_that_overflow_every_update_are_refused() {
    let (key, message) = invalid(&circle_with(
        // k2 stays at the paper's 4, so the loop-rate rule (on k2) passes; ‖K‖ overflows f32.
        "[controller]\nk1 = [1e30, 1e30, 1e30, 0, 1e30, 1e30]\n",
    ));
    assert_eq!(key, "controller");
    assert!(message.contains("overflows"), "{message}");
}

#[test]
fn a_reference_beyond_what_the_controller_accepts_is_refused() {
    // 1 km at 0.1 rad/s is 100 m/s, twice the controller's MAX_LINEAR_SPEED.
    let (key, message) = invalid("[trajectory]\nkind = \"circle\"\nradius = 1000\n");
    assert_eq!(key, "trajectory");
    assert!(message.contains("m/s"), "{message}");
    // The lawn-mower advances 0.25 m/s: after a day it is 21.6 km out, beyond ±10 km.
    let (key, message) =
        invalid("duration = 86400\n[trajectory]\nkind = \"lawn-mower\"\nscale = 1\n");
    assert_eq!(key, "trajectory");
    assert!(message.contains("10000"), "{message}");
}

#[test]
fn the_step_cap_refuses_a_long_fast_run_unless_overridden() {
    // One day at 1 kHz: ten times the cap of control periods.
    let text = "duration = 86400\n[trajectory]\nkind = \"circle\"\nradius = 10\n[controller]\nrate_hz = 1000\n";
    let (key, message) = invalid(text);
    assert_eq!(key, "duration");
    assert!(
        message.contains(&MAX_CONTROL_PERIODS.to_string()) && message.contains("--allow-long-run"),
        "{message}"
    );
    // The same with the explicit override builds.
    let mut config: SimConfig = parse_scenario(
        "[trajectory]\nkind = \"circle\"\nradius = 10\n[controller]\nrate_hz = 1000\n",
    )
    .unwrap()
    .into_config();
    config.duration = 86_400.0;
    config.allow_long_run = true;
    let s = Scenario::new(config.clone()).unwrap();
    assert_eq!(s.steps() + 1, 86_400_001);

    // A tiny plant step used to loop for ever: refused, even with the override.
    config.plant_step = 1e-300;
    for allow in [false, true] {
        config.allow_long_run = allow;
        match Scenario::new(config.clone()) {
            Err(ScenarioError::Invalid { key, .. }) => assert_eq!(key, "plant_step"),
            other => panic!("plant_step 1e-300 (override {allow}): {other:?}"),
        }
    }
}

/// Finite values beyond what the vehicle can meet used to load, diverge at
/// t = 0 and print 0.000 metrics; each is refused, naming its key, its number readable.
#[test]
fn absurd_finite_values_are_refused_with_their_key() {
    let top = |extra: &str| format!("{extra}\n{}", circle_with(""));
    for (text, key) in [
        (top("initial_offset = [1e308, 0, 0, 0, 0, 0]"), "initial_offset"),
        // 60 m from the reference with the default 50 m divergence limit.
        (top("initial_offset = [0, 60, 0, 0, 0, 0]"), "initial_offset"),
        (top("initial_offset = [0, 0, 0, 4, 0, 0]"), "initial_offset[3]"),
        (top("initial_offset = [0, 0, 0, 0, 1.6, 0]"), "initial_offset[4]"),
        (top("initial_offset = [0, 0, 0, 0, 0, -1e308]"), "initial_offset[5]"),
        (top("divergence_limit = 1e308"), "divergence_limit"),
        (top("thruster_lag = 1e308"), "thruster_lag"),
        (
            circle_with("[current]\nmodel = \"constant\"\nvelocity = [1e308, 0, 0]\n"),
            "current.velocity",
        ),
        (
            circle_with("[current]\nmodel = \"constant\"\nvelocity = [4, 4, 0]\n"),
            "current.velocity",
        ),
        (
            circle_with("[current]\nmodel = \"gauss-markov\"\nmean = [0, 1e308, 0]\nsigma = [0, 0, 0]\ntau = 30\n"),
            "current.mean",
        ),
        (
            circle_with("[current]\nmodel = \"gauss-markov\"\nsigma = [1e308, 0, 0]\ntau = 30\n"),
            "current.sigma",
        ),
        (circle_with("[noise]\neta_sigma = [1e308, 0, 0, 0, 0, 0]\n"), "noise.eta_sigma[0]"),
        (circle_with("[noise]\neta_sigma = [0, 0, 0, 0, 0, 7]\n"), "noise.eta_sigma[5]"),
        (circle_with("[noise]\nnu_sigma = [0, 0, 0, 0, 0, 1e308]\n"), "noise.nu_sigma[5]"),
    ] {
        let (k, message) = invalid(&text);
        assert_eq!(k, key, "{text}: {message}");
        assert!(!message.contains("00000000"), "{key}: {message}");
    }
    let (_, message) = invalid(&top("initial_offset = [1e308, 0, 0, 0, 0, 0]"));
    assert!(
        message.contains("1e308") && message.contains("divergence_limit"),
        "{message}"
    );
    // Just inside each limit: accepted (a 4.9 m/s current, a start 49 m off, pitched 83°).
    for ok in [
        top("initial_offset = [0, 49, 0, 3.1, 1.45, -3.1]"),
        circle_with("[current]\nmodel = \"constant\"\nvelocity = [3, 3.9, 0]\n"),
        top("divergence_limit = 10000\nthruster_lag = 10"),
    ] {
        parse_scenario(&ok).unwrap_or_else(|e| panic!("{ok}: {e}"));
    }
}

/// A number in a message reads as the user wrote it, not as 309 digits.
#[test]
fn numbers_in_messages_are_readable() {
    let (key, message) = invalid(&circle_with(
        "[variation]\nprofile = \"abs-sin\"\nomega = 1e308\n",
    ));
    assert_eq!(key, "variation.omega");
    assert!(
        message.starts_with("1e308 rad/s is too fast") && message.len() < 200,
        "{message}"
    );
    // The core's own messages too.
    let (key, message) = invalid(&circle_with("[controller]\nmu = -1e30\n"));
    assert_eq!(key, "controller.mu");
    assert!(message.ends_with("got -1e30"), "{message}");
    let (_, message) = invalid(&circle_with("[controller]\nk2 = [1e30, 4, 4, 0, 4, 4]\n"));
    assert!(!message.contains("0000000000"), "{message}");
    let (_, message) = invalid(&format!("duration = 1e300\n{}", circle_with("")));
    assert!(message.ends_with("got 1e300"), "{message}");
}
