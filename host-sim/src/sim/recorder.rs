//! What a run keeps of its samples as it goes: the metrics and fault counts from every sample,
//! the observer's view of every sample, and the plot series if asked for; bounded memory
//! whatever the duration.

use super::decimate::Decimator;
use super::metrics;
use super::observer::Observer;
use super::record::{FaultCounts, Metrics, Sample};

/// What a run keeps of its samples besides the metrics and the fault counts (which are
/// accumulated from every sample either way, as is what the observer sees).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recording {
    /// The plot series ([`super::decimate`]) in [`super::RunResult::samples`].
    Plot,
    /// No samples: [`super::RunResult::samples`] is empty. For runs nobody plots: **Choice 82**
    /// (docs/model.md#evaluating-the-plant-fast), Monte Carlo records this way. The [`super::RunResult::summary`] is
    /// the same as with [`Recording::Plot`].
    MetricsOnly,
}

/// The samples of one run, taken one period at a time.
pub struct Recorder<'o> {
    observer: &'o mut dyn Observer,
    plot: Option<Decimator>,
    metrics: metrics::Accumulator,
    faults: FaultCounts,
}

impl<'o> Recorder<'o> {
    /// A recorder for a run of `periods` control periods whose metrics `metrics` accumulates.
    pub fn new(
        observer: &'o mut dyn Observer,
        recording: Recording,
        periods: u64,
        metrics: metrics::Accumulator,
    ) -> Self {
        Recorder {
            observer,
            plot: (recording == Recording::Plot).then(|| Decimator::new(periods)),
            metrics,
            faults: FaultCounts::default(),
        }
    }

    pub fn record(&mut self, s: &Sample) {
        self.metrics.push(s);
        self.faults.record(s);
        self.observer.sample(s);
        if let Some(plot) = &mut self.plot {
            plot.push(s);
        }
    }

    /// The metrics, the fault counts and the plot series (empty unless [`Recording::Plot`]).
    pub fn finish(self) -> (Metrics, FaultCounts, Vec<Sample>) {
        let samples = self.plot.map_or_else(Vec::new, Decimator::finish);
        (self.metrics.metrics(), self.faults, samples)
    }
}
