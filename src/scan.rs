//! One planar laser scan and the layout of its beams.
//!
//! Beam `i` points at `start_angle_rad + i * step_rad` in the sensor frame (0 = straight ahead,
//! counter-clockwise positive), and the sensor sits at `mount` in the robot frame. A beam with no
//! return reports `max_range_m` (or more), as SICK scanners and CARMEN logs do.

use crate::geom::Pose2;

/// Where beams point and how far they reach. Any beam count and field of view.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamLayout {
    /// Angle of beam 0 in the sensor frame, radians (−π/2 for a 180° scanner sweeping right to left).
    pub start_angle_rad: f64,
    /// Angle between neighbouring beams, radians.
    pub step_rad: f64,
    /// Number of beams.
    pub count: usize,
    /// Readings at or beyond this range are "no return", metres.
    pub max_range_m: f64,
    /// Sensor pose in the robot frame (the LMS200 on a P3-DX sits 0.021 m ahead of the centre).
    pub mount: Pose2,
}

impl BeamLayout {
    /// `count` beams spread evenly over `fov_rad`, centred straight ahead (CARMEN's convention).
    pub fn centered(count: usize, fov_rad: f64, max_range_m: f64, mount: Pose2) -> Self {
        let step_rad = if count > 1 {
            fov_rad / (count - 1) as f64
        } else {
            0.0
        };
        BeamLayout {
            start_angle_rad: -fov_rad / 2.0,
            step_rad,
            count,
            max_range_m,
            mount,
        }
    }

    /// Field of view from the first to the last beam, radians.
    pub fn fov_rad(&self) -> f64 {
        self.step_rad * self.count.saturating_sub(1) as f64
    }

    /// Nominal angle of beam `i` in the sensor frame, radians.
    pub fn beam_angle_rad(&self, i: usize) -> f64 {
        self.start_angle_rad + self.step_rad * i as f64
    }
}

/// One scan: a range per beam, metres.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    pub layout: BeamLayout,
    pub ranges_m: Vec<f64>,
    /// Acquisition time, seconds since the start of the log or run.
    pub time_s: f64,
}

impl Scan {
    /// Whether beam `i` returned from an obstacle (as opposed to reporting "nothing in range").
    pub fn is_hit(&self, i: usize) -> bool {
        let r = self.ranges_m[i];
        r.is_finite() && r > 0.0 && r < self.layout.max_range_m
    }
}
