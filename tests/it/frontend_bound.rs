//! The approximate front end (`[recognizer.grid] beam_stride = 4`, `[recognizer.density]
//! ray_stride = 2`, the defaults) keeps Ψ within a bound of the exact one (both 1: the authors'
//! grid update and kernel): over the first run of every shipped scenario and the start of every
//! CARMEN log, Ψ of each observation is compared (docs/design.md, "The front end's
//! approximation"; `examples/psi_bound.rs` prints the same figures for whole runs).

use super::common::root;
use placewords::experiment::{ExperimentOptions, load_scenario, real, simulate};
use placewords::io::real_log::TruthSource;
use placewords::log::RunLog;
use placewords::recognizer::{DensityFrontEnd, DensityObservation, PsiGap, RecognizerConfig};

/// The bound, per dataset: |ΔΨ| at the 99th percentile and on average, the share of
/// observations beyond [`PsiGap::FAR`] (a passer-by's trace fades at another pace in places,
/// |ΔΨ| up to 0.46 in the long-term run: rare, so that share is bounded rather than the
/// largest), and the share whose class (Φ included) changes.
const P99: f64 = 0.04;
const MEAN: f64 = 0.008;
const FAR_SHARE: f64 = 0.005;
const CLASS_SHARE: f64 = 0.08;
/// Scans of a log read: its first ones (all of a log with fewer).
const LOG_SCANS: usize = 1500;

/// The gap of `b` from `a`, which observe the same inputs.
fn gap_of(cfg: &RecognizerConfig, a: &[DensityObservation], b: &[DensityObservation]) -> PsiGap {
    let gap = PsiGap::between(cfg, a, b).expect("both front ends observe at the same travel");
    assert!(gap.observations > 300, "{} observations", gap.observations);
    gap
}

fn within(gap: &PsiGap) -> bool {
    gap.p99 <= P99
        && gap.mean <= MEAN
        && gap.far_share <= FAR_SHARE
        && gap.class_share <= CLASS_SHARE
}

fn observe(runs: &[RunLog], cfg: &RecognizerConfig, scans: usize) -> Vec<DensityObservation> {
    let mut fe = DensityFrontEnd::new(cfg).unwrap();
    let mut out = Vec::new();
    let mut frame = 0;
    for run in runs {
        fe.start_run();
        for f in run.frames().take(scans) {
            out.extend(fe.push_frame(frame, f.odom, &f.scan));
            frame += 1;
        }
    }
    out
}

fn exact(cfg: &RecognizerConfig) -> RecognizerConfig {
    cfg.clone().with_exact_front_end()
}

/// The approximation the bound is for: every 4th beam a scan, every 2nd density ray.
fn approximate(cfg: &RecognizerConfig) -> RecognizerConfig {
    cfg.clone().with_fast_front_end()
}

/// Per dataset (the first run of every scenario, the first scans of every log): its name, the
/// inputs, the settings and how many scans of each run to read.
fn datasets() -> Vec<(String, Vec<RunLog>, RecognizerConfig, usize)> {
    let mut out = Vec::new();
    let mut scenarios: Vec<_> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenarios.sort();
    for path in scenarios {
        let mut scn = load_scenario(&path).unwrap();
        scn.sim.runs.truncate(1);
        let (runs, _, _) = simulate(&scn, &ExperimentOptions::default()).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        out.push((name, runs, scn.recognizer.clone(), usize::MAX));
    }
    let logs = root().join("../shared/data/carmen");
    let noise = real::parse_noise_model("proportional").unwrap();
    for log in ["csail", "fhw", "freiburg-079", "intel", "seattle"] {
        let path = logs.join(format!("{log}-corrected.log.gz"));
        let (run, _) = real::load_real_run(
            &path,
            false,
            TruthSource::Corrected,
            noise.as_ref(),
            1,
            &Default::default(),
        )
        .unwrap();
        let cfg = RecognizerConfig::default();
        out.push((log.to_string(), vec![run], cfg, LOG_SCANS));
    }
    out
}

/// The approximate front end is within the bound of the exact one on every shipped scenario
/// and log; a coarser kernel (rays every 4°, every ray walked) is not, so the bound tells a
/// worse approximation. The defaults are the approximate front end.
#[test]
fn the_approximate_front_end_keeps_psi_within_the_bound_of_the_exact_one() {
    let default = RecognizerConfig::default();
    assert_eq!(
        (default.grid.beam_stride, default.density.ray_stride),
        (4, 2)
    );
    for (name, runs, cfg, scans) in datasets() {
        let a = observe(&runs, &exact(&cfg), scans);
        let gap = gap_of(&cfg, &a, &observe(&runs, &approximate(&cfg), scans));
        eprintln!("{name}: {} observations, approximate {gap:?}", a.len());
        assert!(within(&gap), "{name}: {gap:?}");
        let mut coarse = exact(&cfg);
        coarse.density.ray_step_deg = 4.0;
        let gap = gap_of(&cfg, &a, &observe(&runs, &coarse, scans));
        eprintln!("{name}: 4° rays {gap:?}");
        assert!(!within(&gap), "{name}: 4° rays pass the bound: {gap:?}");
    }
}

/// A stride out of range is refused with where it is and what is allowed.
#[test]
fn strides_out_of_range_are_refused_where_they_are_written() {
    use placewords::experiment::parse_recognizer_config;
    use std::path::Path;
    for (table, key, value) in [
        ("grid", "beam_stride", "0"),
        ("grid", "beam_stride", "9"),
        ("density", "ray_stride", "0"),
        ("density", "ray_stride", "20"),
    ] {
        let src = format!("[recognizer.{table}]\n{key} = {value}\n");
        let e = parse_recognizer_config(&src, Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("[recognizer.{table}] {key}")) && e.contains("[1, 8]"),
            "{key} = {value}: {e}"
        );
        assert!(e.starts_with("t.toml:"), "{e}");
    }
}

/// `docs/exact-front-end.toml`, the file the README and docs/design.md point to for the authors'
/// front end, gives exactly the exact settings over the defaults.
#[test]
fn the_exact_front_end_file_gives_the_exact_settings() {
    let path = root().join("docs/exact-front-end.toml");
    let cfg = placewords::experiment::load_recognizer_config(&path).unwrap();
    assert_eq!(cfg, RecognizerConfig::default().with_exact_front_end());
    assert_ne!(cfg, RecognizerConfig::default());
}
