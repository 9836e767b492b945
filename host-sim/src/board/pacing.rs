//! How a board in the loop is paced ([`Pacing`]), and the timing figures of a real-time run
//! ([`RealTimeStats`]) with the pacer that takes them ([`RealTime`], used by
//! period.rs). docs/board.md#pacing.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// How the runner paces the board (docs/board.md#pacing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Pacing {
    /// The board runs one period per state frame, on the frame's tick (PIL's protocol): the
    /// result does not depend on either side's speed and equals SIL bit for bit.
    #[default]
    Lockstep,
    /// The board runs on its own timer (`SetConfig { lockstep: false }`); the host sends each
    /// state frame at its wall-clock period and applies the newest telemetry it has when the
    /// next period is due.
    Realtime,
}

impl Pacing {
    /// `"lockstep"` or `"realtime"` (the flag's and the JSON's value).
    pub fn as_str(self) -> &'static str {
        match self {
            Pacing::Lockstep => "lockstep",
            Pacing::Realtime => "realtime",
        }
    }
}

/// The timing of a real-time run ([`Pacing::Realtime`]): what the board's own clock and the
/// link did to the loop. Times in seconds of the host's monotonic clock.
///
/// **Choice 67** (docs/board.md#pacing): latency from a state frame sent to the first
/// telemetry naming it (a reply more than 16 frames late counts as none), p99 by nearest
/// rank; jitter as the RMS and the largest deviation of the telemetry interval from the
/// period; board missed = gaps in the telemetry's ticks; host missed = periods begun more
/// than a period late.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RealTimeStats {
    /// Control periods the host ran.
    pub periods: u64,
    /// State frames whose telemetry (the board's output computed from that frame,
    /// `last_state_seq`) had not arrived when the next period was due: the plant flew that
    /// period on an older state's output.
    pub late_frames: u64,
    /// Periods the host itself began more than a whole period late (it fell behind the wall
    /// clock: a loaded desktop).
    pub host_missed_periods: u64,
    /// Board periods without telemetry: gaps in the telemetry's tick numbers.
    pub board_missed_periods: u64,
    /// Reply latency, state frame sent → its telemetry received: mean, 99th percentile, max.
    pub latency_mean: f64,
    pub latency_p99: f64,
    pub latency_max: f64,
    /// Replies the latency is taken over.
    pub latency_samples: u64,
    /// Interval between consecutive telemetry frames: mean, and its jitter (RMS and largest
    /// deviation from the nominal period).
    pub reply_interval_mean: f64,
    pub reply_jitter_rms: f64,
    pub reply_jitter_max: f64,
}

impl std::fmt::Display for RealTimeStats {
    /// One line: the counts, then latency, interval and jitter in ms.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} periods, {} late frames, host missed {}, board missed {}; latency mean {:.2} / p99 {:.2} / max {:.2} ms over {} replies; reply interval {:.2} ms, jitter RMS {:.2} / max {:.2} ms",
            self.periods,
            self.late_frames,
            self.host_missed_periods,
            self.board_missed_periods,
            1e3 * self.latency_mean,
            1e3 * self.latency_p99,
            1e3 * self.latency_max,
            self.latency_samples,
            1e3 * self.reply_interval_mean,
            1e3 * self.reply_jitter_rms,
            1e3 * self.reply_jitter_max,
        )
    }
}

/// Telemetry frames the host listens to once the board is armed at the mission's rate, before
/// a real-time mission starts, to find the board's period phase ([`board_edge`]).
pub(super) const PHASE_FRAMES: usize = 8;

/// One of the board's period boundaries as the host sees it, from the arrival times of
/// telemetry the board sends once per period, just after each boundary. A frame is only ever
/// delayed (by the board's work, the link, a host that read it late), so the boundary is the
/// arrival after which the others come soonest: the one whose phase, modulo `period`, the
/// others follow by the least in total — robust to a few frames delayed by a large part of a
/// period, and to phases that straddle a boundary. (A frame delayed by nearly a whole period
/// reads as one that came just before its boundary; the set-up's frames, read as they come,
/// are not.) `None` without arrivals. **Choice 78**,
/// docs/board.md#where-the-hosts-periods-sit.
pub(super) fn board_edge(arrivals: &[Instant], period: Duration) -> Option<Instant> {
    let (&first, _) = arrivals.split_first()?;
    let p = period.as_nanos().max(1);
    let phases: Vec<u128> = arrivals.iter().map(|&a| phase(a, first, period)).collect();
    let lag = |c: u128| -> u128 { phases.iter().map(|&ph| (ph + p - c) % p).sum() };
    let best = phases.iter().copied().min_by_key(|&c| lag(c))?;
    Some(first + Duration::from_nanos(best as u64))
}

/// How far `at` is past the last boundary of a clock that has one at `from` and every
/// `period` after it (ns, in [0, period); 0 for an `at` before `from`).
fn phase(at: Instant, from: Instant, period: Duration) -> u128 {
    at.saturating_duration_since(from).as_nanos() % period.as_nanos().max(1)
}

/// The real-time pacer and its accumulators.
pub(super) struct RealTime {
    period: Duration,
    /// The wall-clock time of period 0 (set on the first period).
    origin: Option<Instant>,
    /// One of the board's period boundaries ([`board_edge`]), if the set-up found it.
    edge: Option<Instant>,
    /// The last state frames sent (sequence number, when), not yet answered.
    sent: std::collections::VecDeque<(u16, Instant)>,
    latencies: Vec<f64>,
    last_arrival: Option<Instant>,
    intervals: Vec<f64>,
    stats: RealTimeStats,
}

impl RealTime {
    pub(super) fn new(rate_hz: u32) -> Self {
        RealTime {
            period: Duration::from_secs_f64(1.0 / f64::from(rate_hz.max(1))),
            origin: None,
            edge: None,
            sent: std::collections::VecDeque::new(),
            latencies: Vec::new(),
            last_arrival: None,
            intervals: Vec::new(),
            stats: RealTimeStats::default(),
        }
    }

    /// The board's period boundary, from the `arrivals` of the frames it sent once armed
    /// ([`board_edge`]).
    pub(super) fn find_edge(&mut self, arrivals: &[Instant]) {
        self.edge = board_edge(arrivals, self.period);
    }

    /// Starts the run's clock from the board's answer to the first state frame at `answer`
    /// ([`RealTime::origin_after`]).
    pub(super) fn start_after(&mut self, answer: Instant) {
        self.origin = Some(self.origin_after(answer));
    }

    /// The run's clock, from the board's answer to the first state frame at `answer`: half a
    /// period after the board's boundary that answer followed, so that the host's periods fall
    /// between the board's (Choice 66). The boundary is the set-up's [`board_edge`] carried
    /// forward, or, without one, the answer itself (which is late by whatever delayed it).
    fn origin_after(&self, answer: Instant) -> Instant {
        let boundary = match self.edge {
            Some(edge) if answer >= edge => {
                answer - Duration::from_nanos(phase(answer, edge, self.period) as u64)
            }
            _ => answer,
        };
        boundary + self.period / 2
    }

    /// When period `k` is due.
    pub(super) fn due(&mut self, k: u64) -> Instant {
        let origin = *self.origin.get_or_insert_with(Instant::now);
        origin + self.period.mul_f64(k as f64)
    }

    /// Sleeps until period `k` is due; counts it missed if the host is a period late.
    pub(super) fn pace(&mut self, k: u64) {
        let due = self.due(k);
        let now = Instant::now();
        if now < due {
            std::thread::sleep(due - now);
        } else if now - due > self.period {
            self.stats.host_missed_periods += 1;
        }
        self.stats.periods += 1;
    }

    /// State frame `seq` was sent now.
    pub(super) fn sent(&mut self, seq: u16) {
        // A reply more than 16 periods late counts as none.
        if self.sent.len() == 16 {
            self.sent.pop_front();
        }
        self.sent.push_back((seq, Instant::now()));
    }

    /// Telemetry computed from state frame `seq` arrived at `at`: the first such reply gives
    /// that frame's latency (a late one too).
    pub(super) fn answered(&mut self, seq: u16, at: Instant) {
        if let Some(i) = self.sent.iter().position(|&(s, _)| s == seq) {
            let (_, sent) = self.sent[i];
            self.latencies.push((at - sent).as_secs_f64());
            // Older frames are answered by this one or never.
            self.sent.drain(..=i);
        }
    }

    /// A telemetry frame arrived at `at`. The intervals count from the first period on
    /// (the set-up's frames come at the board's default rate).
    pub(super) fn arrived(&mut self, at: Instant) {
        if self.origin.is_none() {
            return;
        }
        if let Some(last) = self.last_arrival.replace(at) {
            self.intervals.push((at - last).as_secs_f64());
        }
    }

    /// A state frame's answer had not come when the next period was due.
    pub(super) fn late_frame(&mut self) {
        self.stats.late_frames += 1;
    }

    /// `n` of the board's periods sent no telemetry.
    pub(super) fn board_missed(&mut self, n: u64) {
        self.stats.board_missed_periods += n;
    }

    /// The figures, from the samples.
    pub(super) fn finish(&mut self) -> RealTimeStats {
        let mut s = std::mem::take(&mut self.stats);
        let mut l = std::mem::take(&mut self.latencies);
        l.sort_by(f64::total_cmp);
        s.latency_samples = l.len() as u64;
        if !l.is_empty() {
            s.latency_mean = l.iter().sum::<f64>() / l.len() as f64;
            // Nearest rank.
            let rank = ((0.99 * l.len() as f64).ceil() as usize).clamp(1, l.len());
            s.latency_p99 = l[rank - 1];
            s.latency_max = l[l.len() - 1];
        }
        let iv = std::mem::take(&mut self.intervals);
        if !iv.is_empty() {
            let nominal = self.period.as_secs_f64();
            s.reply_interval_mean = iv.iter().sum::<f64>() / iv.len() as f64;
            s.reply_jitter_rms =
                (iv.iter().map(|d| (d - nominal).powi(2)).sum::<f64>() / iv.len() as f64).sqrt();
            s.reply_jitter_max = iv.iter().map(|d| (d - nominal).abs()).fold(0.0, f64::max);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boundaries every 10 ms from a known instant; frames delayed by 0.25 ms at best, some by
    /// several ms (one by more than half a period, one by more than a whole one), the first of
    /// them late; then a set whose phases straddle a boundary: the boundary found is the
    /// least-delayed arrival's, and the clock starts half a period after the boundary before
    /// a late answer.
    #[test]
    fn the_board_boundary_is_the_least_delayed_arrival() {
        let p = Duration::from_millis(10);
        let e0 = Instant::now();
        let ms = |x: f64| Duration::from_secs_f64(x * 1e-3);
        let arrivals_of = |delays: &[f64]| -> Vec<Instant> {
            delays
                .iter()
                .enumerate()
                .map(|(i, &d)| e0 + p * i as u32 + ms(d))
                .collect()
        };
        let phase_of = |edge: Instant| (edge - e0).as_nanos() % p.as_nanos();
        let arrivals = arrivals_of(&[4.6, 0.4, 0.25, 6.0, 0.3, 12.0, 0.5, 0.35]);
        let edge = board_edge(&arrivals, p).unwrap();
        assert_eq!(phase_of(edge), ms(0.25).as_nanos());
        // Relative to the first arrival (0.4 ms late) the best is 9.85 ms on: across the wrap.
        let straddling = arrivals_of(&[0.4, 0.25, 0.3, 3.0]);
        assert_eq!(
            phase_of(board_edge(&straddling, p).unwrap()),
            ms(0.25).as_nanos()
        );
        assert_eq!(board_edge(&[], p), None);
        // One arrival is its own boundary.
        assert_eq!(board_edge(&arrivals[1..2], p), Some(arrivals[1]));

        let mut rt = RealTime::new(100);
        // Without a boundary: half a period after the answer.
        let answer = e0 + p * 20 + ms(4.6);
        assert_eq!(rt.origin_after(answer), answer + ms(5.0));
        // With it: half a period after the boundary the answer followed (e0 + 200.25 ms).
        rt.edge = Some(edge);
        let origin = rt.origin_after(answer);
        let want = e0 + p * 20 + ms(0.25) + ms(5.0);
        assert!(
            origin.max(want) - origin.min(want) < Duration::from_nanos(2),
            "{:?}",
            origin.max(want) - origin.min(want)
        );
    }

    /// The figures from samples whose answers are worked by hand: intervals 10, 12, 8 ms
    /// against a 10 ms period deviate by 0, +2, −2 ms (RMS √(8/3) ms, largest 2 ms); latencies
    /// of 1 ..= 100 ms have mean 50.5 ms, nearest-rank p99 99 ms and max 100 ms.
    #[test]
    fn real_time_figures_from_known_samples() {
        let mut rt = RealTime::new(100);
        let t0 = Instant::now();
        // Before the run's clock starts (the set-up), arrivals do not count.
        rt.arrived(t0);
        rt.origin = Some(t0);
        for ms in [0u64, 10, 22, 30] {
            rt.arrived(t0 + Duration::from_millis(100 + ms));
        }
        rt.latencies = (1..=100).map(|ms| ms as f64 * 1e-3).rev().collect();
        let s = rt.finish();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        assert!(close(s.reply_interval_mean, 10e-3), "{s:?}");
        assert!(
            close(s.reply_jitter_rms, (8.0f64 / 3.0).sqrt() * 1e-3),
            "{s:?}"
        );
        assert!(close(s.reply_jitter_max, 2e-3), "{s:?}");
        assert_eq!(s.latency_samples, 100);
        assert!(close(s.latency_mean, 50.5e-3), "{s:?}");
        assert!(close(s.latency_p99, 99e-3), "{s:?}");
        assert!(close(s.latency_max, 100e-3), "{s:?}");
    }

    /// A reply names the frame it was computed from: the first reply to a frame gives its
    /// latency, and frames older than an answered one are never answered.
    #[test]
    fn a_reply_answers_its_frame_once_and_retires_older_ones() {
        let mut rt = RealTime::new(100);
        for seq in [7u16, 8, 9] {
            rt.sent(seq);
        }
        let later = Instant::now() + Duration::from_millis(5);
        rt.answered(8, later);
        rt.answered(8, later);
        rt.answered(7, later);
        assert_eq!(rt.latencies.len(), 1);
        assert!(rt.latencies[0] >= 5e-3);
        rt.answered(9, later);
        assert_eq!(rt.latencies.len(), 2);
        assert!(rt.sent.is_empty());
    }
}
