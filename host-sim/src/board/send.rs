//! What the runner sends the board: commands and state frames, numbered, signed if the link
//! is, with the scenario's link faults injected; one control period's frames at a time.

use auv_link::{
    encode, encode_signed, Command as LinkCommand, Envelope, Msg, StateFrame, MAX_FRAME,
    PROTOCOL_VERSION,
};

use super::frames::mavlink_time;
use super::pacing::Pacing;
use super::runner::BoardInTheLoop;
use crate::scenario::LinkFaults;

impl BoardInTheLoop {
    pub(super) fn send(&mut self, msg: Msg) -> Result<(), String> {
        let mut buf = [0u8; MAX_FRAME];
        let n = self.encode(msg, &mut buf)?;
        self.write(&buf[..n])
    }

    pub(super) fn encode(&mut self, msg: Msg, buf: &mut [u8; MAX_FRAME]) -> Result<usize, String> {
        let env = Envelope {
            version: PROTOCOL_VERSION,
            seq: self.seq,
            msg,
        };
        self.seq = self.seq.wrapping_add(1);
        match &mut self.signer {
            None => encode(&env, buf),
            Some(signer) => {
                signer.advance_to(mavlink_time());
                encode_signed(&env, signer, buf)
            }
        }
        .map_err(|e| format!("encoding: {e}"))
    }

    pub(super) fn write(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.stream
            .write_frame(bytes)
            .map_err(|e| self.lost(&e, "write"))
    }

    /// Appends this period's state frame to `out` — `frame`, or with a delay fault the one
    /// from `delay_ticks` earlier, with a corruption fault a byte flipped — and returns the
    /// sequence number the board's answer will name (none for a frame the board will refuse
    /// or drop).
    fn encode_state(
        &mut self,
        frame: StateFrame,
        corrupt: bool,
        delayed: bool,
        out: &mut Vec<u8>,
    ) -> Result<Option<u16>, String> {
        let mut buf = [0u8; MAX_FRAME];
        let sent = if delayed {
            let i = self
                .history
                .len()
                .saturating_sub(1 + self.faults.delay_ticks as usize);
            self.history[i]
        } else {
            frame
        };
        // A corrupted frame is refused, and a delayed one holds an old state that the board
        // drops as off its mission clock: neither is answered.
        let expect = (!corrupt && !delayed).then_some(self.seq);
        let n = self.encode(Msg::State(sent), &mut buf)?;
        if corrupt {
            buf[n / 2] ^= 0x5A;
        }
        out.extend_from_slice(&buf[..n]);
        self.stats.state_frames_sent += 1;
        Ok(expect)
    }

    /// Sends period `k`'s frames: the state frame (unless the link faults drop, corrupt,
    /// delay or silence it), the mission's start with the first, and a re-arming once the link
    /// is healthy again after a fail-safe. Returns the sequence number the board's answer will
    /// name (none for a frame the board will refuse or drop) and the last frame sent.
    pub(super) fn send_period(
        &mut self,
        k: u64,
        frame: StateFrame,
    ) -> Result<(Option<u16>, Option<u16>), String> {
        self.history.push_back(frame);
        if self.history.len() > (self.faults.delay_ticks as usize).saturating_add(1) {
            self.history.pop_front();
        }
        let silent = LinkFaults::any(&self.faults.silent, k);
        let dropped = LinkFaults::any(&self.faults.drop, k);
        let corrupt = LinkFaults::any(&self.faults.corrupt, k);
        let delayed = LinkFaults::any(&self.faults.delay, k);
        let healthy = !(silent || dropped || corrupt || delayed);
        let mut expect_seq = None;
        let mut out = Vec::with_capacity(4 * MAX_FRAME);
        // Lock-step: commands, then the state frame (a mission's first state frame sets its
        // clock; an earlier one is not on it). Real time: the state first, so that a mission
        // (re)started in this period has a state when the board's next period comes
        // (Choice 68, docs/board.md#pacing).
        let state_first = self.pacing == Pacing::Realtime;
        if !silent {
            if state_first && !dropped {
                expect_seq = self.encode_state(frame, corrupt, delayed, &mut out)?;
            }
            self.encode_commands(healthy, &mut out)?;
            if !state_first && !dropped {
                expect_seq = self.encode_state(frame, corrupt, delayed, &mut out)?;
            }
        }
        // The last frame this period sent (real time's period 0 waits until the board took it).
        let last_sent = (!out.is_empty()).then(|| self.seq.wrapping_sub(1));
        if !out.is_empty() {
            self.write(&out)?;
        }
        if let (Some(rt), Some(seq)) = (&mut self.rt, expect_seq) {
            rt.sent(seq);
        }
        Ok((expect_seq, last_sent))
    }

    /// The period's commands: the mission's start with the first period; after a fail-safe,
    /// once the link is `healthy` again, the re-arming.
    fn encode_commands(&mut self, healthy: bool, out: &mut Vec<u8>) -> Result<(), String> {
        let mut buf = [0u8; MAX_FRAME];
        if self.needs_rearm && healthy {
            // Recovery: the link is good again; re-arm (the fail-safe latches until
            // then) and start the mission again, since disarming dropped it. Its first
            // state frame below sets the board's mission clock to this tick.
            for c in [
                LinkCommand::Disarm,
                LinkCommand::Arm,
                LinkCommand::StartMission(self.mission),
            ] {
                let n = self.encode(Msg::Command(c), &mut buf)?;
                out.extend_from_slice(&buf[..n]);
            }
            self.needs_rearm = false;
            self.stats.rearms += 1;
        }
        if !self.started {
            let n = self.encode(
                Msg::Command(LinkCommand::StartMission(self.mission)),
                &mut buf,
            )?;
            out.extend_from_slice(&buf[..n]);
            self.started = true;
        }
        Ok(())
    }
}
