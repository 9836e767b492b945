#![no_std]
#![doc = include_str!("../README.md")]
// One `unsafe` block in the crate: the FPU's square-root instruction on the target
// (`math::kernels::sqrt`), which core has no stable function for.
#![deny(unsafe_code)]

pub mod allocation;
pub mod axes;
pub mod config;
pub mod controller;
pub mod effectiveness;
pub mod estimator;
pub mod kinematics;
pub mod law;
pub mod math;
pub mod model;
pub mod phase;
pub mod readable;
pub mod thruster;
pub mod trajectory;
pub mod uncertainty;

pub use config::{BBound, ConfigError, ControllerConfig};
pub use controller::{
    BoxBounds, Controller, EstimatorStage, Fault, Output, Solution, Stage, Status,
};
pub use estimator::{Estimate, EstimatorConfig, EstimatorKind};
pub use law::RobustLaw;
pub use thruster::{ThrustUnit, DEFAULT_V_LIMIT};
pub use trajectory::{
    Desired, HeadingMode, Mission, Table1Case, Trajectory, TrajectoryKind, WaypointList,
};
