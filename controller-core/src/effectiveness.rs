//! Thruster geometry and the effectiveness matrix B (τ = B·T), docs/thrusters.md#geometry-and-the-effectiveness-matrix.
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
//! docs/thrusters.md#geometry-and-the-effectiveness-matrix (positions) and docs/real-vehicle.md#the-default-mounting (mounting signs, [`AUV150_REVERSED`]); any other
//! geometry is configuration and is checked here.

use core::fmt;

use nalgebra::Matrix6x5;

/// Number of thrusters.
pub const THRUSTERS: usize = 5;
/// The thrusters' names in thruster order ([`MAIN`], [`VERT_FORE`], …): the words of scenario
/// files (`reversed_thrusters`), plots, tables, the preflight and the board's reports.
pub const THRUSTER_NAMES: [&str; THRUSTERS] =
    ["main", "vert fore", "vert aft", "horz fore", "horz aft"];
/// Index of the stern main thruster (along +x).
pub const MAIN: usize = 0;
/// Index of the fore vertical tunnel thruster (reference axis +z).
pub const VERT_FORE: usize = 1;
/// Index of the aft vertical tunnel thruster (reference axis +z).
pub const VERT_AFT: usize = 2;
/// Index of the fore horizontal tunnel thruster (reference axis +y).
pub const HORZ_FORE: usize = 3;
/// Index of the aft horizontal tunnel thruster (reference axis +y).
pub const HORZ_AFT: usize = 4;

/// Allowed deviation of a direction's norm from 1: |‖d‖ − 1| ≤ this.
pub const UNIT_TOLERANCE: f32 = 1.0e-3;

/// Where the AUV-150's thrusters sit, body frame (m), thruster order (docs/thrusters.md#geometry-and-the-effectiveness-matrix
/// **Choice**: all on the centre line; the main thruster at the stern, the tunnels at ±1.8 m).
pub const AUV150_POSITIONS: [[f32; 3]; THRUSTERS] = [
    [-2.43, 0.0, 0.0],
    [1.8, 0.0, 0.0],
    [-1.8, 0.0, 0.0],
    [1.8, 0.0, 0.0],
    [-1.8, 0.0, 0.0],
];

/// The reference axis of each AUV-150 thruster, thruster order: +x for the main thruster, +z
/// (down) for the vertical tunnels, +y (starboard) for the horizontal tunnels. A thruster's
/// direction is its reference axis or, if it is mounted the other way round, the axis
/// negated ([`ThrusterGeometry::auv150`]).
pub const AUV150_AXES: [[f32; 3]; THRUSTERS] = [
    [1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, 1.0],
    [0.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];

/// The real vehicle's mounting (docs/real-vehicle.md#the-default-mounting, **Choice 105**), as a reversed-thruster
/// mask for [`ThrusterGeometry::auv150`]: bit i set ⇔ thruster i's positive (strong) thrust
/// pushes against its reference axis [`AUV150_AXES`]. Chosen by flying: of the 32 masks, the
/// one under which the six real missions (the Table-1 paths, tangent heading, the Table-3
/// payload trimmed) fly at the smallest time scales the preflight proposes
/// (`host-sim validate-preflight`).
///
/// * Vertical fore reversed: its strong direction pushes **up** (−z); vertical aft as it is,
///   pushing **down** (+z). A trimmed payload's standing vertical demand is the moment of its
///   CG shift, x_G W ≥ 0 (nose down: the payload is never aft of CO), which needs the fore
///   thruster to push up and the aft one down: both strong sides (36 % of the envelope at
///   Table 3's corner, against 79 % when the aft one holds it on its weak side).
/// * Horizontal pair reversed: its strong direction pushes to **port** (−y). With the
///   tangent heading the sway demand is the centripetal force of the turn, ≈ (m − X_u̇)·u·r;
///   both Table-1 circles turn to port all the time (ψ̇_d = −ω), so that is their standing
///   demand, while the figure-eights and lawn-mowers turn both ways equally.
/// * Main thruster as it is: positive thrust forward (+x).
pub const AUV150_REVERSED: u8 = (1 << VERT_FORE) | (1 << HORZ_FORE) | (1 << HORZ_AFT);

/// Which way each AUV-150 thruster's strong (positive) thrust pushes the vehicle under the
/// reversed-thruster mask `reversed` ([`ThrusterGeometry::auv150`]), in words, thruster order:
/// the main thruster `forward` or `aft`, the vertical pair `down` or `up`, the horizontal pair
/// `starboard` or `port`. What scenario files, `host-sim check` and the board's log print, so
/// that a team reads the mounting a board runs without decoding a bit mask.
pub const fn mounting_words(reversed: u8) -> [&'static str; THRUSTERS] {
    const WORDS: [[&str; 2]; THRUSTERS] = [
        ["forward", "aft"],
        ["down", "up"],
        ["down", "up"],
        ["starboard", "port"],
        ["starboard", "port"],
    ];
    let mut out = [""; THRUSTERS];
    let mut i = 0;
    while i < THRUSTERS {
        out[i] = WORDS[i][((reversed >> i) & 1) as usize];
        i += 1;
    }
    out
}

/// The AUV-150 mounting `reversed` as one line: `main forward, vert fore up, vert aft down,
/// horz fore port, horz aft port` ([`mounting_words`] after each [`THRUSTER_NAMES`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mounting(pub u8);

impl fmt::Display for Mounting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let words = mounting_words(self.0);
        for (i, (name, word)) in THRUSTER_NAMES.iter().zip(words).enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{name} {word}")?;
        }
        Ok(())
    }
}

/// Thruster positions (m) and unit thrust directions, body frame (origin CO, x forward,
/// y starboard, z down), in thruster order. The direction carries the **mounting sign**:
/// positive thrust pushes the vehicle along it.
///
/// [`Default`] is the real AUV-150 of docs/thrusters.md#geometry-and-the-effectiveness-matrix, docs/real-vehicle.md#the-real-missions (**Choice**):
/// [`auv150`](Self::auv150)([`AUV150_REVERSED`]) — the main thruster at x = −2.43 m along +x;
/// the vertical tunnels at x = +1.8 m (fore, along −z: pushing up) and −1.8 m (aft, along +z:
/// pushing down); the
/// horizontal tunnels at x = ±1.8 m along −y (pushing to port); all on the centre line. It is
/// configuration: [`effectiveness`](Self::effectiveness) accepts any geometry that passes its
/// checks, and the allocator any whose 5×5 allocation is block diagonal
/// ([`crate::allocation::Allocator`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThrusterGeometry {
    /// Position rᵢ of thruster i, m.
    pub position: [[f32; 3]; THRUSTERS],
    /// Unit thrust direction dᵢ of thruster i (positive thrust pushes the vehicle along dᵢ).
    pub direction: [[f32; 3]; THRUSTERS],
}

impl Default for ThrusterGeometry {
    /// The real AUV-150: [`ThrusterGeometry::auv150`]`(`[`AUV150_REVERSED`]`)` (see the
    /// type's docs).
    fn default() -> Self {
        ThrusterGeometry::auv150(AUV150_REVERSED)
    }
}

impl ThrusterGeometry {
    /// The AUV-150 layout ([`AUV150_POSITIONS`]) with each thruster along its reference axis
    /// ([`AUV150_AXES`]), or against it where bit i of `reversed` is set (bits above the
    /// fifth are ignored). `auv150(0)` is every thruster along +x, +z, +z, +y, +y.
    pub const fn auv150(reversed: u8) -> Self {
        let mut direction = AUV150_AXES;
        let mut i = 0;
        while i < THRUSTERS {
            if reversed & (1 << i) != 0 {
                let mut k = 0;
                while k < 3 {
                    direction[i][k] = -direction[i][k];
                    k += 1;
                }
            }
            i += 1;
        }
        ThrusterGeometry {
            position: AUV150_POSITIONS,
            direction,
        }
    }

    /// The reversed-thruster mask `m` with `self == auv150(m)`, if this is the AUV-150 layout
    /// with some thrusters reversed; `None` for any other geometry. The board's link carries
    /// the geometry as this mask (`SetConfig`).
    pub fn auv150_reversed(&self) -> Option<u8> {
        let mut mask = 0u8;
        for (i, axis) in AUV150_AXES.iter().enumerate() {
            if self.direction[i] != *axis {
                mask |= 1 << i;
            }
        }
        (*self == ThrusterGeometry::auv150(mask)).then_some(mask)
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
    /// allocation's question ([`crate::allocation::PseudoInverse::new`]).
    ///
    /// For the AUV-150 layout, with r = (x, 0, 0): r × d = (0, −x d_z, x d_y), so a downward
    /// (+z) tunnel thrust at x = +1.8 m gives M = −1.8·T and a starboard (+y) one N = +1.8·T;
    /// the default mounting reverses both (an upward push fore gives M = +1.8·T, a push to
    /// port fore N = −1.8·T). The K row is zero (every thruster on the centre line).
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
