//! The six degrees of freedom by index: one order for every 6-vector of the crate,
//! η = [x y z φ θ ψ], ν = [u v w p q r], τ = [X Y Z K M N] (docs/model.md#frames-and-state).
//!
//! Roll is neither actuated nor controlled: no thruster gives a roll moment K
//! (docs/thrusters.md#geometry-and-the-effectiveness-matrix), so the law controls the other five axes (K₁₄ = K₂₄ = 0 in the paper: roll is left out
//! of ‖e‖, w and Δu) and the allocation inverts B over the same five rows (B₅).

/// Index of roll (φ, p, K).
pub const ROLL: usize = 3;

/// Index of yaw (ψ, r, N).
pub const YAW: usize = 5;

/// The actuated axes, which are the controlled ones: surge, sway, heave, pitch, yaw (every
/// axis but [`ROLL`]).
pub const ACTUATED: [usize; 5] = [0, 1, 2, 4, 5];

/// The axes by name, in index order: the scenario files' `axis_priority` and the messages.
pub const NAMES: [&str; 6] = ["surge", "sway", "depth", "roll", "pitch", "yaw"];

// ACTUATED is every index but ROLL, in order.
const _: () = {
    let mut k = 0;
    let mut axis = 0;
    while axis < 6 {
        if axis != ROLL {
            assert!(ACTUATED[k] == axis);
            k += 1;
        }
        axis += 1;
    }
    assert!(k == ACTUATED.len());
};
