//! The board's whole configuration on the link and its digest (protocol 6, Choice 228).
//!
//! A [`ConfigPatch`] with every field set ([`ConfigPatch::is_whole`]) is a board's whole link
//! configuration: what [`ConfigPatch::whole`] makes of the core's `ControllerConfig`, the
//! stale-state limit and the pacing. Every telemetry frame carries the
//! [`ConfigPatch::digest`] of the configuration the board flies
//! ([`Telemetry::config_digest`]), so a navigation computer that sent a whole patch confirms
//! every field it set by comparing one number ([`ConfigPatch::confirm`]): a board that reset
//! (its watchdog, a brown-out) is back on its defaults, and says so in its next frame.
//!
//! **The digest** is the CRC-32/ISO-HDLC (the mission upload's, [`crate::upload`]) of the
//! whole configuration's fields in declaration order, each as fixed bytes: `rate_hz` (u32,
//! little-endian), `robust` (1 byte, 0 or 1), `delta_max` and `voltage_limit` (f32, their four
//! little-endian bytes), `stale_periods` (1 byte), `lockstep` (0 or 1), the thrust unit (its
//! wire index: 0 kgf, 1 newton), `reversed_thrusters` (1 byte), then the priority's six ranks
//! (1 byte each) and six weights (f32 each), then the estimator's (protocol 7): on (0 or 1),
//! σₚ, σᵥ, σₐ (six f32 each), then the law's (protocol 8): K₁, K₂ (six f32 each), q₁, q₂, β,
//! μ (f32 each), the robust law's and the ‖b‖ bound's wire index (1 byte each: 0 Theorem 3,
//! 1 Theorem 4; 0 controlled rows, 1 literal) and the pitch limit (f32): 190 bytes. Written
//! field by field, not through postcard, so that the board carries no serializer for a message
//! it only receives.

use controller_core::ControllerConfig;

use crate::msg::{BBound, ConfigPatch, LawSettings, RobustLaw, Telemetry, ThrustUnit, NOT_AUV150};
use crate::upload::CRC32;

/// Bytes the digest covers (module docs).
const DIGEST_BYTES: usize = 4 + 1 + 4 + 4 + 1 + 1 + 1 + 1 + 6 + 6 * 4 + 1 + 18 * 4 + LAW_BYTES;
/// The law's bytes of the digest (protocol 8).
const LAW_BYTES: usize = 16 * 4 + 1 + 1 + 4;

/// The thruster mounting a board that flies `config` reports: the AUV-150 layout's
/// reversed-thruster mask ([`Telemetry::reversed_thrusters`]), or [`NOT_AUV150`] for a geometry
/// that is not the AUV-150 layout (a board built with another geometry; the link cannot set
/// one).
pub fn mounting_of(config: &ControllerConfig) -> u8 {
    config.geometry.auv150_reversed().unwrap_or(NOT_AUV150)
}

impl ConfigPatch {
    /// The whole link configuration of a board that flies `config`, with `stale_periods` and
    /// `lockstep`: every field set, the mounting as [`mounting_of`] reports it.
    pub fn whole(config: &ControllerConfig, stale_periods: u8, lockstep: bool) -> ConfigPatch {
        ConfigPatch {
            rate_hz: Some(config.rate_hz),
            robust: Some(config.robust),
            delta_max: Some(config.delta_max),
            voltage_limit: Some(config.voltage_limit),
            stale_periods: Some(stale_periods),
            lockstep: Some(lockstep),
            thrust_unit: Some(config.thrust_unit.into()),
            reversed_thrusters: Some(mounting_of(config)),
            priority: Some(config.priority.into()),
            estimator: Some(config.estimator.into()),
            law: Some(LawSettings::of(config)),
        }
    }

    /// Every field is set: the patch is a whole configuration, and has a digest.
    pub fn is_whole(&self) -> bool {
        self.digest().is_some()
    }

    /// The digest of a whole configuration (module docs; `None` if a field is unset): what
    /// [`Telemetry::config_digest`] reports of a board that flies it. Two configurations
    /// with the same digest are the same, bit for bit, but for a 2⁻³² chance.
    pub fn digest(&self) -> Option<u32> {
        let (
            Some(rate_hz),
            Some(robust),
            Some(delta_max),
            Some(voltage_limit),
            Some(stale_periods),
            Some(lockstep),
            Some(unit),
            Some(mounting),
            Some(priority),
            Some(estimator),
            Some(law),
        ) = (
            self.rate_hz,
            self.robust,
            self.delta_max,
            self.voltage_limit,
            self.stale_periods,
            self.lockstep,
            self.thrust_unit,
            self.reversed_thrusters,
            self.priority,
            self.estimator,
            self.law,
        )
        else {
            return None;
        };
        let mut bytes = [0u8; DIGEST_BYTES];
        bytes[..4].copy_from_slice(&rate_hz.to_le_bytes());
        bytes[4] = u8::from(robust);
        bytes[5..9].copy_from_slice(&delta_max.to_le_bytes());
        bytes[9..13].copy_from_slice(&voltage_limit.to_le_bytes());
        bytes[13] = stale_periods;
        bytes[14] = u8::from(lockstep);
        bytes[15] = match unit {
            ThrustUnit::Kgf => 0,
            ThrustUnit::Newton => 1,
        };
        bytes[16] = mounting;
        bytes[17..23].copy_from_slice(&priority.rank);
        for (i, w) in priority.weight.iter().enumerate() {
            bytes[23 + 4 * i..27 + 4 * i].copy_from_slice(&w.to_le_bytes());
        }
        bytes[47] = u8::from(estimator.kalman);
        let sigmas = [
            &estimator.position_sigma,
            &estimator.velocity_sigma,
            &estimator.accel_sigma,
        ];
        for (i, x) in sigmas.into_iter().flatten().enumerate() {
            bytes[48 + 4 * i..52 + 4 * i].copy_from_slice(&x.to_le_bytes());
        }
        law_bytes(&law, &mut bytes[DIGEST_BYTES - LAW_BYTES..]);
        Some(CRC32.checksum(&bytes))
    }

    /// Confirms that the board whose telemetry is `t` flies this whole patch: its thrust unit
    /// and mounting (named in every frame) and then every field through the digest.
    pub fn confirm(&self, t: &Telemetry) -> Result<(), ConfigMismatch> {
        let Some(sent) = self.digest() else {
            return Err(ConfigMismatch::NotWhole);
        };
        if let Some(sent) = self.thrust_unit {
            if t.thrust_unit != sent {
                return Err(ConfigMismatch::ThrustUnit {
                    sent,
                    board: t.thrust_unit,
                });
            }
        }
        if let Some(sent) = self.reversed_thrusters {
            if t.reversed_thrusters != sent {
                return Err(ConfigMismatch::Mounting {
                    sent,
                    board: t.reversed_thrusters,
                });
            }
        }
        if t.config_digest != sent {
            return Err(ConfigMismatch::Digest {
                sent,
                board: t.config_digest,
            });
        }
        Ok(())
    }
}

/// The law's bytes of the digest (module docs) into `out` (`LAW_BYTES` long).
fn law_bytes(law: &LawSettings, out: &mut [u8]) {
    let scalars = [law.beta, law.mu];
    let floats = law.k1.iter().chain(&law.k2).chain(&law.q).chain(&scalars);
    let mut n = 0;
    for x in floats {
        out[n..n + 4].copy_from_slice(&x.to_le_bytes());
        n += 4;
    }
    out[n] = match law.law {
        RobustLaw::Discontinuous => 0,
        RobustLaw::BoundaryLayer => 1,
    };
    out[n + 1] = match law.b_bound {
        BBound::ControlledRows => 0,
        BBound::Literal => 1,
    };
    out[n + 2..n + 6].copy_from_slice(&law.pitch_limit.to_le_bytes());
}

/// Why a board's telemetry does not confirm a configuration ([`ConfigPatch::confirm`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigMismatch {
    /// The patch sent leaves a field unset: only a whole configuration has a digest to
    /// compare.
    NotWhole,
    /// The board reads Eqs 31–32 in another unit.
    ThrustUnit {
        /// The unit sent.
        sent: ThrustUnit,
        /// The unit the board flies.
        board: ThrustUnit,
    },
    /// The board flies another mounting (reversed-thruster mask).
    Mounting {
        /// The mask sent.
        sent: u8,
        /// The board's.
        board: u8,
    },
    /// Another field differs (or the board reset to its defaults): the digests differ.
    Digest {
        /// The digest of the configuration sent.
        sent: u32,
        /// The board's.
        board: u32,
    },
}

impl core::fmt::Display for ConfigMismatch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ConfigMismatch::NotWhole => {
                f.write_str("the configuration sent does not set every field, so it cannot be confirmed")
            }
            ConfigMismatch::ThrustUnit { sent, board } => write!(
                f,
                "the board reads its thrust in {board:?}, not the {sent:?} sent"
            ),
            ConfigMismatch::Mounting { sent, board } => write!(
                f,
                "the board flies thruster mounting {board:#07b}, not the {sent:#07b} sent"
            ),
            ConfigMismatch::Digest { sent, board } => write!(
                f,
                "the board flies a configuration with digest {board:08x}, not the {sent:08x} sent (a field differs, or the board reset to its defaults)"
            ),
        }
    }
}
