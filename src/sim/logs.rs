//! Writing simulated runs as CARMEN logs, plus a JSON manifest.
//!
//! Per frame, in this order: `ODOM` (odometry pose; speeds from the previous frame), `FLASER`
//! (181 ranges; the odometry pose in both pose slots, as a robot's logger would record it) and
//! `TRUEPOS` (ground truth beside the odometry pose). Timestamps are seconds since the run
//! started; the host is `placewords-sim`. `#` comment lines mark each lap and its doors.

use crate::geom::{Pose2, wrap_angle};
use crate::io::atomic::write_atomic;
use crate::io::carmen::{LaserRecord, LogRecord, OdomRecord, TruePosRecord, write_record};
use crate::log::RunLog;
use crate::sim::plan::SimPlan;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Host name written in every record.
pub const HOST: &str = "placewords-sim";

/// The CARMEN text of one run.
pub fn carmen_log(scn: &SimPlan, run: &RunLog) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "# placewords simulation: scenario {}, seed {}, run {}, route {} of world {}\n",
        scn.name, scn.seed, run.run, scn.route.id, scn.world.name
    ));
    let mut prev: Option<(f64, Pose2)> = None;
    for lap in &run.laps {
        out.push_str(&format!(
            "# lap {} doors {}: open [{}]\n",
            lap.lap,
            lap.door_config,
            lap.open_doors.join(" ")
        ));
        for f in &lap.frames {
            let odom = f.odom.0;
            let (tv, rv) = match prev {
                Some((t0, p0)) if f.time_s > t0 => {
                    let dt = f.time_s - t0;
                    let d = p0.between(&odom);
                    let dist = (d.x * d.x + d.y * d.y).sqrt() * d.x.signum();
                    (dist / dt, wrap_angle(odom.theta - p0.theta) / dt)
                }
                _ => (0.0, 0.0),
            };
            prev = Some((f.time_s, odom));
            write_record(
                &mut out,
                &LogRecord::Odom(OdomRecord {
                    pose: odom,
                    tv_m_s: tv,
                    rv_rad_s: rv,
                    accel_m_s2: 0.0,
                    ipc_timestamp: f.time_s,
                    host: HOST.into(),
                    logger_timestamp: f.time_s,
                }),
            );
            write_record(
                &mut out,
                &LogRecord::Laser(LaserRecord {
                    start_angle_rad: f.scan.layout.start_angle_rad,
                    fov_rad: f.scan.layout.fov_rad(),
                    ranges_m: f.scan.ranges_m.clone(),
                    pose: odom,
                    odom,
                    ipc_timestamp: f.time_s,
                    host: HOST.into(),
                    logger_timestamp: f.time_s,
                }),
            );
            write_record(
                &mut out,
                &LogRecord::TruePos(TruePosRecord {
                    truth: f.truth.0,
                    odom,
                    ipc_timestamp: f.time_s,
                    host: HOST.into(),
                    logger_timestamp: f.time_s,
                }),
            );
        }
    }
    out
}

/// The JSON manifest of a simulation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    pub placewords_version: String,
    pub scenario: String,
    pub scenario_name: String,
    pub world: String,
    pub route: String,
    pub seed: u64,
    pub laps_override: Option<usize>,
    pub runs: Vec<ManifestRun>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ManifestRun {
    pub run: usize,
    pub file: String,
    pub start_waypoint: usize,
    pub frames: usize,
    pub laps: Vec<ManifestLap>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ManifestLap {
    pub lap: usize,
    pub door_config: String,
    pub open_doors: Vec<String>,
    pub frames: usize,
}

/// File name of run `run`'s log.
pub fn log_file_name(run: usize) -> String {
    format!("run-{run:03}.log")
}

pub fn manifest(scn: &SimPlan, runs: &[RunLog], laps_override: Option<usize>) -> Manifest {
    Manifest {
        placewords_version: env!("CARGO_PKG_VERSION").into(),
        scenario: scn.path.display().to_string(),
        scenario_name: scn.name.clone(),
        world: scn.world_path.display().to_string(),
        route: scn.route.id.clone(),
        seed: scn.seed,
        laps_override,
        runs: runs
            .iter()
            .map(|r| ManifestRun {
                run: r.run,
                file: log_file_name(r.run),
                start_waypoint: scn.runs[r.run].start_waypoint,
                frames: r.frames().count(),
                laps: r
                    .laps
                    .iter()
                    .map(|l| ManifestLap {
                        lap: l.lap,
                        door_config: l.door_config.clone(),
                        open_doors: l.open_doors.clone(),
                        frames: l.frames.len(),
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Writes `run-NNN.log` per run and `manifest.json` into `dir`, each atomically; returns the
/// paths written.
pub fn write_logs(
    scn: &SimPlan,
    runs: &[RunLog],
    laps_override: Option<usize>,
    dir: &Path,
) -> std::io::Result<Vec<PathBuf>> {
    let ctx = |p: &Path, e: std::io::Error| {
        std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", p.display()))
    };
    use rayon::prelude::*;
    let mut written = Vec::new();
    // Formatting dominates; format the runs in parallel, write them one by one.
    let texts: Vec<String> = runs.par_iter().map(|r| carmen_log(scn, r)).collect();
    for (r, text) in runs.iter().zip(texts) {
        let p = dir.join(log_file_name(r.run));
        write_atomic(&p, text.as_bytes()).map_err(|e| ctx(&p, e))?;
        written.push(p);
    }
    let p = dir.join("manifest.json");
    let json = serde_json::to_string_pretty(&manifest(scn, runs, laps_override))
        .map_err(|e| std::io::Error::other(e.to_string()))?;
    write_atomic(&p, (json + "\n").as_bytes()).map_err(|e| ctx(&p, e))?;
    written.push(p);
    Ok(written)
}
