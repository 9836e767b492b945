//! Thruster voltage → H-bridge duty cycle.
//!
//! Each thruster is driven by an H-bridge from the board's supply V_s in locked anti-phase
//! PWM: duty d gives a mean motor voltage (2d − 1)·V_s. So
//!
//! d = (V + V_s) / (2 V_s),  V ∈ [−V_s, +V_s],
//!
//! and the **neutral / off duty is 50 %** (0 V mean). Voltages outside ±V_s are clamped (the
//! controller already clamps them to its `voltage_limit` ≤ V_s), and a non-finite voltage gives
//! neutral. The duty goes to an `embedded_hal::pwm::SetDutyCycle` channel as a fraction of its
//! maximum duty.

use embedded_hal::pwm::SetDutyCycle;

/// Duty fraction in [0, 1] for voltage `v` from supply `v_supply` (> 0).
pub fn duty_fraction(v: f32, v_supply: f32) -> f32 {
    if !(v.is_finite() && v_supply.is_finite() && v_supply > 0.0) {
        return 0.5;
    }
    let d = (v + v_supply) / (2.0 * v_supply);
    d.clamp(0.0, 1.0)
}

/// Duty in counts of `max_duty` for voltage `v`, rounded to the nearest count.
pub fn duty_counts(v: f32, v_supply: f32, max_duty: u16) -> u16 {
    let c = duty_fraction(v, v_supply) * max_duty as f32 + 0.5;
    // c ∈ [0.5, max_duty + 0.5]: the cast saturates and truncation rounds.
    (c as u32).min(max_duty as u32) as u16
}

/// Drives one channel with voltage `v`; errors of the channel are returned to the caller.
pub fn set_voltage<P: SetDutyCycle>(pwm: &mut P, v: f32, v_supply: f32) -> Result<(), P::Error> {
    let max = pwm.max_duty_cycle();
    pwm.set_duty_cycle(duty_counts(v, v_supply, max))
}

/// Drives one channel to neutral (0 V, 50 % duty).
pub fn set_neutral<P: SetDutyCycle>(pwm: &mut P) -> Result<(), P::Error> {
    pwm.set_duty_cycle_fraction(1, 2)
}

/// A PWM channel that keeps its duty in RAM: the thrusters of a board whose timers are not
/// there — QEMU's `mps2-an386` has no timer PWM, and QEMU's STM32F405 does not model TIM1 or
/// TIM8 (the `stm32f405` emulator build). It behaves as a timer channel does towards
/// `embedded_hal::pwm::SetDutyCycle`: a duty above the maximum is clamped to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemPwm {
    duty: u16,
    max: u16,
}

impl MemPwm {
    /// A channel of `max` counts of full duty, at neutral (half of `max`).
    pub const fn neutral(max: u16) -> Self {
        MemPwm { duty: max / 2, max }
    }

    /// The duty last set (counts of [`SetDutyCycle::max_duty_cycle`]).
    pub const fn duty(&self) -> u16 {
        self.duty
    }
}

impl embedded_hal::pwm::ErrorType for MemPwm {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for MemPwm {
    fn max_duty_cycle(&self) -> u16 {
        self.max
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.duty = duty.min(self.max);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ram_channel_maps_the_supply_range_onto_its_counts() {
        // d = (V + V_s) / (2 V_s): −V_s → 0, 0 → half, +V_s → full, beyond → clamped.
        let mut ch = MemPwm::neutral(8400);
        assert_eq!(ch.duty(), 4200);
        for (v, want) in [
            (-24.0, 0),
            (0.0, 4200),
            (12.0, 6300),
            (24.0, 8400),
            (99.0, 8400),
        ] {
            let Ok(()) = set_voltage(&mut ch, v, 24.0);
            assert_eq!(ch.duty(), want, "{v} V");
        }
        let Ok(()) = set_voltage(&mut ch, f32::NAN, 24.0);
        assert_eq!(ch.duty(), 4200, "a non-finite voltage gives neutral");
        let Ok(()) = ch.set_duty_cycle(u16::MAX);
        assert_eq!(
            ch.duty(),
            8400,
            "a duty above the maximum is clamped, as a timer's is"
        );
    }
}
