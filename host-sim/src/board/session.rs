//! The session with the board ([`Session`]): what the run asks of it (the configuration, the
//! mission, the thrust unit and mounting it must fly) and where it stands — the set-up
//! (numbering, disarm, `SetConfig`, a waypoint mission's upload, `Arm`, until armed), the
//! mission's start with the first period, and the re-arm after a fail-safe once the link is
//! healthy again.

use std::time::{Duration, Instant};

use auv_link::{
    BoardStatus, Command as LinkCommand, ConfigPatch, MissionPlan, MissionUpload, Msg, Telemetry,
    ThrustUnit, DEFAULT_STALE_PERIODS,
};

use super::error::Error;
use super::link::Link;
use super::pacing::Pacing;
use super::stats::{FailSafeEvent, FailSafeEventKind, UploadStats};
use super::upload::upload;
use crate::scenario::Scenario;

/// The longest the set-up waits for the board to report itself armed, whatever telemetry
/// keeps coming.
const ARM_WAIT: Duration = Duration::from_secs(30);

/// What the run asks of the board, and where the session stands.
pub(super) struct Session {
    config: ConfigPatch,
    mission: MissionPlan,
    /// A waypoint mission's upload (none for a closed-form path).
    upload: Option<MissionUpload>,
    /// The thrust unit the plant reads the board's voltages in: every telemetry frame must
    /// report it.
    thrust_unit: ThrustUnit,
    /// The scenario's mounting, as the link's reversed-thruster mask.
    mounting: u8,
    /// The control rate (Hz; the fail-safe events' times).
    rate_hz: u32,
    /// The mission has been started.
    started: bool,
    /// The board went to fail-safe: re-arm once the link is healthy.
    needs_rearm: bool,
    last_status: Option<BoardStatus>,
}

/// What the set-up leaves: the board's telemetry that reported it armed, and a waypoint
/// mission's upload with the board's last refusal when it verified it.
pub(super) struct SetUp {
    pub(super) armed: Telemetry,
    pub(super) upload: Option<(UploadStats, Telemetry)>,
}

impl Session {
    /// The session of `scenario`'s validated controller and mission, paced by `pacing`.
    /// Refuses a thruster geometry the link cannot carry. The whole configuration is sent
    /// (`ConfigPatch::whole`: the law's settings — K₁, K₂, Q, β, μ, the robust law, the ‖b‖
    /// bound, the pitch limit since protocol 8, Choice 508 — the thruster chain and the state
    /// estimator's settings, from which the board computes its gains, Choice 361), so the
    /// board flies the law the scenario sets, as SIL does.
    pub(super) fn new(scenario: &Scenario, pacing: Pacing) -> Result<Self, Error> {
        let c = scenario.controller().config();
        // The link carries the geometry as the AUV-150 layout's reversed-thruster mask.
        let mounting = c.geometry.auv150_reversed().ok_or(Error::Geometry)?;
        let thrust_unit = ThrustUnit::from(c.thrust_unit);
        let mission = scenario.trajectory().mission();
        Ok(Session {
            config: ConfigPatch::whole(c, DEFAULT_STALE_PERIODS, pacing == Pacing::Lockstep),
            mission: MissionPlan::from(mission),
            upload: MissionUpload::of(&mission),
            thrust_unit,
            mounting,
            rate_hz: c.rate_hz,
            started: false,
            needs_rearm: false,
            last_status: None,
        })
    }

    /// The set-up over `link`: numbers this end's frames after the board's last, disarms,
    /// configures, uploads a waypoint mission (its chunks `lose` lost on their first
    /// sending), arms, and waits until the board reports itself armed with the scenario's
    /// mounting and unit.
    ///
    /// **Choice 65** (docs/board.md#hardware-in-the-loop): disarm first (a bench board may still be armed
    /// from a run before, and refuses a configuration while armed); `Armed` counts only from
    /// telemetry whose `last_rx_seq` is the `Arm`'s (an earlier frame of a board that was
    /// armed before says nothing of this set-up). Armed, the board must fly every field of
    /// the configuration sent (its mounting and unit by name, the rest by the digest of the
    /// whole, Choice 228).
    pub(super) fn set_up(&mut self, link: &mut Link, lose: &[u8]) -> Result<SetUp, Error> {
        // Continue the board's numbering: a board that already heard a runner (this one
        // restarted) drops frames numbered at or before its last (auv_link::seq).
        let first = link.next_telemetry()?;
        if first.rx_frames > 0 {
            link.number_after(first.last_rx_seq);
        }
        // A fresh board is disarmed already; disarming is never refused.
        link.send(Msg::Command(LinkCommand::Disarm))?;
        link.send(Msg::Command(LinkCommand::SetConfig(self.config)))?;
        // A waypoint mission travels as an upload, taken only while disarmed (upload.rs),
        // once the board has taken the configuration (its refusals are the set-up's, those
        // of a lossy upload the upload's own).
        let mut refused = first.refused_commands;
        let mut uploaded = None;
        if let Some(up) = &self.upload {
            let t = link.acknowledged(link.last_seq())?;
            refuse_if(&t, refused)?;
            let (stats, t) = upload(link, up, lose)?;
            refused = t.refused_commands;
            uploaded = Some((stats, t));
        }
        let arm_seq = link.next_seq();
        link.send(Msg::Command(LinkCommand::Arm))?;
        let armed = self.wait_armed(link, arm_seq, refused)?;
        Ok(SetUp {
            armed,
            upload: uploaded,
        })
    }

    /// The telemetry that reports the board armed by the `Arm` numbered `arm_seq` with the
    /// scenario's mounting and unit; the board had refused `refused_before` commands before.
    fn wait_armed(
        &self,
        link: &mut Link,
        arm_seq: u16,
        refused_before: u32,
    ) -> Result<Telemetry, Error> {
        let deadline = Instant::now() + ARM_WAIT;
        loop {
            let t = link.next_telemetry()?;
            refuse_if(&t, refused_before)?;
            if t.status == BoardStatus::Armed && t.last_rx_seq == arm_seq {
                if t.reversed_thrusters != self.mounting {
                    return Err(Error::Mounting {
                        board: t.reversed_thrusters,
                        scenario: self.mounting,
                    });
                }
                self.check_unit(&t)?;
                // Every other field, through the digest of the whole configuration sent.
                self.config
                    .confirm(&t)
                    .map_err(|mismatch| Error::Config { mismatch })?;
                return Ok(t);
            }
            if Instant::now() > deadline {
                return Err(Error::NotArmed { status: t.status });
            }
        }
    }

    /// The board reports the thrust unit the plant reads its voltages in.
    pub(super) fn check_unit(&self, t: &Telemetry) -> Result<(), Error> {
        if t.thrust_unit == self.thrust_unit {
            Ok(())
        } else {
            Err(Error::ThrustUnit {
                board: t.thrust_unit,
                plant: self.thrust_unit,
                tick: t.tick,
            })
        }
    }

    /// The commands of a period whose link is `healthy`: the mission's start with the first;
    /// after a fail-safe, once the link is healthy again, the re-arming (the fail-safe latches
    /// until then) and the mission's start again, since disarming dropped it (its first state
    /// frame sets the board's mission clock to this tick). Returns them and whether they
    /// re-arm.
    pub(super) fn commands(&mut self, healthy: bool) -> (Vec<LinkCommand>, bool) {
        let mut out = Vec::new();
        let rearm = self.needs_rearm && healthy;
        if rearm {
            out.extend([
                LinkCommand::Disarm,
                LinkCommand::Arm,
                LinkCommand::StartMission(self.mission),
            ]);
            self.needs_rearm = false;
        }
        if !self.started {
            out.push(LinkCommand::StartMission(self.mission));
            self.started = true;
        }
        (out, rearm)
    }

    /// Notes the board's status in telemetry `t`, the answer of period `k`: an entry into
    /// fail-safe (which asks for a re-arm) or an exit from it.
    pub(super) fn note(&mut self, t: &Telemetry, k: u64) -> Option<FailSafeEvent> {
        let was_fail = matches!(self.last_status, Some(BoardStatus::FailSafe(_)));
        let is_fail = matches!(t.status, BoardStatus::FailSafe(_));
        self.last_status = Some(t.status);
        let (kind, reason) = match t.status {
            BoardStatus::FailSafe(reason) if !was_fail => {
                self.needs_rearm = true;
                (FailSafeEventKind::Enter, reason.as_str().to_string())
            }
            status if was_fail && !is_fail => (FailSafeEventKind::Exit, format!("{status:?}")),
            _ => return None,
        };
        Some(FailSafeEvent {
            tick: k,
            t: k as f64 / f64::from(self.rate_hz),
            kind,
            reason,
        })
    }
}

/// The set-up fails if telemetry `t` counts more refused commands than `before`.
fn refuse_if(t: &Telemetry, before: u32) -> Result<(), Error> {
    if t.refused_commands > before {
        Err(Error::Refused {
            reason: t.last_refusal,
        })
    } else {
        Ok(())
    }
}
