//! Earlier observations near a query, found without looking at each of them: the index behind
//! revisits, visit recall and possible pairs ([`super::metrics`], [`super::pair_recall`]).
//!
//! Those figures ask, for every observation in creation order, about the observations made at
//! least `min_gap_m` of true travel before it that lie within a radius and face a given way.
//! Scanning every earlier observation in the grid cells around it made scoring quadratic in the
//! passes over a place (a log of 287 copies of one path ran for more than an hour). Here the
//! truth sites sit in a static k-d tree over position and heading; a site is *activated* once the
//! travel gap to the current query is reached ([`sweep`]; observations are in creation order, so
//! their true travel never decreases and the activated sites are always a prefix), and every node
//! counts its active sites. A query adds a whole node when every site in it passes the test,
//! skips it when none can, and tests sites one by one only in nodes that straddle the edge.
//!
//! The answers are exactly those of testing every site with the figures' own predicate
//! ([`Site::agrees_with`]): a node's distance bounds are computed with the same floating-point
//! operations as a site's distance, which are monotone, so a node said to be all inside (or all
//! outside) holds no site the predicate would judge otherwise; headings are decided per node
//! only with a margin of 1e-9 rad, and per site otherwise.

use super::pair_recall::Facing;
use crate::geom::wrap_angle;

/// The truth of one observation, as the scores use it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Site {
    pub x: f64,
    pub y: f64,
    pub theta: f64,
    /// True travel up to the observation's frame, metres.
    pub travel_m: f64,
    /// Global lap index (`GroundTruth::laps`).
    pub lap: usize,
}

impl Site {
    /// Whether earlier site `p` is within `r2` (squared radius) of `self` and faces as
    /// `facing` says: the figures' own test, operand for operand.
    pub fn agrees_with(&self, p: &Site, r2: f64, facing: Facing, tol_rad: f64) -> bool {
        (self.x - p.x).powi(2) + (self.y - p.y).powi(2) <= r2
            && facing.agrees(self.theta, p.theta, tol_rad)
    }
}

/// Sites in a leaf at most (at most 32: a leaf's sites are flagged in a `u32`).
const LEAF: usize = 16;
const _: () = assert!(LEAF <= 32);
/// Headings are classified per node only this far from the tolerance, radians.
const HEADING_MARGIN_RAD: f64 = 1e-9;
/// Marks a leaf in `Node::children`.
const NO_CHILD: u32 = u32::MAX;

/// A box of sites: position and wrapped-heading bounds, laps, its slice of `order`.
#[derive(Clone, Copy, Debug)]
struct Node {
    x: [f64; 2],
    y: [f64; 2],
    theta: [f64; 2],
    lap: [usize; 2],
    start: u32,
    end: u32,
    children: [u32; 2],
}

/// How much of a node a query takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cover {
    None,
    Part,
    All,
}

/// A query: the site asked about, the squared radius, the facing and heading tolerance.
#[derive(Clone, Copy, Debug)]
pub struct Query<'q> {
    pub site: &'q Site,
    pub r2: f64,
    pub facing: Facing,
    pub tol_rad: f64,
}

/// The sites of one sweep (see the module doc), with the active ones counted per node.
pub struct SiteTree<'s> {
    sites: &'s [Site],
    /// Site indices in tree order (each node holds a contiguous slice).
    order: Vec<u32>,
    /// The sites in tree order, so that a leaf's sites are read from consecutive memory.
    placed: Vec<Site>,
    nodes: Vec<Node>,
    parent: Vec<u32>,
    leaf_of: Vec<u32>,
    active: Vec<u32>,
    /// Sites `[0, frontier)` are active.
    frontier: usize,
}

impl<'s> SiteTree<'s> {
    /// The tree of `sites` (creation order), none active.
    pub fn new(sites: &'s [Site]) -> Self {
        let mut t = SiteTree {
            sites,
            order: (0..sites.len() as u32).collect(),
            placed: Vec::new(),
            nodes: Vec::new(),
            parent: Vec::new(),
            leaf_of: vec![0; sites.len()],
            active: Vec::new(),
            frontier: 0,
        };
        if !sites.is_empty() {
            t.build(0, sites.len(), NO_CHILD);
        }
        t.active = vec![0; t.nodes.len()];
        t.placed = t.order.iter().map(|&s| sites[s as usize]).collect();
        t
    }

    /// Builds the node of `order[start..end]` under `parent`; returns its index.
    fn build(&mut self, start: usize, end: usize, parent: u32) -> u32 {
        let id = self.nodes.len() as u32;
        let node = self.bounds(start, end);
        self.nodes.push(node);
        self.parent.push(parent);
        if end - start <= LEAF {
            for &s in &self.order[start..end] {
                self.leaf_of[s as usize] = id;
            }
            return id;
        }
        let extent = [
            node.x[1] - node.x[0],
            node.y[1] - node.y[0],
            node.theta[1] - node.theta[0],
        ];
        let axis = (0..3)
            .max_by(|&a, &b| extent[a].total_cmp(&extent[b]))
            .unwrap_or(0);
        let sites = self.sites;
        let key = |s: &u32| {
            let p = &sites[*s as usize];
            [p.x, p.y, wrap_angle(p.theta)][axis]
        };
        let mid = start + (end - start) / 2;
        self.order[start..end]
            .select_nth_unstable_by(mid - start, |a, b| key(a).total_cmp(&key(b)));
        let left = self.build(start, mid, id);
        let right = self.build(mid, end, id);
        self.nodes[id as usize].children = [left, right];
        id
    }

    /// The bounds of `order[start..end]`, as a leaf.
    fn bounds(&self, start: usize, end: usize) -> Node {
        let mut n = Node {
            x: [f64::INFINITY, f64::NEG_INFINITY],
            y: [f64::INFINITY, f64::NEG_INFINITY],
            theta: [f64::INFINITY, f64::NEG_INFINITY],
            lap: [usize::MAX, 0],
            start: start as u32,
            end: end as u32,
            children: [NO_CHILD; 2],
        };
        for &s in &self.order[start..end] {
            let p = &self.sites[s as usize];
            let t = wrap_angle(p.theta);
            n.x = [n.x[0].min(p.x), n.x[1].max(p.x)];
            n.y = [n.y[0].min(p.y), n.y[1].max(p.y)];
            n.theta = [n.theta[0].min(t), n.theta[1].max(t)];
            n.lap = [n.lap[0].min(p.lap), n.lap[1].max(p.lap)];
        }
        n
    }

    /// Activates sites up to (not including) `to`.
    fn activate_to(&mut self, to: usize) {
        while self.frontier < to {
            let mut n = self.leaf_of[self.frontier];
            while n != NO_CHILD {
                self.active[n as usize] += 1;
                n = self.parent[n as usize];
            }
            self.frontier += 1;
        }
    }

    /// How much of node `n` the query `q` takes.
    fn cover(&self, n: &Node, q: &Query) -> Cover {
        cover(n.x, n.y, n.theta, q)
    }

    /// Active sites that `q` takes; with `first`, stops at the first (returns 0 or 1).
    pub fn count(&self, q: &Query, first: bool) -> u64 {
        let mut total = 0u64;
        let mut stack = vec![0u32];
        while let Some(id) = stack.pop() {
            let Some(node) = self.live(id) else { continue };
            match self.cover(node, q) {
                Cover::None => continue,
                Cover::All => total += u64::from(self.active[id as usize]),
                Cover::Part if node.children[0] == NO_CHILD => {
                    total += self
                        .leaf_sites(node)
                        .filter(|p| q.site.agrees_with(p, q.r2, q.facing, q.tol_rad))
                        .count() as u64;
                }
                Cover::Part => stack.extend(node.children),
            }
            if first && total > 0 {
                return 1;
            }
        }
        total
    }

    /// Adds to `laps` the lap of every active site `q` takes (nodes of one lap already in
    /// `laps` are skipped). Visit recall finds laps with `eval::lap_grid`; this is the
    /// reference it is tested against ([`super::evaluate_by_site_tree`]).
    pub fn laps(&self, q: &Query, laps: &mut LapSet) {
        let mut stack = vec![0u32];
        while let Some(id) = stack.pop() {
            let Some(node) = self.live(id) else { continue };
            if node.lap[0] == node.lap[1] && laps.contains(node.lap[0]) {
                continue;
            }
            match self.cover(node, q) {
                Cover::None => {}
                Cover::All if node.lap[0] == node.lap[1] => laps.insert(node.lap[0]),
                _ if node.children[0] == NO_CHILD => {
                    for p in self.leaf_sites(node) {
                        if q.site.agrees_with(p, q.r2, q.facing, q.tol_rad) {
                            laps.insert(p.lap);
                        }
                    }
                }
                _ => stack.extend(node.children),
            }
        }
    }

    /// Active sites within `r2` of `site` facing each way of `facings` (tolerance `tol_rad`):
    /// [`Self::count`] of each facing's query, the tree walked once for all (a node's position
    /// bounds are tested once, its headings per facing still undecided there).
    pub fn count_facings<const N: usize>(
        &self,
        site: &Site,
        r2: f64,
        facings: [Facing; N],
        tol_rad: f64,
    ) -> [u64; N] {
        let all = facings_mask::<N>();
        let mut total = [0u64; N];
        // (node, the facings whose heading test the node's ancestors left undecided)
        let mut stack = vec![(0u32, all)];
        while let Some((id, mut open)) = stack.pop() {
            let Some(node) = self.live(id) else { continue };
            let Some(inside) = position_cover(node.x, node.y, site, r2) else {
                continue;
            };
            for (f, &facing) in facings.iter().enumerate() {
                if open & (1 << f) == 0 {
                    continue;
                }
                // The decision of `cover` for this facing's query, operand for operand.
                match heading_cover(site.theta, node.theta, facing, tol_rad) {
                    Cover::None => open &= !(1 << f),
                    Cover::All if inside => {
                        total[f] += u64::from(self.active[id as usize]);
                        open &= !(1 << f);
                    }
                    _ => {}
                }
            }
            if open == 0 {
                continue;
            }
            if node.children[0] == NO_CHILD {
                for p in self.leaf_sites(node) {
                    if (site.x - p.x).powi(2) + (site.y - p.y).powi(2) > r2 {
                        continue;
                    }
                    for (f, &facing) in facings.iter().enumerate() {
                        if open & (1 << f) != 0 && facing.agrees(site.theta, p.theta, tol_rad) {
                            total[f] += 1;
                        }
                    }
                }
            } else {
                stack.extend(node.children.map(|c| (c, open)));
            }
        }
        total
    }

    /// Pairs of sites (every site, active or not) within `r2` of each other and facing each
    /// way of `facings`, each pair once and tested as (later, earlier) in creation order, as a
    /// sweep's query tests it. Counted over pairs of nodes (a dual-tree walk): a pair of boxes
    /// wholly within the radius and facing so adds the product of their sizes, one wholly out
    /// adds nothing, and only pairs of leaves on the edge test their sites pair by pair. The
    /// decisions per pair of boxes are those of `position_cover` and `heading_cover`
    /// widened to a box at each end (monotone operations, the same heading margin).
    pub fn count_pairs_facings<const N: usize>(
        &self,
        r2: f64,
        facings: [Facing; N],
        tol_rad: f64,
    ) -> [u64; N] {
        let all = facings_mask::<N>();
        let mut total = [0u64; N];
        if self.nodes.is_empty() {
            return total;
        }
        let mut stack = vec![(0u32, 0u32, all)];
        while let Some((a, b, mut open)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            let Some(inside) = boxes_cover(na, nb, r2) else {
                continue;
            };
            let size = |n: &Node| u64::from(n.end - n.start);
            let pairs = if a == b {
                size(na) * (size(na) - 1) / 2
            } else {
                size(na) * size(nb)
            };
            // Heading widened by b's half-range: every heading pair's difference is within.
            let half_b = (nb.theta[1] - nb.theta[0]) / 2.0;
            let mid_b = nb.theta[0] + half_b;
            let widened = [na.theta[0] - half_b, na.theta[1] + half_b];
            for (f, &facing) in facings.iter().enumerate() {
                if open & (1 << f) == 0 {
                    continue;
                }
                match heading_cover(mid_b, widened, facing, tol_rad) {
                    Cover::None => open &= !(1 << f),
                    Cover::All if inside => {
                        total[f] += pairs;
                        open &= !(1 << f);
                    }
                    _ => {}
                }
            }
            if open == 0 {
                continue;
            }
            let (leaf_a, leaf_b) = (na.children[0] == NO_CHILD, nb.children[0] == NO_CHILD);
            if leaf_a && leaf_b {
                self.count_leaf_pairs((na, nb, a == b), r2, facings, tol_rad, open, &mut total);
            } else if a == b {
                let [l, r] = na.children;
                stack.extend([(l, l, open), (l, r, open), (r, r, open)]);
            } else if leaf_a || (!leaf_b && size(nb) > size(na)) {
                stack.extend(nb.children.map(|c| (a, c, open)));
            } else {
                stack.extend(na.children.map(|c| (c, b, open)));
            }
        }
        total
    }

    /// [`Self::count_pairs_facings`] in two leaves (the same leaf when `same`), site by site,
    /// for the facings `open` leaves undecided. Each site of the first leaf is first tested
    /// against the second's box, as a query is ([`position_cover`], [`heading_cover`]): the
    /// facings it decides for the whole box need no test per pair.
    fn count_leaf_pairs<const N: usize>(
        &self,
        (na, nb, same): (&Node, &Node, bool),
        r2: f64,
        facings: [Facing; N],
        tol_rad: f64,
        open: u8,
        total: &mut [u64; N],
    ) {
        let (a0, a1) = (na.start as usize, na.end as usize);
        let (b0, b1) = (nb.start as usize, nb.end as usize);
        for i in a0..a1 {
            let from = if same { i + 1 } else { b0 };
            if from >= b1 {
                continue;
            }
            let a = &self.placed[i];
            let Some(inside) = position_cover(nb.x, nb.y, a, r2) else {
                continue;
            };
            // Per facing still open: whether every heading of the box agrees (only the
            // positions are left to test), or only some do.
            let (mut by_position, mut by_pair) = (0u8, 0u8);
            for (f, &facing) in facings.iter().enumerate() {
                if open & (1 << f) == 0 {
                    continue;
                }
                match heading_cover(a.theta, nb.theta, facing, tol_rad) {
                    Cover::None => {}
                    Cover::All if inside => total[f] += (b1 - from) as u64,
                    Cover::All => by_position |= 1 << f,
                    Cover::Part => by_pair |= 1 << f,
                }
            }
            if by_position | by_pair == 0 {
                continue;
            }
            // The sites within the radius, without a branch per site (the squared distance is
            // the pair test's: a difference's square does not depend on its sign).
            let mut within = 0u32;
            for (k, b) in self.placed[from..b1].iter().enumerate() {
                let d2 = (a.x - b.x).powi(2) + (a.y - b.y).powi(2);
                within |= u32::from(d2 <= r2) << k;
            }
            for (f, n) in total.iter_mut().enumerate() {
                if by_position & (1 << f) != 0 {
                    *n += u64::from(within.count_ones());
                }
            }
            if by_pair == 0 {
                continue;
            }
            let mut bits = within;
            while bits != 0 {
                let j = from + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (later, earlier) = if self.order[i] > self.order[j] {
                    (a, &self.placed[j])
                } else {
                    (&self.placed[j], a)
                };
                for (f, &facing) in facings.iter().enumerate() {
                    if by_pair & (1 << f) != 0 && facing.agrees(later.theta, earlier.theta, tol_rad)
                    {
                        total[f] += 1;
                    }
                }
            }
        }
    }

    /// The sites, in creation order.
    pub fn sites(&self) -> &'s [Site] {
        self.sites
    }

    /// Site `k` (creation order).
    pub fn site(&self, k: usize) -> Site {
        self.sites[k]
    }

    /// Deactivates every site: the tree is ready for another sweep ([`sweep_tree`]).
    pub fn reset(&mut self) {
        self.active.fill(0);
        self.frontier = 0;
    }

    /// Node `id` when it holds an active site.
    fn live(&self, id: u32) -> Option<&Node> {
        (self.active.get(id as usize).copied().unwrap_or(0) > 0).then(|| &self.nodes[id as usize])
    }

    /// The active sites of a leaf.
    fn leaf_sites<'a>(&'a self, node: &Node) -> impl Iterator<Item = &'a Site> + 'a {
        let frontier = self.frontier;
        let (start, end) = (node.start as usize, node.end as usize);
        self.order[start..end]
            .iter()
            .zip(&self.placed[start..end])
            .filter(move |&(&s, _)| (s as usize) < frontier)
            .map(|(_, p)| p)
    }
}

/// How much of a box of sites (position bounds `x`, `y`, wrapped-heading bounds `theta`) the
/// query `q` takes.
pub(super) fn cover(x: [f64; 2], y: [f64; 2], theta: [f64; 2], q: &Query) -> Cover {
    let s = q.site;
    let Some(inside) = position_cover(x, y, s, q.r2) else {
        return Cover::None;
    };
    joined_cover(inside, heading_cover(s.theta, theta, q.facing, q.tol_rad))
}

/// How much of a box a query takes, from whether its positions are all `inside` the radius
/// (none outside) and how many of its headings agree.
pub(super) fn joined_cover(inside: bool, heading: Cover) -> Cover {
    match (inside, heading) {
        (_, Cover::None) => Cover::None,
        (true, Cover::All) => Cover::All,
        _ => Cover::Part,
    }
}

/// Whether a box of sites (position bounds `x`, `y`) lies within `r2` (squared) of `s`:
/// `None` when wholly outside, `Some(true)` wholly inside, `Some(false)` in part. The distance
/// bounds use the site test's own operations (see the module doc).
pub(super) fn position_cover(x: [f64; 2], y: [f64; 2], s: &Site, r2: f64) -> Option<bool> {
    let far = |v: f64, b: [f64; 2]| (v - b[0]).powi(2).max((v - b[1]).powi(2));
    let near = |v: f64, b: [f64; 2]| {
        let (lo, hi) = (v - b[1], v - b[0]);
        if lo <= 0.0 && hi >= 0.0 {
            0.0
        } else {
            lo.powi(2).min(hi.powi(2))
        }
    };
    if near(s.x, x) + near(s.y, y) > r2 {
        return None;
    }
    Some(far(s.x, x) + far(s.y, y) <= r2)
}

/// Whether every pair of sites of two boxes lies within `r2` (squared) of each other: `None`
/// when no pair can, `Some(true)` when every pair does, `Some(false)` in part. The bounds use
/// the site test's own operations, which are monotone (see the module doc).
fn boxes_cover(a: &Node, b: &Node, r2: f64) -> Option<bool> {
    let far = |p: [f64; 2], q: [f64; 2]| (p[1] - q[0]).powi(2).max((q[1] - p[0]).powi(2));
    let near = |p: [f64; 2], q: [f64; 2]| {
        if q[0] > p[1] {
            (q[0] - p[1]).powi(2)
        } else if p[0] > q[1] {
            (p[0] - q[1]).powi(2)
        } else {
            0.0
        }
    };
    if near(a.x, b.x) + near(a.y, b.y) > r2 {
        return None;
    }
    Some(far(a.x, b.x) + far(a.y, b.y) <= r2)
}

/// How many headings in the wrapped range `range` agree with `theta` as `facing` says.
pub(super) fn heading_cover(theta: f64, range: [f64; 2], facing: Facing, tol_rad: f64) -> Cover {
    let half = (range[1] - range[0]) / 2.0;
    let mid = range[0] + half;
    let one = |offset: f64| {
        let c = wrap_angle(theta - mid - offset).abs();
        if c + half + HEADING_MARGIN_RAD <= tol_rad {
            Cover::All
        } else if c - half - HEADING_MARGIN_RAD > tol_rad {
            Cover::None
        } else {
            Cover::Part
        }
    };
    let (same, opposite) = (|| one(0.0), || one(std::f64::consts::PI));
    match facing {
        Facing::Same => same(),
        Facing::Opposite => opposite(),
        Facing::Either => match (same(), opposite()) {
            (Cover::All, _) | (_, Cover::All) => Cover::All,
            (Cover::None, Cover::None) => Cover::None,
            _ => Cover::Part,
        },
    }
}

/// A set of laps, emptied in O(1) between queries.
#[derive(Clone, Debug, Default)]
pub struct LapSet {
    /// Per lap: the generation it was last inserted in.
    stamp: Vec<u64>,
    generation: u64,
    /// The laps inserted since the last clear, in insertion order.
    pub list: Vec<usize>,
}

impl LapSet {
    /// Empties the set.
    pub fn clear(&mut self) {
        self.generation += 1;
        self.list.clear();
    }

    pub fn contains(&self, lap: usize) -> bool {
        self.stamp.get(lap) == Some(&(self.generation + 1))
    }

    pub fn insert(&mut self, lap: usize) {
        if self.stamp.len() <= lap {
            self.stamp.resize(lap + 1, 0);
        }
        if self.stamp[lap] != self.generation + 1 {
            self.stamp[lap] = self.generation + 1;
            self.list.push(lap);
        }
    }
}

/// Calls `visit(k, tree)` for every site `k` in order, with exactly the sites before it that
/// are at least `min_gap_m` of true travel earlier active in `tree` (see the module doc).
pub fn sweep(sites: &[Site], min_gap_m: f64, visit: impl FnMut(usize, &SiteTree)) {
    sweep_tree(&mut SiteTree::new(sites), min_gap_m, visit);
}

/// [`sweep`] in a tree already built over the sites (reset first): one build serves every
/// sweep over the same sites.
pub fn sweep_tree(tree: &mut SiteTree, min_gap_m: f64, mut visit: impl FnMut(usize, &SiteTree)) {
    tree.reset();
    let sites = tree.sites;
    let mut ready = 0;
    for (k, s) in sites.iter().enumerate() {
        while ready < k && s.travel_m - sites[ready].travel_m >= min_gap_m {
            ready += 1;
        }
        tree.activate_to(ready);
        visit(k, &*tree);
    }
}

/// A bit per facing of `N` queried at once (at most 8, the width of the masks the walks carry).
fn facings_mask<const N: usize>() -> u8 {
    assert!(N <= 8, "at most 8 facings at once");
    ((1u16 << N) - 1) as u8
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Sites on several noisy passes over one path, some driven the other way, on 3 laps.
    pub(in crate::eval) fn passes(seed: u64) -> Vec<Site> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut out = Vec::new();
        let mut travel = 0.0;
        for pass in 0..12 {
            let back = pass % 3 == 2;
            for k in 0..200 {
                let u = if back { 200 - k } else { k } as f64 * 0.1;
                let heading = if back { std::f64::consts::PI } else { 0.0 };
                out.push(Site {
                    x: u + rng.random_range(-0.05..0.05),
                    y: (u * 0.3).sin() + rng.random_range(-0.05..0.05),
                    theta: heading
                        + rng.random_range(-0.9..0.9)
                        + 2.0 * std::f64::consts::PI * (pass % 2) as f64,
                    travel_m: travel,
                    lap: pass / 4,
                });
                travel += 0.1;
            }
        }
        out
    }

    /// The brute force: every earlier site beyond the gap, tested one by one.
    fn brute(sites: &[Site], k: usize, gap: f64, r: f64, facing: Facing) -> Vec<usize> {
        (0..k)
            .filter(|&j| sites[k].travel_m - sites[j].travel_m >= gap)
            .filter(|&j| sites[k].agrees_with(&sites[j], r * r, facing, 0.7))
            .collect()
    }

    /// Counts, existence and laps equal the brute force for every site, radius and facing.
    #[test]
    fn answers_equal_testing_every_earlier_site() {
        let sites = passes(3);
        for r in [0.05, 0.5, 1.0, 3.0] {
            for facing in [Facing::Same, Facing::Opposite, Facing::Either] {
                sweep(&sites, 2.0, |k, tree| {
                    let want = brute(&sites, k, 2.0, r, facing);
                    let q = Query {
                        site: &sites[k],
                        r2: r * r,
                        facing,
                        tol_rad: 0.7,
                    };
                    assert_eq!(
                        tree.count(&q, false),
                        want.len() as u64,
                        "{k} {r} {facing:?}"
                    );
                    assert_eq!(tree.count(&q, true), u64::from(!want.is_empty()));
                    let mut laps: Vec<usize> = want.iter().map(|&j| sites[j].lap).collect();
                    laps.dedup();
                    let mut set = LapSet::default();
                    set.insert(99);
                    set.clear();
                    tree.laps(&q, &mut set);
                    let mut found = set.list.clone();
                    found.sort_unstable();
                    assert_eq!(found, laps, "{k} {r} {facing:?}");
                });
            }
        }
    }

    /// Counted for every facing at once, in one tree swept again for each radius, the counts
    /// equal the brute force's.
    #[test]
    fn facings_at_once_in_a_reused_tree_equal_testing_every_earlier_site() {
        let sites = passes(4);
        let facings = [Facing::Same, Facing::Opposite, Facing::Either];
        let mut tree = SiteTree::new(&sites);
        for r in [3.0, 0.05, 1.0] {
            let mut sum = [0u64; 3];
            sweep_tree(&mut tree, 2.0, |k, tree| {
                let got = tree.count_facings(&sites[k], r * r, facings, 0.7);
                let want = facings.map(|f| brute(&sites, k, 2.0, r, f).len() as u64);
                assert_eq!(got, want, "{k} {r}");
                sum.iter_mut().zip(got).for_each(|(s, g)| *s += g);
            });
            assert!(sum.iter().all(|&n| n > 0) || r < 0.1, "{r} {sum:?}");
        }
    }

    #[test]
    fn no_sites_no_answers() {
        sweep(&[], 1.0, |_, _| panic!("no site to visit"));
        let one = [Site {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
            travel_m: 0.0,
            lap: 0,
        }];
        sweep(&one, 0.0, |k, tree| {
            let q = Query {
                site: &one[k],
                r2: 1.0,
                facing: Facing::Either,
                tol_rad: 1.0,
            };
            assert_eq!(
                tree.count(&q, false),
                0,
                "a site is not its own earlier site"
            );
        });
    }
}
