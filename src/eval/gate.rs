//! The CI gate: the reports of a scenario's seeds against its `[expect]` block.
//!
//! Every bound of an expectation is checked on its own and gives one [`Outcome`] (one JUnit
//! testcase): `min_precision`, `min_recall`, `min_visit_recall`, `min_pair_recall` and
//! `max_seconds_per_lap` of each `[[expect.subjects]]` entry, then the bounds of the entry's
//! `[expect.subjects.same]` and `[expect.subjects.opposite]` sub-tables, checked on that
//! direction's figures alone (`Scores::of_direction`); their outcomes name the subject and the
//! direction (`reverse/words-3/opposite/precision`, `FAIL reverse words-3 opposite precision …`).
//! A bound applies
//! to the worst seed, or with `quantile = q` to the q-quantile from the worst end
//! (`eval::distribution`). A bound on a subject no report holds fails ("not in the
//! report"), and so does a precision bound when no seed matched anything ("no matches"). Exit
//! decision ([`gate_exit_code`], the one rule the CLI uses): 2 when a scenario or seed could not
//! be run (an error), else 1 when any outcome missed, else 0.

use crate::eval::distribution::{self, Metric};
use crate::eval::scores::Report;
use crate::place::Direction;
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

impl Bound {
    /// The metric the bound is on.
    pub fn metric(self) -> Metric {
        match self {
            Bound::MinPrecision => Metric::Precision,
            Bound::MinRecall => Metric::Recall,
            Bound::MinVisitRecall => Metric::VisitRecall,
            Bound::MinPairRecall => Metric::PairRecall,
            Bound::MaxSecondsPerLap => Metric::SecondsPerLap,
        }
    }
}

/// Why a bound has no figure to check.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Missing {
    /// No report holds the subject.
    NotInReport,
    /// The subject is there but matched nothing (in the bound's direction) at any seed.
    NoMatches,
    /// No seed ran to the end; the first seed's error, first line.
    EverySeedFailed { error: String },
}

/// The result of checking one bound over the seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Outcome {
    /// Scenario label (its name; with its file when two scenarios share a name).
    pub scenario: String,
    /// The subject's name: `words-3`, `icp`.
    pub subject: String,
    /// The direction whose figures alone the bound is on; `None`: both directions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<Direction>,
    pub bound: Bound,
    /// The bound from the scenario file.
    pub limit: f64,
    /// The quantile the bound applies to; `None`: the worst seed.
    pub quantile: Option<f64>,
    /// The figure checked; `None` when there is none (see `missing`).
    pub actual: Option<f64>,
    /// The seed whose result `actual` is.
    pub seed: Option<u64>,
    /// Seeds with a value for the metric.
    pub seeds: usize,
    /// Seeds checked (those that matched nothing included).
    pub runs: usize,
    /// Why there is no figure.
    pub missing: Option<Missing>,
    pub passed: bool,
    /// Seconds the configuration spent recognizing, over all seeds.
    pub seconds: f64,
}

impl Outcome {
    /// The testcase name, the same whatever the bound: `B/words-3/precision`, or with a
    /// direction `reverse/words-3/opposite/precision`.
    pub fn name(&self) -> String {
        let subject = match self.direction {
            None => self.subject.clone(),
            Some(d) => format!("{}/{}", self.subject, d.name()),
        };
        format!("{}/{subject}/{}", self.scenario, self.bound.metric().name())
    }

    /// "worst" or "p10" (the statistic the bound applies to).
    pub fn statistic(&self) -> String {
        match self.quantile {
            None => "worst".into(),
            Some(q) => format!("p{}", fmt_quantile(q)),
        }
    }
}

/// 0.1 → "10", 0.25 → "25", 0.125 → "12.5".
fn fmt_quantile(q: f64) -> String {
    let pct = q * 100.0;
    if (pct - pct.round()).abs() < 1e-9 {
        format!("{}", pct.round() as i64)
    } else {
        format!("{pct}")
    }
}

/// Checks one report (one seed) against `expect`.
pub fn check(report: &Report, expect: &ExpectSpec) -> Vec<Outcome> {
    check_seeds(&report.scenario, std::slice::from_ref(report), expect)
}

/// Checks the reports of a scenario's seeds against `expect`: one outcome per bound, in file
/// order (subject entries, each followed by its same- and opposite-direction bounds;
/// precision, recall, time within each).
pub fn check_seeds(scenario: &str, reports: &[Report], expect: &ExpectSpec) -> Vec<Outcome> {
    let mut entries: Vec<(String, Option<Direction>, Expectation)> = Vec::new();
    for e in &expect.subjects {
        let subject = e.subject.clone();
        entries.push((subject.clone(), None, e.expectation()));
        for (d, de) in [
            (Direction::Same, &e.same),
            (Direction::Opposite, &e.opposite),
        ] {
            if let Some(de) = de {
                entries.push((subject.clone(), Some(d), de.expectation()));
            }
        }
    }
    let mut out = Vec::new();
    for (subject, direction, e) in entries {
        let bounds = [
            (Bound::MinPrecision, e.min_precision),
            (Bound::MinRecall, e.min_recall),
            (Bound::MinVisitRecall, e.min_visit_recall),
            (Bound::MinPairRecall, e.min_pair_recall),
            (Bound::MaxSecondsPerLap, e.max_seconds_per_lap),
        ];
        for (bound, limit) in bounds {
            let Some(limit) = limit else { continue };
            let target = Target {
                subject: &subject,
                direction,
            };
            out.push(check_bound(
                scenario,
                reports,
                target,
                bound,
                limit,
                expect.quantile,
            ));
        }
    }
    out
}

/// What a bound is on: a configuration, and optionally one direction's figures alone.
#[derive(Clone, Copy)]
struct Target<'a> {
    subject: &'a str,
    direction: Option<Direction>,
}

fn check_bound(
    scenario: &str,
    reports: &[Report],
    target: Target<'_>,
    bound: Bound,
    limit: f64,
    quantile: Option<f64>,
) -> Outcome {
    let Target { subject, direction } = target;
    let metric = bound.metric();
    let samples = distribution::samples_of(reports, subject, direction, metric);
    let at = distribution::quantile(&samples, quantile.unwrap_or(0.0), metric.higher_is_better());
    let present = reports
        .iter()
        .any(|r| distribution::scores_of(r, subject).is_some());
    let missing = match (at, present) {
        (Some(_), _) => None,
        (None, true) => Some(Missing::NoMatches),
        (None, false) => Some(Missing::NotInReport),
    };
    let passed = match at {
        None => false,
        Some((_, a)) if metric.higher_is_better() => a >= limit,
        Some((_, a)) => a <= limit,
    };
    Outcome {
        scenario: scenario.to_string(),
        subject: subject.to_string(),
        direction,
        bound,
        limit,
        quantile,
        actual: at.map(|a| a.1),
        seed: at.map(|a| a.0),
        seeds: samples.len(),
        runs: reports.len(),
        missing,
        passed,
        seconds: recognize_seconds(reports, subject),
    }
}

/// Seconds `subject` spent recognizing, over all `reports`.
fn recognize_seconds(reports: &[Report], subject: &str) -> f64 {
    reports
        .iter()
        .filter_map(|r| {
            distribution::scores_of(r, subject).map(|s| s.recognize_seconds_per_lap * r.laps as f64)
        })
        .sum()
}

/// Exit code: every expectation met.
pub const EXIT_PASS: u8 = 0;
/// Exit code: an expectation missed.
pub const EXIT_MISSED: u8 = 1;
/// Exit code: an error (bad input, a run that could not be carried out, an unwritable output).
pub const EXIT_ERROR: u8 = 2;

/// 0 when every outcome passed, 1 when any missed.
pub fn exit_code(outcomes: &[Outcome]) -> i32 {
    i32::from(gate_exit_code(0, outcomes))
}

/// The gate's exit code: 2 when `errors` scenarios could not be run, else 1 when any outcome
/// missed, else 0.
pub fn gate_exit_code<'a>(errors: usize, outcomes: impl IntoIterator<Item = &'a Outcome>) -> u8 {
    if errors > 0 {
        EXIT_ERROR
    } else if outcomes.into_iter().all(|o| o.passed) {
        EXIT_PASS
    } else {
        EXIT_MISSED
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;
    use crate::spec::evaluation::SubjectExpectation;

    fn expect(levels: usize, p: f64, r: f64, s: Option<f64>) -> SubjectExpectation {
        SubjectExpectation {
            subject: format!("words-{levels}"),
            min_precision: Some(p),
            min_recall: Some(r),
            min_visit_recall: None,
            min_pair_recall: None,
            max_seconds_per_lap: s,
            same: None,
            opposite: None,
        }
    }

    fn icp(min_precision: Option<f64>, min_recall: Option<f64>) -> SubjectExpectation {
        SubjectExpectation {
            subject: "icp".into(),
            min_precision,
            min_recall,
            min_visit_recall: None,
            min_pair_recall: None,
            max_seconds_per_lap: None,
            same: None,
            opposite: None,
        }
    }

    #[test]
    fn all_pass_gives_zero() {
        let rep = sample("B", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let spec = ExpectSpec {
            subjects: vec![expect(3, 0.9, 0.3, Some(2.0)), expect(1, 0.9, 0.1, None)],
            quantile: None,
            regression: None,
        };
        let o = check(&rep, &spec);
        assert_eq!(o.len(), 5);
        assert_eq!(exit_code(&o), 0);
        assert!(o[0].passed);
        assert_eq!((o[0].actual, o[0].seed, o[0].runs), (Some(0.9), Some(7), 1));
        assert_eq!(o[0].name(), "B/words-3/precision");
        assert_eq!(
            (o[2].bound, o[2].actual),
            (Bound::MaxSecondsPerLap, Some(1.5))
        );
    }

    #[test]
    fn a_miss_gives_one_with_a_failing_line() {
        let rep = sample("C", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let spec = ExpectSpec {
            subjects: vec![expect(2, 0.95, 0.2, None), icp(Some(0.01), None)],
            quantile: None,
            regression: None,
        };
        let o = check(&rep, &spec);
        assert_eq!(exit_code(&o), 1);
        assert!(!o[0].passed);
        assert_eq!(
            (o[0].subject.as_str(), o[0].actual),
            ("words-2", Some(0.91))
        );
        assert!(o[1].passed && o[2].passed);
        assert_eq!(o[2].subject, "icp");
    }

    #[test]
    fn missing_configuration_fails() {
        let mut rep = sample("A", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        rep.subjects.truncate(1);
        let spec = ExpectSpec {
            subjects: vec![expect(3, 0.5, 0.1, None), icp(None, Some(0.0))],
            quantile: None,
            regression: None,
        };
        let o = check(&rep, &spec);
        assert!(o.iter().all(|o| !o.passed));
        assert_eq!(o[0].missing, Some(Missing::NotInReport));
        assert_eq!(exit_code(&o), 1);
    }

    #[test]
    fn no_expectation_passes() {
        let rep = sample("A", [0.9; 3], [0.1; 3]);
        assert_eq!(exit_code(&check(&rep, &ExpectSpec::default())), 0);
        assert_eq!(gate_exit_code(1, &check(&rep, &ExpectSpec::default())), 2);
    }

    #[test]
    fn bounds_apply_to_the_worst_seed_or_to_the_quantile() {
        let reports: Vec<Report> = (1..=10)
            .map(|seed| {
                let mut r = sample("A", [0.9; 3], [0.5; 3]);
                r.seed = seed;
                r.subjects[2].scores.precision = if seed == 4 { 0.6 } else { 0.9 };
                r
            })
            .collect();
        let mut spec = ExpectSpec {
            subjects: vec![expect(3, 0.8, 0.0, None)],
            quantile: None,
            regression: None,
        };
        let worst = check_seeds("A", &reports, &spec);
        assert!(!worst[0].passed);
        assert_eq!((worst[0].seed, worst[0].seeds), (Some(4), 10));
        spec.quantile = Some(0.2);
        let p20 = check_seeds("A", &reports, &spec);
        assert!(p20[0].passed, "{:?}", p20[0]);
        assert_eq!(
            (p20[0].statistic().as_str(), p20[0].actual),
            ("p20", Some(0.9))
        );
    }

    #[test]
    fn no_matches_at_any_seed_fails_a_precision_bound_by_name() {
        let mut rep = sample("A", [0.9; 3], [0.0; 3]);
        rep.subjects[0].scores.no_pairs = true;
        let spec = ExpectSpec {
            subjects: vec![expect(1, 0.5, 0.0, None)],
            quantile: None,
            regression: None,
        };
        let o = check(&rep, &spec);
        assert!(!o[0].passed);
        assert_eq!(o[0].missing, Some(Missing::NoMatches));
        assert!(o[1].passed, "recall 0 >= 0");
    }

    /// Three seeds whose words-3 directions are set: same precision 0.95; opposite precision
    /// 0.99 (0.8 at seed 2), recall 0.3.
    fn reports_with_directions() -> Vec<Report> {
        (1..=3)
            .map(|seed| {
                let mut r = sample("R", [0.9; 3], [0.5; 3]);
                r.seed = seed;
                let d = &mut r.subjects[2].scores.directions;
                (d.same.precision, d.same.pairs) = (0.95, 50);
                (d.opposite.precision, d.opposite.pairs) = (0.99, 40);
                d.opposite.recall = 0.3;
                if seed == 2 {
                    d.opposite.precision = 0.8;
                }
                r
            })
            .collect()
    }

    /// words-3 with precision >= 0.9 for `same`, and precision >= 0.9, recall >= 0.2 for
    /// `opposite`.
    fn direction_spec() -> ExpectSpec {
        use crate::spec::evaluation::DirectionExpectation;
        let mut entry = expect(3, 0.5, 0.0, None);
        let p = DirectionExpectation {
            min_precision: Some(0.9),
            ..DirectionExpectation::default()
        };
        entry.same = Some(p.clone());
        entry.opposite = Some(DirectionExpectation {
            min_recall: Some(0.2),
            ..p
        });
        ExpectSpec {
            subjects: vec![entry],
            quantile: None,
            regression: None,
        }
    }

    /// Bounds in `[expect.subjects.same]` / `[expect.subjects.opposite]` apply to that direction's
    /// figures alone and their outcomes name the direction.
    #[test]
    fn direction_bounds_check_one_direction_and_name_it() {
        let o = check_seeds("R", &reports_with_directions(), &direction_spec());
        assert_eq!(o.len(), 5, "{o:?}");
        assert!(o[0].passed && o[1].passed && o[2].passed && o[4].passed);
        assert_eq!(o[2].name(), "R/words-3/same/precision");
        assert_eq!(o[3].direction, Some(Direction::Opposite));
        assert!(!o[3].passed);
        assert_eq!((o[3].actual, o[3].seed, o[3].runs), (Some(0.8), Some(2), 3));
        assert_eq!(o[3].name(), "R/words-3/opposite/precision");
        assert_eq!(exit_code(&o), 1);
    }

    #[test]
    fn a_direction_without_matches_fails_its_precision_bound_by_name() {
        let mut reports = reports_with_directions();
        for r in &mut reports {
            r.subjects[2].scores.directions.opposite.no_pairs = true;
        }
        let o = check_seeds("R", &reports, &direction_spec());
        assert!(!o[3].passed);
        assert_eq!(o[3].missing, Some(Missing::NoMatches));
        assert_eq!(o[3].direction, Some(Direction::Opposite));
        assert!(o[2].passed, "the same direction is untouched");
    }
}
