//! Why an allocation is refused at configuration time: one variant per check, with its
//! numbers (docs/thrusters.md#allocation, docs/thrusters.md#allocation-blocks-and-the-axis-priority, docs/law.md#configuration-checks).

use core::fmt;

use crate::axes;
use crate::effectiveness::GeometryError;

/// Why a thruster geometry, envelope or priority was rejected by
/// [`PseudoInverse::new`](super::PseudoInverse::new) or [`Allocator::new`](super::Allocator::new).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AllocationError {
    /// The geometry itself failed its checks (non-finite, or a direction that is not a unit
    /// vector).
    Geometry(GeometryError),
    /// The 5×5 matrix over (X, Y, Z, M, N) has no inverse (`try_inverse` failed or gave a
    /// non-finite matrix).
    Singular,
    /// κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ exceeds the limit.
    IllConditioned {
        /// κ∞(B₅).
        condition: f32,
        /// The limit, [`MAX_CONDITION`](super::MAX_CONDITION).
        limit: f32,
    },
    /// The saturation-aware allocator ([`Allocator`](super::Allocator)) solves blocks of one or two
    /// thrusters: this geometry couples `thrusters` thrusters through `axes` actuated axes
    /// (docs/thrusters.md#allocation-blocks-and-the-axis-priority **Choice**: non-block geometries are refused, no fallback).
    NotBlockDiagonal {
        /// Thrusters in the offending block.
        thrusters: usize,
        /// Actuated axes they touch.
        axes: usize,
    },
    /// A thruster's thrust envelope is not finite with T_min < T_max (e.g. a supply limit so low
    /// that no thrust range is left).
    ThrustEnvelope {
        /// Thruster index.
        thruster: usize,
        /// T_min (N).
        min: f32,
        /// T_max (N).
        max: f32,
    },
    /// An axis priority weight of an actuated axis is not finite and > 0.
    Weight {
        /// Row of τ = [X Y Z K M N].
        axis: usize,
        /// The weight.
        weight: f32,
    },
}

impl From<GeometryError> for AllocationError {
    fn from(e: GeometryError) -> Self {
        AllocationError::Geometry(e)
    }
}

impl fmt::Display for AllocationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            AllocationError::Geometry(e) => e.fmt(f),
            AllocationError::Singular => write!(
                f,
                "allocation check failed: the 5x5 matrix over (X, Y, Z, M, N) is singular"
            ),
            AllocationError::IllConditioned { condition, limit } => write!(
                f,
                "allocation check failed: condition number (inf-norm) of the 5x5 matrix over (X, Y, Z, M, N) is {condition}, limit {limit}"
            ),
            AllocationError::NotBlockDiagonal { thrusters, axes } => write!(
                f,
                "allocation check failed: {thrusters} thrusters share {axes} actuated axes; the saturation-aware allocator needs a block-diagonal allocation with blocks of one or two thrusters (docs/thrusters.md#allocation-blocks-and-the-axis-priority)"
            ),
            AllocationError::ThrustEnvelope { thruster, min, max } => write!(
                f,
                "allocation check failed: thruster {thruster} has the envelope [{min}, {max}] N at the supply limit; it needs finite bounds with min < max"
            ),
            AllocationError::Weight { axis, weight } => write!(
                f,
                "allocation check failed: the priority weight of axis {} ({axis}) must be a finite number > 0, got {weight}",
                axes::NAMES.get(axis).unwrap_or(&"?")
            ),
        }
    }
}

impl core::error::Error for AllocationError {}
