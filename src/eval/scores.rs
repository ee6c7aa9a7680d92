//! The computed results of an experiment: the [`Scores`] every recognizer gets, the [`Report`]
//! of one scenario, the [`SweepReport`] and the [`TableReport`]. Evaluation builds them;
//! `report` only formats them (`report::json` writes them as JSON, `report::table` as tables).
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
//!                 "rejected_candidates": { "sampled": 25, "correct": 22, "correct_travel": 10,
//!                                          "correct_turn": 8, ... } | absent,
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
//! it. `"longest_revisit_m"` (written whenever the figure has revisits, here and in each
//! direction's figures; the top-level one is the longer of the two directions') is the longest
//! stretch of true travel along which every observation has a revisit.

use super::Recognition;
use super::metrics::{
    DirectionMetrics, DoorConfigMetrics, Evaluation, Metrics, RevisitStretch, pairs_not_in,
};
use super::sweep::{PrCurve, SweepResult};
use crate::place::Diagnostics;
use crate::spec::evaluation::EvaluationSpec;
use serde::{Deserialize, Serialize};

/// The scores every recognizer gets (flattened into its JSON object).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
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

    /// Evaluates `rec` with `spec` and takes its timing (the scoring's included).
    pub fn of(rec: &Recognition, spec: &EvaluationSpec) -> Self {
        let w = crate::clock::Stopwatch::start();
        let e = super::evaluate(rec, spec);
        let d = rec.diagnostics.as_deref();
        let rejected = d.and_then(|d| RejectedScores::of(&rec.rejected, &d.checks(), spec));
        let ranking = super::ranking::of_recognition(rec, e.main.revisits, spec);
        Scores {
            recognize_wall_seconds_per_lap: rec.wall_seconds_per_lap(),
            score_seconds: rec.score_seconds + w.cpu_s(),
            no_pairs_reason: no_pairs_reason(&e, d, rejected.as_ref(), spec),
            rejected_candidates: rejected,
            diagnostics: d.map(Diagnostics::to_json),
            notes: d.map(Diagnostics::notes).unwrap_or_default(),
            ranking: Some(ranking),
            ..Scores::new(&e, rec.seconds_per_lap())
        }
    }
}

/// Why evaluation `e` has no pair, as far as the truth and the recognizer's `diagnostics` tell;
/// `None` when there are pairs.
pub fn no_pairs_reason(
    e: &Evaluation,
    diagnostics: Option<&dyn Diagnostics>,
    rejected: Option<&RejectedScores>,
    spec: &EvaluationSpec,
) -> Option<String> {
    let m = &e.main;
    if m.pairs > 0 {
        return None;
    }
    let mut why = Vec::new();
    if m.revisits == 0 {
        why.push(format!(
            "no observation has a revisit (an earlier pass within {} m, {} m of travel before)",
            spec.tp_radius_m, spec.min_gap_m
        ));
    }
    match diagnostics {
        Some(d) => {
            why.push(d.no_match_reason());
            let c = d.candidates();
            if m.revisits > 0 && c.accepted + c.rejected == 0 {
                why.extend(d.revisit_length_reason(
                    e.directions.same.longest_revisit_m.m,
                    e.directions.opposite.longest_revisit_m.m,
                ));
            }
            if c.accepted == 0 {
                why.extend(rejected.map(|r| r.sentence(spec)));
            }
        }
        None if why.is_empty() => why.push("the recognizer does not say why".into()),
        None => {}
    }
    Some(why.join("; "))
}

/// The candidates a recognizer turned down, scored against the truth at their sampled
/// observation pairs (`eval::Recognition::rejected`).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct RejectedScores {
    /// Rejected candidates sampled (the paper's recognizer keeps the first 10,000).
    pub sampled: usize,
    /// Of them, those whose pair is correct at `tp_radius_m` (same place, facing as the
    /// candidate's direction claims): true revisits that verification turned down.
    pub correct: usize,
    /// `correct` per check that turned them down, in the recognizer's order of checks (every
    /// check named, 0 included).
    pub correct_by_check: Vec<CheckCount>,
}

/// A count for one of a recognizer's checks.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct CheckCount {
    /// The check's name, as the recognizer calls it ("turn").
    pub check: String,
    pub count: usize,
}

impl RejectedScores {
    /// The scores of `rejected` (turned down by the named `checks`) with `spec`'s radius and
    /// heading tolerance; `None` when empty.
    pub fn of(
        rejected: &[super::RejectedTruth],
        checks: &[String],
        spec: &EvaluationSpec,
    ) -> Option<Self> {
        if rejected.is_empty() {
            return None;
        }
        let mut s = RejectedScores {
            sampled: rejected.len(),
            correct: 0,
            correct_by_check: checks
                .iter()
                .map(|c| CheckCount {
                    check: c.clone(),
                    count: 0,
                })
                .collect(),
        };
        for r in rejected.iter().filter(|r| r.is_right(spec)) {
            s.correct += 1;
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

    /// What the truth says of the rejected candidates, in words.
    fn sentence(&self, spec: &EvaluationSpec) -> String {
        if self.correct == 0 {
            return format!(
                "by the ground truth none of the {} rejected candidates sampled paired the same \
                 place (within {} m): verification turned down look-alikes",
                self.sampled, spec.tp_radius_m
            );
        }
        let by_check: Vec<String> = self
            .correct_by_check
            .iter()
            .map(|c| format!("{} {}", c.check, c.count))
            .collect();
        format!(
            "by the ground truth {} of the {} rejected candidates sampled paired the same place \
             (within {} m; {}): verification turned down true revisits",
            self.correct,
            self.sampled,
            spec.tp_radius_m,
            by_check.join(", ")
        )
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
pub struct LevelGain {
    /// The configuration compared with (levels − 1).
    pub than_levels: usize,
    /// Distinct (query, past) observation pairs found here and not there.
    pub pairs: usize,
    /// How many of them are correct at `tp_radius_m`.
    pub correct_pairs: usize,
}

/// The report of one scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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

    /// Scores `rec` (the paper's recognizer run with `levels` levels and `thresholds`) and adds
    /// it as subject `words-<levels>`.
    pub fn add_level(
        &mut self,
        levels: usize,
        thresholds: &[usize],
        rec: &Recognition,
    ) -> &SubjectReport {
        let added = self.add_subject(&words_subject_name(levels), SubjectKind::Words, rec);
        added.levels = Some(levels);
        added.thresholds = thresholds.to_vec();
        added
    }

    /// Scores `rec` and adds it as the subject `name` of `kind`.
    pub fn add_subject(
        &mut self,
        name: &str,
        kind: SubjectKind,
        rec: &Recognition,
    ) -> &mut SubjectReport {
        let mut added = SubjectReport::new(name, kind, Scores::of(rec, &self.evaluation));
        added.recognize_seconds_by_lap = rec.lap_seconds.clone();
        self.subjects.push(added);
        self.subjects.last_mut().expect("just pushed")
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
            lr.only_here = Some(LevelGain {
                than_levels: below,
                pairs,
                correct_pairs,
            });
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
pub struct TableReport {
    pub reports: Vec<Report>,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::recognizer::{MatchDiagnostics, Rejection};

    /// A run without pairs says why: verification counts when every candidate was rejected,
    /// chain lengths against τ when no chain was long enough, and missing revisits.
    #[test]
    fn no_pairs_reason_names_the_cause() {
        let spec = EvaluationSpec::default();
        let none = Evaluation {
            main: Metrics {
                revisits: 10,
                ..Metrics::default()
            },
            ..Evaluation::default()
        };
        let mut d = MatchDiagnostics {
            longest_chain: vec![7, 9],
            min_ngram: vec![6, 9],
            within_gap: 0,
            verification: Default::default(),
            long_steps: 0,
            reverse_extra_ngram: 0,
            rejected: Vec::new(),
            mean_word_m: 0.0,
        };
        d.verification.rejected_travel = 3;
        d.verification.rejected_density = 2;
        d.verification.rejected_straight = 1;
        let why = no_pairs_reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(
            why.contains(
                "rejected by verification: 6 (travel 3, turn 0, density 2, sides 0, straight 1)"
            ),
            "{why}"
        );
        d.verification = Default::default();
        d.longest_chain = vec![4, 8];
        let why = no_pairs_reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("4 (τ = 6) at 1 level, 8 (τ = 9) at 2 levels"),
            "{why}"
        );
        d.long_steps = 3;
        let why = no_pairs_reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("3 steps between scans were longer than max_interpolation_m"),
            "{why}"
        );
        let why = no_pairs_reason(&Evaluation::default(), None, None, &spec).unwrap();
        assert!(why.starts_with("no observation has a revisit"), "{why}");
        let mut some = none.clone();
        some.main.pairs = 1;
        assert_eq!(
            no_pairs_reason(&some, Some(&d as &dyn Diagnostics), None, &spec),
            None
        );
    }

    /// When no chain is long enough, the reason says whether the revisits are shorter than τ
    /// words of the run's mean length (nothing to chain) or long enough (the words differ).
    #[test]
    fn no_pairs_reason_compares_revisit_length_with_tau_words() {
        let spec = EvaluationSpec::default();
        let mut e = Evaluation::default();
        e.main.revisits = 300;
        e.main.longest_revisit_m = 20.2.into();
        e.directions.same.longest_revisit_m = 11.2.into();
        e.directions.opposite.longest_revisit_m = 9.0.into();
        let d = MatchDiagnostics {
            longest_chain: vec![4],
            min_ngram: vec![6],
            mean_word_m: 2.5,
            ..MatchDiagnostics::default()
        };
        let why = no_pairs_reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("is 11.2 m driven the same way and 9.0 m the other way"),
            "{why}"
        );
        assert!(why.contains("a word spans 2.5 m on average"), "{why}");
        assert!(why.contains("τ = 6 words need about 15 m,"), "{why}");
        assert!(why.contains("too short for a chain"), "{why}");
        // Read backwards a chain needs more words: 16 m is enough driven the same way, not
        // the other way.
        let d = MatchDiagnostics {
            reverse_extra_ngram: 2,
            ..d
        };
        e.directions.opposite.longest_revisit_m = 16.0.into();
        let why = no_pairs_reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(
            why.contains("τ = 6 words need about 15 m (8 read backwards, about 20 m)"),
            "{why}"
        );
        assert!(why.contains("too short for a chain"), "{why}");
        e.directions.same.longest_revisit_m = 16.0.into();
        let why = no_pairs_reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("the words differ between visits"), "{why}");
        // Verification's counts are the reason when candidates were made.
        let mut v = d.clone();
        v.verification.rejected_turn = 2;
        let why = no_pairs_reason(&e, Some(&v as &dyn Diagnostics), None, &spec).unwrap();
        assert!(!why.contains("stretch"), "{why}");
    }

    /// Rejected candidates are scored at their sampled pair: right when the two true poses are
    /// within the radius and face as the candidate's direction claims; the reason then says
    /// whether verification turned down true revisits or look-alikes.
    #[test]
    fn rejected_candidates_are_scored_against_the_truth() {
        use crate::eval::RejectedTruth;
        use crate::geom::{Pose2, TruePose};
        use crate::place::Direction;
        let spec = EvaluationSpec::default();
        let at = |x: f64, theta_deg: f64| TruePose(Pose2::new(x, 0.0, theta_deg.to_radians()));
        let r = |q, p, direction, reason: Rejection| RejectedTruth {
            query: q,
            past: p,
            direction,
            check: reason.index(),
        };
        let checks: Vec<String> = Rejection::ALL.iter().map(|r| r.name().into()).collect();
        let rejected = [
            // The same place, facing alike: a true revisit turned down by the turn check.
            r(
                at(0.0, 0.0),
                at(0.5, 10.0),
                Direction::Same,
                Rejection::Turn,
            ),
            // The same place driven the other way, claimed opposite: right too.
            r(
                at(0.0, 0.0),
                at(0.3, 175.0),
                Direction::Opposite,
                Rejection::Sides,
            ),
            // Claimed the same direction but driven the other way: wrong.
            r(
                at(0.0, 0.0),
                at(0.3, 175.0),
                Direction::Same,
                Rejection::Turn,
            ),
            // A look-alike 5 m away.
            r(
                at(0.0, 0.0),
                at(5.0, 0.0),
                Direction::Same,
                Rejection::Travel,
            ),
        ];
        let s = RejectedScores::of(&rejected, &checks, &spec).expect("four sampled");
        assert_eq!((s.sampled, s.correct), (4, 2));
        assert_eq!(
            (
                s.correct_by("turn"),
                s.correct_by("sides"),
                s.correct_by("travel")
            ),
            (1, 1, 0)
        );
        assert_eq!(RejectedScores::of(&[], &checks, &spec), None);
        let mut e = Evaluation::default();
        e.main.revisits = 10;
        let d = MatchDiagnostics {
            longest_chain: vec![8],
            min_ngram: vec![6],
            verification: crate::recognizer::VerificationCounts {
                rejected_turn: 2,
                rejected_sides: 1,
                rejected_travel: 1,
                ..Default::default()
            },
            ..MatchDiagnostics::default()
        };
        let why = no_pairs_reason(&e, Some(&d as &dyn Diagnostics), Some(&s), &spec).unwrap();
        assert!(
            why.contains("every candidate was rejected by verification: 4"),
            "{why}"
        );
        assert!(
            why.contains("2 of the 4 rejected candidates sampled paired the same place"),
            "{why}"
        );
        assert!(why.contains("turned down true revisits"), "{why}");
        let none_right = RejectedScores::of(&rejected[3..], &checks, &spec).unwrap();
        let why =
            no_pairs_reason(&e, Some(&d as &dyn Diagnostics), Some(&none_right), &spec).unwrap();
        assert!(why.contains("turned down look-alikes"), "{why}");
    }

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
