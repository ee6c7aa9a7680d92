//! Which past words a closing word is matched against: the bound that keeps the work per lap
//! flat however long the history.
//!
//! **Rule.** With `max_candidates` = k > 0, a word is matched only against the k most recent
//! earlier words of its class that match it (size and angle) and end beyond the candidate gap;
//! the search walks the class's occurrence list newest first and stops at the k-th. A place
//! driven past a thousand times is thus matched to its k most recent look-alikes, not to every
//! one: memo entries, chains, aligned pairs and the words walked per closing word are at most k
//! (plus the non-matching words of its class met on the way back), the same at lap 1000 as at
//! lap 10 once k candidates exist. Chains stay consistent: the predecessors of a current word
//! were bounded the same way, so they hold the same recent laps. With k = 0 every earlier
//! matching word is a candidate (the paper's search).

use super::words::{Word, WordId};

/// A word in its class's occurrence list: what the candidate search reads of it (the
/// syllables `syllables_match` compares and where it ends), kept beside its id so that walking
/// a class's occurrences over many laps reads a few bytes per word, not each whole [`Word`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Occurrence {
    pub(super) id: WordId,
    /// S, observations.
    pub(super) size: usize,
    /// A, degrees.
    pub(super) angle_deg: f64,
    /// A's slack, degrees ([`Word::angle_slack_deg`]).
    pub(super) angle_slack_deg: f64,
    /// S's slack, observations ([`Word::sampling_slack_obs`]; f32 fills the id's padding, so
    /// an occurrence stays 40 bytes).
    pub(super) sampling_slack_obs: f32,
    /// Travel at its last observation, metres.
    pub(super) end_travel_m: f64,
}

// The candidate walk reads a class's occurrences over many laps: keep them small.
const _: () = assert!(std::mem::size_of::<Occurrence>() == 40);

impl Occurrence {
    /// The sampling slack of this word and `w` together, observations (what
    /// [`MatcherOptions::sizes_match`](super::options::MatcherOptions::sizes_match) reads).
    pub(super) fn sampling_slack_with(&self, w: &Word) -> f64 {
        w.sampling_slack_obs + f64::from(self.sampling_slack_obs)
    }

    pub(super) fn of(id: WordId, w: &Word) -> Self {
        Occurrence {
            id,
            size: w.size,
            angle_deg: w.angle_deg,
            angle_slack_deg: w.angle_slack_deg,
            sampling_slack_obs: w.sampling_slack_obs as f32,
            end_travel_m: w.end_travel_m,
        }
    }
}

/// Appends to `out` the candidates among `occurrences` (oldest first): the ids of the last
/// `limit` that satisfy `matches`, oldest first, or of every such one when `limit` is 0. The
/// caller keeps `out` between words, so the search allocates nothing once it is large enough.
pub(super) fn recent_candidates(
    occurrences: &[Occurrence],
    limit: usize,
    mut matches: impl FnMut(&Occurrence) -> bool,
    out: &mut Vec<WordId>,
) {
    let from = out.len();
    if limit == 0 {
        out.extend(occurrences.iter().filter(|o| matches(o)).map(|o| o.id));
        return;
    }
    out.extend(
        occurrences
            .iter()
            .rev()
            .filter(|o| matches(o))
            .take(limit)
            .map(|o| o.id),
    );
    out[from..].reverse();
}

#[cfg(test)]
mod tests {
    use super::*;

    use proptest::prelude::*;

    fn occurrence(id: WordId) -> Occurrence {
        Occurrence {
            id,
            size: 5,
            angle_deg: 0.0,
            angle_slack_deg: 0.0,
            sampling_slack_obs: 0.0,
            end_travel_m: id as f64,
        }
    }

    fn candidates(occ: &[Occurrence], limit: usize, f: impl Fn(WordId) -> bool) -> Vec<WordId> {
        let mut out = vec![99];
        recent_candidates(occ, limit, |o| f(o.id), &mut out);
        assert_eq!(out.remove(0), 99, "what `out` held stays");
        out
    }

    #[test]
    fn keeps_the_most_recent_matching_words_in_order() {
        let occ: Vec<Occurrence> = (0..10).map(occurrence).collect();
        let even = |p: WordId| p.is_multiple_of(2);
        assert_eq!(candidates(&occ, 0, even), vec![0, 2, 4, 6, 8]);
        assert_eq!(candidates(&occ, 2, even), vec![6, 8]);
        assert_eq!(candidates(&occ, 9, even), vec![0, 2, 4, 6, 8]);
    }

    proptest! {
        /// The search appends exactly what the plain rule lists: every matching word in order,
        /// or the last `limit` of them in order.
        #[test]
        fn appends_what_the_plain_rule_lists(
            ids in proptest::collection::vec(0u32..1000, 0..60),
            modulus in 1u32..5,
            limit in 0usize..8,
        ) {
            let occ: Vec<Occurrence> = ids.iter().map(|&i| occurrence(i)).collect();
            let matches = |p: WordId| p.is_multiple_of(modulus);
            let all: Vec<WordId> = ids.iter().copied().filter(|&p| matches(p)).collect();
            let plain = if limit == 0 {
                all
            } else {
                all[all.len().saturating_sub(limit)..].to_vec()
            };
            prop_assert_eq!(candidates(&occ, limit, matches), plain);
        }
    }
}
