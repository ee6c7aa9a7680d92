//! Baselines the recognizer is compared with: ICP (the paper's Table I) and a Scan Context-style
//! polar descriptor, both written against the plug-in API (`place`).

pub mod icp;
pub mod scan_context;

pub use icp::{IcpConfig, IcpRecognizer};
pub use scan_context::{ScanContextConfig, ScanContextRecognizer};

use crate::geom::OdomPose;
use crate::place::{FrameId, Observation};

/// Appends the next observation of a baseline (its id is its index in `observations`; the run
/// is 0 before the first `start_run`) and returns its id.
fn push_observation(
    observations: &mut Vec<Observation>,
    run: Option<usize>,
    frame_id: FrameId,
    odom: OdomPose,
    travel_m: f64,
) -> usize {
    let id = observations.len();
    observations.push(Observation::new(
        id,
        run.unwrap_or(0),
        frame_id,
        odom,
        travel_m,
    ));
    id
}
