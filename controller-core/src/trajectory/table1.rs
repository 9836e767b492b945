//! The six missions of the paper's Table 1 (docs/missions.md#closed-form-paths, docs/simulator.md#table-1 **Choice**: R = 10, 20;
//! A = 15, 20; s = 2/3, 1), with the paper's frequencies and depth.

use crate::trajectory::{Circle, FigureEight, LawnMower, Trajectory, TrajectoryKind};

/// The six missions of the paper's Table 1 (docs/missions.md#closed-form-paths, docs/simulator.md#table-1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Table1Case {
    /// Circle, R = 10 m.
    Circular10R,
    /// Circle, R = 20 m.
    Circular20R,
    /// Figure-eight in a 30 m × 30 m square, A = 15 m.
    FigureEight30x30,
    /// Figure-eight in a 40 m × 40 m square, A = 20 m.
    FigureEight40x40,
    /// Lawn-mower, loop 20 m high × ≈10 m wide, s = 2/3.
    LawnMower20x10,
    /// Lawn-mower, loop 30 m high × ≈15 m wide, s = 1 (the paper's printed equations).
    LawnMower30x15,
}

impl Table1Case {
    /// All six cases, in the order of the paper's Table 1.
    pub const ALL: [Self; 6] = [
        Self::Circular10R,
        Self::Circular20R,
        Self::FigureEight30x30,
        Self::FigureEight40x40,
        Self::LawnMower20x10,
        Self::LawnMower30x15,
    ];

    /// Stable name for logs and command lines, e.g. `"figure-eight-30x30"`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Circular10R => "circular-10R",
            Self::Circular20R => "circular-20R",
            Self::FigureEight30x30 => "figure-eight-30x30",
            Self::FigureEight40x40 => "figure-eight-40x40",
            Self::LawnMower20x10 => "lawn-mower-20x10",
            Self::LawnMower30x15 => "lawn-mower-30x15",
        }
    }

    /// The case whose [`name`](Self::name) is `name` (exact match).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The mission: paper frequencies (ω = 0.1, lawn-mower ω = 0.05) and depth 5 m, with the
    /// Table-1 sizes R = 10, 20; A = 15, 20; s = 2/3, 1.
    pub const fn kind(self) -> TrajectoryKind {
        match self {
            Self::Circular10R => circle_kind(10.0),
            Self::Circular20R => circle_kind(20.0),
            Self::FigureEight30x30 => figure_eight_kind(15.0),
            Self::FigureEight40x40 => figure_eight_kind(20.0),
            Self::LawnMower20x10 => lawn_mower_kind(2.0 / 3.0),
            Self::LawnMower30x15 => lawn_mower_kind(1.0),
        }
    }
}

pub(super) const fn circle_kind(radius: f32) -> TrajectoryKind {
    TrajectoryKind::Circle(Circle {
        radius,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    })
}

pub(super) const fn figure_eight_kind(amplitude: f32) -> TrajectoryKind {
    TrajectoryKind::FigureEight(FigureEight {
        amplitude,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    })
}

pub(super) const fn lawn_mower_kind(scale: f32) -> TrajectoryKind {
    TrajectoryKind::LawnMower(LawnMower {
        scale,
        omega: Trajectory::PAPER_LAWN_MOWER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    })
}
