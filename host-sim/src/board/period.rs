//! One control period with the board in the loop: [`BoardInTheLoop`] as the closed loop's
//! [`ControlSource`]. Lock-step: the board's answer to this period's state frame. Real time:
//! the answer if it comes before the next period is due, else the newest telemetry
//! (**Choice 66**).

use std::time::Instant;

use auv_link::{StateFrame, Telemetry};

use super::pacing::Pacing;
use super::runner::BoardInTheLoop;
use crate::sim::{ControlOut, ControlSource, ControlStatus};

/// Board periods real time's period 0 waits for an answer that took all it sent (Choice 83),
/// before it takes the newest telemetry.
const K0_PATIENCE: u32 = 10;

impl BoardInTheLoop {
    /// Lock-step: the board's answer to the state frame `expect_seq`; if it timed out before
    /// the frame arrived (host slower than the board's virtual clock), that timeout period is
    /// skipped. Without a valid frame the answer is the board's next (timed-out) period.
    fn lockstep_reply(&mut self, expect_seq: Option<u16>) -> Result<Telemetry, String> {
        loop {
            let t = self.next_period()?;
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
        k: u64,
        expect_seq: Option<u16>,
        last_sent: Option<u16>,
    ) -> Result<Telemetry, String> {
        if k == 0 {
            // The answer is the first telemetry that names the first state frame from a
            // period in which the board had also taken the rest of what period 0 sent (the
            // `StartMission` after it): when the two straddle one of the board's boundaries,
            // the board's first answer names the state but is still `armed`, and flying on it
            // would count a period with the thrusters off. After `K0_PATIENCE` board periods
            // without such an answer (the frames were lost or damaged on the line), the newest
            // telemetry is the answer: the mission goes on, and what the board did shows in
            // the run's faults — never an unbounded wait while telemetry keeps coming.
            let mut periods = 0;
            // The mission starts with the board's answer to its first state frame (bounded by
            // the reply timeout), so period 0 does not fly on a reply from before the mission
            // ran. The board sends telemetry just after its period boundary: the run's clock
            // starts half a period after the boundary that answer followed, so that the host's
            // periods fall between the board's — a frame then waits half a period for the
            // board, and its answer has half a period to come back. (Started on the answer
            // itself, every frame arrived just after a boundary and was answered just after
            // the next period was due: every frame late.) The boundary is the set-up's
            // estimate (Choice 78), not the answer's arrival: a first answer delayed by a few
            // ms put every later frame just after the board's boundary. The clocks drift
            // apart over a run; the figures show it.
            loop {
                let t = self.next_period()?;
                let heard = self.heard;
                if let Some(rt) = &mut self.rt {
                    rt.answered(t.last_state_seq, heard);
                }
                periods += 1;
                let took_all = last_sent.is_none_or(|seq| t.last_rx_seq == seq);
                let names_state = expect_seq.is_none_or(|seq| t.last_state_seq == seq);
                if (names_state && took_all) || periods > K0_PATIENCE {
                    if let Some(rt) = &mut self.rt {
                        rt.origin = Some(rt.origin_after(heard));
                    }
                    return Ok(t);
                }
            }
        }
        let due = match &mut self.rt {
            Some(rt) => rt.due(k + 1),
            None => Instant::now(),
        };
        loop {
            match self.poll_period(Some(due))? {
                Some(t) => {
                    let heard = self.heard;
                    if let Some(rt) = &mut self.rt {
                        rt.answered(t.last_state_seq, heard);
                    }
                    if expect_seq.is_some_and(|seq| t.last_state_seq == seq) {
                        return Ok(t);
                    }
                }
                None => {
                    if let (Some(rt), Some(_)) = (&mut self.rt, expect_seq) {
                        rt.stats.late_frames += 1;
                    }
                    return self
                        .latest
                        .ok_or_else(|| "no telemetry from the board yet".to_string());
                }
            }
        }
    }
}

impl ControlSource for BoardInTheLoop {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, String> {
        if let Some(rt) = &mut self.rt {
            rt.pace(k);
        }
        let frame = StateFrame {
            t_ticks: k,
            eta: *eta,
            nu: *nu,
        };
        let (expect_seq, last_sent) = self.send_period(k, frame)?;
        let t = match self.pacing {
            Pacing::Lockstep => self.lockstep_reply(expect_seq)?,
            Pacing::Realtime => self.realtime_reply(k, expect_seq, last_sent)?,
        };
        self.note_status(&t, k);
        self.check_unit(&t)?;
        Ok(ControlOut {
            status: ControlStatus::Board(t.status),
            tau: t.tau,
            voltage: t.voltages,
            saturated: t.saturated,
            delta: t.delta,
            delta_clamped: t.delta_clamped,
            w_norm: t.w_norm,
        })
    }
}
