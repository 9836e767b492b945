//! The board's whole configuration on the link and its digest (protocol 6, Choice 228).
//!
//! A [`ConfigPatch`] with every field set ([`ConfigPatch::is_whole`]) is a board's whole link
//! configuration: what [`ConfigPatch::whole`] makes of the core's `ControllerConfig`, the
//! stale-state limit and the pacing. Every telemetry frame carries the
//! [`ConfigPatch::digest`] of the configuration the board flies
//! ([`Telemetry::config_digest`]), so a navigation computer that sent a whole patch confirms
//! every field it set by comparing one number ([`ConfigPatch::confirm`]): a board that reset
//! (its watchdog, a brown-out) is back on its defaults, and says so in its next frame.

use controller_core::ControllerConfig;

use crate::msg::{ConfigPatch, Telemetry, ThrustUnit, NOT_AUV150};

/// CRC-32/ISO-HDLC, as the mission upload's (`crate::upload`).
const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

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
        }
    }

    /// Every field is set: the patch is a whole configuration, and its digest is what a board
    /// that took it reports.
    pub const fn is_whole(&self) -> bool {
        self.rate_hz.is_some()
            && self.robust.is_some()
            && self.delta_max.is_some()
            && self.voltage_limit.is_some()
            && self.stale_periods.is_some()
            && self.lockstep.is_some()
            && self.thrust_unit.is_some()
            && self.reversed_thrusters.is_some()
            && self.priority.is_some()
    }

    /// The CRC-32 (ISO-HDLC) of the patch's postcard encoding: its fields in order, each f32
    /// as its four bytes, so two patches have the same digest exactly when they encode the
    /// same (a 2⁻³² chance otherwise). For a whole patch, what [`Telemetry::config_digest`]
    /// reports of a board that flies it.
    pub fn digest(&self) -> u32 {
        let mut buf = [0u8; ConfigPatch::MAX_SIZE];
        // A patch always fits MAX_SIZE (the link's tests hold the bound exact), so the empty
        // slice of a failed encoding is never digested in place of one.
        let bytes = postcard::to_slice(self, &mut buf).map_or(&[][..], |b| &b[..]);
        CRC32.checksum(bytes)
    }

    /// Confirms that the board whose telemetry is `t` flies this whole patch: its thrust unit
    /// and mounting (named in every frame) and then every field through the digest.
    pub fn confirm(&self, t: &Telemetry) -> Result<(), ConfigMismatch> {
        if !self.is_whole() {
            return Err(ConfigMismatch::NotWhole);
        }
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
        let sent = self.digest();
        if t.config_digest != sent {
            return Err(ConfigMismatch::Digest {
                sent,
                board: t.config_digest,
            });
        }
        Ok(())
    }
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
