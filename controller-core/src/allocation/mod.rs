//! Control allocation: which thrusts T give the body wrench τ the law asks for
//! (docs/thrusters.md#allocation, docs/thrusters.md#allocation-blocks-and-the-axis-priority, docs/thrusters.md#the-chain-end-to-end). Two parts, in the manner of PX4's `ControlAllocation` (whose methods are
//! `ControlAllocationPseudoInverse` and `ControlAllocationSequentialDesaturation`):
//!
//! - the **geometric allocation** [`PseudoInverse`] (`pseudo_inverse.rs`): B from the thruster
//!   geometry, B₅⁻¹ over the actuated rows and its condition check, built once; exact and
//!   unconstrained, T = B₅⁻¹·[X Y Z M N]ᵀ. The simulator's ideal actuators deliver these
//!   thrusts (the paper's experiment).
//! - the **prioritised, saturation-aware allocator** [`Allocator`] (`prioritised.rs`), which the
//!   board flies: it starts from B₅⁻¹τ, keeps each block of B₅ (`blocks.rs`) inside the
//!   thrusters' [envelopes](crate::thruster::ThrustEnvelope) and, where a block cannot meet its
//!   demand, gives up the least important force first by the [`AxisPriority`]
//!   (`priority.rs`), solving the block within its box in closed form (`box_solution.rs`).
//!
//! Every refusal at configuration time is an [`AllocationError`] (`error.rs`).

mod blocks;
mod box_solution;
mod error;
mod prioritised;
mod priority;
mod pseudo_inverse;

pub use error::AllocationError;
pub use prioritised::{Allocated, Allocator};
pub use priority::AxisPriority;
pub use pseudo_inverse::{PseudoInverse, MAX_CONDITION};
