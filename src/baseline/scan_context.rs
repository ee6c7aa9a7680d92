//! A Scan Context baseline: the polar descriptor of G. Kim and A. Kim, "Scan Context: Egocentric
//! Spatial Descriptor for Place Recognition within 3D Point Cloud Map", IROS 2018, adapted to
//! 2D laser scans. It is written against the plug-in API only ([`crate::place`]): the harness
//! drives and scores it like any recognizer.
//!
//! How it works (defaults in [`ScanContextConfig`]):
//!
//! - An observation is made each `observation_spacing_m` of odometric travel. Its descriptor is
//!   a `rings × sectors` polar grid around the robot, in the robot's frame: ring `i` holds the
//!   points `i·max_radius_m/rings` to `(i+1)·max_radius_m/rings` away, sector `j` those at
//!   bearings `j·360°/sectors` to `(j+1)·360°/sectors` (counter-clockwise from ahead). The
//!   points are the `cell_m` grid cells (odometry frame) hit by a scan endpoint within the last
//!   `history_m` of travel, carried into the current robot frame by odometry: a 180° laser sees
//!   half of the circle, and the history fills in the rest. There is no height in 2D, so a bin's
//!   value is `ln(1 + n)` of the `n` cells in it (about the length of wall it holds; the paper
//!   takes the greatest height).
//! - The **ring key** (per ring, the share of sectors that hold a point; the same whatever the
//!   robot's heading) goes into a k-d tree (`kiddo`) once the observation lies `min_gap_m` of
//!   travel behind the newest one, so recent frames are never candidates (the same gap the truth
//!   uses). Each observation asks the tree for the `candidates` nearest ring keys.
//! - Each candidate is compared with the **column-shift distance**: for every shift `k` of the
//!   query's sectors, one minus the mean cosine similarity of the sector columns that hold points
//!   in both descriptors (query column `s + k` against past column `s`); the least over `k` is the
//!   distance and its `k` the heading change (`k·360°/sectors`). A heading change of more than
//!   90° makes it a revisit driven the other way ([`Direction::Opposite`]). Shifts at which fewer
//!   than `min_overlap_ratio` of the sectors hold points in both are not counted.
//! - The nearest candidate is a match when its distance is at most `max_distance`; the match pairs
//!   the observation with that candidate, score `1 − distance`.
//!
//! Cost per observation: one k-d tree query and `candidates` comparisons, each proportional to
//! the sectors squared plus the products of the occupied bins ring by ring. Only the tree query
//! grows with the history, and faster than the tree's logarithm: a k-d tree prunes poorly in
//! the ring key's 20 dimensions (perf: 30 % of the samples of an A run, BENCHMARKS.md).

use crate::geom::{OdomPose, Pose2, Vec2};
use crate::place::{
    AlignedRun, CandidateCounts, Diagnostics, Direction, FrameId, Match, ObsId, Observation,
    PlaceRecognizer, RejectedCandidate, TravelSchedule,
};
use crate::scan::Scan;
use kiddo::{KdTree, SquaredEuclidean};
use std::collections::{HashMap, VecDeque};

/// The most rings a descriptor can have (the ring key's dimension in the k-d tree).
pub const MAX_RINGS: usize = 32;
/// The most sectors a descriptor can have.
pub const MAX_SECTORS: usize = 720;
/// The most candidates a query may compare.
pub const MAX_CANDIDATES: usize = 1000;
/// Rejected candidates kept for the diagnostics.
const REJECTED_KEPT: usize = 10_000;

/// Settings of the Scan Context baseline, read from a scenario's `[scan_context]` table (every
/// key optional). Distances in metres, shares in 0..1.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ScanContextConfig {
    /// Odometric travel between observations, metres, 0.001 to 10. Default 0.10 (as the paper's
    /// recognizer and ICP).
    pub observation_spacing_m: f64,
    /// Rings of the descriptor (radial bins), 1 to [`MAX_RINGS`]. Default 20 (the paper's).
    pub rings: usize,
    /// Sectors of the descriptor (bearing bins over the full turn), 2 to [`MAX_SECTORS`].
    /// Default 60 (the paper's: 6° each).
    pub sectors: usize,
    /// Radius of the descriptor, metres: farther points are left out. Default 10.0 (the
    /// institute floor's corridors are 2 m wide; the paper's 80 m is for outdoor lidar).
    pub max_radius_m: f64,
    /// Travel over which the cells hit by past scans are kept and carried into the current robot
    /// frame, metres; 0 uses the current scan only. Default 20.0 (on smoke seeds 1-3 at
    /// `max_distance` 0.06: precision 0.72 with 5 m, 0.99 with 10 m, 1.00 with 20 m; one scan's
    /// corridor looks like any other's).
    pub history_m: f64,
    /// Side of the cells that scan endpoints are gathered in (one point per cell), metres.
    /// Default 0.10.
    pub cell_m: f64,
    /// Nearest ring keys compared per observation, 1 to [`MAX_CANDIDATES`]. Default 10 (the
    /// paper's).
    pub candidates: usize,
    /// A candidate matches when its column-shift distance (0 same, 1 nothing alike) is at most
    /// this. Default 0.10, tuned on scenario A (seeds 1-2): the largest of 0.10, 0.12, 0.15, 0.20,
    /// 0.25 whose precision stayed at least 0.95 (RESULTS.md).
    pub max_distance: f64,
    /// A column shift counts only when at least this share of the sectors hold points in both
    /// descriptors, 0..1. Default 0.2.
    pub min_overlap_ratio: f64,
    /// A past observation is a candidate only once it lies at least this much travel behind the
    /// query, metres. Default 20.0; the harness sets it to the evaluation's `min_gap_m` (the
    /// truth's gap), it is not read from `[scan_context]`.
    pub min_gap_m: f64,
}

impl Default for ScanContextConfig {
    fn default() -> Self {
        ScanContextConfig {
            observation_spacing_m: 0.10,
            rings: 20,
            sectors: 60,
            max_radius_m: 10.0,
            history_m: 20.0,
            cell_m: 0.10,
            candidates: 10,
            max_distance: 0.10,
            min_overlap_ratio: 0.2,
            min_gap_m: 20.0,
        }
    }
}

/// A setting of [`ScanContextConfig`] out of its range: the key (as in `[scan_context]`) and
/// what to do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigProblem {
    pub key: &'static str,
    pub message: String,
}

impl std::fmt::Display for ConfigProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.key, self.message)
    }
}

impl ScanContextConfig {
    /// The settings' problems, each naming its key; empty when the settings can run.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut out = Vec::new();
        let mut bad = |key: &'static str, ok: bool, want: String| {
            if !ok {
                out.push(ConfigProblem { key, message: want });
            }
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let d = ScanContextConfig::default();
        bad(
            "observation_spacing_m",
            (0.001..=10.0).contains(&self.observation_spacing_m),
            format!(
                "use a distance from 0.001 to 10 metres (default {})",
                d.observation_spacing_m
            ),
        );
        bad(
            "rings",
            (1..=MAX_RINGS).contains(&self.rings),
            format!(
                "use a whole number from 1 to {MAX_RINGS} (default {})",
                d.rings
            ),
        );
        bad(
            "sectors",
            (2..=MAX_SECTORS).contains(&self.sectors),
            format!(
                "use a whole number from 2 to {MAX_SECTORS} (default {})",
                d.sectors
            ),
        );
        bad(
            "max_radius_m",
            positive(self.max_radius_m),
            format!(
                "use a positive distance, metres (default {})",
                d.max_radius_m
            ),
        );
        bad(
            "history_m",
            self.history_m.is_finite() && (0.0..=100.0).contains(&self.history_m),
            format!(
                "use a distance from 0 to 100 metres (default {})",
                d.history_m
            ),
        );
        bad(
            "cell_m",
            self.cell_m.is_finite() && (0.001..=1.0).contains(&self.cell_m),
            format!("use a size from 0.001 to 1 metre (default {})", d.cell_m),
        );
        bad(
            "candidates",
            (1..=MAX_CANDIDATES).contains(&self.candidates),
            format!(
                "use a whole number from 1 to {MAX_CANDIDATES} (default {})",
                d.candidates
            ),
        );
        bad(
            "max_distance",
            (0.0..=1.0).contains(&self.max_distance),
            format!("use a distance from 0 to 1 (default {})", d.max_distance),
        );
        bad(
            "min_overlap_ratio",
            self.min_overlap_ratio > 0.0 && self.min_overlap_ratio <= 1.0,
            format!(
                "use a share above 0 and at most 1 (default {})",
                d.min_overlap_ratio
            ),
        );
        bad(
            "min_gap_m",
            self.min_gap_m.is_finite() && self.min_gap_m >= 0.0,
            "use a non-negative distance, metres".into(),
        );
        out
    }
}

/// The polar descriptor of one observation.
#[derive(Clone, Debug, PartialEq)]
pub struct Descriptor {
    rings: usize,
    sectors: usize,
    /// Per ring, the occupied sectors and their bin value divided by the sector column's norm.
    by_ring: Vec<Vec<(u16, f32)>>,
    /// Whether each sector column holds a point.
    occupied: Vec<bool>,
    /// Per ring, the share of sectors holding a point (padded with zeros to [`MAX_RINGS`]).
    ring_key: [f64; MAX_RINGS],
}

/// The number of `points` in each bin (sector-major: `sector * rings + ring`) of the polar
/// grid within `max_radius_m`.
fn bin_counts(points: impl IntoIterator<Item = Vec2>, cfg: &ScanContextConfig) -> Vec<u32> {
    let (rings, sectors) = (cfg.rings, cfg.sectors);
    let mut counts = vec![0u32; rings * sectors];
    for p in points {
        let r = p.norm();
        if !r.is_finite() || r >= cfg.max_radius_m {
            continue;
        }
        let ring = ((r / cfg.max_radius_m * rings as f64) as usize).min(rings - 1);
        let a = p.y.atan2(p.x).rem_euclid(std::f64::consts::TAU);
        let sector = ((a / std::f64::consts::TAU * sectors as f64) as usize).min(sectors - 1);
        counts[sector * rings + ring] += 1;
    }
    counts
}

impl Descriptor {
    /// The descriptor of `points` (robot frame, metres) with `cfg`'s rings, sectors and radius.
    pub fn new(points: impl IntoIterator<Item = Vec2>, cfg: &ScanContextConfig) -> Descriptor {
        let (rings, sectors) = (cfg.rings, cfg.sectors);
        let counts = bin_counts(points, cfg);
        let mut by_ring = vec![Vec::new(); rings];
        let mut occupied = vec![false; sectors];
        let mut ring_key = [0.0; MAX_RINGS];
        for (s, column) in counts.chunks(rings).enumerate() {
            let values: Vec<f64> = column.iter().map(|&c| (c as f64).ln_1p()).collect();
            let norm = values.iter().map(|v| v * v).sum::<f64>().sqrt();
            if norm == 0.0 {
                continue;
            }
            occupied[s] = true;
            for (r, v) in values.iter().enumerate() {
                if *v > 0.0 {
                    by_ring[r].push((s as u16, (v / norm) as f32));
                    ring_key[r] += 1.0 / sectors as f64;
                }
            }
        }
        Descriptor {
            rings,
            sectors,
            by_ring,
            occupied,
            ring_key,
        }
    }

    /// The descriptor of `scan` seen from the robot at the odometry origin (no history).
    pub fn of_scan(scan: &Scan, cfg: &ScanContextConfig) -> Descriptor {
        Descriptor::new(scan_points(&Pose2::IDENTITY, scan), cfg)
    }

    /// The ring key: per ring, the share of sectors holding a point.
    pub fn ring_key(&self) -> &[f64] {
        &self.ring_key[..self.rings]
    }

    /// Whether no point fell inside the descriptor.
    pub fn is_empty(&self) -> bool {
        !self.occupied.iter().any(|&o| o)
    }

    /// The column-shift distance to `past` and the shift that gives it: query column
    /// `(s + shift) mod sectors` lies on past column `s`. `None` when no shift has
    /// `min_overlap_ratio` of the sectors occupied in both (or the shapes differ).
    pub fn distance(&self, past: &Descriptor, min_overlap_ratio: f64) -> Option<(f64, usize)> {
        let n = self.sectors;
        if past.sectors != n || past.rings != self.rings {
            return None;
        }
        // cos[i·n + j]: cosine of query column i and past column j.
        let mut cos = vec![0f32; n * n];
        for (q, p) in self.by_ring.iter().zip(&past.by_ring) {
            for &(i, a) in q {
                let row = i as usize * n;
                for &(j, b) in p {
                    cos[row + j as usize] += a * b;
                }
            }
        }
        self.shift_distances(past, &cos, min_overlap_ratio)
    }

    fn shift_distances(
        &self,
        past: &Descriptor,
        cos: &[f32],
        min_overlap_ratio: f64,
    ) -> Option<(f64, usize)> {
        let n = self.sectors;
        let min_overlap = ((min_overlap_ratio * n as f64).ceil() as usize).max(1);
        let mut best: Option<(f64, usize)> = None;
        for k in 0..n {
            let (mut sum, mut both) = (0f64, 0usize);
            for s in 0..n {
                let i = (s + k) % n;
                if self.occupied[i] && past.occupied[s] {
                    both += 1;
                    sum += cos[i * n + s] as f64;
                }
            }
            if both < min_overlap {
                continue;
            }
            let d = (1.0 - sum / both as f64).max(0.0);
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, k));
            }
        }
        best
    }
}

/// The endpoints of `scan`'s hits, in the frame `pose` is given in (the robot at `pose`).
fn scan_points<'a>(pose: &Pose2, scan: &'a Scan) -> impl Iterator<Item = Vec2> + 'a {
    let sensor = pose.compose(&scan.layout.mount);
    (0..scan.ranges_m.len().min(scan.layout.count))
        .filter(|&i| scan.is_hit(i))
        .map(move |i| {
            let (r, a) = (scan.ranges_m[i], scan.layout.beam_angle_rad(i));
            sensor.transform_point(Vec2::new(r * a.cos(), r * a.sin()))
        })
}

/// The heading change of `shift` sectors of `sectors`, radians in (−π, π].
pub fn shift_angle_rad(shift: usize, sectors: usize) -> f64 {
    crate::geom::wrap_angle(shift as f64 / sectors as f64 * std::f64::consts::TAU)
}

/// What the baseline did, for its diagnostics.
#[derive(Clone, Debug, Default, PartialEq)]
struct Counts {
    observations: usize,
    /// Observations whose descriptor held no point (not matched, not indexed).
    empty: usize,
    /// Observations that had candidates in the tree.
    queried: usize,
    /// Candidates compared.
    compared: usize,
    /// Best candidates at most `max_distance` (matches).
    accepted: usize,
    /// Best candidates farther than `max_distance`.
    too_far: usize,
    /// Queries whose candidates shared too few sectors at every shift.
    no_overlap: usize,
}

/// The diagnostics of a run of the baseline.
#[derive(Clone, Debug)]
struct ScanContextDiagnostics {
    counts: Counts,
    max_distance: f64,
    rejected: Vec<RejectedCandidate>,
}

impl Diagnostics for ScanContextDiagnostics {
    fn no_match_reason(&self) -> String {
        let c = &self.counts;
        if c.observations == 0 {
            "no observation was made (no travel)".into()
        } else if c.queried == 0 {
            "no observation had a candidate: none lay min_gap_m of travel behind another with \
             points in its descriptor"
                .into()
        } else {
            format!(
                "every nearest candidate was farther than max_distance = {} ({} of {} queries; \
                 {} had too little sector overlap)",
                self.max_distance, c.too_far, c.queried, c.no_overlap
            )
        }
    }

    fn to_json(&self) -> serde_json::Value {
        let c = &self.counts;
        serde_json::json!({
            "observations": c.observations,
            "empty_descriptors": c.empty,
            "queries": c.queried,
            "candidates_compared": c.compared,
            "accepted": c.accepted,
            "rejected_distance": c.too_far,
            "rejected_overlap": c.no_overlap,
        })
    }

    fn candidates(&self) -> CandidateCounts {
        CandidateCounts::new(self.counts.accepted, self.counts.too_far)
    }

    fn checks(&self) -> Vec<String> {
        vec!["distance".into()]
    }

    fn rejected(&self) -> &[RejectedCandidate] {
        &self.rejected
    }
}

/// The Scan Context baseline as a [`PlaceRecognizer`].
#[derive(Clone)]
pub struct ScanContextRecognizer {
    cfg: ScanContextConfig,
    observations: Vec<Observation>,
    descriptors: Vec<Option<Descriptor>>,
    /// Ring keys of the observations far enough back, deduplicated (kiddo refuses many equal
    /// points): the tree's item is an index into `groups`.
    tree: KdTree<f64, MAX_RINGS>,
    groups: Vec<Vec<ObsId>>,
    group_of_key: HashMap<[u64; MAX_RINGS], usize>,
    /// Observations not yet in the tree, oldest first.
    waiting: VecDeque<ObsId>,
    /// Cells hit by the scans of the last `history_m` of travel (odometry frame), with the
    /// travel at their last hit.
    cells: HashMap<(i64, i64), f64>,
    run: Option<usize>,
    /// Travel and the observation slots on it.
    schedule: TravelSchedule,
    counts: Counts,
    rejected: Vec<RejectedCandidate>,
}

impl ScanContextRecognizer {
    /// A recognizer with `cfg`, or the settings' problems.
    pub fn new(cfg: ScanContextConfig) -> Result<Self, Vec<ConfigProblem>> {
        let problems = cfg.problems();
        if !problems.is_empty() {
            return Err(problems);
        }
        let schedule = TravelSchedule::new(cfg.observation_spacing_m);
        Ok(ScanContextRecognizer {
            cfg,
            observations: Vec::new(),
            descriptors: Vec::new(),
            tree: KdTree::new(),
            groups: Vec::new(),
            group_of_key: HashMap::new(),
            waiting: VecDeque::new(),
            cells: HashMap::new(),
            run: None,
            schedule,
            counts: Counts::default(),
            rejected: Vec::new(),
        })
    }

    pub fn config(&self) -> &ScanContextConfig {
        &self.cfg
    }

    /// Records an observation of frame `frame_id` at `odom`, `travel_m` along the run; its id.
    fn observe(&mut self, frame_id: FrameId, odom: OdomPose, travel_m: f64) -> usize {
        let id =
            super::push_observation(&mut self.observations, self.run, frame_id, odom, travel_m);
        self.counts.observations += 1;
        id
    }

    /// Moves the waiting observations that lie `min_gap_m` behind `travel_m` into the tree.
    fn index_up_to(&mut self, travel_m: f64) {
        while let Some(&id) = self.waiting.front() {
            if self.observations[id].travel_m > travel_m - self.cfg.min_gap_m {
                break;
            }
            self.waiting.pop_front();
            let Some(d) = &self.descriptors[id] else {
                continue;
            };
            let key = d.ring_key;
            let bits = key.map(f64::to_bits);
            match self.group_of_key.get(&bits) {
                Some(&g) => self.groups[g].push(id),
                None => {
                    let g = self.groups.len();
                    self.groups.push(vec![id]);
                    self.group_of_key.insert(bits, g);
                    self.tree.add(&key, g as u64);
                }
            }
        }
    }

    /// The descriptor of the cells of the history seen from `pose` (their order does not
    /// matter: the descriptor counts them).
    fn describe(&self, pose: &Pose2) -> Descriptor {
        let inv = pose.inverse();
        let cell = self.cfg.cell_m;
        let points = self.cells.keys().map(|&(i, j)| {
            inv.transform_point(Vec2::new((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell))
        });
        Descriptor::new(points, &self.cfg)
    }

    /// The match of observation `id` (descriptor `d`), if its nearest candidate is near enough.
    fn query(&mut self, id: ObsId, d: &Descriptor) -> Option<Match> {
        if self.groups.is_empty() {
            return None;
        }
        let k = self.cfg.candidates;
        let mut candidates: Vec<ObsId> = Vec::with_capacity(k);
        for nn in self.tree.nearest_n::<SquaredEuclidean>(&d.ring_key, k) {
            let group = &self.groups[nn.item as usize];
            candidates.extend(group.iter().take(k - candidates.len()));
            if candidates.len() >= k {
                break;
            }
        }
        self.counts.queried += 1;
        self.counts.compared += candidates.len();
        let best = candidates
            .iter()
            .filter_map(|&c| {
                let past = self.descriptors[c].as_ref()?;
                let (dist, shift) = d.distance(past, self.cfg.min_overlap_ratio)?;
                Some((dist, shift, c))
            })
            // Least distance, then the oldest observation: the same whatever the tree's order.
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        let Some((dist, shift, past)) = best else {
            self.counts.no_overlap += 1;
            return None;
        };
        let turned = shift_angle_rad(shift, self.cfg.sectors).abs() > std::f64::consts::FRAC_PI_2;
        let (direction, past_step) = if turned {
            (Direction::Opposite, -1)
        } else {
            (Direction::Same, 1)
        };
        if dist > self.cfg.max_distance {
            self.counts.too_far += 1;
            if self.rejected.len() < REJECTED_KEPT {
                self.rejected
                    .push(RejectedCandidate::new(id, past, direction, 0));
            }
            return None;
        }
        self.counts.accepted += 1;
        let run = AlignedRun::new(id, past, 1, past_step);
        Some(Match::new(vec![run], direction, 1.0 - dist))
    }
}

impl PlaceRecognizer for ScanContextRecognizer {
    fn start_run(&mut self) -> Vec<Match> {
        self.run = Some(self.run.map_or(0, |r| r + 1));
        self.cells.clear();
        self.schedule.start_run();
        Vec::new()
    }

    fn push(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<Match> {
        if self.run.is_none() {
            self.start_run();
        }
        let pose = odom.0;
        let (cell, travel_m) = (self.cfg.cell_m, self.schedule.advance(pose));
        for p in scan_points(&pose, scan) {
            let key = ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
            self.cells.insert(key, travel_m);
        }
        if !self.schedule.take_due() {
            return Vec::new();
        }
        let id = self.observe(frame_id, odom, travel_m);
        let keep_from = travel_m - self.cfg.history_m;
        self.cells.retain(|_, t| *t >= keep_from);
        self.index_up_to(travel_m);
        let d = self.describe(&pose);
        let found = if d.is_empty() {
            self.counts.empty += 1;
            None
        } else {
            self.query(id, &d)
        };
        self.descriptors.push((!d.is_empty()).then_some(d));
        self.waiting.push_back(id);
        found.into_iter().collect()
    }

    fn observations(&self) -> &[Observation] {
        &self.observations
    }

    /// Every match names the newest observation as its query.
    fn query_horizon(&self) -> usize {
        self.observations.len()
    }

    fn name(&self) -> String {
        "scan-context".to_string()
    }

    fn diagnostics(&self) -> Option<Box<dyn Diagnostics>> {
        Some(Box::new(ScanContextDiagnostics {
            counts: self.counts.clone(),
            max_distance: self.cfg.max_distance,
            rejected: self.rejected.clone(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An asymmetric room seen from its middle: points on a few walls at different ranges.
    fn room() -> Vec<Vec2> {
        let mut pts = Vec::new();
        for k in 0..200 {
            let t = k as f64 / 200.0;
            pts.push(Vec2::new(-3.0 + 8.0 * t, 1.2)); // a long wall on the left
            pts.push(Vec2::new(-3.0 + 4.0 * t, -2.5)); // a short one on the right
            pts.push(Vec2::new(5.0, -1.0 + 2.2 * t)); // ahead
            pts.push(Vec2::new(2.0 + t, -0.8 - t)); // a diagonal corner
        }
        pts
    }

    fn rotated(pts: &[Vec2], angle: f64) -> Vec<Vec2> {
        let (s, c) = angle.sin_cos();
        pts.iter()
            .map(|p| Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y))
            .collect()
    }

    #[test]
    fn a_scene_rotated_by_k_sectors_matches_at_shift_k() {
        let cfg = ScanContextConfig::default();
        let past = Descriptor::new(room(), &cfg);
        for k in [0usize, 1, 7, 30, 45, 59] {
            let a = k as f64 * std::f64::consts::TAU / cfg.sectors as f64;
            let q = Descriptor::new(rotated(&room(), a), &cfg);
            // The same but for points a rounding error moved over a sector edge.
            let key_change = q
                .ring_key()
                .iter()
                .zip(past.ring_key())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                key_change <= 2.0 / cfg.sectors as f64,
                "ring key turned with the scene"
            );
            let (d, shift) = q.distance(&past, cfg.min_overlap_ratio).unwrap();
            assert_eq!(shift, k, "rotated by {k} sectors");
            assert!(d < 0.05, "distance {d} at k = {k}");
        }
    }

    #[test]
    fn an_unrelated_scene_is_far() {
        let cfg = ScanContextConfig::default();
        let past = Descriptor::new(room(), &cfg);
        // A round room of radius 4 m.
        let round: Vec<Vec2> = (0..600)
            .map(|k| {
                let a = k as f64 / 600.0 * std::f64::consts::TAU;
                Vec2::new(4.0 * a.cos(), 4.0 * a.sin())
            })
            .collect();
        let (d, _) = Descriptor::new(round, &cfg)
            .distance(&past, cfg.min_overlap_ratio)
            .unwrap();
        assert!(d > cfg.max_distance, "distance {d}");
    }

    #[test]
    fn problems_name_their_keys() {
        let cfg = ScanContextConfig {
            rings: 0,
            max_distance: 1.5,
            ..ScanContextConfig::default()
        };
        let keys: Vec<&str> = cfg.problems().iter().map(|p| p.key).collect();
        assert_eq!(keys, ["rings", "max_distance"]);
        assert!(ScanContextConfig::default().problems().is_empty());
        assert!(ScanContextRecognizer::new(cfg).is_err());
    }

    /// Walls of a corridor 30 m long with bays, pillars and a side room at uneven places, so
    /// every stretch looks different.
    fn corridor() -> Vec<(Vec2, Vec2)> {
        let v = Vec2::new;
        // (start x, length, side): bays 2 m deep into the wall at y = side·1.
        let bays = [
            (2.0, 1.5, 1.0),
            (9.0, 0.6, -1.0),
            (13.5, 2.5, 1.0),
            (21.0, 1.0, -1.0),
            (27.0, 3.0, -1.0),
        ];
        let mut w = vec![(v(-5.0, -1.0), v(-5.0, 1.0)), (v(35.0, -1.0), v(35.0, 1.0))];
        for side in [-1.0, 1.0] {
            let mut x0 = -5.0;
            for &(x, len, _) in bays.iter().filter(|b| b.2 == side) {
                w.push((v(x0, side), v(x, side)));
                w.push((v(x, side), v(x, side * 3.0)));
                w.push((v(x + len, side), v(x + len, side * 3.0)));
                w.push((v(x, side * 3.0), v(x + len, side * 3.0)));
                x0 = x + len;
            }
            w.push((v(x0, side), v(35.0, side)));
        }
        for x in [5.0, 17.0, 24.5] {
            w.push((v(x, 0.6), v(x + 0.3, 0.6)));
        }
        w
    }

    /// A 360° scan of `walls` from `pose` (one beam a degree, 30 m range).
    fn scan_at(walls: &[(Vec2, Vec2)], pose: Pose2) -> Scan {
        let layout =
            crate::scan::BeamLayout::centered(360, std::f64::consts::TAU, 30.0, Pose2::IDENTITY);
        let ranges_m = (0..360)
            .map(|i| {
                let a = pose.theta + layout.beam_angle_rad(i);
                let (dx, dy) = (a.cos(), a.sin());
                walls
                    .iter()
                    .filter_map(|(p, q)| {
                        // pose + t·d = p + u·(q − p)
                        let (ex, ey) = (q.x - p.x, q.y - p.y);
                        let den = dx * ey - dy * ex;
                        if den.abs() < 1e-12 {
                            return None;
                        }
                        let (wx, wy) = (p.x - pose.x, p.y - pose.y);
                        let t = (wx * ey - wy * ex) / den;
                        let u = (wx * dy - wy * dx) / den;
                        (t > 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
                    })
                    .fold(30.0, f64::min)
            })
            .collect();
        Scan {
            ranges_m,
            layout,
            time_s: 0.0,
        }
    }

    /// Drives the corridor once forward, then forward again (or backward); returns the matches of
    /// the second pass as (query x, past x, direction). Driven backward, the second pass has its
    /// revisit 20 m of travel behind from x = 20 m on (the runs follow each other at x = 30 m).
    fn second_pass(backward: bool) -> Vec<(f64, f64, Direction)> {
        let walls = corridor();
        // Exact 360° scans, one scan and fine cells: a true revisit is within 0.05, the corridor's
        // look-alikes beyond 0.07.
        let mut rec = ScanContextRecognizer::new(ScanContextConfig {
            history_m: 0.0,
            cell_m: 0.001,
            max_distance: 0.06,
            ..ScanContextConfig::default()
        })
        .unwrap();
        let mut found = Vec::new();
        let mut frame = 0;
        for pass in 0..2 {
            found.extend(rec.start_run());
            for k in 0..=300 {
                let x = k as f64 * 0.1;
                let pose = if pass == 1 && backward {
                    Pose2::new(30.0 - x, 0.0, std::f64::consts::PI)
                } else {
                    Pose2::new(x, 0.0, 0.0)
                };
                found.extend(rec.push(frame, OdomPose(pose), &scan_at(&walls, pose)));
                frame += 1;
            }
        }
        let obs = rec.observations();
        let x_of = |id: ObsId| obs[id].odom_pose.0.x;
        assert!(
            found
                .iter()
                .flat_map(|m| m.pairs())
                .all(|(q, _)| obs[q].run == 1),
            "a match within the first pass"
        );
        found
            .iter()
            .flat_map(|m| m.pairs().map(|(q, p)| (x_of(q), x_of(p), m.direction)))
            .collect()
    }

    #[test]
    fn finds_a_revisit_driven_the_same_way() {
        let pairs = second_pass(false);
        assert!(
            pairs.len() > 200,
            "{} of 301 observations matched",
            pairs.len()
        );
        for (q, p, dir) in &pairs {
            assert_eq!(*dir, Direction::Same);
            assert!((q - p).abs() <= 1.0, "{q} paired with {p}");
        }
    }

    #[test]
    fn finds_a_revisit_driven_the_other_way() {
        let pairs = second_pass(true);
        assert!(
            pairs.len() > 200,
            "{} of 301 observations matched",
            pairs.len()
        );
        for (q, p, dir) in &pairs {
            assert_eq!(*dir, Direction::Opposite, "{q} paired with {p}");
            assert!((q - p).abs() <= 1.0, "{q} paired with {p}");
        }
    }
}
