//! Verification of a candidate n-gram before it is reported (`[recognizer.verify]`).
//!
//! **Verification** (`enabled`). A candidate n-gram is accepted only if it is consistent: the
//! odometric travel and turn between its words agree on both sides (`verify_travel_*`,
//! `verify_turn_deg`), the RMS Ψ difference of its aligned pairs is at most
//! `verify_max_psi_rms`, and the free space lies on the same side of the path at both visits:
//! the RMS difference of the observations' `lateral_moment` is at most `verify_max_lateral_rms`
//! (`reverse_verify_max_lateral_rms` read backwards, where the past side's moment is negated,
//! since driven the other way left is right). Ψ and the words are blind to a reflection: it
//! negates the turns and reading backwards negates them again, so a corridor read backwards
//! matched its mirror image (scenario A, which has no opposite revisit, got thousands of false
//! opposite pairs); the side of the free space is what a reflection changes. Where a place is
//! symmetric across the path the moment is near zero and decides nothing; the travel rule for
//! chains read backwards (`reverse_ngram_travel_m`, 30 m) adds the context those need. A
//! straight corridor is the worst case: read backwards it matches itself mirrored about any
//! line across it where its doors and recesses happen to be symmetric (the institute floor's
//! 40 m north corridor, about its middle alcove, in scenarios A, B and C), and its turns cannot
//! help (there are none). So an n-gram read backwards must turn: the current side's heading must
//! change by at least `reverse_min_turn_deg` from its first word. Within a stretch whose ends
//! both turn, reading backwards negates the turns and breaks such false chains at the corners.
//! Before any of that, an n-gram driven the same way whose current words take two density
//! classes only waits for `two_class_extra_ngram` more words of chain
//! ([`WordMatcher::too_few_classes`]): its classes alternate, so they add nothing after its
//! first word, and what is left (sizes, turns) repeats along a corridor of regularly spaced
//! doors and between corners that turn alike (scenario A with weaving laps: 7 of 8 false
//! chains, seeds 1–5).
//! The turn is judged over the n-gram as a whole (`verify_turn_outliers`, not in the paper): a
//! real robot cuts corners and turns on the spot, so a word boundary falls inside a corner on
//! one visit and after it on the other, and that one word start's heading is off by the corner
//! while the next agrees again. So each word start's heading offset between the two sides must
//! lie within `verify_turn_deg` of the offsets' median, except at a few word starts inside the
//! n-gram; at its first and newest word starts the offset must agree (one side turning there
//! alone is where two paths meet, or where the robot left the revisit). An n-gram that extends
//! a reported chain begins inside that chain, not where two paths met: its first word start
//! was an inner one of the n-gram verified a word earlier, and there, when it disagreed, the
//! word start before it agreed with the rest; so there it counts as an inner word start (Intel,
//! noise seed 4: a corner cut at such a word start ended a chain read backwards, and the last
//! 6 m of its revisit went unrecognized). The travel can be
//! judged likewise (`verify_travel_outliers`, off by default): a word start that moved on one
//! pass is passed over, and the next one is measured from the last that agreed.
//! Read backwards on a sparse log, the travel between two word starts may differ by
//! `reverse_sampling_slack` of the sampling slack of the words spanning it
//! ([`super::words::Word::sampling_slack_obs`]) more: their sizes, which that travel is, match
//! within as much, since a class boundary a long scan step crossed lies somewhere along it.
//! Read backwards, the oldest end of a chain can lie where the robot came into the revisit
//! from another corridor: its oldest word starts then turn (or travel) on one side only and the
//! n-gram fails, although its newer words are the place. Chains read backwards are a few long
//! words, so the next word comes too late to leave the junction behind (seattle, noise seeds
//! 1, 2, 3 and 5: 6-word chains whose two oldest word starts turn on one side only; their
//! newest 4 words, over 25 m, pass).
//! So such an n-gram is verified again without its oldest word pair, and again, while what is
//! left is still a short n-gram (`reverse_trim_to_short`; `reverse_short_ngram_words` words
//! spanning `reverse_short_ngram_travel_m`), held to the short rule's checks, its anchors taken
//! anew; the first that passes is the match, and the candidate counts as turned down (with the
//! whole n-gram's reason) only if none does.
//! The first 10,000 candidates verification turns down are kept as one observation pair each
//! (`MatchDiagnostics::rejected`), so that the harness, which knows the truth, can tell whether
//! the checks turned down look-alikes or true revisits.
//!

use super::align::{PastSide, Placement};
use super::diagnostics::Rejection;
use super::matcher::{Scratch, WordMatcher};
use super::types::Direction;
use super::words::WordId;
use crate::geom::wrap_angle;

/// Word starts whose heading offsets `verify_turn_outliers` judges together at most (τ at four
/// levels is 15, read backwards 2 more).
const TURN_OFFSETS: usize = 32;

impl WordMatcher {
    /// Why the n-gram of `word_pairs` (oldest first) is inconsistent, if it is: odometric travel
    /// and turn between its words, from consecutive words and from its first word, must agree on
    /// both sides (but for `verify_travel_outliers` and `verify_turn_outliers` word starts); the
    /// Ψ residual of its aligned pairs must be small (`extends_reported`: the n-gram extends a
    /// chain verified and reported a word earlier; then only its newest pair's residual is
    /// measured, and its first word start counts as an inner one for the turn). The placements it makes (of the pairs
    /// whose residual it measured, oldest first) are appended to `placed`.
    /// Read backwards (`dir` Opposite), a past word starts at its last observation and travel
    /// runs the other way, so the past side's travel and turn between two words are negated.
    /// An n-gram the short rule made (`short`, `reverse_short_ngram_words`) is held to
    /// `reverse_short_max_lateral_rms` and to the per-word turn limit (with four words, one
    /// word start passed over is half of its interior: weaving A seed 2 got a false chain read
    /// backwards that way).
    pub(super) fn verify(
        &self,
        word_pairs: &[(WordId, WordId)],
        dir: Direction,
        anchors: &[i64],
        (extends_reported, short): (bool, bool),
        placed: &mut Vec<Option<Placement>>,
    ) -> Option<Rejection> {
        let start = |w: WordId| self.reading_start(w, Direction::Same);
        let past_start = |w: WordId| self.reading_start(w, dir);
        // Read backwards on a sparse log, the travel between two word starts is known as well as
        // the sizes of the words spanning it (`reverse_sampling_slack`).
        let sampling = |w: (WordId, WordId)| {
            let m = &self.matcher_opts;
            let obs = self.word(w.0).sampling_slack_obs + self.word(w.1).sampling_slack_obs;
            m.travel_sampling_slack_m(obs, self.spacing_m, dir)
        };
        let first_sampling_m = sampling(word_pairs[0]);
        let ok_travel = |a: f64, b: f64, sampling_m: f64| {
            (a - b).abs()
                <= self.verify_opts.verify_travel_ratio * a.abs().max(b.abs())
                    + self.verify_opts.verify_travel_slack_m
                    + sampling_m
        };
        let turn_tol = self.verify_opts.verify_turn_deg.to_radians();
        let (mut cum_c, mut cum_p) = ((0.0, 0.0), (0.0, 0.0));
        let mut turned: f64 = 0.0;
        // The heading offsets per word start, when the turn is judged over the n-gram as a
        // whole (`verify_turn_outliers`); longer n-grams than the buffer use the per-word limit.
        let mut offsets = [0.0; TURN_OFFSETS];
        let robust =
            self.verify_opts.verify_turn_outliers > 0 && !short && word_pairs.len() <= TURN_OFFSETS;
        // Travel at the last word start that agreed (current, past), and the interior word
        // starts passed over so far (`verify_travel_outliers`).
        let (mut agreed, mut passed_over) = ((0.0, 0.0), 0);
        for (i, w) in word_pairs.windows(2).enumerate() {
            let (c0, c1) = (start(w[0].0), start(w[1].0));
            let (p0, p1) = (past_start(w[0].1), past_start(w[1].1));
            let dc = (c1.0 - c0.0, wrap_angle(c1.1 - c0.1));
            let dp = (p1.0 - p0.0, wrap_angle(p1.1 - p0.1));
            cum_c = (cum_c.0 + dc.0, cum_c.1 + dc.1);
            cum_p = (cum_p.0 + dp.0, cum_p.1 + dp.1);
            let interior = i + 2 < word_pairs.len();
            let step_sampling_m = sampling(w[0]);
            if ok_travel(cum_c.0 - agreed.0, cum_p.0 - agreed.1, step_sampling_m)
                && ok_travel(cum_c.0, cum_p.0, first_sampling_m + step_sampling_m)
            {
                agreed = (cum_c.0, cum_p.0);
            } else if interior && passed_over < self.verify_opts.verify_travel_outliers {
                passed_over += 1;
            } else {
                return Some(Rejection::Travel);
            }
            if robust {
                offsets[i + 1] = cum_c.1 - cum_p.1;
            } else if wrap_angle(dc.1 - dp.1).abs() > turn_tol
                || (cum_c.1 - cum_p.1).abs() > turn_tol
            {
                return Some(Rejection::Turn);
            }
            turned = turned.max(cum_c.1.abs());
        }
        let outliers = self.verify_opts.verify_turn_outliers;
        let offsets = &mut offsets[..word_pairs.len()];
        if robust && turn_offsets_disagree(offsets, turn_tol, outliers, extends_reported) {
            return Some(Rejection::Turn);
        }
        if dir == Direction::Opposite && turned < self.verify_opts.reverse_min_turn_deg.to_radians()
        {
            return Some(Rejection::Straight);
        }
        let (mut sum, mut lateral, mut count) = (0.0, 0.0, 0usize);
        let newest = word_pairs.len().saturating_sub(1);
        let from = if extends_reported { newest } else { 0 };
        for (&(c, p), &anchor) in word_pairs.iter().zip(anchors).skip(from) {
            let placement = self.placement(c, p, dir, anchor);
            if let Some(w) = &placement {
                sum += w.cost * w.count() as f64;
                lateral += self.lateral_squared_error(c, p, dir, w);
                count += w.count();
            }
            placed.push(placement);
        }
        let mean = |s: f64| {
            if count == 0 {
                f64::INFINITY
            } else {
                (s / count as f64).sqrt()
            }
        };
        if mean(sum) > self.verify_opts.verify_max_psi_rms {
            Some(Rejection::Density)
        } else if mean(lateral) > self.lateral_bound(short, dir) {
            Some(Rejection::Sides)
        } else {
            None
        }
    }

    /// [`verify`](Self::verify) of the n-gram of `scr`'s word pairs `pairs`, with its anchors;
    /// read backwards, one that fails the travel or turn check is tried again without its
    /// oldest word pair while what is left is still a short n-gram (`reverse_trim_to_short`),
    /// its anchors taken anew and its densities checked in full (also when it extends a
    /// reported chain: the junction stays in the n-gram of every later word until it slides
    /// out), and `pairs` then starts at the one that passed. `None` when one
    /// passed, else the whole n-gram's rejection; `scr.placed` holds the placements of the one
    /// that passed (from `placed_from`).
    pub(super) fn verify_or_trim(
        &self,
        pairs: &mut std::ops::Range<usize>,
        dir: Direction,
        (extends_reported, short): (bool, bool),
        placed_from: usize,
        scr: &mut Scratch,
    ) -> Option<Rejection> {
        let whole = pairs.clone();
        let reason = self.verify(
            &scr.word_pairs[whole.clone()],
            dir,
            &scr.anchors[whole.clone()],
            (extends_reported, short),
            &mut scr.placed,
        )?;
        let Some((words, short_m)) = self.matcher_opts.short_opposite_rule() else {
            return Some(reason);
        };
        if !(self.verify_opts.reverse_trim_to_short
            && dir == Direction::Opposite
            && matches!(reason, Rejection::Travel | Rejection::Turn))
        {
            return Some(reason);
        }
        let end_m = self.word(scr.word_pairs[whole.end - 1].0).end_travel_m;
        let mut anchors = Vec::new();
        for from in whole.start + 1..=whole.end.saturating_sub(words) {
            if end_m - self.word(scr.word_pairs[from].0).start_travel_m < short_m {
                break;
            }
            scr.placed.truncate(placed_from);
            let trimmed = from..whole.end;
            anchors.clear();
            self.chain_anchors(
                &scr.word_pairs[trimmed.clone()],
                dir,
                &mut scr.offsets,
                &mut anchors,
            );
            match self.verify(
                &scr.word_pairs[trimmed.clone()],
                dir,
                &anchors,
                (false, true),
                &mut scr.placed,
            ) {
                None => {
                    scr.anchors[trimmed.clone()].copy_from_slice(&anchors);
                    *pairs = trimmed;
                    return None;
                }
                Some(Rejection::Travel | Rejection::Turn) => {}
                Some(_) => break,
            }
        }
        scr.placed.truncate(placed_from);
        Some(reason)
    }

    /// The sides bound for an n-gram read in direction `dir`: tighter for one the short rule
    /// made (`reverse_short_max_lateral_rms`).
    fn lateral_bound(&self, short: bool, dir: Direction) -> f64 {
        if short {
            self.verify_opts.reverse_short_max_lateral_rms
        } else {
            self.verify_opts.max_lateral_rms(dir)
        }
    }

    /// Whether the n-gram of `word_pairs` (oldest first), whose chain is `chain_len` words
    /// long, is not yet a candidate: driven the same way, its current words (the classes the
    /// matching compared, whatever their level) take fewer than three density classes, and its
    /// chain is shorter than the n-gram plus `two_class_extra_ngram` words.
    pub(super) fn too_few_classes(
        &self,
        word_pairs: &[(WordId, WordId)],
        dir: Direction,
        chain_len: usize,
    ) -> bool {
        let extra = self.matcher_opts.two_class_extra_ngram;
        if extra == 0 || dir == Direction::Opposite || chain_len >= word_pairs.len() + extra {
            return false;
        }
        let mut seen: [Option<u8>; 2] = [None; 2];
        for &(c, _) in word_pairs {
            let class = self.word(c).class;
            match seen {
                [Some(a), Some(b)] if class != a && class != b => return false,
                [None, _] => seen[0] = Some(class),
                [Some(a), None] if class != a => seen[1] = Some(class),
                _ => {}
            }
        }
        true
    }

    /// Σ over the pairs of placement `w` of the squared difference of the observations'
    /// `lateral_moment`, the past side's negated when read backwards (its left is then our right).
    pub(super) fn lateral_squared_error(
        &self,
        c: WordId,
        p: WordId,
        dir: Direction,
        w: &Placement,
    ) -> f64 {
        let lateral = self.words.lateral_moments();
        let s2 = self.word(c).first_obs as i64;
        let past = PastSide::of(self.word(p), dir);
        let sign = past.step as f64;
        let sq = |(q, p): (&f64, &f64)| {
            let d = q - sign * p;
            d * d
        };
        if w.count() == 0 {
            return std::iter::empty::<f64>().sum();
        }
        // Both sides as slices (no index arithmetic per pair), summed in the same order.
        let cur = &lateral[(s2 + w.a + w.r.start) as usize..(s2 + w.a + w.r.end) as usize];
        let first = past.index(w.b + w.r.start);
        if past.step > 0 {
            cur.iter()
                .zip(&lateral[first..first + cur.len()])
                .map(sq)
                .sum()
        } else {
            let back = lateral[first + 1 - cur.len()..=first].iter().rev();
            cur.iter().zip(back).map(sq).sum()
        }
    }

    /// Where word `w` begins when read in direction `dir`: (travel, odometric heading) of its
    /// first observation, or read backwards, of its last one with travel negated (so that
    /// differences between words read backwards come out as travelled that way).
    pub(super) fn reading_start(&self, w: WordId, dir: Direction) -> (f64, f64) {
        self.reading_starts[w as usize][dir as usize]
    }

    /// [`reading_start`](Self::reading_start), from the word's observations.
    pub(super) fn measure_reading_start(&self, w: WordId, dir: Direction) -> (f64, f64) {
        let obs = self.words.observations();
        let w = self.word(w);
        match dir {
            Direction::Same => (w.start_travel_m, obs[w.first_obs].odom_pose.0.theta),
            Direction::Opposite => (
                -w.end_travel_m,
                obs[w.first_obs + w.size - 1].odom_pose.0.theta,
            ),
        }
    }
}

/// Whether the heading offsets between the two sides at an n-gram's word starts (`offsets`,
/// oldest first, the first 0; reordered here) disagree: more than `outliers` of them lie over
/// `tol` (radians) from their median, or the newest does, or the oldest does unless the n-gram
/// `extends_reported` (then its oldest word start lies inside a chain verified a word earlier,
/// and counts like any inner one).
fn turn_offsets_disagree(
    offsets: &mut [f64],
    tol: f64,
    outliers: usize,
    extends_reported: bool,
) -> bool {
    let (Some(&oldest), Some(&newest)) = (offsets.first(), offsets.last()) else {
        return false;
    };
    offsets.sort_unstable_by(f64::total_cmp);
    let n = offsets.len();
    let median = (offsets[(n - 1) / 2] + offsets[n / 2]) / 2.0;
    let off = |e: f64| (e - median).abs() > tol;
    let outside = offsets.iter().filter(|&&e| off(e)).count();
    (off(oldest) && !extends_reported) || off(newest) || outside > outliers
}

#[cfg(test)]
mod tests {
    use super::turn_offsets_disagree;

    fn disagree(offsets_deg: &[f64], extends_reported: bool) -> bool {
        let mut rad: Vec<f64> = offsets_deg.iter().map(|d| d.to_radians()).collect();
        turn_offsets_disagree(&mut rad, 30f64.to_radians(), 1, extends_reported)
    }

    /// One word start off by a corner cut: inside the n-gram it passes; as the first word start
    /// of a new chain (two paths meeting) it does not, but as the first of an n-gram that
    /// extends a reported chain (Intel, noise seed 4: offsets 0, 75, 77, 77, 73, 68, 66, 74°) it
    /// does; the newest never passes, and two off never do.
    #[test]
    fn a_corner_cut_at_the_first_word_start_passes_only_inside_a_chain() {
        let inner = [0.0, 2.0, 75.0, 1.0, -3.0, 4.0];
        assert!(!disagree(&inner, false));
        let first = [0.0, 75.0, 77.0, 77.0, 73.0, 68.0, 66.0, 74.0];
        assert!(disagree(&first, false), "a new chain's first word start");
        assert!(!disagree(&first, true), "inside a reported chain");
        let newest = [0.0, 1.0, 2.0, -2.0, -8.0, -10.0, -2.0, 78.0];
        assert!(disagree(&newest, false) && disagree(&newest, true));
        let two = [0.0, 75.0, 77.0, 10.0, 73.0, 68.0, 66.0, 74.0];
        assert!(disagree(&two, true), "the first and another inner one");
    }
}
