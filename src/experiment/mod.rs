//! An experiment: runs of frames (simulated from a scenario, or read from a real log) fed to the
//! recognizer at each requested level configuration and to the ICP baseline, scored against the
//! truth, and gathered in one [`Report`]. The commands `run`, `check`, `table`, `sweep` and
//! `recognize` are thin layers over this module.

pub mod cache;
pub mod motion;
pub mod output;
pub mod picture;
pub(crate) mod progress;
pub mod real;
mod recognizer_settings;
pub(crate) mod scenario;
pub mod score;
mod shared_front;
pub(crate) mod stream;
pub mod stress;

use crate::baseline::icp::{IcpConfig, IcpRecognizer};
use crate::baseline::scan_context::{ScanContextConfig, ScanContextRecognizer};
use crate::eval::metrics::Scorer;
use crate::eval::ranking::{self, SubjectRanking};
use crate::eval::scores::{Report, SubjectKind};
use crate::eval::sweep::{GridPoint, SweepResult, sweep_matches};
use crate::eval::{Recognition, recognize_runs_with_progress};
use crate::external::{ExternalRecognizer, ExternalSpec};
use crate::place::{Match, PlaceRecognizer};
use crate::recognizer::{DensityObservation, Recognizer, RecognizerConfig, WordMatch, WordMatcher};
use crate::sim::{RunLog, SimError};
use crate::spec::SpecError;
use crate::spec::evaluation::EvaluationSpec;
pub use progress::{Progress, ProgressSink};
use rayon::prelude::*;
pub use recognizer_settings::{load_recognizer_config, parse_recognizer_config};
pub use scenario::{
    Scenario, Workload, check_scenario, load_scenario, load_scenario_for, parse_scenario,
    parse_scenario_for,
};
pub use stream::run_scenario_streamed;

/// Why an experiment could not be carried out.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error("simulation failed: {0}")]
    Sim(#[from] SimError),
    #[error("{0}")]
    Recognizer(String),
    #[error(transparent)]
    Output(#[from] crate::io::atomic::StageError),
    #[error("{0}")]
    Write(#[from] std::io::Error),
    #[error(transparent)]
    RealLog(#[from] crate::io::real_log::RealLogError),
    #[error("{0}")]
    External(String),
    /// A lap cache entry that failed after it was verified.
    #[error("lap cache: {0}")]
    Cache(String),
}

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentOptions {
    /// Level configurations of the recognizer to run (1, 2, 3, 4). Default [1, 2, 3].
    pub levels: Vec<usize>,
    /// Also run the ICP baseline. Default false (it is slow: every region against every past one).
    pub icp: bool,
    /// Also run the Scan Context baseline. Default false.
    pub scan_context: bool,
    /// The Scan Context baseline's settings (a scenario's `[scan_context]` table; its `min_gap_m`
    /// is replaced by the evaluation's). Default [`ScanContextConfig::default`].
    pub scan_context_config: ScanContextConfig,
    /// Recognizers in other processes to score beside the built-in ones (`--recognizer
    /// NAME=exec:COMMAND`). Default none.
    pub external: Vec<ExternalSpec>,
    /// Replace every run's lap count. Default: the scenario's.
    pub laps: Option<usize>,
    /// Where progress goes. Default: nowhere.
    pub progress: ProgressSink,
    /// The lap cache to read simulated laps from and store them in (`--cache DIR`). Default
    /// none: every lap is simulated.
    pub cache: Option<std::sync::Arc<cache::LapCache>>,
}

impl Default for ExperimentOptions {
    fn default() -> Self {
        ExperimentOptions {
            levels: vec![1, 2, 3],
            icp: false,
            scan_context: false,
            scan_context_config: ScanContextConfig::default(),
            external: Vec::new(),
            laps: None,
            progress: ProgressSink::none(),
            cache: None,
        }
    }
}

/// The provenance of results made from `scenarios`, each simulated at its own seed with
/// `laps` (`--laps`) replacing the lap counts when given: each one's inputs, simulation key and
/// seed (`eval::provenance`).
pub fn scenario_provenance(
    scenarios: &[&Scenario],
    laps: Option<usize>,
    command_line: Vec<String>,
) -> crate::eval::provenance::Provenance {
    use crate::eval::provenance::{self, Provenance};
    let mut p = Provenance::new(command_line);
    for scn in scenarios {
        p.add_inputs(provenance::scenario_inputs(
            &scn.sim,
            &scn.recognizer,
            &scn.evaluation,
            &scn.expect,
        ));
        p.add_inputs([provenance::simulation_input(&scn.sim, scn.sim.seed, laps)]);
        p.add_seeds([scn.sim.seed]);
    }
    p
}

/// Everything an experiment produced: the report, and the data behind it for pictures.
pub struct Experiment {
    pub report: Report,
    pub runs: Vec<RunLog>,
    /// One recognition per level configuration, in the order of `ExperimentOptions::levels`.
    pub recognitions: Vec<(usize, Recognition)>,
    pub icp: Option<Recognition>,
    pub scan_context: Option<Recognition>,
    /// The external subjects' recognitions, by name, in the order of
    /// `ExperimentOptions::external`.
    pub external: Vec<(String, Recognition)>,
    /// Where the laps came from with a lap cache (`None` without one, or for a real log).
    pub lap_source: Option<crate::eval::provenance::LapSource>,
}

/// Which subject a recognition belongs to while an experiment runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SubjectId {
    /// The paper's recognizer with this many levels.
    Words(usize),
    /// The ICP baseline.
    Icp,
    /// The Scan Context baseline.
    ScanContext,
    /// An external recognizer, by name.
    External(String),
}

impl SubjectId {
    /// The levels of a words subject.
    pub fn levels(&self) -> Option<usize> {
        match self {
            SubjectId::Words(l) => Some(*l),
            _ => None,
        }
    }
}

/// Starts the external recognizers of `specs`.
fn start_external(specs: &[ExternalSpec]) -> Result<Vec<ExternalRecognizer>, ExperimentError> {
    specs
        .iter()
        .map(|s| ExternalRecognizer::start(s).map_err(|e| ExperimentError::External(e.to_string())))
        .collect()
}

/// The first failure of a recognizer that can fail (an external program), as an error.
fn failed<'a>(
    recs: impl IntoIterator<Item = &'a dyn PlaceRecognizer>,
) -> Result<(), ExperimentError> {
    match recs.into_iter().find_map(|r| r.failure()) {
        Some(why) => Err(ExperimentError::External(why)),
        None => Ok(()),
    }
}

/// The recognizer settings of a scenario (checked when the scenario was loaded).
pub fn recognizer_config(scn: &Scenario) -> Result<RecognizerConfig, SpecError> {
    Ok(scn.recognizer.clone())
}

/// `base` with `levels` level configurations (thresholds unchanged).
pub fn config_for_levels(base: &RecognizerConfig, levels: usize) -> RecognizerConfig {
    base.clone().with_levels(levels)
}

pub use crate::recognizer::thresholds;

/// Simulates a scenario (or reads its laps from `opts.cache`), telling its progress per lap;
/// returns the runs, the CPU seconds the laps cost, and where they came from with a cache.
pub fn simulate(
    scn: &Scenario,
    opts: &ExperimentOptions,
) -> Result<(Vec<RunLog>, f64, Option<crate::eval::provenance::LapSource>), SimError> {
    match &opts.cache {
        Some(cache) => cache
            .runs(&scn.sim, opts.laps, || simulate_here(scn, opts))
            .map(|(runs, s, source)| (runs, s, Some(source))),
        None => simulate_here(scn, opts).map(|(runs, s)| (runs, s, None)),
    }
}

/// [`simulate`] without a cache.
fn simulate_here(scn: &Scenario, opts: &ExperimentOptions) -> Result<(Vec<RunLog>, f64), SimError> {
    let laps: usize = scn
        .sim
        .runs
        .iter()
        .map(|r| opts.laps.unwrap_or(r.laps))
        .sum();
    opts.progress.start("simulating", laps as u64);
    let runs = crate::sim::runner::simulate_timed(&scn.sim, opts.laps, &|| opts.progress.step());
    opts.progress.done();
    runs
}

/// `opts` with the scenario's own baseline settings (`[scan_context]`) and its `[[subjects]]`
/// before the `--recognizer` ones; a flag naming a subject of the scenario replaces it (to try
/// another build of the same recognizer against the scenario's bounds).
pub fn options_for_scenario(scn: &Scenario, opts: &ExperimentOptions) -> ExperimentOptions {
    let own = scn
        .subjects
        .iter()
        .filter(|s| !opts.external.iter().any(|x| x.name == s.name));
    ExperimentOptions {
        scan_context_config: scn.scan_context.clone(),
        external: own.chain(&opts.external).cloned().collect(),
        ..opts.clone()
    }
}

/// The Scan Context baseline with `opts`' settings and the evaluation's gap.
pub(crate) fn scan_context_recognizer(
    opts: &ExperimentOptions,
    evaluation: &EvaluationSpec,
) -> Result<ScanContextRecognizer, ExperimentError> {
    let mut cfg = opts.scan_context_config.clone();
    cfg.min_gap_m = evaluation.min_gap_m;
    ScanContextRecognizer::new(cfg).map_err(|problems| {
        let text: Vec<String> = problems.iter().map(ToString::to_string).collect();
        ExperimentError::Recognizer(format!("[scan_context]: {}", text.join("; ")))
    })
}

/// Simulates a scenario and evaluates it.
pub fn run_scenario(
    scn: &Scenario,
    opts: &ExperimentOptions,
) -> Result<Experiment, ExperimentError> {
    let opts = &options_for_scenario(scn, opts);
    let base = recognizer_config(scn)?;
    let (runs, sim_s, lap_source) = simulate(scn, opts)?;
    let mut exp = evaluate_runs(
        &scn.sim.name,
        scn.sim.seed,
        runs,
        &base,
        &scn.evaluation,
        opts,
    )?;
    let laps = exp.report.laps.max(1);
    exp.report.simulate_seconds_per_lap = sim_s / laps as f64;
    exp.lap_source = lap_source;
    Ok(exp)
}

/// Feeds `runs` to the recognizer at each requested level configuration (in parallel; each
/// times itself) and, if asked, to ICP; scores them all.
pub fn evaluate_runs(
    name: &str,
    seed: u64,
    runs: Vec<RunLog>,
    base: &RecognizerConfig,
    evaluation: &EvaluationSpec,
    opts: &ExperimentOptions,
) -> Result<Experiment, ExperimentError> {
    let laps: usize = runs.iter().map(|r| r.laps.len()).sum();
    let configs = level_configs(base, &opts.levels)?;
    let external = start_external(&opts.external)?;
    let jobs = configs.len() + usize::from(opts.icp) + usize::from(opts.scan_context);
    // The Scan Context job, when asked, is the last; its settings are checked before any work.
    if opts.scan_context {
        scan_context_recognizer(opts, evaluation)?;
    }
    opts.progress
        .start("recognizing", ((jobs + external.len()) * laps) as u64);
    // Each task is single-threaded and timed on its own; the tasks share the cores.
    let results: Result<Vec<(SubjectId, Recognition)>, _> = (0..jobs)
        .into_par_iter()
        .map(|j| {
            let mut on_lap = |_: usize| opts.progress.step();
            if j < configs.len() {
                let cfg = &configs[j];
                let mut rec = Recognizer::new(cfg.clone())
                    .map_err(|e| ExperimentError::Recognizer(e.to_string()))?;
                Ok((
                    SubjectId::Words(cfg.levels),
                    recognize_runs_with_progress(&mut rec, &runs, &mut on_lap),
                ))
            } else if j == configs.len() + usize::from(opts.icp) {
                let mut sc = scan_context_recognizer(opts, evaluation)?;
                Ok((
                    SubjectId::ScanContext,
                    recognize_runs_with_progress(&mut sc, &runs, &mut on_lap),
                ))
            } else {
                let mut icp = IcpRecognizer::new(IcpConfig {
                    min_gap_m: evaluation.min_gap_m,
                    ..IcpConfig::default()
                });
                Ok((
                    SubjectId::Icp,
                    recognize_runs_with_progress(&mut icp, &runs, &mut on_lap),
                ))
            }
        })
        .collect::<Result<_, ExperimentError>>();
    let mut results = results?;
    for mut rec in external {
        let mut on_lap = |_: usize| opts.progress.step();
        let recognition = recognize_runs_with_progress(&mut rec, &runs, &mut on_lap);
        failed([&rec as &dyn PlaceRecognizer])?;
        results.push((SubjectId::External(rec.name()), recognition));
    }
    opts.progress.done();
    Ok(assemble(
        name, seed, laps, evaluation, &configs, results, runs,
    ))
}

/// The recognizer settings of each level configuration in `levels`, checked.
fn level_configs(
    base: &RecognizerConfig,
    levels: &[usize],
) -> Result<Vec<RecognizerConfig>, ExperimentError> {
    let mut configs = Vec::new();
    for &levels in levels {
        let cfg = config_for_levels(base, levels);
        let problems = cfg.problems();
        if !problems.is_empty() {
            let text: Vec<String> = problems.iter().map(ToString::to_string).collect();
            return Err(ExperimentError::Recognizer(format!(
                "recognizer with {levels} levels: {}",
                text.join("; ")
            )));
        }
        configs.push(cfg);
    }
    Ok(configs)
}

/// Scores the recognitions (one per entry of `configs`, in order, then ICP's with `None`) into
/// an experiment.
fn assemble(
    name: &str,
    seed: u64,
    laps: usize,
    evaluation: &EvaluationSpec,
    configs: &[RecognizerConfig],
    results: Vec<(SubjectId, Recognition)>,
    runs: Vec<RunLog>,
) -> Experiment {
    let mut report = Report::new(name, seed, laps, evaluation.clone());
    let (mut icp, mut recognitions, mut external) = (None, Vec::new(), Vec::new());
    let mut scan_context = None;
    for (id, r) in results {
        match id {
            SubjectId::Words(levels) => {
                report.add_level(levels, &thresholds(&configs[recognitions.len()]), &r);
                recognitions.push((levels, r));
            }
            SubjectId::Icp => {
                report.add_subject("icp", SubjectKind::Icp, &r);
                icp = Some(r);
            }
            SubjectId::ScanContext => {
                report.add_subject("scan-context", SubjectKind::ScanContext, &r);
                scan_context = Some(r);
            }
            SubjectId::External(name) => {
                report.add_subject(&name, SubjectKind::External, &r);
                external.push((name, r));
            }
        }
    }
    report.set_level_gains(&recognitions);
    report.finish();
    Experiment {
        report,
        runs,
        recognitions,
        icp,
        scan_context,
        external,
        lap_source: None,
    }
}

/// Runs the back end with the levels and thresholds of `point` over `observations`, handing
/// `sink` the matches of each observation as they are found, with the back end's query horizon
/// after them (no later match names an older query), so the caller scores them as they come
/// rather than holding them.
pub fn back_end_stream(
    observations: &[DensityObservation],
    base: &RecognizerConfig,
    point: &GridPoint,
    sink: &mut dyn FnMut(&[Match], usize),
) -> Result<(), ExperimentError> {
    let mut min_ngram = base.matcher.min_ngram.clone();
    for (k, t) in point.thresholds.iter().enumerate() {
        if k < min_ngram.len() {
            min_ngram[k] = *t;
        } else {
            min_ngram.push(*t);
        }
    }
    let mut cfg = config_for_levels(base, point.levels);
    cfg.matcher.min_ngram = min_ngram;
    let mut back =
        WordMatcher::new(&cfg).map_err(|e| ExperimentError::Recognizer(e.to_string()))?;
    let mut hand = |found: Vec<WordMatch>, horizon: usize| {
        if !found.is_empty() {
            let matches: Vec<Match> = found.iter().map(WordMatch::to_place).collect();
            sink(&matches, horizon);
        }
    };
    for o in observations {
        let found = back.push_observation(o);
        hand(found, back.query_horizon());
    }
    let found = back.finish_run();
    hand(found, back.query_horizon());
    Ok(())
}

/// The back-end passes [`sweep`] makes over `grid`, for the work budget: one per grid point,
/// and at most one per level for the words subjects' score curves.
pub fn sweep_passes(grid: &[GridPoint]) -> usize {
    grid.len() + crate::recognizer::words::MAX_LEVELS
}

/// The paper's Fig. 8 sweep of `scn` (laps per run replaced by `opts.laps`): the laps are
/// simulated (or read from `opts.cache`) and turned into observations as they come, each lap's
/// scans dropped once observed (`stream::observe_scenario`), so memory holds the observations
/// and the truth, not the scans; then every grid point's back end runs in parallel. Results in
/// grid order whatever the thread count, with the laps driven and each words subject's curve
/// over its match score at the scenario's thresholds (`words-1` … `words-<levels>`).
pub fn sweep(
    scn: &Scenario,
    opts: &ExperimentOptions,
    grid: &[GridPoint],
) -> Result<(Vec<SweepResult>, usize, Vec<SubjectRanking>), ExperimentError> {
    let base = recognizer_config(scn)?;
    // Check every grid point's settings before any work, so errors are reported once.
    for p in grid {
        back_end_stream(&[], &base, p, &mut |_, _| {})?;
    }
    let (densities, truth) = stream::observe_scenario(scn, &base, opts)?;
    let observations: Vec<_> = densities.iter().map(|d| d.observation).collect();
    let progress = &opts.progress;
    progress.start("sweeping", grid.len() as u64);
    let results = sweep_matches(
        grid,
        &observations,
        &truth,
        &scn.evaluation,
        |p, sink| {
            // Every point's settings were checked above.
            let _ = back_end_stream(&densities, &base, p, sink);
        },
        &|| progress.step(),
    );
    progress.done();
    let evaluation = &scn.evaluation;
    let scorer = Scorer::new(&observations, &truth, evaluation);
    let positives = scorer
        .revisits(evaluation.tp_radius_m)
        .iter()
        .filter(|&&r| r)
        .count();
    let thresholds = &base.matcher.min_ngram;
    let score_curves = (1..=base.levels.max(1))
        .map(|levels| {
            let point = GridPoint::new(levels, &thresholds[..levels.min(thresholds.len())]);
            let mut ranking = ranking::Ranking::default();
            back_end_stream(&densities, &base, &point, &mut |matches, _| {
                for m in matches {
                    ranking.add(m, &scorer, evaluation);
                }
            })?;
            Ok(SubjectRanking {
                name: crate::eval::scores::words_subject_name(levels),
                ranking: ranking.scores(positives, observations.len(), 0.0, evaluation),
            })
        })
        .collect::<Result<Vec<_>, ExperimentError>>()?;
    Ok((results, truth.laps.len(), score_curves))
}
