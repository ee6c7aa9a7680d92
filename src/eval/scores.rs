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
//!                 "recognize_seconds_per_lap": 0.8, "recognize_seconds_by_lap": [0.7, 0.8, ...],
//!                 "sensitivity": [ { "radius_m": 0.5, "precision": ..., "recall": ..., ... } ],
//!                 "door_configs": [ { "door_config": "all-closed", "laps": 20,
//!                                     "metrics": { "precision": ..., ... } } ] } ],
//!   "icp": { same fields as a "levels" entry without "levels" and "thresholds" } | null,
//!   "simulate_seconds_per_lap": 0.4,
//!   "evaluation": { "tp_radius_m": 1.0, "min_gap_m": 20.0, "heading_tolerance_deg": 45.0,
//!                   "sensitivity_radii_m": [0.5, 2.0, 3.0] } }
//! ```
//!
//! Precision is 0 with `"no_pairs": true` when nothing was matched (never NaN).

use super::Recognition;
use super::metrics::{DoorConfigMetrics, Evaluation, Metrics};
use super::sweep::{PrCurve, SweepResult};
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
    /// Share of (observation, earlier lap through the same spot) pairs recognized: rewards
    /// matching across door changes (see `eval::metrics::Metrics::visit_recall`).
    #[serde(default)]
    pub visit_recall: f64,
    /// Correct pairs ÷ every pair that could have been found (see `eval::pair_recall`).
    #[serde(default)]
    pub pair_recall: f64,
    pub recognize_seconds_per_lap: f64,
    /// Scores at each sensitivity radius.
    pub sensitivity: Vec<Metrics>,
    /// Scores per door configuration at `tp_radius_m`.
    pub door_configs: Vec<DoorConfigMetrics>,
}

impl Scores {
    /// The scores of an evaluation and the timing of its recognition.
    pub fn new(e: &Evaluation, recognize_seconds_per_lap: f64) -> Self {
        let m = &e.main;
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
            visit_recall: m.visit_recall,
            pair_recall: m.pair_recall,
            recognize_seconds_per_lap,
            sensitivity: e.sensitivity.clone(),
            door_configs: e.door_configs.clone(),
        }
    }

    /// Evaluates `rec` with `spec` and takes its timing.
    pub fn of(rec: &Recognition, spec: &EvaluationSpec) -> Self {
        Scores::new(&super::evaluate(rec, spec), rec.seconds_per_lap())
    }
}

/// The result of one level configuration of the recognizer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelReport {
    /// 1 = level 0 only, 2 = levels 0-1, 3 = levels 0-2.
    pub levels: usize,
    /// Minimum n-gram size per level.
    pub thresholds: Vec<usize>,
    #[serde(flatten)]
    pub scores: Scores,
    /// The recognizer's seconds on each lap's frames, in the order fed (how per-lap work grows
    /// with history): thread CPU time where readable (see `Recognition::lap_seconds`); empty
    /// when not recorded.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recognize_seconds_by_lap: Vec<f64>,
}

/// The result of the ICP baseline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IcpReport {
    #[serde(flatten)]
    pub scores: Scores,
}

/// The report of one scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Scenario name (file stem, e.g. "B").
    pub scenario: String,
    pub seed: u64,
    /// Laps driven in all runs.
    pub laps: usize,
    /// Observations with a revisit at `tp_radius_m` (those of the first level configuration
    /// reported, or of ICP when there is none).
    pub revisits: usize,
    pub levels: Vec<LevelReport>,
    pub icp: Option<IcpReport>,
    pub simulate_seconds_per_lap: f64,
    /// How the scores were computed.
    pub evaluation: EvaluationSpec,
}

impl Report {
    /// An empty report; push level results and set `icp`, then call [`Report::finish`].
    pub fn new(scenario: &str, seed: u64, laps: usize, evaluation: EvaluationSpec) -> Self {
        Report {
            scenario: scenario.to_string(),
            seed,
            laps,
            revisits: 0,
            levels: Vec::new(),
            icp: None,
            simulate_seconds_per_lap: 0.0,
            evaluation,
        }
    }

    /// Sets the top-level `revisits` from the parts and sorts levels by number of levels.
    pub fn finish(&mut self) {
        self.levels.sort_by_key(|l| l.levels);
        self.revisits = self
            .levels
            .first()
            .map(|l| l.scores.revisits)
            .or(self.icp.as_ref().map(|i| i.scores.revisits))
            .unwrap_or(0);
    }

    /// Scores `rec` (a recognizer run with `levels` levels and `thresholds`) and adds it.
    pub fn add_level(
        &mut self,
        levels: usize,
        thresholds: &[usize],
        rec: &Recognition,
    ) -> &LevelReport {
        let scores = Scores::of(rec, &self.evaluation);
        self.levels.push(LevelReport {
            levels,
            thresholds: thresholds.to_vec(),
            scores,
            recognize_seconds_by_lap: rec.lap_seconds.clone(),
        });
        self.levels.last().expect("just pushed")
    }

    /// Scores `rec` (an ICP baseline run) and sets it as the report's ICP result.
    pub fn set_icp(&mut self, rec: &Recognition) {
        self.icp = Some(IcpReport {
            scores: Scores::of(rec, &self.evaluation),
        });
    }

    /// The result of the configuration with `levels` levels.
    pub fn level(&self, levels: usize) -> Option<&LevelReport> {
        self.levels.iter().find(|l| l.levels == levels)
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
}

impl SweepReport {
    /// A sweep report of `results` (in grid order) with its PR curves.
    pub fn new(
        scenario: &str,
        seed: u64,
        laps: usize,
        evaluation: EvaluationSpec,
        results: Vec<SweepResult>,
    ) -> Self {
        let curves = super::sweep::pr_curves(&results);
        SweepReport {
            scenario: scenario.to_string(),
            seed,
            laps,
            evaluation,
            results,
            curves,
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

    pub(crate) fn sample(scenario: &str, p: [f64; 3], r: [f64; 3]) -> Report {
        let mut rep = Report::new(scenario, 7, 40, EvaluationSpec::default());
        let th = [vec![6], vec![6, 9], vec![6, 9, 12]];
        for l in 0..3 {
            rep.levels.push(LevelReport {
                levels: l + 1,
                thresholds: th[l].clone(),
                scores: Scores {
                    precision: p[l],
                    recall: r[l],
                    pairs: 100 * (l + 1),
                    revisits: 5000,
                    recognize_seconds_per_lap: 0.5 * (l + 1) as f64,
                    ..Scores::default()
                },
                recognize_seconds_by_lap: Vec::new(),
            });
        }
        rep.icp = Some(IcpReport {
            scores: Scores {
                precision: 0.05,
                recall: 0.04,
                revisits: 4900,
                recognize_seconds_per_lap: 9.0,
                ..Scores::default()
            },
        });
        rep.simulate_seconds_per_lap = 0.25;
        rep.finish();
        rep
    }
}
