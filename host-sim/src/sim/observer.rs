//! What sees every sample of a run as it is made: the streaming CSV
//! ([`crate::output::csv::CsvStream`]), the flight log ([`crate::output::log::McapLog`]), the progress counter ([`super::progress`]). `()` sees
//! nothing; a pair shows each sample to both.

use super::record::Sample;

/// Sees every sample of a run as it is made.
pub trait Observer {
    fn sample(&mut self, sample: &Sample);
}

impl Observer for () {
    fn sample(&mut self, _: &Sample) {}
}

impl<T: Observer + ?Sized> Observer for &mut T {
    fn sample(&mut self, s: &Sample) {
        (**self).sample(s);
    }
}

/// An observer that may be absent (an output that could not be started).
impl<T: Observer> Observer for Option<T> {
    fn sample(&mut self, s: &Sample) {
        if let Some(o) = self {
            o.sample(s);
        }
    }
}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn sample(&mut self, s: &Sample) {
        self.0.sample(s);
        self.1.sample(s);
    }
}
