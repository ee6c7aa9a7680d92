//! The simulated robot: differential drive and route-following controller, LMS200 laser model,
//! odometry error models, pedestrians, seeded random streams, and lap generation.
//!
//! What a simulation produces ([`RunLog`], defined in [`crate::log`]) is also what real logs are
//! turned into, so the recognizer and evaluation see one shape of data.

pub mod laser;
pub mod logs;
pub mod odometry;
pub(crate) mod pedestrians;
pub(crate) mod plan;
pub mod rng;
pub(crate) mod robot;
pub mod runner;
pub mod test_drive;
pub(crate) mod variation;

pub use plan::{DoorChoice, DoorPlan, RunPlan, SimPlan};
pub use runner::{SimError, simulate};

/// The records a simulation produces live in the neutral [`crate::log`] module (real-log readers
/// produce them too); re-exported here for the simulator's users.
pub use crate::log::{Frame, LapLog, RunLog};
