//! Turning a real CARMEN log into the shape the recognizer and evaluation consume
//! ([`crate::log::RunLog`]): one run, one lap holding every laser frame, door configuration
//! `"unknown"`.
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
//! field of view. The sensor mount is the identity
//! (the logged pose is already the laser's). Maximum range, see [`max_range_m`].

use crate::geom::{OdomPose, Pose2, TruePose};
use crate::io::carmen::{LaserRecord, LogReadout, LogRecord, ReadOptions, TruePosRecord, read_log};
use crate::log::{Frame, LapLog, RunLog};
use crate::scan::{BeamLayout, Scan};

/// Used when the log names no laser maximum range, metres. SICK LMS scanners in CARMEN logs
/// report "no return" as ~81.9 m, so readings at or beyond 80 m are treated as no return.
pub const DEFAULT_MAX_RANGE_M: f64 = 80.0;

/// Speed used to derive time from travelled distance when a log's stamps are unusable, m/s.
pub const NOMINAL_SPEED_M_S: f64 = 0.4;

/// Whether laser stamps can serve as time: at most 10 % of consecutive pairs fail to increase.
pub fn stamps_usable(lasers: &[&LaserRecord]) -> bool {
    let bad = lasers
        .windows(2)
        .filter(|w| w[1].ipc_timestamp <= w[0].ipc_timestamp)
        .count();
    bad * 10 <= lasers.len().saturating_sub(1)
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
    for r in &readout.records {
        if let LogRecord::Param { name, value } = r
            && (name == "robot_front_laser_max" || name == "laser_front_laser_max_range")
            && let Ok(v) = value.parse::<f64>()
            && v.is_finite()
            && v > 0.0
        {
            return v;
        }
    }
    match readout.robotlaser_max_range_m {
        Some(v) if v.is_finite() && v > 0.0 => v,
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

/// Turns a read log into one run; see the module documentation for every convention.
/// `perturb` maps each corrected increment (robot frame) to the odometry increment.
pub fn log_to_run(
    readout: &LogReadout,
    name: &str,
    truth: TruthSource,
    perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<RunLog, RealLogError> {
    // Front lasers only, unless the log has nothing but rear ones: interleaving two scanners
    // would make every other frame look backwards.
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
    let lasers: Vec<&LaserRecord> = all
        .into_iter()
        .filter(|(i, _)| !any_front || !rear.contains(i))
        .map(|(_, l)| l)
        .collect();
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
    mut perturb: impl FnMut(Pose2) -> Pose2,
) -> Result<RunLog, RealLogError> {
    if lasers.is_empty() {
        return Err(RealLogError::NoLaser(name.to_string()));
    }
    let mut tp: Vec<(f64, Pose2)> = truepos.iter().map(|t| (t.ipc_timestamp, t.truth)).collect();
    if truth == TruthSource::TruePos {
        if tp.is_empty() {
            return Err(RealLogError::NoTruePos(name.to_string()));
        }
        tp.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let t0 = lasers[0].ipc_timestamp;
    let use_stamps = stamps_usable(lasers);
    let mut travelled = 0.0f64;
    let mut frames = Vec::with_capacity(lasers.len());
    let mut odom = lasers[0].pose;
    let mut last_time = 0.0f64;
    for (k, l) in lasers.iter().enumerate() {
        if k > 0 {
            let inc = lasers[k - 1].pose.between(&l.pose);
            odom = odom.compose(&perturb(inc));
        }
        if k > 0 {
            travelled += lasers[k - 1].pose.distance(&l.pose);
        }
        let raw = if use_stamps {
            l.ipc_timestamp - t0
        } else {
            travelled / NOMINAL_SPEED_M_S
        };
        let time_s = raw.max(last_time);
        last_time = time_s;
        let true_pose = match truth {
            TruthSource::Corrected => l.pose,
            TruthSource::TruePos => {
                let (gap, p) = nearest(&tp, l.ipc_timestamp);
                if gap > TRUEPOS_MAX_GAP_S {
                    return Err(RealLogError::TruePosGap {
                        name: name.to_string(),
                        index: k,
                        time: l.ipc_timestamp,
                        gap,
                        max_gap: TRUEPOS_MAX_GAP_S,
                    });
                }
                p
            }
        };
        let n = l.ranges_m.len();
        let mut layout = BeamLayout::centered(n, l.fov_rad, max_range_m, Pose2::IDENTITY);
        layout.start_angle_rad = l.start_angle_rad;
        frames.push(Frame {
            time_s,
            odom: OdomPose(odom),
            truth: TruePose(true_pose),
            scan: Scan {
                layout,
                ranges_m: l.ranges_m.clone(),
                time_s,
            },
        });
    }
    Ok(RunLog {
        run: 0,
        laps: vec![LapLog {
            lap: 0,
            door_config: "unknown".into(),
            open_doors: Vec::new(),
            frames,
        }],
    })
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
