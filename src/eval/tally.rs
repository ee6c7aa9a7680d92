//! Scoring as matches arrive: the one implementation of the counting rules of
//! [`super::metrics`] (docs/design.md, Evaluation), fed one match at a time.
//!
//! A [`Tally`] learns the truth and the observations as they are made ([`Tally::sync`]), counts
//! each match's pairs the moment it arrives ([`Tally::add`]) and keeps of them only what the
//! rules still need:
//!
//! - **Deduplication.** A pair counts once however many matches repeat it, so the tally keeps
//!   the distinct pairs it has counted, but only those whose query lies at or after the
//!   recognizer's *query horizon* ([`crate::place::PlaceRecognizer::query_horizon`]): no later
//!   match can name an older query, so [`Tally::evict_below`] forgets the pairs behind it. A
//!   recognizer that promises nothing (horizon 0) has every distinct pair kept to the end, as
//!   before. A pair that arrives behind the horizon anyway is counted and reported in
//!   [`Metrics::late_pairs`] (always 0 for a recognizer that keeps its promise; tests check it).
//! - **Recall.** Per observation, one flag per figure: the query (or either side) of a correct
//!   pair.
//! - **Visit recall.** The earlier laps each query observation was correctly paired with, one
//!   packed `u64` per (observation, lap), not per pair (appended as pairs come, merged whenever
//!   the list doubles).
//! - **Pair recall.** The count of distinct correct pairs.
//!
//! A pair that comes again with the claim it was counted with (later matches of a chain repeat
//! most of the earlier ones' pairs) only counts in its match: its map entry is the one lookup.
//!
//! What needs every observation's truth (which observations have a revisit, which earlier laps
//! pass there, how many pairs could have been found) is computed at [`Tally::finish`] from the
//! truth sites: the earlier laps at `tp_radius_m` in one sweep of the lap grid
//! (`eval::lap_grid`), which also gives the revisits at that radius of every facing, and the
//! revisits at the other radii and the possible pairs from the k-d tree of
//! [`super::site_tree`]. So memory grows with the observations and with the
//! (observation, lap) pairs found, never with the aligned pairs: `placewords run` and
//! `recognize` score a thousand-lap run this way while it is recognized ([`super::Recording`]),
//! and [`super::evaluate`] scores a finished recognition by feeding its matches in order.

use super::GroundTruth;
use super::lap_grid::{LapSweep, Laps};
use super::metrics::{Counts, DirectionMetrics, DoorConfigMetrics, Evaluation, Metrics, Scorer};
use super::pair_recall::{Facing, PairRecall, count_possible, count_possible_facings};
use super::pair_set::pack;
use super::ranking::Ranking;
use super::site_tree::{Site, SiteTree};
use crate::place::{Direction, Match, ObsId, Observation};
use crate::spec::evaluation::EvaluationSpec;
// foldhash: the keys are packed indices, not adversarial input, and SipHash stood high in the
// profile of scoring as matches arrive (BENCHMARKS.md, issue 30).
use super::pair_set::RunSet;
use foldhash::{HashMap, HashSet};

/// What a tally counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// Everything [`Evaluation`] holds: every radius, per door configuration, per direction,
    /// visit and pair recall.
    Full,
    /// The top-level figures at `tp_radius_m` only, without visit and pair recall (sweeps).
    Main,
}

/// Index of a facing in the per-pair flags.
fn facing_bit(f: Facing) -> u8 {
    match f {
        Facing::Either => 0,
        Facing::Same => 1,
        Facing::Opposite => 2,
    }
}

/// One figure: a facing at a radius.
#[derive(Clone, Debug)]
struct Slot {
    facing: Facing,
    radius_m: f64,
    /// Counted per door configuration too.
    breakdown: bool,
    /// Visit and pair recall counted too.
    recalls: bool,
    counts: Counts,
    per_cfg: Vec<Counts>,
    /// Per observation: the query of a correct pair.
    recalled_query: Bits,
    /// Per observation: either side of a correct pair.
    recalled_any: Bits,
    /// Distinct pairs found that could have been found (pair recall's numerator).
    found: u64,
    /// The match being counted: its distinct pairs, the correct ones, its door configuration.
    n: usize,
    ok: usize,
    cfg: Option<usize>,
}

impl Slot {
    fn new(facing: Facing, radius_m: f64, breakdown: bool, recalls: bool) -> Self {
        Slot {
            facing,
            radius_m,
            breakdown,
            recalls,
            counts: Counts::default(),
            per_cfg: Vec::new(),
            recalled_query: Bits::default(),
            recalled_any: Bits::default(),
            found: 0,
            n: 0,
            ok: 0,
            cfg: None,
        }
    }
}

/// Scores matches as they arrive (see the module doc).
pub struct Tally {
    spec: EvaluationSpec,
    scorer: Scorer,
    slots: Vec<Slot>,
    /// Distinct resolved pairs `(query, past)` (observation indices) at or after the horizon,
    /// claimed the same way (0) and the opposite way (1), as runs along the lines of the
    /// matches' runs (`pair_set::RunSet`: a chain's matches repeat each other's pairs along
    /// one line, so a lookup reads a small map of lines, not a table of every pair, which was
    /// scoring's main cost in a `check`: BENCHMARKS.md, session 5). Whether a pair was found
    /// for pair recall follows from the claims it was seen with ([`could_be_found`]).
    window: [RunSet; 2],
    /// Pairs naming an unknown observation (by ids) → seen by facing; never forgotten (a
    /// recognizer that names unknown observations is broken, not long-running).
    unresolved: HashMap<u64, u8>,
    /// (query index, lap, claims: bit 0 same, bit 1 opposite) of the correct pairs, packed
    /// `query << 32 | lap << 2 | claims`: appended as pairs arrive (no lookup per pair) and
    /// compacted (`compact_visits`) whenever it doubles, so it holds at most about twice the
    /// distinct (query, lap) entries.
    visits: Vec<u64>,
    /// Length of `visits` after its last compaction.
    visits_compact: usize,
    /// `visits` is not compacted below this length (a test lowers it).
    visits_compact_min: usize,
    /// Query indices below this were forgotten.
    evicted_below: usize,
    late_pairs: usize,
    /// Pairs forgotten since the last [`Tally::take_forgotten`], when asked to keep them.
    forgotten: Option<Vec<u64>>,
    in_match: HashSet<(ObsId, ObsId)>,
    /// Searches with the k-d tree of every earlier site ([`Self::by_site_tree`]).
    by_site_tree: bool,
    /// Visit recall counted as the horizon passes ([`VisitStream`]); `None` without visit
    /// recall (or `tp_radius_m` not positive) and for the reference searches.
    stream: Option<VisitStream>,
}

/// Visit recall counted while a run is scored. Once the horizon passes an observation no later
/// match names it as query, so its visits are final: the lap grid's sweep, resumed up to there
/// ([`Scorer::sweep_laps_below`]), gives the earlier laps that revisit it, its visits are
/// counted ([`LapCount`]) and their entries dropped. `Tally::visits` then holds the
/// observations at or after the horizon, not every (observation, lap) found, which on a
/// thousand-lap run of one loop with every look-alike a candidate grew with the laps squared
/// (BENCHMARKS.md). The counts are those of the one sweep at the end, bar a visit of a late
/// pair (one behind the horizon, [`Metrics::late_pairs`]: a recognizer breaking its promise),
/// which is not counted.
struct VisitStream {
    r_m: f64,
    sweep: LapSweep<2>,
    count: LapCount,
    /// Per facing (as [`facing_bit`]), per observation swept: an earlier lap revisits it.
    revisits: [Vec<bool>; 3],
}

impl Tally {
    /// An empty tally counting `scope` with `spec`'s rules.
    pub fn new(spec: &EvaluationSpec, scope: Scope) -> Self {
        Self::with_scorer(spec, scope, Scorer::empty(spec))
    }

    /// A tally over the observations and truth `scorer` already joined (no [`Self::sync`]).
    pub fn over(scorer: &Scorer, spec: &EvaluationSpec, scope: Scope) -> Self {
        let mut t = Self::with_scorer(spec, scope, scorer.clone());
        t.grow_slots();
        t
    }

    fn with_scorer(spec: &EvaluationSpec, scope: Scope, scorer: Scorer) -> Self {
        let r = spec.tp_radius_m;
        let mut slots = vec![Slot::new(
            Facing::Either,
            r,
            scope == Scope::Full,
            scope == Scope::Full,
        )];
        if scope == Scope::Full {
            slots.extend(
                spec.sensitivity_radii_m
                    .iter()
                    .map(|&s| Slot::new(Facing::Either, s, false, false)),
            );
            slots.push(Slot::new(Facing::Same, r, false, true));
            slots.push(Slot::new(Facing::Opposite, r, false, true));
        }
        let stream = match scope {
            Scope::Full => scorer.lap_sweep(r).map(|sweep| VisitStream {
                r_m: r,
                sweep,
                count: LapCount::default(),
                revisits: Default::default(),
            }),
            Scope::Main => None,
        };
        Tally {
            spec: spec.clone(),
            scorer,
            slots,
            window: Default::default(),
            unresolved: HashMap::default(),
            visits: Vec::new(),
            visits_compact: 0,
            visits_compact_min: 1 << 16,
            evicted_below: 0,
            late_pairs: 0,
            forgotten: None,
            in_match: HashSet::default(),
            by_site_tree: false,
            stream,
        }
    }

    /// Searches as the scoring did before it was linear in the laps (the k-d tree of every
    /// earlier site): the reference of `metrics::evaluate_by_site_tree`.
    pub(super) fn by_site_tree(&mut self) {
        self.by_site_tree = true;
        self.stream = None;
    }

    /// Keep the distinct resolved pairs forgotten by [`Self::evict_below`] until
    /// [`Self::take_forgotten`] (to compare level configurations, `Report::set_level_gains`).
    pub fn keep_forgotten(&mut self) {
        self.forgotten.get_or_insert_with(Vec::new);
    }

    /// Learns the laps, frames and observations added to `truth` and `observations` since the
    /// last call (both only ever grow; call before adding matches that name new observations).
    pub fn sync(&mut self, observations: &[Observation], truth: &GroundTruth) {
        self.scorer.sync(observations, truth);
        self.grow_slots();
    }

    /// Sizes the per-observation and per-configuration tables to what is known.
    fn grow_slots(&mut self) {
        let (n, configs) = (self.scorer.observation_count(), self.scorer.config_count());
        for s in &mut self.slots {
            s.recalled_query.resize(n);
            s.recalled_any.resize(n);
            if s.breakdown {
                s.per_cfg.resize(configs, Counts::default());
            }
        }
    }

    /// Counts match `m` (its observations must be synced).
    pub fn add(&mut self, m: &Match) {
        self.add_ranked(m, None);
    }

    /// [`Self::add`], and each resolved pair's answer given to `ranking` (as
    /// [`Ranking::add`] would give it, in the same order) in the same pass over the pairs.
    pub fn add_ranked(&mut self, m: &Match, mut ranking: Option<&mut Ranking>) {
        let claim = Facing::of(m.direction);
        for s in &mut self.slots {
            (s.n, s.ok, s.cfg) = (0, 0, None);
        }
        self.in_match.clear();
        // Pairs repeat within a match only where its runs' queries overlap (a run's queries are
        // distinct), so the set of the match's pairs is kept only then.
        let may_repeat = !queries_disjoint(m);
        for run in &m.runs {
            for (query, past) in run.pairs() {
                let Some(pair) = self.scorer.resolve(query, past) else {
                    self.add_unresolved(query, past, m.direction);
                    continue;
                };
                let new_in_match = !may_repeat || self.in_match.insert((query, past));
                let right = self.add_pair(pair, run.past_step, claim, new_in_match);
                if let Some(r) = ranking.as_deref_mut() {
                    r.answer(pair.0, m.score, right);
                }
            }
        }
        let counts = |s: &Slot| s.facing.counts(m.direction);
        for s in self.slots.iter_mut().filter(|s| counts(s) && s.n > 0) {
            let good = 2 * s.ok > s.n;
            s.counts.matches += 1;
            s.counts.correct_matches += usize::from(good);
            if let (true, Some(c)) = (s.breakdown, s.cfg) {
                s.per_cfg[c].matches += 1;
                s.per_cfg[c].correct_matches += usize::from(good);
            }
        }
    }

    /// Counts a pair naming an unknown observation, claimed as `direction` says.
    fn add_unresolved(&mut self, query: ObsId, past: ObsId, direction: Direction) {
        let claim_bit = facing_bit(Facing::of(direction));
        let flags = self.unresolved.entry(pack(query, past)).or_insert(0);
        let before = *flags;
        for s in self.slots.iter_mut().filter(|s| s.facing.counts(direction)) {
            if before & (1 << facing_bit(s.facing)) == 0 {
                s.counts.unresolved += 1;
            }
        }
        *flags |= 1 | (1 << claim_bit);
    }

    /// Counts resolved pair `(qi, pi, q, pa)` (positions and sites) of a run of step `step` of
    /// a match claiming `claim` (`new_in_match`: not yet counted in this match). Returns
    /// whether the pair is a right answer by the ranking's rule ([`Ranking::add`]).
    fn add_pair(
        &mut self,
        (qi, pi, q, pa): (usize, usize, Site, Site),
        step: i8,
        claim: Facing,
        new_in_match: bool,
    ) -> bool {
        let tol = self.scorer.heading_tol_rad();
        let r_main = self.spec.tp_radius_m;
        if qi < self.evicted_below {
            self.late_pairs += 1;
        }
        let d2 = (q.x - pa.x).powi(2) + (q.y - pa.y).powi(2);
        let agrees = claim.agrees(q.theta, pa.theta, tol);
        let right =
            d2 <= r_main * r_main && agrees && q.travel_m - pa.travel_m >= self.spec.min_gap_m;
        let counts = |s: &Slot| s.facing == Facing::Either || s.facing == claim;
        let cfg = self.scorer.config(qi);
        let (own, other) = claim_sets(&mut self.window, claim);
        if own.contains(qi, pi) {
            // Seen with this claim: every figure counting it has counted it, its pair recall
            // and visit were recorded then (the same test of the same pair), so only the
            // match's own tally is left.
            if new_in_match {
                for s in self.slots.iter_mut().filter(|s| counts(s)) {
                    s.n += 1;
                    s.ok += usize::from(d2 <= s.radius_m * s.radius_m && agrees);
                    s.cfg.get_or_insert(cfg);
                }
            }
            return right;
        }
        own.insert(qi, pi, step);
        // What was recorded when the pair came with the other claim: seen (either facing and
        // that one) and, where it could have been found so, found.
        let mut before = 0u8;
        if !other.is_empty() && other.contains(qi, pi) {
            let other_claim = match claim {
                Facing::Same => Facing::Opposite,
                _ => Facing::Same,
            };
            before = 1 | 1 << facing_bit(other_claim);
            if self.slots.iter().any(|s| s.recalls)
                && could_be_found(&self.scorer, &self.spec, (qi, &q), (pi, &pa), other_claim)
            {
                before |= 1 << 3 | 1 << (3 + facing_bit(other_claim));
            }
        }
        let mut recalls = false;
        for s in self.slots.iter_mut().filter(|s| counts(s)) {
            let correct = d2 <= s.radius_m * s.radius_m && agrees;
            recalls |= s.recalls;
            if new_in_match {
                s.n += 1;
                s.ok += usize::from(correct);
                s.cfg.get_or_insert(cfg);
            }
            if before & (1 << facing_bit(s.facing)) == 0 {
                s.counts.pairs += 1;
                s.counts.correct += usize::from(correct);
                if s.breakdown {
                    s.per_cfg[cfg].pairs += 1;
                    s.per_cfg[cfg].correct += usize::from(correct);
                }
                if correct {
                    s.recalled_query.set(qi);
                    s.recalled_any.set(qi);
                    s.recalled_any.set(pi);
                }
            }
        }
        if recalls && could_be_found(&self.scorer, &self.spec, (qi, &q), (pi, &pa), claim) {
            for s in self.slots.iter_mut().filter(|s| s.recalls && counts(s)) {
                s.found += u64::from(before & 1 << (3 + facing_bit(s.facing)) == 0);
            }
        }
        if recalls && d2 <= r_main * r_main && agrees {
            self.push_visit(qi, pa.lap, if claim == Facing::Same { 1 } else { 2 });
        }
        right
    }

    /// Records that query `qi` was correctly paired with lap `lap` by a match claiming
    /// `claims` (1 same, 2 opposite), merging the list whenever it doubles.
    fn push_visit(&mut self, qi: usize, lap: usize, claims: u64) {
        self.visits
            .push((qi as u64) << 32 | (lap as u64) << 2 | claims);
        if self.visits.len() >= 2 * self.visits_compact.max(self.visits_compact_min) {
            compact_visits(&mut self.visits, self.visits_compact);
            self.visits_compact = self.visits.len();
        }
    }

    /// Forgets the pairs whose query index is below `query_index` (a recognizer's query horizon:
    /// no later match names such a query).
    pub fn evict_below(&mut self, query_index: usize) {
        let h = query_index.min(self.scorer.observation_count());
        if h <= self.evicted_below {
            return;
        }
        let gone = self.forgotten.as_mut();
        match gone {
            Some(gone) => {
                let from = gone.len();
                self.window
                    .iter_mut()
                    .for_each(|w| w.remove_below(h, Some(&mut *gone)));
                // Sorted within the eviction; a pair claimed both ways is listed once.
                let mut tail = gone.split_off(from);
                tail.sort_unstable();
                tail.dedup();
                gone.append(&mut tail);
            }
            None => self.window.iter_mut().for_each(|w| w.remove_below(h, None)),
        }
        self.evicted_below = h;
        self.count_visits_below(h);
    }

    /// Counts the visit recall of the observations below `h` (behind the horizon: their visits
    /// are final) and drops their visit entries ([`VisitStream`]).
    fn count_visits_below(&mut self, h: usize) {
        let Some(mut stream) = self.stream.take() else {
            return;
        };
        compact_visits(&mut self.visits, self.visits_compact);
        let n = self.scorer.observation_count();
        let VisitStream {
            sweep,
            count,
            revisits,
            ..
        } = &mut stream;
        revisits.iter_mut().for_each(|v| v.resize(n, false));
        count.at = 0;
        self.scorer
            .sweep_laps_below(sweep, h, |i, [same, opposite]| {
                revisits[0][i] = !same.is_empty() || !opposite.is_empty();
                revisits[1][i] = !same.is_empty();
                revisits[2][i] = !opposite.is_empty();
                count.add(self, i, same, opposite);
            });
        let below = self.visits.partition_point(|&v| ((v >> 32) as usize) < h);
        self.visits.drain(..below);
        self.visits_compact = self.visits.len();
        self.stream = Some(stream);
    }

    /// The distinct resolved pairs forgotten since the last call, packed `(query, past)`
    /// indices, sorted within each eviction (see [`Self::keep_forgotten`]).
    pub fn take_forgotten(&mut self) -> Vec<u64> {
        self.forgotten
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Whether the pair of observation indices `(q, p)` is within `tp_radius_m` (true
    /// positions, no heading test: a level configuration's gain counts it correct so).
    pub fn within_radius(&self, q: usize, p: usize) -> bool {
        self.scorer.within(q, p, self.spec.tp_radius_m)
    }

    /// Pairs held to deduplicate (those at or after the horizon; a pair claimed both ways, or
    /// along two lines, counts twice).
    pub fn pairs_held(&self) -> usize {
        self.window.iter().map(RunSet::len).sum()
    }

    /// Pairs that arrived behind the horizon so far (see [`Metrics::late_pairs`]).
    pub fn late_pairs(&self) -> usize {
        self.late_pairs
    }

    /// Observations synced so far.
    pub fn observations(&self) -> usize {
        self.scorer.observation_count()
    }

    /// The top-level figures at `tp_radius_m` (a [`Scope::Main`] tally), with the revisits at
    /// that radius when already computed.
    pub fn finish_main(self, revisits: Option<&[bool]>) -> Metrics {
        let r = self.spec.tp_radius_m;
        let computed;
        let revisits = match revisits {
            Some(v) => v,
            None => {
                computed = self.scorer.revisits(r);
                &computed
            }
        };
        let mut metrics = self.slots[0].metrics(revisits, &self.scorer).0;
        metrics.late_pairs = self.late_pairs;
        metrics
    }

    /// Every figure (a [`Scope::Full`] tally) of the observations synced ([`Self::sync`] the
    /// last ones first).
    pub fn finish(self, truth: &GroundTruth) -> Evaluation {
        self.finish_sharing(truth, &mut SharedTruth::default())
    }

    /// [`Self::finish`], taking what depends on the truth and the observations alone from
    /// `shared` when an earlier tally over the same observations, truth and rules left it
    /// there, and leaving this tally's there for the next.
    pub fn finish_sharing(mut self, truth: &GroundTruth, shared: &mut SharedTruth) -> Evaluation {
        self.evict_below(usize::MAX);
        compact_visits(&mut self.visits, self.visits_compact);
        let n = self.scorer.observation_count();
        let streamed = self.stream.take().map(|mut s| {
            s.revisits.iter_mut().for_each(|v| v.resize(n, false));
            let sweep = VisitSweep {
                recall: s.count.recall(),
                revisits: Some(s.revisits),
                lists: None,
            };
            (s.r_m, sweep)
        });
        let own_recall = streamed.as_ref().map(|(r, v)| (*r, v.recall));
        let slots: Vec<(Facing, u64)> = self
            .slots
            .iter()
            .map(|s| (s.facing, s.radius_m.to_bits()))
            .collect();
        let sites = self.frame_sites(truth);
        let reuse = shared.kept.take().filter(|t| {
            !self.by_site_tree
                && t.slots == slots
                && t.spec == self.spec
                && t.frame_sites == sites
                && t.scorer.same_truth_side(&self.scorer)
        });
        let fresh = reuse.is_none();
        let keep = shared.tallies > 1 && !self.by_site_tree;
        shared.tallies = shared.tallies.saturating_sub(1);
        let side = match reuse {
            Some(side) => side,
            None => self.truth_side(sites, slots, keep, streamed),
        };
        let mut metrics: Vec<(Metrics, Vec<DoorConfigMetrics>)> = Vec::new();
        let mut recalls_of: Vec<(f64, [f64; 3])> = Vec::new();
        for (k, s) in self.slots.iter().enumerate() {
            let scorer = self.scorer.with_facing(s.facing);
            let bit = usize::from(facing_bit(s.facing));
            let swept = side.sweeps.iter().rfind(|w| w.0 == s.radius_m);
            let revisits = match (&side.own[k], swept.and_then(|w| w.1.as_ref())) {
                (Some(v), _) => v,
                (None, Some(by_facing)) => &by_facing[bit],
                (None, None) => unreachable!("every figure's revisits are counted"),
            };
            let (mut m, cfgs) = s.metrics(revisits, &scorer);
            if s.recalls {
                let recalls = match recalls_of.iter().find(|w| w.0 == s.radius_m) {
                    Some(w) => w.1,
                    None => {
                        let recall = match (own_recall, swept) {
                            (Some((r, own)), _) if r == s.radius_m => own,
                            (_, Some(w)) if fresh => w.3,
                            (_, Some((_, _, Some(lists), _))) => lists.recall(&self),
                            _ => self.visit_recalls(s.radius_m, false).recall,
                        };
                        recalls_of.push((s.radius_m, recall));
                        recall
                    }
                };
                m.visit_recall = recalls[bit];
                let possible = side
                    .possible_of
                    .iter()
                    .find(|(f, r_bits, _)| *f == s.facing && *r_bits == s.radius_m.to_bits())
                    .map_or(0, |p| p.2);
                m.pair_recall = PairRecall {
                    possible,
                    found: s.found,
                }
                .ratio();
            }
            m.late_pairs = self.late_pairs;
            metrics.push((m, cfgs));
        }
        if keep {
            shared.kept = Some(side);
        }
        let n_sens = self.spec.sensitivity_radii_m.len();
        let mut it = metrics.into_iter();
        // A `Scope::Main` tally has the first figure only; the others stay empty.
        let (mut main, door_configs) = it.next().unwrap_or_default();
        let sensitivity = it.by_ref().take(n_sens).map(|(m, _)| m).collect();
        let (same, opposite) = (
            it.next().unwrap_or_default().0,
            it.next().unwrap_or_default().0,
        );
        // A chain follows one direction: the stretch the figure promises is the longer of the
        // two directions', not one that turns from same-direction revisits to opposite ones.
        main.longest_revisit_m = super::metrics::longest_of_directions(&main, &same, &opposite);
        let recognized = self.recognized(n);
        Evaluation {
            main,
            sensitivity,
            door_configs,
            directions: DirectionMetrics { same, opposite },
            recognized,
        }
    }

    /// Per observation of the `n`: the newer side of a correct pair at `tp_radius_m` (the first
    /// figure's, either direction).
    fn recognized(&self, n: usize) -> Vec<bool> {
        match self.slots.first() {
            Some(s) => (0..n).map(|i| s.recalled_query.get(i)).collect(),
            None => Vec::new(),
        }
    }

    /// What the figures need from the truth and the observations alone (see
    /// [`SharedTruth`]): the revisits of every figure, the laps that revisit each observation
    /// at each radius with visit recall, pair recall's possible pairs.
    /// `keep`: keep the laps that revisit each observation, for the next tally. `streamed`:
    /// the sweep counted as the run was scored ([`VisitStream`]), at its radius.
    fn truth_side(
        &self,
        frame_sites: Vec<Site>,
        slots: Vec<(Facing, u64)>,
        keep: bool,
        mut streamed: Option<(f64, VisitSweep)>,
    ) -> TruthSide {
        // Every figure with visit recall is at `tp_radius_m`; its sweep of the earlier laps
        // also tells which observations have a revisit there, of every facing.
        let mut sweeps: Vec<Swept> = Vec::new();
        let mut swept: Vec<bool> = Vec::new();
        for s in &self.slots {
            if s.recalls && sweeps.iter().all(|w| w.0 != s.radius_m) {
                let v = match streamed.take_if(|(r, _)| *r == s.radius_m) {
                    Some((_, v)) => v,
                    None => self.visit_recalls(s.radius_m, keep),
                };
                sweeps.push((s.radius_m, v.revisits, v.lists, v.recall));
            }
            swept.push(sweeps.iter().any(|w| w.0 == s.radius_m && w.1.is_some()));
        }
        // The revisits no sweep gave: per facing, every radius in one sweep of one k-d tree.
        let mut own: Vec<Option<Vec<bool>>> = vec![None; self.slots.len()];
        for facing in [Facing::Either, Facing::Same, Facing::Opposite] {
            let at: Vec<usize> = (0..self.slots.len())
                .filter(|&k| !swept[k] && self.slots[k].facing == facing)
                .collect();
            if at.is_empty() {
                continue;
            }
            let radii: Vec<f64> = at.iter().map(|&k| self.slots[k].radius_m).collect();
            let scorer = self.scorer.with_facing(facing);
            let found = if self.by_site_tree {
                // The reference: a sweep of its own per radius.
                radii.iter().map(|&r| scorer.revisits(r)).collect()
            } else {
                scorer.revisits_at(&radii)
            };
            for (k, v) in at.into_iter().zip(found) {
                own[k] = Some(v);
            }
        }
        let mut possible_of = Vec::new();
        let mut tree = None;
        for s in self.slots.iter().filter(|s| s.recalls) {
            self.possible(
                &frame_sites,
                &mut tree,
                s.radius_m,
                s.facing,
                &mut possible_of,
            );
        }
        drop(tree);
        TruthSide {
            scorer: self.scorer.clone(),
            spec: self.spec.clone(),
            slots,
            frame_sites,
            sweeps,
            own,
            possible_of,
        }
    }

    /// Pair recall's possible pairs at radius `r` facing as `facing` says (`known`: the counts
    /// made so far, `tree`: the k-d tree of `sites`, built when first needed). Every facing at
    /// `r` is counted in one sweep that walks the tree once per site for all of them; with a
    /// heading tolerance below 90° no pair faces both the same and the opposite way, so the
    /// pairs of either facing are those of the two counted apart (the reference,
    /// [`Self::by_site_tree`], counts each facing in a sweep of its own, either too).
    fn possible<'s>(
        &self,
        sites: &'s [Site],
        tree: &mut Option<SiteTree<'s>>,
        r: f64,
        facing: Facing,
        known: &mut Vec<(Facing, u64, u64)>,
    ) -> u64 {
        if r <= 0.0 || !r.is_finite() {
            return 0;
        }
        let find = |known: &[(Facing, u64, u64)]| {
            known
                .iter()
                .find(|(f, r_bits, _)| *f == facing && *r_bits == r.to_bits())
                .map(|&(.., n)| n)
        };
        if let Some(n) = find(known) {
            return n;
        }
        let (gap, tol) = (self.spec.min_gap_m, self.scorer.heading_tol_rad());
        if self.by_site_tree {
            let n = count_possible(sites, gap, r, facing, tol);
            known.push((facing, r.to_bits(), n));
            return n;
        }
        let tree = tree.get_or_insert_with(|| SiteTree::new(sites));
        let (same, opposite) = (Facing::Same, Facing::Opposite);
        let either = if tol < std::f64::consts::FRAC_PI_2 - 1e-6 {
            let [s, o] = count_possible_facings(tree, gap, r, [same, opposite], tol);
            known.extend([(same, r.to_bits(), s), (opposite, r.to_bits(), o)]);
            s + o
        } else {
            let [e, s, o] =
                count_possible_facings(tree, gap, r, [Facing::Either, same, opposite], tol);
            known.extend([(same, r.to_bits(), s), (opposite, r.to_bits(), o)]);
            e
        };
        known.push((Facing::Either, r.to_bits(), either));
        find(known).unwrap_or(0)
    }

    /// Visit recall at radius `r` of each facing, indexed as [`facing_bit`]: the earlier laps
    /// each observation was correctly paired with ÷ the earlier laps that revisit it. The laps
    /// of either facing are the union of those of the same and the opposite facing, found in
    /// one sweep of the lap grid ([`Scorer::sweep_laps`]), which also tells which observations
    /// have a revisit of each facing (an earlier lap revisits them so): the revisits at `r`
    /// need no search of their own.
    fn visit_recalls(&self, r: f64, record: bool) -> VisitSweep {
        if r <= 0.0 || !r.is_finite() {
            return VisitSweep {
                recall: [0.0; 3],
                revisits: None,
                lists: None,
            };
        }
        if self.by_site_tree {
            // The reference counts the revisits apart ([`Scorer::revisits`]).
            return VisitSweep {
                recall: [Facing::Either, Facing::Same, Facing::Opposite]
                    .map(|f| self.visit_recall_by_site_tree(r, f)),
                revisits: None,
                lists: None,
            };
        }
        let mut count = LapCount::default();
        // An observation has a revisit of a facing when an earlier lap revisits it so (either:
        // the same or the opposite way); those without truth have none.
        let n = self.scorer.observation_count();
        let mut revisits = [vec![false; n], vec![false; n], vec![false; n]];
        let mut lists = record.then(LapLists::default);
        self.scorer.sweep_laps(r, |i, [same, opposite]| {
            revisits[0][i] = !same.is_empty() || !opposite.is_empty();
            revisits[1][i] = !same.is_empty();
            revisits[2][i] = !opposite.is_empty();
            count.add(self, i, same, opposite);
            if let Some(l) = &mut lists {
                l.push(i, same, opposite);
                if l.laps.len() > LapLists::MAX_LAPS {
                    lists = None;
                }
            }
        });
        VisitSweep {
            recall: count.recall(),
            revisits: Some(revisits),
            lists,
        }
    }

    /// Visit recall at radius `r` of one facing, the laps from the k-d tree of every earlier
    /// site: the reference of [`Self::visit_recalls`].
    fn visit_recall_by_site_tree(&self, r: f64, facing: Facing) -> f64 {
        let need: u64 = match facing {
            Facing::Either => 3,
            Facing::Same => 1,
            Facing::Opposite => 2,
        };
        let mut mark: Vec<u8> = Vec::new();
        let mut at = 0usize;
        let (mut visits, mut found) = (0usize, 0usize);
        self.scorer
            .with_facing(facing)
            .sweep_laps_by_site(r, |i, laps| {
                visits += laps.len();
                for &l in laps {
                    if mark.len() <= l {
                        mark.resize(l + 1, 0);
                    }
                    mark[l] = 1;
                }
                found += self
                    .visits_of(i, &mut at)
                    .iter()
                    .filter(|&&v| v & need != 0 && lap_mark(&mark, v) != 0)
                    .count();
                for &l in laps {
                    mark[l] = 0;
                }
            });
        super::metrics::ratio(found, visits)
    }

    /// The entries of `visits` of observation `i`, one per lap it was correctly paired with;
    /// `at` walks `visits` once for observations asked about in increasing order.
    fn visits_of(&self, i: usize, at: &mut usize) -> &[u64] {
        let base = (i as u64) << 32;
        *at += self.visits[*at..].partition_point(|&v| v < base);
        let end = *at + self.visits[*at..].partition_point(|&v| v >> 32 == i as u64);
        let entries = &self.visits[*at..end];
        *at = end;
        entries
    }

    /// Pair recall's sites: each observation's frame truth (not moved to the observation).
    fn frame_sites(&self, truth: &GroundTruth) -> Vec<Site> {
        (0..self.scorer.observation_count())
            .filter_map(|i| {
                let f = truth.frame(self.scorer.frame_of(i))?;
                Some(Site {
                    x: f.pose.0.x,
                    y: f.pose.0.y,
                    theta: f.pose.0.theta,
                    travel_m: f.travel_m,
                    lap: f.lap_slot,
                })
            })
            .collect()
    }
}

impl Slot {
    /// The slot's figures with `revisits` (per observation), and per door configuration when
    /// it breaks them down.
    fn metrics(&self, revisits: &[bool], scorer: &Scorer) -> (Metrics, Vec<DoorConfigMetrics>) {
        let mut total = self.counts.clone();
        let mut per_cfg = self.per_cfg.clone();
        scorer.each_site(|i, config| {
            if !revisits[i] {
                return;
            }
            total.revisits += 1;
            let (query, any) = (self.recalled_query.get(i), self.recalled_any.get(i));
            total.recalled += usize::from(query);
            total.recalled_any += usize::from(any);
            if self.breakdown {
                let c = &mut per_cfg[config];
                c.revisits += 1;
                c.recalled += usize::from(query);
                c.recalled_any += usize::from(any);
            }
        });
        let configs = if self.breakdown {
            scorer.config_metrics(&per_cfg, self.radius_m)
        } else {
            Vec::new()
        };
        let metrics = Metrics {
            longest_revisit_m: scorer.longest_revisit_m(revisits),
            ..total.metrics(self.radius_m)
        };
        (metrics, configs)
    }
}

/// The pairs seen with `claim` (same or opposite) and those seen with the other claim.
fn claim_sets(window: &mut [RunSet; 2], claim: Facing) -> (&mut RunSet, &RunSet) {
    let [same, opposite] = window;
    match claim {
        Facing::Opposite => (opposite, same),
        _ => (same, opposite),
    }
}

/// Pair recall's test of a pair claimed `claim`: the two frames' true positions within
/// `tp_radius_m`, at least `min_gap_m` of true travel apart, facing as claimed
/// (`pair_recall::pair_recall`'s rule). A free function so that it can run while the tally's
/// pair map is borrowed.
fn could_be_found(
    scorer: &Scorer,
    spec: &EvaluationSpec,
    (qi, qs): (usize, &Site),
    (pi, ps): (usize, &Site),
    claim: Facing,
) -> bool {
    let r = spec.tp_radius_m;
    if r <= 0.0 || !r.is_finite() {
        return false;
    }
    // A site's travel is its frame's; the gap is tested before the frames are read (the past
    // frame's truth is a read from far back).
    if qs.travel_m - ps.travel_m < spec.min_gap_m {
        return false;
    }
    let (Some(q), Some(p)) = (scorer.frame_pose(qi), scorer.frame_pose(pi)) else {
        return false;
    };
    (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) <= r * r
        && claim.agrees(q[2], p[2], scorer.heading_tol_rad())
}

/// Sorts visit entries (`query << 32 | lap << 2 | claims`), the first `sorted` already in
/// order, and merges those of one (query, lap), their claims joined.
fn compact_visits(visits: &mut Vec<u64>, sorted: usize) {
    visits[sorted..].sort_unstable();
    // Two sorted runs: the stable sort finds them and merges them in one pass.
    visits.sort();
    visits.dedup_by(|b, a| {
        let same = *a >> 2 == *b >> 2;
        if same {
            *a |= *b & 3;
        }
        same
    });
}

/// Whether the query ranges of `m`'s runs are in increasing order and do not overlap (then no
/// pair of `m` repeats: a run's queries are distinct).
fn queries_disjoint(m: &Match) -> bool {
    m.runs
        .windows(2)
        .all(|w| w[0].query_start + w[0].len as usize <= w[1].query_start)
}

/// What one sweep of the earlier laps at a radius gives, per facing indexed as [`facing_bit`].
struct VisitSweep {
    /// Visit recall.
    recall: [f64; 3],
    /// Per observation: whether it has a revisit (`None` from the reference searches, which
    /// count them apart).
    revisits: Option<[Vec<bool>; 3]>,
    /// The laps that revisit each observation, when kept for another tally over the same
    /// observations ([`SharedTruth`]).
    lists: Option<LapLists>,
}

/// Visit recall's counts, fed the laps that revisit each observation in order.
#[derive(Default)]
struct LapCount {
    /// Where [`Tally::visits_of`] stands.
    at: usize,
    /// Per facing (as [`facing_bit`]): the earlier laps that revisit, those paired correctly.
    visits: [usize; 3],
    found: [usize; 3],
}

impl LapCount {
    /// Counts observation `i`, revisited by the earlier laps `same` and `opposite` (counted,
    /// not listed: on one loop every earlier lap revisits each observation).
    fn add(&mut self, tally: &Tally, i: usize, same: &Laps, opposite: &Laps) {
        self.visits[0] += same.union_len(opposite);
        self.visits[1] += same.len();
        self.visits[2] += opposite.len();
        for &v in tally.visits_of(i, &mut self.at) {
            let lap = ((v & 0xffff_ffff) >> 2) as usize;
            let m = u8::from(same.contains(lap)) | u8::from(opposite.contains(lap)) << 1;
            let claims = v & 3;
            self.found[0] += usize::from(m != 0 && claims != 0);
            self.found[1] += usize::from(m & 1 != 0 && claims & 1 != 0);
            self.found[2] += usize::from(m & 2 != 0 && claims & 2 != 0);
        }
    }

    fn recall(&self) -> [f64; 3] {
        [0, 1, 2].map(|f| super::metrics::ratio(self.found[f], self.visits[f]))
    }
}

/// The laps that revisit each observation, the same and the opposite way, as one sweep of the
/// lap grid found them (to count another tally's visit recall without sweeping again).
#[derive(Clone, Default)]
struct LapLists {
    /// Per observation swept: its position, and where its same and opposite laps end.
    obs: Vec<(u32, u32, u32)>,
    laps: Vec<usize>,
}

impl LapLists {
    /// Laps kept at most (8 bytes each): beyond, the next tally sweeps again.
    const MAX_LAPS: usize = 1 << 24;

    fn push(&mut self, i: usize, same: &Laps, opposite: &Laps) {
        self.laps.extend(same.iter());
        let mid = self.laps.len() as u32;
        self.laps.extend(opposite.iter());
        self.obs.push((i as u32, mid, self.laps.len() as u32));
    }

    /// Visit recall of `tally` over these laps, per facing as [`facing_bit`].
    fn recall(&self, tally: &Tally) -> [f64; 3] {
        let mut count = LapCount::default();
        let (mut same, mut opposite) = (Laps::default(), Laps::default());
        let mut from = 0usize;
        for &(i, mid, end) in &self.obs {
            let (mid, end) = (mid as usize, end as usize);
            same = Laps::of(&self.laps[from..mid], same);
            opposite = Laps::of(&self.laps[mid..end], opposite);
            count.add(tally, i as usize, &same, &opposite);
            from = end;
        }
        count.recall()
    }
}

/// What the last count of a tally ([`Tally::finish_sharing`]) computed from the truth and the
/// observations alone — the revisits at every radius, the laps that revisit each observation,
/// pair recall's possible pairs — kept for the next tally over the same observations and
/// truth with the same rules: the level configurations of one experiment see the same
/// observations, and count these once between them. The figures are those of counting again.
#[derive(Default)]
pub struct SharedTruth {
    kept: Option<TruthSide>,
    /// Tallies still to finish with it, this one included: the last keeps nothing (the
    /// default, 0, keeps nothing either).
    tallies: usize,
}

impl SharedTruth {
    /// For `tallies` tallies to finish one after the other.
    pub fn new(tallies: usize) -> Self {
        SharedTruth {
            kept: None,
            tallies,
        }
    }
}

/// One sweep of the lap grid: its radius, the revisits by facing (none from the reference
/// searches), the laps that revisit each observation (none: not kept) and the visit recall of
/// the tally that swept.
type Swept = (f64, Option<[Vec<bool>; 3]>, Option<LapLists>, [f64; 3]);

/// One tally's truth side (see [`SharedTruth`]).
struct TruthSide {
    /// What it was counted over: the observations joined with their truth, the rules, the
    /// figures (`slots`: their facing and radius).
    scorer: Scorer,
    spec: EvaluationSpec,
    slots: Vec<(Facing, u64)>,
    /// Pair recall's sites (each observation's frame truth).
    frame_sites: Vec<Site>,
    sweeps: Vec<Swept>,
    own: Vec<Option<Vec<bool>>>,
    possible_of: Vec<(Facing, u64, u64)>,
}

/// The mark of the lap of `visits` entry `v` (`query << 32 | lap << 2 | claims`), 0 when unmarked.
fn lap_mark(mark: &[u8], v: u64) -> u8 {
    mark.get(((v & 0xffff_ffff) >> 2) as usize)
        .copied()
        .unwrap_or(0)
}

/// One flag per observation, 64 to a word (125 KB per figure for a million observations).
#[derive(Clone, Debug, Default)]
struct Bits(Vec<u64>);

impl Bits {
    /// Room for flags `0..n` (new ones unset).
    fn resize(&mut self, n: usize) {
        self.0.resize(n.div_ceil(64), 0);
    }

    fn set(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }

    fn get(&self, i: usize) -> bool {
        self.0.get(i / 64).is_some_and(|w| w >> (i % 64) & 1 == 1)
    }
}

/// The pairs of `here` (sorted packed observation indices) that `fewer` (sorted) does not hold,
/// and how many of them `correct` accepts: what a level configuration found that the one with
/// a level fewer did not (`Report::set_level_gains`).
pub fn gain(here: &[u64], fewer: &[u64], correct: impl Fn(usize, usize) -> bool) -> (usize, usize) {
    let (mut pairs, mut ok, mut j) = (0, 0, 0);
    for &k in here {
        while j < fewer.len() && fewer[j] < k {
            j += 1;
        }
        if fewer.get(j) == Some(&k) {
            continue;
        }
        pairs += 1;
        ok += usize::from(correct((k >> 32) as usize, (k & 0xffff_ffff) as usize));
    }
    (pairs, ok)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::LapInfo;
    use crate::eval::metrics::tests::circle;
    use crate::geom::{OdomPose, Pose2, TruePose};
    use crate::place::Direction;
    use proptest::prelude::*;

    /// Laps of a short route, each `(run, reversed, offset)`: driven one way or the other, moved
    /// sideways, with a heading wobble; some frames without an observation.
    fn laps_of(laps: &[(usize, bool, f64)], wobble: &[f64]) -> (Vec<Observation>, GroundTruth) {
        let (mut obs, mut gt) = (Vec::new(), GroundTruth::default());
        let per_lap = wobble.len();
        for (lap, &(run, reversed, offset)) in laps.iter().enumerate() {
            gt.start_lap(LapInfo {
                run,
                lap,
                door_config: format!("c{}", lap % 3),
                open_doors: vec![],
            });
            for k in 0..per_lap {
                let u = if reversed { per_lap - 1 - k } else { k };
                // A corner halfway: along x, then along y.
                let t = u as f64 * 0.25;
                let (x, y, along) = if t < 5.0 {
                    (t, offset, 0.0)
                } else {
                    (5.0 + offset, t - 5.0, std::f64::consts::FRAC_PI_2)
                };
                let back = if reversed { std::f64::consts::PI } else { 0.0 };
                let pose = Pose2::new(x, y, along + back + wobble[(k + lap) % per_lap]);
                let frame = gt.frames.len();
                gt.push_frame(TruePose(pose), OdomPose(pose));
                if k % 7 != 3 {
                    let id = obs.len();
                    obs.push(Observation::new(
                        id,
                        run,
                        frame,
                        OdomPose(pose),
                        frame as f64,
                    ));
                }
            }
        }
        (obs, gt)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Every figure of the searches in use equals that of the reference searches (the k-d
        /// tree of every earlier site, `by_site_tree`), on small random runs and matches.
        #[test]
        fn figures_equal_the_reference_searches(
            laps in proptest::collection::vec((0usize..3, any::<bool>(), -0.6f64..0.6), 1..6),
            wobble in proptest::collection::vec(-0.9f64..0.9, 40..60),
            picks in proptest::collection::vec((any::<u16>(), any::<u16>(), 1u32..6, any::<bool>()), 0..40),
            gap_m in prop_oneof![Just(0.0), Just(2.0), 0.0f64..30.0],
            tp_radius_m in prop_oneof![Just(1.0), 0.1f64..3.0],
            tol_deg in prop_oneof![Just(45.0), 5.0f64..120.0],
        ) {
            let mut laps = laps;
            laps.sort_by_key(|l| l.0);
            let (obs, gt) = laps_of(&laps, &wobble);
            let n = obs.len();
            // Each match two runs of pairs, whose queries may overlap (pairs may repeat).
            let matches: Vec<Match> = picks
                .chunks(2)
                .filter(|_| n > 1)
                .map(|two| {
                    let runs = two.iter().flat_map(|&(a, b, len, _)| {
                        let (a, b) = (a as usize % n, b as usize % n);
                        let (q, p) = (a.max(b), a.min(b));
                        let len = (len as usize).min(n - q);
                        Match::from_pairs((0..len).map(move |d| (q + d, p + d)), 1.0).runs
                    });
                    let direction = if two[0].3 { Direction::Opposite } else { Direction::Same };
                    Match::new(runs.collect(), direction, 1.0)
                })
                .collect();
            let spec = EvaluationSpec {
                min_gap_m: gap_m,
                tp_radius_m,
                heading_tolerance_deg: tol_deg,
                ..EvaluationSpec::default()
            };
            let score = |reference: bool, compact_min: usize| {
                let mut t = Tally::new(&spec, Scope::Full);
                if reference {
                    t.by_site_tree();
                }
                t.visits_compact_min = compact_min;
                t.sync(&obs, &gt);
                matches.iter().for_each(|m| t.add(m));
                t.finish(&gt)
            };
            let want = score(true, 1 << 16);
            prop_assert_eq!(&score(false, 1 << 16), &want);
            // The visits merged every few correct pairs as they arrive: the same figures.
            prop_assert_eq!(&score(false, 1), &want);
            // The truth side left by a tally over other observations is not taken; that of a
            // tally over the same ones (without matches) is, with the same figures.
            let mut shared = SharedTruth::new(3);
            let fewer = obs.len().saturating_sub(5);
            for (upto, ms) in [(fewer, &matches[..0]), (obs.len(), &matches[..0]), (obs.len(), &matches[..])] {
                let mut t = Tally::new(&spec, Scope::Full);
                t.sync(&obs[..upto], &gt);
                ms.iter().for_each(|m| t.add(m));
                let e = t.finish_sharing(&gt, &mut shared);
                if upto == obs.len() && !ms.is_empty() {
                    prop_assert_eq!(&e, &want);
                }
            }
        }
    }

    /// Observation ids need not be positions: the same observations and match with every id
    /// moved by 1000 score the same, and a match naming ids never reported is not scored.
    #[test]
    fn ids_that_are_not_positions_score_the_same() {
        let (obs, gt) = circle(3, 40.0);
        let spec = EvaluationSpec::default();
        let pairs: Vec<(usize, usize)> = (400..obs.len()).map(|q| (q, q - 400)).collect();
        let score = |obs: &[Observation], shift: usize| {
            let m = Match::from_pairs(pairs.iter().map(|&(q, p)| (q + shift, p + shift)), 1.0);
            let mut t = Tally::new(&spec, Scope::Full);
            t.sync(obs, &gt);
            t.add(&m);
            t.finish(&gt)
        };
        let moved: Vec<Observation> = obs
            .iter()
            .map(|o| Observation::new(o.id + 1000, o.run, o.frame_id, o.odom_pose, o.travel_m))
            .collect();
        let (dense, sparse) = (score(&obs, 0), score(&moved, 1000));
        assert!(
            dense.main.pairs > 400 && dense.main.precision == 1.0,
            "{:?}",
            dense.main
        );
        assert_eq!(dense, sparse);
        let unknown = score(&obs, 5000);
        assert_eq!(
            (unknown.main.pairs, unknown.main.unresolved_pairs),
            (0, pairs.len())
        );
    }
}
