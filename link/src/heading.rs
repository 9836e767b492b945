//! [`Heading`], the wire form of the core's heading mode: its own module because both a
//! `StartMission` ([`crate::msg`]) and a mission upload's header ([`crate::upload`]) carry it.

use serde::{Deserialize, Serialize};

/// The wire form of `controller_core::HeadingMode` (variant order is the wire format).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Heading {
    /// The paper's heading of the path.
    Paper,
    /// The path's course, atan2(ẏ_d, ẋ_d).
    Tangent,
}

impl Heading {
    /// Worst-case postcard size of a `Heading` (bytes).
    pub const MAX_SIZE: usize = 1; // the variant index, one byte
}
