//! The computed results of an experiment: the [`Scores`] every recognizer gets, the [`Report`]
//! of one scenario, the [`SweepReport`] and the [`TableReport`]. Evaluation computes their
//! figures ([`Scores::measure`]) and what made a run without pairs ([`NoPairsCauses`]);
//! `report` words the causes (`report::explain`: `Scores::of`, `Report::add_subject`) and
//! formats the rest (`report::json` writes them as JSON, `report::table` as tables).
//!
//! JSON schema of [`Report`] (all times in seconds, ratios in [0, 1], radii in metres):
//!
//! ```text
//! { "scenario": "B", "seed": 7, "laps": 40, "revisits": 61234,
//!   "levels": [ { "levels": 3, "thresholds": [6, 9, 12],
//!                 "precision": 0.93, "recall": 0.41, "match_precision": 0.95,
//!                 "pairs": 10234, "correct_pairs": 9518, "no_pairs": false,
//!                 "matches": 812, "correct_matches": 771, "revisits": 61234,
//!                 "recall_either_side": 0.45, "visit_recall": 0.3, "pair_recall": 0.1,
//!                 "longest_revisit_m": 62.5,
//!                 "rejected_candidates": { "sampled": 25, "correct": 22,
//!                                          "correct_recognized": 19, "correct_by_check":
//!                                          [ { "check": "travel", "count": 10 }, ... ] }
//!                                        | absent,
//!                 "recognize_seconds_per_lap": 0.8, "recognize_seconds_by_lap": [0.7, 0.8, ...],
//!                 "only_here": { "than_levels": 2, "pairs": 812, "correct_pairs": 790 } | null,
//!                 "sensitivity": [ { "radius_m": 0.5, "precision": ..., "recall": ..., ... } ],
//!                 "door_configs": [ { "door_config": "all-closed", "laps": 20,
//!                                     "metrics": { "precision": ..., ... } } ],
//!                 "directions": { "same": { "precision": ..., "recall": ..., ... },
//!                                 "opposite": { ... } } } ],
//!   "icp": { same fields as a "levels" entry without "levels" and "thresholds" } | null,
//!   "simulate_seconds_per_lap": 0.4,
//!   "evaluation": { "tp_radius_m": 1.0, "min_gap_m": 20.0, "heading_tolerance_deg": 45.0,
//!                   "sensitivity_radii_m": [0.5, 2.0, 3.0] } }
//! ```
//!
//! Precision is 0 with `"no_pairs": true` when nothing was matched (never NaN); then
//! `"no_pairs_reason"` says why when it can tell, and `"diagnostics"` (the recognizer's longest
//! chains, verification counts and mean word length, when it tells) gives the figures behind
//! it. A subject with pairs one way whose other direction has revisits and none writes
//! `"direction_no_pairs_reasons": [ { "direction": "opposite", "reason": "..." } ]`: that
//! direction's longest revisit against the chain it needs, and what verification turned down
//! that way. `"longest_revisit_m"` (written whenever the figure has revisits, here and in each
//! direction's figures; the top-level one is the longer of the two directions') is the longest
//! stretch of true travel along which every observation has a revisit.

use super::Recognition;
use super::metrics::{
    DirectionMetrics, DoorConfigMetrics, Evaluation, Metrics, RevisitStretch, pairs_not_in,
};
use super::sweep::{PrCurve, SweepResult};
use crate::place::{Diagnostics, Direction};
use crate::spec::evaluation::EvaluationSpec;
use serde::{Deserialize, Serialize};

/// The scores every recognizer gets (flattened into its JSON object).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Scores {
    pub precision: f64,
    pub recall: f64,
    pub match_precision: f64,
    pub pairs: usize,
    pub correct_pairs: usize,
    pub no_pairs: bool,
    pub matches: usize,
    pub correct_matches: usize,
    pub revisits: usize,
    pub recall_either_side: f64,
    /// The longest stretch of true travel along which every observation has a revisit, metres
    /// (see `eval::metrics::Metrics::longest_revisit_m`: the longer of the two directions';
    /// written whenever there are revisits).
    #[serde(default, skip_serializing_if = "RevisitStretch::uncounted")]
    pub longest_revisit_m: RevisitStretch,
    /// Share of (observation, earlier lap through the same spot) pairs recognized: rewards
    /// matching across door changes (see `eval::metrics::Metrics::visit_recall`).
    #[serde(default)]
    pub visit_recall: f64,
    /// Correct pairs ÷ every pair that could have been found (see `eval::pair_recall`).
    #[serde(default)]
    pub pair_recall: f64,
    /// The recognizer's CPU seconds per lap (the thread's clock, [`crate::clock`]).
    pub recognize_seconds_per_lap: f64,
    /// The recognizer's wall-clock seconds per lap (more than the CPU figure when other work
    /// shares the cores).
    #[serde(default)]
    pub recognize_wall_seconds_per_lap: f64,
    /// CPU seconds spent scoring this subject's matches, in all.
    #[serde(default)]
    pub score_seconds: f64,
    /// Scores at each sensitivity radius.
    pub sensitivity: Vec<Metrics>,
    /// Scores per door configuration at `tp_radius_m`.
    pub door_configs: Vec<DoorConfigMetrics>,
    /// Scores per direction at `tp_radius_m`: the matches of that direction against the
    /// revisits of that direction (`eval::metrics`); the figures above count both.
    #[serde(default)]
    pub directions: DirectionMetrics,
    /// Set when there is no pair: why, as far as the evaluation and the recognizer can tell (no
    /// observation with a revisit; no chain of matching words as long as τ; every candidate
    /// rejected by verification, with counts per reason).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_pairs_reason: Option<String>,
    /// Per direction whose revisits got no pair while the other direction's did: why, as far
    /// as the recognizer and the truth tell (its longest stretch of revisits against the chain
    /// the recognizer needs that way, and the candidates of that direction verification turned
    /// down); empty otherwise (a subject without any pair says why in `no_pairs_reason`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub direction_no_pairs_reasons: Vec<DirectionReason>,
    /// The candidates the recognizer's verification turned down (as sampled), and how many of
    /// them the truth says were right; `None` when none was turned down.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejected_candidates: Option<RejectedScores>,
    /// What the recognizer saw, in its own counters (the paper's recognizer: longest chains,
    /// verification counts), when it tells.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diagnostics: Option<serde_json::Value>,
    /// The recognizer's notes worth showing beside the figures (e.g. inputs it could not use in
    /// full); empty when it has none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The field's figures over the match score, per query observation: the PR curve, max
    /// F1, recall at 100 % and 99 % precision, average precision, the query rate
    /// (`eval::ranking`); `None` where not computed (per direction, per door configuration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranking: Option<super::ranking::RankingScores>,
}

impl Scores {
    /// The scores of an evaluation and the timing of its recognition.
    pub fn new(e: &Evaluation, recognize_seconds_per_lap: f64) -> Self {
        Scores {
            sensitivity: e.sensitivity.clone(),
            door_configs: e.door_configs.clone(),
            directions: e.directions.clone(),
            ..Scores::of_metrics(&e.main, recognize_seconds_per_lap)
        }
    }

    /// The headline figures of `m` (no breakdowns).
    fn of_metrics(m: &Metrics, recognize_seconds_per_lap: f64) -> Self {
        Scores {
            precision: m.precision,
            recall: m.recall,
            match_precision: m.match_precision,
            pairs: m.pairs,
            correct_pairs: m.correct_pairs,
            no_pairs: m.no_pairs,
            matches: m.matches,
            correct_matches: m.correct_matches,
            revisits: m.revisits,
            recall_either_side: m.recall_either_side,
            longest_revisit_m: m.longest_revisit_m,
            visit_recall: m.visit_recall,
            pair_recall: m.pair_recall,
            recognize_seconds_per_lap,
            recognize_wall_seconds_per_lap: 0.0,
            score_seconds: 0.0,
            sensitivity: Vec::new(),
            door_configs: Vec::new(),
            directions: DirectionMetrics::default(),
            no_pairs_reason: None,
            direction_no_pairs_reasons: Vec::new(),
            rejected_candidates: None,
            diagnostics: None,
            notes: Vec::new(),
            ranking: None,
        }
    }

    /// The scores of one direction's matches against that direction's revisits (no
    /// breakdowns), with the same timing.
    pub fn of_direction(&self, d: crate::place::Direction) -> Self {
        let m = match d {
            crate::place::Direction::Same => &self.directions.same,
            crate::place::Direction::Opposite => &self.directions.opposite,
        };
        Scores::of_metrics(m, self.recognize_seconds_per_lap)
    }

    /// Whether there is anything to say about the opposite direction: revisits driven the
    /// other way, or opposite matches.
    pub fn has_opposite(&self) -> bool {
        self.directions.opposite.revisits > 0 || self.directions.opposite.pairs > 0
    }

    /// Evaluates `rec` with `spec` and takes its timing (the scoring's included): the figures,
    /// with `no_pairs_reason` unset, and what made a run without pairs, when it has none.
    /// `Scores::of` (`report::explain`) puts the causes into words.
    pub fn measure(
        rec: &Recognition,
        spec: &EvaluationSpec,
    ) -> (Self, Option<NoPairsCauses>, Vec<DirectionCauses>) {
        let w = crate::clock::Stopwatch::start();
        let e = super::evaluate(rec, spec);
        let d = rec.diagnostics.as_deref();
        let rejected =
            d.and_then(|d| RejectedScores::of(&rec.rejected, &d.checks(), spec, &e.recognized));
        let ranking = super::ranking::of_recognition(rec, e.main.revisits, spec);
        let causes = no_pairs_causes(&e, d, rejected.as_ref());
        let directions = d.map_or_else(Vec::new, |d| direction_causes(&e, d, &rec.rejected, spec));
        let scores = Scores {
            recognize_wall_seconds_per_lap: rec.wall_seconds_per_lap(),
            score_seconds: rec.score_seconds + w.cpu_s(),
            rejected_candidates: rejected,
            diagnostics: d.map(Diagnostics::to_json),
            notes: d.map(Diagnostics::notes).unwrap_or_default(),
            ranking: Some(ranking),
            ..Scores::new(&e, rec.seconds_per_lap())
        };
        (scores, causes, directions)
    }
}

/// Why one direction's revisits got no pair, in words ([`Scores::direction_no_pairs_reasons`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct DirectionReason {
    pub direction: Direction,
    pub reason: String,
}

impl DirectionReason {
    pub fn new(direction: Direction, reason: String) -> Self {
        DirectionReason { direction, reason }
    }
}

/// What made one direction's revisits get no pair while the other direction's did
/// (`report::explain` puts it into words for [`Scores::direction_no_pairs_reasons`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct DirectionCauses {
    pub direction: Direction,
    /// [`Diagnostics::direction_length_reason`] against that direction's longest revisit.
    pub length_reason: Option<String>,
    /// The candidates of that direction verification turned down, scored against the truth;
    /// `None` when none was (as sampled).
    pub rejected: Option<RejectedScores>,
}

/// For each direction with revisits and no pair, when the other direction has pairs: its
/// longest revisit in the recognizer's words and its candidates `rejected` scored with `spec`
/// (a subject without any pair is explained by [`no_pairs_causes`] instead).
pub fn direction_causes(
    e: &Evaluation,
    d: &dyn Diagnostics,
    rejected: &[super::RejectedTruth],
    spec: &EvaluationSpec,
) -> Vec<DirectionCauses> {
    if e.main.pairs == 0 {
        return Vec::new();
    }
    Direction::BOTH
        .into_iter()
        .filter_map(|direction| {
            let m = match direction {
                Direction::Same => &e.directions.same,
                Direction::Opposite => &e.directions.opposite,
            };
            if m.revisits == 0 || m.pairs > 0 {
                return None;
            }
            let that_way: Vec<_> = rejected
                .iter()
                .filter(|r| r.direction == direction)
                .copied()
                .collect();
            Some(DirectionCauses {
                direction,
                length_reason: d.direction_length_reason(direction, m.longest_revisit_m.m),
                rejected: RejectedScores::of(&that_way, &d.checks(), spec, &e.recognized),
            })
        })
        .collect()
}

/// What made an evaluation without pairs, as far as the truth and the recognizer tell
/// (`report::explain` puts it into words for `Scores::no_pairs_reason`).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct NoPairsCauses {
    /// No observation has a revisit (within `tp_radius_m`, `min_gap_m` of travel before).
    pub no_revisit: bool,
    /// The recognizer's own account, when it keeps diagnostics.
    pub recognizer: Option<RecognizerAccount>,
}

/// A recognizer's account of why it matched nothing, in its own words
/// ([`Diagnostics`]), with the truth of the candidates its verification turned down.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RecognizerAccount {
    /// [`Diagnostics::no_match_reason`].
    pub no_match_reason: String,
    /// [`Diagnostics::revisit_length_reason`] against the longest revisits of each
    /// direction, when there were revisits but no candidate at all.
    pub revisit_length_reason: Option<String>,
    /// The rejected candidates scored against the truth, when none was accepted.
    pub rejected: Option<RejectedScores>,
}

/// What made evaluation `e` have no pair, from the truth, the recognizer's `diagnostics` and
/// its `rejected` candidates scored; `None` when there are pairs.
pub fn no_pairs_causes(
    e: &Evaluation,
    diagnostics: Option<&dyn Diagnostics>,
    rejected: Option<&RejectedScores>,
) -> Option<NoPairsCauses> {
    let m = &e.main;
    if m.pairs > 0 {
        return None;
    }
    let recognizer = diagnostics.map(|d| {
        let c = d.candidates();
        RecognizerAccount {
            no_match_reason: d.no_match_reason(),
            revisit_length_reason: if m.revisits > 0 && c.accepted + c.rejected == 0 {
                d.revisit_length_reason(
                    e.directions.same.longest_revisit_m.m,
                    e.directions.opposite.longest_revisit_m.m,
                )
            } else {
                None
            },
            rejected: if c.accepted == 0 {
                rejected.cloned()
            } else {
                None
            },
        }
    });
    Some(NoPairsCauses {
        no_revisit: m.revisits == 0,
        recognizer,
    })
}

/// The candidates a recognizer turned down, scored against the truth at their sampled
/// observation pairs (`eval::Recognition::rejected`).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RejectedScores {
    /// Rejected candidates sampled (the paper's recognizer keeps the first 10,000).
    pub sampled: usize,
    /// Of them, those whose pair is correct at `tp_radius_m` (same place, facing as the
    /// candidate's direction claims): true revisits that verification turned down.
    pub correct: usize,
    /// `correct` per check that turned them down, in the recognizer's order of checks (every
    /// check named, 0 included).
    pub correct_by_check: Vec<CheckCount>,
    /// Of `correct`, those whose query observation is the newer side of a correct pair by the
    /// end of the run: verification made the revisit wait (a later, longer n-gram through it
    /// was accepted, or another match found it), it did not lose it. `correct` minus this is
    /// what the checks cost the recall at the sampled candidates.
    #[serde(default)]
    pub correct_recognized: usize,
}

/// A count for one of a recognizer's checks.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct CheckCount {
    /// The check's name, as the recognizer calls it ("turn").
    pub check: String,
    pub count: usize,
}

impl CheckCount {
    /// `count` for the check named `check`.
    pub fn new(check: &str, count: usize) -> Self {
        CheckCount {
            check: check.to_string(),
            count,
        }
    }
}

impl RejectedScores {
    /// The scores of `rejected` (turned down by the named `checks`) with `spec`'s radius and
    /// heading tolerance, `recognized` saying per observation whether it is the newer side of
    /// a correct pair ([`super::Evaluation::recognized`]); `None` when empty.
    pub fn of(
        rejected: &[super::RejectedTruth],
        checks: &[String],
        spec: &EvaluationSpec,
        recognized: &[bool],
    ) -> Option<Self> {
        if rejected.is_empty() {
            return None;
        }
        let mut s = RejectedScores {
            sampled: rejected.len(),
            correct: 0,
            correct_by_check: checks.iter().map(|c| CheckCount::new(c, 0)).collect(),
            correct_recognized: 0,
        };
        for r in rejected.iter().filter(|r| r.is_right(spec)) {
            s.correct += 1;
            s.correct_recognized += usize::from(recognized.get(r.query_index) == Some(&true));
            if let Some(c) = s.correct_by_check.get_mut(r.check) {
                c.count += 1;
            }
        }
        Some(s)
    }

    /// Correct rejections by the check named `check` (0 when it has no such check).
    pub fn correct_by(&self, check: &str) -> usize {
        self.correct_by_check
            .iter()
            .find(|c| c.check == check)
            .map_or(0, |c| c.count)
    }
}

/// What kind of recognizer a subject is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SubjectKind {
    /// The paper's recognizer at one level configuration (multi-level words of densities).
    Words,
    /// The ICP scan-matching baseline.
    Icp,
    /// A Scan Context-style polar descriptor baseline.
    ScanContext,
    /// A recognizer outside the harness (a program speaking the plug-in protocol).
    External,
}

impl SubjectKind {
    /// Its name in reports: `words`, `icp`, `scan-context`, `external`.
    pub fn name(self) -> &'static str {
        match self {
            SubjectKind::Words => "words",
            SubjectKind::Icp => "icp",
            SubjectKind::ScanContext => "scan-context",
            SubjectKind::External => "external",
        }
    }
}

pub use crate::spec::evaluation::{words_subject_levels, words_subject_name};

/// The result of one subject: a recognizer under test (one level configuration of the paper's
/// recognizer, a baseline, or an external program), scored on the same runs as the others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SubjectReport {
    /// Its name, unique in the report: what `[[expect.subjects]]`, tables and JUnit call it
    /// (`words-3`, `icp`, or the name an external subject was given).
    pub name: String,
    pub kind: SubjectKind,
    /// Words subjects: 1 = level 0 only, 2 = levels 0-1, 3 = levels 0-2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub levels: Option<usize>,
    /// Words subjects: minimum n-gram size τ per level.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub thresholds: Vec<usize>,
    #[serde(flatten)]
    pub scores: Scores,
    /// The recognizer's seconds on each lap's frames, in the order fed (how per-lap work grows
    /// with history): thread CPU time where readable (see `Recognition::lap_seconds`); empty
    /// when not recorded.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recognize_seconds_by_lap: Vec<f64>,
    /// Words subjects: the distinct pairs this configuration found that the configuration with
    /// one level fewer did not (`None` when that one was not run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub only_here: Option<LevelGain>,
}

impl SubjectReport {
    /// A subject `name` of `kind` with `scores` (no per-lap times, no level gain).
    pub fn new(name: &str, kind: SubjectKind, scores: Scores) -> Self {
        SubjectReport {
            name: name.to_string(),
            kind,
            levels: None,
            thresholds: Vec::new(),
            scores,
            recognize_seconds_by_lap: Vec::new(),
            only_here: None,
        }
    }

    /// The paper recognizer's subject with `levels` levels and τ per level `thresholds`.
    pub fn words(levels: usize, thresholds: &[usize], scores: Scores) -> Self {
        SubjectReport {
            levels: Some(levels),
            thresholds: thresholds.to_vec(),
            ..SubjectReport::new(&words_subject_name(levels), SubjectKind::Words, scores)
        }
    }

    /// How tables label it: `words-3 [6, 9, 12]` (its τ per level), or its name.
    pub fn label(&self) -> String {
        if self.thresholds.is_empty() {
            return self.name.clone();
        }
        let th: Vec<String> = self.thresholds.iter().map(|t| t.to_string()).collect();
        format!("{} [{}]", self.name, th.join(", "))
    }
}

/// What a level configuration adds over the one with one level fewer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct LevelGain {
    /// The configuration compared with (levels − 1).
    pub than_levels: usize,
    /// Distinct (query, past) observation pairs found here and not there.
    pub pairs: usize,
    /// How many of them are correct at `tp_radius_m`.
    pub correct_pairs: usize,
}

impl LevelGain {
    /// `pairs` found (`correct_pairs` of them correct) that the configuration with
    /// `than_levels` levels did not find.
    pub fn new(than_levels: usize, pairs: usize, correct_pairs: usize) -> Self {
        LevelGain {
            than_levels,
            pairs,
            correct_pairs,
        }
    }
}

/// The report of one scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Report {
    /// Scenario name (file stem, e.g. "B").
    pub scenario: String,
    pub seed: u64,
    /// Laps driven in all runs.
    pub laps: usize,
    /// Observations with a revisit at `tp_radius_m` (those of the first subject reported).
    pub revisits: usize,
    /// Every recognizer scored on these runs: the paper's level configurations first, by
    /// levels, then the others in the order they were run.
    pub subjects: Vec<SubjectReport>,
    pub simulate_seconds_per_lap: f64,
    /// How the scores were computed.
    pub evaluation: EvaluationSpec,
    /// Set when the runs are a real log's (not simulated): what it held.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log: Option<LogSummary>,
}

/// What a real log held, for a report's header (a log has no laps or door states).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct LogSummary {
    /// Scans the recognizers were given (after `--scan-step`).
    pub scans: usize,
    /// True travel along the log, metres.
    pub travel_m: f64,
}

impl LogSummary {
    /// The scans and travel of a real log's ground truth.
    pub fn of(truth: &super::GroundTruth) -> Self {
        LogSummary {
            scans: truth.frames.len(),
            travel_m: truth.frames.last().map_or(0.0, |f| f.travel_m),
        }
    }
}

impl Report {
    /// An empty report; add subjects, then call [`Report::finish`].
    pub fn new(scenario: &str, seed: u64, laps: usize, evaluation: EvaluationSpec) -> Self {
        Report {
            scenario: scenario.to_string(),
            seed,
            laps,
            revisits: 0,
            subjects: Vec::new(),
            simulate_seconds_per_lap: 0.0,
            evaluation,
            log: None,
        }
    }

    /// Sets the top-level `revisits` from the first subject and puts the words subjects first,
    /// by levels (the others keep their order).
    pub fn finish(&mut self) {
        self.subjects
            .sort_by_key(|s| (s.kind != SubjectKind::Words, s.levels.unwrap_or(0)));
        self.revisits = self.subjects.first().map_or(0, |s| s.scores.revisits);
    }

    /// Sets each level configuration's `only_here` from the recognitions of every configuration
    /// run, `(levels, recognition)`: the pairs it found that the one with one level fewer did not.
    pub fn set_level_gains(&mut self, recognitions: &[(usize, Recognition)]) {
        let radius_m = self.evaluation.tp_radius_m;
        let rec_of = |levels: usize| {
            recognitions
                .iter()
                .find(|(l, _)| *l == levels)
                .map(|(_, rec)| rec)
        };
        for lr in &mut self.subjects {
            let Some(levels) = lr.levels else { continue };
            let below = levels.saturating_sub(1);
            let (Some(here), Some(fewer)) = (rec_of(levels), rec_of(below)) else {
                continue;
            };
            // Counted as the matches arrived when they were scored so (the two configurations
            // compared as they forgot their pairs, `experiment::stream`); from the matches
            // otherwise.
            let (pairs, correct_pairs) = match here.level_gain {
                Some(gain) => gain,
                None => pairs_not_in(here, fewer, radius_m),
            };
            lr.only_here = Some(LevelGain::new(below, pairs, correct_pairs));
        }
    }

    /// The subject called `name`.
    pub fn subject(&self, name: &str) -> Option<&SubjectReport> {
        self.subjects.iter().find(|s| s.name == name)
    }

    /// The paper recognizer's subject with `levels` levels.
    pub fn level(&self, levels: usize) -> Option<&SubjectReport> {
        self.subjects.iter().find(|s| s.levels == Some(levels))
    }

    /// The paper recognizer's subjects, by levels.
    pub fn words(&self) -> impl Iterator<Item = &SubjectReport> {
        self.subjects.iter().filter(|s| s.levels.is_some())
    }
}

/// The JSON output of `placewords sweep`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SweepReport {
    pub scenario: String,
    pub seed: u64,
    pub laps: usize,
    pub evaluation: EvaluationSpec,
    /// Every grid point, in grid order.
    pub results: Vec<SweepResult>,
    /// The PR curves built from `results`.
    pub curves: Vec<PrCurve>,
    /// Each words subject's curve over its match score, at the scenario's thresholds
    /// (`eval::ranking`; untimed: query rate 0).
    #[serde(default)]
    pub score_curves: Vec<super::ranking::SubjectRanking>,
}

impl SweepReport {
    /// A sweep report of `results` (in grid order) with its PR curves, and the subjects'
    /// `score_curves`.
    pub fn new(
        scenario: &str,
        seed: u64,
        laps: usize,
        evaluation: EvaluationSpec,
        results: Vec<SweepResult>,
        score_curves: Vec<super::ranking::SubjectRanking>,
    ) -> Self {
        let curves = super::sweep::pr_curves(&results);
        SweepReport {
            scenario: scenario.to_string(),
            seed,
            laps,
            evaluation,
            results,
            curves,
            score_curves,
        }
    }
}

/// The JSON output of `placewords table`: one report per scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct TableReport {
    pub reports: Vec<Report>,
}

impl TableReport {
    /// The table of `reports`, one per scenario.
    pub fn new(reports: Vec<Report>) -> Self {
        TableReport { reports }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn sample(scenario: &str, p: [f64; 3], r: [f64; 3]) -> Report {
        let mut rep = Report::new(scenario, 7, 40, EvaluationSpec::default());
        let th = [vec![6], vec![6, 9], vec![6, 9, 12]];
        for l in 0..3 {
            let scores = Scores {
                precision: p[l],
                recall: r[l],
                pairs: 100 * (l + 1),
                revisits: 5000,
                recognize_seconds_per_lap: 0.5 * (l + 1) as f64,
                ..Scores::default()
            };
            rep.subjects
                .push(SubjectReport::words(l + 1, &th[l], scores));
        }
        rep.subjects.push(SubjectReport::new(
            "icp",
            SubjectKind::Icp,
            Scores {
                precision: 0.05,
                recall: 0.04,
                revisits: 4900,
                recognize_seconds_per_lap: 9.0,
                ..Scores::default()
            },
        ));
        rep.simulate_seconds_per_lap = 0.25;
        rep.finish();
        rep
    }
}
