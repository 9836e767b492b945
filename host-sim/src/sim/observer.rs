//! What sees every sample of a run as it is made: the streaming CSV
//! ([`crate::output::csv::CsvStream`]), the flight log ([`crate::output::log::McapLog`]), the progress counter ([`super::progress`]). `()` sees
//! nothing; a pair shows each sample to both.

use super::record::Sample;

/// Sees every sample of a run as it is made.
pub trait Observer {
    fn sample(&mut self, sample: &Sample);

    /// Whether this observer looks at the samples at all (`()` and an absent one do not): a
    /// run nobody watches and that keeps only its metrics may leave out of each sample what
    /// the metrics do not read ([`super::fly`], Choice 569).
    fn watches(&self) -> bool {
        true
    }
}

impl Observer for () {
    fn sample(&mut self, _: &Sample) {}

    fn watches(&self) -> bool {
        false
    }
}

impl<T: Observer + ?Sized> Observer for &mut T {
    fn sample(&mut self, s: &Sample) {
        (**self).sample(s);
    }

    fn watches(&self) -> bool {
        (**self).watches()
    }
}

/// An observer that may be absent (an output that could not be started).
impl<T: Observer> Observer for Option<T> {
    fn sample(&mut self, s: &Sample) {
        if let Some(o) = self {
            o.sample(s);
        }
    }

    fn watches(&self) -> bool {
        self.as_ref().is_some_and(Observer::watches)
    }
}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn sample(&mut self, s: &Sample) {
        self.0.sample(s);
        self.1.sample(s);
    }

    fn watches(&self) -> bool {
        self.0.watches() || self.1.watches()
    }
}
