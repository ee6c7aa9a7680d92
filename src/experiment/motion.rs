//! The motion figures (`eval::motion`) of a real log's true path or of a scenario's simulated
//! laps, for `placewords motion`: how a real robot weaves, against the simulator's laps.

use crate::eval::motion::{Motion, measure};
use crate::experiment::{ExperimentError, load_scenario};
use crate::io::carmen::{ReadOptions, read_log};
use crate::io::real_log::{RealLogError, TruthSource, log_stamps_usable, log_to_run};
use crate::sim::RunLog;
use std::path::Path;

/// The figures of every lap of `runs`, each lap's true path measured on its own.
pub fn of_runs(runs: &[RunLog]) -> Motion {
    let mut m = Motion::default();
    for lap in runs.iter().flat_map(|r| &r.laps) {
        let path: Vec<_> = lap.frames.iter().map(|f| (f.time_s, f.truth.0)).collect();
        m.add(&measure(&path));
    }
    m
}

/// The figures of a CARMEN log's corrected path (plain or gzip).
/// When its stamps are unusable (csail), time was derived from travel at a nominal speed, so
/// its speeds are dropped and the figures say `speed_unknown`.
pub fn of_log(path: &Path) -> Result<Motion, ExperimentError> {
    let readout = read_log(path, ReadOptions::default()).map_err(RealLogError::from)?;
    let name = path.display().to_string();
    let run = log_to_run(&readout, &name, TruthSource::Corrected, |p| p)?;
    let mut m = of_runs(&[run]);
    if !log_stamps_usable(&readout) {
        m.speed_m_s.clear();
        m.speed_unknown = true;
    }
    Ok(m)
}

/// The figures of a scenario's simulated laps at `seed` (its own seed when `None`), with
/// `laps` per run when given.
pub fn of_scenario(
    path: &Path,
    seed: Option<u64>,
    laps: Option<usize>,
) -> Result<Motion, ExperimentError> {
    let mut scn = load_scenario(path)?;
    if let Some(seed) = seed {
        scn.sim.seed = seed;
    }
    let (runs, _) = crate::sim::runner::simulate_timed(&scn.sim, laps, &|| {})?;
    Ok(of_runs(&runs))
}
