//! The ROS 2 messages placewords writes and reads, their CDR layout ([`super::cdr`]) and their
//! `ros2msg` schema text (the definition, then each nested type after a line of `=`, as
//! `ros2 bag record` embeds it in MCAP).
//!
//! Poses are planar: a [`Pose2`] becomes `z = 0` and a rotation about z by `theta`
//! (quaternion `(0, 0, sin θ/2, cos θ/2)`); read back, the yaw of any quaternion.

use super::cdr::{CdrError, CdrReader, CdrWriter};
use crate::geom::Pose2;

/// `sensor_msgs/msg/LaserScan`.
pub const LASER_SCAN: &str = "sensor_msgs/msg/LaserScan";
/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: &str = "nav_msgs/msg/Odometry";
/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";
/// `geometry_msgs/msg/PoseStamped`.
pub const POSE_STAMPED: &str = "geometry_msgs/msg/PoseStamped";
/// `std_msgs/msg/String`.
pub const STRING: &str = "std_msgs/msg/String";

const SEP: &str =
    "================================================================================\n";

const TIME_DEF: &str = "int32 sec\nuint32 nanosec\n";
const HEADER_DEF: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const POINT_DEF: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION_DEF: &str = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const VECTOR3_DEF: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const POSE_DEF: &str = "Point position\nQuaternion orientation\n";

/// The `ros2msg` schema text of `type_name` (one of the constants above), `None` for others.
pub fn schema_text(type_name: &str) -> Option<String> {
    let dep = |name: &str, def: &str| format!("{SEP}MSG: {name}\n{def}");
    let header = dep("std_msgs/Header", HEADER_DEF) + &dep("builtin_interfaces/Time", TIME_DEF);
    let pose = dep("geometry_msgs/Pose", POSE_DEF)
        + &dep("geometry_msgs/Point", POINT_DEF)
        + &dep("geometry_msgs/Quaternion", QUATERNION_DEF);
    Some(match type_name {
        LASER_SCAN => format!(
            "std_msgs/Header header\n\
             float32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n\
             float32 time_increment\nfloat32 scan_time\n\
             float32 range_min\nfloat32 range_max\n\
             float32[] ranges\nfloat32[] intensities\n{header}"
        ),
        ODOMETRY => format!(
            "std_msgs/Header header\nstring child_frame_id\n\
             geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n{header}{}{pose}{}{}{}",
            dep(
                "geometry_msgs/PoseWithCovariance",
                "Pose pose\nfloat64[36] covariance\n"
            ),
            dep(
                "geometry_msgs/TwistWithCovariance",
                "Twist twist\nfloat64[36] covariance\n"
            ),
            dep("geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"),
            dep("geometry_msgs/Vector3", VECTOR3_DEF),
        ),
        TF_MESSAGE => format!(
            "geometry_msgs/TransformStamped[] transforms\n{}{header}{}{}{}",
            dep(
                "geometry_msgs/TransformStamped",
                "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"
            ),
            dep(
                "geometry_msgs/Transform",
                "Vector3 translation\nQuaternion rotation\n"
            ),
            dep("geometry_msgs/Vector3", VECTOR3_DEF),
            dep("geometry_msgs/Quaternion", QUATERNION_DEF),
        ),
        POSE_STAMPED => format!("std_msgs/Header header\ngeometry_msgs/Pose pose\n{header}{pose}"),
        STRING => "string data\n".to_string(),
        _ => return None,
    })
}

/// `builtin_interfaces/Time` as seconds; written as whole seconds and nanoseconds.
pub fn write_time(w: &mut CdrWriter, t_s: f64) {
    let ns = time_ns(t_s);
    w.i32((ns / 1_000_000_000) as i32);
    w.u32((ns % 1_000_000_000) as u32);
}

/// Seconds as whole nanoseconds (negative and non-finite times as 0).
pub fn time_ns(t_s: f64) -> u64 {
    if t_s.is_finite() && t_s > 0.0 {
        (t_s * 1e9).round() as u64
    } else {
        0
    }
}

fn read_time(r: &mut CdrReader<'_>) -> Result<f64, CdrError> {
    let sec = r.i32("header.stamp.sec")?;
    let nanosec = r.u32("header.stamp.nanosec")?;
    Ok(sec as f64 + nanosec as f64 * 1e-9)
}

/// `std_msgs/Header`.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Seconds.
    pub stamp_s: f64,
    pub frame_id: String,
}

impl Header {
    fn write(&self, w: &mut CdrWriter) {
        write_time(w, self.stamp_s);
        w.string(&self.frame_id);
    }

    fn read(r: &mut CdrReader<'_>) -> Result<Header, CdrError> {
        Ok(Header {
            stamp_s: read_time(r)?,
            frame_id: r.string("header.frame_id")?,
        })
    }
}

fn write_pose(w: &mut CdrWriter, p: &Pose2) {
    for v in [p.x, p.y, 0.0] {
        w.f64(v);
    }
    let (s, c) = (p.theta / 2.0).sin_cos();
    for v in [0.0, 0.0, s, c] {
        w.f64(v);
    }
}

/// A position and quaternion, read as the planar pose (x, y, yaw).
fn read_pose(r: &mut CdrReader<'_>, what: &'static str) -> Result<Pose2, CdrError> {
    let x = r.f64(what)?;
    let y = r.f64(what)?;
    let _z = r.f64(what)?;
    let (qx, qy, qz, qw) = (r.f64(what)?, r.f64(what)?, r.f64(what)?, r.f64(what)?);
    let yaw = (2.0 * (qw * qz + qx * qy)).atan2(1.0 - 2.0 * (qy * qy + qz * qz));
    Ok(Pose2::new(x, y, yaw))
}

/// `sensor_msgs/msg/LaserScan` (no intensities are written; those read are skipped).
#[derive(Clone, Debug, PartialEq)]
pub struct LaserScan {
    pub header: Header,
    /// Angle of the first beam, radians.
    pub angle_min: f32,
    /// Angle of the last beam, radians.
    pub angle_max: f32,
    /// Angle between beams, radians.
    pub angle_increment: f32,
    /// Time between beams, seconds.
    pub time_increment: f32,
    /// Time between scans, seconds.
    pub scan_time: f32,
    /// Metres.
    pub range_min: f32,
    /// Metres.
    pub range_max: f32,
    /// Metres.
    pub ranges: Vec<f32>,
}

impl LaserScan {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        for v in [
            self.angle_min,
            self.angle_max,
            self.angle_increment,
            self.time_increment,
            self.scan_time,
            self.range_min,
            self.range_max,
        ] {
            w.f32(v);
        }
        w.count(self.ranges.len());
        for r in &self.ranges {
            w.f32(*r);
        }
        w.count(0);
        w.into_bytes()
    }

    pub fn decode(bytes: &[u8]) -> Result<LaserScan, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        let header = Header::read(&mut r)?;
        let mut f = [0f32; 7];
        for v in &mut f {
            *v = r.f32("scan angles, times and ranges")?;
        }
        let n = r.count("ranges", 4)?;
        let ranges = (0..n)
            .map(|_| r.f32("ranges"))
            .collect::<Result<Vec<f32>, CdrError>>()?;
        Ok(LaserScan {
            header,
            angle_min: f[0],
            angle_max: f[1],
            angle_increment: f[2],
            time_increment: f[3],
            scan_time: f[4],
            range_min: f[5],
            range_max: f[6],
            ranges,
        })
    }
}

/// `nav_msgs/msg/Odometry`, planar: pose (x, y, yaw) and speeds (forward, turn); covariances
/// written as zeros (unknown), skipped when read.
#[derive(Clone, Debug, PartialEq)]
pub struct Odometry {
    pub header: Header,
    pub child_frame_id: String,
    pub pose: Pose2,
    /// Forward speed, m/s.
    pub speed_m_s: f64,
    /// Turn rate, rad/s.
    pub turn_rad_s: f64,
}

impl Odometry {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.string(&self.child_frame_id);
        write_pose(&mut w, &self.pose);
        for _ in 0..36 {
            w.f64(0.0);
        }
        for v in [self.speed_m_s, 0.0, 0.0, 0.0, 0.0, self.turn_rad_s] {
            w.f64(v);
        }
        for _ in 0..36 {
            w.f64(0.0);
        }
        w.into_bytes()
    }

    pub fn decode(bytes: &[u8]) -> Result<Odometry, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        let header = Header::read(&mut r)?;
        let child_frame_id = r.string("child_frame_id")?;
        let pose = read_pose(&mut r, "pose.pose")?;
        for _ in 0..36 {
            r.f64("pose.covariance")?;
        }
        let mut twist = [0.0; 6];
        for v in &mut twist {
            *v = r.f64("twist.twist")?;
        }
        Ok(Odometry {
            header,
            child_frame_id,
            pose,
            speed_m_s: twist[0],
            turn_rad_s: twist[5],
        })
    }
}

/// `geometry_msgs/msg/TransformStamped`, planar.
#[derive(Clone, Debug, PartialEq)]
pub struct Transform {
    pub header: Header,
    pub child_frame_id: String,
    /// The child frame's pose in the header's frame.
    pub pose: Pose2,
}

/// `tf2_msgs/msg/TFMessage`.
pub fn encode_tf(transforms: &[Transform]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.count(transforms.len());
    for t in transforms {
        t.header.write(&mut w);
        w.string(&t.child_frame_id);
        write_pose(&mut w, &t.pose);
    }
    w.into_bytes()
}

/// Reads a `tf2_msgs/msg/TFMessage`.
pub fn decode_tf(bytes: &[u8]) -> Result<Vec<Transform>, CdrError> {
    let mut r = CdrReader::new(bytes)?;
    // A transform takes at least 8 (stamp) + 4 + 4 (strings) + 56 bytes.
    let n = r.count("transforms", 72)?;
    (0..n)
        .map(|_| {
            Ok(Transform {
                header: Header::read(&mut r)?,
                child_frame_id: r.string("child_frame_id")?,
                pose: read_pose(&mut r, "transform")?,
            })
        })
        .collect()
}

/// `geometry_msgs/msg/PoseStamped`, planar.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose2,
}

impl PoseStamped {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        write_pose(&mut w, &self.pose);
        w.into_bytes()
    }

    pub fn decode(bytes: &[u8]) -> Result<PoseStamped, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        Ok(PoseStamped {
            header: Header::read(&mut r)?,
            pose: read_pose(&mut r, "pose")?,
        })
    }
}

/// `std_msgs/msg/String`.
pub fn encode_string(s: &str) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.string(s);
    w.into_bytes()
}

/// Reads a `std_msgs/msg/String`.
pub fn decode_string(bytes: &[u8]) -> Result<String, CdrError> {
    CdrReader::new(bytes)?.string("data")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_read_back_as_written() {
        let header = Header {
            stamp_s: 12.25,
            frame_id: "laser".into(),
        };
        let scan = LaserScan {
            header: header.clone(),
            angle_min: -1.5,
            angle_max: 1.5,
            angle_increment: 0.5,
            time_increment: 0.0,
            scan_time: 0.1,
            range_min: 0.0,
            range_max: 32.767,
            ranges: vec![1.0, 2.5, 32.767, 0.25, 4.0, 5.0, 6.0],
        };
        assert_eq!(LaserScan::decode(&scan.encode()).unwrap(), scan);
        let odom = Odometry {
            header: header.clone(),
            child_frame_id: "base_link".into(),
            pose: Pose2::new(1.0, -2.0, 0.75),
            speed_m_s: 0.4,
            turn_rad_s: -0.1,
        };
        let back = Odometry::decode(&odom.encode()).unwrap();
        assert!((back.pose.theta - 0.75).abs() < 1e-12, "{back:?}");
        assert_eq!((back.speed_m_s, back.turn_rad_s), (0.4, -0.1));
        let tf = vec![Transform {
            header,
            child_frame_id: "laser".into(),
            pose: Pose2::new(0.021, 0.0, 0.0),
        }];
        assert_eq!(decode_tf(&encode_tf(&tf)).unwrap(), tf);
        assert_eq!(decode_string(&encode_string("{}")).unwrap(), "{}");
    }

    #[test]
    fn every_type_has_its_schema() {
        for t in [LASER_SCAN, ODOMETRY, TF_MESSAGE, POSE_STAMPED, STRING] {
            let s = schema_text(t).unwrap();
            assert!(!s.contains("MSG: std_msgs/Header") || s.contains("builtin_interfaces/Time"));
        }
        assert!(schema_text("x/msg/Y").is_none());
    }
}
