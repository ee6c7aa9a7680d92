//! The earlier laps that pass near each observation, found lap by lap: the index behind visit
//! recall ([`super::tally`]).
//!
//! Visit recall asks, for every observation in creation order, which earlier laps hold an
//! observation at least `min_gap_m` of true travel before it, within a radius and facing a given
//! way. The answer is a set of laps, so once one site of a lap agrees, the rest of that lap need
//! not be looked at. The k-d tree of [`super::site_tree`] finds the sites, not the laps, and
//! grew with the square of the laps on a long run (a thousand laps of one loop). Here the
//! active sites sit in square cells at least the radius wide, each cut into 4 × 4 sub-cells
//! that keep the bounds of their sites and their laps as a bit set ([`Laps`]). A query looks at
//! the 3 × 3 cells around it: first every sub-cell it takes wholly gives all its laps at once;
//! then, in the sub-cells it takes in part whose laps are not all found yet, per *run* of a lap
//! not yet found (a sub-cell's sites of one lap, in creation order), first at the lap's
//! *witness* (the site of that lap that last agreed with a query: consecutive observations are
//! close, so it usually agrees again), then at the run's bounds and only then at the run's
//! sites one by one, stopping at the first that agrees. On one loop every earlier lap passes
//! through a sub-cell wholly within the radius, so the work per query is a few bit-set words
//! per sub-cell, and the answer is counted (a popcount), not listed.
//!
//! The answers are exactly those of testing every active site with the figures' own predicate
//! ([`Site::agrees_with`]): a site within the radius lies in one of the 3 × 3 cells (the cells
//! are 1 % wider than the radius, far more than the rounding of a cell index); a lap is taken
//! from a witness or a site that passes that predicate, or from a run or sub-cell whose bounds
//! are decided as the k-d tree decides a node's (the same operations, [`super::site_tree`]).

use super::pair_recall::Facing;
use super::site_tree::{Cover, Query, Site, cover, heading_cover, joined_cover, position_cover};
use crate::geom::wrap_angle;
use foldhash::HashMap;
use std::f64::consts::PI;

/// Sub-cells per side of a cell: a sub-cell is a quarter of the radius wide, so one within
/// about 0.64 radii of a query lies wholly within the radius and all its laps are taken at once.
const SUBS: i64 = 4;

/// A set of laps, one bit each, from word `first` (64 laps a word) on.
#[derive(Clone, Debug, Default)]
pub struct Laps {
    first: usize,
    words: Vec<u64>,
}

impl Laps {
    /// Whether `lap` is in the set.
    pub fn contains(&self, lap: usize) -> bool {
        let w = (lap / 64).wrapping_sub(self.first);
        self.words.get(w).is_some_and(|b| b >> (lap % 64) & 1 == 1)
    }

    /// Adds `lap`.
    pub fn insert(&mut self, lap: usize) {
        let w = lap / 64;
        if self.words.is_empty() {
            self.first = w;
        } else if w < self.first {
            let more = self.first - w;
            self.words.splice(0..0, std::iter::repeat_n(0, more));
            self.first = w;
        }
        let at = w - self.first;
        if self.words.len() <= at {
            self.words.resize(at + 1, 0);
        }
        self.words[at] |= 1 << (lap % 64);
    }

    /// Laps in the set.
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    /// Laps in this set or `other`.
    pub fn union_len(&self, other: &Laps) -> usize {
        let (a, b) = (self.first, other.first);
        let end = (a + self.words.len()).max(b + other.words.len());
        let word = |l: &Laps, w: usize| {
            w.checked_sub(l.first)
                .and_then(|i| l.words.get(i))
                .copied()
                .unwrap_or(0)
        };
        (a.min(b)..end)
            .map(|w| (word(self, w) | word(other, w)).count_ones() as usize)
            .sum()
    }

    /// The laps in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(move |(i, &w)| {
            let base = (self.first + i) * 64;
            (0..64)
                .filter(move |b| w >> b & 1 == 1)
                .map(move |b| base + b)
        })
    }

    /// The set of `laps`, in the room of `reuse`.
    pub fn of(laps: &[usize], mut reuse: Laps) -> Laps {
        reuse.words.clear();
        laps.iter().for_each(|&l| reuse.insert(l));
        reuse
    }

    /// Empties the set, keeping its room.
    fn clear(&mut self) {
        self.words.fill(0);
    }

    /// Room for laps `0..n` in a set that starts at lap 0.
    fn reserve_laps(&mut self, n: usize) {
        debug_assert_eq!(self.first, 0);
        if self.words.len() < n.div_ceil(64) {
            self.words.resize(n.div_ceil(64), 0);
        }
    }

    /// Adds every lap of `other` (this set starts at lap 0 and has room for them).
    fn add_all(&mut self, other: &Laps) {
        let to = &mut self.words[other.first..other.first + other.words.len()];
        to.iter_mut().zip(&other.words).for_each(|(a, b)| *a |= b);
    }

    /// Whether every lap of `other` is in this set (which starts at lap 0).
    fn holds_all(&self, other: &Laps) -> bool {
        let from = &self.words[other.first..other.first + other.words.len()];
        from.iter().zip(&other.words).all(|(a, b)| b & !a == 0)
    }
}

/// The bounds of a box of sites: positions, wrapped headings, and the headings turned by π
/// and wrapped (narrow where the first straddle ±π).
#[derive(Clone, Copy)]
struct Bounds {
    x: [f64; 2],
    y: [f64; 2],
    theta: [f64; 2],
    turned: [f64; 2],
}

impl Bounds {
    fn of(s: &Site) -> Self {
        let (t, u) = (wrap_angle(s.theta), wrap_angle(s.theta - PI));
        Bounds {
            x: [s.x; 2],
            y: [s.y; 2],
            theta: [t; 2],
            turned: [u; 2],
        }
    }

    fn add(&mut self, s: &Site) {
        let b = Bounds::of(s);
        let join = |a: [f64; 2], b: [f64; 2]| [a[0].min(b[0]), a[1].max(b[1])];
        self.x = join(self.x, b.x);
        self.y = join(self.y, b.y);
        self.theta = join(self.theta, b.theta);
        self.turned = join(self.turned, b.turned);
    }

    /// The headings' bounds: the narrower of the two ranges (the turned range, turned back,
    /// holds the same headings within rounding, far below the margin the heading test keeps:
    /// [`super::site_tree`]).
    fn headings(&self) -> [f64; 2] {
        if self.turned[1] - self.turned[0] < self.theta[1] - self.theta[0] {
            [self.turned[0] + PI, self.turned[1] + PI]
        } else {
            self.theta
        }
    }
}

/// One run of a lap in a sub-cell: where it ends in the sub-cell's sites, and the bounds of
/// its sites' positions and wrapped headings (a run wholly in or out of a query is decided at
/// once).
#[derive(Clone, Copy)]
struct Run {
    lap: u32,
    end: u32,
    x: [f64; 2],
    y: [f64; 2],
    theta: [f64; 2],
}

/// One sub-cell: its sites in creation order, as runs of one lap, their bounds and laps.
struct Sub {
    /// Where in its cell (row × [`SUBS`] + column).
    at: u8,
    bounds: Bounds,
    laps: Laps,
    sites: Vec<u32>,
    /// A run starts where the previous one ends.
    runs: Vec<Run>,
}

/// One cell (the radius wide, 1 % more): its sub-cells that hold a site.
#[derive(Default)]
struct Cell {
    subs: Vec<Sub>,
}

/// The active sites of one sweep in cells of sub-cells, with a witness per lap and facing
/// asked about (see the module doc). The sites are handed to each call (a slice that only
/// grows), so a sweep can be resumed as sites are made ([`LapSweep`]).
struct LapGrid<const N: usize> {
    /// Sub-cells per metre.
    inv_sub_m: f64,
    cells: HashMap<(i64, i64), Cell>,
    /// Per facing asked about, per lap: a copy of the site that last agreed with a query (kept
    /// beside each other, so testing the witnesses of many laps reads few cache lines).
    witness: [Vec<Option<Site>>; N],
    /// Scratch of [`Self::laps`]: the (cell, sub-cell, facing) taken in part.
    part: Vec<(u8, u32, u8)>,
}

impl<const N: usize> LapGrid<N> {
    /// An empty grid for queries within `r_m` (positive and finite).
    fn new(r_m: f64) -> Self {
        LapGrid {
            inv_sub_m: SUBS as f64 / (r_m * 1.01),
            cells: HashMap::default(),
            witness: std::array::from_fn(|_| Vec::new()),
            part: Vec::new(),
        }
    }

    /// The cell of `s` and its sub-cell there. A site within the radius of a query lies in
    /// the 3 × 3 cells around the query's: their sub-cell indices differ by at most
    /// 4 / 1.01 (plus rounding), so the cells' by at most 1.
    fn cell_of(&self, s: &Site) -> ((i64, i64), u8) {
        let fx = (s.x * self.inv_sub_m).floor() as i64;
        let fy = (s.y * self.inv_sub_m).floor() as i64;
        let at = fy.rem_euclid(SUBS) * SUBS + fx.rem_euclid(SUBS);
        ((fx.div_euclid(SUBS), fy.div_euclid(SUBS)), at as u8)
    }

    /// Makes site `k` of `sites` active.
    fn activate(&mut self, sites: &[Site], k: usize) {
        let s = &sites[k];
        let (key, at) = self.cell_of(s);
        let lap = s.lap as u32;
        for w in &mut self.witness {
            if w.len() <= s.lap {
                w.resize(s.lap + 1, None);
            }
        }
        let t = wrap_angle(s.theta);
        let cell = self.cells.entry(key).or_default();
        let sub = match cell.subs.iter().position(|b| b.at == at) {
            Some(i) => &mut cell.subs[i],
            None => {
                cell.subs.push(Sub {
                    at,
                    bounds: Bounds::of(s),
                    laps: Laps::default(),
                    sites: Vec::new(),
                    runs: Vec::new(),
                });
                cell.subs.last_mut().expect("just pushed")
            }
        };
        sub.bounds.add(s);
        sub.laps.insert(s.lap);
        sub.sites.push(k as u32);
        let end = sub.sites.len() as u32;
        match sub.runs.last_mut() {
            Some(r) if r.lap == lap => {
                r.end = end;
                r.x = [r.x[0].min(s.x), r.x[1].max(s.x)];
                r.y = [r.y[0].min(s.y), r.y[1].max(s.y)];
                r.theta = [r.theta[0].min(t), r.theta[1].max(t)];
            }
            _ => sub.runs.push(Run {
                lap,
                end,
                x: [s.x; 2],
                y: [s.y; 2],
                theta: [t; 2],
            }),
        }
    }

    /// Adds to `laps[f]` the lap of every active site `qs[f]` takes (the queries ask about one
    /// site, each facing its own way). First the sub-cells wholly taken give all their laps at
    /// once; then, in those taken in part, the runs of laps not yet found are looked at one by
    /// one. A sub-cell whose laps are all found already is not looked at (for that facing), so
    /// the query's own cell comes first: its sub-cells are the likeliest to be taken whole. A
    /// sub-cell's position bounds are tested once for every facing.
    fn laps(&mut self, sites: &[Site], qs: &[Query; N], laps: &mut [Laps; N]) {
        let s = qs[0].site;
        let ((cx, cy), _) = self.cell_of(s);
        let cells: [Option<&Cell>; 9] = std::array::from_fn(|i| {
            let i = (i + 4) as i64 % 9;
            self.cells.get(&(cx + i / 3 - 1, cy + i % 3 - 1))
        });
        let mut part = std::mem::take(&mut self.part);
        part.clear();
        for (c, cell) in cells.iter().enumerate() {
            for (k, sub) in cell.iter().flat_map(|c| &c.subs).enumerate() {
                let mut inside = None;
                for (f, (q, laps)) in qs.iter().zip(laps.iter_mut()).enumerate() {
                    if laps.holds_all(&sub.laps) {
                        continue;
                    }
                    let b = &sub.bounds;
                    let Some(inside) =
                        *inside.get_or_insert_with(|| position_cover(b.x, b.y, s, q.r2))
                    else {
                        break;
                    };
                    let headings = heading_cover(s.theta, b.headings(), q.facing, q.tol_rad);
                    match joined_cover(inside, headings) {
                        Cover::All => laps.add_all(&sub.laps),
                        Cover::Part => part.push((c as u8, k as u32, f as u8)),
                        Cover::None => {}
                    }
                }
            }
        }
        for &(c, k, f) in &part {
            let sub = &cells[c as usize].expect("a cell held").subs[k as usize];
            let f = f as usize;
            if !laps[f].holds_all(&sub.laps) {
                part_laps(sites, sub, &qs[f], &mut laps[f], &mut self.witness[f]);
            }
        }
        self.part = part;
    }
}

/// Adds to `laps` the lap of every site of `sub` that `q` takes, lap by lap: per run of a lap
/// not yet found, first the lap's witness (the site of that lap that last agreed with a query:
/// consecutive observations are close, so it usually agrees again), then the run's bounds, and
/// only then its sites one by one, stopping at the first that agrees.
fn part_laps(sites: &[Site], sub: &Sub, q: &Query, laps: &mut Laps, witness: &mut [Option<Site>]) {
    let mut start = 0usize;
    for run in &sub.runs {
        let (lap, from) = (run.lap as usize, start);
        start = run.end as usize;
        if laps.contains(lap) {
            continue;
        }
        let agrees = |p: &Site| q.site.agrees_with(p, q.r2, q.facing, q.tol_rad);
        if witness[lap].as_ref().is_some_and(agrees) {
            laps.insert(lap);
            continue;
        }
        let run_sites = &sub.sites[from..start];
        let hit = match cover(run.x, run.y, run.theta, q) {
            Cover::None => None,
            Cover::All => run_sites.first(),
            Cover::Part => run_sites.iter().find(|&&j| agrees(&sites[j as usize])),
        };
        if let Some(&j) = hit {
            witness[lap] = Some(sites[j as usize]);
            laps.insert(lap);
        }
    }
}

/// Calls `visit(k, laps)` for every site `k` in order, with, per facing of `facings`, the laps
/// of the sites before it, at least `min_gap_m` of true travel earlier, within `r_m` and facing
/// that way (nothing when `r_m` is not positive and finite).
pub fn sweep_laps<const N: usize>(
    sites: &[Site],
    min_gap_m: f64,
    r_m: f64,
    facings: [Facing; N],
    tol_rad: f64,
    visit: impl FnMut(usize, [&Laps; N]),
) {
    if let Some(mut sweep) = LapSweep::new(min_gap_m, r_m, facings, tol_rad) {
        sweep.advance(sites, sites.len(), visit);
    }
}

/// [`sweep_laps`] resumed as sites are made: each [`LapSweep::advance`] visits the next sites
/// of a slice that only grows, with the same laps as one sweep over the whole slice (a site's
/// laps depend on the sites before it alone). What lets visit recall be counted while a run is
/// scored, rather than holding every (observation, lap) found to the end (`eval::tally`).
pub struct LapSweep<const N: usize> {
    grid: LapGrid<N>,
    laps: [Laps; N],
    min_gap_m: f64,
    r_m: f64,
    facings: [Facing; N],
    tol_rad: f64,
    /// Sites made active, and sites visited.
    ready: usize,
    done: usize,
}

impl<const N: usize> LapSweep<N> {
    /// A sweep at the start; `None` when `r_m` is not positive and finite (no laps at all).
    pub fn new(min_gap_m: f64, r_m: f64, facings: [Facing; N], tol_rad: f64) -> Option<Self> {
        if r_m <= 0.0 || !r_m.is_finite() {
            return None;
        }
        Some(LapSweep {
            grid: LapGrid::new(r_m),
            laps: std::array::from_fn(|_| Laps::default()),
            min_gap_m,
            r_m,
            facings,
            tol_rad,
            ready: 0,
            done: 0,
        })
    }

    /// Visits sites `done()..end` of `sites` in order, as [`sweep_laps`] does (`sites` holds
    /// at least the sites of every earlier call, unchanged).
    pub fn advance(
        &mut self,
        sites: &[Site],
        end: usize,
        mut visit: impl FnMut(usize, [&Laps; N]),
    ) {
        for k in self.done..end.min(sites.len()) {
            let s = &sites[k];
            while self.ready < k && s.travel_m - sites[self.ready].travel_m >= self.min_gap_m {
                self.grid.activate(sites, self.ready);
                self.ready += 1;
            }
            let lap_count = self.grid.witness.first().map_or(0, Vec::len);
            for laps in &mut self.laps {
                laps.clear();
                laps.reserve_laps(lap_count);
            }
            let qs = self.facings.map(|facing| Query {
                site: s,
                r2: self.r_m * self.r_m,
                facing,
                tol_rad: self.tol_rad,
            });
            self.grid.laps(sites, &qs, &mut self.laps);
            visit(k, std::array::from_fn(|f| &self.laps[f]));
            self.done = k + 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::site_tree::{LapSet, sweep, tests::passes};

    /// The laps equal the k-d tree's (which equal testing every earlier site) for every site,
    /// radius and facing, on passes that go both ways.
    #[test]
    fn laps_equal_the_site_tree() {
        let sites = passes(5);
        for r in [0.05, 0.5, 1.0, 3.0] {
            for facing in [Facing::Same, Facing::Opposite, Facing::Either] {
                let mut want = Vec::new();
                let mut set = LapSet::default();
                sweep(&sites, 2.0, |k, tree| {
                    set.clear();
                    let q = Query {
                        site: &sites[k],
                        r2: r * r,
                        facing,
                        tol_rad: 0.7,
                    };
                    tree.laps(&q, &mut set);
                    let mut l = set.list.clone();
                    l.sort_unstable();
                    want.push(l);
                });
                let mut got = Vec::new();
                sweep_laps(&sites, 2.0, r, [facing], 0.7, |_, [laps]| {
                    let mut l: Vec<usize> = laps.iter().collect();
                    l.sort_unstable();
                    got.push(l);
                });
                assert_eq!(got, want, "{r} {facing:?}");
                // Asked with the other facings at once, each facing's laps are the same.
                let mut all = Vec::new();
                let facings = [Facing::Opposite, facing, Facing::Same];
                sweep_laps(&sites, 2.0, r, facings, 0.7, |_, [_, laps, _]| {
                    let mut l: Vec<usize> = laps.iter().collect();
                    l.sort_unstable();
                    all.push(l);
                });
                assert_eq!(all, want, "{r} {facing:?} with the others");
                if r >= 0.5 {
                    assert!(want.iter().any(|l| l.len() > 1), "{r} {facing:?}");
                }
            }
        }
    }

    /// A sweep resumed in uneven steps, as sites are made, visits every site once with the
    /// laps of one sweep over all of them (what lets a tally count visit recall as it scores).
    #[test]
    fn a_resumed_sweep_visits_each_site_with_the_laps_of_one_sweep() {
        let sites = passes(5);
        let facings = [Facing::Same, Facing::Opposite];
        let mut want = Vec::new();
        sweep_laps(&sites, 2.0, 1.0, facings, 0.7, |k, [s, o]| {
            want.push((
                k,
                s.iter().collect::<Vec<_>>(),
                o.iter().collect::<Vec<_>>(),
            ));
        });
        let mut got = Vec::new();
        let mut sweep = LapSweep::new(2.0, 1.0, facings, 0.7).expect("a positive radius");
        let mut end = 0;
        while end < sites.len() {
            end = (end + 1 + end / 3).min(sites.len());
            // Each call sees only the sites made so far.
            sweep.advance(&sites[..end], end, |k, [s, o]| {
                got.push((
                    k,
                    s.iter().collect::<Vec<_>>(),
                    o.iter().collect::<Vec<_>>(),
                ));
            });
        }
        assert_eq!(got, want);
        assert!(want.iter().any(|w| w.1.len() > 1));
        assert!(LapSweep::new(2.0, 0.0, facings, 0.7).is_none());
    }
}
