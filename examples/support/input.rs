//! What the study examples read: a real log or a simulated scenario, and the recognizer run
//! over it (shared by `psi_evidence` and `word_lengths`).

use anyhow::{Result, bail};
use placewords::experiment::{ExperimentOptions, load_scenario, real, simulate};
use placewords::io::real_log::TruthSource;
use placewords::log::RunLog;
use placewords::recognizer::{Recognizer, RecognizerConfig};
use std::path::Path;
use std::process::ExitCode;

/// The runs of a log at `path` (one run, `recognize`'s default noise, noise seed `seed`) or of
/// a simulated scenario (`.toml`, at its seed `seed`), and the recognizer settings to observe
/// them with.
pub fn load(path: &Path, seed: u64) -> Result<(Vec<RunLog>, RecognizerConfig)> {
    if path.extension().is_some_and(|e| e == "toml") {
        // Its errors name the file, line and column.
        let mut scn = load_scenario(path)?;
        scn.sim.seed = seed;
        let (runs, _, _) = simulate(&scn, &ExperimentOptions::default())?;
        return Ok((runs, scn.recognizer.clone()));
    }
    let Some(noise) = real::parse_noise_model("proportional").map_err(anyhow::Error::msg)? else {
        bail!("the default noise model has no parameters");
    };
    let (run, _) = real::load_real_run(
        path,
        false,
        TruthSource::Corrected,
        Some(&noise),
        seed,
        &Default::default(),
    )?;
    Ok((vec![run], RecognizerConfig::default()))
}

/// The recognizer with `cfg` after every frame of `runs` (each run a run of its own).
#[allow(dead_code)] // not every example recognizes (`psi_bound` runs front ends only)
pub fn recognize(runs: &[RunLog], cfg: RecognizerConfig) -> Result<Recognizer> {
    let mut rec = Recognizer::new(cfg)?;
    let mut frame = 0;
    for run in runs {
        rec.start_run();
        for f in run.frames() {
            rec.push_frame(frame, f.odom, &f.scan);
            frame += 1;
        }
    }
    rec.finish();
    Ok(rec)
}

/// The exit code of an example whose work returned `outcome`: 0, or 2 with the error printed.
pub fn exit_code(outcome: Result<()>) -> ExitCode {
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
