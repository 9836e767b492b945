//! Thruster geometry and the effectiveness matrix B (τ = B·T), docs/design.md §5.
//!
//! This module says where the five thrusters sit and which way they push, and turns that into
//! the 6×5 matrix B whose column i is the wrench [dᵢ; rᵢ × dᵢ] of one newton on thruster i
//! (rows X Y Z K M N). In PX4's terms it is the *actuator effectiveness*; solving B·T = τ for
//! T is the *control allocation* of [`crate::allocation`], and what a thruster does with a
//! voltage is [`crate::thruster`].
//!
//! Thruster order everywhere: `[main, vertical fore, vertical aft, horizontal fore,
//! horizontal aft]` (indices [`MAIN`], [`VERT_FORE`], [`VERT_AFT`], [`HORZ_FORE`],
//! [`HORZ_AFT`]).
//!
//! The geometry is **not in the paper**. [`ThrusterGeometry::default`] is the **Choice** of
//! docs/design.md §5; any other geometry is configuration and is checked here.

use core::fmt;

use nalgebra::Matrix6x5;

/// Number of thrusters.
pub const THRUSTERS: usize = 5;
/// Index of the stern main thruster (along +x).
pub const MAIN: usize = 0;
/// Index of the fore vertical tunnel thruster (along +z).
pub const VERT_FORE: usize = 1;
/// Index of the aft vertical tunnel thruster (along +z).
pub const VERT_AFT: usize = 2;
/// Index of the fore horizontal tunnel thruster (along +y).
pub const HORZ_FORE: usize = 3;
/// Index of the aft horizontal tunnel thruster (along +y).
pub const HORZ_AFT: usize = 4;

/// Allowed deviation of a direction's norm from 1: |‖d‖ − 1| ≤ this.
pub const UNIT_TOLERANCE: f32 = 1.0e-3;

/// Thruster positions (m) and unit thrust directions, body frame (origin CO, x forward,
/// y starboard, z down), in thruster order.
///
/// [`Default`] is docs/design.md §5 **Choice** — main at x = −2.43 m along +x; vertical
/// tunnels at x = +1.8 m (fore) and −1.8 m (aft) along +z; horizontal tunnels at x = +1.8 m
/// (fore) and −1.8 m (aft) along +y; all on the centre line. It is configuration:
/// [`effectiveness`](Self::effectiveness) accepts any geometry that passes its checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThrusterGeometry {
    /// Position rᵢ of thruster i, m.
    pub position: [[f32; 3]; THRUSTERS],
    /// Unit thrust direction dᵢ of thruster i (positive thrust pushes the vehicle along dᵢ).
    pub direction: [[f32; 3]; THRUSTERS],
}

impl Default for ThrusterGeometry {
    /// The docs/design.md §5 **Choice** layout (see the type's docs).
    fn default() -> Self {
        ThrusterGeometry {
            position: [
                [-2.43, 0.0, 0.0],
                [1.8, 0.0, 0.0],
                [-1.8, 0.0, 0.0],
                [1.8, 0.0, 0.0],
                [-1.8, 0.0, 0.0],
            ],
            direction: [
                [1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
        }
    }
}

/// Why a thruster geometry was rejected by [`ThrusterGeometry::effectiveness`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GeometryError {
    /// A position or direction component is NaN or infinite.
    NonFinite {
        /// Thruster index.
        thruster: usize,
    },
    /// |‖dᵢ‖ − 1| > [`UNIT_TOLERANCE`], checked as ‖dᵢ‖² outside [(1 − tol)², (1 + tol)²].
    NotUnitDirection {
        /// Thruster index.
        thruster: usize,
        /// ‖dᵢ‖².
        norm_squared: f32,
    },
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            GeometryError::NonFinite { thruster } => write!(
                f,
                "thruster geometry check failed: thruster {thruster} has a non-finite position or direction"
            ),
            GeometryError::NotUnitDirection {
                thruster,
                norm_squared,
            } => write!(
                f,
                "thruster geometry check failed: direction of thruster {thruster} is not a unit vector: |d|^2 = {norm_squared}, need ||d| - 1| <= {UNIT_TOLERANCE}"
            ),
        }
    }
}

impl core::error::Error for GeometryError {}

impl ThrusterGeometry {
    /// The 6×5 effectiveness matrix B (rows X Y Z K M N), column i = [dᵢ; rᵢ × dᵢ], so that
    /// the wrench of thrusts T (N) is τ = B·T.
    ///
    /// Rejects, with the thruster and its numbers: a non-finite position or direction, and a
    /// direction with |‖d‖ − 1| > [`UNIT_TOLERANCE`]. Whether B can be inverted is the
    /// allocation's question ([`crate::allocation::Allocation::new`]).
    ///
    /// For the default geometry, with r = (x, 0, 0): r × d = (0, −x d_z, x d_y), so a downward
    /// (+z) tunnel thrust at x = +1.8 m gives M = −1.8·T and a starboard (+y) one N = +1.8·T;
    /// the K row is zero (every thruster on the centre line).
    pub fn effectiveness(&self) -> Result<Matrix6x5<f32>, GeometryError> {
        let lo = (1.0 - UNIT_TOLERANCE) * (1.0 - UNIT_TOLERANCE);
        let hi = (1.0 + UNIT_TOLERANCE) * (1.0 + UNIT_TOLERANCE);
        let mut b = Matrix6x5::<f32>::zeros();
        for i in 0..THRUSTERS {
            let r = self.position[i];
            let d = self.direction[i];
            if !r.iter().chain(d.iter()).all(|x| x.is_finite()) {
                return Err(GeometryError::NonFinite { thruster: i });
            }
            let n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if !(lo..=hi).contains(&n2) {
                return Err(GeometryError::NotUnitDirection {
                    thruster: i,
                    norm_squared: n2,
                });
            }
            let m = [
                r[1] * d[2] - r[2] * d[1],
                r[2] * d[0] - r[0] * d[2],
                r[0] * d[1] - r[1] * d[0],
            ];
            for k in 0..3 {
                b[(k, i)] = d[k];
                b[(k + 3, i)] = m[k];
            }
        }
        Ok(b)
    }
}
