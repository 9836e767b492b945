//! The controller a flying image boots with (**Choice 363**): the default configuration on
//! the suprema over its parameter box that the firmware's build computed on the host with the
//! same f32 core ([`BOOT_BOUNDS`], firmware/build.rs), through
//! `Controller::with_bounds`. A flying image therefore carries no eigen-solver for the
//! bounds (≈ 12 kB of flash) and spends no ≈ 26 M instructions on them at boot; its link
//! cannot change the vehicle or the box (Choice 225), so `Controller::rebuild` keeps them.
//! The self-test computes them on the board and requires the same bits (its "boot bounds"
//! line); tests/boot.rs requires them equal to the host's `Controller::new`.

use controller_core::uncertainty::{Theorem2, UncertaintyBounds};
use controller_core::{BoxBounds, ConfigError, Controller, ControllerConfig};

include!(concat!(env!("OUT_DIR"), "/boot_bounds.rs"));

/// [`BOOT_BOUNDS`] with the default configuration's parameters and box they are of.
pub fn box_bounds() -> BoxBounds {
    let c = ControllerConfig::default();
    BoxBounds {
        params: c.params,
        uncertainty: c.uncertainty,
        bounds: BOOT_BOUNDS,
    }
}

/// The default controller on [`BOOT_BOUNDS`].
pub fn controller() -> Result<Controller, ConfigError> {
    Controller::with_bounds(ControllerConfig::default(), &box_bounds())
}
