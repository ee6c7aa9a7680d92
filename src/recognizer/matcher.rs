//! Back end: observations → words of every level → n-gram matches → fine alignment.
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
//! **Reverse direction** (paper §VI, future work; `reverse = true`). A revisit driven the
//! other way sees the past words in reverse order, each turned the other way: read backwards, a
//! word keeps its class and size and its angle syllable is negated. Each current word is also
//! matched against the past words read backwards, and chains grow through successors: (cᵢ, pⱼ)
//! extends (cᵢ₋₁, pⱼ₊₁) where pⱼ₊₁ is a word whose predecessor is pⱼ. This is a second memo
//! with the same search; its matches carry `Direction::Opposite`, are verified with the past
//! side's travel and turn measured backwards, and are aligned on the past word's Ψ read
//! backwards (so past ids decrease as query ids increase).
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
//! **Verification** (`verify`). A candidate n-gram is accepted only if it is consistent: the
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
//! The first 10,000 candidates verification turns down are kept as one observation pair each
//! (`MatchDiagnostics::rejected`), so that the harness, which knows the truth, can tell whether
//! the checks turned down look-alikes or true revisits.
//!
//! **Fine alignment** (paper §IV, Eq. 2). Each reported word pair is aligned by the shift
//! minimising the mean squared Ψ difference between n = min(S₁, S₂) current and past
//! observations. Where the shift may be is the `alignment` setting: `paper` searches
//! d ∈ (−Δmax, Δmax) from the words' starts, as Eq. 2 is written; `whole-word` lets the smaller
//! word sit anywhere inside the larger one (never past its ends), since matched words may differ
//! in size by the size tolerance and a boundary that moved by more than Δmax paired a long word
//! metres off; `chain` (default) searches within ±`chain_alignment_offset` of the shift the
//! whole n-gram agrees on (the median over its word pairs of the travel offsets between their
//! start boundaries and between their end boundaries), even past the words' ends, and near the
//! placement inside the larger word nearest to it; placements within `chain_alignment_tie` of
//! the least error go to the n-gram's shift. A long word of flat Ψ has no minimum of its own:
//! inside its own ends it slid to wherever noise favoured, and when both its boundaries had
//! moved the same way (a level-1 word of scenario A, 1.2 m) no placement inside it was right, so
//! its pairs fell just outside the 1 m radius. Shifts whose whole window lies in the past word's
//! run are preferred (near a run's start or end, those with the largest overlap). The aligned
//! pairs whose travel differs by less than `candidate_gap_m` are dropped.

use super::config::{AlignmentMode, RecognizerConfig, RecognizerError};
use super::diagnostics::{MAX_REJECTED_SAMPLES, MatchDiagnostics, Rejection, VerificationCounts};
use super::index::recent_candidates;
use super::types::{
    AlignedRun, DensityObservation, Direction, Observation, WordMatch, push_pair, push_run,
};
use super::words::{MAX_LEVELS, Word, WordId, WordLevels};
use crate::geom::wrap_angle;
use crate::place::RejectedCandidate;
use std::cell::RefCell;
use std::collections::HashMap;

#[derive(Clone, Copy, Debug)]
struct Entry {
    past: WordId,
    /// Longest chain per level configuration (0 when a word's level is outside it).
    len: [u16; MAX_LEVELS],
    /// Per configuration: the current word of the best chain's previous pair (a predecessor of
    /// this pair's current word, or across a substitution one word further back).
    back_word: [WordId; MAX_LEVELS],
    /// Per configuration: index of the best chain's previous pair in that word's memo.
    back_idx: [u32; MAX_LEVELS],
    /// Bit k: reported in configuration k.
    reported: u8,
}

#[derive(Clone, Debug)]
struct Params {
    levels: usize,
    min_ngram: [usize; MAX_LEVELS],
    size_ratio: f64,
    angle_tol_deg: f64,
    candidate_gap_m: f64,
    max_candidates: usize,
    max_offset: usize,
    chain_offset: usize,
    alignment: AlignmentMode,
    reverse: bool,
    reverse_extra_ngram: usize,
    substitutions: bool,
    substitution_size_ratio: f64,
    /// Per direction (`Same`, `Opposite`): `ngram_travel_m`, `reverse_ngram_travel_m`.
    ngram_travel_m: [f64; 2],
    ngram_travel_min_words: usize,
    chain_tie: f64,
    verify: bool,
    verify_travel_ratio: f64,
    verify_travel_slack_m: f64,
    verify_turn_rad: f64,
    verify_max_psi_rms: f64,
    /// Per direction (`Same`, `Opposite`).
    verify_max_lateral_rms: [f64; 2],
    reverse_min_turn_rad: f64,
    /// Odometric travel between observations, metres.
    spacing_m: f64,
}

/// Words, multi-level words, matching and alignment over a stream of observations.
#[derive(Clone, Debug)]
pub struct WordMatcher {
    params: Params,
    words: WordLevels,
    /// Per class, the words of that class in creation order (so by end travel).
    occurrences: Vec<Vec<WordId>>,
    /// Per direction (`Same`, `Opposite`), per word, an entry per matching past word, sorted by
    /// past word.
    memo: [Vec<Vec<Entry>>; 2],
    /// Per word, the words whose predecessor it is (the chain links of a past n-gram read
    /// backwards).
    successors: Vec<Vec<WordId>>,
    /// Words before this one belong to finished runs; their memo (both directions) has been
    /// freed.
    memo_forgotten: usize,
    /// Per predecessor slot of the word being matched: (stamp, entry index) per past word.
    /// Slots `MAX_LEVELS..`: the same for the predecessors of its level-0 predecessor (the
    /// pairs a substitution bridges to).
    lookup: [Vec<(u32, u32)>; 2 * MAX_LEVELS],
    stamp: u32,
    rejections: VerificationCounts,
    /// Per level configuration, the longest chain of matching word pairs seen (either direction).
    longest: [u16; MAX_LEVELS],
    /// Chains that reached τ but whose n-gram began within the candidate gap of its past side.
    within_gap: usize,
    /// Level-0 words closed so far, and the travel they span (each word's observations times
    /// the spacing), metres.
    level0_words: usize,
    level0_travel_m: f64,
    /// The first `MAX_REJECTED_SAMPLES` candidates verification turned down, one observation
    /// pair each (so the harness can tell whether they were right).
    rejected: Vec<RejectedCandidate>,
    /// Per word matched so far, where it begins read forwards and read backwards
    /// ([`reading_start`](Self::reading_start)): verification reads it for every word of every
    /// candidate n-gram, and a word's first and last observations are far apart in memory.
    reading_starts: Vec<[(f64, f64); 2]>,
    /// Working space of `report`.
    scratch: Scratch,
    /// Placements made while reporting the current word, by (current word, past word,
    /// direction, anchor): a word's level configurations mostly verify the same newest pair at
    /// the same shift.
    placements: RefCell<HashMap<PlacementKey, Option<Placement>>>,
    /// Whether every observation so far has its index as id (the recognizer's own stream): an
    /// aligned window then makes its pairs as one run without reading each observation.
    ids_are_indices: bool,
}

impl WordMatcher {
    pub fn new(config: &RecognizerConfig) -> Result<Self, RecognizerError> {
        config.validate()?;
        let mut min_ngram = [usize::MAX; MAX_LEVELS];
        for (k, m) in min_ngram.iter_mut().enumerate().take(config.levels) {
            *m = config.min_ngram[k].max(1);
        }
        Ok(WordMatcher {
            params: Params {
                levels: config.levels,
                min_ngram,
                size_ratio: config.size_tolerance_ratio,
                angle_tol_deg: config.angle_tolerance_deg,
                candidate_gap_m: config.candidate_gap_m,
                max_candidates: config.max_candidates,
                max_offset: config.max_alignment_offset,
                chain_offset: config.chain_alignment_offset,
                alignment: config.alignment,
                reverse: config.reverse,
                reverse_extra_ngram: config.reverse_extra_ngram,
                substitutions: config.substitutions,
                substitution_size_ratio: config.substitution_size_ratio,
                ngram_travel_m: [config.ngram_travel_m, config.reverse_ngram_travel_m],
                ngram_travel_min_words: config.ngram_travel_min_words,
                chain_tie: config.chain_alignment_tie,
                verify: config.verify,
                verify_travel_ratio: config.verify_travel_ratio,
                verify_travel_slack_m: config.verify_travel_slack_m,
                verify_turn_rad: config.verify_turn_deg.to_radians(),
                verify_max_psi_rms: config.verify_max_psi_rms,
                verify_max_lateral_rms: [
                    config.verify_max_lateral_rms,
                    config.reverse_verify_max_lateral_rms,
                ],
                reverse_min_turn_rad: config.reverse_min_turn_deg.to_radians(),
                spacing_m: config.observation_spacing_m,
            },
            rejections: VerificationCounts::default(),
            words: WordLevels::with_rule(
                config.classes,
                config.min_word_size,
                config.levels,
                config.multi_level,
            ),
            occurrences: vec![Vec::new(); config.classes],
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
            out = self.match_words(&closed);
            self.forget_finished_runs();
        }
        let closed = self.words.push(density);
        out.extend(self.match_words(&closed));
        out
    }

    /// Closes the current run (its last word is matched) and starts a new one; does nothing
    /// while the current run has no observation.
    pub fn start_run(&mut self) -> Vec<WordMatch> {
        let closed = self.words.start_run();
        let out = self.match_words(&closed);
        self.forget_finished_runs();
        out
    }

    /// Frees the memo (both directions) of every word made so far, once their runs are over: a
    /// memo is read only through the predecessors of a closing word (read backwards, the past
    /// side walks successors, but the memo is still that of the current word's predecessors),
    /// and predecessors never cross a run, so these entries are never read again (the memo then
    /// holds one run's words, not the history's).
    fn forget_finished_runs(&mut self) {
        for memo in &mut self.memo {
            for m in &mut memo[self.memo_forgotten..] {
                *m = Vec::new();
            }
        }
        self.memo_forgotten = self.memo[0].len();
    }

    /// Closes the current run's open word and matches it, without starting a new run (call at
    /// the end of the input).
    pub fn finish_run(&mut self) -> Vec<WordMatch> {
        let closed = self.words.finish_run();
        self.match_words(&closed)
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
        let p = &self.params;
        let tau = p.min_ngram[..p.levels].iter().max().copied().unwrap_or(1)
            + if p.reverse { p.reverse_extra_ngram } else { 0 };
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

    /// What the matcher saw so far, to say why nothing matched.
    pub fn diagnostics(&self) -> MatchDiagnostics {
        let levels = self.params.levels;
        MatchDiagnostics {
            longest_chain: self.longest[..levels].iter().map(|&l| l as usize).collect(),
            min_ngram: self.params.min_ngram[..levels].to_vec(),
            within_gap: self.within_gap,
            verification: self.rejections,
            rejected: self.rejected.clone(),
            long_steps: 0,
            reverse_extra_ngram: if self.params.reverse {
                self.params.reverse_extra_ngram
            } else {
                0
            },
            mean_word_m: if self.level0_words == 0 {
                0.0
            } else {
                self.level0_travel_m / self.level0_words as f64
            },
        }
    }

    /// Matching word pairs held in the memo (a measure of its size).
    pub fn memo_entries(&self) -> usize {
        self.memo.iter().flatten().map(Vec::len).sum()
    }

    fn word(&self, id: WordId) -> &Word {
        self.words.word(id)
    }

    /// Whether current word `a` matches past word `b` read in direction `dir` (backwards, b's
    /// angle syllable is negated; class and size do not change).
    fn syllables_match(&self, a: &Word, b: &Word, dir: Direction) -> bool {
        let (sa, sb) = (a.size as f64, b.size as f64);
        if (sa - sb).abs() > self.params.size_ratio * sa.max(sb) + 1e-9 {
            return false;
        }
        let b_angle = match dir {
            Direction::Same => b.angle_deg,
            Direction::Opposite => -b.angle_deg,
        };
        let mut d = (a.angle_deg - b_angle).abs() % 360.0;
        if d > 180.0 {
            d = 360.0 - d;
        }
        d <= self.params.angle_tol_deg + 1e-9
    }

    fn match_words(&mut self, closed: &[WordId]) -> Vec<WordMatch> {
        let mut out = Vec::new();
        for &c in closed {
            debug_assert_eq!(self.reading_starts.len(), c as usize);
            let starts = Direction::BOTH.map(|dir| self.measure_reading_start(c, dir));
            self.reading_starts.push(starts);
            self.link_successors(c);
            self.memoise(c, Direction::Same);
            if self.params.reverse {
                self.memoise(c, Direction::Opposite);
            } else {
                self.memo[Direction::Opposite as usize].push(Vec::new());
            }
            self.report(c, &mut out);
            let (level, size) = (self.word(c).level, self.word(c).size);
            if level == 0 {
                self.level0_words += 1;
                self.level0_travel_m += size as f64 * self.params.spacing_m;
            }
            let class = self.word(c).class as usize;
            self.occurrences[class].push(c);
        }
        out
    }

    /// Records `c` as the successor of each of its predecessors.
    fn link_successors(&mut self, c: WordId) {
        self.successors.resize(c as usize + 1, Vec::new());
        for &p in self.words.word(c).pred_ids() {
            self.successors[p as usize].push(c);
        }
    }

    /// The words a chain through past word `p` continues from, in direction `dir`: its
    /// predecessors, or (read backwards) its successors.
    fn past_links(&self, p: WordId, dir: Direction) -> &[WordId] {
        match dir {
            Direction::Same => self.word(p).pred_ids(),
            Direction::Opposite => &self.successors[p as usize],
        }
    }

    /// Fills the memo of word `c` in direction `dir`: one entry per matching past word.
    fn memoise(&mut self, c: WordId, dir: Direction) {
        let d = dir as usize;
        debug_assert_eq!(self.memo[d].len(), c as usize);
        let stamp = self.fill_lookups(c, d);
        let cw = self.word(c).clone();
        let limit = cw.start_travel_m - self.params.candidate_gap_m;
        let occ = &self.occurrences[cw.class as usize];
        let end = occ.partition_point(|&p| self.word(p).end_travel_m <= limit + 1e-9);
        let c_preds = cw.pred_ids();

        let levels = self.params.levels;
        let candidates = recent_candidates(&occ[..end], self.params.max_candidates, |p| {
            self.syllables_match(&cw, self.word(p), dir)
        });
        let mut entries = Vec::with_capacity(candidates.len());
        for p in candidates {
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
            if self.params.substitutions {
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
    }

    /// Fills the lookup tables for word `c` in direction `d` under a new stamp (returned): slot i
    /// maps each past word of the memo of c's i-th predecessor to its entry, slot
    /// `MAX_LEVELS` + i the same for the i-th predecessor of c's level-0 predecessor (the pairs
    /// a substitution bridges to).
    fn fill_lookups(&mut self, c: WordId, d: usize) -> u32 {
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
            .params
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
    fn level0_link(&self, w: WordId, dir: Direction) -> Option<WordId> {
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
    fn bridge_substitution(
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
        let levels = self.params.levels;
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
        if (a - b).abs() > self.params.substitution_size_ratio * a.max(b) + 1e-9 {
            return;
        }
        // The memo entries of c_skip's predecessors, by past word: lookup slots MAX_LEVELS.. (see
        // `memoise`).
        for (slot, &c2) in self.word(c_skip).pred_ids().iter().enumerate() {
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
    fn step_back(entry: &Entry, k: usize) -> Option<(WordId, usize)> {
        if entry.len[k] <= 1 {
            return None;
        }
        Some((entry.back_word[k], entry.back_idx[k] as usize))
    }

    fn report(&mut self, c: WordId, out: &mut Vec<WordMatch>) {
        self.placements.get_mut().clear();
        let mut scratch = std::mem::take(&mut self.scratch);
        for k in 0..self.params.levels {
            // Every candidate first, then the reports: a candidate's new pairs are counted when
            // it is reported (see `emit`).
            scratch.clear();
            for dir in Direction::BOTH {
                for idx in 0..self.memo[dir as usize][c as usize].len() {
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

    /// Appends to `chain` the τ-gram of configuration k ending at memo entry `idx` of `c`,
    /// newest pair first; false (nothing appended) when the chain is shorter than τ (and not
    /// long enough in travel).
    fn tau_chain(
        &self,
        (c, idx): (WordId, usize),
        k: usize,
        dir: Direction,
        chain: &mut Vec<(WordId, usize)>,
    ) -> bool {
        let memo = &self.memo[dir as usize];
        let tau = match dir {
            Direction::Same => self.params.min_ngram[k],
            Direction::Opposite => self.params.min_ngram[k] + self.params.reverse_extra_ngram,
        };
        let e = memo[c as usize][idx];
        let travel_m = self.params.ngram_travel_m[dir as usize];
        let by_travel = travel_m > 0.0;
        let min_words = self.params.ngram_travel_min_words.max(1)
            + match dir {
                Direction::Same => 0,
                Direction::Opposite => self.params.reverse_extra_ngram,
            };
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
            // `reverse_ngram_travel_m`).
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
            let pe = memo[pc as usize][pidx];
            chain.push((pc, pidx));
            (wc, we) = (pc, pe);
        }
        true
    }

    /// The τ-gram of configuration k ending at memo entry `idx` of `c` (direction `dir`) if it
    /// is long enough, satisfies the candidate gap, passes verification and has unreported
    /// pairs; its pairs, anchors and placements are appended to `scr`.
    fn candidate(
        &mut self,
        c: WordId,
        idx: usize,
        k: usize,
        dir: Direction,
        scr: &mut Scratch,
    ) -> Option<Candidate> {
        let (from, placed_from) = (scr.chain.len(), scr.placed.len());
        let extends_reported = self.push_chain((c, idx), k, dir, scr)?;
        let pairs = from..scr.chain.len();
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
        if self.params.verify
            && let Some(reason) = self.verify(
                &scr.word_pairs[pairs.clone()],
                dir,
                &scr.anchors[pairs.clone()],
                extends_reported,
                &mut scr.placed,
            )
        {
            self.rejections.add(reason);
            if self.rejected.len() < MAX_REJECTED_SAMPLES {
                let (&newest, &anchor) =
                    (&scr.word_pairs[pairs.end - 1], &scr.anchors[pairs.end - 1]);
                self.rejected.push(self.sample(newest, anchor, dir, reason));
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

    /// A rejected candidate's sample: the middle observation of its newest current word `c`,
    /// and the past observation the n-gram's shift `anchor` aligns with it (clamped into the
    /// past word `p`).
    fn sample(
        &self,
        (c, p): (WordId, WordId),
        anchor: i64,
        dir: Direction,
        reason: Rejection,
    ) -> RejectedCandidate {
        let (cw, pw) = (self.word(c), self.word(p));
        let i = cw.size as i64 / 2;
        let j = (i + anchor).clamp(0, (pw.size as i64 - 1).max(0));
        let obs = self.words.observations();
        RejectedCandidate {
            query: obs[cw.first_obs + i as usize].id,
            past: obs[PastSide::of(pw, dir).index(j)].id,
            direction: dir,
            check: reason.index(),
        }
    }

    /// Appends to `scr` the τ-gram of configuration k ending at memo entry `idx` of `c`, oldest
    /// pair first (its chain and word pairs); whether it extends a chain reported in
    /// configuration k, or `None` (nothing appended) when there is no τ-gram.
    fn push_chain(
        &self,
        (c, idx): (WordId, usize),
        k: usize,
        dir: Direction,
        scr: &mut Scratch,
    ) -> Option<bool> {
        let memo = &self.memo[dir as usize];
        let from = scr.chain.len();
        if !self.tau_chain((c, idx), k, dir, &mut scr.chain) {
            return None;
        }
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
        Some(extends_reported)
    }

    /// Whether the n-gram's first current word begins at least `candidate_gap_m` after its
    /// latest past word ends (the last one read forwards, the first one read backwards).
    fn beyond_candidate_gap(&self, word_pairs: &[(WordId, WordId)]) -> bool {
        let past_end = word_pairs
            .iter()
            .map(|&(_, p)| self.word(p).end_travel_m)
            .fold(f64::NEG_INFINITY, f64::max);
        let first_current = self.word(word_pairs[0].0);
        first_current.start_travel_m + 1e-9 >= past_end + self.params.candidate_gap_m
    }

    /// Marks a candidate's new pairs reported and makes its match.
    fn emit(&mut self, c: WordId, k: usize, cand: &Candidate, scr: &mut Scratch) -> WordMatch {
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

    /// Why the n-gram of `word_pairs` (oldest first) is inconsistent, if it is: odometric travel
    /// and turn between its words, from consecutive words and from its first word, must agree on
    /// both sides; the Ψ residual of its aligned pairs (with `newest_only`, of its newest pair:
    /// the n-gram extends a verified one) must be small. The placements it makes (of the pairs
    /// whose residual it measured, oldest first) are appended to `placed`.
    /// Read backwards (`dir` Opposite), a past word starts at its last observation and travel
    /// runs the other way, so the past side's travel and turn between two words are negated.
    fn verify(
        &self,
        word_pairs: &[(WordId, WordId)],
        dir: Direction,
        anchors: &[i64],
        newest_only: bool,
        placed: &mut Vec<Option<Placement>>,
    ) -> Option<Rejection> {
        let start = |w: WordId| self.reading_start(w, Direction::Same);
        let past_start = |w: WordId| self.reading_start(w, dir);
        let ok_travel = |a: f64, b: f64| {
            (a - b).abs()
                <= self.params.verify_travel_ratio * a.abs().max(b.abs())
                    + self.params.verify_travel_slack_m
        };
        let turn_tol = self.params.verify_turn_rad;
        let (mut cum_c, mut cum_p) = ((0.0, 0.0), (0.0, 0.0));
        let mut turned: f64 = 0.0;
        for w in word_pairs.windows(2) {
            let (c0, c1) = (start(w[0].0), start(w[1].0));
            let (p0, p1) = (past_start(w[0].1), past_start(w[1].1));
            let dc = (c1.0 - c0.0, wrap_angle(c1.1 - c0.1));
            let dp = (p1.0 - p0.0, wrap_angle(p1.1 - p0.1));
            cum_c = (cum_c.0 + dc.0, cum_c.1 + dc.1);
            cum_p = (cum_p.0 + dp.0, cum_p.1 + dp.1);
            if !ok_travel(dc.0, dp.0) || !ok_travel(cum_c.0, cum_p.0) {
                return Some(Rejection::Travel);
            }
            if wrap_angle(dc.1 - dp.1).abs() > turn_tol || (cum_c.1 - cum_p.1).abs() > turn_tol {
                return Some(Rejection::Turn);
            }
            turned = turned.max(cum_c.1.abs());
        }
        if dir == Direction::Opposite && turned < self.params.reverse_min_turn_rad {
            return Some(Rejection::Straight);
        }
        let (mut sum, mut lateral, mut count) = (0.0, 0.0, 0usize);
        let from = if newest_only { word_pairs.len() - 1 } else { 0 };
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
        if mean(sum) > self.params.verify_max_psi_rms {
            Some(Rejection::Density)
        } else if mean(lateral) > self.params.verify_max_lateral_rms[dir as usize] {
            Some(Rejection::Sides)
        } else {
            None
        }
    }

    /// Σ over the pairs of placement `w` of the squared difference of the observations'
    /// `lateral_moment`, the past side's negated when read backwards (its left is then our right).
    fn lateral_squared_error(&self, c: WordId, p: WordId, dir: Direction, w: &Placement) -> f64 {
        let lateral = self.words.lateral_moments();
        let s2 = self.word(c).first_obs as i64;
        let past = PastSide::of(self.word(p), dir);
        let sign = past.step as f64;
        w.r.clone()
            .map(|i| {
                let q = lateral[(s2 + w.a + i) as usize];
                let d = q - sign * lateral[past.index(w.b + i)];
                d * d
            })
            .sum()
    }

    /// Per word pair of an n-gram (oldest first), the shift k (past index − current index, from
    /// the words' starts as read in direction `dir`) that puts the pair at the travel offset the
    /// whole n-gram agrees on: the median over its word pairs of the offset between the two
    /// words' centres (the past side's travel negated when read backwards).
    fn chain_anchors(
        &self,
        word_pairs: &[(WordId, WordId)],
        dir: Direction,
        offsets: &mut Vec<f64>,
        anchors: &mut Vec<i64>,
    ) {
        // Both boundaries of every word pair, as read: a word of flat Ψ whose boundaries moved
        // shifts its centre, while most boundaries of the n-gram still agree.
        offsets.clear();
        offsets.extend(word_pairs.iter().flat_map(|&(c, p)| {
            let (cw, pw) = (self.word(c), self.word(p));
            match dir {
                Direction::Same => [
                    cw.start_travel_m - pw.start_travel_m,
                    cw.end_travel_m - pw.end_travel_m,
                ],
                Direction::Opposite => [
                    cw.start_travel_m + pw.end_travel_m,
                    cw.end_travel_m + pw.start_travel_m,
                ],
            }
        }));
        offsets.sort_by(f64::total_cmp);
        let offset_m = offsets.get(offsets.len() / 2).copied().unwrap_or(0.0);
        anchors.extend(word_pairs.iter().map(|&(c, p)| {
            let start_gap_m = self.word(c).start_travel_m - self.reading_start(p, dir).0;
            ((start_gap_m - offset_m) / self.params.spacing_m).round() as i64
        }));
    }

    /// Where word `w` begins when read in direction `dir`: (travel, odometric heading) of its
    /// first observation, or read backwards, of its last one with travel negated (so that
    /// differences between words read backwards come out as travelled that way).
    fn reading_start(&self, w: WordId, dir: Direction) -> (f64, f64) {
        self.reading_starts[w as usize][dir as usize]
    }

    /// [`reading_start`](Self::reading_start), from the word's observations.
    fn measure_reading_start(&self, w: WordId, dir: Direction) -> (f64, f64) {
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

    /// Eq. 2: the best placement of the two words' observation windows (see the module doc).
    /// Read in direction `dir`, the past word is its Ψ backwards: offsets count from its last
    /// observation. `anchor` is the n-gram's shift for the pair (used by `alignment = "chain"`).
    fn placement(&self, c: WordId, p: WordId, dir: Direction, anchor: i64) -> Option<Placement> {
        let key = (c, p, dir, anchor);
        if let Some(w) = self.placements.borrow().get(&key) {
            return w.clone();
        }
        let w = self.place(c, p, dir, anchor);
        self.placements.borrow_mut().insert(key, w.clone());
        w
    }

    /// [`placement`](Self::placement), computed.
    fn place(&self, c: WordId, p: WordId, dir: Direction, anchor: i64) -> Option<Placement> {
        let psi = self.words.psi();
        let (cw, pw) = (self.word(c), self.word(p));
        let (sc, sp) = (cw.size as i64, pw.size as i64);
        let n = sc.min(sp);
        let s2 = cw.first_obs as i64;
        let past = PastSide::of(pw, dir);
        let run = self.words.run_range(pw.run);
        let (lo, hi) = (run.start as i64, run.end as i64);
        let dmax = self.params.max_offset as i64;
        // Offset k = past index − current index, from the words' starts (as read): a = start in
        // the current word, b = a + k start in the past word.
        let window = |k: i64| -> Placement {
            let a = (-k).clamp(0, sc - n);
            let b = a + k;
            // Keep the past window inside the past word's run.
            let r = past.inside(lo, hi, b, n);
            Placement { a, b, r, cost: 0.0 }
        };
        let (kmin, kmax) = match self.params.alignment {
            // d ∈ (−Δmax, Δmax): the n-windows from both starts, the past one shifted by d.
            AlignmentMode::Paper => (-(dmax - 1).max(0), (dmax - 1).max(0)),
            // The smaller word at every placement inside the larger one, never past its ends.
            AlignmentMode::WholeWord => (-(sc - n), sp - n),
            // Near the n-gram's shift (past the words' ends if it lies there), or near the
            // placement inside the larger word nearest to it.
            AlignmentMode::Chain => {
                let (lo, hi) = (-(sc - n), sp - n);
                let inside = anchor.clamp(lo, hi);
                let w = self.params.chain_offset as i64;
                (
                    (anchor - w).min((inside - w).max(lo)),
                    (anchor + w).max((inside + w).min(hi)),
                )
            }
        };
        // Whole windows first (Eq. 2 sums over all n observations), then the least mean squared
        // Ψ difference, then (ties) the shift nearest the n-gram's for `chain`, the smallest
        // shift from the words' starts otherwise.
        let mut best: Option<(Placement, i64)> = None;
        let (eps, pivot) = match self.params.alignment {
            AlignmentMode::Chain => (self.params.chain_tie, anchor),
            _ => (1e-15, 0),
        };
        for k in kmin..=kmax {
            let mut w = window(k);
            let count = w.count();
            if count == 0 {
                continue;
            }
            let cur = &psi[(s2 + w.a + w.r.start) as usize..(s2 + w.a + w.r.end) as usize];
            w.cost = past.squared_error(psi, w.b, &w.r, cur) / count as f64;
            let better = match &best {
                None => true,
                Some((bw, bk)) => {
                    count > bw.count()
                        || (count == bw.count()
                            && (w.cost < bw.cost - eps
                                || ((w.cost - bw.cost).abs() <= eps
                                    && (k - pivot).abs() < (bk - pivot).abs())))
                }
            };
            if better {
                best = Some((w, k));
            }
        }
        best.map(|(w, _)| w)
    }

    /// Eq. 2: aligned observation pairs of current word `c` and past word `p` read in direction
    /// `dir` at their `placement` (the one place pairs are made; read backwards, the past id
    /// decreases as the query id increases).
    fn aligned_pairs(
        &self,
        c: WordId,
        p: WordId,
        dir: Direction,
        placement: Option<Placement>,
        out: &mut Vec<AlignedRun>,
    ) {
        let obs = self.words.observations();
        let Some(w) = placement else {
            return;
        };
        let s2 = self.word(c).first_obs as i64;
        let past = PastSide::of(self.word(p), dir);
        if self.ids_are_indices && self.beyond_gap(s2, &past, &w) {
            let (q, pst) = ((s2 + w.a + w.r.start) as usize, past.index(w.b + w.r.start));
            push_run(out, q, pst, past.step as i8, w.count() as u32);
            return;
        }
        for i in w.r {
            let (q, pst) = (&obs[(s2 + w.a + i) as usize], &obs[past.index(w.b + i)]);
            if q.travel_m - pst.travel_m + 1e-9 < self.params.candidate_gap_m {
                continue;
            }
            push_pair(out, q.id, pst.id, past.step as i8);
        }
    }

    /// Whether every pair of placement `w` (current word from observation `s2`) passes the
    /// candidate gap of `aligned_pairs`: travel never decreases with the index, so the first
    /// current observation and the latest past one bound every pair's difference (rounding is
    /// monotone, so the bound holds for the computed differences too).
    fn beyond_gap(&self, s2: i64, past: &PastSide, w: &Placement) -> bool {
        if w.count() == 0 {
            return true;
        }
        let obs = self.words.observations();
        let q_first = obs[(s2 + w.a + w.r.start) as usize].travel_m;
        let (p0, p1) = (past.index(w.b + w.r.start), past.index(w.b + w.r.end - 1));
        let p_max = obs[p0].travel_m.max(obs[p1].travel_m);
        q_first - p_max + 1e-9 >= self.params.candidate_gap_m
    }
}

/// An n-gram that passed the gap and verification, before it is reported; its data is in the
/// matcher's [`Scratch`].
#[derive(Clone, Debug)]
struct Candidate {
    idx: usize,
    dir: Direction,
    /// Its word pairs in `Scratch::{chain, word_pairs, anchors}`, oldest first.
    pairs: std::ops::Range<usize>,
    /// The placements verification made (of its last `placed.len()` word pairs) in
    /// `Scratch::placed`.
    placed: std::ops::Range<usize>,
}

/// The candidates of one word and configuration, back to back, kept between words so that
/// finding and reporting them allocates nothing but the matches.
#[derive(Clone, Debug, Default)]
struct Scratch {
    found: Vec<Candidate>,
    /// Per word pair: (current word, memo index), (current word, past word), the n-gram's shift.
    chain: Vec<(WordId, usize)>,
    word_pairs: Vec<(WordId, WordId)>,
    anchors: Vec<i64>,
    placed: Vec<Option<Placement>>,
    /// Working space of `chain_anchors` and of `emit`.
    offsets: Vec<f64>,
    runs: Vec<AlignedRun>,
}

impl Scratch {
    fn clear(&mut self) {
        self.found.clear();
        self.truncate(0, 0);
    }

    /// Drops the word pairs from `pairs` on and the placements from `placed` on.
    fn truncate(&mut self, pairs: usize, placed: usize) {
        self.chain.truncate(pairs);
        self.word_pairs.truncate(pairs);
        self.anchors.truncate(pairs);
        self.placed.truncate(placed);
    }
}

/// What a placement is a function of while a word is reported: (current word, past word,
/// direction, anchor).
type PlacementKey = (WordId, WordId, Direction, i64);

/// A placement of the alignment: windows start at `a` in the current word and `b` in the past
/// word; `r` the indices within the windows that lie in the past word's run; `cost` the mean
/// squared Ψ difference over them.
#[derive(Clone, Debug)]
struct Placement {
    a: i64,
    b: i64,
    r: std::ops::Range<i64>,
    cost: f64,
}

impl Placement {
    fn count(&self) -> usize {
        (self.r.end - self.r.start).max(0) as usize
    }
}

/// The root mean square Ψ difference over the placements of a match's word pairs (its score's
/// alignment residual, `WordMatch::psi_rms`): kept apart from the matching so that the score is
/// one small function of what the alignment already computed.
#[derive(Default)]
struct PsiResidual {
    sum: f64,
    count: usize,
}

impl PsiResidual {
    fn add(&mut self, placement: Option<&Placement>) {
        if let Some(w) = placement {
            self.sum += w.cost * w.count() as f64;
            self.count += w.count();
        }
    }

    /// The RMS, infinite without an aligned pair.
    fn rms(&self) -> f64 {
        if self.count == 0 {
            f64::INFINITY
        } else {
            (self.sum / self.count as f64).sqrt()
        }
    }
}

/// The past word of an alignment as read: position j of the word read forwards is observation
/// `first + j`; read backwards, `last − j`.
#[derive(Clone, Copy, Debug)]
struct PastSide {
    /// Observation index of position 0 as read.
    base: i64,
    /// +1 forwards, −1 backwards.
    step: i64,
}

impl PastSide {
    fn of(w: &Word, dir: Direction) -> Self {
        match dir {
            Direction::Same => PastSide {
                base: w.first_obs as i64,
                step: 1,
            },
            Direction::Opposite => PastSide {
                base: (w.first_obs + w.size) as i64 - 1,
                step: -1,
            },
        }
    }

    /// Observation index of position `j` as read.
    fn index(&self, j: i64) -> usize {
        (self.base + self.step * j) as usize
    }

    /// The window positions i in 0..n whose observation `index(b + i)` lies in `lo..hi`.
    fn inside(&self, lo: i64, hi: i64, b: i64, n: i64) -> std::ops::Range<i64> {
        if self.step > 0 {
            (lo - self.base - b).max(0)..(hi - self.base - b).min(n)
        } else {
            (self.base - b - hi + 1).max(0)..(self.base - b - lo + 1).min(n)
        }
    }

    /// Σ (Ψ(past at b + i) − cur[i − r.start])² over i in `r`.
    fn squared_error(&self, psi: &[f64], b: i64, r: &std::ops::Range<i64>, cur: &[f64]) -> f64 {
        if self.step > 0 {
            let from = (self.base + b + r.start) as usize;
            squared_error(&psi[from..from + cur.len()], cur)
        } else {
            let last = self.index(b + r.start);
            let past = &psi[last + 1 - cur.len()..=last];
            past.iter()
                .rev()
                .zip(cur)
                .map(|(x, y)| (x - y) * (x - y))
                .sum()
        }
    }
}

/// Σ (a − b)², four lanes at a time.
fn squared_error(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            let d = x[l] - y[l];
            acc[l] += d * d;
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| (x - y) * (x - y)).sum();
    acc[0] + acc[1] + acc[2] + acc[3] + tail
}
