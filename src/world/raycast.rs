//! Fast exact 2D laser ray casting by a whole-scan angular sweep.
//!
//! Instead of casting each beam into an acceleration structure, every obstacle segment is
//! projected onto the range of beam indices it covers (from the angles of its two endpoints seen
//! from the sensor), and only those beams are intersected with it. Segments behind a sensor whose
//! field of view is at most 180°, and segments outside the square of the maximum range, are
//! skipped before any angle is computed. Discs (people) are handled the same way, analytically.
//! Everything is f64 and each hit is an exact ray/segment intersection.
//!
//! The segments are bucketed in a uniform grid (`CellGrid`); cells are visited in square rings
//! around the sensor, and a whole cell is skipped when it is behind the scanner, beyond the
//! maximum range, or every beam it spans already hit something nearer than the cell. Far cells
//! that span few beams try only those beams on their segments. Each range is the least of the
//! same exact intersections as an unculled sweep, so the skipping changes no bit of any range.

use crate::geom::{Segment, Vec2};
use crate::world::cell_grid::{CellGrid, PaddedSegment};
use crate::world::{DoorStates, World};
use std::f64::consts::PI;

/// A disc obstacle (a pedestrian), metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    pub centre: Vec2,
    pub radius_m: f64,
}

/// The beams of a scanner in its own frame: nominal layout for index lookup plus the true
/// direction of each beam (nominal angle plus a fixed angle error).
#[derive(Clone, Debug, PartialEq)]
pub struct Beams {
    start_rad: f64,
    step_rad: f64,
    /// 1 / `step_rad`: index ranges are widened by `margin_beams`, far more than the rounding
    /// of a product instead of a quotient.
    per_step: f64,
    /// cos and sin of each beam's true angle in the sensor frame.
    dirs: Vec<(f64, f64)>,
    /// How many beams to widen each covered index range by (angle errors, rounding).
    margin_beams: f64,
    /// True when every beam points into the half plane ahead (x ≥ 0), so segments wholly
    /// behind can be skipped.
    front_only: bool,
}

impl Beams {
    /// `count` beams from `start_rad` every `step_rad`, each off by `angle_errors_rad[i]`
    /// (empty for none).
    pub fn new(start_rad: f64, step_rad: f64, count: usize, angle_errors_rad: &[f64]) -> Self {
        let err = |i: usize| angle_errors_rad.get(i).copied().unwrap_or(0.0);
        let max_err = (0..count).map(|i| err(i).abs()).fold(0.0, f64::max);
        let dirs = (0..count)
            .map(|i| {
                let (s, c) = (start_rad + step_rad * i as f64 + err(i)).sin_cos();
                (c, s)
            })
            .collect();
        let end = start_rad + step_rad * count.saturating_sub(1) as f64;
        let front_only =
            start_rad - max_err >= -PI / 2.0 - 1e-12 && end + max_err <= PI / 2.0 + 1e-12;
        let margin_beams = if step_rad > 0.0 {
            max_err / step_rad + 1e-6
        } else {
            0.0
        };
        Beams {
            start_rad,
            step_rad,
            per_step: 1.0 / step_rad,
            dirs,
            margin_beams,
            front_only,
        }
    }

    pub fn count(&self) -> usize {
        self.dirs.len()
    }

    /// Inclusive beam index range covered by sensor-frame angles `[lo, hi]` (lo ≤ hi, both
    /// within (-π, π]); `None` when empty.
    fn index_range(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        let n = self.dirs.len();
        if n == 0 {
            return None;
        }
        if self.step_rad <= 0.0 {
            return Some((0, n - 1));
        }
        let x0 = (lo - self.start_rad) * self.per_step - self.margin_beams;
        let x1 = (hi - self.start_rad) * self.per_step + self.margin_beams;
        let last = (n - 1) as f64;
        if !(x1 >= 0.0 && x0 <= last && x0 <= x1) {
            return None;
        }
        // ceil and floor by truncation (both are within [0, n-1] after clamping; avoids libm;
        // i64 converts in fewer instructions than usize).
        let x0 = if x0 > 0.0 { x0 } else { 0.0 };
        let mut i0 = x0 as i64;
        if (i0 as f64) < x0 {
            i0 += 1;
        }
        let i1 = (if x1 < last { x1 } else { last }) as i64;
        if i0 > i1 {
            return None;
        }
        Some((i0 as usize, i1 as usize))
    }
}

/// Obstacle segments ready for sweeping.
#[derive(Clone, Debug, Default)]
pub struct SweepCaster {
    /// (ax, ay, bx, by).
    segs: Vec<[f64; 4]>,
    /// Per segment: +1 visible only from its left (looking from a to b), -1 only from its right,
    /// 0 from both. A face of a solid is only seen from outside the solid.
    faces: Vec<i8>,
    /// The segments by cell, for skipping cells that cannot change a range.
    grid: CellGrid,
}

/// Whether `p` is inside the rectangle of half-width `half` around `s` (not its round caps).
fn inside_slab(s: &Segment, half: f64, p: Vec2) -> bool {
    let d = s.b - s.a;
    let len2 = d.norm_squared();
    if len2 == 0.0 {
        return false;
    }
    let t = (p - s.a).dot(&d) / len2;
    if !(0.0..=1.0).contains(&t) {
        return false;
    }
    let cross = (d.x * (p.y - s.a.y) - d.y * (p.x - s.a.x)).abs() / len2.sqrt();
    cross < half
}

/// Offsets to probe whether segment `a`–`b` is hidden inside solids: a step along it (its ends
/// pulled in by 1 µm) and a step across it (1 µm to either side). A segment whose whole length,
/// 1 µm to each side, lies in one solid per side (solids are convex slabs, so both probed ends in
/// one slab cover everything between) can only be reached from inside a solid, and is dropped:
/// the end caps where wall pieces of a polyline or abutting walls meet.
fn hidden_probe(a: Vec2, b: Vec2) -> (Vec2, Vec2) {
    let d = b - a;
    let unit = d / d.norm();
    (unit * 1e-6, Vec2::new(-unit.y, unit.x) * 1e-6)
}

/// Segments whose bounding box comes this close to the sensor test every beam they cover,
/// metres; farther ones skip beams that already hit something nearer than their bounding box.
const NEAR_M: f64 = 3.0;

/// Maximum error of [`fast_atan2`], radians (1e-5 in practice; 1e-4 leaves room).
const ATAN2_TOL_RAD: f64 = 1e-4;

/// Slack on distance lower bounds of whole cells, metres: covers the rounding of cell bounds and
/// of beam directions that are unit vectors only to the last bit.
const CELL_SLACK_M: f64 = 1e-6;

/// One scan's sensor: position, heading, beams and their world-frame directions.
struct Sensor<'a> {
    ox: f64,
    oy: f64,
    /// cos and sin of the heading.
    hc: f64,
    hs: f64,
    max_range_m: f64,
    beams: &'a Beams,
    /// World-frame direction `[x, y]` of each beam.
    dirs: &'a [[f64; 2]],
}

impl Sensor<'_> {
    /// Sensor-frame angle of a sensor-relative world vector.
    fn angle(&self, x: f64, y: f64) -> f64 {
        fast_atan2(-self.hs * x + self.hc * y, self.hc * x + self.hs * y)
    }
}

/// Calls `f(i0, i1)` for each inclusive beam index range covered by the sensor-frame angles
/// `[lo, hi]`, where `lo ≥ -2π`, `lo ≤ π` and `hi - lo < π + 1e-3` (wrapping past ±π).
fn for_each_range(beams: &Beams, lo: f64, hi: f64, mut f: impl FnMut(usize, usize)) {
    let mut range = |l: f64, h: f64| {
        if let Some((i0, i1)) = beams.index_range(l, h) {
            f(i0, i1);
        }
    };
    if hi <= PI {
        range(lo, hi);
    } else {
        range(lo, PI);
        range(-PI, hi - 2.0 * PI);
    }
    if lo < -PI {
        range(lo + 2.0 * PI, PI);
    }
}

impl SweepCaster {
    /// Segments seen from both sides.
    pub fn new(segments: &[Segment]) -> Self {
        let segs: Vec<[f64; 4]> = segments
            .iter()
            .filter(|s| s.length() > 0.0)
            .map(|s| [s.a.x, s.a.y, s.b.x, s.b.y])
            .collect();
        let faces = vec![0; segs.len()];
        let padded: Vec<PaddedSegment> = segs.iter().map(|s| (*s, 0.0)).collect();
        let grid = CellGrid::new(&padded);
        SweepCaster { segs, faces, grid }
    }

    /// The world's walls and doors with the doors in `doors` (their outline, from
    /// [`World::obstacle_outline`]). Each outline segment that is a face of a thick wall or door
    /// (solid on one side, free on the other, tested 1 mm either side of its midpoint) is culled
    /// when the sensor is on its solid side: a ray from outside a solid meets a front face first,
    /// so the ranges are unchanged and about half the segments are skipped. Segments hidden inside
    /// solids on both sides (see `hidden_probe`) are dropped.
    pub fn for_world(world: &World, doors: &DoorStates) -> Self {
        let mut c = Self::new(&world.obstacle_outline(doors));
        let mut solids: Vec<(Segment, f64)> = Vec::new();
        for w in &world.walls {
            for s in w.segments() {
                solids.push((s, w.thickness_m / 2.0));
            }
        }
        for (i, d) in world.doors.iter().enumerate() {
            solids.push((d.panel(doors.is_open(i)), d.thickness_m / 2.0));
        }
        solids.retain(|(_, h)| *h > 0.0);
        let padded: Vec<PaddedSegment> = solids
            .iter()
            .map(|(s, h)| ([s.a.x, s.a.y, s.b.x, s.b.y], *h))
            .collect();
        let near = CellGrid::new(&padded);
        let inside = |p: Vec2| {
            near.items_at(p.x, p.y).iter().any(|&k| {
                let (s, h) = &solids[k as usize];
                inside_slab(s, *h, p)
            })
        };
        for (k, g) in c.segs.iter().enumerate() {
            let (a, b) = (Vec2::new(g[0], g[1]), Vec2::new(g[2], g[3]));
            let d = b - a;
            let n = Vec2::new(-d.y, d.x) / d.norm() * 1e-3;
            let m = (a + b) / 2.0;
            c.faces[k] = match (inside(m + n), inside(m - n)) {
                (false, true) => 1,
                (true, false) => -1,
                _ => 0,
            };
        }
        let hidden: Vec<bool> = c
            .segs
            .iter()
            .map(|g| {
                let covered = |p: Vec2, q: Vec2| {
                    near.items_at(p.x, p.y).iter().any(|&k| {
                        let (s, h) = &solids[k as usize];
                        inside_slab(s, *h, p) && inside_slab(s, *h, q)
                    })
                };
                let (a, b) = (Vec2::new(g[0], g[1]), Vec2::new(g[2], g[3]));
                let (u, n) = hidden_probe(a, b);
                covered(a + u + n, b - u + n) && covered(a + u - n, b - u - n)
            })
            .collect();
        c.drop_segments(&hidden);
        c
    }

    /// Removes the segments marked in `drop` and rebuckets the rest.
    fn drop_segments(&mut self, drop: &[bool]) {
        let keep = |k: &usize| !drop[*k];
        let idx: Vec<usize> = (0..self.segs.len()).filter(keep).collect();
        self.segs = idx.iter().map(|&k| self.segs[k]).collect();
        self.faces = idx.iter().map(|&k| self.faces[k]).collect();
        let padded: Vec<PaddedSegment> = self.segs.iter().map(|s| (*s, 0.0)).collect();
        self.grid = CellGrid::new(&padded);
    }

    pub fn segment_count(&self) -> usize {
        self.segs.len()
    }

    /// Exact ranges of every beam from a sensor at `origin` facing `heading_rad`, against the
    /// segments and `discs`; beams with nothing within `max_range_m` get `max_range_m`.
    /// `out` is resized to the beam count.
    ///
    /// Each range is the least exact intersection over all segments, so the order in which
    /// segments are swept does not matter; cells of the grid are visited in rings around the
    /// sensor, and a cell is skipped (its segments not swept for it) when it is behind the
    /// scanner, beyond the maximum range, or every beam it covers already hit something nearer
    /// than the cell. Skipping only drops intersections that could not have been the least.
    pub fn cast(
        &self,
        origin: Vec2,
        heading_rad: f64,
        beams: &Beams,
        max_range_m: f64,
        discs: &[Disc],
        out: &mut Vec<f64>,
    ) {
        let n = beams.count();
        out.clear();
        out.resize(n, max_range_m);
        let (hs, hc) = heading_rad.sin_cos();
        // World-frame beam directions, collected rather than written into a zeroed buffer (the
        // zeroing cost more than the allocation).
        let dirs: Vec<[f64; 2]> = beams
            .dirs
            .iter()
            .map(|&(c, s)| [hc * c - hs * s, hs * c + hc * s])
            .collect();
        let sensor = Sensor {
            ox: origin.x,
            oy: origin.y,
            hc,
            hs,
            max_range_m,
            beams,
            dirs: &dirs,
        };
        self.sweep_cells(&sensor, out);
        for d in discs {
            sweep_disc(&sensor, d, out);
        }
    }

    /// Sweeps the segments of every cell that may hold a nearest hit, ring by ring outwards;
    /// stops when no beam can get a nearer hit from the rings left.
    fn sweep_cells(&self, s: &Sensor, out: &mut [f64]) {
        let g = &self.grid;
        if g.dims().0 == 0 {
            return;
        }
        let mut swept = vec![0u64; self.segs.len().div_ceil(64)];
        let (ci, cj) = g.cell_of(s.ox, s.oy);
        // Beams before `open` hit something within an earlier ring's bound; ranges only shrink
        // and the bound only grows, so they never need looking at again.
        let mut open = 0;
        for k in 0..=g.last_ring(ci, cj) {
            // Every point of ring k is at least this far from the sensor.
            let ring_min = (k - 1) as f64 * g.cell_m() - CELL_SLACK_M;
            if ring_min >= s.max_range_m {
                break;
            }
            if k >= 2 {
                open += out[open..].iter().take_while(|&&o| o <= ring_min).count();
                if open == out.len() {
                    break;
                }
            }
            for strip in g.ring(ci, cj, k).into_iter().flatten() {
                if in_view(s, g.cells_rect(strip)).is_some() {
                    for j in strip[2]..=strip[3] {
                        for i in strip[0]..=strip[1] {
                            self.sweep_cell(s, i, j, &mut swept, out);
                        }
                    }
                }
            }
        }
    }

    /// Sweeps the segments of cell `(i, j)` unless nothing in it can change a range. In a cell
    /// that spans few beams only those beams are tried (a hit inside the cell is on one of them,
    /// and the segment's hits outside the cell are found from the cells they are in); otherwise
    /// each segment is swept over all the beams it covers, once per scan (`swept`).
    fn sweep_cell(&self, s: &Sensor, i: usize, j: usize, swept: &mut [u64], out: &mut [f64]) {
        let g = &self.grid;
        if g.is_empty(i, j) {
            return;
        }
        let Some(span) = cell_span(s, g.cells_rect([i, i, j, j]), out) else {
            return;
        };
        for &k in g.items_in(j * g.dims().0 + i) {
            let (w, bit) = (k as usize / 64, 1u64 << (k % 64));
            if swept[w] & bit != 0 {
                continue;
            }
            let Some((seg, dmin)) = self.relative(s, k as usize) else {
                swept[w] |= bit; // culled from everywhere
                continue;
            };
            if span.beams <= FEW_BEAMS {
                for &(i0, i1) in &span.ranges[..span.len] {
                    hit_beams(s, &seg, i0, i1, dmin, out);
                }
            } else {
                swept[w] |= bit;
                let (lo, hi) = seg.angles(s);
                for_each_range(s.beams, lo, hi, |i0, i1| {
                    hit_beams(s, &seg, i0, i1, dmin, out)
                });
            }
        }
    }

    /// Segment `k` relative to the sensor and a lower bound on its hits' distances (0 near the
    /// sensor); `None` when it cannot be hit: wholly beyond the maximum range, wholly behind the
    /// scanner, edge-on, or a face seen from inside.
    fn relative(&self, s: &Sensor, k: usize) -> Option<(RelSegment, f64)> {
        let seg = &self.segs[k];
        let (px, py, qx, qy) = (seg[0] - s.ox, seg[1] - s.oy, seg[2] - s.ox, seg[3] - s.oy);
        // Ordered by comparison rather than f64::min/max (no NaN handling needed: finite).
        let (x0, x1) = if px <= qx { (px, qx) } else { (qx, px) };
        let (y0, y1) = if py <= qy { (py, qy) } else { (qy, py) };
        let d2 = box_distance_sq(x0, y0, x1, y1);
        if d2 >= s.max_range_m * s.max_range_m {
            return None;
        }
        if s.beams.front_only && s.hc * px + s.hs * py < 0.0 && s.hc * qx + s.hs * qy < 0.0 {
            return None;
        }
        let (ex, ey) = (qx - px, qy - py);
        let pe = px * ey - py * ex;
        // pe > 0: the sensor is on the segment's left.
        let face = self.faces[k];
        if pe == 0.0 || (face > 0 && pe < 0.0) || (face < 0 && pe > 0.0) {
            return None;
        }
        let dmin = if d2 <= NEAR_M * NEAR_M {
            0.0
        } else {
            d2.sqrt()
        };
        Some((RelSegment { px, py, ex, ey, pe }, dmin))
    }
}

/// A segment from `p` to `p + e` relative to the sensor; `pe` is the cross product p × e.
struct RelSegment {
    px: f64,
    py: f64,
    ex: f64,
    ey: f64,
    pe: f64,
}

impl RelSegment {
    /// The sensor-frame angular interval `[lo, hi]` the segment covers, widened by the error of
    /// [`fast_atan2`].
    fn angles(&self, s: &Sensor) -> (f64, f64) {
        let ap = s.angle(self.px, self.py);
        let aq = s.angle(self.px + self.ex, self.py + self.ey);
        let mut span = aq - ap;
        if span > PI {
            span -= 2.0 * PI;
        } else if span < -PI {
            span += 2.0 * PI;
        }
        let lo = if span >= 0.0 { ap } else { aq } - ATAN2_TOL_RAD;
        (lo, lo + span.abs() + 2.0 * ATAN2_TOL_RAD)
    }
}

/// Intersects a segment with beams `i0..=i1`, keeping each beam's nearest hit; beams that already
/// hit something within `dmin` are skipped.
fn hit_beams(s: &Sensor, g: &RelSegment, i0: usize, i1: usize, dmin: f64, out: &mut [f64]) {
    let beams = i0..i1 + 1;
    // Without branches: whether a beam hits depends on the quotients, and mispredicted
    // branches waiting on two divisions cost more than dividing for every beam.
    for (o, &[bx, by]) in out[beams.clone()].iter_mut().zip(&s.dirs[beams]) {
        let denom = bx * g.ey - by * g.ex;
        // A parallel beam (denom 0) needs no test of its own: pe ≠ 0, so t is ±∞ and is
        // rejected like any hit behind the sensor or beyond the beam's range.
        let t = g.pe / denom;
        let u = (g.px * by - g.py * bx) / denom;
        let miss = (*o <= dmin) | (t <= 0.0) | (t >= *o) | !(0.0..=1.0).contains(&u);
        *o = if miss { *o } else { t };
    }
}

/// Cells spanning at most this many beams try only those beams on their segments.
const FEW_BEAMS: usize = 12;

/// The beams a cell may still change: up to three inclusive index ranges (trimmed to beams
/// that have no hit nearer than the cell) and how many beams they hold in all (`usize::MAX`
/// when the sensor is in the cell).
struct BeamSpan {
    ranges: [(usize, usize); 3],
    len: usize,
    beams: usize,
}

/// Squared distance from the sensor (the origin) to the box `[x0, x1] × [y0, y1]`.
fn box_distance_sq(x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
    let gap = |a: f64, b: f64| {
        if a > 0.0 {
            a
        } else if b < 0.0 {
            -b
        } else {
            0.0
        }
    };
    let (gx, gy) = (gap(x0, x1), gap(y0, y1));
    gx * gx + gy * gy
}

/// The squared distance from the sensor to the world rectangle `rect`, or `None` when the
/// rectangle is beyond the maximum range or wholly behind a scanner that only looks ahead.
fn in_view(s: &Sensor, rect: [f64; 4]) -> Option<f64> {
    let (x0, y0, x1, y1) = (
        rect[0] - s.ox,
        rect[1] - s.oy,
        rect[2] - s.ox,
        rect[3] - s.oy,
    );
    // The largest sensor-frame x over the rectangle.
    let ahead = s.hc * if s.hc > 0.0 { x1 } else { x0 } + s.hs * if s.hs > 0.0 { y1 } else { y0 };
    if s.beams.front_only && ahead < 0.0 {
        return None;
    }
    let d2 = box_distance_sq(x0, y0, x1, y1);
    (d2 < s.max_range_m * s.max_range_m).then_some(d2)
}

/// The beams a segment inside the world rectangle `rect` could give a nearer hit than they
/// have; `None` when the rectangle is out of view ([`in_view`]) or every beam it spans already
/// hit something nearer than the rectangle.
fn cell_span(s: &Sensor, rect: [f64; 4], out: &[f64]) -> Option<BeamSpan> {
    let d2 = in_view(s, rect)?;
    let (x0, y0, x1, y1) = (
        rect[0] - s.ox,
        rect[1] - s.oy,
        rect[2] - s.ox,
        rect[3] - s.oy,
    );
    // The corners that bound the rectangle's angular interval, clockwise-most first, by where
    // the rectangle lies: west, across, east of the sensor (x), then south, across, north (y).
    let (xs, ys) = ([x0, x1], [y0, y1]);
    let region = |lo: f64, hi: f64| usize::from(hi >= 0.0) + usize::from(lo > 0.0);
    let [a, b] = match (region(x0, x1), region(y0, y1)) {
        (1, 1) => {
            let ranges = [(0, 0); 3];
            return Some(BeamSpan {
                ranges,
                len: 0,
                beams: usize::MAX,
            });
        }
        (2, 0) => [(0, 0), (1, 1)],
        (2, 1) => [(0, 0), (0, 1)],
        (2, 2) => [(1, 0), (0, 1)],
        (1, 2) => [(1, 0), (0, 0)],
        (0, 2) => [(1, 1), (0, 0)],
        (0, 1) => [(1, 1), (1, 0)],
        (0, 0) => [(0, 1), (1, 0)],
        _ => [(0, 1), (1, 1)], // (1, 0): south
    };
    let ap = s.angle(xs[a.0], ys[a.1]);
    let mut span = s.angle(xs[b.0], ys[b.1]) - ap;
    if span < 0.0 {
        span += 2.0 * PI;
    }
    let dmin = d2.sqrt() - CELL_SLACK_M;
    let mut bs = BeamSpan {
        ranges: [(0, 0); 3],
        len: 0,
        beams: 0,
    };
    let lo = ap - ATAN2_TOL_RAD;
    for_each_range(s.beams, lo, lo + span + 2.0 * ATAN2_TOL_RAD, |i0, i1| {
        let beams = &out[i0..i1 + 1];
        let open = |o: &f64| *o > dmin;
        if let Some(a) = beams.iter().position(open) {
            let b = beams.iter().rposition(open).unwrap_or(a);
            let (a, b) = (i0 + a, i0 + b);
            bs.ranges[bs.len] = (a, b);
            bs.len += 1;
            bs.beams += b - a + 1;
        }
    });
    (bs.len > 0).then_some(bs)
}

/// Intersects a disc with the beams it covers.
// Beams are indexed into parallel arrays (dirs, out): an index loop reads clearest.
#[allow(clippy::needless_range_loop)]
fn sweep_disc(s: &Sensor, d: &Disc, out: &mut [f64]) {
    let (cx, cy) = (d.centre.x - s.ox, d.centre.y - s.oy);
    let c2 = cx * cx + cy * cy;
    let r2 = d.radius_m * d.radius_m;
    if c2 <= r2 {
        return; // the sensor is inside the disc
    }
    let dist = c2.sqrt();
    if dist - d.radius_m >= s.max_range_m {
        return;
    }
    let cxs = s.hc * cx + s.hs * cy;
    if s.beams.front_only && cxs < -d.radius_m {
        return;
    }
    let a = s.angle(cx, cy);
    let half = (d.radius_m / dist).asin() + ATAN2_TOL_RAD;
    let mut hit = |i0: usize, i1: usize| {
        for i in i0..=i1 {
            let [bx, by] = s.dirs[i];
            let b = bx * cx + by * cy;
            let disc = b * b - (c2 - r2);
            if disc < 0.0 || b <= 0.0 {
                continue;
            }
            let t = b - disc.sqrt();
            if t > 0.0 && t < out[i] {
                out[i] = t;
            }
        }
    };
    let (lo, hi) = (a - half, a + half);
    for (l, h) in [
        (lo, hi),
        (lo + 2.0 * PI, hi + 2.0 * PI),
        (lo - 2.0 * PI, hi - 2.0 * PI),
    ] {
        let (l, h) = (l.max(-PI), h.min(PI));
        if l <= h
            && let Some((i0, i1)) = s.beams.index_range(l, h)
        {
            hit(i0, i1);
        }
    }
}

/// atan2 with a polynomial arctangent; maximum error about 1e-5 rad.
#[inline]
pub fn fast_atan2(y: f64, x: f64) -> f64 {
    let ax = x.abs();
    let ay = y.abs();
    // By comparison rather than f64::max/min, which also order NaNs.
    let (mn, mx) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if mx == 0.0 {
        return 0.0;
    }
    let a = mn / mx;
    let s = a * a;
    // Odd minimax polynomial for atan on [0, 1] (max error about 1e-5 rad).
    let r = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46
                    + s * (-0.116_432_87 + s * (0.052_653_32 - 0.011_721_20 * s)))));
    // Selects rather than branches (the octant is unpredictable).
    let r = if ay > ax { PI / 2.0 - r } else { r };
    let r = if x < 0.0 { PI - r } else { r };
    if y < 0.0 { -r } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_atan2_is_close_to_atan2() {
        let mut worst: f64 = 0.0;
        for i in 0..3600 {
            let a = (i as f64) * 0.1f64.to_radians() - PI + 1e-9;
            for r in [0.01, 1.0, 50.0] {
                let (y, x) = (a.sin() * r, a.cos() * r);
                worst = worst.max((fast_atan2(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < ATAN2_TOL_RAD / 2.0, "worst {worst}");
    }

    /// Every beam against every segment the caster may not cull by the segment's own
    /// orientation (edge-on, faces seen from inside): the ranges without any cell skipping.
    fn unculled(c: &SweepCaster, o: Vec2, heading: f64, beams: &Beams, max: f64) -> Vec<f64> {
        let (hs, hc) = heading.sin_cos();
        (0..beams.count())
            .map(|i| {
                let (bc, bs) = beams.dirs[i];
                let (bx, by) = (hc * bc - hs * bs, hs * bc + hc * bs);
                let mut best = max;
                for (k, g) in c.segs.iter().enumerate() {
                    let (px, py) = (g[0] - o.x, g[1] - o.y);
                    let (qx, qy) = (g[2] - o.x, g[3] - o.y);
                    let (ex, ey) = (qx - px, qy - py);
                    let pe = px * ey - py * ex;
                    let f = c.faces[k];
                    if pe == 0.0 || (f > 0 && pe < 0.0) || (f < 0 && pe > 0.0) {
                        continue;
                    }
                    let denom = bx * ey - by * ex;
                    if denom == 0.0 {
                        continue;
                    }
                    let t = pe / denom;
                    let u = (px * by - py * bx) / denom;
                    if t > 0.0 && t < best && (0.0..=1.0).contains(&u) {
                        best = t;
                    }
                }
                best
            })
            .collect()
    }

    fn institute_floor() -> World {
        let p =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/institute-floor.toml");
        crate::world::load_world(&p).expect("the shipped floor is valid")
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(300))]
        /// Skipping cells changes no bit of any range: anywhere on (and around) the institute
        /// floor, facing anywhere, with any doors open and both laser ranges, the grid sweep
        /// equals the least intersection over every beam and every segment.
        #[test]
        fn cell_skipping_changes_no_bit(x in -5.0f64..70.0, y in -5.0f64..40.0, th in -4.0f64..4.0,
                                        doors in proptest::collection::vec(proptest::bool::ANY, 77),
                                        far in proptest::bool::ANY, err_seed in 0u32..1000) {
            let world = institute_floor();
            let c = SweepCaster::for_world(&world, &DoorStates { open: doors });
            let errs: Vec<f64> = (0..181)
                .map(|i| ((i as f64 * 12.9898 + err_seed as f64).sin() * 43758.5453).fract() * 7e-4)
                .collect();
            let beams = Beams::new(-PI / 2.0, PI / 180.0, 181, &errs);
            let max = if far { 32.767 } else { 8.191 };
            let mut got = Vec::new();
            c.cast(Vec2::new(x, y), th, &beams, max, &[], &mut got);
            let want = unculled(&c, Vec2::new(x, y), th, &beams, max);
            for i in 0..181 {
                proptest::prop_assert_eq!(got[i].to_bits(), want[i].to_bits(), "beam {}: {} vs {}", i, got[i], want[i]);
            }
        }
    }

    #[test]
    fn square_room_ranges_are_exact() {
        let v = |x, y| Vec2::new(x, y);
        let segs = [
            Segment::new(v(-2.0, -2.0), v(2.0, -2.0)),
            Segment::new(v(2.0, -2.0), v(2.0, 2.0)),
            Segment::new(v(2.0, 2.0), v(-2.0, 2.0)),
            Segment::new(v(-2.0, 2.0), v(-2.0, -2.0)),
        ];
        let caster = SweepCaster::new(&segs);
        let step = 1f64.to_radians();
        let beams = Beams::new(-PI, step, 360, &[]);
        let mut out = Vec::new();
        caster.cast(Vec2::zeros(), 0.3, &beams, 30.0, &[], &mut out);
        for (i, r) in out.iter().enumerate() {
            let a = 0.3 - PI + step * i as f64;
            let exact = 2.0 / a.cos().abs().max(a.sin().abs());
            assert!((r - exact).abs() < 1e-9, "beam {i}: {r} vs {exact}");
        }
    }
}
