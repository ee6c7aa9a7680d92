//! Exact planar distance queries (f64) and a broad-phase index over thick segments.
//!
//! Validation and rendering work on centre lines with a half thickness: a thick wall segment is
//! treated as the capsule of its centre line (slightly conservative at wall ends, by at most
//! half the thickness). The broad phase is parry's `Bvh` over padded f32 boxes; every candidate
//! it returns is then measured exactly in f64.

use crate::geom::{Segment, Vec2, segment_distance};
use parry2d::bounding_volume::Aabb;
use parry2d::math::Vector;
use parry2d::partitioning::{Bvh, BvhBuildStrategy};

/// A thick segment: centre line and half its thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickSegment {
    pub seg: Segment,
    pub half_thickness_m: f64,
}

impl ThickSegment {
    /// Clearance from a point to the segment's surface (negative inside).
    pub fn clearance_to_point(&self, p: Vec2) -> f64 {
        self.seg.distance_to_point(p) - self.half_thickness_m
    }

    /// Clearance from a segment (for example a leg swept by a disc's centre) to the surface.
    pub fn clearance_to_segment(&self, s: Segment) -> f64 {
        segment_distance(self.seg, s) - self.half_thickness_m
    }
}

/// A broad-phase index over thick segments; queries return candidate indices whose boxes come
/// within a margin of the query, and callers measure exactly.
pub struct SegmentIndex {
    items: Vec<ThickSegment>,
    bvh: Bvh,
}

fn padded_aabb(a: Vec2, b: Vec2, pad: f64) -> Aabb {
    let lo = a.inf(&b);
    let hi = a.sup(&b);
    // f32 rounding: pad by a relative amount as well.
    let rel = 1e-5 * (lo.abs().max() + hi.abs().max()) + 1e-3;
    let p = pad + rel;
    Aabb::new(
        Vector::new((lo.x - p) as f32, (lo.y - p) as f32),
        Vector::new((hi.x + p) as f32, (hi.y + p) as f32),
    )
}

impl SegmentIndex {
    pub fn new(items: Vec<ThickSegment>) -> Self {
        let boxes: Vec<Aabb> = items
            .iter()
            .map(|t| padded_aabb(t.seg.a, t.seg.b, t.half_thickness_m))
            .collect();
        let bvh = if boxes.is_empty() {
            Bvh::new()
        } else {
            Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes)
        };
        SegmentIndex { items, bvh }
    }

    /// Indices of items whose box comes within `margin` of the box of `s`.
    pub fn candidates(&self, s: Segment, margin: f64) -> Vec<usize> {
        if self.items.is_empty() {
            return Vec::new();
        }
        let q = padded_aabb(s.a, s.b, margin);
        let mut out: Vec<usize> = self.bvh.intersect_aabb(&q).map(|i| i as usize).collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The item with the least surface clearance to `s` among those closer than `margin`, as
    /// (index, clearance).
    pub fn nearest_within(&self, s: Segment, margin: f64) -> Option<(usize, f64)> {
        self.candidates(s, margin)
            .into_iter()
            .map(|i| (i, self.items[i].clearance_to_segment(s)))
            .filter(|(_, c)| *c < margin)
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Vec2::new(ax, ay), Vec2::new(bx, by))
    }

    #[test]
    fn index_finds_near_segment() {
        let idx = SegmentIndex::new(vec![
            ThickSegment {
                seg: seg(0.0, 0.0, 10.0, 0.0),
                half_thickness_m: 0.05,
            },
            ThickSegment {
                seg: seg(0.0, 5.0, 10.0, 5.0),
                half_thickness_m: 0.05,
            },
        ]);
        let (i, c) = idx.nearest_within(seg(2.0, 0.3, 3.0, 0.3), 1.0).unwrap();
        assert_eq!(i, 0);
        assert!((c - 0.25).abs() < 1e-9);
    }
}
