//! Figures over seeds: per level configuration (and ICP) and metric, the mean, the 10th
//! percentile, the worst value and the seed that gave it.
//!
//! "Worst" and "percentile" count from the bad end: the lowest precision or recall, the highest
//! seconds per lap. Quantiles use the nearest-rank method (the value of the seed at rank
//! ⌈q·n⌉ from the worst, at least 1), so every figure is one seed's result and reproducible
//! with `--seed`. A seed whose recognizer made no pair has no precision ("no matches"): it is
//! left out of the precision figures and listed in `no_match_seeds`; its recall (0) counts.

use crate::eval::scores::{Report, Scores, SubjectKind};
use crate::place::Direction;
use serde::{Deserialize, Serialize};

/// The quantile the `p10` figures use.
pub const P10: f64 = 0.1;

/// A metric reported over seeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    Precision,
    Recall,
    VisitRecall,
    PairRecall,
    SecondsPerLap,
}

impl Metric {
    /// Every metric, in report order.
    pub const ALL: [Metric; 5] = [
        Metric::Precision,
        Metric::Recall,
        Metric::VisitRecall,
        Metric::PairRecall,
        Metric::SecondsPerLap,
    ];

    /// The name in test case names and tables: `precision`, `recall`, `visit_recall`,
    /// `pair_recall`, `seconds_per_lap`.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Precision => "precision",
            Metric::Recall => "recall",
            Metric::VisitRecall => "visit_recall",
            Metric::PairRecall => "pair_recall",
            Metric::SecondsPerLap => "seconds_per_lap",
        }
    }

    /// Whether a larger value is better (all but time).
    pub fn higher_is_better(self) -> bool {
        self != Metric::SecondsPerLap
    }

    /// The metric in `s`; `None` for precision when nothing was matched.
    pub fn of(self, s: &Scores) -> Option<f64> {
        match self {
            Metric::Precision if s.no_pairs => None,
            Metric::Precision => Some(s.precision),
            Metric::Recall => Some(s.recall),
            Metric::VisitRecall => Some(s.visit_recall),
            Metric::PairRecall => Some(s.pair_recall),
            Metric::SecondsPerLap => Some(s.recognize_seconds_per_lap),
        }
    }
}

/// One metric over the seeds that have a value for it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    pub mean: f64,
    /// The 10th percentile from the bad end (nearest rank).
    pub p10: f64,
    pub worst: f64,
    pub worst_seed: u64,
    /// Seeds with a value.
    pub seeds: usize,
}

/// The seed and value at quantile `q` from the bad end (nearest rank; `q = 0` is the worst).
/// Ties go to the smaller seed, so the answer does not depend on the input order.
pub fn quantile(samples: &[(u64, f64)], q: f64, higher_is_better: bool) -> Option<(u64, f64)> {
    let mut sorted = samples.to_vec();
    sorted.sort_by(|a, b| {
        let by_value = if higher_is_better {
            a.1.total_cmp(&b.1)
        } else {
            b.1.total_cmp(&a.1)
        };
        by_value.then(a.0.cmp(&b.0))
    });
    let rank = ((q * sorted.len() as f64).ceil() as usize).max(1);
    sorted.get(rank - 1).copied()
}

impl Spread {
    /// The spread of `samples` (seed, value); `None` when there are none.
    pub fn of(samples: &[(u64, f64)], higher_is_better: bool) -> Option<Self> {
        let (worst_seed, worst) = quantile(samples, 0.0, higher_is_better)?;
        let (_, p10) = quantile(samples, P10, higher_is_better)?;
        let mean = samples.iter().map(|s| s.1).sum::<f64>() / samples.len() as f64;
        Some(Spread {
            mean,
            p10,
            worst,
            worst_seed,
            seeds: samples.len(),
        })
    }
}

/// One recognizer configuration over seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfigSpread {
    /// The subject's name (`words-3`, `icp`).
    pub subject: String,
    pub kind: SubjectKind,
    /// Level count (words subjects only).
    pub levels: Option<usize>,
    pub thresholds: Vec<usize>,
    /// `None` when no seed matched anything.
    pub precision: Option<Spread>,
    pub recall: Option<Spread>,
    pub visit_recall: Option<Spread>,
    #[serde(default)]
    pub pair_recall: Option<Spread>,
    pub seconds_per_lap: Option<Spread>,
    /// Seeds at which the recognizer made no pair at all.
    pub no_match_seeds: Vec<u64>,
}

impl ConfigSpread {
    /// The spread of `metric`, if any seed has a value.
    pub fn get(&self, metric: Metric) -> Option<&Spread> {
        match metric {
            Metric::Precision => self.precision.as_ref(),
            Metric::Recall => self.recall.as_ref(),
            Metric::VisitRecall => self.visit_recall.as_ref(),
            Metric::PairRecall => self.pair_recall.as_ref(),
            Metric::SecondsPerLap => self.seconds_per_lap.as_ref(),
        }
    }
}

/// The scores of subject `subject` (`words-3`, `icp`) in `report`.
pub fn scores_of<'a>(report: &'a Report, subject: &str) -> Option<&'a Scores> {
    report.subject(subject).map(|s| &s.scores)
}

/// (seed, value) of `metric` for `subject` in every report that has one.
pub fn samples(reports: &[Report], subject: &str, metric: Metric) -> Vec<(u64, f64)> {
    samples_of(reports, subject, None, metric)
}

/// [`samples`] of one direction's figures alone (`Scores::of_direction`), or with `None` of
/// both directions' (the top-level figures).
pub fn samples_of(
    reports: &[Report],
    subject: &str,
    direction: Option<Direction>,
    metric: Metric,
) -> Vec<(u64, f64)> {
    let value = |s: &Scores| match direction {
        None => metric.of(s),
        Some(d) => metric.of(&s.of_direction(d)),
    };
    reports
        .iter()
        .filter_map(|r| Some((r.seed, value(scores_of(r, subject)?)?)))
        .collect()
}

/// Per subject found in any of `reports` (words subjects by levels, then the others in the
/// order first seen), the spread of every metric over the reports (one per seed).
pub fn summarize(reports: &[Report]) -> Vec<ConfigSpread> {
    let mut subjects: Vec<(String, SubjectKind, Option<usize>, Vec<usize>)> = Vec::new();
    for r in reports {
        for s in &r.subjects {
            if !subjects.iter().any(|x| x.0 == s.name) {
                subjects.push((s.name.clone(), s.kind, s.levels, s.thresholds.clone()));
            }
        }
    }
    subjects.sort_by_key(|s| (s.1 != SubjectKind::Words, s.2.unwrap_or(0)));
    subjects
        .into_iter()
        .map(|(subject, kind, levels, thresholds)| {
            let spread =
                |m: Metric| Spread::of(&samples(reports, &subject, m), m.higher_is_better());
            let no_match_seeds = reports
                .iter()
                .filter(|r| scores_of(r, &subject).is_some_and(|s| s.no_pairs))
                .map(|r| r.seed)
                .collect();
            let (precision, recall) = (spread(Metric::Precision), spread(Metric::Recall));
            let visit_recall = spread(Metric::VisitRecall);
            let pair_recall = spread(Metric::PairRecall);
            let seconds_per_lap = spread(Metric::SecondsPerLap);
            ConfigSpread {
                subject,
                kind,
                levels,
                thresholds,
                precision,
                recall,
                visit_recall,
                pair_recall,
                seconds_per_lap,
                no_match_seeds,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;

    #[test]
    fn worst_and_p10_count_from_the_bad_end_and_name_their_seed() {
        let samples: Vec<(u64, f64)> = (1..=20).map(|s| (s, s as f64 / 20.0)).collect();
        let s = Spread::of(&samples, true).unwrap();
        assert_eq!((s.worst_seed, s.worst), (1, 0.05));
        assert_eq!(s.p10, 0.1, "nearest rank 2 of 20");
        assert!((s.mean - 0.525).abs() < 1e-12);
        let t = Spread::of(&samples, false).unwrap();
        assert_eq!((t.worst_seed, t.worst, t.p10), (20, 1.0, 0.95));
        assert_eq!(quantile(&[(4, 0.5), (2, 0.5)], 0.0, true), Some((2, 0.5)));
        assert_eq!(Spread::of(&[], true), None);
    }

    #[test]
    fn a_seed_without_pairs_has_no_precision_but_counts_for_recall() {
        let mut a = sample("B", [0.9; 3], [0.5; 3]);
        let mut b = sample("B", [0.8; 3], [0.4; 3]);
        b.seed = 8;
        b.subjects[2].scores.no_pairs = true;
        b.subjects[2].scores.precision = 0.0;
        b.subjects[2].scores.recall = 0.0;
        a.subjects.retain(|s| s.kind != SubjectKind::Icp);
        b.subjects.retain(|s| s.kind != SubjectKind::Icp);
        let sum = summarize(&[a, b]);
        let l3 = sum.iter().find(|c| c.subject == "words-3").unwrap();
        assert_eq!(l3.no_match_seeds, vec![8]);
        assert_eq!(l3.get(Metric::Precision).unwrap().seeds, 1);
        assert_eq!(l3.get(Metric::Recall).unwrap().worst_seed, 8);
        assert_eq!(sum.len(), 3, "no ICP row without ICP results");
    }
}
