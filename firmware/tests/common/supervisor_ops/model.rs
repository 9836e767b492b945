//! The model of what the board may do, learnt only from the frames sent and the supervisor's
//! public counters, and the invariants of its state table checked after every command and
//! every control period.

use super::*;

/// What the board may have done: learnt only from the frames sent and the supervisor's public
/// counters and telemetry.
#[derive(Clone, Copy, Debug)]
pub(super) struct Model {
    pub(super) armed: bool,
    pub(super) mission: bool,
    pub(super) lockstep: bool,
    pub(super) stale_periods: u8,
    pub(super) latched: Option<FailSafeReason>,
    /// Disarmed since the latch (the next accepted `Arm` clears it).
    pub(super) disarmed_since_latch: bool,
    pub(super) last_seq: Option<u16>,
    pub(super) last_timestamp: Option<u64>,
    /// Time the board counted since `last_timestamp` was accepted (timestamp units).
    pub(super) counted: u64,
    /// Authentic frames refused as too far ahead.
    pub(super) ahead: u32,
    /// Periods run since the last accepted state frame (`None`: none, or none since the
    /// mission started).
    pub(super) periods_since_state: Option<u64>,
    /// Lock-step mission clock: the last accepted tick, and periods since.
    pub(super) clock: Option<(u64, u64)>,
    /// Periods run since the mission started (a mission waits `stale_periods` for its first
    /// state).
    pub(super) mission_periods: u64,
    /// An accepted `SetConfig` changed the controller's configuration since the last period:
    /// a rebuild, the period's long job (Choice 226).
    pub(super) rebuilt: bool,
}

impl Model {
    pub(super) fn new() -> Self {
        Model {
            armed: false,
            mission: false,
            lockstep: false,
            stale_periods: DEFAULT_STALE_PERIODS,
            latched: None,
            disarmed_since_latch: false,
            last_seq: None,
            last_timestamp: None,
            counted: 0,
            ahead: 0,
            periods_since_state: None,
            clock: None,
            mission_periods: 0,
            rebuilt: false,
        }
    }

    pub(super) fn fresh(&self) -> bool {
        self.periods_since_state
            .is_some_and(|n| n <= u64::from(self.stale_periods))
    }

    /// A mission that has had no state yet, still within its `stale_periods` grace: running,
    /// thrusters off.
    pub(super) fn waiting(&self) -> bool {
        self.periods_since_state.is_none() && self.mission_periods <= u64::from(self.stale_periods)
    }
}

/// The supervisor's settings a `SetConfig` may change.
pub(super) fn settings(sup: &Supervisor) -> (ControllerConfig, u8, bool) {
    (
        *sup.controller().config(),
        sup.stale_periods(),
        sup.lockstep(),
    )
}

impl Harness {
    pub(super) fn command(&mut self, c: &Command, refused: bool) {
        let m = &mut self.model;
        match c {
            Command::Arm => {
                if refused {
                    assert!(m.armed && m.latched.is_some(), "Arm refused: {m:?}");
                } else {
                    assert!(
                        !(m.armed && m.latched.is_some()),
                        "lone Arm accepted, latched"
                    );
                    if !m.armed {
                        if m.latched.is_some() {
                            assert!(m.disarmed_since_latch);
                            self.stats.rearms_after_latch += 1;
                        }
                        m.latched = None;
                        m.disarmed_since_latch = false;
                    }
                    m.armed = true;
                }
            }
            Command::Disarm | Command::StopMission => {
                assert!(!refused, "{c:?} refused");
                if matches!(c, Command::Disarm) {
                    m.armed = false;
                    m.disarmed_since_latch = m.latched.is_some();
                }
                m.mission = false;
            }
            Command::StartMission(_) => {
                if !refused {
                    assert!(
                        m.armed && m.latched.is_none() && !m.mission,
                        "StartMission accepted: {m:?}"
                    );
                    m.mission = true;
                    m.mission_periods = 0;
                    m.clock = None;
                    // A new mission counts from its start, in either pacing (Choice 227): a
                    // state from before it is not its state.
                    m.periods_since_state = None;
                }
            }
            Command::Upload(_) => {
                assert!(refused || !m.armed, "an upload part accepted armed");
            }
            Command::SetConfig(p) => {
                if !refused {
                    assert!(!m.armed, "SetConfig accepted armed");
                    if let Some(n) = p.stale_periods {
                        m.stale_periods = n;
                    }
                    if let Some(l) = p.lockstep {
                        m.lockstep = l;
                    }
                    assert_eq!(self.sup.stale_periods(), m.stale_periods, "whole patch");
                    assert_eq!(self.sup.lockstep(), m.lockstep, "whole patch");
                    let cfg = self.sup.controller().config();
                    assert!(p.rate_hz.is_none_or(|r| r == cfg.rate_hz), "whole patch");
                    assert!(
                        p.voltage_limit
                            .is_none_or(|v| v.to_bits() == cfg.voltage_limit.to_bits()),
                        "whole patch"
                    );
                    assert!(
                        cfg.voltage_limit <= SUPPLY,
                        "voltage limit above the supply"
                    );
                }
            }
        }
    }

    /// One control period, checked; returns its telemetry.
    pub(super) fn period(&mut self, overrun: bool) -> Telemetry {
        let step = self.sup.step(overrun, &|| 0);
        let t: Telemetry = step.telemetry;
        self.stats.periods += 1;
        let limit = self.sup.controller().config().voltage_limit;
        for v in step.voltages {
            assert!(
                v.is_finite() && v.abs() <= limit,
                "voltage {v}, limit {limit}"
            );
        }
        let on = step.voltages.iter().any(|v| *v != 0.0);
        // A rebuild is the period's long job, and a period that ran one never flies.
        assert!(
            step.long_job || !self.model.rebuilt,
            "a rebuild not counted as the period's long job"
        );
        assert!(!(step.long_job && on), "a period with a long job flew");
        self.model.rebuilt = false;
        let m = self.model;
        let may_run = m.armed && m.mission && m.latched.is_none() && !overrun;
        let may_fly = may_run && m.fresh();
        if on {
            assert!(
                may_fly,
                "thrusters on {:?}, {t:?}, model {m:?}",
                step.voltages
            );
            assert_eq!(t.status, BoardStatus::Running);
            self.stats.periods_on += 1;
        } else if t.status == BoardStatus::Running {
            // Running with the thrusters off: a mission waiting for its first state.
            assert!(
                may_fly || (may_run && m.waiting()),
                "running, {t:?}, model {m:?}"
            );
        }
        match m.latched {
            Some(r) => {
                assert!(!on);
                assert_eq!(t.latched, Some(r), "the latched reason in every frame");
                let want = if m.armed {
                    BoardStatus::FailSafe(r)
                } else {
                    BoardStatus::Disarmed
                };
                assert_eq!(t.status, want);
            }
            None => match t.status {
                BoardStatus::FailSafe(r) => {
                    assert!(m.armed && m.mission, "fail-safe without a mission: {m:?}");
                    let want = if overrun {
                        FailSafeReason::Overrun
                    } else if !m.fresh() && !m.waiting() {
                        FailSafeReason::StaleState
                    } else {
                        FailSafeReason::ControllerFault
                    };
                    assert_eq!(r, want, "model {m:?}");
                    assert_eq!(t.latched, Some(r));
                    self.model.latched = Some(r);
                    self.stats.latches += 1;
                }
                status => {
                    assert_eq!(t.latched, None);
                    let want = match (m.armed, m.mission) {
                        (false, _) => BoardStatus::Disarmed,
                        (true, false) => BoardStatus::Armed,
                        (true, true) => BoardStatus::Running,
                    };
                    assert_eq!(status, want, "model {m:?}");
                }
            },
        }
        assert_eq!(t.rx_ahead, self.model.ahead, "frames refused as ahead");
        // The telemetry goes out: it always fits a frame and, signed, the board can always sign
        // it (this fuzz target once found a key holder's stamp at 2⁴⁸ − 1 leaving it none): the
        // navigation computer verifies it, and the stamp leaves at least RESERVE − periods.
        let env = self.sup.envelope(t);
        let frame = match self.link.encode(&env) {
            Ok(frame) => frame.to_vec(),
            Err(e) => panic!("telemetry does not encode: {e:?}, model {:?}", self.model),
        };
        assert!(frame.len() <= MAX_FRAME);
        if self.signing {
            let body = frame.strip_suffix(&[0]).expect("a delimited frame");
            let got = decode_frame_signed(&mut body.to_vec(), &mut self.nav);
            assert_eq!(
                got.map(|e| e.seq),
                Ok(env.seq),
                "the navigation end refused it"
            );
            let stamp = self.nav.last_timestamp().unwrap_or(0);
            let periods = u64::from(self.stats.periods);
            assert!(
                stamp <= CEILING + periods,
                "stamp {stamp}, {periods} periods"
            );
            assert!(MAX_TIMESTAMP - stamp >= auv_link::sign::RESERVE - periods);
        }
        // The period is over: the board counts it (its link's lead bound grows by as much).
        let rate = self.sup.rate_hz();
        self.link.period_passed(rate);
        let m = &mut self.model;
        m.counted += UNITS_PER_SECOND.div_ceil(u64::from(rate));
        m.periods_since_state = m.periods_since_state.map(|n| n + 1);
        m.mission_periods += 1;
        m.clock = m.clock.map(|(t, n)| (t, n + 1));
        t
    }
}
