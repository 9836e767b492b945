//! The board's answer to each control period ([`Periods`]), lock-step or in real time
//! (**Choice 66**): lock-step, the board's answer to this period's state frame; real time, the
//! answer if it comes before the next period is due, else the newest telemetry. It owns the
//! pacing (the real-time pacer, [`RealTime`]), the board's newest telemetry and the last of
//! its periods seen.

use std::time::Instant;

use auv_link::Telemetry;

use super::error::Error;
use super::link::Link;
use super::pacing::{Pacing, RealTime, RealTimeStats, PHASE_FRAMES};

/// Board periods real time's period 0 waits for an answer that took all it sent (Choice 83),
/// before it takes the newest telemetry.
const K0_PATIENCE: u32 = 10;

/// The run's periods as the board answers them.
pub(super) struct Periods {
    /// Real time's pacer and figures (`None`: lock-step).
    rt: Option<RealTime>,
    /// The newest telemetry (real time: what the thrusters apply when a reply is late).
    latest: Telemetry,
    /// The board's last period seen.
    last_tick: Option<u64>,
}

impl Periods {
    /// The periods of a run paced by `pacing` at `rate_hz`, once the board reported itself
    /// `armed`.
    pub(super) fn new(pacing: Pacing, rate_hz: u32, armed: Telemetry) -> Self {
        Periods {
            rt: (pacing == Pacing::Realtime).then(|| RealTime::new(rate_hz)),
            latest: armed,
            last_tick: None,
        }
    }

    pub(super) fn pacing(&self) -> Pacing {
        if self.rt.is_some() {
            Pacing::Realtime
        } else {
            Pacing::Lockstep
        }
    }

    /// Real time: the board's period phase, from the frames it sends armed at the mission's
    /// rate (**Choice 78**); nothing in lock-step.
    pub(super) fn find_phase(&mut self, link: &mut Link) -> Result<(), Error> {
        let Some(rt) = &mut self.rt else {
            return Ok(());
        };
        let mut arrivals = Vec::with_capacity(PHASE_FRAMES);
        for _ in 0..PHASE_FRAMES {
            self.latest = link.next_telemetry()?;
            arrivals.push(link.heard());
        }
        rt.find_edge(&arrivals);
        Ok(())
    }

    /// Real time: waits until period `k` is due.
    pub(super) fn pace(&mut self, k: u64) {
        if let Some(rt) = &mut self.rt {
            rt.pace(k);
        }
    }

    /// State frame `seq` was sent now.
    pub(super) fn sent(&mut self, seq: u16) {
        if let Some(rt) = &mut self.rt {
            rt.sent(seq);
        }
    }

    /// The board's answer for period `k`, whose state frame the board will answer as
    /// `expect_seq` (none for a frame it refuses or drops), the last frame of the period
    /// being `last_sent`.
    pub(super) fn reply(
        &mut self,
        link: &mut Link,
        k: u64,
        expect_seq: Option<u16>,
        last_sent: Option<u16>,
    ) -> Result<Telemetry, Error> {
        match self.rt {
            None => self.lockstep_reply(link, expect_seq),
            Some(_) => self.realtime_reply(link, k, expect_seq, last_sent),
        }
    }

    /// Real time's figures (none in lock-step).
    pub(super) fn finish(&mut self) -> Option<RealTimeStats> {
        self.rt.as_mut().map(RealTime::finish)
    }

    /// Lock-step: the board's answer to the state frame `expect_seq`; if it timed out before
    /// the frame arrived (host slower than the board's virtual clock), that timeout period is
    /// skipped. Without a valid frame the answer is the board's next (timed-out) period.
    fn lockstep_reply(
        &mut self,
        link: &mut Link,
        expect_seq: Option<u16>,
    ) -> Result<Telemetry, Error> {
        loop {
            let t = self.next_period(link)?;
            match expect_seq {
                Some(seq) if t.last_state_seq != seq => continue,
                _ => return Ok(t),
            }
        }
    }

    /// Real time: the board's output for state frame `expect_seq` if it arrives before
    /// period `k + 1` is due, else the newest output the board sent (a late frame: the
    /// thrusters hold what the board last commanded, as they would on the vehicle). Period 0
    /// waits for its answer, and the run's wall clock starts then.
    /// **Choice 66**, docs/board.md#pacing.
    fn realtime_reply(
        &mut self,
        link: &mut Link,
        k: u64,
        expect_seq: Option<u16>,
        last_sent: Option<u16>,
    ) -> Result<Telemetry, Error> {
        if k == 0 {
            return self.first_reply(link, expect_seq, last_sent);
        }
        let due = match &mut self.rt {
            Some(rt) => rt.due(k + 1),
            None => Instant::now(),
        };
        loop {
            match self.poll_period(link, Some(due))? {
                Some(t) => {
                    self.answered(&t, link.heard());
                    if expect_seq.is_some_and(|seq| t.last_state_seq == seq) {
                        return Ok(t);
                    }
                }
                None => {
                    if let (Some(rt), Some(_)) = (&mut self.rt, expect_seq) {
                        rt.late_frame();
                    }
                    return Ok(self.latest);
                }
            }
        }
    }

    /// Real time's period 0: the answer is the first telemetry that names the first state
    /// frame from a period in which the board had also taken the rest of what period 0 sent
    /// (the `StartMission` after it): when the two straddle one of the board's boundaries, the
    /// board's first answer names the state but is still `armed`, and flying on it would count
    /// a period with the thrusters off. After `K0_PATIENCE` board periods without such an
    /// answer (the frames were lost or damaged on the line), the newest telemetry is the
    /// answer: the mission goes on, and what the board did shows in the run's faults — never
    /// an unbounded wait while telemetry keeps coming.
    ///
    /// The mission starts with the board's answer to its first state frame (bounded by the
    /// reply timeout), so period 0 does not fly on a reply from before the mission ran. The
    /// board sends telemetry just after its period boundary: the run's clock starts half a
    /// period after the boundary that answer followed, so that the host's periods fall
    /// between the board's — a frame then waits half a period for the board, and its answer
    /// has half a period to come back. (Started on the answer itself, every frame arrived just
    /// after a boundary and was answered just after the next period was due: every frame
    /// late.) The boundary is the set-up's estimate (Choice 78), not the answer's arrival: a
    /// first answer delayed by a few ms put every later frame just after the board's
    /// boundary. The clocks drift apart over a run; the figures show it.
    fn first_reply(
        &mut self,
        link: &mut Link,
        expect_seq: Option<u16>,
        last_sent: Option<u16>,
    ) -> Result<Telemetry, Error> {
        let mut periods = 0;
        loop {
            let t = self.next_period(link)?;
            let heard = link.heard();
            self.answered(&t, heard);
            periods += 1;
            let took_all = last_sent.is_none_or(|seq| t.last_rx_seq == seq);
            let names_state = expect_seq.is_none_or(|seq| t.last_state_seq == seq);
            if (names_state && took_all) || periods > K0_PATIENCE {
                if let Some(rt) = &mut self.rt {
                    rt.start_after(heard);
                }
                return Ok(t);
            }
        }
    }

    /// Real time: telemetry `t`, which arrived at `at`, answers the state frame it names.
    fn answered(&mut self, t: &Telemetry, at: Instant) {
        if let Some(rt) = &mut self.rt {
            rt.answered(t.last_state_seq, at);
        }
    }

    /// The telemetry of the board's next control period (later than any seen before).
    fn next_period(&mut self, link: &mut Link) -> Result<Telemetry, Error> {
        loop {
            if let Some(t) = self.poll_period(link, None)? {
                return Ok(t);
            }
        }
    }

    /// [`Periods::next_period`], or `None` once `until` has passed; in real time, counts the
    /// telemetry's arrivals and the board's periods missing between two frames.
    fn poll_period(
        &mut self,
        link: &mut Link,
        until: Option<Instant>,
    ) -> Result<Option<Telemetry>, Error> {
        loop {
            let Some(t) = link.poll_telemetry(until)? else {
                return Ok(None);
            };
            if let Some(rt) = &mut self.rt {
                rt.arrived(link.heard());
            }
            if self.last_tick.is_none_or(|last| t.tick > last) {
                if let (Some(rt), Some(last)) = (&mut self.rt, self.last_tick) {
                    rt.board_missed(t.tick - last - 1);
                }
                self.last_tick = Some(t.tick);
                self.latest = t;
                return Ok(Some(t));
            }
        }
    }
}
