//! The map as a grid of cells: which cells the robot fits in, where to start, and the free
//! space reachable from there.

use super::leg_clear;
use crate::geom::{Segment, Vec2};
use std::collections::VecDeque;

/// A grid over the walls' bounding box (and the home), grown by 1 m on every side.
pub(super) struct Raster {
    /// Corner of cell (0, 0).
    lo: Vec2,
    /// Cell size, metres.
    res: f64,
    pub nx: usize,
    pub ny: usize,
}

/// Most cells route generation rasterises a map into: its work budget. Thinning a free space
/// that fills the whole raster (a map whose outer wall a far-away line broke open) costs about
/// 0.25 µs of CPU per cell, so 4 million cells keep the worst case near a second.
pub const MAX_CELLS: f64 = 4.0e6;

/// The coarsest cell a large map is rasterised at, metres.
pub const COARSEST_M: f64 = 0.1;

/// The largest raster area route generation takes (the walls' and home's bounding box grown by
/// [`MARGIN_M`] on every side), square metres: [`MAX_CELLS`] cells of [`COARSEST_M`].
pub const MAX_AREA_M2: f64 = MAX_CELLS * COARSEST_M * COARSEST_M;

/// How far the raster reaches beyond the walls' and home's bounding box, metres.
pub const MARGIN_M: f64 = 1.0;

/// The bounding box (corners lo, hi) of `home` and every end of `walls`: what route generation
/// rasterises, before [`MARGIN_M`] is added on every side.
pub fn bounding_box<'a>(home: Vec2, walls: impl IntoIterator<Item = &'a Segment>) -> (Vec2, Vec2) {
    let (mut lo, mut hi) = (home, home);
    for w in walls {
        lo = lo.inf(&w.a).inf(&w.b);
        hi = hi.sup(&w.a).sup(&w.b);
    }
    (lo, hi)
}

/// The area route generation rasterises for a [`bounding_box`]: the box grown by [`MARGIN_M`]
/// on every side, square metres.
pub fn raster_area_m2((lo, hi): (Vec2, Vec2)) -> f64 {
    (hi.x - lo.x + 2.0 * MARGIN_M) * (hi.y - lo.y + 2.0 * MARGIN_M)
}

/// The cell size of a raster of `area_m2` asked at `resolution_m`: coarsened so it stays under
/// [`MAX_CELLS`]; `None` when even [`COARSEST_M`] would not (the work budget, one rule for
/// route generation and for `world import`'s early refusal).
pub fn cell_size_m(area_m2: f64, resolution_m: f64) -> Option<f64> {
    let res = resolution_m.max((area_m2 / MAX_CELLS).sqrt());
    (!res.is_nan() && res <= COARSEST_M + 1e-12).then_some(res)
}

impl Raster {
    /// Cells of `resolution_m`, coarsened (up to [`COARSEST_M`]) for large maps so the raster
    /// stays under [`MAX_CELLS`]; larger maps are refused with their size (width, height in
    /// metres). `world import` refuses them earlier, at the map's line
    /// (`authoring::mobilesim`).
    pub fn around(walls: &[Segment], home: Vec2, resolution_m: f64) -> Result<Raster, (f64, f64)> {
        let (lo, hi) = bounding_box(home, walls);
        let lo = lo - Vec2::new(MARGIN_M, MARGIN_M);
        let hi = hi + Vec2::new(MARGIN_M, MARGIN_M);
        let Some(res) = cell_size_m((hi.x - lo.x) * (hi.y - lo.y), resolution_m) else {
            return Err((hi.x - lo.x, hi.y - lo.y));
        };
        Ok(Raster {
            lo,
            res,
            nx: ((hi.x - lo.x) / res).ceil() as usize,
            ny: ((hi.y - lo.y) / res).ceil() as usize,
        })
    }

    /// The centre of cell (i, j).
    pub fn center(&self, i: usize, j: usize) -> Vec2 {
        Vec2::new(
            self.lo.x + (i as f64 + 0.5) * self.res,
            self.lo.y + (j as f64 + 0.5) * self.res,
        )
    }

    fn idx(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }

    /// Free: cell centres at least `need` from every wall surface. Each segment only visits the
    /// cells of its own bounding box grown by that distance (exact distances, no full scan per
    /// cell).
    pub fn free_cells(&self, walls: &[Segment], thickness_m: f64, need: f64) -> Vec<bool> {
        let (nx, ny) = (self.nx, self.ny);
        let mut free = vec![true; nx * ny];
        let reach = need + thickness_m / 2.0;
        let cell_of = |v: f64, o: f64, n: usize| {
            (((v - o) / self.res - 0.5).floor().max(0.0) as usize).min(n - 1)
        };
        for w in walls {
            let (a, b) = (w.a.inf(&w.b), w.a.sup(&w.b));
            let (i0, i1) = (
                cell_of(a.x - reach, self.lo.x, nx),
                cell_of(b.x + reach, self.lo.x, nx) + 1,
            );
            let (j0, j1) = (
                cell_of(a.y - reach, self.lo.y, ny),
                cell_of(b.y + reach, self.lo.y, ny) + 1,
            );
            for j in j0..=j1.min(ny - 1) {
                for i in i0..=i1.min(nx - 1) {
                    let k = self.idx(i, j);
                    if free[k] && w.distance_to_point(self.center(i, j)) - thickness_m / 2.0 < need
                    {
                        free[k] = false;
                    }
                }
            }
        }
        free
    }

    /// The free cell nearest the home (within 2 m) that the home can see (no wall between
    /// them), so a home in a tight spot never lands the route outside the building.
    pub fn start_cell(
        &self,
        free: &[bool],
        walls: &[Segment],
        home: Vec2,
    ) -> Option<(usize, usize)> {
        let res = self.res;
        let hc = (
            (home.x - self.lo.x) / res - 0.5,
            (home.y - self.lo.y) / res - 0.5,
        );
        let reach = (2.0 / res).ceil() as i64;
        let mut cand: Vec<(f64, (usize, usize))> = Vec::new();
        for j in (hc.1 as i64 - reach).max(0)..=(hc.1 as i64 + reach).min(self.ny as i64 - 1) {
            for i in (hc.0 as i64 - reach).max(0)..=(hc.0 as i64 + reach).min(self.nx as i64 - 1) {
                let (i, j) = (i as usize, j as usize);
                let d = ((i as f64 - hc.0).powi(2) + (j as f64 - hc.1).powi(2)).sqrt() * res;
                if free[self.idx(i, j)] && d <= 2.0 {
                    cand.push((d, (i, j)));
                }
            }
        }
        cand.sort_by(|a, b| a.0.total_cmp(&b.0));
        cand.iter()
            .find(|(_, (i, j))| {
                leg_clear(walls, 0.0, &Segment::new(home, self.center(*i, *j)), 1e-9)
            })
            .map(|c| c.1)
    }

    /// The 4-connected free component holding `start`.
    pub fn component(&self, free: &[bool], start: (usize, usize)) -> Vec<bool> {
        let (nx, ny) = (self.nx, self.ny);
        let mut comp = vec![false; nx * ny];
        let mut queue = VecDeque::from([start]);
        comp[self.idx(start.0, start.1)] = true;
        while let Some((i, j)) = queue.pop_front() {
            let mut push = |a: usize, b: usize| {
                let k = self.idx(a, b);
                if free[k] && !comp[k] {
                    comp[k] = true;
                    queue.push_back((a, b));
                }
            };
            if i > 0 {
                push(i - 1, j);
            }
            if i + 1 < nx {
                push(i + 1, j);
            }
            if j > 0 {
                push(i, j - 1);
            }
            if j + 1 < ny {
                push(i, j + 1);
            }
        }
        comp
    }
}
