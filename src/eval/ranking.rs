//! The metrics of the place-recognition field over a recognizer's match score: the
//! precision–recall curve as the score threshold falls, maximum F1, recall at 100 % and at 99 %
//! precision, average precision, and the query rate (docs/design.md, Evaluation; README, "The
//! report").
//!
//! The field scores **per query observation** (each observation is a query against everything
//! before it), not per pair:
//!
//! - **The query's answer.** Every observation that is the newer side of at least one pair is a
//!   *retrieving query*; its answer is its pair of highest score ([`crate::place::Match::score`];
//!   a match's score is each of its pairs'). Pairs whose observations have no truth are left
//!   out, as the pair figures leave them out.
//! - **Right answer.** The answer is right when its pair is a true revisit by the ground-truth
//!   rule of the figures: the two true positions within `tp_radius_m`, the true headings as the
//!   match's direction claims (within `heading_tolerance_deg`, or 180° ± it for `opposite`),
//!   and the past observation at least `min_gap_m` of true travel before the query. When a
//!   right and a wrong pair share the highest score, the answer counts as wrong: the recognizer
//!   did not tell them apart.
//! - **Positives.** The queries that have a revisit (an earlier observation passing the same
//!   rule): the denominator of the pair figures' recall. A right answer is always a positive's.
//! - **At threshold t**, the queries whose answer scores ≥ t are retrieved: precision = right
//!   answers ÷ retrieved, recall = right answers ÷ positives. The curve has a point at each
//!   distinct answer score, highest first; its last point (every answer retrieved) is the
//!   operating point the recognizer reports without a threshold.
//! - **Average precision** is scikit-learn's step-wise sum (`average_precision_score`):
//!   Σₙ (Rₙ − Rₙ₋₁)·Pₙ over the curve's points, R₀ = 0. Positives that no answer is right for
//!   never enter the curve, so AP is at most the last recall.
//! - **Recall at 100 % (99 %) precision**: the highest recall of a point whose precision is 1
//!   (at least 0.99); 0 when no point has it. **Max F1**: the highest F1 of a point, with the
//!   threshold of the first point (highest threshold) that has it.
//! - **Query rate**: observations the recognizer made ÷ its CPU seconds (the wall clock's for
//!   a recognizer in another process): how many queries per second of CPU it answers.
//!
//! [`Ranking`] collects the answers as matches arrive (one score and one flag per
//! observation); [`curve`] computes the figures from answers and positives.

use super::GroundTruth;
use super::metrics::Scorer;
use super::pair_recall::Facing;
use crate::place::{Match, Observation};
use crate::spec::evaluation::EvaluationSpec;
use serde::{Deserialize, Serialize};

/// The most points a report's curve keeps (the figures are computed on the whole curve).
pub const MAX_CURVE_POINTS: usize = 100;

/// The answer of each query observation so far (see the module doc).
#[derive(Clone, Debug, Default)]
pub struct Ranking {
    /// Per observation position: the highest score of a pair it is the query of (`NaN`: none).
    best: Vec<f64>,
    /// Per observation position: whether every pair at that highest score is right.
    right: Vec<bool>,
}

impl Ranking {
    /// Counts the pairs of `m` (its observations joined in `scorer`) with `spec`'s rule.
    pub fn add(&mut self, m: &Match, scorer: &Scorer, spec: &EvaluationSpec) {
        let (r2, tol) = (spec.tp_radius_m.powi(2), scorer.heading_tol_rad());
        let facing = Facing::of(m.direction);
        for (query, past) in m.pairs() {
            let Some((qi, _, q, p)) = scorer.resolve(query, past) else {
                continue;
            };
            let right =
                q.agrees_with(&p, r2, facing, tol) && q.travel_m - p.travel_m >= spec.min_gap_m;
            self.answer(qi, m.score, right);
        }
    }

    /// Records a pair of query position `qi` with `score`, right or not.
    pub fn answer(&mut self, qi: usize, score: f64, right: bool) {
        if self.best.len() <= qi {
            self.best.resize(qi + 1, f64::NAN);
            self.right.resize(qi + 1, false);
        }
        let best = self.best[qi];
        if best.is_nan() || score > best {
            (self.best[qi], self.right[qi]) = (score, right);
        } else if score == best {
            self.right[qi] &= right;
        }
    }

    /// The figures, with `positives` queries that have a revisit, `observations` made in
    /// `cpu_s` seconds, and the ground-truth rule of `spec`.
    pub fn scores(
        &self,
        positives: usize,
        observations: usize,
        cpu_s: f64,
        spec: &EvaluationSpec,
    ) -> RankingScores {
        let answers: Vec<(f64, bool)> = self
            .best
            .iter()
            .zip(&self.right)
            .filter(|(s, _)| !s.is_nan())
            .map(|(&s, &r)| (s, r))
            .collect();
        let mut scores = curve(&answers, positives);
        scores.queries_per_cpu_second = rate(observations, cpu_s);
        scores.rule = TruthRule::of(spec);
        scores
    }
}

/// The figures of `rec` (its ranking as scored while it was recognized, or of its matches now),
/// with `positives` queries that have a revisit (the evaluation's `revisits`).
pub fn of_recognition(
    rec: &super::Recognition,
    positives: usize,
    spec: &EvaluationSpec,
) -> RankingScores {
    if let Some((ranking, observations)) = &rec.ranking {
        return ranking.scores(positives, *observations, rec.seconds, spec);
    }
    let untimed = of_matches(&rec.observations, &rec.truth, spec, &rec.matches, positives);
    RankingScores {
        queries_per_cpu_second: rate(rec.observations.len(), rec.seconds),
        ..untimed
    }
}

/// The figures of `matches` over `observations` (joined with `truth`), with `positives`
/// queries that have a revisit; untimed (query rate 0).
pub fn of_matches(
    observations: &[Observation],
    truth: &GroundTruth,
    spec: &EvaluationSpec,
    matches: &[Match],
    positives: usize,
) -> RankingScores {
    let scorer = Scorer::new(observations, truth, spec);
    let mut ranking = Ranking::default();
    for m in matches {
        ranking.add(m, &scorer, spec);
    }
    ranking.scores(positives, observations.len(), 0.0, spec)
}

/// A subject's name and its figures over the match score (`sweep`'s score curves).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SubjectRanking {
    pub name: String,
    pub ranking: RankingScores,
}

/// `n` per `seconds`, 0 when untimed.
fn rate(n: usize, seconds: f64) -> f64 {
    if seconds > 0.0 {
        n as f64 / seconds
    } else {
        0.0
    }
}

/// The ground-truth rule a figure was counted with, written beside it.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct TruthRule {
    pub tp_radius_m: f64,
    pub min_gap_m: f64,
    pub heading_tolerance_deg: f64,
}

impl TruthRule {
    /// The rule of `spec`.
    pub fn of(spec: &EvaluationSpec) -> Self {
        TruthRule {
            tp_radius_m: spec.tp_radius_m,
            min_gap_m: spec.min_gap_m,
            heading_tolerance_deg: spec.heading_tolerance_deg,
        }
    }
}

/// One point of the score curve: the queries whose answer scores at least `threshold`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ScorePoint {
    pub threshold: f64,
    pub precision: f64,
    pub recall: f64,
}

/// The field's figures over a subject's match score (see the module doc).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RankingScores {
    /// The ground-truth rule the figures were counted with.
    pub rule: TruthRule,
    /// Queries with a revisit: recall's denominator.
    pub positives: usize,
    /// Queries that are the newer side of a pair (those with an answer).
    pub retrieving: usize,
    /// Of them, those whose answer is right.
    pub right: usize,
    /// Scikit-learn's step-wise average precision, Σ (Rₙ − Rₙ₋₁)·Pₙ.
    pub average_precision: f64,
    pub max_f1: f64,
    /// The score threshold of `max_f1` (`null` without answers).
    pub max_f1_threshold: Option<f64>,
    pub recall_at_100_precision: f64,
    pub recall_at_99_precision: f64,
    /// Observations made per CPU second of the recognizer.
    pub queries_per_cpu_second: f64,
    /// The curve, highest threshold first: at most [`MAX_CURVE_POINTS`], the first and the
    /// last included.
    pub curve: Vec<ScorePoint>,
}

/// The figures of `answers` (per retrieving query: its answer's score and whether it is right)
/// with `positives` queries that have a revisit. Ties in score across queries are one threshold.
pub fn curve(answers: &[(f64, bool)], positives: usize) -> RankingScores {
    let mut sorted = answers.to_vec();
    sorted.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut full: Vec<ScorePoint> = Vec::new();
    let (mut retrieved, mut right) = (0usize, 0usize);
    let mut i = 0;
    while i < sorted.len() {
        let t = sorted[i].0;
        while i < sorted.len() && sorted[i].0 == t {
            retrieved += 1;
            right += usize::from(sorted[i].1);
            i += 1;
        }
        full.push(ScorePoint {
            threshold: t,
            precision: right as f64 / retrieved as f64,
            recall: super::metrics::ratio(right, positives),
        });
    }
    let mut s = RankingScores {
        positives,
        retrieving: sorted.len(),
        right,
        ..RankingScores::default()
    };
    let mut last_recall = 0.0;
    for p in &full {
        s.average_precision += (p.recall - last_recall) * p.precision;
        last_recall = p.recall;
        let f1 = super::metrics::f1(p.precision, p.recall);
        if s.max_f1_threshold.is_none() || f1 > s.max_f1 {
            (s.max_f1, s.max_f1_threshold) = (f1, Some(p.threshold));
        }
        if p.precision >= 1.0 {
            s.recall_at_100_precision = s.recall_at_100_precision.max(p.recall);
        }
        if p.precision >= 0.99 {
            s.recall_at_99_precision = s.recall_at_99_precision.max(p.recall);
        }
    }
    s.curve = thin(full);
    s
}

/// At most [`MAX_CURVE_POINTS`] of `points`, evenly spaced in order, the first and last kept.
fn thin(points: Vec<ScorePoint>) -> Vec<ScorePoint> {
    let n = points.len();
    if n <= MAX_CURVE_POINTS {
        return points;
    }
    let last = (MAX_CURVE_POINTS - 1) as f64;
    let keep: Vec<usize> = (0..MAX_CURVE_POINTS)
        .map(|k| (k as f64 * (n - 1) as f64 / last).round() as usize)
        .collect();
    points
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep.binary_search(i).is_ok())
        .map(|(_, p)| p)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    /// Every right answer above every wrong one: precision 1 until the right ones run out.
    #[test]
    fn a_perfect_ranking_reaches_its_recall_at_full_precision() {
        // 3 right answers (scores 9, 8, 7), 2 wrong (2, 1); 4 positives.
        let a = [
            (9.0, true),
            (2.0, false),
            (8.0, true),
            (1.0, false),
            (7.0, true),
        ];
        let s = curve(&a, 4);
        assert_eq!((s.retrieving, s.right, s.positives), (5, 3, 4));
        assert!(close(s.recall_at_100_precision, 0.75));
        assert!(close(s.recall_at_99_precision, 0.75));
        // Σ (ΔR)·P = 0.25·1 + 0.25·1 + 0.25·1.
        assert!(close(s.average_precision, 0.75));
        // F1 at t = 7: P 1, R 0.75 → 6/7.
        assert!(close(s.max_f1, 6.0 / 7.0));
        assert_eq!(s.max_f1_threshold, Some(7.0));
        assert_eq!(s.curve.len(), 5);
        assert_eq!(s.curve[0].threshold, 9.0);
        let last = s.curve.last().unwrap();
        assert!(close(last.precision, 0.6) && close(last.recall, 0.75));
    }

    /// Every wrong answer above every right one: no point is precise.
    #[test]
    fn a_reversed_ranking_has_no_recall_at_high_precision() {
        let a = [(1.0, true), (2.0, true), (3.0, false), (4.0, false)];
        let s = curve(&a, 2);
        assert_eq!(s.recall_at_100_precision, 0.0);
        assert_eq!(s.recall_at_99_precision, 0.0);
        // Points: t 4 (P 0, R 0), t 3 (0, 0), t 2 (1/3, 1/2), t 1 (1/2, 1).
        assert!(close(s.average_precision, 0.5 / 3.0 + 0.5 * 0.5));
        assert!(close(s.max_f1, 2.0 / 3.0));
        assert_eq!(s.max_f1_threshold, Some(1.0));
    }

    /// Answers of one score are one threshold: a tie of a right and a wrong answer never shows
    /// the right one alone.
    #[test]
    fn ties_across_queries_are_one_threshold() {
        let a = [(5.0, true), (5.0, false), (3.0, true)];
        let s = curve(&a, 2);
        assert_eq!(s.curve.len(), 2);
        assert!(close(s.curve[0].precision, 0.5) && close(s.curve[0].recall, 0.5));
        assert_eq!(s.recall_at_100_precision, 0.0);
        assert!(close(s.average_precision, 0.5 * 0.5 + 0.5 * (2.0 / 3.0)));
    }

    /// A query's answer is its highest-scoring pair; a wrong pair at the same score makes it
    /// wrong, a wrong pair below does not.
    #[test]
    fn a_query_answers_with_its_best_pair_and_ties_count_wrong() {
        let mut r = Ranking::default();
        r.answer(0, 3.0, false);
        r.answer(0, 5.0, true); // query 0: best 5, right
        r.answer(1, 4.0, true);
        r.answer(1, 4.0, false); // query 1: best 4, tie with a wrong pair
        r.answer(3, 2.0, true);
        let spec = EvaluationSpec::default();
        let s = r.scores(3, 10, 2.0, &spec);
        assert_eq!((s.retrieving, s.right), (3, 2));
        assert!(close(s.queries_per_cpu_second, 5.0));
        assert_eq!(s.rule.tp_radius_m, spec.tp_radius_m);
        let thresholds: Vec<f64> = s.curve.iter().map(|p| p.threshold).collect();
        assert_eq!(thresholds, [5.0, 4.0, 2.0]);
        assert!(close(s.curve[1].precision, 0.5));
    }

    /// On a recognition: each query answers with its best-scoring pair, the pair must be a
    /// true revisit, and recall counts every query with a revisit.
    #[test]
    fn a_recognition_is_ranked_by_its_queries_best_pairs() {
        use crate::eval::metrics::tests::{circle, recognition};
        let (obs, gt) = circle(2, 40.0);
        let m = |pairs: Vec<(usize, usize)>, score| Match::from_pairs(pairs, score);
        let matches = vec![
            // Right answers, surest, for the first half of lap 2.
            m((400..600).map(|q| (q, q - 400)).collect(), 2.0),
            // 5 m off: below them there, the only answer for the second half.
            m((450..800).map(|q| (q, q - 450)).collect(), 1.0),
            // Right but too recent (within the 20 m gap): never a right answer.
            m((100..150).map(|q| (q, q - 1)).collect(), 3.0),
        ];
        let rec = recognition(&obs, &gt, matches);
        let spec = EvaluationSpec::default();
        let positives = crate::eval::evaluate(&rec, &spec).main.revisits;
        assert_eq!(positives, 410);
        let s = of_recognition(&rec, positives, &spec);
        assert_eq!((s.retrieving, s.right), (450, 200));
        let t: Vec<f64> = s.curve.iter().map(|p| p.threshold).collect();
        assert_eq!(t, [3.0, 2.0, 1.0]);
        assert_eq!(s.curve[0].precision, 0.0);
        assert!(close(s.curve[1].precision, 200.0 / 250.0));
        assert_eq!(s.recall_at_100_precision, 0.0);
        assert!(close(s.average_precision, 200.0 / 410.0 * 0.8));
        assert!(close(s.curve[2].recall, 200.0 / 410.0));
    }

    #[test]
    fn no_answers_give_zeros_and_no_threshold() {
        let s = curve(&[], 10);
        assert_eq!(s.max_f1_threshold, None);
        assert_eq!((s.average_precision, s.max_f1), (0.0, 0.0));
        assert!(s.curve.is_empty());
    }

    #[test]
    fn long_curves_are_thinned_keeping_both_ends() {
        let a: Vec<(f64, bool)> = (0..1000).map(|i| (i as f64, i % 3 == 0)).collect();
        let s = curve(&a, 500);
        assert_eq!(s.curve.len(), MAX_CURVE_POINTS);
        assert_eq!(s.curve[0].threshold, 999.0);
        assert_eq!(s.curve.last().unwrap().threshold, 0.0);
        assert!(close(s.curve.last().unwrap().recall, 334.0 / 500.0));
    }
}
