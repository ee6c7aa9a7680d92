//! Turning a real CARMEN log (or a ROS 2 bag, [`load_bag_run`]) into the shape the recognizer and evaluation consume
//! ([`crate::log::RunLog`]): one run, one lap holding every laser frame, door configuration
//! `"unknown"`.
//!
//! **Whole or streamed.** [`load_run`] reads the log into memory and makes every frame;
//! [`LogSurvey::read`] then [`stream_frames`] read it twice as a stream (the first pass learns
//! what the first frame already needs: laser range, which lasers are used, whether stamps serve
//! as time, the TRUEPOS messages) and make the same frames one at a time.
//!
//! **Corrected logs.** The Radish "corrected" logs carry no raw odometry: a laser line's `x y theta`
//! is the corrected (ground-truth quality) pose and `odom_*` repeats it. The odometry the
//! recognizer sees is therefore *derived*: for consecutive laser frames k-1, k the corrected
//! increment `d_k = pose_{k-1}.between(pose_k)` (in the robot frame) is passed through a caller's
//! noise function (`perturb`, seeded by the caller; [`noise_free`] for tests) and the noisy
//! increments are composed, starting from the first corrected pose. With [`noise_free`] the
//! odometry equals the corrected pose.
//!
//! **Truth.** [`TruthSource::Corrected`] (`--truth corrected`): the corrected pose of each laser
//! line. [`TruthSource::TruePos`] (`--truth truepos`): the `TRUEPOS` message nearest in time
//! (`ipc_timestamp`) to each laser line, at most [`TRUEPOS_MAX_GAP_S`] away.
//!
//! **Time.** `time_s` is the laser line's `ipc_timestamp` minus the first one, forced
//! non-decreasing. When the stamps are unusable — more than 10 % of consecutive laser lines
//! share or reverse their stamp, as in csail, whose stamps are printed with six significant
//! digits (`1.13486e+09`) — time is derived instead from the distance travelled along the
//! corrected path at [`NOMINAL_SPEED_M_S`] (the P3-DX cruise speed), and
//! [`RunLog`]'s frames say so only through this rule (check [`stamps_usable`]).
//!
//! **Lasers used.** FLASER and ROBOTLASER1 lines; RLASER (rear scanner) lines only when the log
//! has no other laser.
//!
//! **Beam layout.** FLASER: n beams over 180°, right to left (CARMEN convention, whatever n);
//! RLASER: the same, facing backwards (beam 0 at +90°); ROBOTLASER1: its own start angle and
//! field of view.
//!
//! **Bags.** A ROS 2 bag (MCAP) is read by [`crate::io::ros2::bag::read_bag`] into the same
//! laser and truth records (each scan's pose the odometry at its stamp, the truth topic as
//! TRUEPOS, the maximum range the scans' `range_max`), then made into frames by the same rules.
//!
//! The sensor mount is the identity
//! (the logged pose is already the laser's). Maximum range, see [`max_range_m`].

use crate::geom::{OdomPose, Pose2, TruePose};
use crate::io::carmen::{
    LaserRecord, LogReadout, LogRecord, ReadOptions, RecordStream, TruePosRecord, read_log,
};
use crate::log::{Frame, LapLog, RunLog};
use crate::scan::{BeamLayout, Scan};

/// Used when the log names no laser maximum range, metres. SICK LMS scanners in CARMEN logs
/// report "no return" as ~81.9 m, so readings at or beyond 80 m are treated as no return.
pub const DEFAULT_MAX_RANGE_M: f64 = 80.0;

/// Speed used to derive time from travelled distance when a log's stamps are unusable, m/s.
pub const NOMINAL_SPEED_M_S: f64 = 0.4;

/// Whether laser stamps can serve as time: at most 10 % of consecutive pairs fail to increase.
pub fn stamps_usable(lasers: &[&LaserRecord]) -> bool {
    let mut check = StampCheck::default();
    for l in lasers {
        check.push(l.ipc_timestamp);
    }
    check.usable()
}

/// [`stamps_usable`]'s rule kept stamp by stamp, for a log read as a stream.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StampCheck {
    last: Option<f64>,
    /// Stamps seen.
    pub count: usize,
    /// Stamps not later than the one before.
    bad: usize,
}

impl StampCheck {
    /// Counts the next laser's stamp.
    pub fn push(&mut self, t: f64) {
        if self.last.is_some_and(|p| t <= p) {
            self.bad += 1;
        }
        self.last = Some(t);
        self.count += 1;
    }

    /// At most 10 % of consecutive pairs fail to increase.
    pub fn usable(&self) -> bool {
        self.bad * 10 <= self.count.saturating_sub(1)
    }
}

/// The farthest a TRUEPOS message may be in time from a laser line to serve as its truth, seconds.
pub const TRUEPOS_MAX_GAP_S: f64 = 1.0;

/// Where the ground truth comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruthSource {
    /// The corrected pose on each laser line.
    Corrected,
    /// TRUEPOS messages matched to laser lines by timestamp.
    TruePos,
}

/// Why a log could not be turned into a run.
#[derive(Debug, thiserror::Error)]
pub enum RealLogError {
    /// The log itself could not be read.
    #[error(transparent)]
    Read(#[from] crate::io::carmen::CarmenError),
    /// The bag could not be read.
    #[error(transparent)]
    Bag(#[from] crate::io::ros2::bag::BagError),
    #[error(
        "{0}: the log holds no laser messages (FLASER, RLASER or ROBOTLASER1); check that it is a CARMEN laser log"
    )]
    NoLaser(String),
    #[error(
        "{0}: --truth truepos asked for, but the log holds no TRUEPOS messages; use --truth corrected"
    )]
    NoTruePos(String),
    #[error(
        "{name}: laser message {index} (time {time:.3}) has no TRUEPOS within {max_gap:.1} s (nearest {gap:.3} s away); \
         use --truth corrected"
    )]
    TruePosGap {
        name: String,
        index: usize,
        time: f64,
        gap: f64,
        max_gap: f64,
    },
}

/// The identity noise model: odometry increments pass through unchanged.
pub fn noise_free(increment: Pose2) -> Pose2 {
    increment
}

/// The laser maximum range to use for a log, metres: the first of
/// 1. `PARAM robot_front_laser_max` (or `laser_front_laser_max_range`) if positive,
/// 2. the `max_range` field of a ROBOTLASER1 message,
/// 3. [`DEFAULT_MAX_RANGE_M`].
///
/// Readings at or beyond it are "no return".
pub fn max_range_m(readout: &LogReadout) -> f64 {
    let param = readout.records.iter().find_map(param_max_range);
    max_range_or_default(param, readout.robotlaser_max_range_m)
}

/// The range a `PARAM robot_front_laser_max` (or `laser_front_laser_max_range`) message gives,
/// if `r` is one and its value is positive.
fn param_max_range(r: &LogRecord) -> Option<f64> {
    match r {
        LogRecord::Param { name, value }
            if name == "robot_front_laser_max" || name == "laser_front_laser_max_range" =>
        {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
        }
        _ => None,
    }
}

/// [`max_range_m`]'s order: the PARAM, then the ROBOTLASER1 field, then the default.
fn max_range_or_default(param: Option<f64>, robotlaser: Option<f64>) -> f64 {
    match (param, robotlaser) {
        (Some(v), _) => v,
        (None, Some(v)) if v.is_finite() && v > 0.0 => v,
        _ => DEFAULT_MAX_RANGE_M,
    }
}

/// Reads a log file (plain or gzip) and turns it into one run: [`read_log`] then [`log_to_run`].
/// Also returns the readout's counts (records are dropped to save memory).
pub fn load_run(
    path: &std::path::Path,
    opts: ReadOptions,
    truth: TruthSource,
    perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<(RunLog, LogReadout), RealLogError> {
    let mut readout = read_log(path, opts)?;
    let run = log_to_run(&readout, &path.display().to_string(), truth, perturb)?;
    readout.records = Vec::new();
    Ok((run, readout))
}

/// Reads a ROS 2 bag (MCAP) and turns it into one run, by the rules of [`corrected_to_run`]
/// (the bag's scan poses play the corrected poses, its truth topic the TRUEPOS messages).
pub fn load_bag_run(
    path: &std::path::Path,
    topics: &crate::io::ros2::bag::BagTopics,
    truth: TruthSource,
    perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<RunLog, RealLogError> {
    let bag = crate::io::ros2::bag::read_bag(path, topics)?;
    let lasers: Vec<&LaserRecord> = bag.lasers.iter().collect();
    let truepos: Vec<&TruePosRecord> = bag.truepos.iter().collect();
    let max_range_m = max_range_or_default(None, bag.max_range_m);
    let name = path.display().to_string();
    corrected_to_run(&lasers, &truepos, &name, truth, max_range_m, perturb)
}

/// The laser messages a run is made of: front lasers only, unless the log has nothing but rear
/// ones (interleaving two scanners would make every other frame look backwards).
fn lasers_used(readout: &LogReadout) -> Vec<&LaserRecord> {
    let rear: std::collections::HashSet<usize> =
        readout.rear_laser_indices.iter().copied().collect();
    let all: Vec<(usize, &LaserRecord)> = readout
        .records
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r {
            LogRecord::Laser(l) => Some((i, l)),
            _ => None,
        })
        .collect();
    let any_front = all.iter().any(|(i, _)| !rear.contains(i));
    all.into_iter()
        .filter(|(i, _)| !any_front || !rear.contains(i))
        .map(|(_, l)| l)
        .collect()
}

/// Whether the run [`log_to_run`] makes of `readout` takes its time from the stamps
/// ([`stamps_usable`]) rather than from the travelled distance.
pub fn log_stamps_usable(readout: &LogReadout) -> bool {
    stamps_usable(&lasers_used(readout))
}

/// Turns a read log into one run; see the module documentation for every convention.
/// `perturb` maps each corrected increment (robot frame) to the odometry increment.
pub fn log_to_run(
    readout: &LogReadout,
    name: &str,
    truth: TruthSource,
    perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<RunLog, RealLogError> {
    let lasers = lasers_used(readout);
    let truepos: Vec<&TruePosRecord> = readout
        .records
        .iter()
        .filter_map(|r| match r {
            LogRecord::TruePos(t) => Some(t),
            _ => None,
        })
        .collect();
    corrected_to_run(
        &lasers,
        &truepos,
        name,
        truth,
        max_range_m(readout),
        perturb,
    )
}

/// The core of [`log_to_run`], on the laser and TRUEPOS messages of one log.
pub fn corrected_to_run(
    lasers: &[&LaserRecord],
    truepos: &[&TruePosRecord],
    name: &str,
    truth: TruthSource,
    max_range_m: f64,
    perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<RunLog, RealLogError> {
    if lasers.is_empty() {
        return Err(RealLogError::NoLaser(name.to_string()));
    }
    let tp = sorted_truepos(truepos.iter().map(|t| (t.ipc_timestamp, t.truth)).collect());
    if truth == TruthSource::TruePos && tp.is_empty() {
        return Err(RealLogError::NoTruePos(name.to_string()));
    }
    let mut maker = FrameMaker::new(
        name,
        truth,
        &tp,
        max_range_m,
        stamps_usable(lasers),
        perturb,
    );
    let frames = lasers
        .iter()
        .map(|l| maker.make(l))
        .collect::<Result<Vec<Frame>, RealLogError>>()?;
    Ok(one_lap_run(frames))
}

/// TRUEPOS (time, pose) sorted by time (stably: equal stamps keep file order).
fn sorted_truepos(mut tp: Vec<(f64, Pose2)>) -> Vec<(f64, Pose2)> {
    tp.sort_by(|a, b| a.0.total_cmp(&b.0));
    tp
}

/// A real log's run: one lap, doors unknown.
fn one_lap_run(frames: Vec<Frame>) -> RunLog {
    RunLog {
        run: 0,
        laps: vec![LapLog {
            lap: 0,
            door_config: "unknown".into(),
            open_doors: Vec::new(),
            frames,
        }],
    }
}

/// Makes the frames of a log's lasers, one at a time and in order (the module doc gives every
/// rule): derived odometry, time, truth and beam layout.
struct FrameMaker<'a, P> {
    name: &'a str,
    truth: TruthSource,
    /// TRUEPOS (time, pose), sorted by time.
    truepos: &'a [(f64, Pose2)],
    max_range_m: f64,
    use_stamps: bool,
    perturb: P,
    /// Lasers made so far.
    k: usize,
    /// The previous laser's corrected pose.
    prev: Option<Pose2>,
    t0: f64,
    odom: Pose2,
    travelled_m: f64,
    last_time_s: f64,
}

impl<'a, P: FnMut(Pose2) -> Pose2> FrameMaker<'a, P> {
    fn new(
        name: &'a str,
        truth: TruthSource,
        truepos: &'a [(f64, Pose2)],
        max_range_m: f64,
        use_stamps: bool,
        perturb: P,
    ) -> Self {
        FrameMaker {
            name,
            truth,
            truepos,
            max_range_m,
            use_stamps,
            perturb,
            k: 0,
            prev: None,
            t0: 0.0,
            odom: Pose2::IDENTITY,
            travelled_m: 0.0,
            last_time_s: 0.0,
        }
    }

    /// The frame of the next laser `l`.
    fn make(&mut self, l: &LaserRecord) -> Result<Frame, RealLogError> {
        let time_s = self.advance(l);
        let true_pose = self.true_pose(l)?;
        self.k += 1;
        let n = l.ranges_m.len();
        let mut layout = BeamLayout::centered(n, l.fov_rad, self.max_range_m, Pose2::IDENTITY);
        layout.start_angle_rad = l.start_angle_rad;
        Ok(Frame {
            time_s,
            odom: OdomPose(self.odom),
            truth: TruePose(true_pose),
            scan: Scan {
                layout,
                ranges_m: l.ranges_m.clone(),
                time_s,
            },
        })
    }

    /// Moves the odometry on to laser `l` (by its perturbed motion) and returns its time:
    /// from its stamp or the distance travelled, never before the previous frame's.
    fn advance(&mut self, l: &LaserRecord) -> f64 {
        match self.prev {
            Some(prev) => {
                self.odom = self.odom.compose(&(self.perturb)(prev.between(&l.pose)));
                self.travelled_m += prev.distance(&l.pose);
            }
            None => (self.odom, self.t0) = (l.pose, l.ipc_timestamp),
        }
        self.prev = Some(l.pose);
        let raw = if self.use_stamps {
            l.ipc_timestamp - self.t0
        } else {
            self.travelled_m / NOMINAL_SPEED_M_S
        };
        let time_s = raw.max(self.last_time_s);
        self.last_time_s = time_s;
        time_s
    }

    /// The truth of laser `l` (the `k`-th): its corrected pose or the nearest TRUEPOS.
    fn true_pose(&self, l: &LaserRecord) -> Result<Pose2, RealLogError> {
        if self.truth == TruthSource::Corrected {
            return Ok(l.pose);
        }
        let (gap, p) = nearest(self.truepos, l.ipc_timestamp);
        if gap > TRUEPOS_MAX_GAP_S {
            return Err(RealLogError::TruePosGap {
                name: self.name.to_string(),
                index: self.k,
                time: l.ipc_timestamp,
                gap,
                max_gap: TRUEPOS_MAX_GAP_S,
            });
        }
        Ok(p)
    }
}

/// What a first pass over a log learns that its first frame already needs: the laser range,
/// whether it has front lasers, whether their stamps serve as time, and (for
/// [`TruthSource::TruePos`]) every TRUEPOS message's time and pose (40 bytes each; no scans).
#[derive(Clone, Debug, Default)]
pub struct LogSurvey {
    param_max_range_m: Option<f64>,
    front: StampCheck,
    rear: StampCheck,
    truepos: Vec<(f64, Pose2)>,
    /// The read's counts (skipped, unknown lines; no records).
    pub counts: LogReadout,
}

impl LogSurvey {
    /// Reads `path` once, as a stream.
    pub fn read(
        path: &std::path::Path,
        opts: ReadOptions,
        truth: TruthSource,
    ) -> Result<LogSurvey, RealLogError> {
        let mut s = LogSurvey::default();
        let mut stream = RecordStream::open(path, opts)?;
        while let Some(r) = stream.next_record()? {
            match &r.record {
                LogRecord::Laser(l) if r.rear_laser => s.rear.push(l.ipc_timestamp),
                LogRecord::Laser(l) => s.front.push(l.ipc_timestamp),
                LogRecord::TruePos(t) if truth == TruthSource::TruePos => {
                    s.truepos.push((t.ipc_timestamp, t.truth));
                }
                other => {
                    s.param_max_range_m = s.param_max_range_m.or(param_max_range(other));
                }
            }
        }
        s.counts = stream.counts().clone();
        s.truepos = sorted_truepos(std::mem::take(&mut s.truepos));
        Ok(s)
    }

    /// Whether a laser message is one of the run's frames: front lasers only, unless the log
    /// has nothing but rear ones (interleaving two scanners would make every other frame look
    /// backwards).
    fn uses(&self, rear_laser: bool) -> bool {
        !rear_laser || self.front.count == 0
    }

    /// The stamps of the lasers used.
    fn stamps(&self) -> &StampCheck {
        if self.front.count > 0 {
            &self.front
        } else {
            &self.rear
        }
    }

    /// Frames the run has (lasers used).
    pub fn frames(&self) -> usize {
        self.stamps().count
    }
}

/// The lasers' maximum range, metres: the log's parameter, else the first ROBOTLASER1's, else
/// the default.
fn survey_max_range_m(survey: &LogSurvey) -> f64 {
    max_range_or_default(
        survey.param_max_range_m,
        survey.counts.robotlaser_max_range_m,
    )
}

/// Reads the log at `path` a second time, after its [`LogSurvey`], and hands each frame of its
/// run to `on_frame` in order: the frames [`load_run`] gives, one at a time, so memory holds one
/// line and one frame whatever the log's size. `perturb` as for [`log_to_run`].
pub fn stream_frames(
    path: &std::path::Path,
    opts: ReadOptions,
    survey: &LogSurvey,
    truth: TruthSource,
    perturb: impl FnMut(Pose2) -> Pose2,
    mut on_frame: impl FnMut(Frame),
) -> Result<(), RealLogError> {
    let name = path.display().to_string();
    if survey.frames() == 0 {
        return Err(RealLogError::NoLaser(name));
    }
    if truth == TruthSource::TruePos && survey.truepos.is_empty() {
        return Err(RealLogError::NoTruePos(name));
    }
    let max_range_m = survey_max_range_m(survey);
    let use_stamps = survey.stamps().usable();
    let tp = &survey.truepos;
    let mut maker = FrameMaker::new(&name, truth, tp, max_range_m, use_stamps, perturb);
    let mut stream = RecordStream::open(path, opts)?;
    while let Some(r) = stream.next_record()? {
        if let LogRecord::Laser(l) = &r.record
            && survey.uses(r.rear_laser)
        {
            on_frame(maker.make(l)?);
        }
    }
    Ok(())
}

/// The entry of `sorted` (by time) nearest to `t`: (|gap| seconds, pose). `sorted` is non-empty.
fn nearest(sorted: &[(f64, Pose2)], t: f64) -> (f64, Pose2) {
    let i = sorted.partition_point(|e| e.0 < t);
    let mut best = (f64::INFINITY, sorted[0].1);
    for j in [i.saturating_sub(1), i.min(sorted.len() - 1)] {
        let g = (sorted[j].0 - t).abs();
        if g < best.0 {
            best = (g, sorted[j].1);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::carmen::{ReadOptions, parse_log_str};

    const LOG: &str = "PARAM robot_front_laser_max 50 0 h 0\n\
        FLASER 3 1 2 81.9 0 0 0 0 0 0 100.0 h 100.0\n\
        TRUEPOS 0.01 0 0 0 0 0 100.05 h 100.05\n\
        FLASER 3 1 2 3 1 0 0.5 1 0 0.5 100.2 h 100.2\n\
        TRUEPOS 1 0.01 0.5 0 0 0 100.25 h 100.25\n\
        FLASER 3 1 2 3 2 1 1.0 2 1 1.0 100.3 h 100.3\n";

    #[test]
    fn noise_free_odometry_equals_corrected_pose() {
        let r = parse_log_str(LOG, "t", ReadOptions::default()).unwrap();
        let run = log_to_run(&r, "t", TruthSource::Corrected, noise_free).unwrap();
        let f: Vec<_> = run.frames().collect();
        assert_eq!(f.len(), 3);
        for fr in &f {
            assert!(fr.odom.0.distance(&fr.truth.0) < 1e-9);
            assert!((fr.odom.0.theta - fr.truth.0.theta).abs() < 1e-9);
            assert_eq!(fr.scan.layout.count, 3);
            assert_eq!(fr.scan.layout.max_range_m, 50.0);
            assert!((fr.scan.layout.fov_rad() - std::f64::consts::PI).abs() < 1e-12);
        }
        assert!(!f[0].scan.is_hit(2));
        assert!((f[1].time_s - 0.2).abs() < 1e-9);
        assert!((f[2].time_s - 0.3).abs() < 1e-9);
        assert_eq!(run.laps[0].door_config, "unknown");
    }

    #[test]
    fn unusable_stamps_give_time_from_distance() {
        let src = "FLASER 1 1 0 0 0 0 0 0 5 h 5\nFLASER 1 1 2 0 0 2 0 0 5 h 5\nFLASER 1 1 2 0.4 0 2 0.4 0 5 h 5\n";
        let r = parse_log_str(src, "c", ReadOptions::default()).unwrap();
        let run = log_to_run(&r, "c", TruthSource::Corrected, noise_free).unwrap();
        let t: Vec<f64> = run.frames().map(|f| f.time_s).collect();
        assert!(
            (t[1] - 5.0).abs() < 1e-9 && (t[2] - 6.0).abs() < 1e-9,
            "{t:?}"
        );
    }

    #[test]
    fn perturbed_increments_are_composed() {
        let r = parse_log_str(LOG, "t", ReadOptions::default()).unwrap();
        let run = log_to_run(&r, "t", TruthSource::Corrected, |d| {
            Pose2::new(d.x * 2.0, d.y * 2.0, d.theta)
        })
        .unwrap();
        let f: Vec<_> = run.frames().collect();
        assert!((f[1].odom.0.x - 2.0).abs() < 1e-9);
    }

    #[test]
    fn truepos_matched_by_time() {
        let r = parse_log_str(LOG, "t", ReadOptions::default()).unwrap();
        let run = log_to_run(&r, "t", TruthSource::TruePos, noise_free).unwrap();
        let f: Vec<_> = run.frames().collect();
        assert_eq!(f[0].truth.0.x, 0.01);
        assert_eq!(f[1].truth.0.y, 0.01);
        let no_tp = parse_log_str(
            "FLASER 1 1 0 0 0 0 0 0 5 h 5\n",
            "u",
            ReadOptions::default(),
        )
        .unwrap();
        let e = log_to_run(&no_tp, "u", TruthSource::TruePos, noise_free).unwrap_err();
        assert!(matches!(e, RealLogError::NoTruePos(_)), "{e}");
        let gap = "FLASER 1 1 0 0 0 0 0 0 5 h 5\nTRUEPOS 0 0 0 0 0 0 9 h 9\n";
        let gap = parse_log_str(gap, "g", ReadOptions::default()).unwrap();
        let e = log_to_run(&gap, "g", TruthSource::TruePos, noise_free).unwrap_err();
        assert!(e.to_string().contains("nearest 4.000 s away"), "{e}");
    }
}
