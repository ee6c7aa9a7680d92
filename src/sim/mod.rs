//! The simulated robot: differential drive and route-following controller, LMS200 laser model,
//! odometry error models, pedestrians, seeded random streams, and lap generation.
//!
//! What a simulation produces ([`RunLog`]) is also what real logs are turned into, so the
//! recognizer and evaluation see one shape of data.

pub mod laser;
pub mod logs;
pub mod odometry;
pub mod pedestrians;
pub mod plan;
pub mod rng;
pub mod robot;
pub mod runner;

pub use plan::{DoorChoice, DoorPlan, RunPlan, SimPlan};
pub use runner::{SimError, simulate};

use crate::geom::{OdomPose, TruePose};
use crate::scan::Scan;

/// One laser scan with the poses at its time.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Seconds since the start of the run.
    pub time_s: f64,
    /// Dead-reckoning pose: the only pose the recognizer may see.
    pub odom: OdomPose,
    /// Ground truth, for evaluation only.
    pub truth: TruePose,
    pub scan: Scan,
}

/// One lap of a run: the frames recorded while the robot drove it, and the doors it saw.
#[derive(Clone, Debug, PartialEq)]
pub struct LapLog {
    /// 0-based lap within the run.
    pub lap: usize,
    /// Name of the door configuration during this lap ("all-closed", a named set, "random").
    pub door_config: String,
    /// Ids of the doors open during this lap.
    pub open_doors: Vec<String>,
    pub frames: Vec<Frame>,
}

/// One run: consecutive laps from one start, with continuous odometry.
#[derive(Clone, Debug, PartialEq)]
pub struct RunLog {
    /// 0-based run index within the scenario.
    pub run: usize,
    pub laps: Vec<LapLog>,
}

impl RunLog {
    /// All frames of the run in order.
    pub fn frames(&self) -> impl Iterator<Item = &Frame> {
        self.laps.iter().flat_map(|l| l.frames.iter())
    }
}
