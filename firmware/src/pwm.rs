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
