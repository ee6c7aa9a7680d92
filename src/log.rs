//! Log records: what a run of the robot produced, frame by frame: [`RunLog`] → [`LapLog`] →
//! [`Frame`] (odometry, truth and scan at one time).
//!
//! A neutral data module: the simulator (`sim`) and the real-log readers (`io::real_log`) both
//! produce these records, and the recognizer harness (`eval`) consumes them, so neither producer
//! depends on the other.

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
