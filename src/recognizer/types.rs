//! What the paper's recognizer hands out: observations with their density Ψ, and matches with
//! the words behind them. Each wraps the neutral type of [`crate::place`] that the harness
//! scores ([`DensityObservation::observation`], [`WordMatch::to_place`]).

pub use crate::place::{AlignedRun, Direction, FrameId, ObsId, Observation, push_pair, push_run};
use serde::Serialize;

/// One density observation, made each 0.10 m of odometric travel: the neutral observation and
/// what the paper's recognizer measured there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DensityObservation {
    /// Where and when it was made (what the harness scores).
    #[serde(flatten)]
    pub observation: Observation,
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
    /// How far the robot's true path may lie from this observation's position, metres: 0 at a
    /// scan's own pose; for an observation interpolated along a step between two scans (sparse
    /// logs), the distance from the step's chord to an arc turning the step's heading change Δθ
    /// (step length × |Δθ| × f(1 − f) / 2 at fraction f of the step; 0 on a straight step). A
    /// word's angle syllable is measured from such positions, so it is uncertain by what this
    /// moves its chords (`MatcherOptions::angle_slack`).
    #[serde(default)]
    pub position_slack_m: f64,
    /// The wide density Φ in [0, 1]: the share of a disc of `wide_radius_m` around the robot
    /// that the laser has seen free lately (`recognizer::wide`); 0 when the wide window is off.
    /// It splits Ψ's top class in open space (`WordOptions::wide_classes`).
    #[serde(default)]
    pub wide_density: f64,
    /// How many observations the scan step that made it made in all: 1 when its scan made it
    /// alone (every simulated run: scans 4–10 cm apart), more along a long step between sparse
    /// scans (Intel: about 7, a scan every 0.7 m), where the class boundaries the step crossed
    /// could lie anywhere in it; 0 when unknown (read as 1). Words read it at their ends
    /// ([`super::words::Word::sampling_slack_obs`]).
    #[serde(default)]
    pub scan_step_observations: u32,
}

/// A density observation reads as the neutral observation it carries (`o.travel_m`,
/// `o.odom_pose`), since every harness rule about observations applies to it unchanged.
impl std::ops::Deref for DensityObservation {
    type Target = Observation;
    fn deref(&self) -> &Observation {
        &self.observation
    }
}

impl std::ops::DerefMut for DensityObservation {
    fn deref_mut(&mut self) -> &mut Observation {
        &mut self.observation
    }
}

/// The Ψ residual at which a match's score is half-way between its chain length and the
/// chain length plus ½ ([`WordMatch::score`]): the verification's default bound on the RMS Ψ
/// difference (`verify_max_psi_rms`), so a match at that bound adds ¼.
pub const PSI_RMS_SCALE: f64 = 0.04;

/// A word at a level of the multi-level word lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct WordRef {
    pub level: usize,
    pub index: usize,
}

/// A recognized revisit: an n-gram of current words matched to an n-gram of past words, read
/// forwards or (direction `Opposite`) backwards.
///
/// Each word pair is reported once per level configuration: the first time a chain of matching
/// word pairs reaches the configuration's minimum n-gram size τ, the match carries the τ pairs of
/// that n-gram; when later words extend the chain, each extension is a match carrying only the
/// new pair. The matches of an L-level run are those with `levels` ≤ L.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WordMatch {
    /// The level configuration that found it: 1 = level 0 only, 2 = levels 0-1, ...
    pub levels: usize,
    /// Number of word pairs in the matched n-gram (the chain ending at the last word pair).
    pub ngram_len: usize,
    /// The word pairs (current, past) this match newly covers, oldest first.
    pub word_pairs: Vec<(WordRef, WordRef)>,
    /// Observation pairs of those word pairs after fine alignment, as ranges (see
    /// [`WordMatch::pairs`]).
    pub runs: Vec<AlignedRun>,
    /// The way the past side was read: `Same`, or `Opposite` for a revisit driven the other way.
    pub direction: Direction,
    /// Root mean square Ψ difference of the aligned observation pairs of its word pairs (the
    /// fine alignment's residual; infinite when none aligned).
    pub psi_rms: f64,
}

impl WordMatch {
    /// The aligned observation pairs `(query, past)`, in the order the alignment made them.
    pub fn pairs(&self) -> impl Iterator<Item = (ObsId, ObsId)> + '_ {
        self.runs.iter().flat_map(AlignedRun::pairs)
    }

    /// How many aligned observation pairs the match holds.
    pub fn pair_count(&self) -> usize {
        self.runs.iter().map(|r| r.len as usize).sum()
    }

    /// What the harness scores of it: the pairs and the direction, with [`Self::score`].
    pub fn to_place(&self) -> crate::place::Match {
        crate::place::Match::new(self.runs.clone(), self.direction, self.score())
    }

    /// How sure the match is: the n-gram's length in word pairs (a longer chain of matching
    /// words is surer evidence), plus `½ · s / (s + psi_rms)` with `s` =
    /// `PSI_RMS_SCALE` (in (0, ½], larger as the densities agree better) so that within
    /// one chain length the better aligned match ranks higher and no residual lifts a match
    /// above a longer chain. Monotone: longer chains and smaller residuals score higher.
    pub fn score(&self) -> f64 {
        let agreement = if self.psi_rms.is_finite() {
            PSI_RMS_SCALE / (PSI_RMS_SCALE + self.psi_rms.max(0.0))
        } else {
            0.0
        };
        self.ngram_len as f64 + 0.5 * agreement
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn word_match(ngram_len: usize, psi_rms: f64) -> WordMatch {
        WordMatch {
            levels: 1,
            ngram_len,
            word_pairs: Vec::new(),
            runs: Vec::new(),
            direction: Direction::Same,
            psi_rms,
        }
    }

    /// The score grows with the chain and falls with the residual, and no residual lifts a
    /// match above a longer chain.
    #[test]
    fn score_is_monotone_in_chain_length_and_residual() {
        let s = |n, r| word_match(n, r).score();
        assert!(s(7, 0.0) > s(7, 0.01) && s(7, 0.01) > s(7, 0.04));
        assert!(s(7, 0.04) > s(7, f64::INFINITY));
        assert!(s(8, f64::INFINITY) > s(7, 0.0));
        assert!((s(6, PSI_RMS_SCALE) - 6.25).abs() < 1e-12);
        assert_eq!(s(6, f64::INFINITY), 6.0);
    }
}
