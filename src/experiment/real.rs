//! Real robot logs as experiments. "Corrected" CARMEN logs carry no raw odometry, so odometry is
//! derived from the corrected increments, each read as the wheel travel that drives it and passed
//! through the simulator's odometry model ([`crate::sim::odometry::Odometry`], one update per
//! increment) from a seeded stream; the corrected pose stays the truth.
//!
//! `recognize` reads a log as a stream ([`recognize_log_streamed`]): frames go to the
//! recognizers a chunk at a time and only their truth is kept, so a log of any size fits in the
//! memory of the recognizers' own state.

use super::shared_front::FrontEnds;
use super::stream::{Job, finish_jobs, jobs, settle};
use super::{Experiment, ExperimentError, ExperimentOptions, assemble, level_configs};
use crate::eval::scores::LogSummary;
use crate::eval::{GroundTruth, LapInfo};
use crate::geom::{Pose2, wrap_angle};
use crate::io::carmen::ReadOptions;
use crate::io::real_log::{
    LogSurvey, RealLogError, TruthSource, load_bag_run, load_run, stream_frames,
};
use crate::io::ros2::bag::{BagTopics, is_mcap};
use crate::log::{Frame, RunLog};
use crate::recognizer::RecognizerConfig;
use crate::sim::odometry::{
    Odometry, OdometryConfig, OdometryModel, ProportionalError, noisy_motion,
};
use crate::sim::rng::{Purpose, SimRng, stream};
use crate::spec::evaluation::EvaluationSpec;
use std::path::Path;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

/// Axle track the wheel travels of a real increment are expressed with, metres (the simulated
/// robot's default; only a wheel-radius mismatch depends on it).
const AXLE_TRACK_M: f64 = 0.357;

/// Perturbs one odometry increment (robot frame) with the simulator's odometry model: the
/// increment's signed travel `Δs` and turn `Δθ` are read as the wheel travels of one update,
/// which get the model's systematic ([`Odometry::measured_motion`]) and random
/// ([`noisy_motion`]) errors. The noisy travel keeps the increment's own direction of travel,
/// turned by the update's heading error (a real increment may move sideways, which a
/// differential drive integrated at its midpoint heading would lose).
pub fn perturb_increment(cfg: &OdometryConfig, inc: Pose2, rng: &mut SimRng) -> Pose2 {
    let ds = inc.x.hypot(inc.y).copysign(inc.x);
    let turn_m = inc.theta * AXLE_TRACK_M / 2.0;
    let odometry = Odometry::new(cfg.clone(), AXLE_TRACK_M, Pose2::IDENTITY);
    let measured = odometry.measured_motion(ds - turn_m, ds + turn_m);
    let (ds_noisy, dth_noisy, heading) = noisy_motion(cfg, measured, rng);
    let travel_dir = if ds.abs() > 1e-12 {
        (inc.y * ds.signum()).atan2(inc.x * ds.signum())
    } else {
        0.0
    };
    let dir = travel_dir + heading - inc.theta / 2.0;
    Pose2::new(
        ds_noisy * dir.cos(),
        ds_noisy * dir.sin(),
        wrap_angle(dth_noisy),
    )
}

/// Parses an odometry noise model for real logs: `none` (the corrected increments exactly),
/// `proportional` (0.0075 m/m and rad/rad), `proportional:T,R` (both in the random-walk form:
/// spread `T·√d` after `d` metres, per increment) or `thrun:A1,A2,A3,A4`.
pub fn parse_noise_model(s: &str) -> Result<Option<OdometryConfig>, String> {
    let (name, params) = s.split_once(':').unwrap_or((s, ""));
    let nums = |want: usize, example: &str| -> Result<Vec<f64>, String> {
        let v = params
            .split(',')
            .map(|p| {
                p.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && *v >= 0.0)
                    .ok_or_else(|| format!("`{p}` is not a non-negative number"))
            })
            .collect::<Result<Vec<f64>, String>>()?;
        if v.len() == want {
            Ok(v)
        } else {
            Err(format!("{name} takes {want} numbers, e.g. {example}"))
        }
    };
    let model = match (name, params.is_empty()) {
        ("none", true) => return Ok(None),
        ("proportional", true) => OdometryConfig::default().model,
        ("proportional", false) => {
            let v = nums(2, "proportional:0.0075,0.0075")?;
            OdometryModel::Proportional {
                translation_ratio: v[0],
                rotation_ratio: v[1],
            }
        }
        ("thrun", false) => {
            let v = nums(4, "thrun:0.01,0.01,0.01,0.01")?;
            OdometryModel::Thrun {
                alpha: [v[0], v[1], v[2], v[3]],
            }
        }
        _ => {
            return Err(
                "unknown model; use none, proportional, proportional:T,R or thrun:A1,A2,A3,A4"
                    .into(),
            );
        }
    };
    Ok(Some(OdometryConfig {
        model,
        proportional: ProportionalError::RandomWalk,
        ..OdometryConfig::default()
    }))
}

/// Reads a log and turns it into one run, with odometry derived by `noise` (or exactly the
/// corrected increments when `noise` is `None`) from the stream of `seed`. A ROS 2 bag (MCAP,
/// told by its first bytes) is read with `topics`.
pub fn load_real_run(
    path: &Path,
    lenient: bool,
    truth: TruthSource,
    noise: Option<&OdometryConfig>,
    seed: u64,
    topics: &BagTopics,
) -> Result<(RunLog, usize), RealLogError> {
    let mut rng = stream(seed, 0, 0, Purpose::Odometry);
    let perturb = |inc| match noise {
        Some(cfg) => perturb_increment(cfg, inc, &mut rng),
        None => inc,
    };
    if is_mcap(path) {
        return Ok((load_bag_run(path, topics, truth, perturb)?, 0));
    }
    let (run, readout) = load_run(path, ReadOptions { lenient }, truth, perturb)?;
    Ok((run, readout.skipped_lines))
}

/// Keeps every `k`-th frame of `run` (the first included; `k` ≤ 1 keeps all), so a dense log can
/// be made as sparse as many real logs are. The odometry is untouched: each kept frame still has
/// its pose, so the recognizer sees the same path sampled less often.
pub fn keep_every_nth_scan(run: &mut RunLog, k: usize) {
    let mut i = 0usize;
    for lap in &mut run.laps {
        lap.frames.retain(|_| {
            i += 1;
            keeps_scan(i - 1, k)
        });
    }
}

/// Whether [`keep_every_nth_scan`] keeps frame `i` (0-based, counted over the run).
fn keeps_scan(i: usize, k: usize) -> bool {
    k <= 1 || i.is_multiple_of(k)
}

/// How `recognize` reads a real log.
#[derive(Clone, Debug, PartialEq)]
pub struct RealLogOptions {
    /// Skip malformed lines (counted) instead of failing at the first.
    pub lenient: bool,
    pub truth: TruthSource,
    /// Odometry noise model; `None`: the corrected increments exactly.
    pub noise: Option<OdometryConfig>,
    /// Seed of the odometry noise stream.
    pub seed: u64,
    /// Keep every `scan_step`-th scan (1: all).
    pub scan_step: usize,
    /// A bag's scan and odometry topics (found by type where `None`).
    pub topics: BagTopics,
}

/// Recognizes the real log at `path` with every configuration of `opts`; returns the experiment
/// and the lines skipped. With `keep_runs` (pictures need the scans) the log is loaded whole and
/// `Experiment::runs` holds it; otherwise it is read as a stream ([`recognize_log_streamed`]).
/// The report is the same either way. A ROS 2 bag (MCAP) is always loaded whole.
pub fn recognize_log(
    path: &Path,
    log: &RealLogOptions,
    name: &str,
    base: &RecognizerConfig,
    evaluation: &EvaluationSpec,
    opts: &ExperimentOptions,
    keep_runs: bool,
) -> Result<(Experiment, usize), ExperimentError> {
    if !keep_runs && !is_mcap(path) {
        return recognize_log_streamed(path, log, name, base, evaluation, opts);
    }
    let (mut run, skipped) = load_real_run(
        path,
        log.lenient,
        log.truth,
        log.noise.as_ref(),
        log.seed,
        &log.topics,
    )?;
    keep_every_nth_scan(&mut run, log.scan_step);
    let summary = LogSummary::of(&GroundTruth::from_runs(std::slice::from_ref(&run)));
    let mut exp = super::evaluate_runs(name, log.seed, vec![run], base, evaluation, opts)?;
    exp.report.log = Some(summary);
    Ok((exp, skipped))
}

/// Frames handed to the recognizers at a time.
const CHUNK_FRAMES: usize = 256;

/// Chunks read ahead of the recognizers at most.
const CHUNKS_AHEAD: usize = 2;

/// Recognizes the real log at `path` read as a stream, with every configuration of `opts` (as
/// [`super::evaluate_runs`] does with the log loaded whole, and with the same report): a first
/// pass surveys the log ([`LogSurvey`]), a second makes its frames on a thread of its own and
/// hands them, a chunk at a time, to every recognizer (in parallel), keeping only each frame's
/// truth. Memory holds a few chunks of scans, the truth and the recognizers' own state, whatever
/// the log's size. `Experiment::runs` is left empty. Returns the skipped lines too.
pub fn recognize_log_streamed(
    path: &Path,
    log: &RealLogOptions,
    name: &str,
    base: &RecognizerConfig,
    evaluation: &EvaluationSpec,
    opts: &ExperimentOptions,
) -> Result<(Experiment, usize), ExperimentError> {
    let configs = level_configs(base, &opts.levels)?;
    let (mut jobs, mut fronts) = jobs(&configs, evaluation, opts)?;
    let read = ReadOptions {
        lenient: log.lenient,
    };
    let survey = LogSurvey::read(path, read, log.truth)?;
    let kept = survey.frames().div_ceil(log.scan_step.max(1));
    opts.progress
        .start("recognizing", kept.div_ceil(CHUNK_FRAMES) as u64);
    let (tx, rx) = sync_channel::<Vec<Frame>>(CHUNKS_AHEAD);
    let mut truth = GroundTruth::default();
    let read = std::thread::scope(|s| {
        let producer = s.spawn(|| send_chunks(path, read, &survey, log, tx));
        feed_chunks(&mut jobs, &mut fronts, &mut truth, rx, &opts.progress);
        producer.join().expect("the log reader does not panic")
    });
    opts.progress.done();
    read?;
    let summary = LogSummary::of(&truth);
    let results = finish_jobs(jobs, truth)?;
    let mut exp = assemble(name, log.seed, 1, evaluation, &configs, results, Vec::new());
    exp.report.log = Some(summary);
    Ok((exp, survey.counts.skipped_lines))
}

/// Reads the frames of the log (after its survey), keeps every `scan_step`-th and sends them in
/// chunks of [`CHUNK_FRAMES`]; stops early when the receiver is gone.
fn send_chunks(
    path: &Path,
    read: ReadOptions,
    survey: &LogSurvey,
    log: &RealLogOptions,
    tx: SyncSender<Vec<Frame>>,
) -> Result<(), RealLogError> {
    let mut rng = stream(log.seed, 0, 0, Purpose::Odometry);
    let perturb = |inc| match &log.noise {
        Some(cfg) => perturb_increment(cfg, inc, &mut rng),
        None => inc,
    };
    let (mut chunk, mut i, mut open) = (Vec::with_capacity(CHUNK_FRAMES), 0usize, true);
    stream_frames(path, read, survey, log.truth, perturb, |frame| {
        if keeps_scan(i, log.scan_step) && open {
            chunk.push(frame);
            if chunk.len() == CHUNK_FRAMES {
                open = tx.send(std::mem::take(&mut chunk)).is_ok();
            }
        }
        i += 1;
    })?;
    if !chunk.is_empty() && open {
        let _ = tx.send(chunk);
    }
    Ok(())
}

/// Feeds the chunks from `rx` to every job (the jobs in parallel, through `fronts`) as frames of one run of one
/// lap, doors unknown (as a real log's run is), with their truth kept once in `truth`; a
/// progress step per chunk.
fn feed_chunks(
    jobs: &mut [Job],
    fronts: &mut FrontEnds,
    truth: &mut GroundTruth,
    rx: Receiver<Vec<Frame>>,
    progress: &super::ProgressSink,
) {
    truth.start_lap(LapInfo {
        run: 0,
        lap: 0,
        door_config: "unknown".into(),
        open_doors: Vec::new(),
    });
    fronts.start_run(jobs, truth);
    for (_, _, recording) in jobs.iter_mut() {
        recording.start_lap();
    }
    for chunk in rx {
        let first = truth.push_frames(&chunk);
        fronts.frames(jobs, &chunk, first, truth);
        settle(jobs, false);
        progress.step();
    }
    for (_, _, recording) in jobs.iter_mut() {
        recording.end_lap();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_walk_noise_has_the_configured_spread() {
        let cfg = OdometryConfig {
            proportional: ProportionalError::RandomWalk,
            ..OdometryConfig::default()
        };
        let mut rng = stream(1, 0, 0, Purpose::Odometry);
        let n = 20_000;
        let inc = Pose2::new(1.0, 0.0, 1.0);
        let (mut sx, mut sxx) = (0.0, 0.0);
        for _ in 0..n {
            let p = perturb_increment(&cfg, inc, &mut rng);
            let travel = p.x.hypot(p.y);
            sx += travel - 1.0;
            sxx += (travel - 1.0).powi(2);
        }
        let mean = sx / n as f64;
        let sd = (sxx / n as f64 - mean * mean).sqrt();
        assert!(mean.abs() < 0.0005, "mean error {mean}");
        assert!((sd - 0.0075).abs() < 0.00075, "spread {sd}");
    }

    /// Without errors the simulator's model gives back the increment, sideways motion and
    /// driving backwards included.
    #[test]
    fn a_noise_free_model_keeps_the_increment() {
        let cfg = parse_noise_model("proportional:0,0").unwrap().unwrap();
        let mut rng = stream(1, 0, 0, Purpose::Odometry);
        for inc in [
            Pose2::new(0.5, 0.1, 0.3),
            Pose2::new(-0.4, 0.05, -0.2),
            Pose2::new(0.0, 0.0, 0.7),
        ] {
            let p = perturb_increment(&cfg, inc, &mut rng);
            let err = (p.x - inc.x).abs() + (p.y - inc.y).abs() + (p.theta - inc.theta).abs();
            assert!(err < 1e-12, "{inc:?} became {p:?}");
        }
    }

    #[test]
    fn the_noise_grammar_names_its_mistakes() {
        assert_eq!(parse_noise_model("none"), Ok(None));
        assert!(
            parse_noise_model("thrun:1,2")
                .unwrap_err()
                .contains("takes 4 numbers")
        );
        assert!(
            parse_noise_model("proportional:x,1")
                .unwrap_err()
                .contains("`x`")
        );
        assert!(
            parse_noise_model("gauss")
                .unwrap_err()
                .contains("unknown model")
        );
    }
}
