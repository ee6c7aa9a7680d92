//! A scenario run lap by lap: each lap is simulated on one thread and fed to every recognizer
//! on another as soon as it is made, then dropped. Memory holds at most a few laps of scans
//! (not every run's), plus the truth of every frame and the recognizers' own state, so a run of
//! a thousand laps fits where holding its scans would not. Matches are scored as they arrive
//! ([`crate::eval::Recording::streaming`], `eval::tally`) and dropped: after each lap every job
//! forgets the pairs behind the recognizers' query horizon ([`settle`]), so neither the matches
//! nor their pairs are held.
//!
//! The report is the one [`super::run_scenario`] gives: the simulator draws each lap from its
//! run's seeded streams whatever else runs, and each recognizer sees the same frames in the same
//! order. Only `Experiment::runs` is left empty (so no pictures, no exported matches).
//!
//! The lap producer ([`with_laps`]) also feeds `simulate`'s log writer (`super::output`).

use super::shared_front::FrontEnds;
use super::{ExperimentError, ExperimentOptions, ProgressSink, SubjectId, assemble, level_configs};
use crate::baseline::icp::{IcpConfig, IcpRecognizer};
use crate::eval::provenance::LapSource;
use crate::eval::{GroundTruth, LapInfo, PlaceRecognizer, Recognition, Recording};
use crate::experiment::cache::LapCache;
use crate::external::ExternalRecognizer;
use crate::log::LapLog;
use crate::recognizer::{DensityFrontEnd, DensityObservation, RecognizerConfig};
use crate::sim::runner::RunSim;
use crate::sim::{SimError, SimPlan};
use crate::spec::evaluation::EvaluationSpec;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::time::Instant;

use super::{Experiment, Scenario, recognizer_config};

/// Laps simulated ahead of the recognizers at most (each holds one lap of scans).
const LAPS_AHEAD: usize = 2;

/// A recognizer with its recording, and which subject it is.
pub(super) type Job = (SubjectId, Box<dyn PlaceRecognizer + Send>, Recording);

/// Simulates `scn` and evaluates it lap by lap (see the module doc).
pub fn run_scenario_streamed(
    scn: &Scenario,
    opts: &ExperimentOptions,
) -> Result<Experiment, ExperimentError> {
    let opts = &super::options_for_scenario(scn, opts);
    let configs = level_configs(&recognizer_config(scn)?, &opts.levels)?;
    let (mut jobs, mut fronts) = jobs(&configs, &scn.evaluation, opts)?;
    let plan = &scn.sim;
    let laps_of = |run: usize| opts.laps.unwrap_or(plan.runs[run].laps);
    let total: usize = (0..plan.runs.len()).map(laps_of).sum();
    opts.progress.start("laps", total as u64);
    let mut truth = GroundTruth::default();
    let (sim, ()) = with_laps(plan, &laps_of, opts.cache.as_deref(), |rx| {
        feed(&mut jobs, &mut fronts, &mut truth, rx, &opts.progress)
    });
    opts.progress.done();
    let (sim_s, lap_source) = sim?;
    let results = finish_jobs(jobs, truth)?;
    let mut exp = assemble(
        &plan.name,
        plan.seed,
        total,
        &scn.evaluation,
        &configs,
        results,
        Vec::new(),
    );
    exp.report.simulate_seconds_per_lap = sim_s / total.max(1) as f64;
    exp.lap_source = lap_source;
    Ok(exp)
}

/// The observations `base`'s front end makes of `scn`'s laps (laps per run replaced by
/// `opts.laps`), and the truth of every frame: each lap is observed as it is simulated (or read
/// from `opts.cache`) and its scans dropped, a new run starting the front end's next run, as
/// feeding the held runs would (progress: a step per lap).
pub(super) fn observe_scenario(
    scn: &Scenario,
    base: &RecognizerConfig,
    opts: &ExperimentOptions,
) -> Result<(Vec<DensityObservation>, GroundTruth), ExperimentError> {
    let mut front =
        DensityFrontEnd::new(base).map_err(|e| ExperimentError::Recognizer(e.to_string()))?;
    let plan = &scn.sim;
    let laps_of = |run: usize| opts.laps.unwrap_or(plan.runs[run].laps);
    let total: usize = (0..plan.runs.len()).map(laps_of).sum();
    opts.progress.start("laps", total as u64);
    let mut truth = GroundTruth::default();
    let mut out = Vec::new();
    let (sim, ()) = with_laps(plan, &laps_of, opts.cache.as_deref(), |rx| {
        let mut current = None;
        for (run, lap) in rx {
            if current.is_some_and(|c| c != run) {
                front.start_run();
            }
            current = Some(run);
            truth.start_lap(LapInfo::of(run, &lap));
            truth.push_frames(&lap.frames);
            for f in &lap.frames {
                out.extend(front.push(f.odom, &f.scan));
            }
            opts.progress.step();
        }
    });
    opts.progress.done();
    sim?;
    Ok((out, truth))
}

/// Simulates `plan` (`laps_of(run)` laps per run) on a thread of its own, or reads its laps
/// from `cache` when it holds them (storing them there when it does not), while `consume`
/// takes the laps, in order, from the receiver it is given; returns the simulation's outcome
/// (CPU seconds spent simulating or reading, and with a cache where the laps came from) and
/// `consume`'s. Dropping the receiver early stops the simulation (and stores nothing).
pub(super) fn with_laps<T>(
    plan: &SimPlan,
    laps_of: &(dyn Fn(usize) -> usize + Sync),
    cache: Option<&LapCache>,
    consume: impl FnOnce(Receiver<(usize, LapLog)>) -> T,
) -> (Result<(f64, Option<LapSource>), ExperimentError>, T) {
    let (tx, rx) = sync_channel::<(usize, LapLog)>(LAPS_AHEAD);
    std::thread::scope(|s| {
        let producer = s.spawn(move || produce_laps(plan, laps_of, cache, &tx));
        let out = consume(rx);
        let sim = producer
            .join()
            .expect("the simulation thread does not panic");
        (sim, out)
    })
}

/// The laps of `plan`, sent in order: from `cache`'s intact entry when there is one, else
/// simulated (and stored in `cache`); the CPU seconds spent and where they came from.
fn produce_laps(
    plan: &SimPlan,
    laps_of: &dyn Fn(usize) -> usize,
    cache: Option<&LapCache>,
    tx: &SyncSender<(usize, LapLog)>,
) -> Result<(f64, Option<LapSource>), ExperimentError> {
    let Some(cache) = cache else {
        return Ok((simulate_laps(plan, laps_of, tx, &mut |_, _| {})?.0, None));
    };
    let counts: Vec<usize> = (0..plan.runs.len()).map(laps_of).collect();
    let key = LapCache::key(plan, &counts);
    let w = crate::clock::Stopwatch::start();
    let source = match cache.open_entry(&key, &counts) {
        Ok(Some(mut entry)) => {
            loop {
                match entry.next_lap() {
                    Ok(Some(lap)) => {
                        if tx.send(lap).is_err() {
                            break;
                        }
                    }
                    Ok(None) => break,
                    Err(why) => return Err(ExperimentError::Cache(why)),
                }
            }
            cache.count(LapSource::Hit);
            return Ok((w.cpu_s(), Some(LapSource::Hit)));
        }
        Ok(None) => LapSource::Miss,
        Err(_) => LapSource::Corrupt,
    };
    let mut pending = cache.begin(&key, &counts);
    let (seconds, complete) =
        simulate_laps(plan, laps_of, tx, &mut |run, lap| pending.push(run, lap))?;
    if complete {
        cache.store(pending);
    }
    cache.count(source);
    Ok((seconds, Some(source)))
}

/// Simulates every lap of every run in order, handing each to `keep` and then sending it
/// (blocks while [`LAPS_AHEAD`] laps wait); returns the CPU seconds spent simulating (and
/// keeping) and whether every lap was sent. Stops early when the receiver is gone.
fn simulate_laps(
    plan: &SimPlan,
    laps_of: &dyn Fn(usize) -> usize,
    tx: &SyncSender<(usize, LapLog)>,
    keep: &mut dyn FnMut(usize, &LapLog),
) -> Result<(f64, bool), SimError> {
    let mut seconds = 0.0;
    for run in 0..plan.runs.len() {
        let mut sim = RunSim::new(plan, run);
        for lap in 0..laps_of(run) {
            let w = crate::clock::Stopwatch::start();
            let log = sim.run_lap(lap)?;
            keep(run, &log);
            seconds += w.cpu_s();
            if tx.send((run, log)).is_err() {
                return Ok((seconds, false));
            }
        }
    }
    Ok((seconds, true))
}

/// One job per level configuration, in order, then ICP's and Scan Context's if asked (with the
/// evaluation's `min_gap_m`), then one per external recognizer (started here). Each scores its
/// matches as they arrive ([`Recording::streaming`]; a configuration with one level fewer than
/// another keeps what it forgets, to count the other's gain, [`settle`]). The level
/// configurations with the same front-end settings share one density front end (the
/// [`FrontEnds`] returned, which feed the jobs: `shared_front`).
pub(super) fn jobs(
    configs: &[RecognizerConfig],
    evaluation: &EvaluationSpec,
    opts: &ExperimentOptions,
) -> Result<(Vec<Job>, FrontEnds), ExperimentError> {
    let mut jobs: Vec<Job> = Vec::new();
    let mut fronts = FrontEnds::default();
    for cfg in configs {
        let rec = fronts.words_job(cfg)?;
        jobs.push((
            SubjectId::Words(cfg.levels),
            Box::new(rec),
            Recording::streaming(evaluation),
        ));
    }
    for (here, fewer) in gain_pairs(&jobs) {
        jobs[here].2.keep_forgotten();
        jobs[fewer].2.keep_forgotten();
    }
    if opts.icp {
        let icp = IcpRecognizer::new(IcpConfig {
            min_gap_m: evaluation.min_gap_m,
            ..IcpConfig::default()
        });
        jobs.push((
            SubjectId::Icp,
            Box::new(icp),
            Recording::streaming(evaluation),
        ));
        fronts.own_job();
    }
    if opts.scan_context {
        jobs.push((
            SubjectId::ScanContext,
            Box::new(super::scan_context_recognizer(opts, evaluation)?),
            Recording::streaming(evaluation),
        ));
        fronts.own_job();
    }
    for spec in &opts.external {
        let rec = ExternalRecognizer::start(spec)
            .map_err(|e| ExperimentError::External(e.to_string()))?;
        jobs.push((
            SubjectId::External(spec.name.clone()),
            Box::new(rec),
            Recording::streaming(evaluation),
        ));
        fronts.own_job();
    }
    Ok((jobs, fronts))
}

/// `(job, job with one level fewer)` for every level configuration whose gain is reported.
fn gain_pairs(jobs: &[Job]) -> Vec<(usize, usize)> {
    let levels: Vec<Option<usize>> = jobs.iter().map(|j| j.0.levels()).collect();
    let mut out = Vec::new();
    for (i, l) in levels.iter().enumerate() {
        let Some(l) = l else { continue };
        if let Some(k) = levels.iter().position(|&m| m == Some(l.saturating_sub(1))) {
            out.push((i, k));
        }
    }
    out
}

/// Lets every job forget the pairs behind the recognizers' query horizons, and counts the level
/// gains of what they forgot (`last`: the input has ended; everything goes). The level
/// configurations forget behind one common horizon, the earliest of theirs, so the pairs each
/// forgets are those the one with a level fewer forgets at the same time; ICP behind its own.
pub(super) fn settle(jobs: &mut [Job], last: bool) {
    let common = jobs
        .iter()
        .filter(|j| j.0.levels().is_some())
        .map(|j| j.1.query_horizon())
        .min()
        .unwrap_or(0);
    for (id, rec, recording) in jobs.iter_mut() {
        let h = match (last, id.levels().is_some()) {
            (true, _) => usize::MAX,
            (false, true) => common,
            (false, false) => rec.query_horizon(),
        };
        recording.forget_behind(h);
    }
    let pairs = gain_pairs(jobs);
    if pairs.is_empty() {
        return;
    }
    let forgotten: Vec<Vec<u64>> = jobs.iter_mut().map(|j| j.2.take_forgotten()).collect();
    for (here, fewer) in pairs {
        jobs[here]
            .2
            .add_level_gain(&forgotten[here], &forgotten[fewer]);
    }
}

/// Feeds each lap from `rx` to every job (the jobs in parallel, through `fronts`), starting a
/// run at each new run index, with the laps' truth kept once in `truth`; tells `progress` a
/// step per lap and a status of laps per second and memory.
fn feed(
    jobs: &mut [Job],
    fronts: &mut FrontEnds,
    truth: &mut GroundTruth,
    rx: Receiver<(usize, LapLog)>,
    progress: &ProgressSink,
) {
    let start = Instant::now();
    let mut current = None;
    for (run, lap) in rx {
        let new_run = current != Some(run);
        current = Some(run);
        if new_run {
            fronts.start_run(jobs, truth);
        }
        truth.start_lap(LapInfo::of(run, &lap));
        let first = truth.push_frames(&lap.frames);
        for (_, _, recording) in jobs.iter_mut() {
            recording.start_lap();
        }
        fronts.frames(jobs, &lap.frames, first, truth);
        for (_, _, recording) in jobs.iter_mut() {
            recording.end_lap();
        }
        settle(jobs, false);
        progress.step();
        let done = jobs.first().map_or(0, |j| j.2.laps());
        progress.status(&progress_message(done, start.elapsed().as_secs_f64()));
    }
}

/// Ends every job's input and hands its recording and recognizer over as the scored
/// recognition; `truth` is the truth of every frame fed, shared by the recognitions. A
/// recognizer that failed (an external program) fails the whole experiment.
pub(super) fn finish_jobs(
    mut jobs: Vec<Job>,
    truth: GroundTruth,
) -> Result<Vec<(SubjectId, Recognition)>, ExperimentError> {
    for (_, rec, recording) in &mut jobs {
        recording.close(rec.as_mut(), &truth);
    }
    if let Some(why) = jobs.iter().find_map(|j| j.1.failure()) {
        return Err(ExperimentError::External(why));
    }
    settle(&mut jobs, true);
    // Each recognizer is dropped as soon as its recording has taken what it needs, before any
    // tally makes its last count: the peak memory of a long log is the end of recognition.
    let ended: Vec<(SubjectId, crate::eval::Ended)> = jobs
        .into_iter()
        .map(|(levels, mut rec, recording)| (levels, recording.end(rec.as_mut(), &truth)))
        .collect();
    let truth = Arc::new(truth);
    // The level configurations see the same observations: what their scores take from the
    // truth alone is counted once.
    let mut shared = crate::eval::SharedTruth::new(ended.len());
    Ok(ended
        .into_iter()
        .map(|(levels, e)| (levels, e.finish_sharing(truth.clone(), &mut shared)))
        .collect())
}

/// "12.3 laps/s, 456 MB (peak 789 MB)": the rate so far and the process's resident memory.
fn progress_message(laps: usize, seconds: f64) -> String {
    let rate = laps as f64 / seconds.max(1e-9);
    match resident_memory_mb() {
        Some((now, peak)) => format!("{rate:.1} laps/s, {now:.0} MB (peak {peak:.0} MB)"),
        None => format!("{rate:.1} laps/s"),
    }
}

/// The process's resident memory now and at its peak, MB (`VmRSS` and `VmHWM` of
/// /proc/self/status; `None` where that file does not exist).
pub fn resident_memory_mb() -> Option<(f64, f64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb = |key: &str| -> Option<f64> {
        let line = status.lines().find(|l| l.starts_with(key))?;
        line[key.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()
    };
    Some((kb("VmRSS:")? / 1024.0, kb("VmHWM:")? / 1024.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::load_scenario;
    use std::path::Path;

    /// Scoring as matches arrive keeps only the pairs a later match could repeat (those with
    /// a query in the last τ·(span + 1) level-0 words, several laps of the small loop): over the
    /// smoke scenario driven for 30 + 10 laps, each place matched to its 8 most recent
    /// look-alikes as the long-term scenario does (so the pairs each lap adds stop growing too),
    /// what each configuration holds stops growing with the laps while the pairs it scored do
    /// not, none arrived behind the horizon, and the 3-level configuration's gain over the
    /// 2-level one is counted.
    #[test]
    fn streamed_scoring_forgets_the_pairs_behind_the_horizon() {
        let scn = load_scenario(Path::new("scenarios/smoke.toml")).expect("smoke loads");
        let mut base = recognizer_config(&scn).unwrap();
        base.matcher.max_candidates = 8;
        let configs = level_configs(&base, &[2, 3]).unwrap();
        let (mut jobs, mut fronts) =
            jobs(&configs, &scn.evaluation, &ExperimentOptions::default()).unwrap();
        let laps_of = |run: usize| [30, 10][run];
        let mut held_at = Vec::new();
        let mut truth = GroundTruth::default();
        let (sim, ()) = with_laps(&scn.sim, &laps_of, None, |rx| {
            let mut current = None;
            for (run, lap) in rx {
                if current != Some(run) {
                    fronts.start_run(&mut jobs, &truth);
                }
                truth.start_lap(LapInfo::of(run, &lap));
                let first = truth.push_frames(&lap.frames);
                jobs.iter_mut().for_each(|j| j.2.start_lap());
                fronts.frames(&mut jobs, &lap.frames, first, &truth);
                jobs.iter_mut().for_each(|j| j.2.end_lap());
                current = Some(run);
                settle(&mut jobs, false);
                held_at.push(jobs[1].2.pairs_held().expect("streaming").0);
            }
        });
        sim.expect("simulates");
        let late: Vec<usize> = jobs.iter().map(|j| j.2.pairs_held().unwrap().1).collect();
        let results = finish_jobs(jobs, truth).unwrap();
        let (_, e) = results[1].1.evaluation.as_ref().expect("scored as it went");
        assert!(results[1].1.matches.is_empty(), "no match is kept");
        // Held pairs flatten out: laps 30–40 hold at most a third more than laps 15–20 did,
        // and at the end a small part of what was scored.
        let (mid, end) = (held_at[14..20].iter().max(), held_at[30..].iter().max());
        let (mid, end) = (*mid.unwrap(), *end.unwrap());
        assert!(
            3 * end <= 4 * mid,
            "held {mid} at laps 15-20, {end} at laps 31-40"
        );
        assert!(3 * end < e.main.pairs, "{end} of {} held", e.main.pairs);
        for (_, rec) in &results {
            let (_, e) = rec.evaluation.as_ref().expect("scored as it went");
            assert_eq!(e.main.late_pairs, 0);
        }
        assert_eq!(late, [0, 0]);
        assert!(results[0].1.level_gain.is_none());
        assert!(results[1].1.level_gain.is_some());
    }
}
