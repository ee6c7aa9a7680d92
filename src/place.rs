//! What every place recognizer shares: the observations it makes, the matches it claims, what it
//! says about a run, and the interface the harness drives it through ([`PlaceRecognizer`]).
//!
//! These types are neutral: they know nothing of words, densities or point clouds. The paper's
//! recognizer (`recognizer`), the baselines (`baseline`) and a recognizer in another process all
//! speak them, and the evaluation (`eval`) scores nothing else, so a new recognizer is scored
//! like the built-in ones without touching the evaluation. The module sits near the bottom of
//! the crate (above `scan` and `geom` only): the recognizers, the file formats (`io`) and the
//! evaluation all build on it.
//!
//! A recognizer that keeps more per observation or per match (the paper's keeps the density Ψ,
//! the words of a match and its levels) wraps these types in its own and hands the neutral part
//! to the harness.
//!
//! [`PlaceRecognizer`] shows a tiny recognizer; `eval::recognize_runs` shows one scored.

use crate::geom::OdomPose;
use crate::scan::Scan;
use serde::{Deserialize, Serialize};

/// Index of an observation in the order the recognizer made them (global across runs).
pub type ObsId = usize;

/// The caller's id of an input frame (odometry pose and scan), handed back on each observation.
pub type FrameId = usize;

/// One place the recognizer can match: where the robot was (by odometry) when it made it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Observation {
    pub id: ObsId,
    /// Run the observation belongs to (counts `start_run` calls that ended a run with inputs;
    /// the first run is 0).
    pub run: usize,
    /// Id of the input frame whose scan made it, as the harness tagged the frame
    /// ([`PlaceRecognizer::push`]). The harness scores observations by it: it holds the truth
    /// of every frame it tagged, and the recognizer never sees that truth.
    pub frame_id: FrameId,
    pub odom_pose: OdomPose,
    /// Odometric travel since the recognizer was created, metres (keeps growing across runs).
    pub travel_m: f64,
}

impl Observation {
    pub fn new(
        id: ObsId,
        run: usize,
        frame_id: FrameId,
        odom_pose: OdomPose,
        travel_m: f64,
    ) -> Self {
        Observation {
            id,
            run,
            frame_id,
            odom_pose,
            travel_m,
        }
    }
}

/// Consecutive observation pairs a match puts together, as one range: pair `i` (`i < len`) is
/// query `query_start + i` with past `past_start + i·past_step`. `query` is the newer side.
/// `past_step` is +1 when both sides run the same way (−1 for a place driven in the opposite
/// direction). A match of a long stretch costs a few words of memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct AlignedRun {
    pub query_start: ObsId,
    pub past_start: ObsId,
    pub len: u32,
    pub past_step: i8,
}

impl AlignedRun {
    /// `len` pairs from `(query_start, past_start)`, the past side moving by `past_step` (+1
    /// same direction, −1 opposite) per pair.
    pub fn new(query_start: ObsId, past_start: ObsId, len: u32, past_step: i8) -> Self {
        AlignedRun {
            query_start,
            past_start,
            len,
            past_step,
        }
    }

    /// The pairs `(query, past)` of the run, in order of query.
    pub fn pairs(&self) -> impl Iterator<Item = (ObsId, ObsId)> + '_ {
        let (q, p, step) = (
            self.query_start,
            self.past_start as i64,
            self.past_step as i64,
        );
        (0..self.len as usize).map(move |i| (q + i, (p + step * i as i64) as ObsId))
    }

    /// Appends pair `(query, past)` when it continues the run (same step), returning whether it
    /// did.
    pub fn extend(&mut self, query: ObsId, past: ObsId) -> bool {
        let next_past = self.past_start as i64 + self.past_step as i64 * self.len as i64;
        if query == self.query_start + self.len as usize && past as i64 == next_past {
            self.len += 1;
            true
        } else {
            false
        }
    }
}

/// Appends pair `(query, past)` to `runs`, extending the last run with `past_step` when the pair
/// continues it and starting a new run otherwise.
pub fn push_pair(runs: &mut Vec<AlignedRun>, query: ObsId, past: ObsId, past_step: i8) {
    if let Some(last) = runs.last_mut()
        && last.past_step == past_step
        && last.extend(query, past)
    {
        return;
    }
    runs.push(AlignedRun::new(query, past, 1, past_step));
}

/// Appends the `len` pairs `(query + i, past + i·past_step)`, i < `len`, to `runs`, as `len`
/// calls of [`push_pair`] would (the first may continue the last run; the rest continue it).
pub fn push_run(runs: &mut Vec<AlignedRun>, query: ObsId, past: ObsId, past_step: i8, len: u32) {
    if len == 0 {
        return;
    }
    push_pair(runs, query, past, past_step);
    if let Some(last) = runs.last_mut() {
        last.len += len - 1;
    }
}

/// Which way a revisit is driven, relative to the earlier pass it matches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// The revisit is driven the way the past pass was: past observations follow the query's
    /// order (past id increases as query id increases).
    #[default]
    Same,
    /// The revisit is driven the other way: past id decreases as query id increases.
    Opposite,
}

impl Direction {
    /// Both directions, `Same` first.
    pub const BOTH: [Direction; 2] = [Direction::Same, Direction::Opposite];

    /// `same` or `opposite`: its name in scenario files, reports and matches files.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Same => "same",
            Direction::Opposite => "opposite",
        }
    }
}

/// A recognized revisit: the observation pairs a recognizer claims show the same place, the way
/// the revisit is driven, and how sure it is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Match {
    /// The observation pairs, as ranges (see [`Match::pairs`]).
    pub runs: Vec<AlignedRun>,
    /// The way the revisit is driven relative to its past side.
    pub direction: Direction,
    /// The recognizer's confidence, larger is surer (its scale is the recognizer's own: chain
    /// length in words for the paper's recognizer, fitness for ICP). Precision-recall curves
    /// sweep a threshold over it.
    pub score: f64,
}

impl Match {
    /// A match of the aligned `runs`.
    pub fn new(runs: Vec<AlignedRun>, direction: Direction, score: f64) -> Self {
        Match {
            runs,
            direction,
            score,
        }
    }

    /// A match of the given pairs `(query, past)`, merged into runs of step +1 where they are
    /// consecutive, direction `Same` (for recognizers that produce pairs one by one).
    pub fn from_pairs(pairs: impl IntoIterator<Item = (ObsId, ObsId)>, score: f64) -> Match {
        let mut runs = Vec::new();
        for (q, p) in pairs {
            push_pair(&mut runs, q, p, 1);
        }
        Match::new(runs, Direction::Same, score)
    }

    /// The aligned observation pairs `(query, past)`, in the order the alignment made them.
    pub fn pairs(&self) -> impl Iterator<Item = (ObsId, ObsId)> + '_ {
        self.runs.iter().flat_map(AlignedRun::pairs)
    }

    /// How many aligned observation pairs the match holds.
    pub fn pair_count(&self) -> usize {
        self.runs.iter().map(|r| r.len as usize).sum()
    }
}

/// A candidate a recognizer considered and turned down, as one observation pair (and, for a
/// candidate that spans a stretch, the pair at its other end), so the harness can tell (by its
/// truth) whether it turned down a true revisit or a look-alike.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct RejectedCandidate {
    pub query: ObsId,
    pub past: ObsId,
    pub direction: Direction,
    /// The check that turned it down: an index into [`Diagnostics::checks`].
    pub check: usize,
    /// The pair at the candidate's oldest end, when it spans a stretch (a chain of words): the
    /// candidate is a true revisit only when both ends are, since two paths that meet at one
    /// end (the robot arrived from another corridor) make a chain whose older pairs are false.
    pub oldest: Option<(ObsId, ObsId)>,
}

impl RejectedCandidate {
    /// Pair `(query, past)` of `direction`, turned down by check number `check`.
    pub fn new(query: ObsId, past: ObsId, direction: Direction, check: usize) -> Self {
        RejectedCandidate {
            query,
            past,
            direction,
            check,
            oldest: None,
        }
    }

    /// The same candidate, spanning a stretch whose oldest end is the pair `(query, past)`.
    pub fn with_oldest(self, query: ObsId, past: ObsId) -> Self {
        RejectedCandidate {
            oldest: Some((query, past)),
            ..self
        }
    }
}

/// Candidates by outcome, as a recognizer counts them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct CandidateCounts {
    pub accepted: usize,
    pub rejected: usize,
}

impl CandidateCounts {
    /// `accepted` and `rejected` candidates.
    pub fn new(accepted: usize, rejected: usize) -> Self {
        CandidateCounts { accepted, rejected }
    }
}

/// What a recognizer says about a run, in its own words, so a run without matches can say why
/// and a report can show the recognizer's own counters.
pub trait Diagnostics: std::fmt::Debug + Send + Sync {
    /// Why the recognizer found nothing, as far as it can tell ("every candidate was rejected by
    /// verification: …").
    fn no_match_reason(&self) -> String;
    /// The recognizer's counters, as written in the report (`"diagnostics"`).
    fn to_json(&self) -> serde_json::Value;
    /// Candidates that reached the recognizer's checks, by outcome.
    fn candidates(&self) -> CandidateCounts {
        CandidateCounts::default()
    }
    /// Names of the checks a candidate can fail ([`RejectedCandidate::check`]), in the order
    /// the recognizer applies them.
    fn checks(&self) -> Vec<String> {
        Vec::new()
    }
    /// A sample of the candidates turned down (the paper's recognizer keeps the first 10,000).
    fn rejected(&self) -> &[RejectedCandidate] {
        &[]
    }
    /// Given the longest stretches of true travel along which every observation has a revisit
    /// (driven the same way, and the other way), whether they are long enough for this
    /// recognizer to match, in words; `None` when it cannot tell.
    fn revisit_length_reason(&self, same_m: f64, opposite_m: f64) -> Option<String> {
        let _ = (same_m, opposite_m);
        None
    }
    /// For one direction whose revisits got no pair while the other direction's did: whether
    /// its longest stretch of revisits, `longest_m` of true travel, is long enough for this
    /// recognizer to match that way, in words; `None` when it cannot tell.
    fn direction_length_reason(&self, direction: Direction, longest_m: f64) -> Option<String> {
        let _ = (direction, longest_m);
        None
    }
    /// Notes worth showing beside the results even when there are matches (e.g. inputs the
    /// recognizer could not use in full).
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }
}

/// Anything that recognizes places from odometry and scans alone: the paper's recognizer, a
/// baseline, a recognizer in another process, or a test double. It never sees ground truth.
///
/// A tiny one, fed by hand (`eval::recognize_runs` feeds one the frames of whole runs and
/// scores it):
///
/// ```
/// use placewords::geom::{OdomPose, Pose2};
/// use placewords::place::{FrameId, Match, Observation, PlaceRecognizer};
/// use placewords::scan::{BeamLayout, Scan};
///
/// /// Claims a revisit whenever the odometry comes back within 0.5 m of an earlier observation
/// /// (a toy: real recognizers may not trust odometry like this).
/// #[derive(Default)]
/// struct NearOdometry {
///     observations: Vec<Observation>,
///     run: usize,
///     started: bool,
/// }
///
/// impl PlaceRecognizer for NearOdometry {
///     fn start_run(&mut self) -> Vec<Match> {
///         if self.started {
///             self.run += 1;
///         }
///         self.started = true;
///         Vec::new()
///     }
///     fn push(&mut self, frame_id: FrameId, odom: OdomPose, _scan: &Scan) -> Vec<Match> {
///         let id = self.observations.len();
///         let past = self
///             .observations
///             .iter()
///             .find(|o| o.run < self.run && o.odom_pose.0.distance(&odom.0) < 0.5)
///             .map(|o| o.id);
///         self.observations.push(Observation::new(id, self.run, frame_id, odom, 0.0));
///         past.map(|p| vec![Match::from_pairs([(id, p)], 1.0)]).unwrap_or_default()
///     }
///     fn observations(&self) -> &[Observation] {
///         &self.observations
///     }
///     fn name(&self) -> String {
///         "near-odometry".into()
///     }
/// }
///
/// let mut rec = NearOdometry::default();
/// let layout = BeamLayout::centered(181, std::f64::consts::PI, 30.0, Pose2::IDENTITY);
/// let scan = Scan { ranges_m: vec![30.0; 181], layout, time_s: 0.0 };
/// let mut found = Vec::new();
/// for _run in 0..2 {
///     found.extend(rec.start_run());
///     for i in 0..10 {
///         let odom = OdomPose(Pose2::new(i as f64, 0.0, 0.0));
///         found.extend(rec.push(i, odom, &scan));
///     }
/// }
/// // Every observation of the second run pairs the first run's at the same place.
/// assert_eq!(found.len(), 10);
/// assert!(found.iter().flat_map(|m| m.pairs()).all(|(q, p)| q == p + 10));
/// ```
pub trait PlaceRecognizer {
    /// Marks the start of a new run (no matching link crosses a run boundary). Called before
    /// the first frame of every run, the first one included. Returns the matches that closing
    /// the previous run produced.
    fn start_run(&mut self) -> Vec<Match>;
    /// Feeds one odometry pose and its scan, tagged by the harness with `frame_id` (which the
    /// observations it makes must carry back, [`Observation::frame_id`]); returns the matches
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
    /// pairs behind it. 0, the default, promises nothing.
    fn query_horizon(&self) -> usize {
        0
    }
    /// A short name for reports and progress bars ("levels=2 [6, 9]", "icp").
    fn name(&self) -> String;
    /// What the recognizer saw, so a run without matches can say why; `None` when it cannot
    /// tell.
    fn diagnostics(&self) -> Option<Box<dyn Diagnostics>> {
        None
    }
    /// Why the recognizer could not go on (an external program that crashed, hung or printed
    /// garbage), in words; the harness checks it when the input ends and then fails the run
    /// instead of scoring it. `None`, the default: it never fails.
    fn failure(&self) -> Option<String> {
        None
    }
    /// Whether its work happens in another process, so that the harness's thread CPU clock
    /// does not see it and its time per lap is taken from the wall clock. Default false.
    fn runs_out_of_process(&self) -> bool {
        false
    }
}

/// Odometric travel along a recognizer's input and a fixed schedule of observations on it, one
/// per `spacing_m` of travel, the first at the first frame of the recognizer's input: frame
/// spacing does not stretch the observation spacing, and a long jump skips the slots it passed
/// (one observation, not a burst). Travel carries across runs (it orders a recognizer's whole
/// history); a run's first frame adds none. For any recognizer that observes by travel (the
/// baselines do).
#[derive(Clone, Debug)]
pub struct TravelSchedule {
    spacing_m: f64,
    travel_m: f64,
    last_pose: Option<crate::geom::Pose2>,
    /// Travel at which the next observation is due (`None`: at the next frame).
    next_m: Option<f64>,
}

impl TravelSchedule {
    /// A schedule of one observation per `spacing_m` (clamped to at least 1 µm) of travel.
    pub fn new(spacing_m: f64) -> Self {
        TravelSchedule {
            spacing_m: spacing_m.max(1e-6),
            travel_m: 0.0,
            last_pose: None,
            next_m: None,
        }
    }

    /// A new run: its first frame adds no travel and is due.
    pub fn start_run(&mut self) {
        self.last_pose = None;
        self.next_m = None;
    }

    /// Adds the travel from the last frame's odometric pose to `pose`; returns the travel.
    pub fn advance(&mut self, pose: crate::geom::Pose2) -> f64 {
        if let Some(last) = self.last_pose {
            self.travel_m += last.distance(&pose);
        }
        self.last_pose = Some(pose);
        self.travel_m
    }

    /// Travel so far, metres.
    pub fn travel_m(&self) -> f64 {
        self.travel_m
    }

    /// Whether an observation is due at the travel reached; when it is, the next slot is
    /// scheduled past it.
    pub fn take_due(&mut self) -> bool {
        if self.next_m.is_some_and(|t| self.travel_m < t) {
            return false;
        }
        let spacing = self.spacing_m;
        let mut next = self.next_m.unwrap_or(self.travel_m) + spacing;
        // Skip the passed slots by arithmetic when there are many (a jump of kilometres at a
        // fine spacing), one by one otherwise (the usual case, so the slots stay as they were).
        let behind = (self.travel_m - next) / spacing;
        if behind > 64.0 {
            next += (behind.floor() - 1.0) * spacing;
        }
        while next <= self.travel_m {
            next += spacing;
        }
        self.next_m = Some(next);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::TravelSchedule;
    use crate::geom::Pose2;

    #[test]
    fn observations_fall_on_a_fixed_schedule_of_travel() {
        let mut s = TravelSchedule::new(1.0);
        let due: Vec<bool> = [0.0, 0.4, 1.0, 1.5, 2.2, 7.9, 8.0, 8.5]
            .iter()
            .map(|&x| {
                s.advance(Pose2::new(x, 0.0, 0.0));
                s.take_due()
            })
            .collect();
        // Slots at 0, 1, 2, then the jump to 7.9 takes one and skips 3..7; 8 is the next slot.
        assert_eq!(due, [true, false, true, false, true, true, true, false]);
        // A new run's first frame is due and adds no travel.
        s.start_run();
        s.advance(Pose2::new(100.0, 0.0, 0.0));
        assert!(s.take_due());
        assert_eq!(s.travel_m(), 8.5);
        // A jump of a million slots is skipped at once, to the slot after it.
        s.advance(Pose2::new(1e6 + 100.25, 0.0, 0.0));
        assert!(s.take_due());
        s.advance(Pose2::new(1e6 + 100.9, 0.0, 0.0));
        assert!(!s.take_due());
    }
}
