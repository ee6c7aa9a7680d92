//! `simulate`'s output folder: the CARMEN logs, the manifest and optional pictures of one
//! simulation, written beside the folder and renamed onto it whole ([`StagedDir`]), so the
//! folder never mixes two runs and a failed run leaves it as it was.

use super::{ExperimentError, Scenario};
use crate::io::atomic::{StagedDir, write_atomic};
use crate::sim::logs;
use std::path::{Path, PathBuf};

/// Whether `dir` holds only what [`simulate_to_folder`] writes (a `manifest.json`, `run-NNN.log`
/// and `run-NNN.svg` files, hidden temporary files), so a new simulation may replace it.
pub fn is_simulation_folder(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    let run_file = |n: &str| {
        let stem = n.strip_suffix(".log").or_else(|| n.strip_suffix(".svg"));
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

/// Simulates `scn` (laps per run replaced by `laps`) and writes folder `out`: `run-NNN.log` per
/// run, `manifest.json` and, with `svg`, `run-NNN.svg`. `out` is checked before the simulation
/// starts: it must be new, empty or an earlier simulation folder (which is replaced). Returns the
/// files written, under `out`; progress is told once per lap simulated.
pub fn simulate_to_folder(
    scn: &Scenario,
    laps: Option<usize>,
    out: &Path,
    svg: bool,
    progress: &super::ProgressSink,
) -> Result<Vec<PathBuf>, ExperimentError> {
    let stage = StagedDir::begin(out, &is_simulation_folder)?;
    let total: usize = scn.sim.runs.iter().map(|r| laps.unwrap_or(r.laps)).sum();
    progress.start("simulating", total as u64);
    let runs = crate::sim::simulate(&scn.sim, laps, &|| progress.step());
    progress.done();
    let runs = runs?;
    let mut files = logs::write_logs(&scn.sim, &runs, laps, stage.path())?;
    if svg {
        for r in &runs {
            let p = stage.path().join(format!("run-{:03}.svg", r.run));
            let title = format!("{}: run {}, true path and odometry", scn.sim.name, r.run);
            let svg =
                super::picture::trajectory_svg(&scn.sim.world, std::slice::from_ref(r), &title);
            write_atomic(&p, svg.as_bytes()).map_err(|e| {
                std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", p.display()))
            })?;
            files.push(p);
        }
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
