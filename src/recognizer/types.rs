//! What the recognizer hands out: observations and matches. Evaluation scores these against
//! truth it holds itself, by `Observation::frame_id`.

use crate::geom::OdomPose;
use serde::Serialize;

/// Index of an observation in the order the recognizer made them (global across runs).
pub type ObsId = usize;

/// The caller's id of an input frame (odometry pose and scan), handed back on each observation.
pub type FrameId = usize;

/// One density observation, made each 0.10 m of odometric travel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Observation {
    pub id: ObsId,
    /// Run the observation belongs to (counts `start_run` calls that ended a run with inputs;
    /// the first run is 0).
    pub run: usize,
    /// Id of the input frame whose scan made it, as the caller tagged the frame
    /// ([`Recognizer::push_frame`](super::Recognizer::push_frame); `push` tags its frames 0, 1,
    /// 2, … in order, across runs). The harness scores observations by it: it holds the truth of
    /// every frame it tagged, and the recognizer never sees that truth.
    pub frame_id: FrameId,
    pub odom_pose: OdomPose,
    /// Odometric travel since the recognizer was created, metres (keeps growing across runs).
    pub travel_m: f64,
    /// Free-space density Ψ in [0, 1].
    pub psi: f64,
    /// Where the space around the robot lies across the path: the first moment, along the
    /// robot's left axis (odometry heading), of the space the density kernel's rays reach (free
    /// or unknown, up to the first occupied cell), in kernel radii per node of the rays' prefix
    /// tree (positive: more space on the left; a 3 m side corridor off a 2 m corridor gives
    /// about ±0.12). Driven the other way, a place's left is its right, so the sign flips; at a
    /// place's mirror image it does not. Ψ alone cannot tell those two apart. (Only the lateral
    /// axis: along the path, the grid knows more ahead than behind, so that moment depends on
    /// the direction of travel.)
    pub lateral_moment: f64,
}

/// A word at a level of the multi-level word lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct WordRef {
    pub level: usize,
    pub index: usize,
}

/// Consecutive observation pairs the fine alignment put together, as one range: pair `i`
/// (`i < len`) is query `query_start + i` with past `past_start + i·past_step`. `query` is the
/// newer side. `past_step` is +1 when both sides run the same way (−1 for a place driven in the
/// opposite direction). A word pair's alignment is a few runs, so a match costs a few words of
/// memory however long its words are; odometry of a pair is looked up by id in the observations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct AlignedRun {
    pub query_start: ObsId,
    pub past_start: ObsId,
    pub len: u32,
    pub past_step: i8,
}

impl AlignedRun {
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
    runs.push(AlignedRun {
        query_start: query,
        past_start: past,
        len: 1,
        past_step,
    });
}

/// Appends the `len` pairs `(query + i, past + i·past_step)`, i < `len`, to `runs`, as `len`
/// calls of [`push_pair`] would (the first may continue the last run; the rest continue it).
pub(crate) fn push_run(
    runs: &mut Vec<AlignedRun>,
    query: ObsId,
    past: ObsId,
    past_step: i8,
    len: u32,
) {
    if len == 0 {
        return;
    }
    push_pair(runs, query, past, past_step);
    if let Some(last) = runs.last_mut() {
        last.len += len - 1;
    }
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
    /// Observation pairs of those word pairs after fine alignment, as ranges (see
    /// [`Match::pairs`]).
    pub runs: Vec<AlignedRun>,
    /// The way the past side was read: `Same`, or `Opposite` for a revisit driven the other way.
    pub direction: Direction,
}

impl Match {
    /// The aligned observation pairs `(query, past)`, in the order the alignment made them.
    pub fn pairs(&self) -> impl Iterator<Item = (ObsId, ObsId)> + '_ {
        self.runs.iter().flat_map(AlignedRun::pairs)
    }

    /// How many aligned observation pairs the match holds.
    pub fn pair_count(&self) -> usize {
        self.runs.iter().map(|r| r.len as usize).sum()
    }

    /// A match of the given pairs `(query, past)`, merged into runs of step +1 where they are
    /// consecutive, direction `Same` (for recognizers that produce pairs one by one).
    pub fn from_pairs(
        levels: usize,
        ngram_len: usize,
        word_pairs: Vec<(WordRef, WordRef)>,
        pairs: impl IntoIterator<Item = (ObsId, ObsId)>,
    ) -> Match {
        let mut runs = Vec::new();
        for (q, p) in pairs {
            push_pair(&mut runs, q, p, 1);
        }
        Match {
            levels,
            ngram_len,
            word_pairs,
            runs,
            direction: Direction::Same,
        }
    }
}
