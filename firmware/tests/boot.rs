//! The controller a flying image boots with (firmware::boot, Choice 363): the bounds the build
//! computed are the very bits `Controller::new` computes on the host, and the controller on
//! them is `Controller::new`'s in every field the law reads.

use controller_core::{ConfigError, Controller, ControllerConfig};

#[test]
fn the_boot_bounds_are_those_controller_new_computes() {
    let computed = Controller::new(ControllerConfig::default()).expect("defaults");
    let booted = firmware::boot::controller().expect("the boot controller");
    // Bit for bit: PartialEq on f32 would let -0.0 == 0.0 through.
    let bits = |c: &Controller| {
        let b = c.bounds();
        let t = &b.theorem2;
        [
            b.delta_m,
            b.delta_g,
            b.b_controlled,
            b.b_full,
            b.beta_hat,
            t.lambda_min_m,
            t.lambda_max_m,
            t.lambda_min_delta_m,
            t.lhs,
            t.rhs,
        ]
        .map(f32::to_bits)
    };
    assert_eq!(bits(&booted), bits(&computed));
    assert_eq!(booted.delta_constants(), computed.delta_constants());
    assert_eq!(booted.config(), computed.config());
}

#[test]
fn bounds_of_another_box_are_refused() {
    let mut config = ControllerConfig::default();
    config.params.mass *= 1.5;
    assert_eq!(
        Controller::with_bounds(config, &firmware::boot::box_bounds()).err(),
        Some(ConfigError::BoundsOfAnotherBox)
    );
    let booted = firmware::boot::controller().expect("the boot controller");
    assert_eq!(
        booted.rebuild(config).err(),
        Some(ConfigError::BoundsOfAnotherBox)
    );
    // A configuration a link can set (the rate) keeps the box, and rebuilds.
    let faster = ControllerConfig {
        rate_hz: 200,
        ..ControllerConfig::default()
    };
    let rebuilt = booted.rebuild(faster).expect("the same box");
    assert_eq!(
        rebuilt.bounds(),
        Controller::new(faster).expect("200 Hz").bounds()
    );
}
