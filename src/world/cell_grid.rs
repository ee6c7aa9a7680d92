//! A uniform grid over thick segments: each square cell lists the segments that pass within
//! their pad of it. The ray caster uses it to skip whole cells that are behind the sensor, out of
//! range or hidden behind nearer hits, and to visit cells roughly nearest first (in square rings
//! around the sensor); the face classification uses it to find the solids around a point.
//!
//! The cell size follows the items' bounds and count (at most about one cell per item), so
//! memory and build time grow linearly with the number of segments and their total length.

/// A segment `[ax, ay, bx, by]` with a pad (half its thickness), metres.
pub type PaddedSegment = ([f64; 4], f64);

/// Segment indices bucketed by square cell (compressed rows: cell `c` holds
/// `items[start[c]..start[c + 1]]`, cells numbered `j * nx + i`).
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    x0: f64,
    y0: f64,
    cell_m: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Extra pad on every item, metres: absorbs rounding in cell lookups and piece ends.
const EPS_M: f64 = 1e-6;

/// The cell side is this many times `sqrt(area / items)` (tuned on the institute floor: 1, 1.5,
/// 2 and 3 tried; 3 gives 4.3 m cells there and the fastest `lms200` scans).
const CELL_SCALE: f64 = 3.0;

impl CellGrid {
    /// A grid over `segs` (every cell any part of a segment, widened by its pad, touches).
    pub fn new(segs: &[PaddedSegment]) -> Self {
        let Some((lo, hi)) = bounds(segs) else {
            return CellGrid::default();
        };
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let n = segs.len() as f64;
        let cell_m = (CELL_SCALE * (w * h / n).sqrt())
            .max(w.max(h) / n)
            .max(1e-3);
        let nx = ((w / cell_m) as usize + 1).min(1 << 20);
        let ny = ((h / cell_m) as usize + 1).min(1 << 20);
        let mut g = CellGrid {
            x0: lo[0],
            y0: lo[1],
            cell_m,
            nx,
            ny,
            start: Vec::new(),
            items: Vec::new(),
        };
        g.fill(segs);
        g
    }

    /// Buckets the segments: each is cut into pieces no longer than a cell, and each piece adds
    /// the cells of its padded bounding box.
    fn fill(&mut self, segs: &[PaddedSegment]) {
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(segs.len() * 4);
        for (k, seg) in segs.iter().enumerate() {
            self.push_cells_of(k, seg, &mut pairs);
        }
        pairs.sort_unstable();
        pairs.dedup();
        self.start = vec![0; self.nx * self.ny + 1];
        for &(c, _) in &pairs {
            self.start[c as usize + 1] += 1;
        }
        for c in 0..self.nx * self.ny {
            self.start[c + 1] += self.start[c];
        }
        self.items = pairs.into_iter().map(|(_, k)| k).collect();
    }

    /// Pushes (cell, `k`) for every cell the padded segment `(s, pad)` may touch: the boxes
    /// around pieces of it about a cell long.
    fn push_cells_of(&self, k: usize, &(s, pad): &PaddedSegment, pairs: &mut Vec<(u32, u32)>) {
        let (dx, dy) = (s[2] - s[0], s[3] - s[1]);
        let pieces = ((dx.hypot(dy) / self.cell_m).ceil() as usize).clamp(1, 1 << 24);
        let pad = pad.max(0.0) + EPS_M;
        let at = |t: f64| [s[0] + dx * t, s[1] + dy * t];
        for p in 0..pieces {
            let (a, b) = (
                at(p as f64 / pieces as f64),
                at((p + 1) as f64 / pieces as f64),
            );
            let (i0, j0) = self.clamped_cell(a[0].min(b[0]) - pad, a[1].min(b[1]) - pad);
            let (i1, j1) = self.clamped_cell(a[0].max(b[0]) + pad, a[1].max(b[1]) + pad);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    pairs.push(((j * self.nx + i) as u32, k as u32));
                }
            }
        }
    }

    /// The cell of a point, clamped into the grid.
    fn clamped_cell(&self, x: f64, y: f64) -> (usize, usize) {
        let (i, j) = self.cell_of(x, y);
        (
            i.clamp(0, self.nx as i64 - 1) as usize,
            j.clamp(0, self.ny as i64 - 1) as usize,
        )
    }

    /// Cell coordinates of a point, clamped to one cell beyond the grid on each side.
    pub fn cell_of(&self, x: f64, y: f64) -> (i64, i64) {
        let f = |v: f64, o: f64, n: usize| {
            let c = ((v - o) / self.cell_m).floor();
            if c.is_nan() {
                -1
            } else {
                c.clamp(-1.0, n as f64) as i64
            }
        };
        (f(x, self.x0, self.nx), f(y, self.y0, self.ny))
    }

    /// The segments listed in the cell holding point `(x, y)` (none outside the grid).
    pub fn items_at(&self, x: f64, y: f64) -> &[u32] {
        let (i, j) = self.cell_of(x, y);
        if i < 0 || j < 0 || i >= self.nx as i64 || j >= self.ny as i64 {
            return &[];
        }
        self.items_in(j as usize * self.nx + i as usize)
    }

    /// The segments listed in cell `c`.
    pub fn items_in(&self, c: usize) -> &[u32] {
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// Cells along x and along y.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The bounds `[x_min, y_min, x_max, y_max]` of the cells `i0..=i1` × `j0..=j1`, widened
    /// by the pad.
    pub fn cells_rect(&self, [i0, i1, j0, j1]: [usize; 4]) -> [f64; 4] {
        let c = self.cell_m;
        [
            self.x0 + i0 as f64 * c - EPS_M,
            self.y0 + j0 as f64 * c - EPS_M,
            self.x0 + (i1 + 1) as f64 * c + EPS_M,
            self.y0 + (j1 + 1) as f64 * c + EPS_M,
        ]
    }

    /// The cells at Chebyshev distance `k` (in cells) from cell `(ci, cj)` that lie in the
    /// grid, as up to four strips of inclusive cell ranges `(i0, i1, j0, j1)`. Every point of
    /// such a cell is at least `(k - 1) * cell_m` away from any point of cell `(ci, cj)`.
    pub fn ring(&self, ci: i64, cj: i64, k: i64) -> [Option<[usize; 4]>; 4] {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let strip = |i0: i64, i1: i64, j0: i64, j1: i64| {
            let (i0, i1, j0, j1) = (i0.max(0), i1.min(nx - 1), j0.max(0), j1.min(ny - 1));
            (i0 <= i1 && j0 <= j1).then_some([i0 as usize, i1 as usize, j0 as usize, j1 as usize])
        };
        if k == 0 {
            return [strip(ci, ci, cj, cj), None, None, None];
        }
        [
            strip(ci - k, ci + k, cj - k, cj - k),
            strip(ci - k, ci + k, cj + k, cj + k),
            strip(ci - k, ci - k, cj - k + 1, cj + k - 1),
            strip(ci + k, ci + k, cj - k + 1, cj + k - 1),
        ]
    }

    /// Whether cell `(i, j)` lists no segment.
    pub fn is_empty(&self, i: usize, j: usize) -> bool {
        let c = j * self.nx + i;
        self.start[c] == self.start[c + 1]
    }

    /// The largest ring index around cell `(ci, cj)` that still meets the grid.
    pub fn last_ring(&self, ci: i64, cj: i64) -> i64 {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        ci.max(nx - 1 - ci).max(cj).max(ny - 1 - cj)
    }
}

/// Bounds of all segments and their pads; `None` when there are none or they are not finite.
fn bounds(segs: &[PaddedSegment]) -> Option<([f64; 2], [f64; 2])> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (s, pad) in segs {
        let pad = pad.max(0.0) + EPS_M;
        for d in 0..2 {
            lo[d] = lo[d].min(s[d].min(s[d + 2]) - pad);
            hi[d] = hi[d].max(s[d].max(s[d + 2]) + pad);
        }
    }
    (lo.iter().chain(&hi).all(|v| v.is_finite())).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_point_of_a_segment_is_listed_in_its_cell() {
        let segs: Vec<PaddedSegment> = (0..50)
            .map(|k| {
                let t = k as f64 * 0.7;
                (
                    [t.cos() * 9.0, t.sin() * 5.0, t * 0.3, -t * 0.2],
                    0.05 * (k % 3) as f64,
                )
            })
            .collect();
        let g = CellGrid::new(&segs);
        for (k, (s, pad)) in segs.iter().enumerate() {
            for q in 0..=100 {
                let t = q as f64 / 100.0;
                let (x, y) = (s[0] + (s[2] - s[0]) * t, s[1] + (s[3] - s[1]) * t);
                for (ox, oy) in [(0.0, 0.0), (*pad, 0.0), (0.0, -*pad)] {
                    assert!(g.items_at(x + ox, y + oy).contains(&(k as u32)));
                }
            }
        }
    }

    #[test]
    fn rings_cover_every_cell_once() {
        let segs: Vec<PaddedSegment> = (0..30)
            .map(|k| ([k as f64, 0.0, k as f64, 10.0 + k as f64], 0.0))
            .collect();
        let g = CellGrid::new(&segs);
        let (nx, ny) = g.dims();
        for (ci, cj) in [(0, 0), (-1, -1), (nx as i64, 3), (3, 2)] {
            let mut seen = vec![0; nx * ny];
            for k in 0..=g.last_ring(ci, cj) {
                for [i0, i1, j0, j1] in g.ring(ci, cj, k).into_iter().flatten() {
                    for j in j0..=j1 {
                        for i in i0..=i1 {
                            seen[j * nx + i] += 1;
                        }
                    }
                }
            }
            for (c, n) in seen.iter().enumerate().take(nx * ny) {
                assert_eq!(*n, 1, "cell {c} from ({ci}, {cj})");
            }
        }
    }

    #[test]
    fn no_segments_make_an_empty_grid() {
        let g = CellGrid::new(&[]);
        assert!(g.items_at(0.0, 0.0).is_empty());
    }
}
