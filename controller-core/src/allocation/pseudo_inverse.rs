//! The geometric allocation: the thrusts T that produce a body wrench τ, T = B₅⁻¹·[X Y Z M N]ᵀ
//! (docs/thrusters.md#allocation, docs/thrusters.md#the-chain-end-to-end).
//!
//! [`PseudoInverse`] is built once at configuration time from a [`ThrusterGeometry`]: it takes
//! the effectiveness matrix B of [`crate::effectiveness`], drops the roll row K (roll is not
//! actuated, so τ_K is ignored), inverts the remaining 5×5 matrix B₅ over (X, Y, Z, M, N) once,
//! and checks its condition number. Per tick it is one 5×5 matrix–vector product
//! ([`PseudoInverse::thrusts`]) and, for the report, one 6×5 product
//! ([`PseudoInverse::wrench`]). With five thrusters and five actuated axes B₅ is square, so its
//! pseudo-inverse is its inverse.
//!
//! This is the exact, unconstrained allocation. The board flies the saturation-aware
//! [`Allocator`](super::Allocator), which starts from these thrusts, keeps them where they fit
//! the thrusters' envelopes and solves each block of B₅ within its box where they do not
//! (docs/thrusters.md#allocation-blocks-and-the-axis-priority, docs/thrusters.md#the-chain-end-to-end). The simulator's ideal actuators deliver exactly these
//! unconstrained thrusts (the paper's experiment, docs/simulator.md#table-1).

use nalgebra::{Matrix5, Matrix6x5, Vector5, Vector6};

use crate::allocation::error::AllocationError;
use crate::axes::ACTUATED;
use crate::effectiveness::{ThrusterGeometry, THRUSTERS};

/// Largest accepted ∞-norm condition number κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ of the 5×5 allocation
/// matrix (f32 has ≈ 7 digits; κ = 10⁴ leaves ≈ 3). The AUV-150 default has κ∞ = 3.6.
pub const MAX_CONDITION: f32 = 1.0e4;

/// Thrust allocation τ ↔ T for a fixed thruster geometry, built once at configuration time.
///
/// Holds B (6×5, rows X Y Z K M N, [`ThrusterGeometry::effectiveness`]) and the inverse of its
/// 5×5 sub-matrix B₅ over the actuated rows (X, Y, Z, M, N).
///
/// For the default geometry (docs/thrusters.md#geometry-and-the-effectiveness-matrix **Choice**) this is the closed form, N:
///
/// ```text
/// T_main      = X
/// T_vert,fore = (Z − M/1.8)/2      T_vert,aft = (Z + M/1.8)/2
/// T_horz,fore = (Y + N/1.8)/2      T_horz,aft = (Y − N/1.8)/2
/// ```
///
/// with κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ = 3.6 · 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PseudoInverse {
    b: Matrix6x5<f32>,
    b5_inv: Matrix5<f32>,
    condition: f32,
}

impl PseudoInverse {
    /// Builds B and inverts B₅. Rejects (with the check and its numbers): a geometry that
    /// fails [`ThrusterGeometry::effectiveness`], a singular B₅, and κ∞(B₅) > [`MAX_CONDITION`].
    pub fn new(geometry: &ThrusterGeometry) -> Result<PseudoInverse, AllocationError> {
        let b = geometry.effectiveness()?;
        let b5 = Matrix5::<f32>::from_fn(|row, col| b[(ACTUATED[row], col)]);
        let b5_inv = b5.try_inverse().ok_or(AllocationError::Singular)?;
        if !b5_inv.iter().all(|x| x.is_finite()) {
            return Err(AllocationError::Singular);
        }
        let condition = inf_norm(&b5) * inf_norm(&b5_inv);
        if condition.is_nan() || condition > MAX_CONDITION {
            return Err(AllocationError::IllConditioned {
                condition,
                limit: MAX_CONDITION,
            });
        }
        Ok(PseudoInverse {
            b,
            b5_inv,
            condition,
        })
    }

    /// Thrusts T (N, thruster order) = B₅⁻¹·[X Y Z M N]ᵀ for the wrench `tau` = [X Y Z K M N]
    /// (N, N·m). τ_K is ignored (roll is not actuated). Exact and unconstrained (the
    /// saturation-aware allocation is [`Allocator`](super::Allocator)). Fixed work; a
    /// non-finite τ gives non-finite thrusts, which [`actuate`](crate::thruster::actuate) turns
    /// into 0 V with the bits set.
    #[inline]
    pub fn thrusts(&self, tau: &Vector6<f32>) -> [f32; THRUSTERS] {
        // The rows of `ACTUATED`, written out.
        let tau5 = Vector5::new(tau[0], tau[1], tau[2], tau[4], tau[5]);
        let t = self.b5_inv * tau5;
        [t[0], t[1], t[2], t[3], t[4]]
    }

    /// Wrench τ = B·T (N, N·m) that `thrusts` (N) produce, all six rows including K (zero for
    /// the default geometry).
    #[inline]
    pub fn wrench(&self, thrusts: &[f32; THRUSTERS]) -> Vector6<f32> {
        self.b * Vector5::from(*thrusts)
    }

    /// The 6×5 effectiveness matrix B (rows X Y Z K M N, column i = [dᵢ; rᵢ × dᵢ]).
    pub fn matrix(&self) -> Matrix6x5<f32> {
        self.b
    }

    /// κ∞(B₅) = ‖B₅‖∞·‖B₅⁻¹‖∞ (3.6 for the default geometry: 3.6 · 1).
    pub fn condition(&self) -> f32 {
        self.condition
    }
}

/// ∞-norm (largest absolute row sum) of a 5×5 matrix.
fn inf_norm(m: &Matrix5<f32>) -> f32 {
    let mut best = 0.0f32;
    for r in 0..5 {
        let mut s = 0.0f32;
        for c in 0..5 {
            s += m[(r, c)].abs();
        }
        if s > best {
            best = s;
        }
    }
    best
}
