//! Fast exact 2D laser ray casting by a whole-scan angular sweep.
//!
//! Instead of casting each beam into an acceleration structure, every obstacle segment is
//! projected onto the range of beam indices it covers (from the angles of its two endpoints seen
//! from the sensor), and only those beams are intersected with it. Segments behind a sensor whose
//! field of view is at most 180°, and segments outside the square of the maximum range, are
//! skipped before any angle is computed. Discs (people) are handled the same way, analytically.
//! Everything is f64 and each hit is an exact ray/segment intersection.

use crate::geom::{Segment, Vec2};
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
        let x0 = (lo - self.start_rad) / self.step_rad - self.margin_beams;
        let x1 = (hi - self.start_rad) / self.step_rad + self.margin_beams;
        let last = (n - 1) as f64;
        if x1 < 0.0 || x0 > last || x0 > x1 {
            return None;
        }
        // ceil and floor by truncation (both are within [0, n-1] after clamping; avoids libm).
        let x0 = x0.max(0.0);
        let mut i0 = x0 as usize;
        if (i0 as f64) < x0 {
            i0 += 1;
        }
        let i1 = (x1.min(last) as usize).min(n - 1);
        if i0 > i1 {
            return None;
        }
        Some((i0, i1))
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

/// Segments whose bounding box comes this close to the sensor are swept first, metres.
const NEAR_M: f64 = 3.0;

/// Maximum error of [`fast_atan2`], radians (1e-5 in practice; 1e-4 leaves room).
const ATAN2_TOL_RAD: f64 = 1e-4;

impl SweepCaster {
    /// Segments seen from both sides.
    pub fn new(segments: &[Segment]) -> Self {
        let segs: Vec<[f64; 4]> = segments
            .iter()
            .filter(|s| s.length() > 0.0)
            .map(|s| [s.a.x, s.a.y, s.b.x, s.b.y])
            .collect();
        let faces = vec![0; segs.len()];
        SweepCaster { segs, faces }
    }

    /// The world's walls and doors with the doors in `doors` (their outline, from
    /// [`World::obstacle_outline`]). Each outline segment that is a face of a thick wall or door
    /// (solid on one side, free on the other, tested 1 mm either side of its midpoint) is culled
    /// when the sensor is on its solid side: a ray from outside a solid meets a front face first,
    /// so the ranges are unchanged and about half the segments are skipped.
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
        let inside = |p: Vec2| {
            solids
                .iter()
                .any(|(s, h)| *h > 0.0 && inside_slab(s, *h, p))
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
        c
    }

    pub fn segment_count(&self) -> usize {
        self.segs.len()
    }

    /// Exact ranges of every beam from a sensor at `origin` facing `heading_rad`, against the
    /// segments and `discs`; beams with nothing within `max_range_m` get `max_range_m`.
    /// `out` is resized to the beam count.
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
        // World-frame beam directions.
        let mut dx = [0.0f64; 512];
        let mut dy = [0.0f64; 512];
        let mut heap;
        let (dx, dy): (&mut [f64], &mut [f64]) = if n <= 512 {
            (&mut dx[..n], &mut dy[..n])
        } else {
            heap = (vec![0.0; n], vec![0.0; n]);
            (&mut heap.0[..], &mut heap.1[..])
        };
        for (i, &(c, s)) in beams.dirs.iter().enumerate() {
            dx[i] = hc * c - hs * s;
            dy[i] = hs * c + hc * s;
        }
        let (ox, oy) = (origin.x, origin.y);
        let r = max_range_m;
        // Near segments first, so that far ones can skip beams that already hit something
        // closer than the segment's nearest point (a lower bound from its bounding box).
        let mut process = |k: usize, dmin: f64| {
            let seg = &self.segs[k];
            let face = self.faces[k];
            let (px, py, qx, qy) = (seg[0] - ox, seg[1] - oy, seg[2] - ox, seg[3] - oy);
            // Into the sensor frame.
            let (pxs, pys) = (hc * px + hs * py, -hs * px + hc * py);
            let (qxs, qys) = (hc * qx + hs * qy, -hs * qx + hc * qy);
            if beams.front_only && pxs < 0.0 && qxs < 0.0 {
                return;
            }
            let ex = qx - px;
            let ey = qy - py;
            let pe = px * ey - py * ex;
            // pe > 0: the sensor is on the segment's left.
            if pe == 0.0 || (face > 0 && pe < 0.0) || (face < 0 && pe > 0.0) {
                // Edge-on (the line passes through the sensor), or a face seen from inside.
                return;
            }
            let ap = fast_atan2(pys, pxs);
            let aq = fast_atan2(qys, qxs);
            let mut span = aq - ap;
            if span > PI {
                span -= 2.0 * PI;
            } else if span < -PI {
                span += 2.0 * PI;
            }
            let lo = if span >= 0.0 { ap } else { aq } - ATAN2_TOL_RAD;
            let hi = lo + span.abs() + 2.0 * ATAN2_TOL_RAD;
            let mut hit = |i0: usize, i1: usize| {
                for i in i0..=i1 {
                    if out[i] <= dmin {
                        continue;
                    }
                    let (bx, by) = (dx[i], dy[i]);
                    let denom = bx * ey - by * ex;
                    if denom == 0.0 {
                        continue;
                    }
                    let t = pe / denom;
                    if t <= 0.0 || t >= out[i] {
                        continue;
                    }
                    let u = (px * by - py * bx) / denom;
                    if (0.0..=1.0).contains(&u) {
                        out[i] = t;
                    }
                }
            };
            if hi <= PI {
                if let Some((i0, i1)) = beams.index_range(lo, hi) {
                    hit(i0, i1);
                }
            } else {
                if let Some((i0, i1)) = beams.index_range(lo, PI) {
                    hit(i0, i1);
                }
                if let Some((i0, i1)) = beams.index_range(-PI, hi - 2.0 * PI) {
                    hit(i0, i1);
                }
            }
            if lo < -PI
                && let Some((i0, i1)) = beams.index_range(lo + 2.0 * PI, PI)
            {
                hit(i0, i1);
            }
        };
        let near2 = NEAR_M * NEAR_M;
        let r2 = r * r;
        let mut far: Vec<(u32, f64)> = Vec::with_capacity(self.segs.len());
        for (k, seg) in self.segs.iter().enumerate() {
            let (px, py, qx, qy) = (seg[0] - ox, seg[1] - oy, seg[2] - ox, seg[3] - oy);
            let bx = if px * qx <= 0.0 {
                0.0
            } else {
                px.abs().min(qx.abs())
            };
            let by = if py * qy <= 0.0 {
                0.0
            } else {
                py.abs().min(qy.abs())
            };
            let d2 = bx * bx + by * by;
            if d2 >= r2 {
                continue; // wholly beyond the maximum range
            }
            if d2 <= near2 {
                process(k, 0.0);
            } else {
                far.push((k as u32, d2));
            }
        }
        for (k, d2) in far {
            process(k as usize, d2.sqrt());
        }
        for d in discs {
            let (cx, cy) = (d.centre.x - ox, d.centre.y - oy);
            let c2 = cx * cx + cy * cy;
            let r2 = d.radius_m * d.radius_m;
            if c2 <= r2 {
                continue; // the sensor is inside the disc
            }
            let dist = c2.sqrt();
            if dist - d.radius_m >= r {
                continue;
            }
            let (cxs, cys) = (hc * cx + hs * cy, -hs * cx + hc * cy);
            if beams.front_only && cxs < -d.radius_m {
                continue;
            }
            let a = fast_atan2(cys, cxs);
            let half = (d.radius_m / dist).asin() + ATAN2_TOL_RAD;
            let mut hit = |i0: usize, i1: usize| {
                for i in i0..=i1 {
                    let b = dx[i] * cx + dy[i] * cy;
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
                    && let Some((i0, i1)) = beams.index_range(l, h)
                {
                    hit(i0, i1);
                }
            }
        }
    }
}

/// atan2 with a polynomial arctangent; maximum error about 1e-5 rad.
#[inline]
pub fn fast_atan2(y: f64, x: f64) -> f64 {
    let ax = x.abs();
    let ay = y.abs();
    let mx = ax.max(ay);
    if mx == 0.0 {
        return 0.0;
    }
    let a = ax.min(ay) / mx;
    let s = a * a;
    // Odd minimax polynomial for atan on [0, 1] (max error about 1e-5 rad).
    let mut r = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46
                    + s * (-0.116_432_87 + s * (0.052_653_32 - 0.011_721_20 * s)))));
    if ay > ax {
        r = PI / 2.0 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
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
