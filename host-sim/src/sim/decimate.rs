//! What the plots keep of a long run, in bounded memory: the plot series of
//! [`RunResult::samples`](super::RunResult::samples).
//!
//! A run of at most [`PLOT_SAMPLES`] control periods keeps every sample (the paper's 70 s
//! missions at 100 Hz have 7 001). A longer one is cut into [`PLOT_BUCKETS`] buckets of equal
//! numbers of periods, and of each bucket it keeps, in time order, the first sample (and the
//! run's last) and, for
//! every signal the plots draw ([`PLOTTED`]), the sample where that signal is smallest and the
//! one where it is largest (min/max decimation), and the first sample with a non-finite plotted
//! value. Every signal's line through the kept samples therefore reaches each bucket's true
//! extremes: with about as many buckets as a panel has pixels across, the plot shows the same
//! envelope as the full series, and no peak, saturation or NaN is lost. At most
//! `2 + 2·PLOTTED.len()` samples a bucket are kept, so the memory is bounded whatever the
//! duration. Metrics and fault counts are computed from every sample, not from these.
//!
//! One limit: the heading plot unwraps ψ between consecutive kept samples, so where a bucket is
//! longer than a half-turn of heading the unwrapped curve may be off by whole turns.

use super::record::Sample;

/// Runs of at most this many control periods keep every sample for the plots.
pub const PLOT_SAMPLES: u64 = 20_000;
/// Buckets of a decimated run (about the pixel width of a plot panel).
pub const PLOT_BUCKETS: u64 = 1_500;

/// The signals the plots draw (`output::figures`): XY path and its reference, the six errors,
/// payload, heading and its reference, the five voltages, δ and the δ-clamp flag.
pub const PLOTTED: [fn(&Sample) -> f64; 20] = [
    |s| s.eta[0],
    |s| s.eta[1],
    |s| s.eta_d[0],
    |s| s.eta_d[1],
    |s| s.error[0],
    |s| s.error[1],
    |s| s.error[2],
    |s| s.error[3],
    |s| s.error[4],
    |s| s.error[5],
    |s| s.payload,
    |s| s.eta[5],
    |s| s.eta_d[5],
    |s| s.voltage[0],
    |s| s.voltage[1],
    |s| s.voltage[2],
    |s| s.voltage[3],
    |s| s.voltage[4],
    |s| s.delta,
    |s| f64::from(u8::from(s.delta_clamped)),
];

const SIGNALS: usize = PLOTTED.len();

/// Keeps the plot series of a run of `periods` control periods, pushed one sample at a time.
#[derive(Clone, Debug)]
pub struct Decimator {
    /// Periods per bucket (1: keep everything).
    bucket: u64,
    /// Periods pushed into the current bucket.
    filled: u64,
    first: Option<Sample>,
    last: Option<Sample>,
    non_finite: Option<Sample>,
    min: [Option<(f64, Sample)>; SIGNALS],
    max: [Option<(f64, Sample)>; SIGNALS],
    kept: Vec<Sample>,
}

impl Decimator {
    /// For a run of `periods` control periods (an estimate is fine: a longer run only gets
    /// more buckets).
    pub fn new(periods: u64) -> Self {
        let bucket = if periods <= PLOT_SAMPLES {
            1
        } else {
            periods.div_ceil(PLOT_BUCKETS)
        };
        Decimator {
            bucket,
            filled: 0,
            first: None,
            last: None,
            non_finite: None,
            min: [const { None }; SIGNALS],
            max: [const { None }; SIGNALS],
            kept: Vec::with_capacity(periods.min(PLOT_SAMPLES) as usize),
        }
    }

    pub fn push(&mut self, s: &Sample) {
        if self.bucket == 1 {
            self.kept.push(s.clone());
            return;
        }
        if self.first.is_none() {
            self.first = Some(s.clone());
        }
        for (i, signal) in PLOTTED.iter().enumerate() {
            let v = signal(s);
            if !v.is_finite() {
                if self.non_finite.is_none() {
                    self.non_finite = Some(s.clone());
                }
                continue;
            }
            if self.min[i].as_ref().is_none_or(|(m, _)| v < *m) {
                self.min[i] = Some((v, s.clone()));
            }
            if self.max[i].as_ref().is_none_or(|(m, _)| v > *m) {
                self.max[i] = Some((v, s.clone()));
            }
        }
        self.last = Some(s.clone());
        self.filled += 1;
        if self.filled == self.bucket {
            self.close_bucket();
        }
    }

    fn close_bucket(&mut self) {
        let mut bucket: Vec<Sample> = self
            .first
            .take()
            .into_iter()
            .chain(self.last.take())
            .chain(self.non_finite.take())
            .chain(self.min.iter_mut().filter_map(|m| m.take().map(|x| x.1)))
            .chain(self.max.iter_mut().filter_map(|m| m.take().map(|x| x.1)))
            .collect();
        bucket.sort_by(|a, b| a.t.total_cmp(&b.t));
        bucket.dedup_by(|a, b| a.t.to_bits() == b.t.to_bits());
        self.kept.extend(bucket);
        self.filled = 0;
    }

    /// The kept samples, in time order (the last, partly filled bucket included).
    pub fn finish(mut self) -> Vec<Sample> {
        if self.filled > 0 {
            self.close_bucket();
        }
        self.kept
    }
}
