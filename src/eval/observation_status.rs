//! What happened at each observation of a recognition, judged against the truth: recognized
//! (most of the pairs it is the query of are correct), wrong, a revisit missed, or nothing to
//! find; and the wrong pairs grouped by place. The pictures draw it (`experiment::picture`), the
//! lap strip counts it per lap; the rule of a correct pair is the evaluation's.

use super::Recognition;
use super::metrics::Scorer;
use super::pair_recall::Facing;
use crate::geom::Vec2;
use crate::spec::evaluation::EvaluationSpec;
use std::collections::{HashMap, HashSet};

/// Cell size of wrong-pair clustering (and of grouping turned-down candidates), metres.
pub const CLUSTER_CELL_M: f64 = 5.0;

/// What happened at one observation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObservationKind {
    /// No revisit and no pair.
    Plain,
    /// The query of pairs, at least half of them correct.
    Recognized,
    /// The query of pairs, most of them wrong.
    Wrong,
    /// A revisit with no pair at all.
    Missed,
}

/// Per observation (creation order): its kind, true position, lap slot and revisit; and the
/// wrong pairs' true positions.
pub struct ObservationStatus {
    pub kinds: Vec<ObservationKind>,
    pub positions: Vec<Option<Vec2>>,
    pub lap_slots: Vec<Option<usize>>,
    pub revisits: Vec<bool>,
    /// Per observation: (correct pairs, pairs) it is the query of.
    pub pair_counts: Vec<(usize, usize)>,
    pub correct_pairs: usize,
    pub wrong_pairs: Vec<(Vec2, Vec2)>,
}

/// Classifies every observation of `rec` (a pair is correct within `tp_radius_m` with agreeing
/// headings, as the evaluation says).
pub fn observation_status(rec: &Recognition, spec: &EvaluationSpec) -> ObservationStatus {
    let revisits = Scorer::new(&rec.observations, &rec.truth, spec).revisits(spec.tp_radius_m);
    let index_of: HashMap<usize, usize> = rec
        .observations
        .iter()
        .enumerate()
        .map(|(i, o)| (o.id, i))
        .collect();
    // The observation's own true pose, as the evaluation places it (its frame's, moved by the
    // odometry between them): a real log's scans are up to a metre apart, the observations
    // 0.1 m, so the frame's pose would judge a pair against another place than the report.
    let pose = |i: usize| {
        rec.truth
            .observation_pose(&rec.observations[i])
            .map(|p| p.0)
    };
    let n = rec.observations.len();
    let mut pair_counts = vec![(0usize, 0usize); n];
    let (mut correct_pairs, mut wrong_pairs) = (0, Vec::new());
    let mut seen = HashSet::new();
    let tol = spec.heading_tolerance_deg.to_radians();
    let claimed = rec.matches.iter().flat_map(|m| {
        let claim = Facing::of(m.direction);
        m.pairs().map(move |p| (p, claim))
    });
    for ((query, past), claim) in claimed {
        let (Some(&q), Some(&pa)) = (index_of.get(&query), index_of.get(&past)) else {
            continue;
        };
        let (Some(a), Some(b)) = (pose(q), pose(pa)) else {
            continue;
        };
        if !seen.insert((q, pa)) {
            continue;
        }
        let ok = a.distance(&b) <= spec.tp_radius_m && claim.agrees(a.theta, b.theta, tol);
        pair_counts[q].1 += 1;
        if ok {
            pair_counts[q].0 += 1;
            correct_pairs += 1;
        } else {
            wrong_pairs.push((a.position(), b.position()));
        }
    }
    let kinds = (0..n)
        .map(|i| match pair_counts[i] {
            (c, t) if c > 0 && 2 * c >= t => ObservationKind::Recognized,
            (_, t) if t > 0 => ObservationKind::Wrong,
            _ if revisits[i] => ObservationKind::Missed,
            _ => ObservationKind::Plain,
        })
        .collect();
    ObservationStatus {
        kinds,
        positions: (0..n).map(|i| pose(i).map(|p| p.position())).collect(),
        lap_slots: rec
            .observations
            .iter()
            .map(|o| rec.truth.frame(o.frame_id).map(|f| f.lap_slot))
            .collect(),
        revisits,
        pair_counts,
        correct_pairs,
        wrong_pairs,
    }
}

/// The `k` largest clusters of wrong pairs (query cell, past cell on a 5 m grid), each as the
/// mean query position, the mean past position and its size, largest first.
pub fn worst_wrong_clusters(wrong: &[(Vec2, Vec2)], k: usize) -> Vec<(Vec2, Vec2, usize)> {
    let cell = |p: Vec2| {
        (
            (p.x / CLUSTER_CELL_M).floor() as i64,
            (p.y / CLUSTER_CELL_M).floor() as i64,
        )
    };
    type Acc = (Vec2, Vec2, usize);
    type Cells = ((i64, i64), (i64, i64));
    let mut groups: HashMap<Cells, Acc> = HashMap::new();
    for &(a, b) in wrong {
        let g = groups
            .entry((cell(a), cell(b)))
            .or_insert((Vec2::zeros(), Vec2::zeros(), 0));
        g.0 += a;
        g.1 += b;
        g.2 += 1;
    }
    let mut list: Vec<(Cells, Acc)> = groups.into_iter().collect();
    // Largest first; ties by cell so the picture does not depend on hash order.
    list.sort_by(|x, y| y.1.2.cmp(&x.1.2).then(x.0.cmp(&y.0)));
    list.into_iter()
        .take(k)
        .map(|(_, (a, b, n))| (a / n as f64, b / n as f64, n))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The status judges a pair as the report does, at the observations' own true poses: on a
    /// log whose scans are a metre apart and whose observations are 0.1 m apart, its correct
    /// pairs and the observations it counts as the newer side of one are the evaluation's.
    #[test]
    fn pairs_are_judged_at_the_observations_poses_as_the_report_judges_them() {
        use crate::eval::metrics::evaluate;
        use crate::eval::metrics::tests::{circle_sparse_frames, recognition};
        use crate::place::Match;
        // Two laps of a 40 m circle; a scan (frame) every 1 m, an observation every 0.1 m.
        let (obs, gt) = circle_sparse_frames(2, 40.0, 10);
        let per_lap = 400;
        // The second lap's observations paired with the first's at shifts of up to ±1.5 m.
        let pairs = (50..350).map(|k| (per_lap + k, (k as i64 + (k as i64 % 31) - 15) as usize));
        let rec = recognition(&obs, &gt, vec![Match::from_pairs(pairs, 1.0)]);
        let spec = EvaluationSpec::default();
        let (status, e) = (observation_status(&rec, &spec), evaluate(&rec, &spec));
        assert!(e.main.correct_pairs > 0 && e.main.correct_pairs < e.main.pairs);
        assert_eq!(status.correct_pairs, e.main.correct_pairs);
        let newer_side: Vec<bool> = status.pair_counts.iter().map(|c| c.0 > 0).collect();
        assert_eq!(newer_side, e.recognized);
    }

    #[test]
    fn worst_clusters_are_largest_first() {
        let v = Vec2::new;
        let mut wrong = vec![(v(1.0, 1.0), v(30.0, 1.0)); 5];
        wrong.extend(vec![(v(12.0, 1.0), v(40.0, 1.0)); 2]);
        wrong.push((v(50.0, 50.0), v(0.0, 0.0)));
        let c = worst_wrong_clusters(&wrong, 2);
        assert_eq!(c.iter().map(|c| c.2).collect::<Vec<_>>(), [5, 2]);
        assert_eq!(c[0].0, v(1.0, 1.0));
    }
}
