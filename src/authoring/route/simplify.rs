//! Douglas–Peucker simplification of a pixel path, never accepting a leg too close to a wall.

use crate::geom::{Segment, Vec2};

/// Douglas–Peucker that also splits any leg failing `leg_ok`. Keeps both ends.
pub(super) fn simplify(pts: &[Vec2], tol: f64, leg_ok: &dyn Fn(Vec2, Vec2) -> bool) -> Vec<Vec2> {
    let n = pts.len();
    if n <= 2 {
        return pts.to_vec();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0usize, n - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (far, dmax) = farthest(pts, a, b);
        if dmax > tol || !leg_ok(pts[a], pts[b]) {
            let m = split_point(pts, a, b, far);
            keep[m] = true;
            stack.push((a, m));
            stack.push((m, b));
        }
    }
    pts.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(p, _)| *p)
        .collect()
}

/// The point strictly between `a` and `b` farthest from the segment `pts[a]`–`pts[b]`, and its
/// distance (the first of equals; `a + 1` and -1 when there is none).
fn farthest(pts: &[Vec2], a: usize, b: usize) -> (usize, f64) {
    let seg = Segment::new(pts[a], pts[b]);
    let (mut far, mut dmax) = (a + 1, -1.0);
    for (k, p) in pts.iter().enumerate().take(b).skip(a + 1) {
        let d = seg.distance_to_point(*p);
        if d > dmax {
            dmax = d;
            far = k;
        }
    }
    (far, dmax)
}

/// Where to split the leg from `a` to `b`: at the farthest point `far`, but in the middle for a
/// closed ring, which starts and ends on one point.
fn split_point(pts: &[Vec2], a: usize, b: usize, far: usize) -> usize {
    if (pts[a] - pts[b]).norm() < 1e-9 {
        (a + b) / 2
    } else {
        far
    }
}
