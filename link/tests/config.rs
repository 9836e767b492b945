//! The board's whole configuration and its digest (protocol 6, Choice 228): the digest is the
//! documented CRC-32 of the patch's postcard bytes (checked against a bitwise CRC-32 and bytes
//! laid out by hand), every field moves it, and `confirm` tells a board that flies what was
//! sent from one that does not, naming what differs where telemetry can tell.

use auv_link::{
    AxisPriority, BBound, ConfigMismatch, ConfigPatch, EstimatorSettings, LawSettings, RobustLaw,
    Telemetry, ThrustUnit,
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
    assert_eq!(w.law, Some(LawSettings::of(&c)));
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
        ConfigPatch { law: None, ..w },
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
    // Protocol 8: the law's K₁, K₂, q₁, q₂, β, μ, then Theorem 4 (1), the controlled rows (0),
    // then the pitch limit.
    for x in c.k1.iter().chain(&c.k2).chain(&c.q).chain(&[c.beta, c.mu]) {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    bytes.extend_from_slice(&[1, 0]);
    bytes.extend_from_slice(&c.pitch_limit.to_le_bytes());
    assert_eq!(bytes.len(), 190);
    assert_eq!(w.digest(), Some(crc32_by_hand(&bytes)));
    // Theorem 3 is the law's wire index 0, the literal bound the bound's 1 (bytes 184, 185).
    let mut other = w.law.unwrap();
    other.law = RobustLaw::Discontinuous;
    other.b_bound = BBound::Literal;
    let mut other_bytes = bytes.clone();
    other_bytes[184] = 0;
    other_bytes[185] = 1;
    assert_eq!(
        ConfigPatch {
            law: Some(other),
            ..w
        }
        .digest(),
        Some(crc32_by_hand(&other_bytes))
    );
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
    // Protocol 8: each law setting, changed alone.
    let law = w.law.unwrap();
    let laws = [
        LawSettings { mu: 0.15, ..law },
        LawSettings { beta: 0.7, ..law },
        LawSettings {
            pitch_limit: 1.0,
            ..law
        },
        LawSettings {
            q: [1.0, 2.0],
            ..law
        },
        LawSettings {
            law: RobustLaw::Discontinuous,
            ..law
        },
        LawSettings {
            b_bound: BBound::Literal,
            ..law
        },
        LawSettings {
            k1: [5.0, 4.0, 4.0, 0.0, 4.0, 4.0],
            ..law
        },
        LawSettings {
            k2: [4.0, 4.0, 4.0, 0.0, 4.0, 3.0],
            ..law
        },
        // The same value as K₁'s change, in K₂: the digest tells the fields apart.
        LawSettings {
            k2: [5.0, 4.0, 4.0, 0.0, 4.0, 4.0],
            ..law
        },
    ];
    let mut changed = vec![
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
    changed.extend(laws.map(|l| ConfigPatch { law: Some(l), ..w }));
    let mut digests: Vec<u32> = changed.iter().filter_map(ConfigPatch::digest).collect();
    digests.extend(w.digest());
    let n = digests.len();
    digests.sort_unstable();
    digests.dedup();
    assert_eq!(n, 21);
    assert_eq!(digests.len(), n, "21 configurations, 21 digests");
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

/// Protocol 8: the law's settings cross field for field, every f32 keeping its bits, and
/// `apply` changes the law's fields of a configuration and nothing else.
#[test]
fn the_law_settings_cross_field_for_field() {
    let mut c = ControllerConfig {
        mu: 0.15,
        beta: 0.7,
        q: [1.0, 2.0],
        pitch_limit: 1.0,
        law: controller_core::RobustLaw::Discontinuous,
        b_bound: controller_core::BBound::Literal,
        ..ControllerConfig::default()
    };
    c.k1[0] = 5.0;
    c.k2[5] = f32::from_bits(0x7FC0_1234); // a NaN with a payload
    let law = LawSettings::of(&c);
    assert_eq!(law.law, RobustLaw::Discontinuous);
    assert_eq!(law.b_bound, BBound::Literal);
    let mut back = ControllerConfig {
        rate_hz: 50,
        delta_max: 12.5,
        ..ControllerConfig::default()
    };
    law.apply(&mut back);
    assert_eq!(back.k2[5].to_bits(), 0x7FC0_1234);
    // Everything but what the law does not carry is `c`'s; that is `back`'s own.
    back.k2[5] = c.k2[5];
    assert_eq!(
        format!("{back:?}"),
        format!(
            "{:?}",
            ControllerConfig {
                rate_hz: 50,
                delta_max: 12.5,
                ..c
            }
        )
    );
}
