//! The CI gate: a report against a scenario's `[expect]` block.
//!
//! Every bound of an expectation is checked on its own and gives one [`Outcome`] (one JUnit
//! testcase): `min_precision`, `min_recall`, `min_visit_recall`, `min_pair_recall` and
//! `max_seconds_per_lap` of each `[[expect.levels]]`
//! entry and of `[expect.icp]`. A bound on a configuration the report does not hold fails
//! ("not in the report"). Exit decision ([`gate_exit_code`], the one rule the CLI uses): 2 when a
//! scenario could not be run (an error), else 1 when any outcome missed, else 0.

use crate::eval::scores::{Report, Scores};
use crate::spec::evaluation::{ExpectSpec, Expectation};
use serde::{Deserialize, Serialize};

/// Which bound of an expectation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bound {
    MinPrecision,
    MinRecall,
    MinVisitRecall,
    MinPairRecall,
    MaxSecondsPerLap,
}

/// The result of checking one bound.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    pub scenario: String,
    /// "levels=3" or "icp".
    pub subject: String,
    pub bound: Bound,
    /// The bound from the scenario file.
    pub limit: f64,
    /// What the report holds; `None` when the configuration is not in the report.
    pub actual: Option<f64>,
    pub passed: bool,
}

impl Outcome {
    /// The testcase name: `levels=3 precision >= 0.90`.
    pub fn name(&self) -> String {
        let (what, op) = self.what_op();
        format!(
            "{} {what} {op} {}",
            self.subject,
            fmt_limit(self.bound, self.limit)
        )
    }

    fn what_op(&self) -> (&'static str, &'static str) {
        match self.bound {
            Bound::MinPrecision => ("precision", ">="),
            Bound::MinRecall => ("recall", ">="),
            Bound::MinVisitRecall => ("visit recall", ">="),
            Bound::MinPairRecall => ("pair recall", ">="),
            Bound::MaxSecondsPerLap => ("s/lap", "<="),
        }
    }

    /// The line printed for people: `PASS B levels=3 precision 0.93 >= 0.90`.
    pub fn line(&self) -> String {
        let status = if self.passed { "PASS" } else { "FAIL" };
        let (what, op) = self.what_op();
        let limit = fmt_limit(self.bound, self.limit);
        match self.actual {
            Some(a) => {
                let op = if self.passed { op } else { negate(op) };
                format!(
                    "{status} {} {} {what} {} {op} {limit}",
                    self.scenario,
                    self.subject,
                    fmt_limit(self.bound, a)
                )
            }
            None => format!(
                "{status} {} {} {what} {op} {limit}: not in the report",
                self.scenario, self.subject
            ),
        }
    }
}

fn negate(op: &str) -> &'static str {
    if op == ">=" { "<" } else { ">" }
}

fn fmt_limit(bound: Bound, v: f64) -> String {
    match bound {
        Bound::MaxSecondsPerLap => format!("{v:.2}s"),
        _ => format!("{v:.3}"),
    }
}

/// Checks `report` against `expect`: one outcome per bound, in file order (levels entries,
/// then ICP; precision, recall, time within each).
pub fn check(report: &Report, expect: &ExpectSpec) -> Vec<Outcome> {
    let mut out = Vec::new();
    for e in &expect.levels {
        let scores = report.level(e.levels).map(|l| &l.scores);
        push_bounds(
            &mut out,
            &report.scenario,
            &format!("levels={}", e.levels),
            &e.expectation(),
            scores,
        );
    }
    if let Some(e) = &expect.icp {
        let scores = report.icp.as_ref().map(|i| &i.scores);
        push_bounds(&mut out, &report.scenario, "icp", e, scores);
    }
    out
}

fn push_bounds(
    out: &mut Vec<Outcome>,
    scenario: &str,
    subject: &str,
    e: &Expectation,
    scores: Option<&Scores>,
) {
    let bounds = [
        (Bound::MinPrecision, e.min_precision),
        (Bound::MinRecall, e.min_recall),
        (Bound::MinVisitRecall, e.min_visit_recall),
        (Bound::MinPairRecall, e.min_pair_recall),
        (Bound::MaxSecondsPerLap, e.max_seconds_per_lap),
    ];
    for (bound, limit) in bounds {
        let Some(limit) = limit else { continue };
        let actual = scores.map(|s| match bound {
            Bound::MinPrecision => s.precision,
            Bound::MinRecall => s.recall,
            Bound::MinVisitRecall => s.visit_recall,
            Bound::MinPairRecall => s.pair_recall,
            Bound::MaxSecondsPerLap => s.recognize_seconds_per_lap,
        });
        let passed = match (bound, actual) {
            (_, None) => false,
            (Bound::MaxSecondsPerLap, Some(a)) => a <= limit,
            (_, Some(a)) => a >= limit,
        };
        out.push(Outcome {
            scenario: scenario.to_string(),
            subject: subject.to_string(),
            bound,
            limit,
            actual,
            passed,
        });
    }
}

/// 0 when every outcome passed, 1 when any missed.
pub fn exit_code(outcomes: &[Outcome]) -> i32 {
    i32::from(gate_exit_code(0, outcomes))
}

/// The gate's exit code: 2 when `errors` scenarios could not be run, else 1 when any outcome
/// missed, else 0.
pub fn gate_exit_code<'a>(errors: usize, outcomes: impl IntoIterator<Item = &'a Outcome>) -> u8 {
    if errors > 0 {
        2
    } else if outcomes.into_iter().all(|o| o.passed) {
        0
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;
    use crate::spec::evaluation::LevelExpectation;

    fn expect(levels: usize, p: f64, r: f64, s: Option<f64>) -> LevelExpectation {
        LevelExpectation {
            levels,
            min_precision: Some(p),
            min_recall: Some(r),
            min_visit_recall: None,
            min_pair_recall: None,
            max_seconds_per_lap: s,
        }
    }

    #[test]
    fn all_pass_gives_zero() {
        let rep = sample("B", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let spec = ExpectSpec {
            levels: vec![expect(3, 0.9, 0.3, Some(2.0)), expect(1, 0.9, 0.1, None)],
            icp: None,
        };
        let o = check(&rep, &spec);
        assert_eq!(o.len(), 5);
        assert_eq!(exit_code(&o), 0);
        assert_eq!(o[0].line(), "PASS B levels=3 precision 0.900 >= 0.900");
        assert_eq!(o[2].line(), "PASS B levels=3 s/lap 1.50s <= 2.00s");
    }

    #[test]
    fn a_miss_gives_one_with_a_failing_line() {
        let rep = sample("C", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let spec = ExpectSpec {
            levels: vec![expect(2, 0.95, 0.2, None)],
            icp: Some(Expectation {
                min_precision: Some(0.01),
                ..Expectation::default()
            }),
        };
        let o = check(&rep, &spec);
        assert_eq!(exit_code(&o), 1);
        assert_eq!(o[0].line(), "FAIL C levels=2 precision 0.910 < 0.950");
        assert!(o[1].passed && o[2].passed);
        assert_eq!(o[2].subject, "icp");
    }

    #[test]
    fn missing_configuration_fails() {
        let mut rep = sample("A", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        rep.levels.truncate(1);
        rep.icp = None;
        let spec = ExpectSpec {
            levels: vec![expect(3, 0.5, 0.1, None)],
            icp: Some(Expectation {
                min_recall: Some(0.0),
                ..Expectation::default()
            }),
        };
        let o = check(&rep, &spec);
        assert!(o.iter().all(|o| !o.passed));
        assert!(
            o[0].line().ends_with("not in the report"),
            "{}",
            o[0].line()
        );
        assert_eq!(exit_code(&o), 1);
    }

    #[test]
    fn no_expectation_passes() {
        let rep = sample("A", [0.9; 3], [0.1; 3]);
        assert_eq!(exit_code(&check(&rep, &ExpectSpec::default())), 0);
        assert_eq!(gate_exit_code(1, &check(&rep, &ExpectSpec::default())), 2);
    }
}
