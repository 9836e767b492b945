//! The accuracy each math backend actually gives, against std's f64 functions. Run with and
//! without `--features micromath`; the asserted bounds are the measured ones, rounded up.

use controller_core::math;

fn grid(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| lo + (hi - lo) * i as f64 / n as f64)
}

#[test]
fn sin_cos_accuracy_over_the_wrapped_range() {
    let mut worst = 0.0f64;
    for x in grid(-std::f64::consts::PI, std::f64::consts::PI, 100_000) {
        let xf = x as f32;
        let (s, c) = math::sin_cos(xf);
        worst = worst
            .max((s as f64 - (xf as f64).sin()).abs())
            .max((c as f64 - (xf as f64).cos()).abs());
    }
    println!(
        "{}: worst |sin/cos error| on [−π, π] = {worst:.3e}",
        math::BACKEND
    );
    let bound = if cfg!(feature = "micromath") {
        2e-3
    } else {
        2e-7
    };
    assert!(worst < bound, "{worst}");
}

#[test]
fn sqrt_accuracy() {
    let mut worst = 0.0f64;
    for x in grid(1e-3, 1e4, 200_000) {
        let xf = x as f32;
        let rel = (math::sqrt(xf) as f64 - (xf as f64).sqrt()).abs() / (xf as f64).sqrt();
        worst = worst.max(rel);
    }
    println!("{}: worst relative sqrt error = {worst:.3e}", math::BACKEND);
    if cfg!(feature = "micromath") {
        // micromath's bit-trick sqrt: √2 → 1.5 (6 %).
        assert!(worst < 0.07, "{worst}");
        assert!(
            worst > 0.01,
            "micromath's sqrt is expected to be coarse: {worst}"
        );
    } else {
        assert!(worst < 1e-7, "{worst}");
    }
}

#[test]
fn wrap_pi_lands_in_the_half_open_interval_and_preserves_the_angle() {
    for x in grid(-1000.0, 1000.0, 100_001) {
        let xf = x as f32;
        let w = math::wrap_pi(xf);
        assert!(
            w > -std::f32::consts::PI && w <= std::f32::consts::PI,
            "{xf} → {w}"
        );
        // Same angle: the difference is a multiple of 2π (to f32 rounding of |x|).
        let k = ((xf as f64 - w as f64) / std::f64::consts::TAU).round();
        let residual = xf as f64 - w as f64 - k * std::f64::consts::TAU;
        assert!(
            residual.abs() < 1e-4 * (1.0 + xf.abs() as f64 / 100.0),
            "{xf} → {w}"
        );
    }
    assert_eq!(math::wrap_pi(std::f32::consts::PI), std::f32::consts::PI);
    assert!(math::wrap_pi(f32::NAN).is_nan());
}
