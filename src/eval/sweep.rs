//! Threshold sweeps and precision-recall curves (paper Fig. 8).
//!
//! A sweep evaluates many level configurations on the same runs, in parallel with rayon. Results
//! come back in the order of the grid whatever the thread count: each grid point is computed on
//! its own (its recognizer is built, fed and scored inside one task) and `collect` keeps the
//! input order.
//!
//! Two ways in: [`sweep_recognizers`] builds one recognizer per grid point and feeds it the runs;
//! [`sweep_matches`] takes a function that produces the matches of a grid point from observations
//! computed once (a back-end over precomputed observations), which is much cheaper when the
//! recognizer can do it.

use super::metrics::{Metrics, Scorer, f1};
use super::tally::{Scope, Tally};
use super::{GroundTruth, PlaceRecognizer, Recognition, recognize_runs};
use crate::log::RunLog;
use crate::place::{Match, Observation};
use crate::spec::evaluation::EvaluationSpec;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// One level configuration of a sweep: number of levels and the minimum n-gram size of each.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct GridPoint {
    /// 1 = level 0 only, 2 = levels 0 and 1, ...
    pub levels: usize,
    /// Minimum n-gram size per level, `thresholds[l]` for level `l` (τ0, τ1, ...).
    pub thresholds: Vec<usize>,
}

impl GridPoint {
    pub fn new(levels: usize, thresholds: &[usize]) -> Self {
        GridPoint {
            levels,
            thresholds: thresholds.to_vec(),
        }
    }
}

/// The paper's Fig. 8 grid: single level τ0 = 0..=9, then two levels τ0 = 3..=9 × τ1 = 0..=18.
pub fn fig8_grid() -> Vec<GridPoint> {
    let mut g: Vec<GridPoint> = (0..=9).map(|t0| GridPoint::new(1, &[t0])).collect();
    for t0 in 3..=9 {
        for t1 in 0..=18 {
            g.push(GridPoint::new(2, &[t0, t1]));
        }
    }
    g
}

/// The scores of one grid point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepResult {
    pub point: GridPoint,
    /// At `tp_radius_m`.
    pub metrics: Metrics,
    /// Recognition seconds per lap (0 when the back-end does not time itself).
    pub recognize_seconds_per_lap: f64,
}

/// Builds a recognizer per grid point with `make`, feeds it `runs`, scores it; in parallel,
/// results in grid order. `on_done` is called once per finished point (from any thread).
pub fn sweep_recognizers<F>(
    grid: &[GridPoint],
    runs: &[RunLog],
    spec: &EvaluationSpec,
    make: F,
    on_done: &(dyn Fn() + Sync),
) -> Vec<SweepResult>
where
    F: Fn(&GridPoint) -> Box<dyn PlaceRecognizer> + Sync,
{
    grid.par_iter()
        .map(|p| {
            let mut rec = make(p);
            let r: Recognition = recognize_runs(rec.as_mut(), runs);
            let metrics = super::metrics::score(
                &r.observations,
                &r.matches,
                &r.truth,
                spec,
                spec.tp_radius_m,
            );
            on_done();
            SweepResult {
                point: p.clone(),
                metrics,
                recognize_seconds_per_lap: r.seconds_per_lap(),
            }
        })
        .collect()
}

/// Observations the back end's query horizon must advance by before a grid point's tally
/// forgets the pairs behind it (each forgetting walks the pairs held).
const FORGET_EVERY: usize = 512;

/// Scores the matches `run_point` produces for every grid point against one set of
/// observations; the revisit search is done once. `run_point` hands each batch of matches to
/// its sink as it finds them, with the back end's query horizon after them (no later match
/// names an older query, [`crate::place::PlaceRecognizer::query_horizon`]): each point's tally
/// counts them at once and forgets the pairs behind the horizon, so neither a point's matches
/// nor its pairs are held. In parallel, results in grid order.
pub fn sweep_matches<F>(
    grid: &[GridPoint],
    observations: &[Observation],
    truth: &GroundTruth,
    spec: &EvaluationSpec,
    run_point: F,
    on_done: &(dyn Fn() + Sync),
) -> Vec<SweepResult>
where
    F: Fn(&GridPoint, &mut dyn FnMut(&[Match], usize)) + Sync,
{
    let scorer = Scorer::new(observations, truth, spec);
    let revisits = scorer.revisits(spec.tp_radius_m);
    grid.par_iter()
        .map(|p| {
            let mut tally = Tally::over(&scorer, spec, Scope::Main);
            let mut forgot_below = 0;
            run_point(p, &mut |matches, horizon| {
                for m in matches {
                    tally.add(m);
                }
                if horizon >= forgot_below + FORGET_EVERY {
                    tally.evict_below(horizon);
                    forgot_below = horizon;
                }
            });
            let metrics = tally.finish_main(Some(&revisits));
            on_done();
            SweepResult {
                point: p.clone(),
                metrics,
                recognize_seconds_per_lap: 0.0,
            }
        })
        .collect()
}

/// One point of a PR curve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrPoint {
    /// Value of the varied threshold (the last level's).
    pub threshold: usize,
    pub precision: f64,
    pub recall: f64,
    pub f1: f64,
    pub pairs: usize,
}

/// A precision-recall curve: one threshold varied, the others fixed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrCurve {
    /// `1 level: τ = [t]` or `2 levels: τ = [6, t]` (`t` varies along the curve).
    pub label: String,
    pub levels: usize,
    /// Thresholds of the levels below the varied one (empty for one level).
    pub fixed_thresholds: Vec<usize>,
    /// Points by increasing threshold.
    pub points: Vec<PrPoint>,
    /// The point of highest F1 (lowest threshold on ties); `None` for an empty curve.
    pub max_f1: Option<PrPoint>,
    /// The highest recall among points with precision ≥ [`PRECISION_FLOOR`] and at least one
    /// pair (lowest threshold on ties); `None` when no point reaches it.
    pub best_recall_at_precision: Option<PrPoint>,
}

/// The precision floor of [`PrCurve::best_recall_at_precision`].
pub const PRECISION_FLOOR: f64 = 0.9;

/// Groups sweep results into curves: one per number of levels and fixed lower thresholds,
/// varying the last level's threshold. Curves in order of first appearance in `results`.
pub fn pr_curves(results: &[SweepResult]) -> Vec<PrCurve> {
    let mut curves: Vec<PrCurve> = Vec::new();
    for r in results {
        let p = &r.point;
        let (fixed, varied) = match p.thresholds.split_last() {
            Some((last, rest)) => (rest.to_vec(), *last),
            None => continue,
        };
        let point = PrPoint {
            threshold: varied,
            precision: r.metrics.precision,
            recall: r.metrics.recall,
            f1: f1(r.metrics.precision, r.metrics.recall),
            pairs: r.metrics.pairs,
        };
        match curves
            .iter_mut()
            .find(|c| c.levels == p.levels && c.fixed_thresholds == fixed)
        {
            Some(c) => c.points.push(point),
            None => curves.push(PrCurve {
                label: curve_label(p.levels, &fixed),
                levels: p.levels,
                fixed_thresholds: fixed,
                points: vec![point],
                max_f1: None,
                best_recall_at_precision: None,
            }),
        }
    }
    for c in &mut curves {
        c.points.sort_by_key(|p| p.threshold);
        c.max_f1 = best_by(&c.points, |_| true, |p| p.f1);
        c.best_recall_at_precision = best_by(
            &c.points,
            |p| p.pairs > 0 && p.precision >= PRECISION_FLOOR,
            |p| p.recall,
        );
    }
    curves
}

/// `1 level: τ = [t]` or `2 levels: τ = [6, t]`: the thresholds in the tables' notation
/// (one per level), `t` the one the curve varies.
fn curve_label(levels: usize, fixed: &[usize]) -> String {
    let mut th: Vec<String> = fixed.iter().map(|t| t.to_string()).collect();
    th.push("t".into());
    let levels = if levels == 1 {
        "1 level".to_string()
    } else {
        format!("{levels} levels")
    };
    format!("{levels}: τ = [{}]", th.join(", "))
}

/// The first point (in order) with the largest `key` among those passing `keep`.
fn best_by(
    points: &[PrPoint],
    keep: impl Fn(&PrPoint) -> bool,
    key: impl Fn(&PrPoint) -> f64,
) -> Option<PrPoint> {
    let mut best: Option<&PrPoint> = None;
    for p in points.iter().filter(|p| keep(p)) {
        if best.is_none_or(|b| key(p) > key(b)) {
            best = Some(p);
        }
    }
    best.cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(levels: usize, th: &[usize], p: f64, r: f64) -> SweepResult {
        SweepResult {
            point: GridPoint::new(levels, th),
            metrics: Metrics {
                precision: p,
                recall: r,
                pairs: 10,
                ..Metrics::default()
            },
            recognize_seconds_per_lap: 0.0,
        }
    }

    #[test]
    fn fig8_grid_has_the_papers_shape() {
        let g = fig8_grid();
        assert_eq!(g.len(), 10 + 7 * 19);
        assert_eq!(g[0], GridPoint::new(1, &[0]));
        assert_eq!(g[10], GridPoint::new(2, &[3, 0]));
        assert_eq!(g.last().unwrap(), &GridPoint::new(2, &[9, 18]));
    }

    #[test]
    fn curves_group_and_pick_best_points() {
        let results = vec![
            result(1, &[1], 0.5, 0.5),
            result(1, &[0], 0.2, 0.9),
            result(1, &[2], 0.95, 0.2),
            result(1, &[3], 1.0, 0.1),
            result(2, &[3, 0], 0.91, 0.4),
            result(2, &[3, 1], 0.92, 0.4),
            result(2, &[4, 0], 0.5, 0.1),
        ];
        let c = pr_curves(&results);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0].label, "1 level: τ = [t]");
        assert_eq!(
            c[0].points.iter().map(|p| p.threshold).collect::<Vec<_>>(),
            [0, 1, 2, 3]
        );
        // F1: t0 0.2/0.9 → 0.327, t1 0.5, t2 0.95/0.2 → 0.330, t3 → 0.18
        assert_eq!(c[0].max_f1.as_ref().unwrap().threshold, 1);
        assert!((c[0].max_f1.as_ref().unwrap().f1 - 0.5).abs() < 1e-12);
        assert_eq!(c[0].best_recall_at_precision.as_ref().unwrap().threshold, 2);
        assert_eq!(c[1].label, "2 levels: τ = [3, t]");
        // Equal recall: the lowest threshold wins.
        assert_eq!(c[1].best_recall_at_precision.as_ref().unwrap().threshold, 0);
        assert!(c[2].best_recall_at_precision.is_none());
    }

    #[test]
    fn points_without_pairs_never_count_as_precise() {
        let mut r = result(1, &[5], 1.0, 0.0);
        r.metrics.pairs = 0;
        assert!(pr_curves(&[r])[0].best_recall_at_precision.is_none());
    }

    #[test]
    fn sweep_matches_keeps_grid_order_whatever_the_threads() {
        let (obs, gt) = crate::eval::metrics::tests::circle(3, 40.0);
        let grid = fig8_grid();
        let matches_of = |p: &GridPoint, sink: &mut dyn FnMut(&[Match], usize)| {
            // A fake back-end: pairs each observation with one a lap back, shifted by the
            // last threshold, so precision falls as the threshold grows.
            let shift = *p.thresholds.last().unwrap();
            let m = Match::from_pairs(
                (420..obs.len())
                    .step_by(p.levels)
                    .map(|q| (q, q - 400 - shift)),
                1.0,
            );
            sink(&[m], 0);
        };
        let spec = EvaluationSpec::default();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| sweep_matches(&grid, &obs, &gt, &spec, matches_of, &|| {}))
        };
        let one = run(1);
        let two = run(2);
        assert_eq!(one, two);
        assert_eq!(
            one.iter().map(|r| r.point.clone()).collect::<Vec<_>>(),
            grid
        );
        assert_eq!(one[0].metrics.precision, 1.0);
        assert_eq!(one[9].metrics.precision, 1.0);
    }
}
