//! The interface of a place recognizer: what the harness feeds it and what it answers.
//!
//! It sits below both the evaluation (`eval`, which scores any [`PlaceRecognizer`]) and the
//! recognizers that implement it (`baseline`'s ICP, the paper's recognizer in `experiment`), so no
//! recognizer depends on the evaluation that scores it. It only names the recognizer's output
//! types ([`Match`], [`Observation`]).

use crate::geom::OdomPose;
use crate::recognizer::{FrameId, Match, MatchDiagnostics, Observation};
use crate::scan::Scan;

/// Anything that recognizes places from odometry and scans alone: the paper's recognizer, the
/// ICP baseline, or a test double. It never sees ground truth.
pub trait PlaceRecognizer {
    /// Marks the start of a new run (no matching link crosses a run boundary). Called before
    /// the first frame of every run, the first one included. Returns the matches that closing
    /// the previous run produced (its last word is only complete once the run ends).
    fn start_run(&mut self) -> Vec<Match>;
    /// Feeds one odometry pose and its scan, tagged by the harness with `frame_id` (which the
    /// observations it makes must carry back, `Observation::frame_id`); returns the matches
    /// found because of it.
    fn push(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<Match>;
    /// Called after the last frame: returns the matches that closing the last run produced.
    fn finish(&mut self) -> Vec<Match> {
        Vec::new()
    }
    /// Every observation made so far, in the order made (`observations()[i].id == i` is not
    /// required; ids are looked up).
    fn observations(&self) -> &[Observation];
    /// Every match returned from now on names as its query only observations at or after this
    /// index of [`Self::observations`]; the evaluation forgets what it kept to deduplicate
    /// pairs behind it (`eval::tally`). 0, the default, promises nothing.
    fn query_horizon(&self) -> usize {
        0
    }
    /// A short name for reports and progress bars ("levels=2 [6, 9]", "icp").
    fn name(&self) -> String;
    /// What the recognizer saw, so a run without matches can say why; `None` when it cannot
    /// tell.
    fn diagnostics(&self) -> Option<MatchDiagnostics> {
        None
    }
}
