//! Chain matching: the memo of matching word pairs and the n-gram chains through it (see the
//! `matcher` module doc for the whole back end).
//!
//! **Reverse direction** (paper §VI, future work; `reverse = true`). A revisit driven the
//! other way sees the past words in reverse order, each turned the other way: read backwards, a
//! word keeps its class and size and its angle syllable is negated. Each current word is also
//! matched against the past words read backwards, and chains grow through successors: (cᵢ, pⱼ)
//! extends (cᵢ₋₁, pⱼ₊₁) where pⱼ₊₁ is a word whose predecessor is pⱼ. This is a second memo
//! with the same search; its matches carry `Direction::Opposite`, are verified with the past
//! side's travel and turn measured backwards, and are aligned on the past word's Ψ read
//! backwards (so past ids decrease as query ids increase). On a sparse log the sizes read
//! backwards also match within `reverse_sampling_slack` of the words' sampling slack (the scan
//! steps at their ends: `MatcherOptions::sizes_match`).
//!
//! **Substitutions** (`substitutions`, on by default). In sparse logs, and with turns between
//! scans, a word's turn angle (and a little its size) moves between visits; the word then fails
//! its syllables and the chain breaks. With substitutions, (c, p) may also extend a chain ending
//! one level-0 word further back on both sides when the two skipped words have the same class
//! and sizes within `substitution_size_ratio`; the skipped pair does not count towards the
//! n-gram's size, and verification still checks the whole n-gram. Bridging any same-class word
//! (no size bound) let unrelated words through and cost scenario A precision.
//!
//! **Reporting.** For configuration k with minimum size τₖ, a pair (c, p) whose chain reaches τₖ
//! is reported when the τₖ-gram ending at it satisfies the gap: its first current word begins at
//! least `candidate_gap_m` after p ends. Each word pair is reported at most once per configuration: the
//! first time a chain reaches τₖ the match carries its τₖ word pairs; when a later word extends a
//! reported chain, the match carries only the new pair (`ngram_len` still gives the chain
//! length). The result of an L-level run is the union of the matches with `levels` ≤ L. With
//! `ngram_travel_m` > 0 (same direction) or `reverse_ngram_travel_m` > 0 (read backwards) a chain of at least `ngram_travel_min_words` pairs (read backwards, plus
//! `reverse_extra_ngram`) whose current side spans that much travel is reported as if it had
//! reached τₖ. Read backwards, words split at other places than they did driving the other way
//! (the laser looks ahead), so opposite chains are runs of a few long words.
//!

use super::index::{Occurrence, recent_candidates};
use super::matcher::{Scratch, WordMatcher};
use super::types::Direction;
use super::words::{MAX_LEVELS, Word, WordId};

#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    pub(super) past: WordId,
    /// Longest chain per level configuration (0 when a word's level is outside it).
    pub(super) len: [u16; MAX_LEVELS],
    /// Per configuration: the current word of the best chain's previous pair (a predecessor of
    /// this pair's current word, or across a substitution one word further back).
    pub(super) back_word: [WordId; MAX_LEVELS],
    /// Per configuration: index of the best chain's previous pair in that word's memo.
    pub(super) back_idx: [u32; MAX_LEVELS],
    /// Bit k: reported in configuration k.
    pub(super) reported: u8,
}

impl WordMatcher {
    /// Whether current word `a` matches past word `b` (an entry of its class's occurrence list)
    /// read in direction `dir` (backwards, b's angle syllable is negated; class and size do not
    /// change, though sizes match within `reverse_size_tolerance_observations` more).
    pub(super) fn syllables_match(&self, a: &Word, b: &Occurrence, dir: Direction) -> bool {
        self.sizes_match(a, b, dir) && self.angles_match(a, b, dir)
    }

    /// The size syllables of [`syllables_match`](Self::syllables_match)
    /// ([`MatcherOptions::sizes_match`](super::options::MatcherOptions::sizes_match)).
    fn sizes_match(&self, a: &Word, b: &Occurrence, dir: Direction) -> bool {
        let sampling = b.sampling_slack_with(a);
        self.matcher_opts.sizes_match(a.size, b.size, sampling, dir)
    }

    /// The angle syllables of [`syllables_match`](Self::syllables_match), read in direction `dir`.
    fn angles_match(&self, a: &Word, b: &Occurrence, dir: Direction) -> bool {
        let b_angle = match dir {
            Direction::Same => b.angle_deg,
            Direction::Opposite => -b.angle_deg,
        };
        // `%` is a software fmod; below 360 it returns its operand unchanged.
        let mut d = (a.angle_deg - b_angle).abs();
        if d >= 360.0 {
            d %= 360.0;
        }
        if d > 180.0 {
            d = 360.0 - d;
        }
        let tol = self.matcher_opts.angle_tolerance_deg;
        let slack = if self.matcher_opts.angle_slack {
            (a.angle_slack_deg + b.angle_slack_deg).min(tol / 2.0)
        } else {
            0.0
        };
        d <= tol + slack + 1e-9
    }

    /// Records `c` as the successor of each of its predecessors.
    pub(super) fn link_successors(&mut self, c: WordId) {
        self.successors.resize(c as usize + 1, Vec::new());
        for &p in self.words.word(c).pred_ids() {
            self.successors[p as usize].push(c);
        }
    }

    /// The words a chain through past word `p` continues from, in direction `dir`: its
    /// predecessors, or (read backwards) its successors.
    pub(super) fn past_links(&self, p: WordId, dir: Direction) -> &[WordId] {
        match dir {
            Direction::Same => self.word(p).pred_ids(),
            Direction::Opposite => &self.successors[p as usize],
        }
    }

    /// Lists the candidates of word `c` (`index.rs`) in `candidates`, per direction (read
    /// backwards only with `reverse`): the words of its class that end `candidate_gap_m` before
    /// it begins and match it. When every match is a candidate, one walk over the class serves
    /// both directions.
    pub(super) fn find_candidates(&mut self, c: WordId) {
        let mut found = std::mem::take(&mut self.candidates);
        found.iter_mut().for_each(Vec::clear);
        let cw = self.word(c);
        let limit = cw.start_travel_m - self.matcher_opts.candidate_gap_m;
        let occ = &self.occurrences[cw.class as usize];
        let occ = &occ[..occ.partition_point(|p| p.end_travel_m <= limit + 1e-9)];
        let max = self.matcher_opts.max_candidates;
        if max == 0 && self.matcher_opts.reverse {
            let [same, opposite] = &mut found;
            let m = &self.matcher_opts;
            for p in occ {
                let over = m.size_excess(cw.size, p.size);
                let sampling = p.sampling_slack_with(cw);
                if m.size_excess_matches(over, sampling, Direction::Same)
                    && self.angles_match(cw, p, Direction::Same)
                {
                    same.push(p.id);
                }
                if m.size_excess_matches(over, sampling, Direction::Opposite)
                    && self.angles_match(cw, p, Direction::Opposite)
                {
                    opposite.push(p.id);
                }
            }
        } else {
            let dirs = if self.matcher_opts.reverse {
                &Direction::BOTH[..]
            } else {
                &[Direction::Same]
            };
            for &dir in dirs {
                let matches = |p: &Occurrence| self.syllables_match(cw, p, dir);
                recent_candidates(occ, max, matches, &mut found[dir as usize]);
            }
        }
        self.candidates = found;
    }

    /// Fills the memo of word `c` in direction `dir`: one entry per matching past word (its
    /// candidates, listed by [`find_candidates`](Self::find_candidates)).
    pub(super) fn memoise(&mut self, c: WordId, dir: Direction) {
        let d = dir as usize;
        debug_assert_eq!(self.memo[d].len(), c as usize);
        let stamp = self.fill_lookups(c, d);
        let cw = self.word(c).clone();
        let c_preds = cw.pred_ids();

        let levels = self.levels;
        let candidates = std::mem::take(&mut self.candidates[d]);
        let mut entries = Vec::with_capacity(candidates.len());
        for &p in &candidates {
            let pw = self.word(p);
            let top = cw.level.max(pw.level);
            let mut len = [0u16; MAX_LEVELS];
            let mut back_word = [0 as WordId; MAX_LEVELS];
            let mut back_idx = [0u32; MAX_LEVELS];
            for l in len.iter_mut().take(levels).skip(top) {
                *l = 1;
            }
            for &pp in self.past_links(p, dir) {
                for (ci, &cp) in c_preds.iter().enumerate() {
                    let (s, idx) = self.lookup[ci][pp as usize];
                    if s != stamp {
                        continue;
                    }
                    let e = &self.memo[d][cp as usize][idx as usize];
                    for (k, (l, &el)) in len
                        .iter_mut()
                        .zip(&e.len)
                        .enumerate()
                        .take(levels)
                        .skip(top)
                    {
                        if el > 0 && el >= *l {
                            *l = el.saturating_add(1);
                            back_word[k] = cp;
                            back_idx[k] = idx;
                        }
                    }
                }
            }
            if self.matcher_opts.substitutions {
                self.bridge_substitution(&cw, p, dir, top, &mut len, &mut back_word, &mut back_idx);
            }
            for (m, &l) in self.longest.iter_mut().zip(&len) {
                *m = (*m).max(l);
            }
            entries.push(Entry {
                past: p,
                len,
                back_word,
                back_idx,
                reported: 0,
            });
        }
        self.memo[d].push(entries);
        self.candidates[d] = candidates;
    }

    /// Fills the lookup tables for word `c` in direction `d` under a new stamp (returned): slot i
    /// maps each past word of the memo of c's i-th predecessor to its entry, slot
    /// `MAX_LEVELS` + i the same for the i-th predecessor of c's level-0 predecessor (the pairs
    /// a substitution bridges to).
    pub(super) fn fill_lookups(&mut self, c: WordId, d: usize) -> u32 {
        let n_words = self.words.all_words().len();
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            for l in &mut self.lookup {
                l.fill((0, 0));
            }
            self.stamp = 1;
        }
        let stamp = self.stamp;
        let skipped = self
            .matcher_opts
            .substitutions
            .then(|| self.level0_link(c, Direction::Same));
        let bridged = skipped
            .flatten()
            .map_or(&[][..], |s| self.words.word(s).pred_ids());
        let c_preds = self.words.word(c).pred_ids();
        for (slot, &cp) in c_preds
            .iter()
            .enumerate()
            .chain(bridged.iter().enumerate().map(|(i, w)| (MAX_LEVELS + i, w)))
        {
            debug_assert!(
                cp as usize >= self.memo_forgotten,
                "memo of word {cp} read once freed"
            );
            let table = &mut self.lookup[slot];
            if table.len() < n_words {
                table.resize(n_words, (0, 0));
            }
            for (idx, e) in self.memo[d][cp as usize].iter().enumerate() {
                table[e.past as usize] = (stamp, idx as u32);
            }
        }
        stamp
    }

    /// The level-0 link of `w` read in direction `dir` (its level-0 predecessor, or read
    /// backwards, its level-0 successor): the word a substitution skips.
    pub(super) fn level0_link(&self, w: WordId, dir: Direction) -> Option<WordId> {
        let links: &[WordId] = match dir {
            Direction::Same => self.word(w).pred_ids(),
            Direction::Opposite => &self.successors[w as usize],
        };
        links.iter().copied().find(|&l| self.word(l).level == 0)
    }

    /// Chains across one substituted word (`substitutions`): (c, p) may extend a pair (c'', p'')
    /// where c'' is a predecessor of c's level-0 predecessor and p'' a link of p's level-0 link,
    /// when those two skipped words have the same class (their size or angle syllable did not
    /// match). The bridged pair does not count in the chain's length; direct links win ties.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn bridge_substitution(
        &self,
        cw: &Word,
        p: WordId,
        dir: Direction,
        top: usize,
        len: &mut [u16; MAX_LEVELS],
        back_word: &mut [WordId; MAX_LEVELS],
        back_idx: &mut [u32; MAX_LEVELS],
    ) {
        let d = dir as usize;
        let levels = self.levels;
        let Some(c_skip) = cw
            .pred_ids()
            .iter()
            .copied()
            .find(|&l| self.word(l).level == 0)
        else {
            return;
        };
        let Some(p_skip) = self.level0_link(p, dir) else {
            return;
        };
        if self.word(c_skip).class != self.word(p_skip).class {
            return;
        }
        let (a, b) = (self.word(c_skip).size as f64, self.word(p_skip).size as f64);
        if (a - b).abs() > self.matcher_opts.substitution_size_ratio * a.max(b) + 1e-9 {
            return;
        }
        // The memo entries of c_skip's predecessors, by past word: lookup slots MAX_LEVELS.. (see
        // `memoise`).
        for (slot, &c2) in self.word(c_skip).pred_ids().iter().enumerate() {
            debug_assert!(
                c2 as usize >= self.memo_forgotten,
                "memo of word {c2} read once freed"
            );
            let memo = &self.memo[d][c2 as usize];
            if memo.is_empty() {
                continue;
            }
            for &p2 in self.past_links(p_skip, dir) {
                let (s, idx) = self.lookup[MAX_LEVELS + slot][p2 as usize];
                if s != self.stamp {
                    continue;
                }
                let e = &memo[idx as usize];
                for k in top..levels {
                    let el = e.len[k];
                    if el > 0 && el + 1 > len[k] {
                        len[k] = el + 1;
                        back_word[k] = c2;
                        back_idx[k] = idx;
                    }
                }
            }
        }
    }

    /// The pair before an entry's pair on the best chain of configuration k.
    pub(super) fn step_back(entry: &Entry, k: usize) -> Option<(WordId, usize)> {
        if entry.len[k] <= 1 {
            return None;
        }
        Some((entry.back_word[k], entry.back_idx[k] as usize))
    }

    /// The shortest chain (in word pairs) configuration k reports in direction `dir`: τ, or
    /// with the travel rule (`ngram_travel_m`, `reverse_ngram_travel_m`) its minimum words if
    /// fewer, or read backwards the short rule's (`reverse_short_ngram_words`) if fewer still.
    /// [`tau_chain`](Self::tau_chain) finds nothing for a shorter chain.
    pub(super) fn min_chain_len(&self, k: usize, dir: Direction) -> usize {
        let (tau, min_words) = self.tau_and_min_words(k, dir);
        let mut len = if self.matcher_opts.travel_rule_m(dir) > 0.0 {
            tau.min(min_words)
        } else {
            tau
        };
        if let (Direction::Opposite, Some((words, _))) =
            (dir, self.matcher_opts.short_opposite_rule())
        {
            len = len.min(words);
        }
        len
    }

    /// τ of configuration k read in direction `dir`, and the travel rule's minimum words.
    fn tau_and_min_words(&self, k: usize, dir: Direction) -> (usize, usize) {
        let extra = match dir {
            Direction::Same => 0,
            Direction::Opposite => self.matcher_opts.reverse_extra_ngram,
        };
        (
            self.tau[k] + extra,
            self.matcher_opts.ngram_travel_min_words.max(1) + extra,
        )
    }

    /// Appends to `chain` the τ-gram of configuration k ending at memo entry `idx` of `c`,
    /// newest pair first, and says whether the short rule made it; `None` (nothing appended)
    /// when the chain is shorter than τ (and not long enough in travel). Read backwards, a chain
    /// with neither falls back on the short rule (`reverse_short_ngram_words` words or more,
    /// fewer than τ, over `reverse_short_ngram_travel_m`).
    pub(super) fn tau_chain(
        &self,
        (c, idx): (WordId, usize),
        k: usize,
        dir: Direction,
        chain: &mut Vec<(WordId, usize)>,
    ) -> Option<bool> {
        let (tau, min_words) = self.tau_and_min_words(k, dir);
        let travel_m = self.matcher_opts.travel_rule_m(dir);
        if self.walk_chain((c, idx), k, dir, (tau, min_words, travel_m), chain) {
            return Some(false);
        }
        // The short rule: as few words as span `reverse_short_ngram_travel_m`, at least
        // `reverse_short_ngram_words` and fewer than τ.
        let (words, short_m) = self.matcher_opts.short_opposite_rule()?;
        let most = tau.saturating_sub(1);
        if dir == Direction::Same || words > most {
            return None;
        }
        let start = chain.len();
        if !self.walk_chain((c, idx), k, dir, (most, words, short_m), chain) {
            return None;
        }
        let oldest = chain[chain.len() - 1].0;
        if self.word(c).end_travel_m - self.word(oldest).start_travel_m < short_m {
            chain.truncate(start);
            return None;
        }
        Some(true)
    }

    /// [`tau_chain`](Self::tau_chain) by one rule: τ words, or at least `min_words` whose
    /// current side spans `travel_m` (> 0).
    fn walk_chain(
        &self,
        (c, idx): (WordId, usize),
        k: usize,
        dir: Direction,
        (tau, min_words, travel_m): (usize, usize, f64),
        chain: &mut Vec<(WordId, usize)>,
    ) -> bool {
        let memo = &self.memo[dir as usize];
        let e = memo[c as usize][idx];
        let by_travel = travel_m > 0.0;
        let len = e.len[k] as usize;
        if len < tau && !(by_travel && len >= min_words) {
            return false;
        }
        let start = chain.len();
        chain.push((c, idx));
        let (mut wc, mut we) = (c, e);
        let end_m = self.word(c).end_travel_m;
        while chain.len() - start < tau {
            // An n-gram long in travel but short in words (`ngram_travel_m`,
            // `reverse_ngram_travel_m`, `reverse_short_ngram_travel_m`).
            if by_travel
                && chain.len() - start >= min_words
                && end_m - self.word(wc).start_travel_m >= travel_m
            {
                break;
            }
            let Some((pc, pidx)) = Self::step_back(&we, k) else {
                chain.truncate(start);
                return false;
            };
            debug_assert!(
                pc as usize >= self.memo_forgotten,
                "memo of word {pc} read once freed"
            );
            let pe = memo[pc as usize][pidx];
            chain.push((pc, pidx));
            (wc, we) = (pc, pe);
        }
        true
    }

    /// Appends to `scr` the τ-gram of configuration k ending at memo entry `idx` of `c`, oldest
    /// pair first (its chain and word pairs); whether it extends a chain reported in
    /// configuration k and whether the short rule made it (`tau_chain`), or `None` (nothing
    /// appended) when there is no τ-gram.
    pub(super) fn push_chain(
        &self,
        (c, idx): (WordId, usize),
        k: usize,
        dir: Direction,
        scr: &mut Scratch,
    ) -> Option<(bool, bool)> {
        let memo = &self.memo[dir as usize];
        let from = scr.chain.len();
        let short = self.tau_chain((c, idx), k, dir, &mut scr.chain)?;
        // The chain extends one whose n-gram was verified and reported: only its new pair's
        // densities need checking (the travel and turn checks are cheap and run in full).
        let extends_reported = scr
            .chain
            .get(from + 1)
            .is_some_and(|&(wc, widx)| memo[wc as usize][widx].reported & (1 << k) != 0);
        scr.chain[from..].reverse();
        let chain = &scr.chain[from..];
        scr.word_pairs.extend(
            chain
                .iter()
                .map(|&(wc, widx)| (wc, memo[wc as usize][widx].past)),
        );
        Some((extends_reported, short))
    }

    /// Whether the n-gram's first current word begins at least `candidate_gap_m` after its
    /// latest past word ends (the last one read forwards, the first one read backwards).
    pub(super) fn beyond_candidate_gap(&self, word_pairs: &[(WordId, WordId)]) -> bool {
        let past_end = word_pairs
            .iter()
            .map(|&(_, p)| self.word(p).end_travel_m)
            .fold(f64::NEG_INFINITY, f64::max);
        let first_current = self.word(word_pairs[0].0);
        first_current.start_travel_m + 1e-9 >= past_end + self.matcher_opts.candidate_gap_m
    }
}
