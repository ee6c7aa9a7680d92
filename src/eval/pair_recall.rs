//! Pair recall and the truth-side rules every recall shares.
//!
//! - **True travel.** Revisit gaps are measured on the harness's truth, not on the recognizer's
//!   odometry: [`true_travel_m`] is the distance driven along the true path up to each input
//!   frame, counted across runs (a run boundary adds no travel, but pairs across runs are always
//!   beyond any gap because the second run's travel starts after the first's ends).
//! - **Heading agreement.** A pair is correct only if its two true positions are within the
//!   radius *and* its true headings agree as its match's direction claims ([`Facing::agrees`]):
//!   within `heading_tolerance_deg` for `same`, 180° ± that for `opposite`. A revisit of one
//!   direction is defined with the same rule; the top-level figures count revisits of either
//!   direction ([`Facing::Either`]).
//! - **Pair recall** = correct pairs that could have been found ÷ every pair that could have
//!   been found, where a pair could have been found when it joins an observation to an earlier
//!   one, at least `min_gap_m` of true travel before it, within `tp_radius_m` and facing the
//!   way the figure counts (same, opposite or either) and it is found when a match claiming
//!   that pair's direction holds it. Both are judged at the true poses of the scans the
//!   observations were made from (an observation between two scans takes its scan's; the other
//!   figures move it along the odometry to where it was made), so on a real log, whose scans
//!   are up to a metre apart, a pair can count as correct and not as possible, or the reverse. Unlike per-observation recall (one earlier lap suffices) and visit recall (one
//!   observation per earlier lap suffices), it counts every observation of every earlier pass,
//!   so it is the figure closest to the paper's "matches that could be obtained". Counted by
//!   `eval::tally` (found, as matches arrive) and `count_possible` (the denominator).

use super::GroundTruth;
use super::site_tree::{Query, Site, SiteTree, sweep};
use crate::geom::wrap_angle;
use crate::place::Direction;

/// Distance along the true path from the first frame to each frame, metres (kept with each
/// frame's truth as it is pushed, [`super::FrameTruth::travel_m`]).
pub fn true_travel_m(truth: &GroundTruth) -> Vec<f64> {
    truth.frames.iter().map(|f| f.travel_m).collect()
}

/// Whether two true headings agree as a same-direction pair must.
pub fn heading_agrees(a_rad: f64, b_rad: f64, tolerance_rad: f64) -> bool {
    Facing::Same.agrees(a_rad, b_rad, tolerance_rad)
}

/// The heading agreement a revisit or pair needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Headings within the tolerance.
    Same,
    /// Headings 180° apart within the tolerance.
    Opposite,
    /// Either of the two (the top-level figures).
    Either,
}

impl Facing {
    /// The agreement a match of direction `d` claims for its pairs.
    pub fn of(d: Direction) -> Self {
        match d {
            Direction::Same => Facing::Same,
            Direction::Opposite => Facing::Opposite,
        }
    }

    /// Whether true headings `a_rad` and `b_rad` agree this way within `tolerance_rad`.
    pub fn agrees(self, a_rad: f64, b_rad: f64, tolerance_rad: f64) -> bool {
        let same = || wrap_angle(a_rad - b_rad).abs() <= tolerance_rad;
        let opposite = || wrap_angle(a_rad - b_rad - std::f64::consts::PI).abs() <= tolerance_rad;
        match self {
            Facing::Same => same(),
            Facing::Opposite => opposite(),
            Facing::Either => same() || opposite(),
        }
    }

    /// Whether a match of direction `d` counts in a figure of this facing.
    pub fn counts(self, d: Direction) -> bool {
        self == Facing::Either || self == Facing::of(d)
    }
}

/// Counts behind pair recall (`eval::tally` counts `found` as matches arrive and `possible` at
/// the end, `count_possible`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairRecall {
    /// Pairs that could have been found.
    pub possible: u64,
    /// Distinct pairs of the matches among them (all correct by construction).
    pub found: u64,
}

impl PairRecall {
    /// found / possible, 0 when nothing was possible.
    pub fn ratio(&self) -> f64 {
        if self.possible == 0 {
            0.0
        } else {
            self.found as f64 / self.possible as f64
        }
    }
}

/// Every (observation, earlier observation) pair at least `min_gap_m` of travel apart, within
/// `r` and facing as `facing` says, counted in a k-d tree of the earlier sites
/// ([`super::site_tree`]): the reference [`count_possible_facings`] is tested against.
pub(super) fn count_possible(
    sites: &[Site],
    min_gap_m: f64,
    r: f64,
    facing: Facing,
    tol_rad: f64,
) -> u64 {
    let mut n = 0u64;
    sweep(sites, min_gap_m, |k, tree| {
        let q = Query {
            site: &sites[k],
            r2: r * r,
            facing,
            tol_rad,
        };
        n += tree.count(&q, false);
    });
    n
}

/// [`count_possible`] of each facing of `facings`: every pair within `r` facing so, counted
/// over pairs of the tree's nodes ([`SiteTree::count_pairs_facings`], no query per site), less
/// the pairs a sweep would not take, those less than `min_gap_m` of travel apart: per site, the
/// sites from the sweep's activation frontier up to it, a stretch of `min_gap_m` of travel
/// that does not grow with the laps. Each pair is tested as the sweep tests it, so the counts
/// are those of the sweep's (`tree` is built over the sites in creation order).
pub(super) fn count_possible_facings<const N: usize>(
    tree: &mut SiteTree,
    min_gap_m: f64,
    r: f64,
    facings: [Facing; N],
    tol_rad: f64,
) -> [u64; N] {
    let r2 = r * r;
    let mut n = tree.count_pairs_facings(r2, facings, tol_rad);
    let sites = tree.sites();
    let mut ready = 0;
    for (k, s) in sites.iter().enumerate() {
        while ready < k && s.travel_m - sites[ready].travel_m >= min_gap_m {
            ready += 1;
        }
        for p in &sites[ready..k] {
            if (s.x - p.x).powi(2) + (s.y - p.y).powi(2) > r2 {
                continue;
            }
            for (n, &facing) in n.iter_mut().zip(&facings) {
                *n -= u64::from(facing.agrees(s.theta, p.theta, tol_rad));
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::metrics::tests::circle;
    use crate::eval::tally::{Scope, Tally};
    use crate::place::{Match, Observation};
    use crate::spec::evaluation::EvaluationSpec;

    fn one_match(_obs: &[Observation], pairs: &[(usize, usize)]) -> Match {
        Match::from_pairs(pairs.iter().copied(), 1.0)
    }

    /// Pair recall at 1 m of `matches`, over the pairs facing as `facing` says (scored as
    /// every figure is, by `eval::tally`).
    fn pair_recall(
        obs: &[Observation],
        matches: &[Match],
        gt: &GroundTruth,
        facing: Facing,
    ) -> f64 {
        let spec = EvaluationSpec {
            tp_radius_m: 1.0,
            ..EvaluationSpec::default()
        };
        let mut t = Tally::new(&spec, Scope::Full);
        t.sync(obs, gt);
        matches.iter().for_each(|m| t.add(m));
        let e = t.finish(gt);
        match facing {
            Facing::Either => e.main.pair_recall,
            Facing::Same => e.directions.same.pair_recall,
            Facing::Opposite => e.directions.opposite.pair_recall,
        }
    }

    /// Every possible pair found scores 1; only the nearest neighbour of one earlier lap scores
    /// far less, although per-observation recall would be 1.
    #[test]
    fn pair_recall_counts_every_possible_pair() {
        let (obs, gt) = circle(3, 40.0);
        let spec = EvaluationSpec::default();
        let travel = true_travel_m(&gt);
        let pos = |i: usize| gt.frames[i].pose.0;
        let mut all = Vec::new();
        for q in 0..obs.len() {
            for p in 0..q {
                if travel[q] - travel[p] >= spec.min_gap_m && pos(q).distance(&pos(p)) <= 1.0 {
                    all.push((q, p));
                }
            }
        }
        let full = pair_recall(&obs, &[one_match(&obs, &all)], &gt, Facing::Same);
        assert_eq!(full, 1.0);
        // One pair per observation, one lap back: found / possible is their share of `all`.
        let nearest: Vec<(usize, usize)> = (400..obs.len()).map(|q| (q, q - 400)).collect();
        let some = pair_recall(&obs, &[one_match(&obs, &nearest)], &gt, Facing::Same);
        assert_eq!(some, nearest.len() as f64 / all.len() as f64);
        assert!(some < 0.1, "{some}");
        assert_eq!(pair_recall(&obs, &[], &gt, Facing::Same), 0.0);
    }

    /// Pair recall counts pairs of observations at the true poses of the scans they were made
    /// from (an observation between two scans takes its scan's): where scans are sparser than
    /// observations (a real log), an oracle that claims every pair possible at those poses
    /// scores 1, the pairs found and the pairs possible judged alike.
    #[test]
    fn pair_recall_judges_the_pairs_at_their_scans_poses() {
        let (obs, gt) = crate::eval::metrics::tests::circle_sparse_frames(3, 40.0, 10);
        let spec = EvaluationSpec::default();
        let travel = true_travel_m(&gt);
        let scan = |i: usize| gt.frames[obs[i].frame_id].pose.0;
        let mut all = Vec::new();
        for q in 0..obs.len() {
            for p in 0..q {
                let gap = travel[obs[q].frame_id] - travel[obs[p].frame_id];
                if gap >= spec.min_gap_m && scan(q).distance(&scan(p)) <= 1.0 {
                    all.push((q, p));
                }
            }
        }
        assert!(all.len() > 1000, "{}", all.len());
        let full = pair_recall(&obs, &[one_match(&obs, &all)], &gt, Facing::Same);
        assert_eq!(full, 1.0);
    }

    /// A pair facing the other way is found only by a match claiming the opposite direction.
    #[test]
    fn opposite_headings_do_not_count() {
        let (obs, mut gt) = circle(2, 40.0);
        for f in &mut gt.frames[400..] {
            f.pose.0.theta += std::f64::consts::PI;
        }
        let m = one_match(&obs, &[(400, 0), (450, 50)]);
        let claimed_same = pair_recall(&obs, std::slice::from_ref(&m), &gt, Facing::Either);
        assert_eq!(claimed_same, 0.0);
        // Claimed as opposite, the same pairs are found, in the opposite and top-level figures.
        let opposite = Match {
            direction: Direction::Opposite,
            ..m
        };
        for facing in [Facing::Opposite, Facing::Either] {
            let pr = pair_recall(&obs, std::slice::from_ref(&opposite), &gt, facing);
            assert!(pr > 0.0, "{facing:?}");
        }
        assert_eq!(pair_recall(&obs, &[opposite], &gt, Facing::Same), 0.0);
    }

    /// The possible pairs counted over pairs of nodes equal those of a query per site, on
    /// passes that go both ways, at radii from below the sites' spacing to many leaves wide.
    #[test]
    fn possible_pairs_over_node_pairs_equal_a_query_per_site() {
        let sites = crate::eval::site_tree::tests::passes(3);
        let facings = [Facing::Either, Facing::Same, Facing::Opposite];
        for r in [0.05, 0.5, 1.0, 3.0] {
            for gap in [0.0, 2.0, 30.0] {
                for tol in [0.3, 0.7, 2.0] {
                    let mut tree = SiteTree::new(&sites);
                    let got = count_possible_facings(&mut tree, gap, r, facings, tol);
                    let want = facings.map(|f| count_possible(&sites, gap, r, f, tol));
                    assert_eq!(got, want, "r {r} gap {gap} tol {tol}");
                    assert!(r < 0.5 || want.iter().all(|&n| n > 0), "r {r}");
                }
            }
        }
    }

    #[test]
    fn true_travel_follows_the_true_path() {
        let (_, gt) = circle(2, 40.0);
        let t = true_travel_m(&gt);
        assert_eq!(t[0], 0.0);
        assert!((t[400] - 40.0).abs() < 0.01, "{}", t[400]);
    }
}
