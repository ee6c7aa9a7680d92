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

use super::words::WordId;

/// The candidates among `occurrences` (oldest first): the last `limit` words that satisfy
/// `matches`, oldest first, or every such word when `limit` is 0.
pub(super) fn recent_candidates(
    occurrences: &[WordId],
    limit: usize,
    mut matches: impl FnMut(WordId) -> bool,
) -> Vec<WordId> {
    if limit == 0 {
        return occurrences
            .iter()
            .copied()
            .filter(|&p| matches(p))
            .collect();
    }
    let mut out: Vec<WordId> = occurrences
        .iter()
        .rev()
        .copied()
        .filter(|&p| matches(p))
        .take(limit)
        .collect();
    out.reverse();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_most_recent_matching_words_in_order() {
        let occ: Vec<WordId> = (0..10).collect();
        let even = |p: WordId| p.is_multiple_of(2);
        assert_eq!(recent_candidates(&occ, 0, even), vec![0, 2, 4, 6, 8]);
        assert_eq!(recent_candidates(&occ, 2, even), vec![6, 8]);
        assert_eq!(recent_candidates(&occ, 9, even), vec![0, 2, 4, 6, 8]);
    }
}
