//! The place recognizer of the paper: local grid, density Ψ, density classes, words, multi-level
//! words, incremental n-gram matching and fine alignment. It takes odometry poses and scans and
//! never sees ground truth: its inputs are [`OdomPose`] and [`Scan`] only.
//!
//! Two halves, usable apart so that a threshold sweep computes observations once:
//! - [`DensityFrontEnd`]: scans → local grid → one [`DensityObservation`] (Ψ) per 0.10 m of
//!   travel;
//! - [`WordMatcher`]: observations → words of every level → [`WordMatch`]es with aligned pairs.
//!
//! [`Recognizer`] composes the two, and is a [`PlaceRecognizer`]: the harness scores the neutral
//! part of its matches ([`WordMatch::to_place`]) and hears its [`MatchDiagnostics`] through
//! [`crate::place::Diagnostics`].

mod align;
mod chains;
pub(crate) mod config;
pub(crate) mod density;
pub(crate) mod diagnostics;
pub(crate) mod frontend;
pub(crate) mod grid;
mod index;
pub(crate) mod matcher;
pub(crate) mod options;
/// Synthetic inputs for tests and benchmarks; not part of the API.
#[doc(hidden)]
pub(crate) mod types;
mod verify;
pub(crate) mod wide;
pub(crate) mod words;

pub use config::{
    ConfigProblem, RENAMED_KEYS, RecognizerConfig, RecognizerError, SECTIONS, table_name,
};
pub use density::{CellState, DenseGrid, DensityKernel, FreeCells, RayDeltas, Visited, density};
pub use diagnostics::{MatchDiagnostics, Rejection, VerificationCounts, long_steps_sentence};
pub use frontend::{DensityFrontEnd, Due, ObservationClock, PsiGap};
pub use grid::{Density, LocalGrid};
pub use matcher::WordMatcher;
pub use options::{
    AlignmentMode, AlignmentOptions, DensityOptions, FrontEndOptions, GridOptions, MatcherOptions,
    MultiLevelRule, PsiWindowStatistic, VerifyOptions, WordOptions,
};
pub use types::{
    AlignedRun, DensityObservation, Direction, FrameId, ObsId, Observation, WordMatch, WordRef,
    push_pair,
};
pub use wide::WideWindow;
pub use words::{Word, WordId, WordLevels};

use crate::geom::OdomPose;
use crate::place::{self, PlaceRecognizer};
use crate::scan::Scan;

/// The online recognizer: push odometry and scans, get matches as soon as they exist.
#[derive(Clone, Debug)]
pub struct Recognizer {
    config: RecognizerConfig,
    front: DensityFrontEnd,
    back: WordMatcher,
}

impl Recognizer {
    pub fn new(config: RecognizerConfig) -> Result<Self, RecognizerError> {
        let front = DensityFrontEnd::new(&config)?;
        let back = WordMatcher::new(&config)?;
        Ok(Recognizer {
            config,
            front,
            back,
        })
    }

    /// Integrates one scan taken at `odom`; returns the matches that became known with it.
    ///
    /// A robot drives the same 40 m corridor twice (two runs), with openings on both sides at
    /// irregular places; on the second pass the recognizer matches places of the first, and
    /// every aligned pair joins two observations at the same place of the corridor:
    ///
    /// ```
    /// use placewords::geom::{OdomPose, Pose2};
    /// use placewords::recognizer::{Recognizer, RecognizerConfig};
    /// use placewords::scan::{BeamLayout, Scan};
    ///
    /// // Corridor walls y = ±1 m from x = 0 to 40 m, with openings [from, to] on each side.
    /// let openings = [(3.0, 4.0), (7.5, 8.2), (13.0, 15.5), (21.0, 21.8), (29.0, 31.0)];
    /// let other = [(5.0, 6.5), (11.0, 11.6), (18.0, 20.0), (25.5, 26.0), (34.0, 36.5)];
    /// let wall_at = |x: f64, gaps: &[(f64, f64)]| !gaps.iter().any(|&(a, b)| x >= a && x <= b);
    /// let layout = BeamLayout::centered(181, std::f64::consts::PI, 30.0, Pose2::IDENTITY);
    /// // Range along angle `a` from (x, 0): the first wall y = ±1 the beam meets, if any.
    /// let range = |x: f64, a: f64| -> f64 {
    ///     let (dx, dy) = (a.cos(), a.sin());
    ///     if dy.abs() < 1e-9 {
    ///         return layout.max_range_m;
    ///     }
    ///     let t = 1.0 / dy.abs();
    ///     let hit_x = x + dx * t;
    ///     let gaps: &[(f64, f64)] = if dy > 0.0 { &openings } else { &other };
    ///     if (0.0..=40.0).contains(&hit_x) && wall_at(hit_x, gaps) {
    ///         t.min(layout.max_range_m)
    ///     } else {
    ///         layout.max_range_m
    ///     }
    /// };
    /// let mut rec = Recognizer::new(RecognizerConfig::default()).unwrap();
    /// let mut matches = Vec::new();
    /// for run in 0..2 {
    ///     matches.extend(rec.start_run());
    ///     for step in 0..=380 {
    ///         let x = 1.0 + 0.1 * step as f64;
    ///         let ranges_m = (0..layout.count).map(|i| range(x, layout.beam_angle_rad(i))).collect();
    ///         let scan = Scan { layout: layout.clone(), ranges_m, time_s: step as f64 };
    ///         matches.extend(rec.push(OdomPose(Pose2::new(x, 0.0, 0.0)), &scan));
    ///     }
    ///     matches.extend(rec.finish());
    /// }
    /// // One observation per 0.10 m of travel, on both runs.
    /// assert!(rec.observations().len() >= 2 * 370, "{}", rec.observations().len());
    /// // The second pass recognizes the first, at the right places.
    /// assert!(!matches.is_empty());
    /// for (query, past) in matches.iter().flat_map(|m| m.pairs()) {
    ///     let (q, p) = (&rec.observations()[query], &rec.observations()[past]);
    ///     assert_eq!((q.run, p.run), (1, 0));
    ///     assert!((q.odom_pose.0.x - p.odom_pose.0.x).abs() < 1.0);
    /// }
    /// ```
    pub fn push(&mut self, odom: OdomPose, scan: &Scan) -> Vec<WordMatch> {
        let observations = self.front.push(odom, scan);
        self.match_observations(&observations)
    }

    /// Like [`push`](Self::push), with the frame's id given by the caller: every observation
    /// the scan makes carries `frame_id` (`Observation::frame_id`), so a harness that tags its
    /// frames can score matches against truth it keeps to itself.
    pub fn push_frame(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<WordMatch> {
        let observations = self.front.push_frame(frame_id, odom, scan);
        self.match_observations(&observations)
    }

    fn match_observations(&mut self, observations: &[DensityObservation]) -> Vec<WordMatch> {
        let mut out = Vec::new();
        for obs in observations {
            let matches = self.back.push_observation(obs);
            // Usually one observation per scan: its matches are the scan's, not copied over.
            if out.is_empty() {
                out = matches;
            } else {
                out.extend(matches);
            }
        }
        out
    }

    /// Ends the current run and starts the next: the grid is cleared, the last word of the run
    /// is closed (its matches are returned) and no predecessor links cross the boundary. Does
    /// nothing before the run's first input, so it may be called before every run.
    pub fn start_run(&mut self) -> Vec<WordMatch> {
        self.front.start_run();
        self.back.start_run()
    }

    /// Closes the last word of the current run and returns its matches (call after the last
    /// input; pushing more afterwards continues the run with a fresh word).
    pub fn finish(&mut self) -> Vec<WordMatch> {
        self.back.finish_run()
    }

    pub fn config(&self) -> &RecognizerConfig {
        &self.config
    }

    /// Every observation made so far.
    pub fn observations(&self) -> &[Observation] {
        self.back.observations()
    }

    /// Every match found from now on pairs only observations at or after this index of
    /// [`Self::observations`] as its query (see `WordMatcher::query_horizon`).
    pub fn query_horizon(&self) -> usize {
        self.back.query_horizon()
    }

    /// Words of every level (for tests and plots).
    pub fn words(&self) -> &WordLevels {
        self.back.words()
    }

    /// Words of one level, in order.
    pub fn level_words(&self, level: usize) -> Vec<&Word> {
        self.back.words().level(level).collect()
    }

    pub fn front_end(&self) -> &DensityFrontEnd {
        &self.front
    }

    pub fn back_end(&self) -> &WordMatcher {
        &self.back
    }

    /// What the matcher saw so far, to say why nothing matched.
    pub fn diagnostics(&self) -> MatchDiagnostics {
        MatchDiagnostics {
            long_steps: self.front.long_steps(),
            ..self.back.diagnostics()
        }
    }
}

/// The thresholds a level configuration uses (τ0 .. τ(levels-1)).
pub fn thresholds(cfg: &RecognizerConfig) -> Vec<usize> {
    cfg.matcher
        .min_ngram
        .iter()
        .copied()
        .take(cfg.levels)
        .collect()
}

/// The neutral matches the harness scores.
pub(crate) fn to_place(matches: Vec<WordMatch>) -> Vec<place::Match> {
    matches.iter().map(WordMatch::to_place).collect()
}

/// A recognizer's name in the harness: `levels=3 [6, 9, 12]`.
pub(crate) fn harness_name(c: &RecognizerConfig) -> String {
    format!("levels={} {:?}", c.levels, thresholds(c))
}

/// The recognizer as the harness sees it: neutral matches scored by chain length.
impl PlaceRecognizer for Recognizer {
    fn start_run(&mut self) -> Vec<place::Match> {
        to_place(Recognizer::start_run(self))
    }
    fn push(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<place::Match> {
        to_place(Recognizer::push_frame(self, frame_id, odom, scan))
    }
    fn finish(&mut self) -> Vec<place::Match> {
        to_place(Recognizer::finish(self))
    }
    fn observations(&self) -> &[Observation] {
        Recognizer::observations(self)
    }
    fn query_horizon(&self) -> usize {
        Recognizer::query_horizon(self)
    }
    fn name(&self) -> String {
        harness_name(self.config())
    }
    fn diagnostics(&self) -> Option<Box<dyn place::Diagnostics>> {
        Some(Box::new(Recognizer::diagnostics(self)))
    }
}
