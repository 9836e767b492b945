//! Every configuration check rejects what it should, with an error that names it and its
//! numbers, and accepts the paper's defaults.
// Tests change one field of the defaults at a time; that reads best as an assignment.
#![allow(clippy::field_reassign_with_default)]

use controller_core::config::{BBound, ConfigError, ConfigField, ControllerConfig};
use controller_core::controller::Controller;
use controller_core::law::RobustLaw;

fn err(cfg: ControllerConfig) -> ConfigError {
    match Controller::new(cfg) {
        Ok(_) => panic!("configuration was accepted"),
        Err(e) => e,
    }
}

#[test]
fn paper_defaults_are_accepted() {
    let c = Controller::new(ControllerConfig::default()).expect("paper defaults");
    let cfg = c.config();
    assert_eq!(cfg.k1, [4.0, 4.0, 4.0, 0.0, 4.0, 4.0]);
    assert_eq!(cfg.k2, [4.0, 4.0, 4.0, 0.0, 4.0, 4.0]);
    assert_eq!((cfg.beta, cfg.mu), (0.605, 0.1));
    assert_eq!(cfg.law, RobustLaw::BoundaryLayer);
    // ‖[K₁ K₂]‖₂ = √(4² + 4²).
    assert!((c.delta_constants().k_norm - 32f32.sqrt()).abs() < 1e-6);
}

#[test]
fn gains_must_be_positive_on_controlled_axes_and_zero_on_roll() {
    let mut c = ControllerConfig::default();
    c.k1[4] = -1.0;
    assert!(matches!(err(c), ConfigError::Gain { name: "k1", axis: 4, value } if value == -1.0));
    let mut c = ControllerConfig::default();
    c.k2[0] = f32::NAN;
    assert!(matches!(
        err(c),
        ConfigError::Gain {
            name: "k2",
            axis: 0,
            ..
        }
    ));
    let mut c = ControllerConfig::default();
    c.k1[3] = 4.0;
    assert!(matches!(err(c), ConfigError::RollGain { k1, .. } if k1 == 4.0));
}

#[test]
fn scalar_ranges_are_checked_by_name() {
    type Setter = fn(&mut ControllerConfig);
    let cases: [(&str, Setter); 8] = [
        ("beta", |c| c.beta = 1.0),
        ("beta", |c| c.beta = 0.0),
        ("mu", |c| c.mu = 0.0),
        ("mu", |c| c.mu = f32::NAN),
        ("delta_max", |c| c.delta_max = -3.0),
        ("pitch_limit", |c| c.pitch_limit = 95f32.to_radians()),
        ("pitch_limit", |c| c.pitch_limit = 90f32.to_radians()),
        ("voltage_limit", |c| c.voltage_limit = f32::INFINITY),
    ];
    for (name, set) in cases {
        let mut c = ControllerConfig::default();
        set(&mut c);
        let e = err(c);
        match e {
            ConfigError::OutOfRange { name: n, .. } | ConfigError::NotPositive { name: n, .. } => {
                assert_eq!(n, name)
            }
            ConfigError::PitchLimit { .. } => assert_eq!("pitch_limit", name),
            ref other => panic!("{name}: got {other:?}"),
        }
        // The error names its field, and says so in its text.
        assert_eq!(e.field(), Some(ConfigField { name, index: None }));
        assert!(e.to_string().starts_with(name), "{e}");
    }
    let mut c = ControllerConfig::default();
    c.rate_hz = 0;
    assert_eq!(err(c), ConfigError::ZeroRate);
    assert_eq!(err(c).field().map(|f| f.name), Some("rate_hz"));
    let mut c = ControllerConfig::default();
    c.q = [1.0, 0.0];
    assert!(matches!(
        err(c),
        ConfigError::LyapunovWeight { index: 1, .. }
    ));
    let mut c = ControllerConfig::default();
    c.params.mass = f32::NAN;
    assert_eq!(err(c), ConfigError::NonFiniteParams);
    let mut c = ControllerConfig::default();
    c.uncertainty.lower.mass = 40.0; // above the upper end (30)
    assert_eq!(err(c), ConfigError::InvalidBox);
}

#[test]
fn errors_of_one_setting_name_the_field_and_element() {
    type Setter = fn(&mut ControllerConfig);
    let cases: [(&str, Option<usize>, Setter); 5] = [
        ("k1", Some(4), |c| c.k1[4] = -1.0),
        ("k2", Some(0), |c| c.k2[0] = f32::INFINITY),
        ("k1", Some(3), |c| c.k1[3] = 1.0),
        ("k2", Some(3), |c| c.k2[3] = 1.0),
        ("q", Some(0), |c| c.q[0] = -2.0),
    ];
    for (name, index, set) in cases {
        let mut c = ControllerConfig::default();
        set(&mut c);
        assert_eq!(err(c).field(), Some(ConfigField { name, index }), "{name}");
    }
    // Checks of the whole configuration name no single field.
    let mut c = ControllerConfig::default();
    c.rate_hz = 10;
    assert_eq!(err(c).field(), None);
}

#[test]
fn assumption_2_rejects_a_box_beyond_beta() {
    // Half the vehicle's mass again as payload: β̂ ≈ 0.3…0.5 > a tight β.
    let mut c = ControllerConfig::default();
    c.uncertainty.upper.mass = 250.0;
    c.beta = 0.2;
    match err(c) {
        ConfigError::Assumption2 { beta_hat, beta } => {
            assert_eq!(beta, 0.2);
            assert!(beta_hat > 0.2 && beta_hat < 1.0, "β̂ = {beta_hat}");
            let text = err(c).to_string();
            assert!(
                text.contains("Assumption 2") && text.contains("0.2"),
                "{text}"
            );
        }
        other => panic!("got {other:?}"),
    }
    // The same box is fine with the paper's β = 0.605: β̂ is set by the surge row, where the
    // extra mass is Δm/(m + Δm − X_u̇ + ΔX_u̇) = 250/(539 + 250 + 3) ≈ 0.316 of the inertia.
    let mut c = ControllerConfig::default();
    c.uncertainty.upper.mass = 250.0;
    let beta_hat = Controller::new(c).expect("β̂ < 0.605").bounds().beta_hat;
    assert!((beta_hat - 250.0 / 792.0).abs() < 0.01, "β̂ = {beta_hat}");
}

#[test]
fn theorem_2_as_printed_is_evaluated() {
    // A large forward CG shift couples heave and pitch through m·x_G ≈ 74 kg m, pushing
    // λmin(ΔM) far below −λmin(M): the printed criterion fails.
    let mut c = ControllerConfig::default();
    c.uncertainty.upper.r_g[0] = 0.15;
    match err(c) {
        ConfigError::Theorem2 { lhs, rhs } => {
            assert!(lhs >= rhs);
            assert!(err(c).to_string().contains("Theorem 2"));
        }
        other => panic!("got {other:?}"),
    }
    let ok = Controller::new(ControllerConfig::default()).unwrap();
    assert!(ok.bounds().theorem2.holds());
}

#[test]
fn loop_period_is_checked_against_the_boundary_layer_gain() {
    // docs/law.md#the-loop-rate-rule: with δ_max = 25, μ = 0.1, p₂₂ = 0.15625, k₂ = 4 the loop needs
    // T < 2/(4 + 39.06) = 46 ms: 10 Hz must fail, 25 Hz pass.
    let mut c = ControllerConfig::default();
    c.rate_hz = 10;
    match err(c) {
        ConfigError::LoopRate {
            period, max_period, ..
        } => {
            assert!((period - 0.1).abs() < 1e-6);
            assert!((max_period - 2.0 / (4.0 + 0.15625 * 25.0 / 0.1)).abs() < 1e-5);
        }
        other => panic!("got {other:?}"),
    }
    let mut c = ControllerConfig::default();
    c.rate_hz = 25;
    assert!(Controller::new(c).is_ok());
    // The literal ‖b‖ bound lets δ reach ≈ 200: unclamped at 100 Hz it cannot be stable.
    let mut c = ControllerConfig::default();
    c.b_bound = BBound::Literal;
    c.delta_max = 250.0;
    assert!(matches!(err(c), ConfigError::LoopRate { .. }));
    assert!(err(c)
        .to_string()
        .contains("docs/law.md#the-loop-rate-rule"));
    // …with the default clamp it is accepted.
    let mut c = ControllerConfig::default();
    c.b_bound = BBound::Literal;
    assert!(Controller::new(c).is_ok());
    // Without Δu only the nominal gain matters: 10 Hz is fine.
    let mut c = ControllerConfig::default();
    c.robust = false;
    c.rate_hz = 10;
    assert!(Controller::new(c).is_ok());
}

#[test]
fn degenerate_thruster_geometry_is_rejected() {
    let mut c = ControllerConfig::default();
    c.geometry.position[2] = c.geometry.position[1];
    c.geometry.direction[2] = c.geometry.direction[1];
    assert!(matches!(err(c), ConfigError::Allocation(_)));
}

/// Every setting a board can change over the link (Choice 225), one at a time and all at once:
/// `reconfigure` gives the controller `new` gives, in every bit (`Debug` prints each f32 so
/// that it reads back exactly), and refuses what `new` refuses with the same error.
#[test]
fn reconfigure_gives_what_new_gives_for_every_link_setting() {
    use controller_core::allocation::AxisPriority;
    use controller_core::effectiveness::ThrusterGeometry;
    use controller_core::thruster::ThrustUnit;
    let base = Controller::new(ControllerConfig::default()).unwrap();
    let d = ControllerConfig::default();
    let mut priority = AxisPriority::default();
    priority.rank = [1, 1, 3, 0, 2, 2];
    priority.weight[0] = 2.5;
    let changes: Vec<ControllerConfig> = vec![
        ControllerConfig { rate_hz: 200, ..d },
        ControllerConfig { rate_hz: 25, ..d },
        ControllerConfig { robust: false, ..d },
        ControllerConfig {
            delta_max: 0.25,
            ..d
        },
        ControllerConfig {
            voltage_limit: 12.0,
            ..d
        },
        ControllerConfig {
            thrust_unit: ThrustUnit::Newton,
            ..d
        },
        ControllerConfig {
            geometry: ThrusterGeometry::auv150(0),
            ..d
        },
        ControllerConfig { priority, ..d },
        ControllerConfig {
            rate_hz: 50,
            robust: false,
            delta_max: 2.0,
            voltage_limit: 18.0,
            thrust_unit: ThrustUnit::Newton,
            geometry: ThrusterGeometry::auv150(0b10101),
            priority,
            ..d
        },
    ];
    for cfg in changes {
        let fresh = Controller::new(cfg).unwrap();
        let reused = base.reconfigure(cfg).unwrap();
        assert_eq!(format!("{reused:?}"), format!("{fresh:?}"), "{cfg:?}");
        // And back: the bounds carried along are still the defaults'.
        let back = reused.reconfigure(d).unwrap();
        assert_eq!(format!("{back:?}"), format!("{base:?}"));
    }
    // Refused the same way: the loop-rate rule, a non-finite δ_max, a bad weight.
    let mut bad_weight = AxisPriority::default();
    bad_weight.weight[2] = 0.0;
    for cfg in [
        ControllerConfig { rate_hz: 1, ..d },
        ControllerConfig {
            delta_max: f32::NAN,
            ..d
        },
        ControllerConfig {
            priority: bad_weight,
            ..d
        },
    ] {
        let fresh = Controller::new(cfg).map(|_| ()).unwrap_err();
        let reused = base.reconfigure(cfg).map(|_| ()).unwrap_err();
        assert_eq!(format!("{reused:?}"), format!("{fresh:?}"), "{cfg:?}");
    }
}

/// A configuration with another vehicle or box is not given the old bounds: `reconfigure`
/// computes them again (here a heavier vehicle, whose ΔM over the same box is the same but
/// whose β̂ and M⁻¹ bounds are not).
#[test]
fn reconfigure_recomputes_the_bounds_for_another_vehicle_or_box() {
    let base = Controller::new(ControllerConfig::default()).unwrap();
    let mut heavier = ControllerConfig::default();
    heavier.params.mass *= 1.05;
    let fresh = Controller::new(heavier).unwrap();
    assert_ne!(fresh.bounds(), base.bounds());
    assert_eq!(base.reconfigure(heavier).unwrap().bounds(), fresh.bounds());
    let mut narrower = ControllerConfig::default();
    narrower.uncertainty.upper = narrower.uncertainty.lower;
    let fresh = Controller::new(narrower).unwrap();
    assert_ne!(fresh.bounds(), base.bounds());
    assert_eq!(base.reconfigure(narrower).unwrap().bounds(), fresh.bounds());
}
