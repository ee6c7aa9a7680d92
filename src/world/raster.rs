//! A world drawn into square cells: occupied where a thick wall or door panel covers the cell,
//! free elsewhere; and the free region reachable from a point (4-connected flood fill).
//!
//! Used where a question is about areas rather than lines: which free space a robot at home can
//! reach, and the density of free space around every cell (the density map).

use crate::geom::Vec2;
use crate::world::geometry::ThickSegment;

/// Most cells a raster holds; larger worlds get larger cells.
pub const MAX_CELLS: usize = 8_000_000;

/// Occupancy of a rectangle of square cells; cell (0, 0) is the bottom-left one.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// World position of the bottom-left corner of cell (0, 0), metres.
    pub origin: Vec2,
    pub cell_m: f64,
    pub width: usize,
    pub height: usize,
    /// Row-major from the bottom row: true where occupied.
    pub occupied: Vec<bool>,
}

/// The lowest and highest corners of the box around `items` and `also` (at the origin when
/// there are none).
fn bounds(items: &[ThickSegment], also: &[Vec2]) -> (Vec2, Vec2) {
    let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
    for t in items {
        lo = lo.inf(&t.seg.a).inf(&t.seg.b);
        hi = hi.sup(&t.seg.a).sup(&t.seg.b);
    }
    for p in also {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if !lo.x.is_finite() {
        (lo, hi) = (Vec2::zeros(), Vec2::zeros());
    }
    (lo, hi)
}

impl Raster {
    /// Draws `items` into cells of `cell_m` (grown when the area would exceed [`MAX_CELLS`])
    /// over their bounds and the points `also`, plus `margin_m` on every side. A cell is
    /// occupied when its centre lies within the item's half thickness plus `dilate_m` of its
    /// centre line.
    pub fn new(
        items: &[ThickSegment],
        also: &[Vec2],
        cell_m: f64,
        margin_m: f64,
        dilate_m: f64,
    ) -> Self {
        let (mut lo, mut hi) = bounds(items, also);
        lo -= Vec2::repeat(margin_m);
        hi += Vec2::repeat(margin_m);
        let area = (hi.x - lo.x).max(cell_m) * (hi.y - lo.y).max(cell_m);
        let cell_m = cell_m.max((area / MAX_CELLS as f64).sqrt());
        let width = ((hi.x - lo.x) / cell_m).ceil().max(1.0) as usize;
        let height = ((hi.y - lo.y) / cell_m).ceil().max(1.0) as usize;
        let mut r = Raster {
            origin: lo,
            cell_m,
            width,
            height,
            occupied: vec![false; width * height],
        };
        for t in items {
            r.draw(t, dilate_m);
        }
        r
    }

    fn draw(&mut self, t: &ThickSegment, dilate_m: f64) {
        let reach = t.half_thickness_m + dilate_m;
        let lo = t.seg.a.inf(&t.seg.b) - Vec2::repeat(reach);
        let hi = t.seg.a.sup(&t.seg.b) + Vec2::repeat(reach);
        let (x0, y0) = self.cell_clamped(lo);
        let (x1, y1) = self.cell_clamped(hi);
        for y in y0..=y1 {
            for x in x0..=x1 {
                if t.seg.distance_to_point(self.centre(x, y)) <= reach {
                    self.occupied[y * self.width + x] = true;
                }
            }
        }
    }

    /// Centre of cell (x, y), metres.
    pub fn centre(&self, x: usize, y: usize) -> Vec2 {
        self.origin + Vec2::new(x as f64 + 0.5, y as f64 + 0.5) * self.cell_m
    }

    /// The cell holding `p`, if inside the raster.
    pub fn cell(&self, p: Vec2) -> Option<(usize, usize)> {
        let q = (p - self.origin) / self.cell_m;
        let inside = q.x >= 0.0 && q.y >= 0.0;
        let (x, y) = (q.x.floor() as usize, q.y.floor() as usize);
        (inside && x < self.width && y < self.height).then_some((x, y))
    }

    fn cell_clamped(&self, p: Vec2) -> (usize, usize) {
        let q = (p - self.origin) / self.cell_m;
        let c = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n - 1);
        (c(q.x, self.width), c(q.y, self.height))
    }

    /// Free cells 4-connected to the cells of `seeds` (seeds on occupied cells are skipped);
    /// row-major like `occupied`.
    pub fn reachable(&self, seeds: &[Vec2]) -> Vec<bool> {
        let mut seen = vec![false; self.occupied.len()];
        let mut stack = self.free_seed_cells(seeds, &mut seen);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % self.width, i / self.width);
            let mut visit = |j: usize| {
                if !self.occupied[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < self.width {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - self.width);
            }
            if y + 1 < self.height {
                visit(i + self.width);
            }
        }
        seen
    }

    /// The free cells of `seeds` (inside the raster), each once, marked in `seen`.
    fn free_seed_cells(&self, seeds: &[Vec2], seen: &mut [bool]) -> Vec<usize> {
        let mut cells = Vec::new();
        for s in seeds {
            if let Some((x, y)) = self.cell(*s) {
                let i = y * self.width + x;
                if !self.occupied[i] && !seen[i] {
                    seen[i] = true;
                    cells.push(i);
                }
            }
        }
        cells
    }

    /// Whether any cell of `region` lies on the raster's border.
    pub fn touches_border(&self, region: &[bool]) -> bool {
        let (w, h) = (self.width, self.height);
        (0..w).any(|x| region[x] || region[(h - 1) * w + x])
            || (0..h).any(|y| region[y * w] || region[y * w + w - 1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Segment;

    fn wall(ax: f64, ay: f64, bx: f64, by: f64) -> ThickSegment {
        ThickSegment {
            seg: Segment::new(Vec2::new(ax, ay), Vec2::new(bx, by)),
            half_thickness_m: 0.05,
        }
    }

    #[test]
    fn a_closed_box_keeps_its_inside_apart_from_the_outside() {
        let walls = [
            wall(0.0, 0.0, 4.0, 0.0),
            wall(4.0, 0.0, 4.0, 4.0),
            wall(4.0, 4.0, 0.0, 4.0),
            wall(0.0, 4.0, 0.0, 0.0),
        ];
        let r = Raster::new(&walls, &[], 0.05, 1.0, 0.0);
        let inside = r.reachable(&[Vec2::new(2.0, 2.0)]);
        assert!(!r.touches_border(&inside));
        assert!(
            !inside[{
                let (x, y) = r.cell(Vec2::new(4.5, 2.0)).unwrap();
                y * r.width + x
            }]
        );
        let outside = r.reachable(&[Vec2::new(4.5, 2.0)]);
        assert!(r.touches_border(&outside));
    }
}
