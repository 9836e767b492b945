//! Mission time → phase in integer arithmetic (`controller_core::phase`), checked against an
//! exact rational reference in u128 and against plain f64 evaluation of ω·t.

use controller_core::phase::{Frequency, LinearRate, MissionTime};
use proptest::prelude::*;

/// The exact phase of ν = `omega`/2π (the f64 value, an exact dyadic rational m·2^e) at
/// t = k/rate, in 2⁻³² turns rounded down: frac(k·m·2^e / rate), in u128 arithmetic.
fn exact_phase(omega: f64, ticks: u64, rate: u32) -> u32 {
    let nu = omega / std::f64::consts::TAU;
    let bits = nu.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let m = (bits & ((1 << 52) - 1)) | (1 << 52);
    // ν = m · 2^(exp − 1075); ν < 2 for the frequencies here, so the shift is ≥ 52.
    let shift = 1075 - exp;
    assert!((52..=90).contains(&shift), "ν = {nu}");
    let n = ticks as u128 * m as u128; // < 2¹¹⁷
    let d = (rate as u128) << shift; // ≤ 2¹²²
    let r = n % d;
    // r/d in 2⁻³² units by long division, one quotient bit at a time.
    let mut rem = r;
    let mut q: u32 = 0;
    for _ in 0..32 {
        rem <<= 1;
        q <<= 1;
        if rem >= d {
            rem -= d;
            q |= 1;
        }
    }
    q
}

fn circular_diff(a: u32, b: u32) -> u32 {
    let d = a.wrapping_sub(b);
    d.min(d.wrapping_neg())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]
    /// Within 5·2⁻³² turns of the exact phase for any tick count and any rate, plus the
    /// rounding of ν to 2⁻⁶⁴ turns/s accumulated over q seconds (q·2⁻⁶⁵ turns: nothing before
    /// 2³² s, 136 years).
    #[test]
    fn phase_is_exact_to_three_units_at_any_time(
        omega in 1e-6f64..10.0,
        ticks in any::<u64>(),
        rate in 1u32..=u32::MAX,
    ) {
        let f = Frequency::from_rad_per_s(omega);
        let t = MissionTime::new(ticks, rate);
        let got = f.phase(&t);
        let want = exact_phase(omega, ticks, rate);
        let drift = (t.seconds >> 32) as u32 + 1;
        prop_assert!(circular_diff(got, want) <= 5 + drift, "{got} vs {want}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20000))]
    /// The 32-bit path (ticks < 2³², rate < 2¹⁶) gives the 64-bit path's bits.
    #[test]
    fn both_division_paths_agree(ticks in any::<u32>(), rate in 0u32..=u16::MAX as u32) {
        prop_assert_eq!(MissionTime::new(ticks as u64, rate), MissionTime::long(ticks as u64, rate));
    }
}

#[test]
fn phase_matches_f64_over_a_day() {
    // A 24 h mission at 100 Hz: ω·t in f64 is exact to ≈ 2e-12 rad there.
    let omega = 0.1f32 as f64;
    let f = Frequency::from_rad_per_s(omega);
    let mut worst = 0.0f64;
    for k in (0..86_400 * 100u64).step_by(997) {
        let want = (omega * k as f64 / 100.0).rem_euclid(std::f64::consts::TAU);
        let got =
            f.phase(&MissionTime::new(k, 100)) as f64 / 4_294_967_296.0 * std::f64::consts::TAU;
        let mut e = (got - want).abs();
        e = e.min(std::f64::consts::TAU - e);
        worst = worst.max(e);
    }
    eprintln!("phase vs f64 over 24 h: worst {worst:.2e} rad");
    assert!(worst < 5.0 * std::f64::consts::TAU / 4_294_967_296.0 + 1e-11);
}

#[test]
fn mission_time_splits_ticks_exactly() {
    for (k, rate) in [
        (0u64, 1u32),
        (99, 100),
        (100, 100),
        (u64::MAX, 7),
        (123_456_789, 1000),
    ] {
        let t = MissionTime::new(k, rate);
        assert_eq!(t.seconds * rate as u64 + t.sub_ticks as u64, k);
        assert!(t.sub_ticks < rate);
        // fraction = ⌊sub·2³²/rate⌋.
        let want = ((t.sub_ticks as u128) << 32) / rate as u128;
        assert_eq!(t.fraction as u128, want);
    }
    // Rate 0 reads as 1 Hz.
    assert_eq!(MissionTime::new(5, 0), MissionTime::new(5, 1));
}

#[test]
fn harmonics_are_exact_multiples() {
    // n·θ as a wrapping product is the phase of n·ω (exactly, where ν and the time are exact).
    let f1 = Frequency::from_rad_per_s(std::f64::consts::TAU / 8.0); // 1/8 turn per second
    let f3 = Frequency::from_rad_per_s(3.0 * std::f64::consts::TAU / 8.0);
    // Whole seconds, where the 1/8-turn rate has no rounding at all.
    for seconds in [1u64, 7, 1000, 86_400, u64::MAX / 300] {
        let t = MissionTime::new(seconds * 100, 100);
        assert_eq!(
            f1.phase(&t).wrapping_mul(3),
            f3.phase(&t),
            "t = {seconds} s"
        );
    }
}

#[test]
fn degenerate_frequencies_give_phase_zero() {
    for omega in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let f = Frequency::from_rad_per_s(omega);
        assert_eq!(f.phase(&MissionTime::new(123_456, 100)), 0);
    }
}

#[test]
fn linear_term_is_rounded_once_over_194_days() {
    // The lawn-mower's advance at k = 1.38 (0.25/1.38 m/s, scale 20), a helix's −0.05 m/s, with
    // and without an offset (the lawn-mower's wave, the helix's start depth).
    for (rate, offset) in [
        (20.0 * 0.25 / 1.38f32 as f64, 2.5f32),
        (-0.05f32 as f64, 5.0),
    ] {
        let lr = LinearRate::new(rate);
        let mut worst_ulps = 0.0f64;
        let last = (1u64 << 24) * 100;
        for k in (0..last).step_by(1_000_003).chain([last - 1]) {
            let t = MissionTime::new(k, 100);
            let want = offset as f64 + rate * (k as f64 / 100.0);
            let got = t.linear(&lr, offset) as f64;
            let ulp = (want.abs() as f32).max(1.0) as f64 * f32::EPSILON as f64;
            worst_ulps = worst_ulps.max((got - want).abs() / ulp);
        }
        eprintln!("linear {rate}: worst {worst_ulps:.3} ulp over 194 days");
        assert!(worst_ulps <= 0.51, "{worst_ulps}");
    }
}
