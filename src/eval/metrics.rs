//! Ground truth scoring of matches (docs/design.md, Evaluation).
//!
//! Definitions, all at one radius `r` (`tp_radius_m`, or a sensitivity radius):
//!
//! - **Pairs.** Every match contributes its aligned observation pairs `(query, past)`. A pair
//!   that occurs more than once (in one match or in several matches) counts once: pairs are
//!   deduplicated on the ordered id pair `(query, past)`, the first occurrence wins. Pairs whose
//!   ids the recognizer never reported as observations are not scored; they are counted in
//!   [`Metrics::unresolved_pairs`] (always 0 for a well-behaved recognizer).
//! - **Correct pair.** The true positions of the two observations (truth of the frames that made
//!   them) are at most `r` apart, and their true headings agree as the match's direction claims:
//!   within `heading_tolerance_deg` for a `same` match, 180° ± `heading_tolerance_deg` for an
//!   `opposite` one.
//! - **Precision** = correct pairs / pairs. With no pair at all, precision is reported as 0 and
//!   [`Metrics::no_pairs`] is set, so reports stay free of NaN.
//! - **Per-match precision** (`match_precision`): a match is correct when strictly more than half
//!   of its own (deduplicated) pairs are correct; `match_precision` = correct matches / matches
//!   with at least one scored pair. Matches without pairs are ignored.
//! - **Revisit.** Observation `o` has a revisit when an observation made before it, with at least
//!   `min_gap_m` less true travel (the harness's, [`super::pair_recall::true_travel_m`]), lies within `r` of it (true positions) with a true
//!   heading within `heading_tolerance_deg` of `o`'s (a same-direction revisit, as the paper
//!   counts) or 180° ± `heading_tolerance_deg` from it (an opposite-direction revisit). The
//!   top-level figures count revisits of either direction and every match.
//! - **Per direction** ([`Evaluation::directions`]): the same figures over the matches of one
//!   direction and the revisits of that direction only.
//!   The radius of the revisit test follows the scoring radius, so a sensitivity radius changes
//!   both what is correct and what could have been found.
//! - **Recall** = observations with a revisit that are the *query* side of at least one correct
//!   pair / observations with a revisit. With no revisit recall is 0 (and `revisits` is 0).
//!   [`Metrics::recall_either_side`] counts either side of a correct pair, for reference.
//! - **Per door configuration**: pairs, matches and observations are attributed to the door
//!   configuration of the lap of the query observation (for a match: of its first pair's query).
//!
//! Revisits and visits are searched in a k-d tree of the earlier observations
//! ([`super::site_tree`]), so the cost grows about as `n log n` in the observations, however
//! many passes go over one place.
//!
//! The rules are counted in one place, [`super::tally`], match by match in the order found
//! (the order "first occurrence" refers to); this module holds the figures, the observations
//! joined with their truth ([`Scorer`]) and the revisit searches.

use super::lap_grid::{LapSweep, Laps};
use super::pair_recall::Facing;
use super::pair_set::{PairSet, pack};
use super::site_tree::{Query, Site, sweep};
use super::tally::{Scope, Tally};
use super::{GroundTruth, Recognition};
use crate::place::{Match, ObsId, Observation};
use crate::spec::evaluation::EvaluationSpec;
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

/// Scores at one radius.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Metrics {
    /// Radius a pair must be within to be correct (and a revisit to count), metres.
    pub radius_m: f64,
    /// Distinct `(query, past)` observation pairs scored.
    pub pairs: usize,
    pub correct_pairs: usize,
    /// correct_pairs / pairs; 0 when there is no pair (see `no_pairs`).
    pub precision: f64,
    /// Set when there was no pair to score: `precision` is then 0 by convention.
    pub no_pairs: bool,
    /// Matches with at least one scored pair.
    pub matches: usize,
    /// Matches with strictly more than half of their pairs correct.
    pub correct_matches: usize,
    /// correct_matches / matches; 0 when there is no match.
    pub match_precision: f64,
    /// Observations that have a revisit.
    pub revisits: usize,
    /// Observations with a revisit that are the query of at least one correct pair.
    pub recalled: usize,
    /// recalled / revisits; 0 when there is no revisit.
    pub recall: f64,
    /// Like `recall`, counting an observation on either side of a correct pair.
    pub recall_either_side: f64,
    /// Visit recall: over every observation with a revisit, the share of the earlier laps that
    /// passed there (same direction, beyond the gap) it was correctly paired with. Unlike
    /// `recall`, which one earlier lap in the same door state satisfies, this rewards matching
    /// across door changes. Computed at `tp_radius_m` only (0 elsewhere).
    #[serde(default)]
    pub visit_recall: f64,
    /// Pair recall: correct pairs ÷ every pair that could have been found (see
    /// [`super::pair_recall`]). Computed at `tp_radius_m` only (0 elsewhere).
    #[serde(default)]
    pub pair_recall: f64,
    /// The longest stretch of true travel, metres, along which consecutive observations of one
    /// run all have a revisit (of this figure's facing; the top-level figure: the longer of the
    /// two directions', as a chain follows one direction): the most evidence a place gives to
    /// chain. A recognizer that needs τ words of a few metres each finds nothing where this is
    /// shorter. Written whenever the figure has revisits (0 m when none of them is followed by
    /// another); not counted per door configuration.
    #[serde(default, skip_serializing_if = "RevisitStretch::uncounted")]
    pub longest_revisit_m: RevisitStretch,
    /// Pairs naming an observation id the recognizer never reported (not scored).
    pub unresolved_pairs: usize,
    /// Pairs that arrived behind the recognizer's query horizon, after the scoring had
    /// forgotten the pairs there (`eval::tally`): counted, but perhaps twice. Always 0 for a
    /// recognizer that keeps its promise; written only when not.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub late_pairs: usize,
}

/// A figure's longest revisit stretch, metres ([`Metrics::longest_revisit_m`]), and whether
/// the figure has revisits to measure it on: written as a plain number whenever it has, so a
/// figure with a few scattered revisits says 0 m rather than nothing.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(from = "f64", into = "f64")]
pub struct RevisitStretch {
    pub m: f64,
    /// The figure has revisits (read back: the number was written).
    pub counted: bool,
}

impl RevisitStretch {
    /// A stretch of `m` metres, measured.
    pub fn of(m: f64) -> Self {
        RevisitStretch { m, counted: true }
    }

    /// Not measured (serde: such a stretch is not written).
    pub fn uncounted(&self) -> bool {
        !self.counted
    }
}

impl From<f64> for RevisitStretch {
    fn from(m: f64) -> Self {
        RevisitStretch::of(m)
    }
}

impl From<RevisitStretch> for f64 {
    fn from(s: RevisitStretch) -> f64 {
        s.m
    }
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Scores of the observations and pairs attributed to one door configuration.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct DoorConfigMetrics {
    pub door_config: String,
    /// Laps driven in this configuration.
    pub laps: usize,
    pub metrics: Metrics,
}

/// Everything [`evaluate`] computes for one recognition.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Evaluation {
    /// At `tp_radius_m`.
    pub main: Metrics,
    /// At each of `sensitivity_radii_m`, in the spec's order.
    pub sensitivity: Vec<Metrics>,
    /// At `tp_radius_m`, per door configuration (order of first appearance in the runs).
    pub door_configs: Vec<DoorConfigMetrics>,
    /// At `tp_radius_m`, per direction.
    pub directions: DirectionMetrics,
    /// Per observation (scoring order): whether it is the newer side of a correct pair at
    /// `tp_radius_m`, either direction (recall's numerator). Not written: it tells which of the
    /// true revisits verification turned down were recognized later
    /// ([`super::scores::RejectedScores::correct_recognized`]).
    #[serde(skip)]
    pub recognized: Vec<bool>,
}

/// Scores of the matches of one direction against the revisits of that direction.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct DirectionMetrics {
    pub same: Metrics,
    pub opposite: Metrics,
}

/// Scores `rec` as docs/design.md, Evaluation says: at `tp_radius_m`, at every sensitivity radius, per door
/// configuration and per direction. A recognition scored while it was recognized
/// ([`super::Recording::streaming`]) carries its evaluation; any other is scored now by feeding
/// its matches, in order, to a [`Tally`] (the one implementation of the rules).
pub fn evaluate(rec: &Recognition, spec: &EvaluationSpec) -> Evaluation {
    if let Some((s, e)) = &rec.evaluation
        && s == spec
    {
        return e.clone();
    }
    let mut tally = Tally::new(spec, Scope::Full);
    tally.sync(&rec.observations, &rec.truth);
    for m in &rec.matches {
        tally.add(m);
    }
    tally.finish(&rec.truth)
}

/// [`evaluate`] with the earlier scoring's searches (visit recall's laps from the k-d tree of
/// every earlier site, [`super::site_tree`]): the reference the linear-time searches are tested
/// against on every shipped scenario. Not for use: it grows with the square of the laps.
#[doc(hidden)]
pub fn evaluate_by_site_tree(rec: &Recognition, spec: &EvaluationSpec) -> Evaluation {
    let mut tally = Tally::new(spec, Scope::Full);
    tally.by_site_tree();
    tally.sync(&rec.observations, &rec.truth);
    for m in &rec.matches {
        tally.add(m);
    }
    tally.finish(&rec.truth)
}

/// Scores observations and matches at radius `radius_m`, top-level figures only (no visit or
/// pair recall).
pub fn score(
    observations: &[Observation],
    matches: &[Match],
    truth: &GroundTruth,
    spec: &EvaluationSpec,
    radius_m: f64,
) -> Metrics {
    let spec = EvaluationSpec {
        tp_radius_m: radius_m,
        ..spec.clone()
    };
    let mut tally = Tally::new(&spec, Scope::Main);
    tally.sync(observations, truth);
    for m in matches {
        tally.add(m);
    }
    tally.finish_main(None)
}

/// One deduplicated observation pair with its true positions, for pictures of what matched.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScoredPair {
    pub query: ObsId,
    pub past: ObsId,
    pub query_truth: crate::geom::TruePose,
    pub past_truth: crate::geom::TruePose,
    /// Whether the true positions are within the radius.
    pub correct: bool,
}

/// Every distinct `(query, past)` pair of `rec`'s matches (first occurrence order) with its true
/// poses and whether it is correct at `radius_m`. Pairs without truth are left out.
pub fn scored_pairs(rec: &Recognition, radius_m: f64) -> Vec<ScoredPair> {
    let truth_of = truth_lookup(rec);
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for (query, past) in rec.matches.iter().flat_map(Match::pairs) {
        if !seen.insert(pack(query, past)) {
            continue;
        }
        if let (Some(q), Some(pa)) = (truth_of(query), truth_of(past)) {
            out.push(ScoredPair {
                query,
                past,
                query_truth: q,
                past_truth: pa,
                correct: q.0.distance(&pa.0) <= radius_m,
            });
        }
    }
    out
}

/// The distinct pairs of `here`'s matches that `fewer`'s do not hold (same observations), as
/// [`scored_pairs`] counts them (pairs without truth left out): `(pairs, correct at
/// radius_m)`, by [`super::tally::gain`]'s rule. Held as packed sets, so a long run's millions
/// of pairs cost 8 bytes each.
pub fn pairs_not_in(here: &Recognition, fewer: &Recognition, radius_m: f64) -> (usize, usize) {
    let truth_of = truth_lookup(here);
    let index_of = index_of(&here.observations);
    let resolved = |rec: &Recognition| {
        let set = PairSet::from_pairs(rec.matches.iter().flat_map(Match::pairs).filter_map(
            |(q, p)| {
                truth_of(q)?;
                truth_of(p)?;
                Some((*index_of.get(&q)?, *index_of.get(&p)?))
            },
        ));
        set.iter().map(|(q, p)| pack(q, p)).collect::<Vec<u64>>()
    };
    let (h, f) = (resolved(here), resolved(fewer));
    let pose = |i: usize| truth_of(here.observations[i].id).expect("resolved pairs have truth");
    super::tally::gain(&h, &f, |q, p| pose(q).0.distance(&pose(p).0) <= radius_m)
}

/// The true pose of an observation of `rec` by id (`None` for an id it does not hold or a
/// frame without truth).
fn truth_lookup(rec: &Recognition) -> impl Fn(ObsId) -> Option<crate::geom::TruePose> + '_ {
    let index_of = index_of(&rec.observations);
    move |id| {
        index_of
            .get(&id)
            .and_then(|&i| rec.truth.observation_pose(&rec.observations[i]))
    }
}

/// Observation id → position in `observations`.
fn index_of(observations: &[Observation]) -> HashMap<ObsId, usize> {
    observations
        .iter()
        .enumerate()
        .map(|(i, o)| (o.id, i))
        .collect()
}

/// Observations joined with their truth (shared by the scorers of every facing).
#[derive(Clone, Debug, Default)]
pub(super) struct Joined {
    /// Observation id → position in the observations, once an id is not its position; `None`
    /// while every id equals its position (placewords' own recognizer: no map of a million
    /// observations is kept).
    index_of: Option<HashMap<ObsId, usize>>,
    /// Per observation (creation order): its site, or [`NO_SITE`] when its frame has no truth.
    site_of: Dense,
    /// Per observation: the input frame that made it.
    frame_of: Vec<u32>,
    /// The observations with truth, in creation order.
    sites: Vec<Site>,
    /// Per site: its frame's true pose (x, y, θ), which pair recall tests (a site is the
    /// observation's pose); kept beside the sites so that the test reads no frame truth.
    frame_pose: Vec<[f64; 3]>,
    /// Per site: its door configuration index.
    site_config: Vec<u32>,
    /// Per site: its position in the observations.
    site_obs: Dense,
}

/// A map of positions kept as the identity (no storage) until an entry differs: observation →
/// site and site → observation are the identity while every observation has truth, the usual
/// case, so a log of a million observations keeps no tables.
#[derive(Clone, Debug, Default, PartialEq)]
struct Dense {
    len: usize,
    /// The entries, once one is not its own position.
    table: Option<Vec<u32>>,
}

impl Dense {
    fn push(&mut self, v: u32) {
        match &mut self.table {
            None if v as usize == self.len => {}
            None => {
                let mut t: Vec<u32> = (0..self.len as u32).collect();
                t.push(v);
                self.table = Some(t);
            }
            Some(t) => t.push(v),
        }
        self.len += 1;
    }

    fn get(&self, i: usize) -> Option<u32> {
        match &self.table {
            None => (i < self.len).then_some(i as u32),
            Some(t) => t.get(i).copied(),
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    /// How many entries are below `v`, for entries in increasing order (site → observation).
    fn count_below(&self, v: usize) -> usize {
        match &self.table {
            None => v.min(self.len),
            Some(t) => t.partition_point(|&e| (e as usize) < v),
        }
    }
}

/// Marks an observation without truth in `Joined::site_of`.
const NO_SITE: u32 = u32::MAX;

/// Observations joined with their truth, reusable across radii. It counts the revisits of one
/// facing ([`Facing::Either`] unless [`Scorer::with_facing`] says otherwise).
#[derive(Clone)]
pub struct Scorer {
    joined: Arc<Joined>,
    configs: Vec<String>,
    config_laps: Vec<usize>,
    /// Door configuration index of each lap joined.
    lap_config: Vec<u32>,
    /// Run of each lap joined.
    lap_run: Vec<usize>,
    min_gap_m: f64,
    heading_tol_rad: f64,
    facing: Facing,
}

impl Joined {
    /// The observation (position) of site `k`.
    fn obs_of_site(&self, k: usize) -> usize {
        self.site_obs.get(k).expect("a site of an observation") as usize
    }

    /// The position of the observation with id `id`, if joined.
    fn position(&self, id: ObsId) -> Option<usize> {
        match &self.index_of {
            None => (id < self.site_of.len()).then_some(id),
            Some(m) => m.get(&id).copied(),
        }
    }

    /// Appends observation `o`, at position `i`, with its true pose (`lap_config`: door
    /// configuration of each lap).
    fn push(&mut self, i: usize, o: &Observation, truth: &GroundTruth, lap_config: &[u32]) {
        match &mut self.index_of {
            None if o.id == i => {}
            None => {
                let mut m: HashMap<ObsId, usize> = (0..i).map(|k| (k, k)).collect();
                m.insert(o.id, i);
                self.index_of = Some(m);
            }
            Some(m) => {
                m.insert(o.id, i);
            }
        }
        self.frame_of.push(o.frame_id as u32);
        let pose = truth.observation_pose(o);
        let Some((f, pose)) = truth.frame(o.frame_id).zip(pose) else {
            self.site_of.push(NO_SITE);
            return;
        };
        self.site_of.push(self.sites.len() as u32);
        self.sites.push(Site {
            x: pose.0.x,
            y: pose.0.y,
            theta: pose.0.theta,
            travel_m: f.travel_m,
            lap: f.lap_slot,
        });
        self.frame_pose
            .push([f.pose.0.x, f.pose.0.y, f.pose.0.theta]);
        self.site_config.push(lap_config[f.lap_slot]);
        self.site_obs.push(i as u32);
    }
}

impl Scorer {
    /// `observations` joined with `truth`, counted with `spec`'s rules.
    pub fn new(observations: &[Observation], truth: &GroundTruth, spec: &EvaluationSpec) -> Self {
        let mut scorer = Scorer::empty(spec);
        scorer.sync(observations, truth);
        scorer
    }

    /// No observation yet (grown by [`Self::sync`]).
    pub(super) fn empty(spec: &EvaluationSpec) -> Self {
        Scorer {
            joined: Arc::new(Joined::default()),
            configs: Vec::new(),
            config_laps: Vec::new(),
            lap_config: Vec::new(),
            lap_run: Vec::new(),
            min_gap_m: spec.min_gap_m,
            heading_tol_rad: spec.heading_tolerance_deg.to_radians(),
            facing: Facing::Either,
        }
    }

    /// Joins the laps and observations added to `truth` and `observations` since the last call
    /// (both only ever grow). Door configurations are numbered in order of first appearance.
    pub(super) fn sync(&mut self, observations: &[Observation], truth: &GroundTruth) {
        for lap in &truth.laps[self.lap_config.len()..] {
            let c = match self.configs.iter().position(|c| *c == lap.door_config) {
                Some(c) => c,
                None => {
                    self.configs.push(lap.door_config.clone());
                    self.config_laps.push(0);
                    self.configs.len() - 1
                }
            };
            self.config_laps[c] += 1;
            self.lap_config.push(c as u32);
            self.lap_run.push(lap.run);
        }
        let known = self.observation_count();
        let joined = Arc::make_mut(&mut self.joined);
        for (i, o) in observations.iter().enumerate().skip(known) {
            joined.push(i, o, truth, &self.lap_config);
        }
    }

    /// Observations joined (with or without truth).
    pub(super) fn observation_count(&self) -> usize {
        self.joined.site_of.len()
    }

    /// Door configurations seen.
    pub(super) fn config_count(&self) -> usize {
        self.configs.len()
    }

    pub(super) fn heading_tol_rad(&self) -> f64 {
        self.heading_tol_rad
    }

    /// The input frame of observation `i`.
    pub(super) fn frame_of(&self, i: usize) -> usize {
        self.joined.frame_of[i] as usize
    }

    /// The positions and sites of the observations a pair of ids names, when both are known
    /// and have truth.
    pub(super) fn resolve(&self, query: ObsId, past: ObsId) -> Option<(usize, usize, Site, Site)> {
        let (qi, pi) = (self.joined.position(query)?, self.joined.position(past)?);
        Some((qi, pi, *self.site(qi)?, *self.site(pi)?))
    }

    /// Whether observations `q` and `p` (positions, both with truth) are within `r`.
    pub(super) fn within(&self, q: usize, p: usize, r: f64) -> bool {
        match (self.site(q), self.site(p)) {
            (Some(a), Some(b)) => ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt() <= r,
            _ => false,
        }
    }

    /// The true pose (x, y, θ) of the frame of observation `i` (a position), if it has truth.
    pub(super) fn frame_pose(&self, i: usize) -> Option<&[f64; 3]> {
        let k = self.joined.site_of.get(i)?;
        self.joined.frame_pose.get(k as usize)
    }

    /// The truth of observation `i` (its position in the observations), if its frame has one.
    fn site(&self, i: usize) -> Option<&Site> {
        let k = self.joined.site_of.get(i)?;
        self.joined.sites.get(k as usize)
    }

    /// The longest stretch of true travel, metres, along which consecutive observations of one
    /// run all have a revisit (`revisits`, per observation): see
    /// [`Metrics::longest_revisit_m`]. Travel is the observations' frames' (observations made
    /// along one step between scans share it).
    pub(super) fn longest_revisit_m(&self, revisits: &[bool]) -> RevisitStretch {
        let j = &self.joined;
        let mut longest = 0.0f64;
        // (observation position, site) of the previous observation with truth, and where the
        // current stretch began.
        let mut prev: Option<(usize, &Site)> = None;
        let mut began_m: Option<f64> = None;
        for (k, s) in j.sites.iter().enumerate() {
            let i = j.obs_of_site(k);
            let continues = prev.is_some_and(|(pi, p)| {
                pi + 1 == i && self.lap_run.get(p.lap) == self.lap_run.get(s.lap)
            });
            if !revisits.get(i).copied().unwrap_or(false) {
                began_m = None;
            } else {
                let from = match began_m {
                    Some(b) if continues => b,
                    _ => s.travel_m,
                };
                began_m = Some(from);
                longest = longest.max(s.travel_m - from);
            }
            prev = Some((i, s));
        }
        RevisitStretch {
            m: longest,
            counted: revisits.iter().any(|&r| r),
        }
    }

    /// The door configuration of observation `i`, which has truth.
    pub(super) fn config(&self, i: usize) -> usize {
        let k = self
            .joined
            .site_of
            .get(i)
            .expect("an observation with truth");
        self.joined.site_config[k as usize] as usize
    }

    /// Observations scored (with or without truth).
    fn len(&self) -> usize {
        self.joined.site_of.len()
    }

    /// Whether `other` joined the same observations to the same truth sites, with the same
    /// gap and heading tolerance: then every revisit and every lap that revisits is the same.
    pub(super) fn same_truth_side(&self, other: &Scorer) -> bool {
        let (a, b) = (&*self.joined, &*other.joined);
        self.min_gap_m == other.min_gap_m
            && self.heading_tol_rad == other.heading_tol_rad
            && (Arc::ptr_eq(&self.joined, &other.joined)
                || (a.site_of == b.site_of && a.site_obs == b.site_obs && a.sites == b.sites))
    }

    /// The same scorer counting only revisits facing as `facing` says.
    pub fn with_facing(&self, facing: Facing) -> Self {
        Scorer {
            facing,
            ..self.clone()
        }
    }

    /// Which observations have a revisit at radius `r`.
    pub fn revisits(&self, r: f64) -> Vec<bool> {
        let mut has = vec![false; self.len()];
        if r <= 0.0 || !r.is_finite() {
            return has;
        }
        let j = &self.joined;
        sweep(&j.sites, self.min_gap_m, |k, tree| {
            has[j.obs_of_site(k)] = tree.count(&self.query(k, r), true) > 0;
        });
        has
    }

    /// Which observations have a revisit at each radius of `radii`: [`Self::revisits`] of
    /// each, in one sweep of one k-d tree (a revisit within a radius is one within every larger
    /// radius, so a site's radii are asked from the smallest until one is met).
    pub fn revisits_at(&self, radii: &[f64]) -> Vec<Vec<bool>> {
        let mut has = vec![vec![false; self.len()]; radii.len()];
        let mut order: Vec<usize> = (0..radii.len())
            .filter(|&i| radii[i] > 0.0 && radii[i].is_finite())
            .collect();
        if order.is_empty() {
            return has;
        }
        order.sort_by(|&a, &b| radii[a].total_cmp(&radii[b]));
        let j = &self.joined;
        sweep(&j.sites, self.min_gap_m, |k, tree| {
            let i = j.obs_of_site(k);
            let mut found = false;
            for &ri in &order {
                found = found || tree.count(&self.query(k, radii[ri]), true) > 0;
                has[ri][i] = found;
            }
        });
        has
    }

    /// The revisit test of site `k` at radius `r`, facing as this scorer counts.
    fn query(&self, k: usize, r: f64) -> Query<'_> {
        Query {
            site: &self.joined.sites[k],
            r2: r * r,
            facing: self.facing,
            tol_rad: self.heading_tol_rad,
        }
    }

    /// Calls `visit(i, [same, opposite])` for every observation `i` with truth, in order, with
    /// the earlier laps that revisit it at radius `r` facing the same and the opposite way,
    /// found lap by lap ([`super::lap_grid`]); the laps of either facing are their union.
    pub(super) fn sweep_laps(&self, r: f64, mut visit: impl FnMut(usize, [&Laps; 2])) {
        let j = &self.joined;
        let facings = [Facing::Same, Facing::Opposite];
        let (gap, tol) = (self.min_gap_m, self.heading_tol_rad);
        super::lap_grid::sweep_laps(&j.sites, gap, r, facings, tol, |k, laps| {
            visit(j.obs_of_site(k), laps)
        });
    }

    /// A [`Self::sweep_laps`] at radius `r` to be resumed by [`Self::sweep_laps_below`] as
    /// observations are joined; `None` when `r` is not positive and finite.
    pub(super) fn lap_sweep(&self, r: f64) -> Option<LapSweep<2>> {
        let facings = [Facing::Same, Facing::Opposite];
        LapSweep::new(self.min_gap_m, r, facings, self.heading_tol_rad)
    }

    /// Resumes `sweep` ([`Self::lap_sweep`]) over the observations below `end_obs` it has not
    /// visited: the same calls of `visit` as [`Self::sweep_laps`] makes for them.
    pub(super) fn sweep_laps_below(
        &self,
        sweep: &mut LapSweep<2>,
        end_obs: usize,
        mut visit: impl FnMut(usize, [&Laps; 2]),
    ) {
        let j = &self.joined;
        let end = j.site_obs.count_below(end_obs);
        sweep.advance(&j.sites, end, |k, laps| visit(j.obs_of_site(k), laps));
    }

    /// The earlier laps that revisit each observation at radius `r`, facing as this scorer
    /// counts, by the k-d tree of every earlier site: the reference the lap grid
    /// ([`Self::sweep_laps`]) is tested against.
    pub(super) fn sweep_laps_by_site(&self, r: f64, mut visit: impl FnMut(usize, &[usize])) {
        let j = &self.joined;
        let mut laps = super::site_tree::LapSet::default();
        sweep(&j.sites, self.min_gap_m, |k, tree| {
            laps.clear();
            tree.laps(&self.query(k, r), &mut laps);
            visit(j.obs_of_site(k), &laps.list);
        });
    }

    /// Calls `f(i, config)` for every observation `i` with truth, in order, with its door
    /// configuration.
    pub(super) fn each_site(&self, mut f: impl FnMut(usize, usize)) {
        let j = &self.joined;
        for (k, &config) in j.site_config.iter().enumerate() {
            f(j.obs_of_site(k), config as usize);
        }
    }

    /// `per_cfg` (indexed as the configurations) as named figures at radius `r`.
    pub(super) fn config_metrics(&self, per_cfg: &[Counts], r: f64) -> Vec<DoorConfigMetrics> {
        per_cfg
            .iter()
            .enumerate()
            .map(|(i, c)| DoorConfigMetrics {
                door_config: self.configs[i].clone(),
                laps: self.config_laps[i],
                metrics: c.metrics(r),
            })
            .collect()
    }
}

/// What the figures of one facing at one radius count (`eval::tally`).
#[derive(Clone, Debug, Default)]
pub(super) struct Counts {
    pub(super) pairs: usize,
    pub(super) correct: usize,
    pub(super) matches: usize,
    pub(super) correct_matches: usize,
    pub(super) revisits: usize,
    pub(super) recalled: usize,
    pub(super) recalled_any: usize,
    pub(super) unresolved: usize,
}

/// `num / den`, 0 when `den` is 0.
pub fn ratio(num: usize, den: usize) -> f64 {
    if den == 0 {
        0.0
    } else {
        num as f64 / den as f64
    }
}

impl Counts {
    pub(super) fn metrics(&self, r: f64) -> Metrics {
        Metrics {
            radius_m: r,
            pairs: self.pairs,
            correct_pairs: self.correct,
            precision: ratio(self.correct, self.pairs),
            no_pairs: self.pairs == 0,
            matches: self.matches,
            correct_matches: self.correct_matches,
            match_precision: ratio(self.correct_matches, self.matches),
            revisits: self.revisits,
            recalled: self.recalled,
            recall: ratio(self.recalled, self.revisits),
            recall_either_side: ratio(self.recalled_any, self.revisits),
            visit_recall: 0.0,
            pair_recall: 0.0,
            longest_revisit_m: RevisitStretch::default(),
            unresolved_pairs: self.unresolved,
            late_pairs: 0,
        }
    }
}

/// The level-wide longest revisit stretch ([`Metrics::longest_revisit_m`]): the longer of the
/// two directions' (`main`'s own, counted over revisits of either direction, when the
/// directions were not counted: a sweep's figures).
pub(super) fn longest_of_directions(
    main: &Metrics,
    same: &Metrics,
    opposite: &Metrics,
) -> RevisitStretch {
    if same.revisits + opposite.revisits == 0 {
        main.longest_revisit_m
    } else {
        RevisitStretch {
            m: same.longest_revisit_m.m.max(opposite.longest_revisit_m.m),
            counted: main.longest_revisit_m.counted,
        }
    }
}

/// F1 score of a precision and a recall (0 when both are 0).
pub fn f1(precision: f64, recall: f64) -> f64 {
    if precision + recall <= 0.0 {
        0.0
    } else {
        2.0 * precision * recall / (precision + recall)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::eval::LapInfo;
    use crate::geom::{OdomPose, Pose2, TruePose};
    use crate::place::Direction;
    /// An aligned pair (query, past).
    type AlignedPair = (ObsId, ObsId);
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// `laps` laps of a circle of perimeter `perimeter` m, one observation each 0.1 m; truth
    /// equals odometry. Door configuration alternates "closed"/"open" per lap.
    pub(crate) fn circle(laps: usize, perimeter: f64) -> (Vec<Observation>, GroundTruth) {
        let per_lap = (perimeter / 0.1).round() as usize;
        let radius = perimeter / (2.0 * std::f64::consts::PI);
        let mut obs = Vec::new();
        let mut gt = GroundTruth::default();
        for lap in 0..laps {
            gt.start_lap(LapInfo {
                run: 0,
                lap,
                door_config: if lap % 2 == 0 { "closed" } else { "open" }.into(),
                open_doors: vec![],
            });
            for k in 0..per_lap {
                let a = k as f64 / per_lap as f64 * 2.0 * std::f64::consts::PI;
                let pose = Pose2::new(
                    radius * a.cos(),
                    radius * a.sin(),
                    a + std::f64::consts::FRAC_PI_2,
                );
                let i = obs.len();
                gt.push_frame(TruePose(pose), OdomPose(pose));
                obs.push(Observation::new(i, 0, i, OdomPose(pose), i as f64 * 0.1));
            }
        }
        (obs, gt)
    }

    /// [`circle`] as a real log records it: a scan (frame) only every `obs_per_frame`
    /// observations, so an observation's true pose is its frame's moved by the odometry
    /// between them ([`GroundTruth::observation_pose`]), up to a metre away with 10.
    pub(crate) fn circle_sparse_frames(
        laps: usize,
        perimeter: f64,
        obs_per_frame: usize,
    ) -> (Vec<Observation>, GroundTruth) {
        let per_lap = (perimeter / 0.1).round() as usize;
        let radius = perimeter / (2.0 * std::f64::consts::PI);
        let on_circle = |k: usize| {
            let a = k as f64 / per_lap as f64 * 2.0 * std::f64::consts::PI;
            Pose2::new(
                radius * a.cos(),
                radius * a.sin(),
                a + std::f64::consts::FRAC_PI_2,
            )
        };
        let (mut obs, mut gt) = (Vec::new(), GroundTruth::default());
        for lap in 0..laps {
            gt.start_lap(LapInfo {
                run: 0,
                lap,
                door_config: "closed".into(),
                open_doors: vec![],
            });
            for k in 0..per_lap {
                if k % obs_per_frame.max(1) == 0 {
                    gt.push_frame(TruePose(on_circle(k)), OdomPose(on_circle(k)));
                }
                let (i, frame) = (obs.len(), gt.frames.len() - 1);
                let travel_m = i as f64 * 0.1;
                obs.push(Observation::new(
                    i,
                    0,
                    frame,
                    OdomPose(on_circle(k)),
                    travel_m,
                ));
            }
        }
        (obs, gt)
    }

    fn pair(_obs: &[Observation], q: usize, p: usize) -> AlignedPair {
        (q, p)
    }

    fn one_match(pairs: Vec<AlignedPair>) -> Match {
        Match::from_pairs(pairs, 1.0)
    }

    /// The oracle: for every observation, its nearest earlier neighbour that makes a revisit.
    fn oracle(obs: &[Observation], gt: &GroundTruth, spec: &EvaluationSpec) -> Vec<AlignedPair> {
        let pos = |i: usize| gt.frames[obs[i].frame_id].pose.0;
        let mut pairs = Vec::new();
        for q in 0..obs.len() {
            let best = (0..q)
                .filter(|&p| obs[q].travel_m - obs[p].travel_m >= spec.min_gap_m)
                .filter(|&p| {
                    crate::geom::wrap_angle(pos(q).theta - pos(p).theta).abs()
                        <= spec.heading_tolerance_deg.to_radians()
                })
                .map(|p| (pos(q).distance(&pos(p)), p))
                .filter(|(d, _)| *d <= spec.tp_radius_m)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, p)) = best {
                pairs.push(pair(obs, q, p));
            }
        }
        pairs
    }

    #[test]
    fn perfect_recognizer_scores_one() {
        let (obs, gt) = circle(3, 40.0);
        let spec = EvaluationSpec::default();
        let matches: Vec<Match> = oracle(&obs, &gt, &spec)
            .chunks(20)
            .map(|c| one_match(c.to_vec()))
            .collect();
        let m = score(&obs, &matches, &gt, &spec, 1.0);
        // Two full laps after the first, plus the last metre of the first lap closing the loop.
        assert_eq!(m.revisits, 810);
        assert_eq!(m.pairs, 810);
        assert_eq!(m.precision, 1.0);
        assert_eq!(m.recall, 1.0);
        assert_eq!(m.match_precision, 1.0);
        assert!(!m.no_pairs);
    }

    /// Visit recall counts earlier laps: pairing each observation with its nearest earlier
    /// neighbour only (one lap) recalls every observation but not every visit; pairing it with
    /// its neighbour in every earlier lap recalls every visit.
    #[test]
    fn visit_recall_counts_every_earlier_lap() {
        let (obs, gt) = circle(4, 40.0);
        let spec = EvaluationSpec::default();
        let visit_recall = |matches: &[Match]| {
            let spec = EvaluationSpec {
                tp_radius_m: 1.0,
                ..spec.clone()
            };
            let mut t = Tally::new(&spec, Scope::Full);
            t.sync(&obs, &gt);
            matches.iter().for_each(|m| t.add(m));
            t.finish(&gt).main.visit_recall
        };
        let nearest = vec![one_match(oracle(&obs, &gt, &spec))];
        let m = score(&obs, &nearest, &gt, &spec, 1.0);
        assert_eq!(m.recall, 1.0);
        let one_lap = visit_recall(&nearest);
        assert!(
            one_lap > 0.4 && one_lap < 0.8,
            "nearest lap only: {one_lap}"
        );
        // Every earlier lap: the same arc position 400 observations (one 40 m lap) back.
        let per_lap = 400;
        let all: Vec<AlignedPair> = (0..obs.len())
            .flat_map(|q| (1..=q / per_lap).map(move |k| (q, q - k * per_lap)))
            .map(|(q, p)| pair(&obs, q, p))
            .collect();
        let every = visit_recall(&[one_match(all)]);
        assert!(every > 0.97, "every earlier lap: {every}");
        assert_eq!(visit_recall(&[]), 0.0);
    }

    #[test]
    fn random_recognizer_scores_low() {
        let (obs, gt) = circle(3, 40.0);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let matches: Vec<Match> = (400..obs.len())
            .map(|q| {
                let p = rng.random_range(0..q - 200);
                one_match(vec![pair(&obs, q, p)])
            })
            .collect();
        let m = score(&obs, &matches, &gt, &EvaluationSpec::default(), 1.0);
        assert!(m.precision < 0.15, "{m:?}");
        assert!(m.recall < 0.15, "{m:?}");
        assert!(m.match_precision < 0.15, "{m:?}");
    }

    #[test]
    fn no_matches_means_zero_precision_with_flag() {
        let (obs, gt) = circle(3, 40.0);
        let m = score(&obs, &[], &gt, &EvaluationSpec::default(), 1.0);
        assert_eq!((m.pairs, m.precision, m.recall), (0, 0.0, 0.0));
        assert!(m.no_pairs);
        assert_eq!(m.revisits, 810);
    }

    #[test]
    fn no_revisits_means_zero_recall() {
        let (mut obs, gt) = circle(1, 40.0);
        obs.truncate(300);
        let m = score(&obs, &[], &gt, &EvaluationSpec::default(), 1.0);
        assert_eq!((m.revisits, m.recall), (0, 0.0));
    }

    /// The longest revisit stretch is the true travel along which consecutive observations all
    /// have a revisit: a detour off the first lap's path (frames 500..519) splits the second
    /// lap's stretch, leaving 520..799.
    #[test]
    fn longest_revisit_stretch_is_split_by_a_detour() {
        let (obs, mut gt) = circle(2, 40.0);
        let spec = EvaluationSpec::default();
        // The first lap's last metre already revisits its start (frames 390..399), and the
        // whole second lap follows on.
        let m = score(&obs, &[], &gt, &spec, 1.0);
        assert!(
            (m.longest_revisit_m.m - 40.9).abs() < 0.01,
            "{}",
            m.longest_revisit_m.m
        );
        for f in &mut gt.frames[500..520] {
            f.pose.0.x += 20.0;
        }
        let m = score(&obs, &[], &gt, &spec, 1.0);
        assert!(
            (m.longest_revisit_m.m - 27.9).abs() < 0.01,
            "{}",
            m.longest_revisit_m.m
        );
        // Three quarters of a lap revisit nothing.
        let m = score(&obs[..300], &[], &gt, &spec, 1.0);
        assert_eq!(m.longest_revisit_m.m, 0.0);
    }

    /// A second lap facing the other way is an opposite-direction revisit, not a same-direction
    /// one; its pairs are correct only in a match that claims the opposite direction, and the
    /// top-level figures count both directions.
    #[test]
    fn opposite_revisits_and_pairs_are_scored_per_direction() {
        let (obs, mut gt) = circle(2, 40.0);
        for f in &mut gt.frames[400..] {
            f.pose.0.theta += std::f64::consts::PI;
        }
        let pairs: Vec<AlignedPair> = (0..400).map(|k| pair(&obs, 400 + k, k)).collect();
        let evaluate_as = |direction: Direction| {
            let rec = recognition(
                &obs,
                &gt,
                vec![Match {
                    direction,
                    ..one_match(pairs.clone())
                }],
            );
            evaluate(&rec, &EvaluationSpec::default())
        };
        let e = evaluate_as(Direction::Opposite);
        let (same, opposite) = (&e.directions.same, &e.directions.opposite);
        // Same direction: only the loop closures inside each lap (its last metre near its start).
        assert_eq!(same.revisits, 20);
        assert_eq!(opposite.revisits, 400);
        assert_eq!(e.main.revisits, 410, "either direction, counted once");
        assert_eq!((opposite.pairs, opposite.correct_pairs), (400, 400));
        assert_eq!(opposite.recall, 1.0);
        assert_eq!(opposite.visit_recall, 1.0);
        assert!(opposite.pair_recall > 0.0 && same.pair_recall == 0.0);
        assert_eq!(same.pairs, 0);
        assert!(same.no_pairs);
        assert_eq!((e.main.pairs, e.main.precision), (400, 1.0));
        // The same pairs claimed as same-direction are wrong.
        let e = evaluate_as(Direction::Same);
        assert_eq!((e.main.pairs, e.main.correct_pairs), (400, 0));
        assert_eq!(e.directions.same.precision, 0.0);
        assert_eq!(e.directions.opposite.pairs, 0);
    }

    /// A recognition of `matches` over `obs` with truth `gt`, untimed.
    pub(crate) fn recognition(
        obs: &[Observation],
        gt: &GroundTruth,
        matches: Vec<Match>,
    ) -> Recognition {
        Recognition::new(
            "t",
            obs.to_vec(),
            matches,
            2,
            std::sync::Arc::new(gt.clone()),
        )
    }

    /// A log whose second pass is driven the other way at only 8 scattered observations has 8
    /// opposite revisits, none followed by another: the opposite figures are reported (the
    /// terminal's row per direction, and `longest_revisit_m`, 0 m, in the JSON) as they are for
    /// any figure with revisits; a direction without revisits writes no stretch.
    #[test]
    fn scattered_opposite_revisits_still_give_their_figures() {
        let (obs, mut gt) = circle(2, 40.0);
        for k in 0..8 {
            gt.frames[420 + 45 * k].pose.0.theta += std::f64::consts::PI;
        }
        let rec = recognition(&obs, &gt, Vec::new());
        let spec = EvaluationSpec::default();
        let e = evaluate(&rec, &spec);
        assert_eq!(e.directions.opposite.revisits, 8);
        assert_eq!(
            e.directions.opposite.longest_revisit_m,
            RevisitStretch::of(0.0)
        );
        let (scores, _, _) = crate::eval::scores::Scores::measure(&rec, &spec);
        let json = serde_json::to_value(&scores).unwrap();
        assert_eq!(json["directions"]["opposite"]["longest_revisit_m"], 0.0);
        assert!(scores.has_opposite());
        let (plain, _) = circle(1, 40.0);
        let e = evaluate(&recognition(&plain, &circle(1, 40.0).1, Vec::new()), &spec);
        let json = serde_json::to_value(&e.directions.opposite).unwrap();
        assert!(json.get("longest_revisit_m").is_none(), "{json}");
    }

    /// The level-wide longest revisit is the longer of the two directions', not a stretch that
    /// runs from same-direction revisits into opposite ones (fhw once gave 111.4 m against
    /// 37.7 m and 65.0 m).
    #[test]
    fn level_wide_longest_revisit_is_the_longer_direction() {
        let (obs, mut gt) = circle(2, 40.0);
        // Lap 2: 30 m driven as lap 1, then 10 m turned around (headings flipped).
        for f in &mut gt.frames[700..] {
            f.pose.0.theta += std::f64::consts::PI;
        }
        let e = evaluate(
            &recognition(&obs, &gt, Vec::new()),
            &EvaluationSpec::default(),
        );
        let (same, opposite) = (
            e.directions.same.longest_revisit_m.m,
            e.directions.opposite.longest_revisit_m.m,
        );
        // Lap 1's last metre (near its start) leads into lap 2's 30 m driven the same way.
        assert!((same - 30.9).abs() < 0.15, "{same}");
        assert!((opposite - 9.9).abs() < 0.15, "{opposite}");
        // Counted over revisits of either direction the stretch would run on to 40.9 m.
        assert_eq!(e.main.longest_revisit_m.m, same);
    }

    #[test]
    fn duplicate_pairs_count_once_and_majority_rule_for_matches() {
        let (obs, gt) = circle(2, 40.0);
        // Match 1: 2 correct, 1 wrong → correct match. Match 2 repeats a pair and adds a wrong
        // one: 1 of 2 correct → not more than half → wrong match.
        let m1 = one_match(vec![
            pair(&obs, 400, 0),
            pair(&obs, 401, 1),
            pair(&obs, 402, 200),
        ]);
        let m2 = one_match(vec![pair(&obs, 400, 0), pair(&obs, 403, 200)]);
        let m = score(&obs, &[m1, m2], &gt, &EvaluationSpec::default(), 1.0);
        assert_eq!((m.pairs, m.correct_pairs), (4, 2));
        assert_eq!((m.matches, m.correct_matches), (2, 1));
        assert_eq!(m.recalled, 2);
        assert!((m.precision - 0.5).abs() < 1e-12);
    }

    #[test]
    fn sensitivity_and_door_breakdown() {
        let (obs, gt) = circle(3, 40.0);
        // Pairs off by 15 observations (1.5 m along the circle): wrong at 1 m, right at 2 m.
        let matches = vec![one_match(
            (415..obs.len()).map(|q| pair(&obs, q, q - 415)).collect(),
        )];
        let rec = Recognition {
            seconds: 1.0,
            wall_seconds: 1.0,
            laps: 3,
            ..recognition(&obs, &gt, matches)
        };
        let e = evaluate(&rec, &EvaluationSpec::default());
        assert_eq!(e.main.precision, 0.0);
        assert_eq!(e.sensitivity.len(), 3);
        assert_eq!(e.sensitivity[0].precision, 0.0);
        assert_eq!(e.sensitivity[1].precision, 1.0);
        assert!(e.sensitivity[1].recall > 0.9, "{:?}", e.sensitivity[1]);
        let names: Vec<_> = e
            .door_configs
            .iter()
            .map(|d| d.door_config.as_str())
            .collect();
        assert_eq!(names, ["closed", "open"]);
        assert_eq!(e.door_configs[0].laps, 2);
        assert_eq!(e.door_configs[1].metrics.pairs, 385);
        assert_eq!(
            e.door_configs[0].metrics.revisits + e.door_configs[1].metrics.revisits,
            e.main.revisits
        );
    }

    #[test]
    fn revisits_counted_on_forty_long_laps() {
        // 40 laps × 2000 observations = 80 000, the size of scenario B (its cost: the scoring
        // bench, benches/scoring.rs).
        let (obs, gt) = circle(40, 200.0);
        let m = score(&obs, &[], &gt, &EvaluationSpec::default(), 3.0);
        assert_eq!(m.revisits, 39 * 2000 + 30);
    }

    #[test]
    fn scored_pairs_deduplicate_and_classify() {
        let (obs, gt) = circle(2, 40.0);
        let matches = vec![
            one_match(vec![pair(&obs, 400, 0), pair(&obs, 401, 200)]),
            one_match(vec![pair(&obs, 400, 0)]),
        ];
        let rec = recognition(&obs, &gt, matches);
        let p = scored_pairs(&rec, 1.0);
        assert_eq!(p.len(), 2);
        assert!(p[0].correct && !p[1].correct);
    }

    #[test]
    fn unknown_ids_are_not_scored() {
        let (obs, gt) = circle(2, 40.0);
        let mut p = pair(&obs, 400, 0);
        p.0 = 99_999;
        let m = score(
            &obs,
            &[one_match(vec![p])],
            &gt,
            &EvaluationSpec::default(),
            1.0,
        );
        assert_eq!((m.pairs, m.unresolved_pairs), (0, 1));
    }
}
