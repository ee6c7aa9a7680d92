//! The earlier laps that pass near each observation, found lap by lap: the index behind visit
//! recall ([`super::tally`]).
//!
//! Visit recall asks, for every observation in creation order, which earlier laps hold an
//! observation at least `min_gap_m` of true travel before it, within a radius and facing a given
//! way. The answer is a set of laps, so once one site of a lap agrees, the rest of that lap need
//! not be looked at. The k-d tree of [`super::site_tree`] finds the sites, not the laps, and
//! grew with the square of the laps on a long run (a thousand laps of one loop). Here the
//! active sites sit in square cells at least the radius wide, each cell's sites kept as *runs*
//! of one lap in creation order; a query looks at the 3 × 3 cells around it and, per run of a
//! lap not yet found, first at the lap's *witness* (the site of that lap that last agreed with a
//! query: consecutive observations are close, so it usually agrees again), then at the run's
//! bounds (position and heading: a run wholly outside the query, or wholly inside it, is decided
//! at once) and only then at the run's sites one by one, stopping at the first that agrees. The work per query is the runs
//! near it, about one per earlier lap that passes there, plus the sites of laps that pass near
//! but do not agree.
//!
//! The answers are exactly those of testing every active site with the figures' own predicate
//! ([`Site::agrees_with`]): a site within the radius lies in one of the 3 × 3 cells (the cells
//! are 1 % wider than the radius, far more than the rounding of a cell index); a lap is taken
//! from a witness or a site that passes that predicate, or from a run whose bounds are decided
//! as the k-d tree decides a node's (the same operations, [`super::site_tree`]).

use super::pair_recall::Facing;
use super::site_tree::{Cover, LapSet, Query, Site, cover};
use crate::geom::wrap_angle;
use foldhash::HashMap;

/// One run of a lap in a cell: where it ends in the cell's sites, and the bounds of its sites'
/// positions and wrapped headings (a run wholly in or out of a query is decided at once).
#[derive(Clone, Copy)]
struct Run {
    lap: u32,
    end: u32,
    x: [f64; 2],
    y: [f64; 2],
    theta: [f64; 2],
}

/// One cell: its sites in creation order, as runs of one lap.
#[derive(Default)]
struct Cell {
    sites: Vec<u32>,
    /// A run starts where the previous one ends.
    runs: Vec<Run>,
}

/// The active sites of one sweep in cells, with a witness per lap and facing asked about (see
/// the module doc).
pub struct LapGrid<'s, const N: usize> {
    sites: &'s [Site],
    inv_cell_m: f64,
    cells: HashMap<(i64, i64), Cell>,
    /// Per facing asked about, per lap: a copy of the site that last agreed with a query (kept
    /// beside each other, so testing the witnesses of many laps reads few cache lines).
    witness: [Vec<Option<Site>>; N],
}

impl<'s, const N: usize> LapGrid<'s, N> {
    /// An empty grid over `sites` for queries within `r_m` (positive and finite).
    fn new(sites: &'s [Site], r_m: f64) -> Self {
        let laps = sites.iter().map(|s| s.lap + 1).max().unwrap_or(0);
        LapGrid {
            sites,
            inv_cell_m: 1.0 / (r_m * 1.01),
            cells: HashMap::default(),
            witness: std::array::from_fn(|_| vec![None; laps]),
        }
    }

    fn cell_of(&self, s: &Site) -> (i64, i64) {
        (
            (s.x * self.inv_cell_m).floor() as i64,
            (s.y * self.inv_cell_m).floor() as i64,
        )
    }

    /// Makes site `k` active.
    fn activate(&mut self, k: usize) {
        let s = &self.sites[k];
        let key = self.cell_of(s);
        let lap = s.lap as u32;
        let t = wrap_angle(s.theta);
        let cell = self.cells.entry(key).or_default();
        cell.sites.push(k as u32);
        let end = cell.sites.len() as u32;
        match cell.runs.last_mut() {
            Some(r) if r.lap == lap => {
                r.end = end;
                r.x = [r.x[0].min(s.x), r.x[1].max(s.x)];
                r.y = [r.y[0].min(s.y), r.y[1].max(s.y)];
                r.theta = [r.theta[0].min(t), r.theta[1].max(t)];
            }
            _ => cell.runs.push(Run {
                lap,
                end,
                x: [s.x; 2],
                y: [s.y; 2],
                theta: [t; 2],
            }),
        }
    }

    /// Adds to `laps[f]` the lap of every active site `qs[f]` takes (the queries ask about one
    /// site, each facing its own way: the cells and runs are walked once for all).
    fn laps(&mut self, qs: &[Query; N], laps: &mut [LapSet; N]) {
        let (cx, cy) = self.cell_of(qs[0].site);
        // The query's own cell first: the laps found there are skipped in the others.
        const AROUND: [(i64, i64); 9] = [
            (0, 0),
            (-1, -1),
            (-1, 0),
            (-1, 1),
            (0, -1),
            (0, 1),
            (1, -1),
            (1, 0),
            (1, 1),
        ];
        for (dx, dy) in AROUND {
            let Some(cell) = self.cells.get(&(cx + dx, cy + dy)) else {
                continue;
            };
            let mut start = 0usize;
            for run in &cell.runs {
                let (lap, from) = (run.lap as usize, start);
                start = run.end as usize;
                for ((q, laps), witness) in qs.iter().zip(laps.iter_mut()).zip(&mut self.witness) {
                    if laps.contains(lap) {
                        continue;
                    }
                    let agrees = |p: &Site| q.site.agrees_with(p, q.r2, q.facing, q.tol_rad);
                    if witness[lap].as_ref().is_some_and(agrees) {
                        laps.insert(lap);
                        continue;
                    }
                    let sites = &cell.sites[from..start];
                    let hit = match cover(run.x, run.y, run.theta, q) {
                        Cover::None => None,
                        Cover::All => sites.first(),
                        Cover::Part => sites.iter().find(|&&j| agrees(&self.sites[j as usize])),
                    };
                    if let Some(&j) = hit {
                        witness[lap] = Some(self.sites[j as usize]);
                        laps.insert(lap);
                    }
                }
            }
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
    mut visit: impl FnMut(usize, [&[usize]; N]),
) {
    if r_m <= 0.0 || !r_m.is_finite() {
        return;
    }
    let mut grid = LapGrid::<N>::new(sites, r_m);
    let mut laps: [LapSet; N] = std::array::from_fn(|_| LapSet::default());
    let mut ready = 0;
    for (k, s) in sites.iter().enumerate() {
        while ready < k && s.travel_m - sites[ready].travel_m >= min_gap_m {
            grid.activate(ready);
            ready += 1;
        }
        laps.iter_mut().for_each(LapSet::clear);
        let qs = facings.map(|facing| Query {
            site: s,
            r2: r_m * r_m,
            facing,
            tol_rad,
        });
        grid.laps(&qs, &mut laps);
        visit(k, std::array::from_fn(|f| laps[f].list.as_slice()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::site_tree::{sweep, tests::passes};

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
                    let mut l = laps.to_vec();
                    l.sort_unstable();
                    got.push(l);
                });
                assert_eq!(got, want, "{r} {facing:?}");
                // Asked with the other facings at once, each facing's laps are the same.
                let mut all = Vec::new();
                let facings = [Facing::Opposite, facing, Facing::Same];
                sweep_laps(&sites, 2.0, r, facings, 0.7, |_, [_, laps, _]| {
                    let mut l = laps.to_vec();
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
}
