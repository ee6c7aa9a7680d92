//! The place recognizer of the paper: local grid, density Ψ, density classes, words, multi-level
//! words, incremental n-gram matching and fine alignment. It takes odometry poses and scans and
//! never sees ground truth: its inputs are [`OdomPose`] and [`Scan`] only.
//!
//! Two halves, usable apart so that a threshold sweep computes observations once:
//! - [`DensityFrontEnd`]: scans → local grid → one [`Observation`] (Ψ) per 0.10 m of travel;
//! - [`WordMatcher`]: observations → words of every level → [`Match`]es with aligned pairs.
//!
//! [`Recognizer`] composes the two.

pub mod config;
pub mod density;
pub mod frontend;
pub mod grid;
mod index;
pub mod matcher;
pub mod synth;
pub mod types;
pub mod words;

pub use config::{AlignmentMode, ConfigProblem, RecognizerConfig, RecognizerError};
pub use density::{CellState, DenseGrid, DensityKernel, RayDeltas, Visited, density};
pub use frontend::DensityFrontEnd;
pub use grid::LocalGrid;
pub use matcher::WordMatcher;
pub use types::{AlignedRun, Match, ObsId, Observation, WordRef, push_pair};
pub use words::{Word, WordId, WordLevels};

use crate::geom::OdomPose;
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
    pub fn push(&mut self, odom: OdomPose, scan: &Scan) -> Vec<Match> {
        let observations = self.front.push(odom, scan);
        let mut out = Vec::new();
        for obs in &observations {
            out.extend(self.back.push_observation(obs));
        }
        out
    }

    /// Ends the current run and starts the next: the grid is cleared, the last word of the run
    /// is closed (its matches are returned) and no predecessor links cross the boundary. Does
    /// nothing before the run's first input, so it may be called before every run.
    pub fn start_run(&mut self) -> Vec<Match> {
        self.front.start_run();
        self.back.start_run()
    }

    /// Closes the last word of the current run and returns its matches (call after the last
    /// input; pushing more afterwards continues the run with a fresh word).
    pub fn finish(&mut self) -> Vec<Match> {
        self.back.finish_run()
    }

    pub fn config(&self) -> &RecognizerConfig {
        &self.config
    }

    /// Every observation made so far.
    pub fn observations(&self) -> &[Observation] {
        self.back.observations()
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
}
