//! The board's whole configuration and its digest (protocol 6, Choice 228): the digest is the
//! documented CRC-32 of the patch's postcard bytes (checked against a bitwise CRC-32 and bytes
//! laid out by hand), every field moves it, and `confirm` tells a board that flies what was
//! sent from one that does not, naming what differs where telemetry can tell.

use auv_link::{
    AxisPriority, ConfigMismatch, ConfigPatch, EstimatorSettings, Telemetry, ThrustUnit,
};
use controller_core::ControllerConfig;

#[path = "common/frames.rs"]
mod frames;
use frames::crc32_by_hand;

/// The whole configuration of a board on the defaults (free-running, 2 stale periods).
fn defaults() -> ConfigPatch {
    ConfigPatch::whole(&ControllerConfig::default(), 2, false)
}

#[test]
fn the_whole_configuration_sets_every_field_from_the_core_and_the_board() {
    let c = ControllerConfig::default();
    let w = defaults();
    assert!(w.is_whole());
    assert_eq!(w.rate_hz, Some(c.rate_hz));
    assert_eq!(w.robust, Some(c.robust));
    assert_eq!(w.delta_max, Some(c.delta_max));
    assert_eq!(w.voltage_limit, Some(c.voltage_limit));
    assert_eq!(w.stale_periods, Some(2));
    assert_eq!(w.lockstep, Some(false));
    assert_eq!(w.thrust_unit, Some(ThrustUnit::Kgf));
    assert_eq!(
        w.reversed_thrusters,
        Some(controller_core::effectiveness::AUV150_REVERSED)
    );
    assert_eq!(w.priority, Some(AxisPriority::from(c.priority)));
    assert_eq!(w.estimator, Some(EstimatorSettings::from(c.estimator)));
    // Any field unset: not whole.
    for unset in [
        ConfigPatch { rate_hz: None, ..w },
        ConfigPatch {
            priority: None,
            ..w
        },
        ConfigPatch {
            estimator: None,
            ..w
        },
        ConfigPatch {
            lockstep: None,
            ..w
        },
    ] {
        assert!(!unset.is_whole());
    }
    assert!(!ConfigPatch::EMPTY.is_whole());
}

#[test]
fn the_digest_is_the_crc32_of_the_documented_bytes() {
    // The defaults, laid out from the module docs: rate 100, Δu on, δ_max, the voltage limit,
    // 2 stale periods, free-running, kgf, the AUV-150 mask, then the priority.
    let c = ControllerConfig::default();
    let w = defaults();
    let p = w.priority.unwrap();
    let mut bytes = Vec::new();
    bytes.extend_from_slice(&100u32.to_le_bytes());
    bytes.push(1);
    bytes.extend_from_slice(&c.delta_max.to_le_bytes());
    bytes.extend_from_slice(&c.voltage_limit.to_le_bytes());
    bytes.extend_from_slice(&[2, 0, 0, controller_core::effectiveness::AUV150_REVERSED]);
    bytes.extend_from_slice(&p.rank);
    for x in p.weight {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    // Protocol 7: the estimator, off, then σₚ, σᵥ, σₐ.
    bytes.push(0);
    let e = c.estimator;
    for x in [e.position_sigma, e.velocity_sigma, e.accel_sigma]
        .iter()
        .flatten()
    {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    assert_eq!(bytes.len(), 120);
    assert_eq!(w.digest(), Some(crc32_by_hand(&bytes)));
    // Newton is the unit's wire index 1.
    let newton = ConfigPatch {
        thrust_unit: Some(ThrustUnit::Newton),
        ..w
    };
    bytes[15] = 1;
    assert_eq!(newton.digest(), Some(crc32_by_hand(&bytes)));
    // A patch that is not whole has none.
    assert_eq!(ConfigPatch::EMPTY.digest(), None);
    assert_eq!(
        ConfigPatch {
            lockstep: None,
            ..w
        }
        .digest(),
        None
    );
}

#[test]
fn every_field_moves_the_digest() {
    let w = defaults();
    let mut priority = w.priority.unwrap();
    priority.weight[5] = 1.5;
    let on = EstimatorSettings {
        kalman: true,
        ..w.estimator.unwrap()
    };
    let mut sigma = w.estimator.unwrap();
    sigma.accel_sigma[5] = 0.005;
    let changed = [
        ConfigPatch {
            estimator: Some(on),
            ..w
        },
        ConfigPatch {
            estimator: Some(sigma),
            ..w
        },
        ConfigPatch {
            rate_hz: Some(200),
            ..w
        },
        ConfigPatch {
            robust: Some(false),
            ..w
        },
        ConfigPatch {
            delta_max: Some(0.5),
            ..w
        },
        ConfigPatch {
            voltage_limit: Some(12.0),
            ..w
        },
        ConfigPatch {
            stale_periods: Some(3),
            ..w
        },
        ConfigPatch {
            lockstep: Some(true),
            ..w
        },
        ConfigPatch {
            thrust_unit: Some(ThrustUnit::Newton),
            ..w
        },
        ConfigPatch {
            reversed_thrusters: Some(0),
            ..w
        },
        ConfigPatch {
            priority: Some(priority),
            ..w
        },
    ];
    let mut digests: Vec<u32> = changed.iter().filter_map(ConfigPatch::digest).collect();
    digests.extend(w.digest());
    let n = digests.len();
    digests.sort_unstable();
    digests.dedup();
    assert_eq!(digests.len(), n, "ten configurations, ten digests");
    // The same configuration, the same digest (a copy, and the same fields rebuilt).
    assert_eq!(defaults().digest(), w.digest());
}

/// Telemetry of a board that flies `applied` (the fields `confirm` reads; the rest as the
/// largest report has them).
fn telemetry_of(applied: &ConfigPatch) -> Telemetry {
    Telemetry {
        thrust_unit: applied.thrust_unit.unwrap(),
        reversed_thrusters: applied.reversed_thrusters.unwrap(),
        config_digest: applied.digest().unwrap(),
        ..Telemetry::LARGEST
    }
}

#[test]
fn confirm_accepts_the_board_that_flies_what_was_sent_and_names_what_differs() {
    let sent = ConfigPatch {
        rate_hz: Some(200),
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(0),
        ..defaults()
    };
    assert_eq!(sent.confirm(&telemetry_of(&sent)), Ok(()));
    // A board reset to its defaults (its watchdog) differs in unit first.
    assert_eq!(
        sent.confirm(&telemetry_of(&defaults())),
        Err(ConfigMismatch::ThrustUnit {
            sent: ThrustUnit::Newton,
            board: ThrustUnit::Kgf
        })
    );
    // Same unit, another mounting.
    let other_mounting = ConfigPatch {
        reversed_thrusters: Some(0b101),
        ..sent
    };
    assert_eq!(
        sent.confirm(&telemetry_of(&other_mounting)),
        Err(ConfigMismatch::Mounting {
            sent: 0,
            board: 0b101
        })
    );
    // Same unit and mounting, another rate: only the digest tells.
    let slower = ConfigPatch {
        rate_hz: Some(100),
        ..sent
    };
    let err = sent.confirm(&telemetry_of(&slower)).unwrap_err();
    assert_eq!(
        err,
        ConfigMismatch::Digest {
            sent: sent.digest().unwrap(),
            board: slower.digest().unwrap()
        }
    );
    assert!(err.to_string().contains("reset to its defaults"), "{err}");
    // A patch that leaves a field unset cannot be confirmed by a digest.
    let partial = ConfigPatch {
        priority: None,
        ..sent
    };
    assert_eq!(
        partial.confirm(&telemetry_of(&sent)),
        Err(ConfigMismatch::NotWhole)
    );
}
