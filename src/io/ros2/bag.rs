//! ROS 2 bags in MCAP: a simulated run written as one ([`BagWriter`]) and a bag read as the
//! laser frames of a real log ([`read_bag`]).
//!
//! **Written** (profile `ros2`, CDR, `ros2msg` schemas, zstd-compressed chunks), per frame, all
//! stamped with the frame's time (seconds since the run started):
//! - `/odom` `nav_msgs/msg/Odometry`: the noisy odometry, `odom` → `base_link`, speeds from the
//!   previous frame;
//! - `/tf` `tf2_msgs/msg/TFMessage`: `odom` → `base_link` (the odometry) and `base_link` →
//!   `laser` (the mount);
//! - `/scan` `sensor_msgs/msg/LaserScan` in `laser`: the beams as laid out (181 over 180°, right
//!   to left, for the LMS200), a no-return as `range_max`;
//! - `/ground_truth` `geometry_msgs/msg/PoseStamped` in `map`: the true pose of `base_link`;
//!
//! and per lap, at its first frame, `/doors` `std_msgs/msg/String`: a JSON object
//! `{"run": 0, "lap": 0, "door_config": "all-closed", "open_doors": ["d1"]}` (docs/ros2.md).
//!
//! **Read.** The scan and odometry topics are the ones named, or else the only channel of type
//! `sensor_msgs/msg/LaserScan` (`nav_msgs/msg/Odometry`); the truth is the only
//! `geometry_msgs/msg/PoseStamped` channel, or `/ground_truth` among several. Each scan's pose is
//! the odometry at its header stamp (interpolated between the two messages around it, at most
//! [`ODOM_MAX_GAP_S`] from one); as in a CARMEN log, that pose is the sensor's (the mount is not
//! applied). Readings that are not finite or reach `range_max` are no-returns.
//!
//! **Resolution.** A `float32` range is read as the shortest decimal that gives it back (the
//! millimetres a scanner reported: `1.234`, not `1.2339999675750732`), and poses at a CARMEN
//! log's resolution (1 µm, 1 µrad, far below any odometry's error): a bag and a CARMEN log of
//! the same run make the same frames, bit for bit, and so the same matches. The file is read
//! whole, record by record, by a small walker of its own (the `mcap` crate writes; its record
//! parser trusts a corrupt length field and allocates what it claims); a record that runs past
//! the end of the file, a chunk that does not decompress or fails its CRC, or a record whose
//! fields do not fit it is an error naming its byte offset.

use super::msg::{self, Header, LaserScan, Odometry, PoseStamped, Transform};
use crate::geom::{Pose2, wrap_angle};
use crate::io::carmen::{LaserRecord, TruePosRecord, odometry_speeds, pose_at_log_resolution};
use crate::log::LapLog;
use std::collections::BTreeMap;
use std::io::{Seek, Write};
use std::path::Path;

/// The 8 bytes every MCAP file starts (and ends) with.
pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// The farthest a scan may be in time from the odometry message it takes its pose from, seconds.
pub const ODOM_MAX_GAP_S: f64 = 0.5;

/// Largest chunk the reader decompresses, bytes: a larger claim means a corrupt file.
pub const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Whether the file at `path` is an MCAP file (by its first bytes).
pub fn is_mcap(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| &head == MAGIC)
}

/// How a scan's beams are timed, seconds (`time_increment`, `scan_time` of `LaserScan`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanTiming {
    /// Between neighbouring beams.
    pub time_increment_s: f64,
    /// Between scans.
    pub scan_time_s: f64,
}

impl ScanTiming {
    /// A SICK LMS200 scanning at `rate_hz`: the mirror turns at 75 Hz, so one degree of sweep
    /// takes 1/(75·360) s, whatever the beam spacing `step_rad`.
    pub fn lms200(rate_hz: f64, step_rad: f64) -> Self {
        ScanTiming {
            time_increment_s: step_rad.to_degrees() / (75.0 * 360.0),
            scan_time_s: if rate_hz > 0.0 { 1.0 / rate_hz } else { 0.0 },
        }
    }
}

/// Writes one simulated run as a ROS 2 bag, lap after lap (the module doc lists the topics).
pub struct BagWriter<W: Write + Seek> {
    mcap: mcap::Writer<W>,
    run: usize,
    timing: ScanTiming,
    channels: [u16; 5],
    sequence: u32,
    /// Time and odometry pose of the last frame written.
    prev: Option<(f64, Pose2)>,
}

/// Topics and types in the order of [`BagWriter`]'s channels.
const TOPICS: [(&str, &str); 5] = [
    ("/odom", msg::ODOMETRY),
    ("/tf", msg::TF_MESSAGE),
    ("/scan", msg::LASER_SCAN),
    ("/ground_truth", msg::POSE_STAMPED),
    ("/doors", msg::STRING),
];

fn io_err(e: mcap::McapError) -> std::io::Error {
    match e {
        mcap::McapError::Io(e) => e,
        e => std::io::Error::other(e),
    }
}

impl<W: Write + Seek> BagWriter<W> {
    /// Starts the bag of run `run` on `out`.
    pub fn new(out: W, run: usize, timing: ScanTiming) -> std::io::Result<Self> {
        let mut mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("placewords ", env!("CARGO_PKG_VERSION")))
            .compression(Some(mcap::Compression::Zstd))
            // Single-threaded: the same bytes whatever the machine.
            .compression_threads(0)
            .create(out)
            .map_err(io_err)?;
        let mut channels = [0u16; 5];
        for (slot, (topic, type_name)) in channels.iter_mut().zip(TOPICS) {
            let text = msg::schema_text(type_name).expect("a known type");
            let schema = mcap
                .add_schema(type_name, "ros2msg", text.as_bytes())
                .map_err(io_err)?;
            *slot = mcap
                .add_channel(schema, topic, "cdr", &BTreeMap::new())
                .map_err(io_err)?;
        }
        Ok(BagWriter {
            mcap,
            run,
            timing,
            channels,
            sequence: 0,
            prev: None,
        })
    }

    fn write(&mut self, channel: usize, time_s: f64, data: &[u8]) -> std::io::Result<()> {
        let t = msg::time_ns(time_s);
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id: self.channels[channel],
            sequence: self.sequence,
            log_time: t,
            publish_time: t,
        };
        self.mcap
            .write_to_known_channel(&header, data)
            .map_err(io_err)
    }

    /// Appends the messages of `lap`.
    pub fn write_lap(&mut self, lap: &LapLog) -> std::io::Result<()> {
        if let Some(first) = lap.frames.first() {
            let doors = serde_json::json!({
                "run": self.run,
                "lap": lap.lap,
                "door_config": lap.door_config,
                "open_doors": lap.open_doors,
            });
            self.write(4, first.time_s, &msg::encode_string(&doors.to_string()))?;
        }
        for f in &lap.frames {
            let odom = f.odom.0;
            let (speed_m_s, turn_rad_s) = odometry_speeds(self.prev, f.time_s, odom);
            self.prev = Some((f.time_s, odom));
            let header = |frame_id: &str| Header {
                stamp_s: f.time_s,
                frame_id: frame_id.into(),
            };
            let odometry = Odometry {
                header: header("odom"),
                child_frame_id: "base_link".into(),
                pose: odom,
                speed_m_s,
                turn_rad_s,
            };
            self.write(0, f.time_s, &odometry.encode())?;
            let tf = [
                Transform {
                    header: header("odom"),
                    child_frame_id: "base_link".into(),
                    pose: odom,
                },
                Transform {
                    header: header("base_link"),
                    child_frame_id: "laser".into(),
                    pose: f.scan.layout.mount,
                },
            ];
            self.write(1, f.time_s, &msg::encode_tf(&tf))?;
            let layout = &f.scan.layout;
            let scan = LaserScan {
                header: header("laser"),
                angle_min: layout.start_angle_rad as f32,
                angle_max: layout.beam_angle_rad(layout.count.saturating_sub(1)) as f32,
                angle_increment: layout.step_rad as f32,
                time_increment: self.timing.time_increment_s as f32,
                scan_time: self.timing.scan_time_s as f32,
                range_min: 0.0,
                range_max: layout.max_range_m as f32,
                ranges: f.scan.ranges_m.iter().map(|r| *r as f32).collect(),
            };
            self.write(2, f.time_s, &scan.encode())?;
            let truth = PoseStamped {
                header: header("map"),
                pose: f.truth.0,
            };
            self.write(3, f.time_s, &truth.encode())?;
        }
        Ok(())
    }

    /// Writes the summary and footer; returns the output.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.mcap.finish().map_err(io_err)?;
        Ok(self.mcap.into_inner())
    }
}

/// Which topics to read; `None`: found by type.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BagTopics {
    /// The `sensor_msgs/msg/LaserScan` topic.
    pub scan: Option<String>,
    /// The `nav_msgs/msg/Odometry` topic.
    pub odom: Option<String>,
}

/// Why a bag could not be read.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    #[error("{path}: cannot read: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: not an MCAP file (it does not start with the MCAP magic bytes)")]
    NotMcap { path: String },
    #[error(
        "{path}: truncated: {what} at byte offset {offset} runs past the end of the file ({len} bytes)"
    )]
    Truncated {
        path: String,
        what: String,
        offset: u64,
        len: u64,
    },
    #[error("{path}: corrupt record at byte offset {offset}: {message}")]
    Corrupt {
        path: String,
        offset: u64,
        message: String,
    },
    #[error("{path}: no {what} topic{wanted}; the bag has {present}{hint}")]
    MissingTopic {
        path: String,
        what: &'static str,
        wanted: String,
        present: String,
        hint: String,
    },
    #[error("{path}: several {type_name} topics ({candidates}); choose one with {flag}")]
    Ambiguous {
        path: String,
        type_name: &'static str,
        candidates: String,
        flag: &'static str,
    },
    #[error("{path}: topic {topic} is {found}, not {expected}")]
    WrongType {
        path: String,
        topic: String,
        found: String,
        expected: &'static str,
    },
    #[error(
        "{path}: topic {topic} uses message encoding `{encoding}`; only `cdr` (ROS 2) is supported"
    )]
    Encoding {
        path: String,
        topic: String,
        encoding: String,
    },
    #[error("{path}: topic {topic}, message {index}: {source}")]
    Message {
        path: String,
        topic: String,
        index: usize,
        source: super::cdr::CdrError,
    },
    #[error("{path}: topic {topic} has no messages")]
    Empty { path: String, topic: String },
    #[error(
        "{path}: scan {index} (time {time_s:.3} s) has no odometry within {max_gap_s:.1} s (nearest {gap_s:.3} s away)"
    )]
    NoOdometry {
        path: String,
        index: usize,
        time_s: f64,
        gap_s: f64,
        max_gap_s: f64,
    },
}

/// One channel of a bag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    pub topic: String,
    /// The schema's name (`sensor_msgs/msg/LaserScan`), empty without a schema.
    pub type_name: String,
    pub encoding: String,
    pub messages: usize,
}

/// What a bag holds for the recognizer: its laser frames as CARMEN-style records.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BagReadout {
    /// One per scan, in file order; `pose` and `odom` both the odometry at its stamp.
    pub lasers: Vec<LaserRecord>,
    /// The truth topic's poses, if it has one.
    pub truepos: Vec<TruePosRecord>,
    /// The first scan's `range_max`, metres, when positive and finite.
    pub max_range_m: Option<f64>,
    /// Every channel, in id order.
    pub topics: Vec<TopicInfo>,
}

/// The raw messages of the bag's channels: id → (info, schema name, payloads).
struct Channels {
    info: BTreeMap<u16, TopicInfo>,
    /// Payloads kept for channels of the types read.
    data: BTreeMap<u16, Vec<Vec<u8>>>,
}

/// `sensor_msgs/LaserScan` and `sensor_msgs/msg/LaserScan` name one type.
fn same_type(a: &str, b: &str) -> bool {
    a.replace("/msg/", "/") == b.replace("/msg/", "/")
}

/// Reads the bag at `path`; see the module doc.
pub fn read_bag(path: &Path, topics: &BagTopics) -> Result<BagReadout, BagError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| BagError::Io {
        path: name.clone(),
        source,
    })?;
    read_bag_bytes(&bytes, &name, topics)
}

/// [`read_bag`] on the file's bytes, `name` naming it in errors.
pub fn read_bag_bytes(
    bytes: &[u8],
    name: &str,
    topics: &BagTopics,
) -> Result<BagReadout, BagError> {
    let channels = read_channels(bytes, name)?;
    let list: Vec<TopicInfo> = channels.info.values().cloned().collect();
    let pick = |what, type_name, wanted: &Option<String>, flag| {
        pick_channel(&channels, name, what, type_name, wanted.as_deref(), flag)
    };
    let scan = pick("scan", msg::LASER_SCAN, &topics.scan, "--scan-topic")?;
    let odom = pick("odometry", msg::ODOMETRY, &topics.odom, "--odom-topic")?;
    let truth = truth_channel(&channels);
    let odoms = odometry(&channels, name, odom)?;
    let scans = decode_all(&channels, name, scan, LaserScan::decode)?;
    let truepos = match truth {
        Some(t) => truepos_records(&channels, name, t)?,
        None => Vec::new(),
    };
    let max_range_m = max_range_m(&scans);
    let lasers = laser_records(scans, &odoms, max_range_m, name)?;
    Ok(BagReadout {
        lasers,
        truepos,
        max_range_m,
        topics: list,
    })
}

/// The first scan's maximum range, metres, when positive and finite.
fn max_range_m(scans: &[LaserScan]) -> Option<f64> {
    scans
        .first()
        .map(|s| f32_decimal(s.range_max))
        .filter(|r| r.is_finite() && *r > 0.0)
}

/// The (time s, pose) of each message of odometry channel `id`, in time order.
fn odometry(channels: &Channels, name: &str, id: u16) -> Result<Vec<(f64, Pose2)>, BagError> {
    let mut odoms = decode_all(channels, name, id, |d| {
        let o = Odometry::decode(d)?;
        Ok((o.header.stamp_s, pose_at_log_resolution(o.pose)))
    })?;
    odoms.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(odoms)
}

/// The poses of channel `id` (ground truth) as TRUEPOS records.
fn truepos_records(
    channels: &Channels,
    name: &str,
    id: u16,
) -> Result<Vec<TruePosRecord>, BagError> {
    decode_all(channels, name, id, |d| {
        let p = PoseStamped::decode(d)?;
        Ok(TruePosRecord {
            truth: pose_at_log_resolution(p.pose),
            odom: Pose2::IDENTITY,
            ipc_timestamp: p.header.stamp_s,
            host: String::new(),
            logger_timestamp: p.header.stamp_s,
        })
    })
}

/// Every message of channel `id`, decoded by `decode`, in file order; an error names the
/// topic and the message's index, and a channel without messages is an error.
fn decode_all<T>(
    channels: &Channels,
    name: &str,
    id: u16,
    decode: impl Fn(&[u8]) -> Result<T, super::cdr::CdrError>,
) -> Result<Vec<T>, BagError> {
    let topic = &channels.info[&id].topic;
    let data = channels.data.get(&id).map(Vec::as_slice).unwrap_or(&[]);
    if data.is_empty() {
        return Err(BagError::Empty {
            path: name.into(),
            topic: topic.clone(),
        });
    }
    data.iter()
        .enumerate()
        .map(|(index, d)| {
            decode(d).map_err(|source| BagError::Message {
                path: name.into(),
                topic: topic.clone(),
                index,
                source,
            })
        })
        .collect()
}

/// One laser record per scan, at the odometry of its stamp (`odoms` sorted by time); ranges
/// that are not finite read as `max_range_m` (no return; infinite without one).
fn laser_records(
    scans: Vec<LaserScan>,
    odoms: &[(f64, Pose2)],
    max_range_m: Option<f64>,
    name: &str,
) -> Result<Vec<LaserRecord>, BagError> {
    let no_return = max_range_m.unwrap_or(f64::INFINITY);
    scans
        .into_iter()
        .enumerate()
        .map(|(index, s)| {
            let t = s.header.stamp_s;
            let pose = odometry_at(odoms, t).map_err(|gap_s| BagError::NoOdometry {
                path: name.into(),
                index,
                time_s: t,
                gap_s,
                max_gap_s: ODOM_MAX_GAP_S,
            })?;
            Ok(laser_record(&s, pose, no_return))
        })
        .collect()
}

/// The laser record of scan `s` taken at odometry `pose`.
fn laser_record(s: &LaserScan, pose: Pose2, no_return: f64) -> LaserRecord {
    let (n, t) = (s.ranges.len(), s.header.stamp_s);
    LaserRecord {
        start_angle_rad: s.angle_min as f64,
        fov_rad: s.angle_increment as f64 * n.saturating_sub(1) as f64,
        ranges_m: ranges_m(&s.ranges, no_return),
        pose,
        odom: pose,
        ipc_timestamp: t,
        host: String::new(),
        logger_timestamp: t,
    }
}

/// A scan's ranges in metres at the log's resolution, a non-finite one as `no_return`.
fn ranges_m(ranges: &[f32], no_return: f64) -> Vec<f64> {
    ranges
        .iter()
        .map(|r| {
            if r.is_finite() {
                f32_decimal(*r)
            } else {
                no_return
            }
        })
        .collect()
}

/// `r` as the shortest decimal that reads back as `r` (what was meant before it became binary).
fn f32_decimal(r: f32) -> f64 {
    r.to_string().parse().unwrap_or(r as f64)
}

/// The odometry pose at `t` from `sorted` (by time): interpolated between the messages around
/// `t`, or the nearest one at the ends; `Err(gap)` when the nearest is farther than
/// [`ODOM_MAX_GAP_S`].
fn odometry_at(sorted: &[(f64, Pose2)], t: f64) -> Result<Pose2, f64> {
    let i = sorted.partition_point(|e| e.0 < t);
    let after = sorted.get(i);
    let before = i.checked_sub(1).and_then(|j| sorted.get(j));
    let gap = |e: Option<&(f64, Pose2)>| e.map_or(f64::INFINITY, |e| (e.0 - t).abs());
    let nearest = gap(before).min(gap(after));
    if nearest.is_nan() || nearest > ODOM_MAX_GAP_S {
        return Err(nearest);
    }
    Ok(match (before, after) {
        (_, Some(a)) if a.0 == t => a.1,
        (Some(b), Some(a)) if a.0 - b.0 <= 2.0 * ODOM_MAX_GAP_S => {
            let w = (t - b.0) / (a.0 - b.0);
            Pose2::new(
                b.1.x + w * (a.1.x - b.1.x),
                b.1.y + w * (a.1.y - b.1.y),
                wrap_angle(b.1.theta + w * wrap_angle(a.1.theta - b.1.theta)),
            )
        }
        (Some(b), a) if gap(Some(b)) <= gap(a) => b.1,
        (_, Some(a)) => a.1,
        (Some(b), None) => b.1,
        (None, None) => unreachable!("a nearest message exists"),
    })
}

/// The channel of `type_name` for `what`: the one named `wanted`, or else the only one of the type.
fn pick_channel(
    channels: &Channels,
    path: &str,
    what: &'static str,
    type_name: &'static str,
    wanted: Option<&str>,
    flag: &'static str,
) -> Result<u16, BagError> {
    let present = || {
        if channels.info.is_empty() {
            "no topics".to_string()
        } else {
            let list: Vec<String> = channels
                .info
                .values()
                .map(|c| format!("{} ({})", c.topic, c.type_name))
                .collect();
            format!("topics {}", list.join(", "))
        }
    };
    let found: Vec<(&u16, &TopicInfo)> = match wanted {
        Some(w) => channels.info.iter().filter(|(_, c)| c.topic == w).collect(),
        None => channels
            .info
            .iter()
            .filter(|(_, c)| same_type(&c.type_name, type_name))
            .collect(),
    };
    let (&id, info) = match found.as_slice() {
        [] => {
            return Err(BagError::MissingTopic {
                path: path.into(),
                what,
                wanted: match wanted {
                    Some(w) => format!(" {w}"),
                    None => format!(" of type {type_name}"),
                },
                present: present(),
                hint: if wanted.is_some() {
                    String::new()
                } else {
                    format!("; name one with {flag}")
                },
            });
        }
        [one] => *one,
        many => {
            if wanted.is_none() {
                let names: Vec<&str> = many.iter().map(|(_, c)| c.topic.as_str()).collect();
                return Err(BagError::Ambiguous {
                    path: path.into(),
                    type_name,
                    candidates: names.join(", "),
                    flag,
                });
            }
            many[0]
        }
    };
    if !same_type(&info.type_name, type_name) {
        return Err(BagError::WrongType {
            path: path.into(),
            topic: info.topic.clone(),
            found: if info.type_name.is_empty() {
                "without a schema".into()
            } else {
                info.type_name.clone()
            },
            expected: type_name,
        });
    }
    if info.encoding != "cdr" {
        return Err(BagError::Encoding {
            path: path.into(),
            topic: info.topic.clone(),
            encoding: info.encoding.clone(),
        });
    }
    Ok(id)
}

/// The truth channel: the only CDR `geometry_msgs/msg/PoseStamped` one, or `/ground_truth`.
fn truth_channel(channels: &Channels) -> Option<u16> {
    let poses: Vec<(&u16, &TopicInfo)> = channels
        .info
        .iter()
        .filter(|(_, c)| same_type(&c.type_name, msg::POSE_STAMPED) && c.encoding == "cdr")
        .collect();
    match poses.as_slice() {
        [(id, _)] => Some(**id),
        many => many
            .iter()
            .find(|(_, c)| c.topic == "/ground_truth")
            .map(|(id, _)| **id),
    }
}

/// Walks the file's records (and the records inside its chunks), keeping every channel and
/// the payloads of the channels whose type the reader decodes.
fn read_channels(bytes: &[u8], path: &str) -> Result<Channels, BagError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(BagError::NotMcap { path: path.into() });
    }
    let mut walk = Walk {
        path,
        schemas: BTreeMap::new(),
        channels: Channels {
            info: BTreeMap::new(),
            data: BTreeMap::new(),
        },
    };
    let len = bytes.len() as u64;
    let truncated = |what: String, offset: usize| BagError::Truncated {
        path: path.into(),
        what,
        offset: offset as u64,
        len,
    };
    let mut pos = MAGIC.len();
    loop {
        if pos == bytes.len() {
            // A file cut at a record boundary: what is there is read (as `mcap recover` would).
            break;
        }
        if bytes.len() - pos < 9 {
            return Err(truncated("a record header".into(), pos));
        }
        let op = bytes[pos];
        let body_len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let start = pos + 9;
        if body_len > (bytes.len() - start) as u64 {
            return Err(truncated(
                format!("record 0x{op:02x} of {body_len} bytes"),
                pos,
            ));
        }
        let body = &bytes[start..start + body_len as usize];
        if op == OP_FOOTER {
            // The footer: the end (the closing magic is not needed).
            break;
        }
        walk.record(op, body, pos as u64)?;
        pos = start + body_len as usize;
    }
    Ok(walk.channels)
}

/// The state of [`read_channels`].
struct Walk<'p> {
    path: &'p str,
    /// Schema id → name.
    schemas: BTreeMap<u16, String>,
    channels: Channels,
}

/// Reads the fields of one record body, every length checked against the bytes there (the
/// `mcap` crate's record parser trusts a corrupt length and allocates what it claims).
struct Fields<'a> {
    body: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    fn bytes(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        let left = (self.body.len() - self.pos) as u64;
        if n > left {
            return Err(format!(
                "its {what} claims {n} bytes, but the record has {left} left"
            ));
        }
        let b = &self.body[self.pos..self.pos + n as usize];
        self.pos += n as usize;
        Ok(b)
    }

    fn u16(&mut self, what: &str) -> Result<u16, String> {
        Ok(u16::from_le_bytes(
            self.bytes(2, what)?.try_into().expect("2"),
        ))
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.bytes(4, what)?.try_into().expect("4"),
        ))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.bytes(8, what)?.try_into().expect("8"),
        ))
    }

    fn string(&mut self, what: &str) -> Result<String, String> {
        let n = self.u32(what)?;
        let b = self.bytes(n as u64, what)?;
        String::from_utf8(b.to_vec()).map_err(|_| format!("its {what} is not UTF-8 text"))
    }

    fn rest(&mut self) -> &'a [u8] {
        let b = &self.body[self.pos..];
        self.pos = self.body.len();
        b
    }
}

/// Record opcodes the reader looks into.
const OP_FOOTER: u8 = 0x02;
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;

impl Walk<'_> {
    fn corrupt(&self, offset: u64, e: impl std::fmt::Display) -> BagError {
        BagError::Corrupt {
            path: self.path.into(),
            offset,
            message: e.to_string(),
        }
    }

    /// One top-level record at `offset`.
    fn record(&mut self, op: u8, body: &[u8], offset: u64) -> Result<(), BagError> {
        if op != OP_CHUNK {
            return self.inner(op, body, offset);
        }
        let records = self
            .chunk(body)
            .map_err(|e| self.corrupt(offset, format!("chunk: {e}")))?;
        // The chunk's records, each with the same bounds checks as the file's.
        let mut pos = 0usize;
        while pos < records.len() {
            let at = |e: String| format!("chunk, at byte {pos} of its records: {e}");
            if records.len() - pos < 9 {
                return Err(self.corrupt(offset, at("a record header is cut off".into())));
            }
            let op = records[pos];
            let n = u64::from_le_bytes(records[pos + 1..pos + 9].try_into().expect("8"));
            if n > (records.len() - pos - 9) as u64 {
                return Err(self.corrupt(
                    offset,
                    at(format!(
                        "record 0x{op:02x} of {n} bytes runs past the chunk's end"
                    )),
                ));
            }
            let body = &records[pos + 9..pos + 9 + n as usize];
            self.inner(op, body, offset)?;
            pos += 9 + n as usize;
        }
        Ok(())
    }

    /// The records of a chunk's body, decompressed and checked against its CRC.
    fn chunk(&self, body: &[u8]) -> Result<Vec<u8>, String> {
        use std::io::Read as _;
        let mut f = Fields { body, pos: 0 };
        let _start = f.u64("start time")?;
        let _end = f.u64("end time")?;
        let size = f.u64("uncompressed size")?;
        let crc = f.u32("CRC")?;
        let compression = f.string("compression")?;
        let compressed_len = f.u64("compressed size")?;
        let data = f.bytes(compressed_len, "records")?;
        if size > MAX_CHUNK_BYTES {
            return Err(format!(
                "it claims {size} bytes uncompressed (at most {MAX_CHUNK_BYTES})"
            ));
        }
        let records = match compression.as_str() {
            "" => data.to_vec(),
            "zstd" => {
                let mut out = Vec::new();
                zstd::stream::read::Decoder::new(data)
                    .and_then(|d| d.take(size + 1).read_to_end(&mut out))
                    .map_err(|e| format!("zstd: {e}"))?;
                out
            }
            other => {
                return Err(format!(
                    "compression `{other}` is not supported (only zstd or none)"
                ));
            }
        };
        if records.len() as u64 != size {
            return Err(format!(
                "it holds {} bytes uncompressed, not the {size} it claims",
                records.len()
            ));
        }
        if crc != 0 && crc32fast::hash(&records) != crc {
            return Err("its CRC does not match its records".into());
        }
        Ok(records)
    }

    /// One schema, channel or message record (others are skipped).
    fn inner(&mut self, op: u8, body: &[u8], offset: u64) -> Result<(), BagError> {
        let mut f = Fields { body, pos: 0 };
        let what = match op {
            OP_SCHEMA => "schema",
            OP_CHANNEL => "channel",
            OP_MESSAGE => "message",
            _ => return Ok(()),
        };
        let path = self.path;
        let bad = |e: String| BagError::Corrupt {
            path: path.into(),
            offset,
            message: format!("{what}: {e}"),
        };
        match op {
            OP_SCHEMA => {
                let id = f.u16("id").map_err(bad)?;
                let name = f.string("name").map_err(bad)?;
                self.schemas.insert(id, name);
            }
            OP_CHANNEL => {
                let id = f.u16("id").map_err(bad)?;
                let schema_id = f.u16("schema id").map_err(bad)?;
                let topic = f.string("topic").map_err(bad)?;
                let encoding = f.string("message encoding").map_err(bad)?;
                let type_name = match schema_id {
                    0 => String::new(),
                    id => self.schemas.get(&id).cloned().ok_or_else(|| {
                        bad(format!(
                            "{topic} names schema {id}, which comes nowhere before it"
                        ))
                    })?,
                };
                self.channels.info.insert(
                    id,
                    TopicInfo {
                        topic,
                        type_name,
                        encoding,
                        messages: 0,
                    },
                );
            }
            _ => {
                let channel = f.u16("channel id").map_err(bad)?;
                f.bytes(20, "sequence and times").map_err(bad)?;
                let data = f.rest();
                let Some(info) = self.channels.info.get_mut(&channel) else {
                    return Err(bad(format!(
                        "its channel {channel} comes nowhere before it"
                    )));
                };
                info.messages += 1;
                let read = [msg::LASER_SCAN, msg::ODOMETRY, msg::POSE_STAMPED]
                    .iter()
                    .any(|t| same_type(&info.type_name, t));
                if read {
                    self.channels
                        .data
                        .entry(channel)
                        .or_default()
                        .push(data.to_vec());
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odometry_is_interpolated_and_gaps_are_refused() {
        let odom = [
            (0.0, Pose2::new(0.0, 0.0, 3.0)),
            (0.2, Pose2::new(1.0, 0.0, -3.0)),
        ];
        let p = odometry_at(&odom, 0.1).unwrap();
        assert!((p.x - 0.5).abs() < 1e-12);
        // Across ±π the short way round.
        assert!(p.theta.abs() > 3.1, "{p:?}");
        assert_eq!(odometry_at(&odom, 0.2).unwrap(), odom[1].1);
        assert_eq!(odometry_at(&odom, 0.6).unwrap(), odom[1].1);
        assert_eq!(odometry_at(&odom, 1.0), Err(0.8));
    }

    #[test]
    fn a_file_that_is_not_mcap_is_named() {
        let e = read_bag_bytes(b"FLASER 1 2 3", "x.log", &BagTopics::default()).unwrap_err();
        assert!(matches!(e, BagError::NotMcap { .. }), "{e}");
    }
}
