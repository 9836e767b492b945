//! Chatter: what a run's voltage commands do between the limits, per thruster, from the command
//! sequence at the control rate (docs/real-vehicle.md#chatter). The one definition of the
//! three figures every output reports and `[bound]` limits (**Choice 320**):
//!
//! - **sign reversals per second** through a dead band of ±[`DEAD_BAND`] V: a reversal counts
//!   when the command goes from above +0.5 V to below −0.5 V, or back, however many periods it
//!   spends inside the band on the way; a command dithering inside the band never reverses;
//! - **total variation per second** (V/s): Σ|V_k − V_{k−1}| over the run, divided by its span;
//! - **high-frequency share**: the fraction of the command's power (its mean square, the
//!   steady part included) above the corner f_c = 1/(2π T) of a thruster of time constant T
//!   (**Choice 321**: the scenario's `thruster_lag`, else [`NOMINAL_THRUSTER_LAG`]), measured
//!   through a 4th-order Butterworth high-pass at f_c (bilinear, pre-warped:
//!   |H(f)|² = 1 / (1 + (tan(π f_c/f_s) / tan(π f/f_s))⁸), ½ at f_c).
//!
//! Constant memory whatever the duration: a few numbers per thruster.

use std::f64::consts::PI;

use controller_core::effectiveness::{THRUSTERS, THRUSTER_NAMES};
use serde::{Deserialize, Serialize};

/// The dead band a sign reversal must cross (V), **Choice 320**: ±0.5 V is about 2 % of the
/// ±24 V supply and inside an ESC's own dead band around zero (the command at which a
/// propeller starts to turn); a command dithering inside it turns nothing.
pub const DEAD_BAND: f64 = 0.5;

/// The thruster time constant (s) the high-frequency share uses when the scenario sets no
/// `thruster_lag` (ideal response), **Choice 321**: a real thruster answers in about 0.1 s
/// (Choice 124), a corner of 1/(2π·0.1) ≈ 1.6 Hz.
pub const NOMINAL_THRUSTER_LAG: f64 = 0.1;

/// One thruster's chatter figures (NaN: none, a run that recorded no period).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThrusterChatter {
    /// Sign reversals through ±[`DEAD_BAND`] per second (1/s).
    #[serde(deserialize_with = "super::record::nan_if_null")]
    pub reversals_per_s: f64,
    /// Total variation of the command per second (V/s).
    #[serde(deserialize_with = "super::record::nan_if_null")]
    pub command_tv: f64,
    /// Share of the command's power above the thruster's corner frequency, in [0, 1].
    #[serde(deserialize_with = "super::record::nan_if_null")]
    pub hf_share: f64,
}

impl ThrusterChatter {
    /// No figures (NaN).
    pub const NONE: ThrusterChatter = ThrusterChatter {
        reversals_per_s: f64::NAN,
        command_tv: f64::NAN,
        hf_share: f64::NAN,
    };
}

impl Default for ThrusterChatter {
    fn default() -> Self {
        ThrusterChatter::NONE
    }
}

/// The chatter of every thruster, in [`THRUSTER_NAMES`] order; JSON writes it as an object
/// keyed by thruster name (`{"main": {…}, "vert fore": {…}, …}`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Chatter(pub [ThrusterChatter; THRUSTERS]);

impl Chatter {
    /// No figures for any thruster.
    pub const NONE: Chatter = Chatter([ThrusterChatter::NONE; THRUSTERS]);

    /// The largest value of `f` over the thrusters and the thruster's index (NaN if any is
    /// NaN: a figure missing is never the best case).
    pub fn worst(&self, f: fn(&ThrusterChatter) -> f64) -> (f64, Option<usize>) {
        let mut best = (f64::NEG_INFINITY, None);
        for (i, c) in self.0.iter().enumerate() {
            let x = f(c);
            if x.is_nan() {
                return (f64::NAN, None);
            }
            if x > best.0 {
                best = (x, Some(i));
            }
        }
        best
    }
}

impl Serialize for Chatter {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(THRUSTERS))?;
        for (name, c) in THRUSTER_NAMES.iter().zip(&self.0) {
            m.serialize_entry(name, c)?;
        }
        m.end()
    }
}

impl<'de> Deserialize<'de> for Chatter {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let map = std::collections::BTreeMap::<String, ThrusterChatter>::deserialize(d)?;
        let mut out = Chatter::NONE;
        for (name, c) in map {
            let i = THRUSTER_NAMES
                .iter()
                .position(|n| *n == name)
                .ok_or_else(|| serde::de::Error::unknown_variant(&name, &THRUSTER_NAMES))?;
            out.0[i] = c;
        }
        Ok(out)
    }
}

/// Where a reversal's command last was outside the dead band.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Side {
    #[default]
    Unknown,
    Above,
    Below,
}

/// One biquad section, direct form I.
#[derive(Clone, Copy, Debug, Default)]
struct Biquad {
    /// Feed-forward gain: y = g (x − 2x₁ + x₂) − a₁y₁ − a₂y₂ (a high-pass's zeros at z = 1,
    /// written so that a constant input gives exactly 0).
    g: f64,
    a1: f64,
    a2: f64,
    x1: f64,
    x2: f64,
    y1: f64,
    y2: f64,
}

impl Biquad {
    /// A 2nd-order Butterworth-family high-pass section of quality `q`, pre-warped
    /// k = tan(π f_c/f_s).
    fn high_pass(k: f64, q: f64) -> Self {
        let norm = 1.0 / (1.0 + k / q + k * k);
        Biquad {
            g: norm,
            a1: 2.0 * (k * k - 1.0) * norm,
            a2: (1.0 - k / q + k * k) * norm,
            ..Biquad::default()
        }
    }

    /// Starts at rest on the constant input `x` (the output of a high-pass is then 0).
    fn settle(&mut self, x: f64) {
        (self.x1, self.x2, self.y1, self.y2) = (x, x, 0.0, 0.0);
    }

    fn step(&mut self, x: f64) -> f64 {
        let y =
            self.g * ((x - self.x1) - (self.x1 - self.x2)) - self.a1 * self.y1 - self.a2 * self.y2;
        (self.x2, self.x1, self.y2, self.y1) = (self.x1, x, self.y1, y);
        y
    }
}

/// The 4th-order Butterworth high-pass: two sections of Q = 1/(2 cos(π/8)), 1/(2 cos(3π/8)).
#[derive(Clone, Copy, Debug)]
struct HighPass([Biquad; 2]);

impl HighPass {
    /// `None` when the corner is at or above the Nyquist frequency (nothing sampled lies above).
    fn new(corner_hz: f64, rate_hz: f64) -> Option<Self> {
        let w = PI * corner_hz / rate_hz;
        if !(w > 0.0 && w < PI / 2.0) {
            return None;
        }
        let k = w.tan();
        Some(HighPass([
            Biquad::high_pass(k, 1.0 / (2.0 * (PI / 8.0).cos())),
            Biquad::high_pass(k, 1.0 / (2.0 * (3.0 * PI / 8.0).cos())),
        ]))
    }

    fn settle(&mut self, x: f64) {
        self.0[0].settle(x);
        self.0[1].settle(0.0);
    }

    fn step(&mut self, x: f64) -> f64 {
        let y = self.0[0].step(x);
        self.0[1].step(y)
    }
}

/// One thruster's running figures.
#[derive(Clone, Copy, Debug)]
struct Track {
    side: Side,
    reversals: u64,
    last: Option<f64>,
    tv: f64,
    power: f64,
    hf_power: f64,
    high_pass: Option<HighPass>,
}

impl Track {
    fn push(&mut self, v: f64) {
        if v > DEAD_BAND {
            self.reversals += u64::from(self.side == Side::Below);
            self.side = Side::Above;
        } else if v < -DEAD_BAND {
            self.reversals += u64::from(self.side == Side::Above);
            self.side = Side::Below;
        }
        match self.last {
            Some(last) => self.tv += (v - last).abs(),
            None => {
                if let Some(h) = &mut self.high_pass {
                    h.settle(v);
                }
            }
        }
        self.last = Some(v);
        self.power += v * v;
        if let Some(h) = &mut self.high_pass {
            let y = h.step(v);
            self.hf_power += y * y;
        }
    }

    fn figures(&self, span: f64) -> ThrusterChatter {
        let per_s = |x: f64| if span > 0.0 { x / span } else { 0.0 };
        ThrusterChatter {
            reversals_per_s: per_s(self.reversals as f64),
            command_tv: per_s(self.tv),
            hf_share: if self.power > 0.0 {
                (self.hf_power / self.power).min(1.0)
            } else {
                0.0
            },
        }
    }
}

/// The chatter of a run's commands, pushed one control period at a time.
#[derive(Clone, Debug)]
pub struct ChatterAccumulator {
    tracks: [Track; THRUSTERS],
    first_t: Option<f64>,
    last_t: f64,
}

impl ChatterAccumulator {
    /// For commands at `rate_hz` to thrusters of time constant `lag` (s; `None`: ideal, the
    /// nominal [`NOMINAL_THRUSTER_LAG`]).
    pub fn new(rate_hz: f64, lag: Option<f64>) -> Self {
        let corner = corner_hz(lag);
        let track = Track {
            side: Side::Unknown,
            reversals: 0,
            last: None,
            tv: 0.0,
            power: 0.0,
            hf_power: 0.0,
            high_pass: HighPass::new(corner, rate_hz),
        };
        ChatterAccumulator {
            tracks: [track; THRUSTERS],
            first_t: None,
            last_t: 0.0,
        }
    }

    /// The commands of the period at time `t` (s).
    pub fn push(&mut self, t: f64, voltage: &[f64; THRUSTERS]) {
        self.first_t.get_or_insert(t);
        self.last_t = t;
        for (track, v) in self.tracks.iter_mut().zip(voltage) {
            track.push(*v);
        }
    }

    /// The figures so far, per second of the span from the first period to the last
    /// ([`Chatter::NONE`] before any period; 0 per second for a single period).
    pub fn chatter(&self) -> Chatter {
        let Some(first) = self.first_t else {
            return Chatter::NONE;
        };
        let span = self.last_t - first;
        Chatter(self.tracks.map(|t| t.figures(span)))
    }
}

/// The corner frequency (Hz) of a first-order thruster of time constant `lag` (s; `None`:
/// [`NOMINAL_THRUSTER_LAG`]): f_c = 1/(2π T).
pub fn corner_hz(lag: Option<f64>) -> f64 {
    1.0 / (2.0 * PI * lag.unwrap_or(NOMINAL_THRUSTER_LAG))
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: f64 = 100.0;

    /// The figures of thruster 0 for the command `v(t)` sampled at 100 Hz over [0, seconds].
    fn figures(seconds: f64, lag: Option<f64>, v: impl Fn(f64) -> f64) -> ThrusterChatter {
        let mut acc = ChatterAccumulator::new(RATE, lag);
        let n = (seconds * RATE).round() as u64;
        for k in 0..=n {
            let t = k as f64 / RATE;
            acc.push(t, &[v(t), 0.0, 0.0, 0.0, 0.0]);
        }
        acc.chatter().0[0]
    }

    fn close(got: f64, want: f64, tol: f64) {
        assert!((got - want).abs() <= tol, "got {got}, want {want} ± {tol}");
    }

    /// A square wave of amplitude A at f: 2f reversals a second, TV 4·A·f (each half period
    /// one jump of 2A).
    #[test]
    fn a_square_wave_reverses_twice_a_period_and_varies_by_four_amplitudes() {
        for (f, a) in [(1.0, 1.0), (2.5, 12.0), (5.0, 24.0)] {
            let square = |t: f64| if (t * f).fract() < 0.5 { a } else { -a };
            // Shift off the sample instants so that no edge is sampled at ±0 ambiguity.
            let c = figures(10.0, None, |t| square(t + 0.001));
            close(c.reversals_per_s, 2.0 * f, 1.0 / 10.0);
            close(c.command_tv, 4.0 * a * f, 2.0 * a / 10.0);
        }
    }

    /// A sinusoid A sin 2πft over D s (whole periods): TV = 4·A·f (the samples fall on its
    /// peaks at 100 Hz for these f); 2fD − 1 reversals (it starts at 0, so its first exit
    /// from the band is no reversal).
    #[test]
    fn a_sinusoid_varies_by_four_amplitudes_a_period() {
        let d = 20.0;
        for (f, a) in [(1.0, 3.0), (0.5, 20.0), (2.5, 1.0)] {
            let c = figures(d, None, |t| a * (2.0 * PI * f * t).sin());
            close(c.command_tv, 4.0 * a * f, 1e-9 * a);
            close(c.reversals_per_s, (2.0 * f * d - 1.0) / d, 1e-12);
        }
    }

    /// The design's response |H(f)|² = 1/(1 + (tan(πf_c/f_s)/tan(πf/f_s))⁸): a sine well
    /// above the corner is almost all high-frequency power, well below almost none, at the
    /// corner half; with a steady part C the share is |H|²·(A²/2)/(C² + A²/2).
    #[test]
    fn the_share_above_the_corner_follows_the_butterworth_response() {
        let lag = 0.1;
        let fc = corner_hz(Some(lag));
        let h2 = |f: f64| {
            let r = (PI * fc / RATE).tan() / (PI * f / RATE).tan();
            1.0 / (1.0 + r.powi(8))
        };
        for f in [fc / 4.0, fc / 2.0, fc, 2.0 * fc, 4.0 * fc, 10.0 * fc] {
            // 200 s: the start-up transient and the partial last period weigh < 0.5 %.
            let c = figures(200.0, Some(lag), |t| 5.0 * (2.0 * PI * f * t).sin());
            close(c.hf_share, h2(f), 5e-3);
        }
        close(h2(fc), 0.5, 1e-12);
        assert!(h2(4.0 * fc) > 0.999 && h2(fc / 4.0) < 2e-5);
        let (cst, a, f) = (3.0, 4.0, 4.0 * fc);
        let c = figures(200.0, Some(lag), |t| cst + a * (2.0 * PI * f * t).sin());
        let want = h2(f) * (a * a / 2.0) / (cst * cst + a * a / 2.0);
        close(c.hf_share, want, 5e-3);
        // The corner is the lag's: the same sine lies below a ten times faster thruster's.
        let fast = figures(200.0, Some(lag / 10.0), |t| (2.0 * PI * f * t).sin());
        assert!(fast.hf_share < 0.01, "{fast:?}");
        // Ideal actuators: the nominal thruster's corner.
        let ideal = figures(200.0, None, |t| {
            (2.0 * PI * 4.0 * corner_hz(None) * t).sin()
        });
        close(ideal.hf_share, 1.0, 5e-3);
    }

    /// A constant command: no reversal, no variation, no power above the corner.
    #[test]
    fn a_constant_command_has_no_chatter() {
        for v in [0.0, 7.5, -24.0] {
            let c = figures(30.0, Some(0.2), |_| v);
            assert_eq!(
                (c.reversals_per_s, c.command_tv, c.hf_share),
                (0.0, 0.0, 0.0)
            );
        }
    }

    /// A ±0.4 V dither flipping every period never leaves the ±0.5 V band: no reversal, though
    /// its TV is 0.8 V a period (80 V/s at 100 Hz); at ±0.6 V every flip is one.
    #[test]
    fn the_dead_band_suppresses_a_dither_inside_it() {
        let dither = |a: f64| {
            move |t: f64| {
                if ((t * RATE).round() as u64).is_multiple_of(2) {
                    a
                } else {
                    -a
                }
            }
        };
        let c = figures(10.0, None, dither(0.4));
        assert_eq!(c.reversals_per_s, 0.0);
        close(c.command_tv, 80.0, 1e-9);
        let c = figures(10.0, None, dither(0.6));
        close(c.reversals_per_s, RATE, 1e-9);
        // A command that crosses the band slowly (one reversal) counts once, however many
        // periods it spends inside the band.
        let c = figures(10.0, None, |t| 2.0 - 0.4 * t);
        close(c.reversals_per_s, 1.0 / 10.0, 1e-12);
    }

    /// No period: no figures (NaN); one period: nothing could change (0).
    #[test]
    fn no_period_has_no_figures_and_one_has_zero() {
        let acc = ChatterAccumulator::new(RATE, None);
        assert!(acc.chatter().0.iter().all(|c| c.reversals_per_s.is_nan()));
        let mut acc = ChatterAccumulator::new(RATE, None);
        acc.push(0.0, &[24.0, -24.0, 1.0, 0.0, 3.0]);
        assert!(acc
            .chatter()
            .0
            .iter()
            .all(|c| c.reversals_per_s == 0.0 && c.command_tv == 0.0 && c.hf_share == 0.0));
    }

    /// The worst thruster is named; a missing figure is never the best case; JSON is keyed by
    /// thruster name and reads back.
    #[test]
    fn the_worst_thruster_and_the_json_shape() {
        let mut c = Chatter(
            [ThrusterChatter {
                reversals_per_s: 1.0,
                command_tv: 2.0,
                hf_share: 0.1,
            }; THRUSTERS],
        );
        c.0[3].reversals_per_s = 40.0;
        assert_eq!(c.worst(|c| c.reversals_per_s), (40.0, Some(3)));
        let json = serde_json::to_value(c).expect("serialises");
        assert_eq!(json["horz fore"]["reversals_per_s"], 40.0);
        let back: Chatter = serde_json::from_value(json).expect("reads back");
        assert_eq!(back, c);
        assert!(Chatter::NONE.worst(|c| c.command_tv).0.is_nan());
    }
}
