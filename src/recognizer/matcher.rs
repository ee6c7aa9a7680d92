//! Back end: observations → words of every level → n-gram matches → fine alignment. This
//! module holds the [`WordMatcher`] and how a closing word's candidates are found, verified and
//! reported; the parts live beside it: `chains` (the memo of matching word pairs and the n-gram
//! chains through it, in both directions, with substitutions), `verify` (the checks a candidate
//! n-gram passes), `align` (fine alignment, Eq. 2) and `diagnostics` (what the matcher saw).
//! Their options are `[recognizer.matcher]`, `[recognizer.verify]` and
//! `[recognizer.alignment]` ([`MatcherOptions`], [`VerifyOptions`], [`AlignmentOptions`]).
//!
//! **Matching** (paper §III). Level configuration k (k = 1..`levels`) uses words of levels
//! 0..k−1. Two words match when D is equal, |S₁ − S₂| ≤ ratio·max(S₁, S₂) and A differs by at
//! most the angle tolerance. An n-gram match is a chain of word pairs (c₁, p₁) … (cₙ, pₙ) where
//! each cᵢ is a predecessor of cᵢ₊₁ and each pᵢ of pᵢ₊₁ (so current and past n-grams are paths in
//! the predecessor lists, mixing levels freely).
//!
//! When a word c closes, its candidates are the words of its class (a per-class occurrence list)
//! that end at least `candidate_gap_m` of travel before c begins and match it; with
//! `max_candidates` = k > 0 only the k most recent of them in each direction (the bound on work per lap, see
//! `index.rs`: a place is matched to its k most recent look-alikes, not to every earlier one). For each candidate p the
//! longest chain ending at (c, p) is 1 + the best memoised chain of a pair (c', p') with c' a
//! predecessor of c and p' one of p, computed for every level configuration at once; the memo
//! holds one entry per matching pair, so the work per word is candidates × predecessors², and
//! nothing sweeps the trajectory.
//!

use super::align::{Placement, PlacementKey, PsiResidual};
use super::chains::Entry;
use super::config::{RecognizerConfig, RecognizerError};
use super::diagnostics::{MAX_REJECTED_SAMPLES, VerificationCounts};
use super::index::Occurrence;
use super::options::{AlignmentOptions, MatcherOptions, VerifyOptions};
use super::types::{AlignedRun, DensityObservation, Direction, Observation, WordMatch};
use super::words::{MAX_LEVELS, Word, WordId, WordLevels};
use crate::place::RejectedCandidate;
use std::cell::RefCell;
// foldhash: the keys are word ids and shifts, not adversarial input; SipHash was ~5 % of the
// back end's instructions (a placement is looked up ~100k times per lap at 40 laps).
use foldhash::HashMap;

/// Words, multi-level words, matching and alignment over a stream of observations.
#[derive(Clone, Debug)]
pub struct WordMatcher {
    /// Level configurations searched (`RecognizerConfig::levels`).
    pub(super) levels: usize,
    /// Per level configuration, τ: its `min_ngram`, at least 1 (a chain is one pair or more);
    /// `usize::MAX` beyond `levels`.
    pub(super) tau: [usize; MAX_LEVELS],
    pub(super) matcher_opts: MatcherOptions,
    pub(super) align_opts: AlignmentOptions,
    pub(super) verify_opts: VerifyOptions,
    /// Odometric travel between observations (`front_end.observation_spacing_m`), metres.
    pub(super) spacing_m: f64,
    pub(super) words: WordLevels,
    /// Per class, the words of that class in creation order (so by end travel).
    pub(super) occurrences: Vec<Vec<Occurrence>>,
    /// Working space of `memoise`: per direction, the candidates of the word being matched
    /// (`find_candidates`).
    pub(super) candidates: [Vec<WordId>; 2],
    /// Per direction (`Same`, `Opposite`), per word, an entry per matching past word, sorted by
    /// past word.
    pub(super) memo: [Vec<Vec<Entry>>; 2],
    /// Per word, the words whose predecessor it is (the chain links of a past n-gram read
    /// backwards).
    pub(super) successors: Vec<Vec<WordId>>,
    /// Words before this one belong to finished runs or lie behind the query horizon; their
    /// memo (both directions) has been freed and is never read again.
    pub(super) memo_forgotten: usize,
    /// Per predecessor slot of the word being matched: (stamp, entry index) per past word.
    /// Slots `MAX_LEVELS..`: the same for the predecessors of its level-0 predecessor (the
    /// pairs a substitution bridges to).
    pub(super) lookup: [Vec<(u32, u32)>; 2 * MAX_LEVELS],
    pub(super) stamp: u32,
    pub(super) rejections: VerificationCounts,
    /// Per level configuration, the longest chain of matching word pairs seen (either direction).
    pub(super) longest: [u16; MAX_LEVELS],
    /// Chains that reached τ but whose n-gram began within the candidate gap of its past side.
    pub(super) within_gap: usize,
    /// Level-0 words closed so far, and the travel they span (each word's observations times
    /// the spacing), metres.
    pub(super) level0_words: usize,
    pub(super) level0_travel_m: f64,
    /// The first `MAX_REJECTED_SAMPLES` candidates verification turned down, one observation
    /// pair each (so the harness can tell whether they were right).
    pub(super) rejected: Vec<RejectedCandidate>,
    /// Per word matched so far, where it begins read forwards and read backwards
    /// ([`reading_start`](Self::reading_start)): verification reads it for every word of every
    /// candidate n-gram, and a word's first and last observations are far apart in memory.
    pub(super) reading_starts: Vec<[(f64, f64); 2]>,
    /// Working space of `report`.
    pub(super) scratch: Scratch,
    /// Placements made while reporting the current word, by (current word, past word,
    /// direction, anchor): a word's level configurations mostly verify the same newest pair at
    /// the same shift.
    pub(super) placements: RefCell<HashMap<PlacementKey, Option<Placement>>>,
    /// Whether every observation so far has its index as id (the recognizer's own stream): an
    /// aligned window then makes its pairs as one run without reading each observation.
    pub(super) ids_are_indices: bool,
}

impl WordMatcher {
    pub fn new(config: &RecognizerConfig) -> Result<Self, RecognizerError> {
        config.validate()?;
        let mut tau = [usize::MAX; MAX_LEVELS];
        for (k, t) in tau.iter_mut().enumerate().take(config.levels) {
            *t = config.matcher.min_ngram[k].max(1);
        }
        let words = &config.words;
        let word_levels = WordLevels::with_rule(
            words.classes,
            words.min_word_size,
            config.levels,
            words.multi_level,
        )
        .with_wide_classes(config.wide_classes_in_use())
        .with_psi_window(words.psi_window, words.psi_window_statistic)
        .with_class_offset(words.class_offset);
        Ok(WordMatcher {
            levels: config.levels,
            tau,
            matcher_opts: config.matcher.clone(),
            align_opts: config.alignment.clone(),
            verify_opts: config.verify.clone(),
            spacing_m: config.front_end.observation_spacing_m,
            rejections: VerificationCounts::default(),
            occurrences: vec![Vec::new(); word_levels.class_count()],
            candidates: Default::default(),
            words: word_levels,
            memo: Default::default(),
            successors: Vec::new(),
            memo_forgotten: 0,
            lookup: Default::default(),
            stamp: 0,
            longest: [0; MAX_LEVELS],
            within_gap: 0,
            rejected: Vec::new(),
            level0_words: 0,
            level0_travel_m: 0.0,
            reading_starts: Vec::new(),
            scratch: Scratch::default(),
            placements: RefCell::default(),
            ids_are_indices: true,
        })
    }

    /// Adds one observation; returns the matches that became known with it. An observation
    /// whose `run` is later than the current run starts the new run first (as
    /// [`start_run`](Self::start_run)), so a stored observation stream can be replayed without
    /// calling it.
    ///
    /// # Panics
    /// When `obs.travel_m` is less than the previous observation's (or NaN): the candidate search
    /// bisects the occurrence lists by travel, which is only correct if travel never decreases.
    pub fn push_observation(&mut self, density: &DensityObservation) -> Vec<WordMatch> {
        let obs = &density.observation;
        let last = self.words.observations().last().map_or(0.0, |o| o.travel_m);
        assert!(
            obs.travel_m >= last,
            "observation {}: travel {} m is less than the previous observation's {} m; \
             observations must come in order of non-decreasing travel",
            obs.id,
            obs.travel_m,
            last
        );
        self.ids_are_indices &= obs.id == self.words.observations().len();
        let mut out = Vec::new();
        if obs.run > self.words.run() {
            let closed = self.words.begin_run(obs.run);
            self.match_words(&closed, &mut out);
            self.forget_finished_runs();
        }
        let closed = self.words.push(density);
        self.match_words(&closed, &mut out);
        out
    }

    /// Closes the current run (its last word is matched) and starts a new one; does nothing
    /// while the current run has no observation.
    pub fn start_run(&mut self) -> Vec<WordMatch> {
        let closed = self.words.start_run();
        let mut out = Vec::new();
        self.match_words(&closed, &mut out);
        self.forget_finished_runs();
        out
    }

    /// Frees the memo (both directions) of every word made so far, once their runs are over: a
    /// memo is read only through the predecessors of a closing word (read backwards, the past
    /// side walks successors, but the memo is still that of the current word's predecessors),
    /// and predecessors never cross a run, so these entries are never read again (the memo then
    /// holds one run's words, not the history's).
    pub(super) fn forget_finished_runs(&mut self) {
        for memo in &mut self.memo {
            for m in &mut memo[self.memo_forgotten..] {
                *m = Vec::new();
            }
        }
        self.memo_forgotten = self.memo[0].len();
    }

    /// Frees the memo (both directions) of the words, oldest first, that begin before the
    /// query horizon: a memo is read only for a current word of a future n-gram (its own, its
    /// predecessors' while memoising, the chain walk's at most τ steps back), and those all begin
    /// at or after the horizon ([`query_horizon`](Self::query_horizon)). Without this, a long
    /// run with `max_candidates = 0` holds a memo entry per matching word pair of all its laps,
    /// which grows with the laps squared. Stops at the first word that begins at or after the
    /// horizon: a higher-level word may begin before a lower one closed earlier, so a few words
    /// are freed late, never early.
    pub(super) fn forget_behind_horizon(&mut self) {
        let horizon = self.query_horizon();
        let made = self.memo[0].len();
        while self.memo_forgotten < made
            && self.words.word(self.memo_forgotten as WordId).first_obs < horizon
        {
            for memo in &mut self.memo {
                memo[self.memo_forgotten] = Vec::new();
            }
            self.memo_forgotten += 1;
        }
    }

    /// Closes the current run's open word and matches it, without starting a new run (call at
    /// the end of the input).
    pub fn finish_run(&mut self) -> Vec<WordMatch> {
        let closed = self.words.finish_run();
        let mut out = Vec::new();
        self.match_words(&closed, &mut out);
        out
    }

    pub fn words(&self) -> &WordLevels {
        &self.words
    }

    pub fn observations(&self) -> &[Observation] {
        self.words.observations()
    }

    /// The first observation (index) a match found from now on may pair as its query: what
    /// lets the evaluation score matches as they come and forget pairs behind it
    /// (`eval::tally`). A match's query observations lie in the current words of its n-gram
    /// (a placement never leaves the current word), an n-gram is at most τ pairs (τ plus
    /// `reverse_extra_ngram` read backwards; chains long in travel stop at τ too), each step back
    /// goes to a predecessor, one word of at most [`WordLevels::max_span_l0`] level-0 words, or
    /// across a substitution one level-0 word further. So every future n-gram starts within
    /// τ·(span + 1) level-0 words of the newest closed one.
    pub fn query_horizon(&self) -> usize {
        let tau = self.tau[..self.levels].iter().max().copied().unwrap_or(1)
            + self.matcher_opts.opposite_extra_ngram();
        let back = tau * (self.words.max_span_l0() + 1) + 1;
        let closed = self.words.closed_l0();
        match closed.checked_sub(back) {
            Some(i) => self.words.level0(i).map_or(0, |w| w.first_obs),
            None => 0,
        }
    }

    /// Candidate n-grams accepted and rejected by verification so far.
    pub fn verification(&self) -> VerificationCounts {
        self.rejections
    }

    /// Matching word pairs held in the memo (a measure of its size).
    pub fn memo_entries(&self) -> usize {
        self.memo.iter().flatten().map(Vec::len).sum()
    }

    pub(super) fn word(&self, id: WordId) -> &Word {
        self.words.word(id)
    }

    /// Matches the words just closed, in order; their matches are appended to `out` (one vector
    /// for all of an observation's, not one per call to copy over).
    pub(super) fn match_words(&mut self, closed: &[WordId], out: &mut Vec<WordMatch>) {
        for &c in closed {
            debug_assert_eq!(self.reading_starts.len(), c as usize);
            let starts = Direction::BOTH.map(|dir| self.measure_reading_start(c, dir));
            self.reading_starts.push(starts);
            self.link_successors(c);
            self.find_candidates(c);
            self.memoise(c, Direction::Same);
            if self.matcher_opts.reverse {
                self.memoise(c, Direction::Opposite);
            } else {
                self.memo[Direction::Opposite as usize].push(Vec::new());
            }
            self.report(c, out);
            let (level, size) = (self.word(c).level, self.word(c).size);
            if level == 0 {
                self.level0_words += 1;
                self.level0_travel_m += size as f64 * self.spacing_m;
            }
            let class = self.word(c).class as usize;
            let occurrence = Occurrence::of(c, self.word(c));
            self.occurrences[class].push(occurrence);
        }
        self.forget_behind_horizon();
    }

    pub(super) fn report(&mut self, c: WordId, out: &mut Vec<WordMatch>) {
        self.placements.get_mut().clear();
        let mut scratch = std::mem::take(&mut self.scratch);
        for k in 0..self.levels {
            // Every candidate first, then the reports: a candidate's new pairs are counted when
            // it is reported (see `emit`).
            scratch.clear();
            for dir in Direction::BOTH {
                let min_len = self.min_chain_len(k, dir);
                for idx in 0..self.memo[dir as usize][c as usize].len() {
                    // A chain too short for k has no τ-gram (`tau_chain`): skipped here at once.
                    if (self.memo[dir as usize][c as usize][idx].len[k] as usize) < min_len {
                        continue;
                    }
                    if let Some(cand) = self.candidate(c, idx, k, dir, &mut scratch) {
                        scratch.found.push(cand);
                    }
                }
            }
            for i in 0..scratch.found.len() {
                let cand = scratch.found[i].clone();
                out.push(self.emit(c, k, &cand, &mut scratch));
            }
        }
        self.scratch = scratch;
    }

    /// The τ-gram of configuration k ending at memo entry `idx` of `c` (direction `dir`) if it
    /// is long enough, satisfies the candidate gap, passes verification and has unreported
    /// pairs; its pairs, anchors and placements are appended to `scr`.
    pub(super) fn candidate(
        &mut self,
        c: WordId,
        idx: usize,
        k: usize,
        dir: Direction,
        scr: &mut Scratch,
    ) -> Option<Candidate> {
        let (from, placed_from) = (scr.chain.len(), scr.placed.len());
        let (extends_reported, short) = self.push_chain((c, idx), k, dir, scr)?;
        let pairs = from..scr.chain.len();
        let chain_len = self.memo[dir as usize][c as usize][idx].len[k] as usize;
        if !extends_reported && self.too_few_classes(&scr.word_pairs[pairs.clone()], dir, chain_len)
        {
            scr.truncate(from, placed_from);
            return None;
        }
        if !self.beyond_candidate_gap(&scr.word_pairs[pairs.clone()]) {
            self.within_gap += 1;
            scr.truncate(from, placed_from);
            return None;
        }
        self.chain_anchors(
            &scr.word_pairs[pairs.clone()],
            dir,
            &mut scr.offsets,
            &mut scr.anchors,
        );
        let mut pairs = pairs;
        if self.verify_opts.enabled
            && let Some(reason) =
                self.verify_or_trim(&mut pairs, dir, (extends_reported, short), placed_from, scr)
        {
            self.rejections.add(reason);
            if self.rejected.len() < MAX_REJECTED_SAMPLES {
                let sample = self.sample(
                    &scr.word_pairs[pairs.clone()],
                    &scr.anchors[pairs.clone()],
                    dir,
                    reason,
                );
                self.rejected.push(sample);
            }
            scr.truncate(from, placed_from);
            return None;
        }
        Some(Candidate {
            idx,
            dir,
            pairs,
            placed: placed_from..scr.placed.len(),
        })
    }

    /// Marks a candidate's new pairs reported and makes its match.
    pub(super) fn emit(
        &mut self,
        c: WordId,
        k: usize,
        cand: &Candidate,
        scr: &mut Scratch,
    ) -> WordMatch {
        let d = cand.dir as usize;
        let chain = &scr.chain[cand.pairs.clone()];
        // Counted now, not when the candidate was found: another candidate of the same word may
        // have reported a pair this chain shares since.
        let fresh = 1 + chain[..chain.len() - 1]
            .iter()
            .rev()
            .take_while(|&&(wc, widx)| self.memo[d][wc as usize][widx].reported & (1 << k) == 0)
            .count();
        let fresh_from = chain.len() - fresh;
        let mut refs = Vec::with_capacity(fresh);
        // Verification placed the last `placed.len()` word pairs already: the same placements.
        let placed_from = chain.len() - cand.placed.len();
        scr.runs.clear();
        let mut residual = PsiResidual::default();
        for (j, &(wc, widx)) in chain.iter().enumerate().skip(fresh_from) {
            let at = cand.pairs.start + j;
            let (past, anchor) = (scr.word_pairs[at].1, scr.anchors[at]);
            self.memo[d][wc as usize][widx].reported |= 1 << k;
            refs.push((self.word(wc).word_ref(), self.word(past).word_ref()));
            let placement = match j.checked_sub(placed_from) {
                Some(i) => scr.placed[cand.placed.start + i].take(),
                None => self.placement(wc, past, cand.dir, anchor),
            };
            residual.add(placement.as_ref());
            self.aligned_pairs(wc, past, cand.dir, placement, &mut scr.runs);
        }
        self.rejections.accepted += 1;
        WordMatch {
            levels: k + 1,
            ngram_len: self.memo[d][c as usize][cand.idx].len[k] as usize,
            word_pairs: refs,
            // Usually one run: exactly as many as there are, no spare capacity per match.
            runs: scr.runs.to_vec(),
            direction: cand.dir,
            psi_rms: residual.rms(),
        }
    }
}

/// An n-gram that passed the gap and verification, before it is reported; its data is in the
/// matcher's [`Scratch`].
#[derive(Clone, Debug)]
pub(super) struct Candidate {
    pub(super) idx: usize,
    pub(super) dir: Direction,
    /// Its word pairs in `Scratch::{chain, word_pairs, anchors}`, oldest first.
    pub(super) pairs: std::ops::Range<usize>,
    /// The placements verification made (of its last `placed.len()` word pairs) in
    /// `Scratch::placed`.
    pub(super) placed: std::ops::Range<usize>,
}

/// The candidates of one word and configuration, back to back, kept between words so that
/// finding and reporting them allocates nothing but the matches.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    pub(super) found: Vec<Candidate>,
    /// Per word pair: (current word, memo index), (current word, past word), the n-gram's shift.
    pub(super) chain: Vec<(WordId, usize)>,
    pub(super) word_pairs: Vec<(WordId, WordId)>,
    pub(super) anchors: Vec<i64>,
    pub(super) placed: Vec<Option<Placement>>,
    /// Working space of `chain_anchors` (offsets as `total_order_key`s) and of `emit`.
    pub(super) offsets: Vec<i64>,
    pub(super) runs: Vec<AlignedRun>,
}

impl Scratch {
    pub(super) fn clear(&mut self) {
        self.found.clear();
        self.truncate(0, 0);
    }

    /// Drops the word pairs from `pairs` on and the placements from `placed` on.
    pub(super) fn truncate(&mut self, pairs: usize, placed: usize) {
        self.chain.truncate(pairs);
        self.word_pairs.truncate(pairs);
        self.anchors.truncate(pairs);
        self.placed.truncate(placed);
    }
}
