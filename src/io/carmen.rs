//! CARMEN text logs: the records placewords reads and writes, and the writer.
//!
//! Line formats (one message per line, whitespace-separated):
//! - `FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp`
//!   (beams spread over 180° right to left; `x y theta` is the pose the logger attached,
//!   which for simulated logs is the odometry pose);
//! - `ODOM x y theta tv rv accel ipc_timestamp host logger_timestamp`;
//! - `TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp`.
//!
//! Angles in radians, distances in metres.

use crate::geom::Pose2;
use std::fmt::Write as _;

/// A laser message (FLASER, RLASER or ROBOTLASER1 after reading).
#[derive(Clone, Debug, PartialEq)]
pub struct LaserRecord {
    /// Start angle of beam 0 relative to the robot heading, radians.
    pub start_angle_rad: f64,
    /// Field of view, radians.
    pub fov_rad: f64,
    /// Ranges, metres.
    pub ranges_m: Vec<f64>,
    /// The pose the logger attached to the scan (corrected pose in "corrected" logs).
    pub pose: Pose2,
    /// The odometry pose attached to the scan.
    pub odom: Pose2,
    pub ipc_timestamp: f64,
    pub host: String,
    pub logger_timestamp: f64,
}

/// An ODOM message.
#[derive(Clone, Debug, PartialEq)]
pub struct OdomRecord {
    pub pose: Pose2,
    pub tv_m_s: f64,
    pub rv_rad_s: f64,
    pub accel_m_s2: f64,
    pub ipc_timestamp: f64,
    pub host: String,
    pub logger_timestamp: f64,
}

/// A TRUEPOS message: ground truth beside the odometry pose.
#[derive(Clone, Debug, PartialEq)]
pub struct TruePosRecord {
    pub truth: Pose2,
    pub odom: Pose2,
    pub ipc_timestamp: f64,
    pub host: String,
    pub logger_timestamp: f64,
}

/// One message of a log, in file order.
#[derive(Clone, Debug, PartialEq)]
pub enum LogRecord {
    Laser(LaserRecord),
    Odom(OdomRecord),
    TruePos(TruePosRecord),
    /// `PARAM name value`.
    Param {
        name: String,
        value: String,
    },
}

/// Appends one record as a CARMEN line (with trailing newline). Lasers are written as FLASER.
pub fn write_record(out: &mut String, rec: &LogRecord) {
    match rec {
        LogRecord::Laser(l) => {
            let _ = write!(out, "FLASER {}", l.ranges_m.len());
            for r in &l.ranges_m {
                let _ = write!(out, " {r:.3}");
            }
            let _ = writeln!(
                out,
                " {} {} {}",
                fmt_pose(&l.pose),
                fmt_pose(&l.odom),
                fmt_stamp(l.ipc_timestamp, &l.host, l.logger_timestamp)
            );
        }
        LogRecord::Odom(o) => {
            let _ = writeln!(
                out,
                "ODOM {} {:.6} {:.6} {:.6} {}",
                fmt_pose(&o.pose),
                o.tv_m_s,
                o.rv_rad_s,
                o.accel_m_s2,
                fmt_stamp(o.ipc_timestamp, &o.host, o.logger_timestamp)
            );
        }
        LogRecord::TruePos(t) => {
            let _ = writeln!(
                out,
                "TRUEPOS {} {} {}",
                fmt_pose(&t.truth),
                fmt_pose(&t.odom),
                fmt_stamp(t.ipc_timestamp, &t.host, t.logger_timestamp)
            );
        }
        LogRecord::Param { name, value } => {
            let _ = writeln!(out, "PARAM {name} {value}");
        }
    }
}

fn fmt_pose(p: &Pose2) -> String {
    format!("{:.6} {:.6} {:.6}", p.x, p.y, p.theta)
}

fn fmt_stamp(ipc: f64, host: &str, logger: f64) -> String {
    format!("{ipc:.6} {host} {logger:.6}")
}
