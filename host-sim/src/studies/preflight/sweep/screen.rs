//! The box's thrust envelope per sample as a function of 1/k (docs/real-vehicle.md#how-the-check-is-made,
//! **Choices 530–531**): each sample the fast engine judges in full over the whole box leaves
//! the span of its 2⁹ corners' thrusts at that 1/k ([`Span`]); a later probe at another 1/k,
//! bracketed by three recorded ones, interpolates the span (quadratic in 1/k: η̇_d/k and
//! η̈_d/k² make Eq (1) a polynomial of degree two in 1/k at a fixed attitude) and skips the
//! sample when the interpolated span lies inside the margin envelope by [`BAND`] of its width
//! on each side. A sample the interpolation does not clear is judged as before.
//!
//! Not exact: the attitude the vehicle holds (the heel, the pitch offset), the quadratic
//! damping under a current and the switch of the extreme corner make the span only nearly
//! quadratic in 1/k. The band is many times the interpolation's largest error measured over
//! the benchmarks and the contract's missions (the docs give the figures); the engines'
//! equivalence tests (tests/preflight_engines.rs) hold the verdicts to the reference's.

use controller_core::effectiveness::THRUSTERS;
use controller_core::thruster::ThrustEnvelope;

/// The margin a skipped sample keeps on each side: this fraction of each thruster's margin
/// envelope width beyond its interpolated span.
pub const BAND: f64 = 0.05;

/// The smallest and the largest thrust (N) of each thruster over every case, current and
/// roll extreme of one sample at one 1/k: what the pseudo-inverse asks, which the margin
/// allocator keeps when it lies inside its envelope.
#[derive(Clone, Copy, Debug)]
pub(super) struct Span {
    lo: [f32; THRUSTERS],
    hi: [f32; THRUSTERS],
}

impl Span {
    pub(super) const EMPTY: Span = Span {
        lo: [f32::INFINITY; THRUSTERS],
        hi: [f32::NEG_INFINITY; THRUSTERS],
    };

    /// Widens the span to `thrusts`.
    pub(super) fn add(&mut self, thrusts: &[f32; THRUSTERS]) {
        for (i, &t) in thrusts.iter().enumerate() {
            self.lo[i] = self.lo[i].min(t);
            self.hi[i] = self.hi[i].max(t);
        }
    }
}

/// The spans recorded per sample (regular samples and the corners' extremes), each sorted by
/// 1/k.
pub(super) struct Screen {
    regular: Vec<Vec<(f64, Span)>>,
    peaks: Vec<Vec<(f64, Span)>>,
}

impl Screen {
    pub(super) fn new(regular: usize, peaks: usize) -> Self {
        Screen {
            regular: vec![Vec::new(); regular],
            peaks: vec![Vec::new(); peaks],
        }
    }

    fn at(&self, peak: bool, j: usize) -> &[(f64, Span)] {
        match peak {
            true => &self.peaks[j],
            false => &self.regular[j],
        }
    }

    /// The span of sample `j` judged in full at 1/k = `inv_k`.
    pub(super) fn record(&mut self, peak: bool, j: usize, inv_k: f64, span: Span) {
        let list = match peak {
            true => &mut self.peaks[j],
            false => &mut self.regular[j],
        };
        match list.binary_search_by(|r| r.0.total_cmp(&inv_k)) {
            Ok(_) => {}
            Err(i) => list.insert(i, (inv_k, span)),
        }
    }

    /// The span recorded for sample `j` at exactly `inv_k`, if any.
    pub(super) fn recorded(&self, peak: bool, j: usize, inv_k: f64) -> Option<Span> {
        let list = self.at(peak, j);
        list.binary_search_by(|r| r.0.total_cmp(&inv_k))
            .ok()
            .map(|i| list[i].1)
    }

    /// Whether sample `j` at 1/k = `inv_k` is cleared: its span, interpolated from three
    /// recorded ones that bracket `inv_k`, lies inside `envelope` by [`BAND`] of its width.
    pub(super) fn clears(
        &self,
        peak: bool,
        j: usize,
        inv_k: f64,
        envelope: &ThrustEnvelope,
    ) -> bool {
        let Some(span) = self.predict(peak, j, inv_k) else {
            return false;
        };
        (0..THRUSTERS).all(|i| {
            let (lo, hi) = (f64::from(envelope.min[i]), f64::from(envelope.max[i]));
            let band = BAND * (hi - lo);
            span.0[i] >= lo + band && span.1[i] <= hi - band
        })
    }

    /// The span at `inv_k` by quadratic interpolation through the nearest recorded 1/k below,
    /// the nearest above and the next nearest (`None`: not bracketed by three).
    #[allow(clippy::type_complexity)]
    fn predict(
        &self,
        peak: bool,
        j: usize,
        inv_k: f64,
    ) -> Option<([f64; THRUSTERS], [f64; THRUSTERS])> {
        let list = self.at(peak, j);
        let above = list.partition_point(|r| r.0 < inv_k);
        if above == 0 || above == list.len() {
            return None;
        }
        let (below, above) = (above - 1, above);
        let third = match (below.checked_sub(1), list.get(above + 1)) {
            (Some(b), Some(a)) if inv_k - list[b].0 <= a.0 - inv_k => b,
            (Some(b), None) => b,
            (_, Some(_)) => above + 1,
            (None, None) => return None,
        };
        let nodes = [list[below], list[above], list[third]];
        let x: [f64; 3] = nodes.map(|n| n.0);
        let w = lagrange(&x, inv_k);
        let at = |f: &dyn Fn(&Span) -> f32| -> f64 {
            (0..3).map(|n| w[n] * f64::from(f(&nodes[n].1))).sum()
        };
        let mut lo = [0.0; THRUSTERS];
        let mut hi = [0.0; THRUSTERS];
        for i in 0..THRUSTERS {
            lo[i] = at(&|s| s.lo[i]);
            hi[i] = at(&|s| s.hi[i]);
        }
        Some((lo, hi))
    }
}

/// The weights of the quadratic through nodes `x` at `u`.
fn lagrange(x: &[f64; 3], u: f64) -> [f64; 3] {
    let l =
        |a: usize, b: usize, c: usize| (u - x[b]) * (u - x[c]) / ((x[a] - x[b]) * (x[a] - x[c]));
    [l(0, 1, 2), l(1, 0, 2), l(2, 0, 1)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A span quadratic in 1/k is interpolated exactly (to rounding) from any three
    /// bracketing nodes; an unbracketed 1/k is not predicted.
    #[test]
    fn a_quadratic_span_is_interpolated_from_bracketing_nodes() {
        let f = |u: f64| [10.0 + 3.0 * u - 40.0 * u * u; THRUSTERS].map(|x| x as f32);
        let mut s = Screen::new(1, 0);
        for u in [0.0, 0.5, 0.8, 1.0] {
            let t = f(u);
            let mut span = Span::EMPTY;
            span.add(&t);
            s.record(false, 0, u, span);
        }
        for u in [0.1, 0.6, 0.9] {
            let (lo, hi) = s.predict(false, 0, u).unwrap();
            let want = 10.0 + 3.0 * u - 40.0 * u * u;
            assert!((lo[0] - want).abs() < 1e-4 && (hi[4] - want).abs() < 1e-4);
        }
        assert!(s.predict(false, 0, 1.2).is_none());
        assert!(s.predict(false, 0, -0.1).is_none());
    }
}
