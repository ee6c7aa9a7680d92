//! Writing simulated runs as CARMEN logs, plus a JSON manifest.
//!
//! Each run's log is a header comment, then its laps as [`LapWriter`] writes them (a `#` line
//! per lap naming its doors; `ODOM`, `FLASER` and `TRUEPOS` per frame). Timestamps are seconds
//! since the run started; the host is `placewords-sim`. [`LogsWriter`] appends lap after lap to
//! the open run's file, so a simulation of any length is written in the memory of a few laps.

use crate::io::atomic::AtomicFile;
use crate::io::carmen::LapWriter;
use crate::log::{LapLog, RunLog};
use crate::sim::plan::SimPlan;
use serde::{Deserialize, Serialize};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Host name written in every record.
pub const HOST: &str = "placewords-sim";

/// The comment line that opens run `run`'s log.
fn header(scn: &SimPlan, run: usize) -> String {
    format!(
        "# placewords simulation: scenario {}, seed {}, run {}, route {} of world {}\n",
        scn.name, scn.seed, run, scn.route.id, scn.world.name
    )
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

/// The manifest of a simulation whose runs are `runs`.
pub fn manifest(scn: &SimPlan, runs: Vec<ManifestRun>, laps_override: Option<usize>) -> Manifest {
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
    let mut writer = LogsWriter::new(scn, laps_override, dir);
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

/// The log file of the run being written.
struct OpenRun {
    file: AtomicFile,
    carmen: LapWriter,
    manifest: ManifestRun,
}

/// Writes a simulation's folder lap by lap: laps arrive in run order, each appended to its run's
/// `run-NNN.log` (written under a temporary name, renamed when the run ends); [`Self::finish`]
/// writes `manifest.json`. Holds one lap's text at a time.
pub struct LogsWriter<'a> {
    scn: &'a SimPlan,
    laps_override: Option<usize>,
    dir: PathBuf,
    open: Option<OpenRun>,
    runs: Vec<ManifestRun>,
    written: Vec<PathBuf>,
    text: String,
}

impl<'a> LogsWriter<'a> {
    /// A writer of `scn`'s logs into `dir` (created if missing).
    pub fn new(scn: &'a SimPlan, laps_override: Option<usize>, dir: &Path) -> Self {
        LogsWriter {
            scn,
            laps_override,
            dir: dir.to_path_buf(),
            open: None,
            runs: Vec::new(),
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
        self.text.clear();
        open.carmen.write_lap(&mut self.text, lap);
        open.file
            .write_all(self.text.as_bytes())
            .map_err(|e| at(open.file.path(), e))?;
        open.manifest.frames += lap.frames.len();
        open.manifest.laps.push(ManifestLap {
            lap: lap.lap,
            door_config: lap.door_config.clone(),
            open_doors: lap.open_doors.clone(),
            frames: lap.frames.len(),
        });
        Ok(())
    }

    /// Ends the last run, writes `manifest.json`; returns the paths written.
    pub fn finish(mut self) -> std::io::Result<Vec<PathBuf>> {
        self.close_run()?;
        let p = self.dir.join("manifest.json");
        let runs = std::mem::take(&mut self.runs);
        let manifest = manifest(self.scn, runs, self.laps_override);
        // Written straight to the file: a million laps' manifest is not held twice as text.
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
        let p = self.dir.join(log_file_name(run));
        let mut file = AtomicFile::create(&p).map_err(|e| at(&p, e))?;
        file.write_all(header(self.scn, run).as_bytes())
            .map_err(|e| at(&p, e))?;
        self.open = Some(OpenRun {
            file,
            carmen: LapWriter::new(HOST),
            manifest: ManifestRun {
                run,
                file: log_file_name(run),
                start_waypoint: self.scn.runs[run].start_waypoint,
                frames: 0,
                laps: Vec::new(),
            },
        });
        Ok(())
    }

    fn close_run(&mut self) -> std::io::Result<()> {
        if let Some(open) = self.open.take() {
            let p = open.file.path().to_path_buf();
            open.file.commit().map_err(|e| at(&p, e))?;
            self.written.push(p);
            self.runs.push(open.manifest);
        }
        Ok(())
    }
}
