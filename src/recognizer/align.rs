//! Fine alignment of matched word pairs (`[recognizer.alignment]`).
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
//! moved between the visits it was paired metres off; the shift its neighbours agree on holds it.
//!
//! **The rest of the current word** (`fill_max_psi_diff`, not in the paper). Eq. 2 pairs n
//! observations; a current word longer than its match (a boundary that moved) kept the others
//! unpaired though the match places them. Outwards from the window, each further current
//! observation is paired at the window's shift while its Ψ stays within the bound of the past
//! observation's ([`WordMatcher::filled`]).

use super::matcher::WordMatcher;
use super::options::AlignmentMode;
use super::types::{AlignedRun, Direction, push_pair, push_run};
use super::words::{Word, WordId};

impl WordMatcher {
    /// Per word pair of an n-gram (oldest first), the shift k (past index − current index, from
    /// the words' starts as read in direction `dir`) that puts the pair at the travel offset the
    /// whole n-gram agrees on: the median over its word pairs of the offset between the two
    /// words' centres (the past side's travel negated when read backwards).
    pub(super) fn chain_anchors(
        &self,
        word_pairs: &[(WordId, WordId)],
        dir: Direction,
        offsets: &mut Vec<i64>,
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
            .map(total_order_key)
        }));
        // The middle offset in `f64::total_cmp`'s order, sorted as integers (see
        // `total_order_key`): the same value a sort of the offsets puts there.
        offsets.sort_unstable();
        let offset_m = offsets
            .get(offsets.len() / 2)
            .map_or(0.0, |&k| from_total_order_key(k));
        anchors.extend(word_pairs.iter().map(|&(c, p)| {
            let start_gap_m = self.word(c).start_travel_m - self.reading_start(p, dir).0;
            ((start_gap_m - offset_m) / self.spacing_m).round() as i64
        }));
    }

    /// Eq. 2: the best placement of the two words' observation windows (see the module doc).
    /// Read in direction `dir`, the past word is its Ψ backwards: offsets count from its last
    /// observation. `anchor` is the n-gram's shift for the pair (used by `alignment = "chain"`).
    pub(super) fn placement(
        &self,
        c: WordId,
        p: WordId,
        dir: Direction,
        anchor: i64,
    ) -> Option<Placement> {
        let key = (c, p, dir, anchor);
        if let Some(w) = self.placements.borrow().get(&key) {
            return w.clone();
        }
        let w = self.place(c, p, dir, anchor);
        self.placements.borrow_mut().insert(key, w.clone());
        w
    }

    /// [`placement`](Self::placement), computed.
    pub(super) fn place(
        &self,
        c: WordId,
        p: WordId,
        dir: Direction,
        anchor: i64,
    ) -> Option<Placement> {
        let psi = self.words.psi();
        let (cw, pw) = (self.word(c), self.word(p));
        let (sc, sp) = (cw.size as i64, pw.size as i64);
        let n = sc.min(sp);
        let s2 = cw.first_obs as i64;
        let past = PastSide::of(pw, dir);
        let run = self.words.run_range(pw.run);
        let (lo, hi) = (run.start as i64, run.end as i64);
        let dmax = self.align_opts.max_alignment_offset as i64;
        // Offset k = past index − current index, from the words' starts (as read): a = start in
        // the current word, b = a + k start in the past word.
        let window = |k: i64| -> Placement {
            let a = (-k).clamp(0, sc - n);
            let b = a + k;
            // Keep the past window inside the past word's run.
            let r = past.inside(lo, hi, b, n);
            Placement { a, b, r, cost: 0.0 }
        };
        let (kmin, kmax) = match self.align_opts.mode {
            // d ∈ (−Δmax, Δmax): the n-windows from both starts, the past one shifted by d.
            AlignmentMode::Paper => (-(dmax - 1).max(0), (dmax - 1).max(0)),
            // The smaller word at every placement inside the larger one, never past its ends.
            AlignmentMode::WholeWord => (-(sc - n), sp - n),
            // Near the n-gram's shift (past the words' ends if it lies there), or near the
            // placement inside the larger word nearest to it.
            AlignmentMode::Chain => {
                let (lo, hi) = (-(sc - n), sp - n);
                let inside = anchor.clamp(lo, hi);
                let w = self.align_opts.chain_alignment_offset as i64;
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
        let (eps, pivot) = match self.align_opts.mode {
            AlignmentMode::Chain => (self.align_opts.chain_alignment_tie, anchor),
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
    pub(super) fn aligned_pairs(
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
        let w = self.filled(c, p, &past, w);
        if self.ids_are_indices && self.beyond_gap(s2, &past, &w) {
            let (q, pst) = ((s2 + w.a + w.r.start) as usize, past.index(w.b + w.r.start));
            push_run(out, q, pst, past.step as i8, w.count() as u32);
            return;
        }
        for i in w.r {
            let (q, pst) = (&obs[(s2 + w.a + i) as usize], &obs[past.index(w.b + i)]);
            if q.travel_m - pst.travel_m + 1e-9 < self.matcher_opts.candidate_gap_m {
                continue;
            }
            push_pair(out, q.id, pst.id, past.step as i8);
        }
    }

    /// Placement `w` of current word `c` against past word `p` (read as `past`), widened over
    /// the rest of the current word (`fill_max_psi_diff`): outwards from the window, each further
    /// current observation pairs with the past observation the window's shift gives, while that
    /// one lies in the past word's run and their Ψ differ by at most the bound. Eq. 2 pairs n =
    /// min(S₁, S₂) observations; when the current word is the longer (a class boundary moved
    /// between the visits and the word still matched within the size tolerance), its other
    /// observations were left unpaired although the match says where they are. The bound stops
    /// the pairs where the two paths part.
    pub(super) fn filled(&self, c: WordId, p: WordId, past: &PastSide, w: Placement) -> Placement {
        let bound = self.align_opts.fill_max_psi_diff;
        if bound <= 0.0 || w.count() == 0 {
            return w;
        }
        let psi = self.words.psi();
        let cw = self.word(c);
        let current = cw.first_obs as i64..(cw.first_obs + cw.size) as i64;
        let run = self.words.run_range(self.word(p).run);
        let run = run.start as i64..run.end as i64;
        let (q0, b) = (current.start + w.a, w.b);
        let pairs = |i: i64| {
            let (q, pj) = (q0 + i, past.base + past.step * (b + i));
            current.contains(&q)
                && run.contains(&pj)
                && (psi[q as usize] - psi[pj as usize]).abs() <= bound
        };
        let (mut start, mut end) = (w.r.start, w.r.end);
        while pairs(start - 1) {
            start -= 1;
        }
        while pairs(end) {
            end += 1;
        }
        Placement { r: start..end, ..w }
    }

    /// Whether every pair of placement `w` (current word from observation `s2`) passes the
    /// candidate gap of `aligned_pairs`: travel never decreases with the index, so the first
    /// current observation and the latest past one bound every pair's difference (rounding is
    /// monotone, so the bound holds for the computed differences too).
    pub(super) fn beyond_gap(&self, s2: i64, past: &PastSide, w: &Placement) -> bool {
        if w.count() == 0 {
            return true;
        }
        let obs = self.words.observations();
        let q_first = obs[(s2 + w.a + w.r.start) as usize].travel_m;
        let (p0, p1) = (past.index(w.b + w.r.start), past.index(w.b + w.r.end - 1));
        let p_max = obs[p0].travel_m.max(obs[p1].travel_m);
        q_first - p_max + 1e-9 >= self.matcher_opts.candidate_gap_m
    }
}

/// `f64::total_cmp`'s order as an integer (the map it compares by): keys sort as their values
/// do under `total_cmp`, and [`from_total_order_key`] gives the value back bit for bit.
fn total_order_key(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ (((bits >> 63) as u64) >> 1) as i64
}

/// The value of a [`total_order_key`] (the map keeps the sign bit, so it is its own inverse).
fn from_total_order_key(key: i64) -> f64 {
    f64::from_bits((key ^ (((key >> 63) as u64) >> 1) as i64) as u64)
}

/// What a placement is a function of while a word is reported: (current word, past word,
/// direction, anchor).
pub(super) type PlacementKey = (WordId, WordId, Direction, i64);

/// A placement of the alignment: windows start at `a` in the current word and `b` in the past
/// word; `r` the indices within the windows that lie in the past word's run; `cost` the mean
/// squared Ψ difference over them.
#[derive(Clone, Debug)]
pub(super) struct Placement {
    pub(super) a: i64,
    pub(super) b: i64,
    pub(super) r: std::ops::Range<i64>,
    pub(super) cost: f64,
}

impl Placement {
    pub(super) fn count(&self) -> usize {
        (self.r.end - self.r.start).max(0) as usize
    }
}

/// The past word of an alignment as read: position j of the word read forwards is observation
/// `first + j`; read backwards, `last − j`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PastSide {
    /// Observation index of position 0 as read.
    pub(super) base: i64,
    /// +1 forwards, −1 backwards.
    pub(super) step: i64,
}

impl PastSide {
    pub(super) fn of(w: &Word, dir: Direction) -> Self {
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
    pub(super) fn index(&self, j: i64) -> usize {
        (self.base + self.step * j) as usize
    }

    /// The window positions i in 0..n whose observation `index(b + i)` lies in `lo..hi`.
    pub(super) fn inside(&self, lo: i64, hi: i64, b: i64, n: i64) -> std::ops::Range<i64> {
        if self.step > 0 {
            (lo - self.base - b).max(0)..(hi - self.base - b).min(n)
        } else {
            (self.base - b - hi + 1).max(0)..(self.base - b - lo + 1).min(n)
        }
    }

    /// Σ (Ψ(past at b + i) − cur[i − r.start])² over i in `r`.
    pub(super) fn squared_error(
        &self,
        psi: &[f64],
        b: i64,
        r: &std::ops::Range<i64>,
        cur: &[f64],
    ) -> f64 {
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

/// The root mean square Ψ difference over the placements of a match's word pairs (its score's
/// alignment residual, `WordMatch::psi_rms`): kept apart from the matching so that the score is
/// one small function of what the alignment already computed.
#[derive(Default)]
pub(super) struct PsiResidual {
    sum: f64,
    count: usize,
}

impl PsiResidual {
    pub(super) fn add(&mut self, placement: Option<&Placement>) {
        if let Some(w) = placement {
            self.sum += w.cost * w.count() as f64;
            self.count += w.count();
        }
    }

    /// The RMS, infinite without an aligned pair.
    pub(super) fn rms(&self) -> f64 {
        if self.count == 0 {
            f64::INFINITY
        } else {
            (self.sum / self.count as f64).sqrt()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn any_f64() -> impl Strategy<Value = f64> {
        prop_oneof![
            -1e3f64..1e3,
            any::<u64>().prop_map(f64::from_bits),
            Just(0.0),
            Just(-0.0),
        ]
    }

    proptest! {
        /// Keys sort as `f64::total_cmp` sorts their values (NaNs and signed zeros included),
        /// and give them back bit for bit: the median offset is the plain sort's.
        #[test]
        fn total_order_keys_sort_as_total_cmp(xs in proptest::collection::vec(any_f64(), 0..40)) {
            let mut plain = xs.clone();
            plain.sort_by(f64::total_cmp);
            let mut keys: Vec<i64> = xs.iter().copied().map(total_order_key).collect();
            keys.sort_unstable();
            let back: Vec<u64> = keys.into_iter().map(|k| from_total_order_key(k).to_bits()).collect();
            prop_assert_eq!(back, plain.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        }
    }
}
