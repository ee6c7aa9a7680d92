//! What the recognizer hands out: observations and matches. Evaluation scores these against
//! truth it holds itself, by `Observation::input_index`.

use crate::geom::OdomPose;
use serde::Serialize;

/// Index of an observation in the order the recognizer made them (global across runs).
pub type ObsId = usize;

/// One density observation, made each 0.10 m of odometric travel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Observation {
    pub id: ObsId,
    /// Run the observation belongs to (counts `start_run` calls that ended a run with inputs;
    /// the first run is 0).
    pub run: usize,
    /// Index of the `push` call (0-based, counted across runs) whose scan made it.
    pub input_index: usize,
    pub odom_pose: OdomPose,
    /// Odometric travel since the recognizer was created, metres (keeps growing across runs).
    pub travel_m: f64,
    /// Free-space density Ψ in [0, 1].
    pub psi: f64,
}

/// A word at a level of the multi-level word lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct WordRef {
    pub level: usize,
    pub index: usize,
}

/// Two observations the fine alignment put together: `query` is the newer one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AlignedPair {
    pub query: ObsId,
    pub past: ObsId,
    pub query_odom: OdomPose,
    pub past_odom: OdomPose,
}

/// Which way the past n-gram was read when it matched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// The revisit is driven the way the past pass was: past observations follow the query's
    /// order (past id increases as query id increases).
    #[default]
    Same,
    /// The revisit is driven the other way: the past n-gram was read backwards (word order
    /// reversed, turn angles negated), so past id decreases as query id increases.
    Opposite,
}

/// A recognized revisit: an n-gram of current words matched to an n-gram of past words, read
/// forwards or (direction `Opposite`) backwards.
///
/// Each word pair is reported once per level configuration: the first time a chain of matching
/// word pairs reaches the configuration's minimum n-gram size τ, the match carries the τ pairs of
/// that n-gram; when later words extend the chain, each extension is a match carrying only the
/// new pair. The matches of an L-level run are those with `levels` ≤ L.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Match {
    /// The level configuration that found it: 1 = level 0 only, 2 = levels 0-1, ...
    pub levels: usize,
    /// Number of word pairs in the matched n-gram (the chain ending at the last word pair).
    pub ngram_len: usize,
    /// The word pairs (current, past) this match newly covers, oldest first.
    pub word_pairs: Vec<(WordRef, WordRef)>,
    /// Observation pairs of those word pairs after fine alignment.
    pub pairs: Vec<AlignedPair>,
    /// The way the past side was read: `Same`, or `Opposite` for a revisit driven the other way.
    pub direction: Direction,
}
