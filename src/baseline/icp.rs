//! The ICP baseline of the paper's Table I: regions of local laser points matched by
//! point-to-point 2D ICP.
//!
//! How it works (defaults in [`IcpConfig`]):
//!
//! - Scan endpoints within `local_radius_m` go into a local grid of `cell_m` cells (a hash set of
//!   hit cells in the odometry frame); cells farther than `local_radius_m` from the robot are
//!   forgotten.
//! - An observation is made each `observation_spacing_m` of odometric travel (same
//!   [`Observation`] type as the recognizer, `psi` = 0).
//! - Every `region_observations` observations of a run close a region: its frame is the pose of
//!   its last observation; its points are `region_points` cells sampled evenly (every k-th of the
//!   cells sorted by index, deterministic) from the grid's occupied cells, expressed in that frame
//!   and then centred on their centroid.
//! - Each new region is aligned with every past region that ended at least `min_gap_m` of
//!   travel before the new one started: trimmed point-to-point ICP against a k-d tree (kiddo) of
//!   the past region's points, from the identity of the two centred sets and from each of
//!   `initial_rotations_deg`; correspondences beyond `max_correspondence_m` are rejected and only
//!   the best `trim_ratio` of the rest drive each step. A cheap rotation-invariant signature
//!   (radial histogram) skips pairs that cannot align (`prefilter_max_l1`), and hopeless
//!   alignments stop early (`early_reject_*`); both only save time.
//! - A region pair is accepted when the trimmed mean residual is at most
//!   `accept_mean_residual_m` and the share of new-region points with a past point within
//!   `inlier_distance_m` is at least `accept_inlier_fraction`. The best accepted pair (or with
//!   `only_best` off, every one) becomes a [`Match`] (`levels` 0) pairing every observation of the new region with the observation of
//!   the past region nearest to it once mapped through the ICP transform (one pair per new
//!   observation).
//!
//! Region pairs are tested in parallel (rayon) when `parallel` is set; results are collected in
//! order, so the output does not depend on the thread count. Times are wall clock. The default is
//! one thread, so its seconds per lap compare with the recognizer's, which Table I times
//! single-threaded side by side.

use crate::geom::{OdomPose, Pose2, Vec2};
use crate::place::PlaceRecognizer;
use crate::place::{FrameId, Match, Observation, TravelSchedule};
use crate::scan::Scan;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::collections::HashSet;

/// Settings of the ICP baseline. Distances in metres, angles in degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct IcpConfig {
    /// Odometric travel between observations. Default 0.10 m (as the recognizer).
    pub observation_spacing_m: f64,
    /// Observations per region. Default 20 (paper).
    pub region_observations: usize,
    /// Points sampled per region. Default 150 (paper).
    pub region_points: usize,
    /// Regions with fewer occupied cells than this are not made. Default 30.
    pub min_region_points: usize,
    /// Local grid cell size. Default 0.05 m.
    pub cell_m: f64,
    /// Scan endpoints and grid cells are kept within this distance of the robot. Default 3 m.
    pub local_radius_m: f64,
    /// A past region must end at least this much travel before the new one starts. Default 20 m.
    pub min_gap_m: f64,
    /// ICP iterations at most. Default 30.
    pub max_iterations: usize,
    /// Correspondences farther apart are outliers. Default 0.5 m.
    pub max_correspondence_m: f64,
    /// Share of the (non-outlier) correspondences, best first, used in each step. Default 0.8.
    pub trim_ratio: f64,
    /// Initial rotations tried besides the centred identity, degrees. Default none: regions
    /// are expressed in the robot's own frame, so two passes in the same direction differ by
    /// a few degrees only.
    pub initial_rotations_deg: Vec<f64>,
    /// Stop when a step's translation (m) plus rotation (rad) is below this. Default 1e-3
    /// (about 1 mm or 1 mrad).
    pub convergence: f64,
    /// From this iteration on, give up when the trimmed mean residual exceeds
    /// `early_reject_residual_m`. Default 6.
    pub early_reject_iteration: usize,
    /// Give up as soon as fewer than this share of the points have a correspondence (within
    /// `max_correspondence_m`). Default 0.5.
    pub early_reject_fraction: f64,
    /// See `early_reject_iteration`. Default 0.15 m (three times the acceptance residual).
    pub early_reject_residual_m: f64,
    /// Before ICP, skip region pairs whose radial signatures (histograms of point distances
    /// from the centroid, 0.25 m bins, normalised) differ by more than this L1 distance (0..2).
    /// The signature does not depend on rotation or translation, so it only removes pairs ICP
    /// would reject anyway, at a fraction of the cost. `None` runs ICP on every pair. Default
    /// 0.5.
    pub prefilter_max_l1: Option<f64>,
    /// Accept when the trimmed mean residual is at most this. Default 0.05 m.
    pub accept_mean_residual_m: f64,
    /// Distance within which a point counts as an inlier. Default 0.10 m.
    pub inlier_distance_m: f64,
    /// Accept when at least this share of the new region's points are inliers. Default 0.8.
    pub accept_inlier_fraction: f64,
    /// Emit only the accepted past region with the most inliers (then lowest residual, then
    /// oldest) per new region, instead of every accepted one. Default true: in corridors most
    /// region pairs align (aliasing), and emitting all of them grows quadratically (on the
    /// institute floor, 6 laps already gave 93 000 matches at precision 0.014; 40 laps would
    /// need gigabytes).
    pub only_best: bool,
    /// Test past regions in parallel (same results, faster wall clock). Default false: Table I
    /// times ICP on one thread, like the recognizer beside it.
    pub parallel: bool,
}

impl Default for IcpConfig {
    fn default() -> Self {
        IcpConfig {
            observation_spacing_m: 0.10,
            region_observations: 20,
            region_points: 150,
            min_region_points: 30,
            cell_m: 0.05,
            local_radius_m: 3.0,
            min_gap_m: 20.0,
            max_iterations: 30,
            max_correspondence_m: 0.5,
            trim_ratio: 0.8,
            initial_rotations_deg: Vec::new(),
            convergence: 1e-3,
            early_reject_iteration: 6,
            early_reject_fraction: 0.5,
            early_reject_residual_m: 0.15,
            prefilter_max_l1: Some(0.5),
            accept_mean_residual_m: 0.05,
            inlier_distance_m: 0.10,
            accept_inlier_fraction: 0.8,
            only_best: true,
            parallel: false,
        }
    }
}

/// A rigid 2D transform `p ↦ R(θ) p + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid {
    pub theta: f64,
    pub t: Vec2,
}

impl Rigid {
    pub const IDENTITY: Rigid = Rigid {
        theta: 0.0,
        t: Vec2::new(0.0, 0.0),
    };

    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        self.applier()(p)
    }

    /// `apply` with the sine and cosine computed once, for many points.
    pub fn applier(&self) -> impl Fn([f64; 2]) -> [f64; 2] + use<> {
        let (s, c) = self.theta.sin_cos();
        let (tx, ty) = (self.t.x, self.t.y);
        move |p| [c * p[0] - s * p[1] + tx, s * p[0] + c * p[1] + ty]
    }
}

/// Bins of [`Cloud::signature`].
pub const SIGNATURE_BINS: usize = 24;
/// Bin width of [`Cloud::signature`], metres.
pub const SIGNATURE_BIN_M: f64 = 0.25;

/// L1 distance of two signatures (0 = same, 2 = disjoint).
pub fn signature_distance(a: &Cloud, b: &Cloud) -> f64 {
    a.signature
        .iter()
        .zip(&b.signature)
        .map(|(x, y)| (x - y).abs())
        .sum()
}

/// A point set to align against, with its k-d tree.
pub struct Cloud {
    /// Points, centred on their centroid.
    pub points: Vec<[f64; 2]>,
    /// Normalised histogram of point distances from the centroid (bins of
    /// [`SIGNATURE_BIN_M`]); invariant to rotation and translation.
    pub signature: [f64; SIGNATURE_BINS],
    /// Centroid of the points before centring (in the frame they were given in).
    pub centroid: [f64; 2],
    tree: ImmutableKdTree<f64, 2>,
}

impl Cloud {
    /// Centres `points` on their centroid and builds the k-d tree.
    pub fn new(points: &[[f64; 2]]) -> Self {
        let n = points.len().max(1) as f64;
        let cx = points.iter().map(|p| p[0]).sum::<f64>() / n;
        let cy = points.iter().map(|p| p[1]).sum::<f64>() / n;
        let centred: Vec<[f64; 2]> = points.iter().map(|p| [p[0] - cx, p[1] - cy]).collect();
        let tree = ImmutableKdTree::new_from_slice(&centred);
        let mut signature = [0.0; SIGNATURE_BINS];
        for p in &centred {
            let b = ((p[0].hypot(p[1]) / SIGNATURE_BIN_M) as usize).min(SIGNATURE_BINS - 1);
            signature[b] += 1.0 / n;
        }
        Cloud {
            points: centred,
            signature,
            centroid: [cx, cy],
            tree,
        }
    }

    /// Nearest point: (squared distance, index).
    fn nearest(&self, q: &[f64; 2]) -> (f64, usize) {
        let n = self.tree.nearest_one::<SquaredEuclidean>(q);
        (n.distance, n.item as usize)
    }
}

/// The outcome of aligning a source cloud with a target cloud.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// Maps centred source points onto centred target points.
    pub transform: Rigid,
    /// Mean distance of the correspondences used in the last step, metres.
    pub mean_residual_m: f64,
    /// Share of source points with a target point within `inlier_distance_m`.
    pub inlier_fraction: f64,
    pub iterations: usize,
    /// Whether the thresholds of the config accept it.
    pub accepted: bool,
}

impl Alignment {
    /// Maps a point of the source's original frame into the target's original frame.
    pub fn map_point(&self, source: &Cloud, target: &Cloud, p: [f64; 2]) -> [f64; 2] {
        let q = self
            .transform
            .apply([p[0] - source.centroid[0], p[1] - source.centroid[1]]);
        [q[0] + target.centroid[0], q[1] + target.centroid[1]]
    }
}

/// The best 2D rigid transform taking `src[i]` to `dst[i]` (least squares).
fn fit(pairs: &[([f64; 2], [f64; 2])]) -> Rigid {
    let n = pairs.len() as f64;
    let (mut sx, mut sy, mut dx, mut dy) = (0.0, 0.0, 0.0, 0.0);
    for (s, d) in pairs {
        sx += s[0];
        sy += s[1];
        dx += d[0];
        dy += d[1];
    }
    let (sx, sy, dx, dy) = (sx / n, sy / n, dx / n, dy / n);
    let (mut cross, mut dot) = (0.0, 0.0);
    for (s, d) in pairs {
        let (ax, ay, bx, by) = (s[0] - sx, s[1] - sy, d[0] - dx, d[1] - dy);
        cross += ax * by - ay * bx;
        dot += ax * bx + ay * by;
    }
    let theta = cross.atan2(dot);
    let (si, co) = theta.sin_cos();
    Rigid {
        theta,
        t: Vec2::new(dx - (co * sx - si * sy), dy - (si * sx + co * sy)),
    }
}

/// Trimmed point-to-point ICP of `source` onto `target`, from the centred identity and each
/// initial rotation; the best result (most inliers, then lowest residual) is returned.
pub fn align(source: &Cloud, target: &Cloud, cfg: &IcpConfig) -> Alignment {
    let mut best: Option<Alignment> = None;
    let starts = std::iter::once(0.0).chain(cfg.initial_rotations_deg.iter().copied());
    for deg in starts {
        let a = align_from(
            source,
            target,
            Rigid {
                theta: deg.to_radians(),
                t: Vec2::zeros(),
            },
            cfg,
        );
        let better = match &best {
            None => true,
            Some(b) => {
                a.inlier_fraction > b.inlier_fraction
                    || (a.inlier_fraction == b.inlier_fraction
                        && a.mean_residual_m < b.mean_residual_m)
            }
        };
        if better {
            best = Some(a);
        }
        if best.is_some_and(|b| b.accepted) {
            break;
        }
    }
    best.expect("at least the identity start")
}

fn align_from(source: &Cloud, target: &Cloud, start: Rigid, cfg: &IcpConfig) -> Alignment {
    let max_d2 = cfg.max_correspondence_m.powi(2);
    let n = source.points.len();
    let mut tf = start;
    let mut corr: Vec<(f64, usize, usize)> = Vec::with_capacity(n);
    let mut pairs: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(n);
    let mut mean_residual = f64::INFINITY;
    let mut iterations = 0;
    let failed = |transform, iterations| Alignment {
        transform,
        mean_residual_m: f64::INFINITY,
        inlier_fraction: 0.0,
        iterations,
        accepted: false,
    };
    if n == 0 || target.points.is_empty() {
        return failed(tf, 0);
    }
    let in_d2 = cfg.inlier_distance_m.powi(2);
    let mut inliers = 0;
    for it in 0..cfg.max_iterations {
        iterations = it + 1;
        corr.clear();
        let apply = tf.applier();
        for (i, p) in source.points.iter().enumerate() {
            let (d2, j) = target.nearest(&apply(*p));
            if d2 <= max_d2 {
                corr.push((d2, i, j));
            }
        }
        if (corr.len() as f64) < cfg.early_reject_fraction * n as f64 || corr.len() < 3 {
            return failed(tf, iterations);
        }
        inliers = corr.iter().filter(|c| c.0 <= in_d2).count();
        let keep = ((corr.len() as f64 * cfg.trim_ratio).ceil() as usize).clamp(3, corr.len());
        if keep < corr.len() {
            corr.select_nth_unstable_by(keep - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        }
        mean_residual = corr[..keep].iter().map(|c| c.0.sqrt()).sum::<f64>() / keep as f64;
        if it + 1 >= cfg.early_reject_iteration && mean_residual > cfg.early_reject_residual_m {
            return failed(tf, iterations);
        }
        pairs.clear();
        pairs.extend(
            corr[..keep]
                .iter()
                .map(|&(_, i, j)| (source.points[i], target.points[j])),
        );
        let next = fit(&pairs);
        let step = (next.t - tf.t).norm() + crate::geom::wrap_angle(next.theta - tf.theta).abs();
        tf = next;
        if step < cfg.convergence {
            break;
        }
    }
    // Residual and inliers are those of the last correspondence step (before its final, small
    // update), which saves a pass of nearest-neighbour queries.
    let inlier_fraction = inliers as f64 / n as f64;
    Alignment {
        transform: tf,
        mean_residual_m: mean_residual,
        inlier_fraction,
        iterations,
        accepted: mean_residual <= cfg.accept_mean_residual_m
            && inlier_fraction >= cfg.accept_inlier_fraction,
    }
}

/// Picks `k` of `n` items evenly (indices `⌊i·n/k⌋`); all of them when `n ≤ k`.
pub fn even_sample<T: Copy>(items: &[T], k: usize) -> Vec<T> {
    let n = items.len();
    if n <= k {
        return items.to_vec();
    }
    (0..k).map(|i| items[i * n / k]).collect()
}

/// A region: consecutive observations of one run and the points seen around them.
struct Region {
    /// Observation ids, oldest first.
    obs: Vec<usize>,
    start_travel_m: f64,
    end_travel_m: f64,
    /// Observation positions in the region frame.
    obs_local: Vec<[f64; 2]>,
    cloud: Cloud,
}

/// The ICP baseline as a [`PlaceRecognizer`].
pub struct IcpRecognizer {
    cfg: IcpConfig,
    observations: Vec<Observation>,
    regions: Vec<Region>,
    /// Occupied cells of the local grid, odometry frame.
    cells: HashSet<(i64, i64)>,
    run: Option<usize>,
    /// Travel and the observation slots on it.
    schedule: TravelSchedule,
    /// Observations of the current run not yet in a region.
    pending: Vec<usize>,
    stats: IcpStats,
}

/// Counts of what the ICP baseline did, for cost estimates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IcpStats {
    /// Region pairs considered (past regions far enough back).
    pub region_pairs: usize,
    /// Pairs the signature prefilter skipped.
    pub prefiltered: usize,
    /// Pairs ICP accepted (before `only_best`).
    pub accepted: usize,
}

impl IcpRecognizer {
    pub fn new(cfg: IcpConfig) -> Self {
        let schedule = TravelSchedule::new(cfg.observation_spacing_m);
        IcpRecognizer {
            cfg,
            observations: Vec::new(),
            regions: Vec::new(),
            cells: HashSet::new(),
            run: None,
            schedule,
            pending: Vec::new(),
            stats: IcpStats::default(),
        }
    }

    pub fn config(&self) -> &IcpConfig {
        &self.cfg
    }

    /// What was tested so far.
    pub fn stats(&self) -> IcpStats {
        self.stats
    }

    /// Regions made so far.
    pub fn region_count(&self) -> usize {
        self.regions.len()
    }

    fn cell_of(&self, p: Vec2) -> (i64, i64) {
        (
            (p.x / self.cfg.cell_m).floor() as i64,
            (p.y / self.cfg.cell_m).floor() as i64,
        )
    }

    fn insert_scan(&mut self, pose: &Pose2, scan: &Scan) {
        let sensor = pose.compose(&scan.layout.mount);
        for i in 0..scan.ranges_m.len().min(scan.layout.count) {
            if !scan.is_hit(i) {
                continue;
            }
            let r = scan.ranges_m[i];
            if r > self.cfg.local_radius_m {
                continue;
            }
            let a = scan.layout.beam_angle_rad(i);
            let p = sensor.transform_point(Vec2::new(r * a.cos(), r * a.sin()));
            if (p - pose.position()).norm() <= self.cfg.local_radius_m {
                let c = self.cell_of(p);
                self.cells.insert(c);
            }
        }
    }

    fn forget_far_cells(&mut self, pose: &Pose2) {
        let (cx, cy, cell) = (pose.x, pose.y, self.cfg.cell_m);
        let r2 = self.cfg.local_radius_m.powi(2);
        self.cells.retain(|&(i, j)| {
            let (x, y) = ((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell);
            (x - cx).powi(2) + (y - cy).powi(2) <= r2
        });
    }

    /// Builds a region from the pending observations and tests it; returns its matches.
    fn close_region(&mut self) -> Vec<Match> {
        let obs_ids = std::mem::take(&mut self.pending);
        let frame = self.observations[*obs_ids.last().expect("a region has observations")]
            .odom_pose
            .0;
        let mut cells: Vec<(i64, i64)> = self.cells.iter().copied().collect();
        if cells.len() < self.cfg.min_region_points {
            return Vec::new();
        }
        cells.sort_unstable();
        let inv = frame.inverse();
        let cell = self.cfg.cell_m;
        let points: Vec<[f64; 2]> = even_sample(&cells, self.cfg.region_points)
            .into_iter()
            .map(|(i, j)| {
                let p = inv
                    .transform_point(Vec2::new((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell));
                [p.x, p.y]
            })
            .collect();
        let obs_local = obs_ids
            .iter()
            .map(|&o| {
                let p = inv.transform_point(self.observations[o].odom_pose.0.position());
                [p.x, p.y]
            })
            .collect();
        let region = Region {
            start_travel_m: self.observations[obs_ids[0]].travel_m,
            end_travel_m: self.observations[*obs_ids.last().unwrap()].travel_m,
            obs: obs_ids,
            obs_local,
            cloud: Cloud::new(&points),
        };
        let limit = region.start_travel_m - self.cfg.min_gap_m;
        let candidates: Vec<usize> = (0..self.regions.len())
            .filter(|&k| self.regions[k].end_travel_m <= limit)
            .collect();
        // Per candidate: None when the prefilter skipped it, else the alignment.
        let test = |&k: &usize| -> (usize, Option<Alignment>) {
            let past = &self.regions[k].cloud;
            if self
                .cfg
                .prefilter_max_l1
                .is_some_and(|max| signature_distance(&region.cloud, past) > max)
            {
                return (k, None);
            }
            (k, Some(align(&region.cloud, past, &self.cfg)))
        };
        let tested: Vec<(usize, Option<Alignment>)> = if self.cfg.parallel {
            candidates.par_iter().map(test).collect()
        } else {
            candidates.iter().map(test).collect()
        };
        self.stats.region_pairs += tested.len();
        self.stats.prefiltered += tested.iter().filter(|t| t.1.is_none()).count();
        let mut accepted: Vec<(usize, Alignment)> = tested
            .into_iter()
            .filter_map(|(k, a)| a.filter(|a| a.accepted).map(|a| (k, a)))
            .collect();
        self.stats.accepted += accepted.len();
        if self.cfg.only_best {
            let best = accepted.iter().copied().reduce(|b, c| {
                let better = c.1.inlier_fraction > b.1.inlier_fraction
                    || (c.1.inlier_fraction == b.1.inlier_fraction
                        && c.1.mean_residual_m < b.1.mean_residual_m);
                if better { c } else { b }
            });
            accepted = best.into_iter().collect();
        }
        let matches = accepted
            .iter()
            .map(|(k, a)| self.region_match(&region, &self.regions[*k], a))
            .collect();
        self.regions.push(region);
        matches
    }

    fn region_match(&self, new: &Region, past: &Region, a: &Alignment) -> Match {
        let pairs = new
            .obs
            .iter()
            .zip(&new.obs_local)
            .map(|(&q, &ql)| {
                let m = a.map_point(&new.cloud, &past.cloud, ql);
                let (k, _) = past
                    .obs_local
                    .iter()
                    .enumerate()
                    .map(|(k, p)| (k, (p[0] - m[0]).powi(2) + (p[1] - m[1]).powi(2)))
                    .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b });
                (q, past.obs[k])
            })
            .collect::<Vec<_>>();
        // Surer the more of the cloud lies on the past one.
        Match::from_pairs(pairs, a.inlier_fraction)
    }
}

impl PlaceRecognizer for IcpRecognizer {
    fn start_run(&mut self) -> Vec<Match> {
        self.run = Some(self.run.map_or(0, |r| r + 1));
        self.cells.clear();
        self.schedule.start_run();
        self.pending.clear();
        Vec::new()
    }

    fn push(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<Match> {
        if self.run.is_none() {
            self.start_run();
        }
        let pose = odom.0;
        let travel_m = self.schedule.advance(pose);
        self.insert_scan(&pose, scan);
        if !self.schedule.take_due() {
            return Vec::new();
        }
        self.forget_far_cells(&pose);
        let id =
            super::push_observation(&mut self.observations, self.run, frame_id, odom, travel_m);
        self.pending.push(id);
        if self.pending.len() >= self.cfg.region_observations {
            self.close_region()
        } else {
            Vec::new()
        }
    }

    fn observations(&self) -> &[Observation] {
        &self.observations
    }

    fn name(&self) -> String {
        "icp".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points every 5 cm along polylines, a corner with a niche and a door gap: not degenerate.
    pub(crate) fn walls() -> Vec<[f64; 2]> {
        let lines: [&[(f64, f64)]; 3] = [
            &[(-2.5, -1.0), (1.0, -1.0), (1.0, -2.5)],
            &[
                (-2.5, 1.0),
                (-0.5, 1.0),
                (-0.5, 1.6),
                (0.3, 1.6),
                (0.3, 1.0),
                (2.5, 1.0),
            ],
            &[(2.5, 1.0), (2.5, -0.3)],
        ];
        let mut pts = Vec::new();
        for l in lines {
            for w in l.windows(2) {
                let (a, b) = (Vec2::new(w[0].0, w[0].1), Vec2::new(w[1].0, w[1].1));
                let n = ((b - a).norm() / 0.05).round() as usize;
                for k in 0..n {
                    let p = a + (b - a) * (k as f64 / n as f64);
                    pts.push([p.x, p.y]);
                }
            }
        }
        pts
    }

    #[test]
    fn recovers_a_known_offset() {
        let cfg = IcpConfig::default();
        let target_pts = even_sample(&walls(), 150);
        // The same walls seen from a robot moved by (0.3, -0.2) and turned by 8°: points in
        // the new frame are the inverse transform of the world points.
        let moved = Pose2::new(0.3, -0.2, 8f64.to_radians());
        let inv = moved.inverse();
        let all: Vec<[f64; 2]> = walls()
            .iter()
            .skip(1) // a different sample of the same walls
            .map(|p| {
                let q = inv.transform_point(Vec2::new(p[0], p[1]));
                [q.x, q.y]
            })
            .collect();
        let source_pts = even_sample(&all, 150);
        let (source, target) = (Cloud::new(&source_pts), Cloud::new(&target_pts));
        let a = align(&source, &target, &cfg);
        assert!(a.accepted, "{a:?}");
        // A source point must land where `moved` puts it.
        for p in [[0.0, 0.0], [1.0, 0.5], [-1.5, 0.8]] {
            let got = a.map_point(&source, &target, p);
            let want = moved.transform_point(Vec2::new(p[0], p[1]));
            let err = ((got[0] - want.x).powi(2) + (got[1] - want.y).powi(2)).sqrt();
            assert!(err < 0.04, "point {p:?}: {got:?} vs {want:?}");
        }
        let dtheta = crate::geom::wrap_angle(a.transform.theta - moved.theta);
        assert!(dtheta.abs() < 1f64.to_radians(), "{a:?}");
    }

    #[test]
    fn rejects_unrelated_regions() {
        let cfg = IcpConfig::default();
        let target = Cloud::new(&even_sample(&walls(), 150));
        // A round room of radius 2 m: nothing like the corridor corner.
        let room: Vec<[f64; 2]> = (0..150)
            .map(|k| {
                let a = k as f64 / 150.0 * std::f64::consts::TAU;
                [2.0 * a.cos(), 2.0 * a.sin()]
            })
            .collect();
        let a = align(&Cloud::new(&room), &target, &cfg);
        assert!(!a.accepted, "{a:?}");
        // And a straight corridor of other width.
        let corridor: Vec<[f64; 2]> = (0..150)
            .map(|k| {
                [
                    -2.5 + (k / 2) as f64 * 0.07,
                    if k % 2 == 0 { -0.6 } else { 0.6 },
                ]
            })
            .collect();
        let a = align(&Cloud::new(&corridor), &target, &cfg);
        assert!(!a.accepted, "{a:?}");
    }

    #[test]
    fn even_sample_is_deterministic_and_spread() {
        let v: Vec<usize> = (0..10).collect();
        assert_eq!(even_sample(&v, 3), vec![0, 3, 6]);
        assert_eq!(even_sample(&v, 20), v);
    }

    #[test]
    fn fit_recovers_an_exact_transform() {
        let tf = Rigid {
            theta: 0.3,
            t: Vec2::new(1.0, -2.0),
        };
        let pairs: Vec<_> = walls().into_iter().map(|p| (p, tf.apply(p))).collect();
        let got = fit(&pairs);
        assert!((got.theta - 0.3).abs() < 1e-9 && (got.t - tf.t).norm() < 1e-9);
    }
}
