//! Planar geometry shared by every part: points, poses, angle helpers, and the two pose frames.
//!
//! Code works in metres and radians; files use degrees. Truth and odometry are different
//! types ([`TruePose`], [`OdomPose`]) so the recognizer, which only takes `OdomPose`, cannot be
//! handed ground truth by accident.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A point or vector in the plane, metres.
pub type Vec2 = nalgebra::Vector2<f64>;

/// Wraps an angle to (-π, π].
pub fn wrap_angle(a: f64) -> f64 {
    // `%` is a division in software (fmod); below 2π in size it would return `a` itself, so
    // skip it there (the result is bit-identical).
    let mut r = if a.abs() < 2.0 * PI {
        a
    } else {
        a % (2.0 * PI)
    };
    if r <= -PI {
        r += 2.0 * PI;
    } else if r > PI {
        r -= 2.0 * PI;
    }
    r
}

/// A rigid 2D pose: position in metres, heading in radians.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose2 {
    pub x: f64,
    pub y: f64,
    pub theta: f64,
}

impl Pose2 {
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
    };

    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose2 { x, y, theta }
    }

    pub fn position(&self) -> Vec2 {
        Vec2::new(self.x, self.y)
    }

    /// `self ⊕ other`: `other` expressed in `self`'s frame, mapped into the parent frame.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2 {
            x: self.x + c * other.x - s * other.y,
            y: self.y + s * other.x + c * other.y,
            theta: wrap_angle(self.theta + other.theta),
        }
    }

    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2 {
            x: -c * self.x - s * self.y,
            y: s * self.x - c * self.y,
            theta: wrap_angle(-self.theta),
        }
    }

    /// The motion from `self` to `other`, in `self`'s frame: `self⁻¹ ⊕ other`.
    pub fn between(&self, other: &Pose2) -> Pose2 {
        self.inverse().compose(other)
    }

    /// Maps a point given in this pose's frame into the parent frame.
    pub fn transform_point(&self, p: Vec2) -> Vec2 {
        let (s, c) = self.theta.sin_cos();
        Vec2::new(self.x + c * p.x - s * p.y, self.y + s * p.x + c * p.y)
    }

    pub fn distance(&self, other: &Pose2) -> f64 {
        ((self.x - other.x).powi(2) + (self.y - other.y).powi(2)).sqrt()
    }
}

/// A robot pose in the world frame: ground truth. Only the simulator, log readers and
/// evaluation handle it.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct TruePose(pub Pose2);

/// A robot pose in the odometry frame, as dead reckoning reports it. The recognizer's only
/// notion of position.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct OdomPose(pub Pose2);

/// A straight segment between two points, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub a: Vec2,
    pub b: Vec2,
}

impl Segment {
    pub fn new(a: Vec2, b: Vec2) -> Self {
        Segment { a, b }
    }

    pub fn length(&self) -> f64 {
        (self.b - self.a).norm()
    }

    /// Shortest distance from `p` to any point of the segment.
    pub fn distance_to_point(&self, p: Vec2) -> f64 {
        (p - self.point_at(self.project(p))).norm()
    }

    /// The fraction along the segment (0 at `a`, 1 at `b`) of its point nearest to `p`; 0 for a
    /// segment of no length.
    pub fn project(&self, p: Vec2) -> f64 {
        let d = self.b - self.a;
        let len2 = d.norm_squared();
        if len2 == 0.0 {
            return 0.0;
        }
        ((p - self.a).dot(&d) / len2).clamp(0.0, 1.0)
    }

    /// The point at fraction `t` along the segment.
    pub fn point_at(&self, t: f64) -> Vec2 {
        self.a + (self.b - self.a) * t
    }
}

/// Cross product z of two planar vectors.
fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Whether the closed segments `s` and `t` share a point.
pub fn segments_intersect(s: Segment, t: Segment) -> bool {
    let d1 = cross(t.b - t.a, s.a - t.a);
    let d2 = cross(t.b - t.a, s.b - t.a);
    let d3 = cross(s.b - s.a, t.a - s.a);
    let d4 = cross(s.b - s.a, t.b - s.a);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    // Touching or collinear cases: an endpoint lies on the other segment.
    const EPS: f64 = 1e-12;
    t.distance_to_point(s.a) <= EPS
        || t.distance_to_point(s.b) <= EPS
        || s.distance_to_point(t.a) <= EPS
        || s.distance_to_point(t.b) <= EPS
}

/// Where `s` and `t` cross each other properly (each passes from one side of the other to the
/// other side), `None` when they do not, touch only, or are parallel.
pub fn crossing_point(s: Segment, t: Segment) -> Option<Vec2> {
    let (ds, dt) = (s.b - s.a, t.b - t.a);
    let d1 = cross(dt, s.a - t.a);
    let d2 = cross(dt, s.b - t.a);
    let d3 = cross(ds, t.a - s.a);
    let d4 = cross(ds, t.b - s.a);
    let opposite = |p: f64, q: f64| (p > 0.0 && q < 0.0) || (p < 0.0 && q > 0.0);
    (opposite(d1, d2) && opposite(d3, d4)).then(|| s.a + ds * (d1 / (d1 - d2)))
}

/// Exact shortest distance between two closed segments (0 when they cross).
pub fn segment_distance(s: Segment, t: Segment) -> f64 {
    if segments_intersect(s, t) {
        return 0.0;
    }
    t.distance_to_point(s.a)
        .min(t.distance_to_point(s.b))
        .min(s.distance_to_point(t.a))
        .min(s.distance_to_point(t.b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment::new(Vec2::new(ax, ay), Vec2::new(bx, by))
    }

    #[test]
    fn crossing_segments_have_zero_distance() {
        assert_eq!(
            segment_distance(seg(0.0, 0.0, 2.0, 2.0), seg(0.0, 2.0, 2.0, 0.0)),
            0.0
        );
    }

    #[test]
    fn parallel_segments_measure_their_gap() {
        let d = segment_distance(seg(0.0, 0.0, 2.0, 0.0), seg(0.5, 1.5, 1.5, 1.5));
        assert!((d - 1.5).abs() < 1e-12);
    }

    #[test]
    fn wrap_angle_stays_in_half_open_interval() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.5) - 0.5).abs() < 1e-12);
        assert!((wrap_angle(-2.0 * PI - 0.25) + 0.25).abs() < 1e-12);
    }

    #[test]
    fn between_undoes_compose() {
        let a = Pose2::new(1.0, -2.0, 0.7);
        let d = Pose2::new(0.3, 0.1, -0.2);
        let b = a.compose(&d);
        let back = a.between(&b);
        assert!((back.x - d.x).abs() < 1e-12 && (back.y - d.y).abs() < 1e-12);
        assert!((back.theta - d.theta).abs() < 1e-12);
    }
}
