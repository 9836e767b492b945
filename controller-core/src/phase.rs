//! Mission time to phase in integer arithmetic (docs/numerics.md#time-as-an-integer-tick-count).
//!
//! Mission time is the integer tick count k at the loop rate f_s, t = k / f_s. A path of
//! frequency ω needs the phase θ = ω t modulo 2π and, for the lawn-mower and the helix, a term
//! linear in t. Neither may be formed from an f32 t (a millisecond a tick is lost after a few
//! hours) nor in f64 (every f64 operation is a soft-float call on the Cortex-M4F, and no f64
//! routine may be reachable from `update`, docs/numerics.md#no-f64-on-the-control-step-from-the-elf).
//!
//! So the tick count is split once per step into whole seconds and a fraction of a second,
//! [`MissionTime`]: q = ⌊k / f_s⌋ and the fraction (k mod f_s)/f_s in 2⁻³² units, one 64-bit
//! integer division each. A frequency is stored as ν = ω/2π turns per second in fixed point,
//! [`Frequency`], computed once at configuration (in f64 there; it is not on the per-tick path):
//! the fractional part of ν in 2⁻⁶⁴ turns and ν in 2⁻³² turns. Then
//!
//! θ/2π ≡ q·frac(ν) + fraction·ν  (mod 1),
//!
//! the first product exact modulo 2⁶⁴ (q·⌊ν⌋ is a whole number of turns), the second in 32-bit
//! fixed point. The result is a phase in 2⁻³² turns, which `math::sin_cos_turns` takes without
//! any floating-point reduction, and harmonics are exact: n·θ is `phase.wrapping_mul(n)`.
//!
//! **Accuracy** (tests/phase.rs checks it against an exact rational reference): ν rounds to
//! 2⁻⁶⁴ turns/s, so after q seconds the phase is off by at most q·2⁻⁶⁵ turns (2·10⁻¹⁵ turns after
//! 24 h, 2⁻³³ turns after 136 years); the fraction of a second (2⁻³² s), the fixed-point
//! products and the final truncation to 2⁻³² turns add less than 5·2⁻³² turns (7·10⁻⁹ rad) at
//! any time. So the phase does not degrade with mission time within any mission's length:
//! today's f64 reduction, rounded to f32 in [0, 2π), was good to 2.4·10⁻⁷ rad.

/// A frequency for [`Frequency::phase`]: ν = ω/2π turns per second in fixed point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Frequency {
    /// frac(ν) in 2⁻⁶⁴ turns per second (the whole turns of q·ν drop out modulo 1).
    frac_q64: u64,
    /// ⌊ν⌋, whole turns per second.
    whole: u32,
}

impl Frequency {
    /// The zero frequency (no phase advance): [`Frequency::default`] as a constant.
    pub const ZERO: Frequency = Frequency {
        frac_q64: 0,
        whole: 0,
    };

    /// ω (rad/s, finite and ≥ 0; negative or non-finite values give the zero frequency) as a
    /// fixed-point turn rate. Configuration time only: this is f64 arithmetic.
    pub fn from_rad_per_s(omega: f64) -> Frequency {
        if !(omega.is_finite() && omega > 0.0) {
            return Frequency::default();
        }
        let nu = omega / core::f64::consts::TAU;
        let whole = libm::floor(nu);
        let frac = nu - whole;
        // frac·2⁶⁴ in two exact steps (frac < 1 has 53 significant bits): the high and low
        // 32-bit halves.
        let hi = libm::floor(frac * 4_294_967_296.0);
        let lo = libm::round((frac * 4_294_967_296.0 - hi) * 4_294_967_296.0);
        let frac_q64 = ((hi as u64) << 32).wrapping_add(lo as u64);
        Frequency {
            frac_q64,
            whole: if whole >= u32::MAX as f64 {
                u32::MAX
            } else {
                whole as u32
            },
        }
    }

    /// θ = ω t modulo 2π as a phase in 2⁻³² turns (fixed work: three integer multiplications).
    #[inline]
    pub fn phase(&self, t: &MissionTime) -> u32 {
        let seconds = (t.seconds.wrapping_mul(self.frac_q64) >> 32) as u32;
        // frac(ν) in 2⁻³² turns/s: the high half of frac_q64.
        let frac_q32 = self.frac_q64 >> 32;
        let fraction = t
            .fraction
            .wrapping_mul(self.whole)
            .wrapping_add(((t.fraction as u64 * frac_q32) >> 32) as u32);
        seconds.wrapping_add(fraction)
    }
}

/// Mission time t = k / f_s split into whole seconds and a fraction of a second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MissionTime {
    /// ⌊k / f_s⌋.
    pub seconds: u64,
    /// (k mod f_s) / f_s in 2⁻³² units (rounded down).
    pub fraction: u32,
    /// k mod f_s, ticks.
    pub sub_ticks: u32,
    /// f_s (Hz), ≥ 1.
    pub rate_hz: u32,
}

impl MissionTime {
    /// Tick `ticks` at `rate_hz` (0 is read as 1 Hz: the caller decides what rate 0 means).
    /// No floating point.
    ///
    /// Cost: for a tick count below 2³² and a rate below 2¹⁶ Hz (497 days at 100 Hz) three
    /// 32-bit hardware divisions; otherwise two 64-bit divisions in software (compiler-builtins'
    /// `__aeabi_uldivmod`, a few hundred instructions on the Cortex-M4F). Both paths give the
    /// same bits (tests/phase.rs).
    #[inline]
    pub fn new(ticks: u64, rate_hz: u32) -> MissionTime {
        let rate_hz = rate_hz.max(1);
        if ticks <= u32::MAX as u64 && rate_hz <= u16::MAX as u32 {
            Self::short(ticks as u32, rate_hz)
        } else {
            Self::long(ticks, rate_hz)
        }
    }

    /// [`new`](Self::new) for ticks < 2³², 1 ≤ rate < 2¹⁶: the fraction ⌊sub·2³²/rate⌋ in two
    /// 16-bit long-division steps, each numerator below rate·2¹⁶ ≤ 2³².
    #[inline]
    fn short(ticks: u32, rate_hz: u32) -> MissionTime {
        let seconds = ticks / rate_hz;
        let sub_ticks = ticks - seconds * rate_hz;
        let n1 = sub_ticks << 16;
        let q1 = n1 / rate_hz;
        let n2 = (n1 - q1 * rate_hz) << 16;
        let q2 = n2 / rate_hz;
        MissionTime {
            seconds: seconds as u64,
            fraction: (q1 << 16) | q2,
            sub_ticks,
            rate_hz,
        }
    }

    /// [`new`](Self::new) in 64-bit arithmetic, for every tick count and rate ≥ 1.
    #[doc(hidden)]
    #[inline(never)]
    pub fn long(ticks: u64, rate_hz: u32) -> MissionTime {
        let rate_hz = rate_hz.max(1);
        let rate = rate_hz as u64;
        let seconds = ticks / rate;
        let sub_ticks = (ticks - seconds * rate) as u32;
        // sub_ticks < rate ≤ 2³² − 1, so the shift cannot overflow and the quotient is < 2³².
        let fraction = (((sub_ticks as u64) << 32) / rate) as u32;
        MissionTime {
            seconds,
            fraction,
            sub_ticks,
            rate_hz,
        }
    }

    /// `offset` + rate·t, a term linear in time (the lawn-mower's advance plus its wave, the
    /// helix's depth), in f32 with one significant rounding: rate·q is formed exactly from
    /// 12-bit halves of q and of the rate ([`LinearRate`]), everything else is added to the
    /// small remainder first. Within 0.5 ulp (plus a few ulps of the remainder, 2⁻¹² smaller)
    /// of the exact value up to q = 2²⁴ s (194 days); beyond, q's halves are no longer exact and
    /// the result slowly coarsens but stays finite.
    #[inline]
    pub fn linear(&self, rate: &LinearRate, offset: f32) -> f32 {
        let q = self.seconds;
        let q_hi = (q & !0xfff) as f32;
        let q_lo = (q & 0xfff) as f32;
        let frac = self.sub_ticks as f32 / self.rate_hz as f32;
        let big = rate.hi * q_hi;
        let rest = rate.hi * q_lo
            + rate.mid * q_hi
            + (rate.mid * q_lo + rate.lo * (q_hi + q_lo))
            // hi + mid is the rate rounded to f32, exactly: enough for the fraction of a second.
            + ((rate.hi + rate.mid) * frac + offset);
        big + rest
    }
}

impl MissionTime {
    /// rate·t − `start` where the result is small beside rate·t (the waypoint path's parameter
    /// within its segment, docs/missions.md#lookup-and-the-local-parameter): the exact products rate·q of
    /// [`linear`](Self::linear) are summed with their rounding errors kept (Knuth's two-sum),
    /// `start` is subtracted from the rounded sum (exact by Sterbenz's lemma when the result is
    /// at most `start`), and the errors and the fraction of a second are added last. So the
    /// result is good to a few ulps of itself, not of rate·t: 1.5e-5 m on a 200 m leg at any
    /// distance along the path (σ itself as an f32 is good to 1.2e-4 m at 1.3 km).
    #[inline]
    pub fn linear_since(&self, rate: &LinearRate, start: f32) -> f32 {
        let q = self.seconds;
        let q_hi = (q & !0xfff) as f32;
        let q_lo = (q & 0xfff) as f32;
        let frac = self.sub_ticks as f32 / self.rate_hz as f32;
        let (s1, e1) = two_sum(rate.hi * q_hi, rate.hi * q_lo);
        let (s2, e2) = two_sum(s1, rate.mid * q_hi);
        let small = rate.mid * q_lo + rate.lo * (q_hi + q_lo) + (rate.hi + rate.mid) * frac;
        (s2 - start) + ((e1 + e2) + small)
    }
}

/// a + b = s + e exactly (Knuth's two-sum, six additions; no fused operations in Rust).
#[inline]
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// A rate (configuration time, f64) as three f32s hi + mid + lo for [`MissionTime::linear`]:
/// hi and mid the high and low 12 significant bits of the rate rounded to f32 (so hi·q and
/// mid·q are exact for 12-bit parts of q), lo the f32 of what the f32 rounding left.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct LinearRate {
    hi: f32,
    mid: f32,
    lo: f32,
}

impl LinearRate {
    /// The zero rate: [`LinearRate::default`] as a constant.
    pub const ZERO: LinearRate = LinearRate {
        hi: 0.0,
        mid: 0.0,
        lo: 0.0,
    };

    /// `rate` (m/s, finite).
    pub fn new(rate: f64) -> LinearRate {
        let sum = rate as f32;
        let hi = f32::from_bits(sum.to_bits() & !0xfff);
        LinearRate {
            hi,
            mid: sum - hi,
            lo: (rate - sum as f64) as f32,
        }
    }
}
