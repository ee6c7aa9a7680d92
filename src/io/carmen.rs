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
//!
//! Laps are written one at a time ([`LapWriter`]) so a caller can append each lap to its file
//! as it is made, without holding a whole run's text; lines are read one at a time
//! ([`RecordStream`]) for the same reason.

use crate::geom::{Pose2, wrap_angle};
use crate::log::LapLog;
use crate::spec::diag::Diagnostic;
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
        LogRecord::Laser(l) => write_flaser(out, l),
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

/// The laser record of a simulated frame: its scan at the odometry pose, sent by `host`.
fn laser_record(f: &crate::log::Frame, host: String) -> LaserRecord {
    LaserRecord {
        start_angle_rad: f.scan.layout.start_angle_rad,
        fov_rad: f.scan.layout.fov_rad(),
        ranges_m: f.scan.ranges_m.clone(),
        pose: f.odom.0,
        odom: f.odom.0,
        ipc_timestamp: f.time_s,
        host,
        logger_timestamp: f.time_s,
    }
}

/// A laser record as a `FLASER` line.
fn write_flaser(out: &mut String, l: &LaserRecord) {
    let _ = write!(out, "FLASER {}", l.ranges_m.len());
    for r in &l.ranges_m {
        push_range(out, *r);
    }
    let _ = writeln!(
        out,
        " {} {} {}",
        fmt_pose(&l.pose),
        fmt_pose(&l.odom),
        fmt_stamp(l.ipc_timestamp, &l.host, l.logger_timestamp)
    );
}

/// Appends ` r` with three decimals. Ranges in millimetres are written as integers (the same
/// text as `{:.3}`, several times faster: 40 laps make 250 MB of ranges).
fn push_range(out: &mut String, r: f64) {
    let mm = (r * 1000.0).round();
    if mm.is_finite() && mm.abs() < 1e15 {
        let mm = mm as i64;
        let sign = if mm < 0 { "-" } else { "" };
        let (whole, frac) = (mm.unsigned_abs() / 1000, mm.unsigned_abs() % 1000);
        let _ = write!(out, " {sign}{whole}.{frac:03}");
    } else {
        let _ = write!(out, " {r:.3}");
    }
}

/// Writes the laps of one run as CARMEN text, lap after lap. Per lap a `#` comment naming the
/// lap and its doors; per frame, in this order: `ODOM` (odometry pose; speeds from the previous
/// frame, across laps), `FLASER` (the odometry pose in both pose slots, as a robot's logger
/// would record it) and `TRUEPOS` (ground truth beside the odometry pose). Timestamps are the
/// frames' `time_s`.
#[derive(Clone, Debug)]
pub struct LapWriter {
    host: String,
    /// Time and odometry pose of the last frame written.
    prev: Option<(f64, Pose2)>,
}

impl LapWriter {
    /// A writer for a run whose records name `host`.
    pub fn new(host: &str) -> Self {
        LapWriter {
            host: host.to_string(),
            prev: None,
        }
    }

    /// Appends the lines of `lap` to `out`.
    pub fn write_lap(&mut self, out: &mut String, lap: &LapLog) {
        let _ = writeln!(
            out,
            "# lap {} doors {}: open [{}]",
            lap.lap,
            lap.door_config,
            lap.open_doors.join(" ")
        );
        for f in &lap.frames {
            let odom = f.odom.0;
            let (tv, rv) = odometry_speeds(self.prev, f.time_s, odom);
            self.prev = Some((f.time_s, odom));
            self.write_frame(out, f, (tv, rv));
        }
    }

    /// The three lines of one frame, with the odometry speeds `(tv, rv)`.
    fn write_frame(&self, out: &mut String, f: &crate::log::Frame, (tv, rv): (f64, f64)) {
        let odom = f.odom.0;
        let host = self.host.clone();
        write_record(
            out,
            &LogRecord::Odom(OdomRecord {
                pose: odom,
                tv_m_s: tv,
                rv_rad_s: rv,
                accel_m_s2: 0.0,
                ipc_timestamp: f.time_s,
                host: host.clone(),
                logger_timestamp: f.time_s,
            }),
        );
        write_record(out, &LogRecord::Laser(laser_record(f, host.clone())));
        write_record(
            out,
            &LogRecord::TruePos(TruePosRecord {
                truth: f.truth.0,
                odom,
                ipc_timestamp: f.time_s,
                host,
                logger_timestamp: f.time_s,
            }),
        );
    }
}

/// The forward speed (m/s, negative backwards) and turn rate (rad/s) from the odometry pose
/// `prev` (at its time, seconds) to `odom` at `time_s`; zero for the first frame or no time step.
pub fn odometry_speeds(prev: Option<(f64, Pose2)>, time_s: f64, odom: Pose2) -> (f64, f64) {
    match prev {
        Some((t0, p0)) if time_s > t0 => {
            let dt = time_s - t0;
            let d = p0.between(&odom);
            let dist = (d.x * d.x + d.y * d.y).sqrt() * d.x.signum();
            (dist / dt, wrap_angle(odom.theta - p0.theta) / dt)
        }
        _ => (0.0, 0.0),
    }
}

/// `v` as a CARMEN log holds it: printed with six decimals and read back (1 µm, 1 µrad).
pub fn at_log_resolution(v: f64) -> f64 {
    format!("{v:.6}").parse().unwrap_or(v)
}

/// [`at_log_resolution`] of each coordinate.
pub fn pose_at_log_resolution(p: Pose2) -> Pose2 {
    Pose2::new(
        at_log_resolution(p.x),
        at_log_resolution(p.y),
        at_log_resolution(p.theta),
    )
}

fn fmt_pose(p: &Pose2) -> String {
    format!("{:.6} {:.6} {:.6}", p.x, p.y, p.theta)
}

fn fmt_stamp(ipc: f64, host: &str, logger: f64) -> String {
    format!("{ipc:.6} {host} {logger:.6}")
}

// ---------------------------------------------------------------------------------------------
// Reader
// ---------------------------------------------------------------------------------------------

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Longest line the reader accepts, bytes (a 100 000-beam laser line is well under 2 MiB); a
/// longer one means the input is not a text log, and reading it whole could exhaust memory.
pub const MAX_LINE_BYTES: u64 = 16 << 20;

/// How strictly to read a log.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Skip malformed lines (and count them) instead of failing at the first one.
    pub lenient: bool,
}

/// What a read produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogReadout {
    /// The understood messages, in file order.
    pub records: Vec<LogRecord>,
    /// Malformed lines skipped in lenient mode (always 0 in strict mode).
    pub skipped_lines: usize,
    /// The first skipped line's problem, located (lenient mode), to show the user.
    pub first_skipped: Option<String>,
    /// Lines whose message type the reader does not know (NEFF, SYNC, RAWLASER…), skipped silently.
    pub unknown_lines: usize,
    /// The `max_range` field of the first ROBOTLASER1 message, metres, if any.
    pub robotlaser_max_range_m: Option<f64>,
    /// Indices into `records` of the lasers read from RLASER (rear scanner) lines.
    pub rear_laser_indices: Vec<usize>,
}

/// Why a log could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CarmenError {
    #[error("{path}: cannot read: {source}; check the path and the file's permissions")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A line that is not a valid message of its type.
    #[error("{0}")]
    Malformed(Diagnostic),
    /// The gzip stream ended early or is corrupt; located at the last complete line read
    /// (line 1 when none was).
    #[error(
        "{path}:{}:1: the gzip stream is truncated or corrupt {} ({source}); \
         re-download or re-compress the log (`gzip -t` tests it), or unpack what is readable with `zcat`",
        (*line).max(1),
        if *line == 0 { "before its first complete line" } else { "after this line, the last complete one" }
    )]
    Decompress {
        path: String,
        /// Last complete line read before the failure.
        line: usize,
        #[source]
        source: std::io::Error,
    },
}

/// Reads a CARMEN log, plain text or gzip (detected by the magic bytes `1f 8b`).
pub fn read_log(path: &Path, opts: ReadOptions) -> Result<LogReadout, CarmenError> {
    RecordStream::open(path, opts)?.collect_all()
}

/// Reads a log from any byte source, plain or gzip; `name` only names it in messages.
pub fn read_log_from<R: Read>(
    src: R,
    name: &str,
    opts: ReadOptions,
) -> Result<LogReadout, CarmenError> {
    RecordStream::from_reader(src, name, opts)?.collect_all()
}

/// Parses a log held in a string; `name` only names it in messages.
pub fn parse_log_str(src: &str, name: &str, opts: ReadOptions) -> Result<LogReadout, CarmenError> {
    RecordStream::new(Box::new(src.as_bytes()), name, opts, false).collect_all()
}

/// One message read from a stream.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamedRecord {
    pub record: LogRecord,
    /// Read from an RLASER (rear scanner) line.
    pub rear_laser: bool,
}

/// A log read one line at a time ([`Self::next_record`]), so memory holds one line whatever
/// the log's size; malformed lines are errors located `file:line:col`, or skipped and counted
/// in lenient mode. [`read_log`] is this stream collected.
pub struct RecordStream<'a> {
    r: Box<dyn BufRead + 'a>,
    name: String,
    opts: ReadOptions,
    gz: bool,
    line_no: usize,
    bytes: Vec<u8>,
    /// Everything of a whole read but the records.
    counts: LogReadout,
}

impl<'a> RecordStream<'a> {
    /// Opens the log file at `path`, plain or gzip.
    pub fn open(path: &Path, opts: ReadOptions) -> Result<RecordStream<'static>, CarmenError> {
        let name = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|source| CarmenError::Io {
            path: name.clone(),
            source,
        })?;
        RecordStream::from_reader(file, &name, opts)
    }

    /// Reads from any byte source, plain or gzip; `name` only names it in messages.
    pub fn from_reader<R: Read + 'a>(
        src: R,
        name: &str,
        opts: ReadOptions,
    ) -> Result<RecordStream<'a>, CarmenError> {
        let mut buf = BufReader::new(src);
        let head = buf.fill_buf().map_err(|source| CarmenError::Io {
            path: name.to_string(),
            source,
        })?;
        let gz = head.len() >= 2 && head[0] == 0x1f && head[1] == 0x8b;
        Ok(if gz {
            let dec = BufReader::new(flate2::bufread::MultiGzDecoder::new(buf));
            RecordStream::new(Box::new(dec), name, opts, true)
        } else {
            RecordStream::new(Box::new(buf), name, opts, false)
        })
    }

    fn new(r: Box<dyn BufRead + 'a>, name: &str, opts: ReadOptions, gz: bool) -> Self {
        RecordStream {
            r,
            name: name.to_string(),
            opts,
            gz,
            line_no: 0,
            bytes: Vec::new(),
            counts: LogReadout::default(),
        }
    }

    /// The counts so far (skipped and unknown lines, the first ROBOTLASER1 range); `records`
    /// and `rear_laser_indices` stay empty.
    pub fn counts(&self) -> &LogReadout {
        &self.counts
    }

    /// The next message, or `None` at the end of the log.
    pub fn next_record(&mut self) -> Result<Option<StreamedRecord>, CarmenError> {
        while self.next_line()? {
            let text = String::from_utf8_lossy(&self.bytes);
            // A byte-order mark would turn the first message type into an unknown one.
            let text = match self.line_no {
                1 => text.strip_prefix('\u{feff}').unwrap_or(&text),
                _ => &text,
            };
            match parse_line(text, &mut self.counts) {
                Ok(Some(rec)) => return Ok(Some(rec)),
                Ok(None) => {}
                Err((col, message)) => {
                    let d = Diagnostic::error(&self.name, (self.line_no, col), message);
                    if !self.opts.lenient {
                        return Err(CarmenError::Malformed(d));
                    }
                    self.counts.skipped_lines += 1;
                    if self.counts.first_skipped.is_none() {
                        self.counts.first_skipped = Some(d.to_string());
                    }
                }
            }
        }
        Ok(None)
    }

    /// The error for a next line longer than [`MAX_LINE_BYTES`].
    fn line_too_long(&self) -> CarmenError {
        CarmenError::Malformed(Diagnostic::error(
            &self.name,
            (self.line_no + 1, 1),
            format!(
                "line longer than {} MiB; this is not a CARMEN text log, or it is corrupt",
                MAX_LINE_BYTES >> 20
            ),
        ))
    }

    /// Reads the next line into `self.bytes`; `false` at the end of the log.
    fn next_line(&mut self) -> Result<bool, CarmenError> {
        self.bytes.clear();
        match (&mut self.r)
            .take(MAX_LINE_BYTES)
            .read_until(b'\n', &mut self.bytes)
        {
            Ok(0) => Ok(false),
            Ok(n) if n as u64 == MAX_LINE_BYTES && self.bytes.last() != Some(&b'\n') => {
                Err(self.line_too_long())
            }
            Ok(_) => {
                self.line_no += 1;
                Ok(true)
            }
            Err(source) if self.gz => Err(CarmenError::Decompress {
                path: self.name.clone(),
                line: self.line_no,
                source,
            }),
            Err(source) => Err(CarmenError::Io {
                path: self.name.clone(),
                source,
            }),
        }
    }

    /// Every remaining message, with the counts.
    fn collect_all(mut self) -> Result<LogReadout, CarmenError> {
        let mut records = Vec::new();
        let mut rear = Vec::new();
        while let Some(r) = self.next_record()? {
            if r.rear_laser {
                rear.push(records.len());
            }
            records.push(r.record);
        }
        Ok(LogReadout {
            records,
            rear_laser_indices: rear,
            ..self.counts
        })
    }
}

/// A whitespace-separated token with its 1-based character column.
struct Tok<'a> {
    col: usize,
    s: &'a str,
}

fn tokenize(line: &str) -> Vec<Tok<'_>> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None; // (byte, col)
    let mut col = 0usize;
    for (i, ch) in line.char_indices() {
        col += 1;
        if ch.is_whitespace() {
            if let Some((b, c)) = start.take() {
                out.push(Tok {
                    col: c,
                    s: &line[b..i],
                });
            }
        } else if start.is_none() {
            start = Some((i, col));
        }
    }
    if let Some((b, c)) = start {
        out.push(Tok {
            col: c,
            s: &line[b..],
        });
    }
    out
}

type LineErr = (usize, String);

struct Fields<'a, 'b> {
    toks: &'b [Tok<'a>],
    kind: &'a str,
    end_col: usize,
}

impl<'a> Fields<'a, '_> {
    fn get(&self, i: usize, what: &str) -> Result<&Tok<'a>, LineErr> {
        self.toks.get(i).ok_or_else(|| {
            (
                self.end_col,
                format!(
                    "{} line ends before field {} ({what}); the line is truncated or has too few values",
                    self.kind, i
                ),
            )
        })
    }

    fn num(&self, i: usize, what: &str) -> Result<f64, LineErr> {
        let t = self.get(i, what)?;
        match t.s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err((
                t.col,
                format!(
                    "{} field {} ({what}) is `{}`, not a finite number; fix or remove the line, or read with --lenient",
                    self.kind,
                    i,
                    clip(t.s)
                ),
            )),
        }
    }

    fn count(&self, i: usize, what: &str) -> Result<usize, LineErr> {
        let t = self.get(i, what)?;
        t.s.parse::<usize>().map_err(|_| {
            (
                t.col,
                format!(
                    "{} field {} ({what}) is `{}`, not a whole number; fix or remove the line, or read with --lenient",
                    self.kind,
                    i,
                    clip(t.s)
                ),
            )
        })
    }

    fn pose(&self, i: usize, what: &str) -> Result<Pose2, LineErr> {
        Ok(Pose2::new(
            self.num(i, &format!("{what} x"))?,
            self.num(i + 1, &format!("{what} y"))?,
            self.num(i + 2, &format!("{what} theta"))?,
        ))
    }

    /// `ipc_timestamp host logger_timestamp` at `i`, and that they end the line.
    fn stamp(&self, i: usize) -> Result<(f64, String, f64), LineErr> {
        let ipc = self.num(i, "ipc_timestamp")?;
        let host = self.get(i + 1, "host")?.s.to_string();
        let logger = self.num(i + 2, "logger_timestamp")?;
        self.end(i + 3)?;
        Ok((ipc, host, logger))
    }

    fn end(&self, n: usize) -> Result<(), LineErr> {
        if let Some(t) = self.toks.get(n) {
            return Err((
                t.col,
                format!(
                    "{} line has {} extra value(s) after its last field (expected {} fields); \
                     check the beam count, or read with --lenient",
                    self.kind,
                    self.toks.len() - n,
                    n
                ),
            ));
        }
        Ok(())
    }
}

fn clip(s: &str) -> String {
    if s.chars().count() > 24 {
        format!("{}…", s.chars().take(24).collect::<String>())
    } else {
        s.to_string()
    }
}

/// The message on `line` (`None` for blank, comment and unknown lines, which `out` counts).
fn parse_line(line: &str, out: &mut LogReadout) -> Result<Option<StreamedRecord>, LineErr> {
    let toks = tokenize(line);
    let Some(first) = toks.first() else {
        return Ok(None);
    };
    if first.s.starts_with('#') {
        return Ok(None);
    }
    let f = Fields {
        toks: &toks,
        kind: first.s,
        end_col: line.trim_end().chars().count() + 1,
    };
    let record = match first.s {
        "FLASER" | "RLASER" => parse_flaser(&f)?,
        "ROBOTLASER1" => parse_robotlaser1(&f, out)?,
        "ODOM" => parse_odom(&f)?,
        "TRUEPOS" => parse_truepos(&f)?,
        "PARAM" => parse_param(&f)?,
        _ => {
            out.unknown_lines += 1;
            return Ok(None);
        }
    };
    Ok(Some(StreamedRecord {
        record,
        rear_laser: first.s == "RLASER",
    }))
}

impl Fields<'_, '_> {
    /// The `n` values from field `at` on, each `what`, once the line is checked to hold them
    /// all (`counted` names them in the message, `after` the count that announced them).
    fn announced(
        &self,
        at: usize,
        n: usize,
        (counted, after, what): (&str, &str, &str),
    ) -> Result<Vec<f64>, LineErr> {
        if self.toks.len() < at.saturating_add(n) {
            return Err((
                self.end_col,
                format!(
                    "{} announces {n} {counted} but the line has only {} values after {after}; \
                     the line is truncated or the count is wrong",
                    self.kind,
                    self.toks.len() - at
                ),
            ));
        }
        (0..n).map(|i| self.num(at + i, what)).collect()
    }
}

/// `FLASER n r… pose odometry stamp` (and `RLASER`, the rear scanner).
fn parse_flaser(f: &Fields) -> Result<LogRecord, LineErr> {
    let n = f.count(1, "number of readings")?;
    let ranges = f.announced(2, n, ("readings", "the count", "range"))?;
    let pose = f.pose(2 + n, "pose")?;
    let odom = f.pose(5 + n, "odometry")?;
    let (ipc, host, logger) = f.stamp(8 + n)?;
    Ok(LogRecord::Laser(LaserRecord {
        // FLASER: 180° right to left, whatever the beam count. RLASER: the rear scanner
        // faces backwards, so its beams start on the robot's left (+90°).
        start_angle_rad: if f.kind == "RLASER" {
            std::f64::consts::FRAC_PI_2
        } else {
            -std::f64::consts::FRAC_PI_2
        },
        fov_rad: std::f64::consts::PI,
        ranges_m: ranges,
        pose,
        odom,
        ipc_timestamp: ipc,
        host,
        logger_timestamp: logger,
    }))
}

/// The start angle, field of view and maximum range of a `ROBOTLASER1` line, its other
/// settings (type, resolution, accuracy, remission mode) only checked to be numbers.
fn robotlaser_settings(f: &Fields) -> Result<(f64, f64, f64), LineErr> {
    let _laser_type = f.num(1, "laser_type")?;
    let start = f.num(2, "start_angle")?;
    let fov = f.num(3, "fov")?;
    let _res = f.num(4, "angular_res")?;
    let max_range = f.num(5, "max_range")?;
    let _acc = f.num(6, "accuracy")?;
    let _rem_mode = f.num(7, "remission_mode")?;
    Ok((start, fov, max_range))
}

/// Checks that the five motion fields of a `ROBOTLASER1` line from `k` on (tv, rv, forward and
/// side safety, turn axis) are numbers.
fn robot_motion_fields(f: &Fields, k: usize) -> Result<(), LineErr> {
    for (j, what) in ["tv", "rv", "forward_safety", "side_safety", "turn_axis"]
        .iter()
        .enumerate()
    {
        f.num(k + j, what)?;
    }
    Ok(())
}

/// `ROBOTLASER1 laser_type start_angle fov angular_res max_range accuracy remission_mode
/// num_readings r… num_remissions rem… laser_pose robot_pose tv rv forward_safety side_safety
/// turn_axis stamp`; the first positive max_range goes to `out`.
fn parse_robotlaser1(f: &Fields, out: &mut LogReadout) -> Result<LogRecord, LineErr> {
    let (start, fov, max_range) = robotlaser_settings(f)?;
    let n = f.count(8, "num_readings")?;
    let ranges = f.announced(9, n, ("readings", "the count", "range"))?;
    let k = 9 + n;
    let m = f.count(k, "num_remissions")?;
    f.announced(k + 1, m, ("remissions", "that count", "remission"))?;
    let k = k + 1 + m;
    let laser_pose = f.pose(k, "laser pose")?;
    let _robot = f.pose(k + 3, "robot pose")?;
    robot_motion_fields(f, k + 6)?;
    let (ipc, host, logger) = f.stamp(k + 11)?;
    if out.robotlaser_max_range_m.is_none() && max_range > 0.0 {
        out.robotlaser_max_range_m = Some(max_range);
    }
    Ok(LogRecord::Laser(LaserRecord {
        start_angle_rad: start,
        fov_rad: fov,
        ranges_m: ranges,
        // The ranges are measured from the laser, so its pose is the scan's pose (as a
        // FLASER line's pose is); the robot pose is only checked.
        pose: laser_pose,
        odom: laser_pose,
        ipc_timestamp: ipc,
        host,
        logger_timestamp: logger,
    }))
}

/// `ODOM x y theta tv rv accel stamp`.
fn parse_odom(f: &Fields) -> Result<LogRecord, LineErr> {
    let pose = f.pose(1, "pose")?;
    let tv = f.num(4, "tv")?;
    let rv = f.num(5, "rv")?;
    let accel = f.num(6, "accel")?;
    let (ipc, host, logger) = f.stamp(7)?;
    Ok(LogRecord::Odom(OdomRecord {
        pose,
        tv_m_s: tv,
        rv_rad_s: rv,
        accel_m_s2: accel,
        ipc_timestamp: ipc,
        host,
        logger_timestamp: logger,
    }))
}

/// `TRUEPOS true_pose odometry stamp`.
fn parse_truepos(f: &Fields) -> Result<LogRecord, LineErr> {
    let truth = f.pose(1, "true pose")?;
    let odom = f.pose(4, "odometry")?;
    let (ipc, host, logger) = f.stamp(7)?;
    Ok(LogRecord::TruePos(TruePosRecord {
        truth,
        odom,
        ipc_timestamp: ipc,
        host,
        logger_timestamp: logger,
    }))
}

/// `PARAM name value [ipc host logger]`; some loggers drop the ipc stamp (`PARAM name value
/// host logger`), so only name and value are required.
fn parse_param(f: &Fields) -> Result<LogRecord, LineErr> {
    let name = f.get(1, "parameter name")?.s.to_string();
    let rest: Vec<&str> = f.toks[2..].iter().map(|t| t.s).collect();
    let value = if rest.len() >= 4
        && rest[rest.len() - 3].parse::<f64>().is_ok()
        && rest[rest.len() - 1].parse::<f64>().is_ok()
    {
        rest[..rest.len() - 3].join(" ")
    } else if let Some(v) = rest.first() {
        v.to_string()
    } else {
        return Err((
            f.end_col,
            "PARAM line has a name but no value; add the value or remove the line".into(),
        ));
    };
    Ok(LogRecord::Param { name, value })
}

#[cfg(test)]
mod tests {
    #[test]
    fn ranges_are_written_as_the_float_formatter_writes_them() {
        for r in [
            0.0, 0.001, 0.5, 1.25, 7.999, 32.767, 81.92, 123.456, -1.5, 8.191,
        ] {
            let mut fast = String::new();
            super::push_range(&mut fast, r);
            assert_eq!(fast, format!(" {r:.3}"), "range {r}");
        }
        let mut odd = String::new();
        super::push_range(&mut odd, f64::NAN);
        assert_eq!(odd, " NaN");
    }

    use super::*;

    const SAMPLE: &str = "# comment\n\nPARAM robot_front_laser_max 50 1.0 host 1.0\n\
        PARAM robot_frontlaser_offset 0.0 nohost 0\n\
        FLASER 3 1.0 2.0 3.0 0.1 0.2 0.3 0.1 0.2 0.3 10.5 h 10.6\n\
        NEFF 10\n\
        ODOM 1 2 0.5 0.1 0.2 0 11.0 h 11.0\n\
        TRUEPOS 1 2 3 4 5 6 12.0 h 12.0\n\
        ROBOTLASER1 0 -1.5 3.0 0.5 30 0.01 0 3 1 2 3 0 1.1 2 0.3 1 2 0.3 0.1 0.2 0 0 0 13.0 h 13.0\n";

    #[test]
    fn reads_every_kind() {
        let r = parse_log_str(SAMPLE, "s.log", ReadOptions::default()).unwrap();
        assert_eq!(r.records.len(), 6);
        assert_eq!(r.unknown_lines, 1);
        assert_eq!(
            r.records[0],
            LogRecord::Param {
                name: "robot_front_laser_max".into(),
                value: "50".into()
            }
        );
        assert_eq!(
            r.records[1],
            LogRecord::Param {
                name: "robot_frontlaser_offset".into(),
                value: "0.0".into()
            }
        );
        let LogRecord::Laser(l) = &r.records[2] else {
            panic!()
        };
        assert_eq!(l.ranges_m, vec![1.0, 2.0, 3.0]);
        assert_eq!(l.fov_rad, std::f64::consts::PI);
        assert_eq!(l.ipc_timestamp, 10.5);
        let LogRecord::Laser(rl) = &r.records[5] else {
            panic!()
        };
        assert_eq!(rl.start_angle_rad, -1.5);
        assert_eq!(rl.fov_rad, 3.0);
        assert_eq!(rl.pose, Pose2::new(1.1, 2.0, 0.3), "the laser pose");
        assert_eq!(r.robotlaser_max_range_m, Some(30.0));
    }

    #[test]
    fn byte_order_mark_is_ignored() {
        let r = parse_log_str(
            "\u{feff}ODOM 1 2 0.5 0.1 0.2 0 11.0 h 11.0\n",
            "b",
            ReadOptions::default(),
        )
        .unwrap();
        assert_eq!(r.records.len(), 1);
    }

    #[test]
    fn bad_value_is_located() {
        let src = "FLASER 2 1.0 x 0 0 0 0 0 0 1 h 1\n";
        let e = parse_log_str(src, "a.log", ReadOptions::default()).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with("a.log:1:14: FLASER field 3 (range)"),
            "{msg}"
        );
    }

    #[test]
    fn short_line_is_located_and_lenient_skips() {
        let src = "ODOM 1 2\nODOM 1 2 0.5 0.1 0.2 0 11.0 h 11.0\nFLASER 5 1 2\n";
        let e = parse_log_str(src, "a.log", ReadOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with("a.log:1:9: ODOM line ends"),
            "{e}"
        );
        let r = parse_log_str(src, "a.log", ReadOptions { lenient: true }).unwrap();
        assert_eq!(r.skipped_lines, 2);
        assert_eq!(r.records.len(), 1);
        assert!(r.first_skipped.unwrap().starts_with("a.log:1:9:"));
    }
}
