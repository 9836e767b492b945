//! A number in a message, readable whatever its size (**Choice 127**, docs/simulator.md#hostile-conditions): as
//! Rust's shortest round-trip decimal (`0.1`, `-1`, `86400`) between 10⁻³ and 10⁶, and in the
//! same shortest digits with an exponent outside (`1e308`, `2.5e-7`, `-3e37`), never a
//! 309-digit integer or thirty zeros after the point. NaN and the infinities read `NaN`,
//! `inf`, `-inf`. The digits are the shortest that read back as the same value, so a number a
//! user wrote comes back as written. Every message that prints a user's number (here and in
//! `host-sim`) goes through [`Readable`].

use core::fmt;

/// `x` for a message: `format!("got {}", Readable(x))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Readable<T>(pub T);

macro_rules! readable {
    ($t:ty) => {
        impl fmt::Display for Readable<$t> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let x = self.0;
                let a = if x < 0.0 { -x } else { x };
                if !x.is_finite() || x == 0.0 || (1e-3..1e6).contains(&a) {
                    write!(f, "{x}")
                } else {
                    write!(f, "{x:e}")
                }
            }
        }
    };
}

readable!(f32);
readable!(f64);

#[cfg(test)]
mod tests {
    extern crate std;
    use super::Readable;
    use std::format;

    #[test]
    fn small_and_large_numbers_read_with_an_exponent_and_the_rest_as_written() {
        let show = |x: f64| format!("{}", Readable(x));
        assert_eq!(show(1e308), "1e308");
        assert_eq!(show(-3e37), "-3e37");
        assert_eq!(show(2.5e-7), "2.5e-7");
        assert_eq!(show(0.1), "0.1");
        assert_eq!(show(-1.0), "-1");
        assert_eq!(show(86_400.0), "86400");
        assert_eq!(show(0.0), "0");
        assert_eq!(show(f64::NAN), "NaN");
        assert_eq!(show(f64::NEG_INFINITY), "-inf");
        assert_eq!(format!("{}", Readable(1e30_f32)), "1e30");
        // The digits read back as the same value.
        for x in [1.234_567_890_123e300, 7.25e-12, 123_456.789] {
            assert_eq!(show(x).parse::<f64>().unwrap(), x);
        }
    }
}
