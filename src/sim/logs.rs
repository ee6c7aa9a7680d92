//! Writing simulated runs as CARMEN logs or ROS 2 bags ([`RunFormat`]), plus a JSON manifest.
//!
//! Each run's CARMEN log is a header comment and a `PARAM robot_front_laser_max` line (the
//! laser's no-return range, so a reader tells no-returns from hits), then its laps as
//! [`LapWriter`] writes them (a `#` line per lap naming its doors; `ODOM`, `FLASER` and
//! `TRUEPOS` per frame). Timestamps are seconds since the run started; the host is
//! `placewords-sim`. A run's bag (`run-NNN.mcap`) holds the same frames as
//! [`crate::io::ros2::bag::BagWriter`] writes them. [`LogsWriter`] appends lap after lap to
//! the open run's file, so a simulation of any length is written in the memory of a few laps.

use crate::io::atomic::{AtomicFile, ScratchFile};
use crate::io::carmen::LapWriter;
use crate::io::ros2::bag::{BagWriter, ScanTiming};
use crate::log::{LapLog, RunLog};
use crate::sim::plan::SimPlan;
use serde::ser::{Error as _, SerializeSeq, SerializeStruct, Serializer};
use serde::{Deserialize, Serialize};
use std::cell::RefCell;
use std::io::{BufRead as _, Write as _};
use std::path::{Path, PathBuf};

/// Host name written in every record.
pub const HOST: &str = "placewords-sim";

/// The comment and `PARAM` lines that open run `run`'s CARMEN log.
fn header(scn: &SimPlan, run: usize) -> String {
    format!(
        "# placewords simulation: scenario {}, seed {}, run {}, route {} of world {}\n\
         PARAM robot_front_laser_max {} 0.000000 {HOST} 0.000000\n",
        scn.name, scn.seed, run, scn.route.id, scn.world.name, scn.laser.max_range_m
    )
}

/// How `simulate` writes each run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RunFormat {
    /// A CARMEN text log, `run-NNN.log`.
    #[default]
    Carmen,
    /// A ROS 2 bag in MCAP, `run-NNN.mcap` (docs/ros2.md).
    Mcap,
}

impl RunFormat {
    /// The file name extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            RunFormat::Carmen => "log",
            RunFormat::Mcap => "mcap",
        }
    }
}

/// How the simulated laser's beams are timed in a bag.
fn scan_timing(scn: &SimPlan) -> ScanTiming {
    ScanTiming::lms200(scn.laser.rate_hz, scn.laser.layout().step_rad)
}

/// The CARMEN text of one run (the text [`LogsWriter`] writes to its file).
pub fn carmen_log(scn: &SimPlan, run: &RunLog) -> String {
    let mut out = header(scn, run.run);
    let mut writer = LapWriter::new(HOST);
    for lap in &run.laps {
        writer.write_lap(&mut out, lap);
    }
    out
}

/// The JSON manifest of a simulation (`R`, the runs' type, differs only while it is written).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest<R = ManifestRun> {
    pub placewords_version: String,
    pub scenario: String,
    pub scenario_name: String,
    pub world: String,
    pub route: String,
    pub seed: u64,
    pub laps_override: Option<usize>,
    pub runs: Vec<R>,
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

/// File name of the manifest.
const MANIFEST: &str = "manifest.json";

/// The lines of the laps' scratch file.
type LapLines = std::io::Lines<std::io::BufReader<std::fs::File>>;

/// A run's manifest entry as [`ManifestRun`] serializes, its laps read from the scratch file
/// (shared by the runs, read in run order) as they are serialized.
struct RunOut<'a> {
    head: &'a RunHead,
    lines: &'a RefCell<Option<LapLines>>,
}

/// The laps of one [`RunOut`].
struct LapsOut<'a>(&'a RunOut<'a>);

impl Serialize for RunOut<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // The fields of `ManifestRun`, in its order.
        let mut st = s.serialize_struct("ManifestRun", 5)?;
        st.serialize_field("run", &self.head.run)?;
        st.serialize_field("file", &self.head.file)?;
        st.serialize_field("start_waypoint", &self.head.start_waypoint)?;
        st.serialize_field("frames", &self.head.frames)?;
        st.serialize_field("laps", &LapsOut(self))?;
        st.end()
    }
}

impl Serialize for LapsOut<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let n = self.0.head.laps;
        let mut seq = s.serialize_seq(Some(n))?;
        let mut lines = self.0.lines.borrow_mut();
        for _ in 0..n {
            let line = lines
                .as_mut()
                .and_then(Iterator::next)
                .ok_or_else(|| S::Error::custom("the laps' scratch file ended early"))?
                .map_err(S::Error::custom)?;
            let lap: ManifestLap = serde_json::from_str(&line).map_err(S::Error::custom)?;
            seq.serialize_element(&lap)?;
        }
        seq.end()
    }
}

/// File name of run `run`'s CARMEN log.
pub fn log_file_name(run: usize) -> String {
    run_file_name(run, RunFormat::Carmen)
}

/// File name of run `run`'s file in `format`.
pub fn run_file_name(run: usize, format: RunFormat) -> String {
    format!("run-{run:03}.{}", format.extension())
}

/// The manifest of a simulation whose runs are `runs`.
pub fn manifest<R>(scn: &SimPlan, runs: Vec<R>, laps_override: Option<usize>) -> Manifest<R> {
    Manifest {
        placewords_version: env!("CARGO_PKG_VERSION").into(),
        scenario: scn.path.display().to_string(),
        scenario_name: scn.name.clone(),
        world: scn.world_path.display().to_string(),
        route: scn.route.id.clone(),
        seed: scn.seed,
        laps_override,
        runs,
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
    let mut writer = LogsWriter::new(scn, laps_override, dir, RunFormat::Carmen);
    for r in runs {
        writer.start_run(r.run)?;
        for lap in &r.laps {
            writer.push_lap(r.run, lap)?;
        }
    }
    writer.finish()
}

/// `e` with the path it happened at.
fn at(p: &Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", p.display()))
}

/// A run's manifest entry without its laps (those wait in [`LogsWriter`]'s scratch file).
#[derive(Clone, Debug)]
struct RunHead {
    run: usize,
    file: String,
    start_waypoint: usize,
    frames: usize,
    laps: usize,
}

/// The file of the run being written.
struct OpenRun {
    file: RunFile,
    path: PathBuf,
    head: RunHead,
}

/// A run's file in its format.
enum RunFile {
    Carmen { file: AtomicFile, carmen: LapWriter },
    Mcap(Box<BagWriter<AtomicFile>>),
}

/// Writes a simulation's folder lap by lap: laps arrive in run order, each appended to its run's
/// `run-NNN.log` or `run-NNN.mcap` (written under a temporary name, renamed when the run ends), its manifest
/// entry to a scratch file; [`Self::finish`] writes `manifest.json` from them. Holds one lap's
/// text at a time, so memory does not grow with the laps.
pub struct LogsWriter<'a> {
    scn: &'a SimPlan,
    laps_override: Option<usize>,
    dir: PathBuf,
    format: RunFormat,
    open: Option<OpenRun>,
    runs: Vec<RunHead>,
    /// The manifest entries of the laps written, one JSON line each.
    laps: Option<ScratchFile>,
    written: Vec<PathBuf>,
    text: String,
}

impl<'a> LogsWriter<'a> {
    /// A writer of `scn`'s runs in `format` into `dir` (created if missing).
    pub fn new(
        scn: &'a SimPlan,
        laps_override: Option<usize>,
        dir: &Path,
        format: RunFormat,
    ) -> Self {
        LogsWriter {
            scn,
            laps_override,
            dir: dir.to_path_buf(),
            format,
            open: None,
            runs: Vec::new(),
            laps: None,
            written: Vec::new(),
            text: String::new(),
        }
    }

    /// Ends the runs before `run` (those without laps get a log with only the header) and opens
    /// `run`'s log if it is not open yet.
    pub fn start_run(&mut self, run: usize) -> std::io::Result<()> {
        while self.runs.len() + usize::from(self.open.is_some()) <= run {
            self.close_run()?;
            self.open_run(self.runs.len())?;
        }
        Ok(())
    }

    /// Appends lap `lap` of run `run` (runs in order, laps in order within a run).
    pub fn push_lap(&mut self, run: usize, lap: &LapLog) -> std::io::Result<()> {
        self.start_run(run)?;
        let open = self.open.as_mut().expect("start_run opened the run");
        match &mut open.file {
            RunFile::Carmen { file, carmen } => {
                self.text.clear();
                carmen.write_lap(&mut self.text, lap);
                file.write_all(self.text.as_bytes())
            }
            RunFile::Mcap(bag) => bag.write_lap(lap),
        }
        .map_err(|e| at(&open.path, e))?;
        open.head.frames += lap.frames.len();
        open.head.laps += 1;
        let entry = ManifestLap {
            lap: lap.lap,
            door_config: lap.door_config.clone(),
            open_doors: lap.open_doors.clone(),
            frames: lap.frames.len(),
        };
        let laps = self.laps.as_mut().expect("open_run made the scratch file");
        serde_json::to_writer(&mut *laps, &entry)
            .map_err(std::io::Error::other)
            .and_then(|()| laps.write_all(b"\n"))
            .map_err(|e| at(&self.dir.join(MANIFEST), e))
    }

    /// Ends the last run, writes `manifest.json`; returns the paths written.
    pub fn finish(mut self) -> std::io::Result<Vec<PathBuf>> {
        self.close_run()?;
        let p = self.dir.join(MANIFEST);
        let lines = match self.laps.as_mut() {
            Some(scratch) => Some(scratch.read_back().map_err(|e| at(&p, e))?.lines()),
            None => None,
        };
        let lines = std::cell::RefCell::new(lines);
        let runs = self.runs.iter().map(|head| RunOut {
            head,
            lines: &lines,
        });
        let manifest = manifest(self.scn, runs.collect(), self.laps_override);
        // Written straight to the file, the laps read back one at a time: a million laps'
        // manifest is never held in memory.
        let mut file = AtomicFile::create(&p).map_err(|e| at(&p, e))?;
        serde_json::to_writer_pretty(&mut file, &manifest)
            .map_err(std::io::Error::other)
            .and_then(|()| file.write_all(b"\n"))
            .and_then(|()| file.commit())
            .map_err(|e| at(&p, e))?;
        self.written.push(p);
        Ok(self.written)
    }

    fn open_run(&mut self, run: usize) -> std::io::Result<()> {
        let name = run_file_name(run, self.format);
        let p = self.dir.join(&name);
        let mut file = AtomicFile::create(&p).map_err(|e| at(&p, e))?;
        let file = match self.format {
            RunFormat::Carmen => {
                file.write_all(header(self.scn, run).as_bytes())
                    .map_err(|e| at(&p, e))?;
                RunFile::Carmen {
                    file,
                    carmen: LapWriter::new(HOST),
                }
            }
            RunFormat::Mcap => RunFile::Mcap(Box::new(
                BagWriter::new(file, run, scan_timing(self.scn)).map_err(|e| at(&p, e))?,
            )),
        };
        if self.laps.is_none() {
            let scratch = self.dir.join("manifest-laps");
            self.laps = Some(ScratchFile::create(&scratch).map_err(|e| at(&scratch, e))?);
        }
        self.open = Some(OpenRun {
            file,
            path: p,
            head: RunHead {
                run,
                file: name,
                start_waypoint: self.scn.runs[run].start_waypoint,
                frames: 0,
                laps: 0,
            },
        });
        Ok(())
    }

    fn close_run(&mut self) -> std::io::Result<()> {
        if let Some(open) = self.open.take() {
            let p = open.path;
            let file = match open.file {
                RunFile::Carmen { file, .. } => file,
                RunFile::Mcap(bag) => bag.finish().map_err(|e| at(&p, e))?,
            };
            file.commit().map_err(|e| at(&p, e))?;
            self.written.push(p);
            self.runs.push(open.head);
        }
        Ok(())
    }
}
