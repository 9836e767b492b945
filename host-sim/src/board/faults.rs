//! The scenario's link faults as the runner injects them ([`Faults`]): per control period,
//! whether its state frame is dropped, corrupted, delayed (an older state sent instead) or the
//! link silent, from [`LinkFaults`]' tick ranges, and the recent states a delay sends.

use std::collections::VecDeque;

use auv_link::StateFrame;

use crate::scenario::LinkFaults;

/// The byte pattern a corrupted frame has one byte flipped with.
const CORRUPTION: u8 = 0x5A;

/// The link faults of one run, and the state frames a delay draws on.
pub(super) struct Faults {
    faults: LinkFaults,
    /// The last `delay_ticks + 1` state frames (what a delayed frame is taken from).
    history: VecDeque<StateFrame>,
}

/// What the link faults do to one period's frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PeriodFaults {
    /// Nothing is sent this period.
    pub(super) silent: bool,
    /// The state frame is not sent.
    pub(super) dropped: bool,
    /// The state frame has a byte flipped: the board refuses it.
    pub(super) corrupt: bool,
    /// The state frame holds the state of `delay_ticks` earlier: the board drops it as old.
    pub(super) delayed: bool,
    /// The state the period's frame carries (this period's, or the delayed one).
    pub(super) state: StateFrame,
}

impl PeriodFaults {
    /// No fault this period: a re-arm may go out.
    pub(super) fn healthy(&self) -> bool {
        !(self.silent || self.dropped || self.corrupt || self.delayed)
    }

    /// The board will answer the state frame (it is neither refused nor dropped as old).
    pub(super) fn answered(&self) -> bool {
        !(self.corrupt || self.delayed)
    }

    /// Damages the encoded state `frame` if this period corrupts it.
    pub(super) fn damage(&self, frame: &mut [u8]) {
        if self.corrupt && !frame.is_empty() {
            frame[frame.len() / 2] ^= CORRUPTION;
        }
    }
}

impl Faults {
    pub(super) fn new(faults: LinkFaults) -> Self {
        Faults {
            faults,
            history: VecDeque::new(),
        }
    }

    /// The chunks of a mission upload whose first sending is lost on purpose.
    pub(super) fn lost_upload_chunks(&self) -> &[u8] {
        &self.faults.lose_upload_chunks
    }

    /// Period `k`, whose state is `frame`: what its faults do.
    pub(super) fn period(&mut self, k: u64, frame: StateFrame) -> PeriodFaults {
        let keep = (self.faults.delay_ticks as usize).saturating_add(1);
        self.history.push_back(frame);
        if self.history.len() > keep {
            self.history.pop_front();
        }
        let delayed = LinkFaults::any(&self.faults.delay, k);
        let state = match self.history.front() {
            // The oldest kept: `delay_ticks` periods old once that many have passed.
            Some(&old) if delayed => old,
            _ => frame,
        };
        PeriodFaults {
            silent: LinkFaults::any(&self.faults.silent, k),
            dropped: LinkFaults::any(&self.faults.drop, k),
            corrupt: LinkFaults::any(&self.faults.corrupt, k),
            delayed,
            state,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::TickRange;

    fn frame(t: u64) -> StateFrame {
        StateFrame {
            t_ticks: t,
            eta: [0.0; 6],
            nu: [0.0; 6],
        }
    }

    fn range(from: u64, to: u64) -> TickRange {
        TickRange { from, to }
    }

    /// A delay of 3 ticks over ticks 5..7 sends the states of ticks 2 and 3; before 3 periods
    /// have passed it sends the oldest it has. Each fault acts on its own ticks only.
    #[test]
    fn each_fault_acts_on_its_ticks_and_a_delay_sends_the_state_from_delay_ticks_before() {
        let mut f = Faults::new(LinkFaults {
            drop: vec![range(1, 2)],
            corrupt: vec![range(2, 3)],
            delay: vec![range(0, 1), range(5, 7)],
            silent: vec![range(8, 9)],
            delay_ticks: 3,
            ..LinkFaults::default()
        });
        let periods: Vec<PeriodFaults> = (0..10).map(|k| f.period(k, frame(k))).collect();
        let sent: Vec<u64> = periods.iter().map(|p| p.state.t_ticks).collect();
        assert_eq!(sent, [0, 1, 2, 3, 4, 2, 3, 7, 8, 9]);
        let healthy: Vec<u64> = (0..10).filter(|&k| periods[k as usize].healthy()).collect();
        assert_eq!(healthy, [3, 4, 7, 9]);
        assert!(periods[1].dropped && periods[1].answered());
        assert!(periods[2].corrupt && !periods[2].answered());
        assert!(periods[6].delayed && !periods[6].answered());
        assert!(periods[8].silent && !periods[8].dropped);
    }

    /// A corrupted frame differs from the original in exactly one byte; others are untouched.
    #[test]
    fn corruption_flips_one_byte() {
        let mut f = Faults::new(LinkFaults {
            corrupt: vec![range(0, 1)],
            ..LinkFaults::default()
        });
        let bytes = [1u8, 2, 3, 4, 5, 6];
        for (k, flipped) in [(0, 1), (1, 0)] {
            let p = f.period(k, frame(k));
            let mut b = bytes;
            p.damage(&mut b);
            let differ = b.iter().zip(&bytes).filter(|(x, y)| x != y).count();
            assert_eq!(differ, flipped, "period {k}");
        }
    }
}
