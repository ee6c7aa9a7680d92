//! The `[evaluation]` and `[expect]` blocks of a scenario file: how matches are scored, and the
//! CI gate a scenario must pass.

use serde::{Deserialize, Serialize};

/// How matches are scored against ground truth (DESIGN.md §6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EvaluationSpec {
    /// A pair is correct when its two true positions are within this distance, metres. Default 1.0.
    pub tp_radius_m: f64,
    /// Observations closer than this in odometric travel are never a revisit, metres. Default 20.
    pub min_gap_m: f64,
    /// A revisit must face the same way within this angle, degrees. Default 45.
    pub heading_tolerance_deg: f64,
    /// Extra radii at which precision and recall are also reported, metres. Default [0.5, 2, 3].
    pub sensitivity_radii_m: Vec<f64>,
}

impl Default for EvaluationSpec {
    fn default() -> Self {
        EvaluationSpec {
            tp_radius_m: 1.0,
            min_gap_m: 20.0,
            heading_tolerance_deg: 45.0,
            sensitivity_radii_m: vec![0.5, 2.0, 3.0],
        }
    }
}

/// The CI gate: `[[expect.levels]]` entries and an optional `[expect.icp]`, checked over the
/// seeds run: each bound applies to the worst seed, or with `quantile = q` to the q-quantile
/// (nearest rank, counted from the worst seed; `quantile = 0.1` lets the worst tenth miss).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExpectSpec {
    pub levels: Vec<LevelExpectation>,
    pub icp: Option<Expectation>,
    /// Bounds apply to this quantile of the seeds instead of the worst seed, in [0, 1).
    /// Default: none (the worst seed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantile: Option<f64>,
}

impl ExpectSpec {
    /// Whether the block sets no bound at all.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty() && self.icp.is_none()
    }
}

/// What one level configuration must achieve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelExpectation {
    /// Level configuration: 1, 2 or 3 levels of words.
    pub levels: usize,
    /// Minimum pair precision in [0, 1].
    #[serde(default)]
    pub min_precision: Option<f64>,
    /// Minimum same-direction recall in [0, 1].
    #[serde(default)]
    pub min_recall: Option<f64>,
    /// Maximum recognition time per lap, seconds.
    #[serde(default)]
    pub max_seconds_per_lap: Option<f64>,
}

impl LevelExpectation {
    /// The thresholds alone.
    pub fn expectation(&self) -> Expectation {
        Expectation {
            min_precision: self.min_precision,
            min_recall: self.min_recall,
            max_seconds_per_lap: self.max_seconds_per_lap,
        }
    }
}

/// Minimum precision and recall, and optionally a time budget.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Expectation {
    /// Minimum pair precision in [0, 1].
    pub min_precision: Option<f64>,
    /// Minimum same-direction recall in [0, 1].
    pub min_recall: Option<f64>,
    /// Maximum recognition time per lap, seconds.
    pub max_seconds_per_lap: Option<f64>,
}
