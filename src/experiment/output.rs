//! `simulate`'s output folder: the CARMEN logs (or ROS 2 bags), the manifest and optional pictures of one
//! simulation, written beside the folder and renamed onto it whole ([`StagedDir`]), so the
//! folder never mixes two runs and a failed run leaves it as it was. The logs are written lap
//! by lap as the simulator makes them (`stream::with_laps`), so memory does not grow with laps.

use super::stream::with_laps;
use super::{ExperimentError, Scenario};
use crate::io::atomic::{StagedDir, write_atomic};
use crate::log::{LapLog, RunLog};
use crate::sim::logs;
use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;

/// Whether `dir` holds only what [`simulate_to_folder`] writes (a `manifest.json`, `run-NNN.log`,
/// `run-NNN.mcap` and `run-NNN.svg` files, hidden temporary files), so a new simulation may replace it.
pub fn is_simulation_folder(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    let run_file = |n: &str| {
        let stem = n
            .strip_suffix(".log")
            .or_else(|| n.strip_suffix(".mcap"))
            .or_else(|| n.strip_suffix(".svg"));
        stem.and_then(|s| s.strip_prefix("run-"))
            .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
    };
    let mut manifest = false;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        manifest |= name == "manifest.json";
        if !(name == "manifest.json" || name.starts_with('.') || run_file(&name)) {
            return false;
        }
    }
    manifest
}

/// Simulates `scn` (laps per run replaced by `laps`) and writes folder `out`: `run-NNN.log` (or
/// `run-NNN.mcap`, by `format`) per run, `manifest.json` and, with `svg`, `run-NNN.svg`. `out` is checked before the simulation
/// starts: it must be new, empty or an earlier simulation folder (which is replaced). Each lap is
/// written as soon as it is simulated and then dropped (with `svg`, its poses are kept), so
/// memory does not grow with the laps; the folder appears whole when every file is written.
/// With `cache`, the laps are read from it when it holds them and stored in it when not.
/// Returns the files written, under `out`; progress is told once per lap simulated.
pub fn simulate_to_folder(
    scn: &Scenario,
    laps: Option<usize>,
    out: &Path,
    format: logs::RunFormat,
    svg: bool,
    progress: &super::ProgressSink,
    cache: Option<&super::cache::LapCache>,
) -> Result<Vec<PathBuf>, ExperimentError> {
    let stage = StagedDir::begin(out, &is_simulation_folder)?;
    let laps_of = |run: usize| laps.unwrap_or(scn.sim.runs[run].laps);
    let total: usize = (0..scn.sim.runs.len()).map(laps_of).sum();
    progress.start("simulating", total as u64);
    let mut writer = logs::LogsWriter::new(&scn.sim, laps, stage.path(), format);
    let mut paths: Vec<RunLog> = Vec::new();
    let keep = svg.then_some(&mut paths);
    let (sim, written) = with_laps(&scn.sim, &laps_of, cache, |rx| {
        write_laps(&mut writer, rx, keep, progress)
    });
    progress.done();
    sim?;
    written?;
    let mut files = writer.finish()?;
    for r in &paths {
        let p = stage.path().join(format!("run-{:03}.svg", r.run));
        let title = format!("{}: run {}, true path and odometry", scn.sim.name, r.run);
        let svg = super::picture::trajectory_svg(&scn.sim.world, std::slice::from_ref(r), &title);
        write_atomic(&p, svg.as_bytes()).map_err(|e| {
            std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", p.display()))
        })?;
        files.push(p);
    }
    stage.commit().map_err(|e| {
        std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", out.display()))
    })?;
    Ok(files
        .iter()
        .filter_map(|f| f.file_name())
        .map(|n| out.join(n))
        .collect())
}

/// Writes each lap from `rx` as it arrives; with `paths`, keeps each lap's frames without their
/// scans (for the trajectory pictures). Stops at the first write error (dropping `rx`, which
/// stops the simulation).
fn write_laps(
    writer: &mut logs::LogsWriter<'_>,
    rx: Receiver<(usize, LapLog)>,
    mut paths: Option<&mut Vec<RunLog>>,
    progress: &super::ProgressSink,
) -> std::io::Result<()> {
    for (run, mut lap) in rx {
        writer.push_lap(run, &lap)?;
        progress.step();
        if let Some(paths) = paths.as_deref_mut() {
            for f in &mut lap.frames {
                f.scan.ranges_m = Vec::new();
            }
            if paths.last().is_none_or(|r| r.run != run) {
                paths.push(RunLog {
                    run,
                    laps: Vec::new(),
                });
            }
            paths.last_mut().expect("pushed").laps.push(lap);
        }
    }
    Ok(())
}
