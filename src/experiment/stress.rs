//! The stress run behind `check` and `run --seeds`: every scenario at every seed of its range,
//! all (scenario × seed) work items in parallel on every core, gathered in a
//! [`SuiteReport`]. With a [`Shard`], only that part's items run and the report is a part for
//! `merge`.
//!
//! Each seed is simulated once and its runs shared by every level configuration (and ICP). A
//! seed's results depend only on the scenario and the seed (`sim::rng`), and items are
//! gathered in plan order, so a report is the same whatever the thread count or the sharding
//! (timings apart).

use crate::eval::provenance::{self, Provenance};
use crate::eval::suite::{ScenarioResult, SeedResult, SuiteReport, labels};
use crate::experiment::scenario::{Scenario, Workload, WorldLoader, parse_scenario_for};
use crate::experiment::{ExperimentOptions, ProgressSink};
use crate::io::atomic::holds_only;
use crate::spec::diag::read_text;
use crate::spec::seeds::{SeedRange, Shard};
use crate::world::load_world_for;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to run over seeds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StressOptions {
    /// Seeds for every scenario. Default: each scenario's `seeds`, else its `seed`.
    pub seeds: Option<SeedRange>,
    /// Run only this part of the work. Default: all of it.
    pub shard: Option<Shard>,
    /// Check the `[expect]` blocks (`check`): the configurations run are those the block
    /// names, and a scenario without one is an error. Default false (`run`).
    pub gate: bool,
    /// With `gate`, skip a scenario without `[expect]` instead of failing. Default false.
    pub allow_no_expect: bool,
    /// Without `gate`: the level configurations and whether ICP and Scan Context run (`levels`, `icp`,
    /// `scan_context`), laps
    /// override (`laps`); progress goes to `progress` (one step per seed).
    pub experiment: ExperimentOptions,
    /// The command line, for the report's provenance. Default empty.
    pub command_line: Vec<String>,
}

/// A scenario as planned: loaded (or why not), its seeds and what to run.
struct Planned {
    file: String,
    scenario: Result<Scenario, String>,
    seeds: SeedRange,
    /// `None`: nothing to run (no `[expect]`, allowed).
    options: Option<ExperimentOptions>,
}

/// A subject `scn`'s `[expect]` names that neither it (`[[subjects]]`) nor `opts` runs (an
/// external one not given).
fn unrun_subject(scn: &Scenario, opts: &ExperimentOptions) -> Option<String> {
    scn.expect
        .subjects
        .iter()
        .map(|e| &e.subject)
        .find(|name| {
            !crate::spec::evaluation::KNOWN_SUBJECTS.contains(&name.as_str())
                && !opts.external.iter().any(|x| &x.name == *name)
                && !scn.subjects.iter().any(|x| &x.name == *name)
        })
        .cloned()
}

/// Loads and plans every scenario of `paths`.
fn plan(paths: &[PathBuf], opts: &StressOptions) -> Vec<Planned> {
    paths
        .iter()
        .map(|path| {
            let file = path.display().to_string();
            let scenario = load_planned(path, opts);
            let (seeds, options) = match &scenario {
                Ok(scn) => (
                    opts.seeds
                        .or(scn.seeds)
                        .unwrap_or(SeedRange::one(scn.sim.seed)),
                    options_for(scn, opts),
                ),
                Err(_) => (opts.seeds.unwrap_or(SeedRange::one(0)), None),
            };
            let scenario = match (scenario, &options) {
                (Ok(_), None) if opts.gate && !opts.allow_no_expect => Err(format!(
                    "{file}: no [expect] block, so `check` would test nothing; add \
                     [[expect.subjects]] bounds, or pass --allow-no-expect to skip it"
                )),
                (Ok(scn), Some(o)) => match unrun_subject(&scn, o) {
                    Some(name) => Err(format!(
                        "{file}: [expect] names subject `{name}`, which is neither built in \
                     ({}) nor declared in [[subjects]] nor given with --recognizer \
                     {name}=exec:COMMAND",
                        crate::spec::evaluation::KNOWN_SUBJECTS.join(", ")
                    )),
                    None => Ok(scn),
                },
                (s, _) => s,
            };
            Planned {
                file,
                scenario,
                seeds,
                options,
            }
        })
        .collect()
}

/// Loads the scenario at `path` for the work `opts` implies: its laps (`--laps`) and one
/// back-end pass per level configuration it runs, and Scan Context's observations when it runs
/// (known once the file is read, so a file running more is read again with them counted).
fn load_planned(path: &Path, opts: &StressOptions) -> Result<Scenario, String> {
    let mut work = Workload {
        laps: opts.experiment.laps,
        ..Workload::default()
    };
    let src = read_text(path).map_err(|e| e.to_string())?;
    let scn = parse_scenario_for(&src, path, &load_world_for, &work).map_err(|e| e.to_string())?;
    let Some(o) = options_for(&scn, opts) else {
        return Ok(scn);
    };
    if o.levels.len() <= 1 && !o.scan_context {
        return Ok(scn);
    }
    work.passes = o.levels.len().max(1);
    work.scan_context = o.scan_context;
    // The passes are known only from the parsed file: the budget counts them in a second
    // parse of the same text, over the world already read and checked (not read again).
    let world = scn.sim.world.clone();
    let loaded: WorldLoader = &|_, _| Ok(world.clone());
    parse_scenario_for(&src, path, loaded, &work).map_err(|e| e.to_string())
}

/// The configurations to run for `scn`: the `[expect]` block's under `gate`, else the options'.
fn options_for(scn: &Scenario, opts: &StressOptions) -> Option<ExperimentOptions> {
    if !opts.gate {
        return Some(opts.experiment.clone());
    }
    if scn.expect.is_empty() {
        return None;
    }
    Some(ExperimentOptions {
        levels: scn.expect.word_levels(),
        icp: scn.expect.names("icp"),
        scan_context: scn.expect.names("scan-context"),
        external: opts.experiment.external.clone(),
        ..opts.experiment.clone()
    })
}

/// Runs every scenario of `paths` over its seeds (or this shard's share of them).
pub fn run_stress(paths: &[PathBuf], opts: &StressOptions) -> SuiteReport {
    let started = Instant::now();
    let planned = plan(paths, opts);
    let mut items: Vec<(usize, u64)> = Vec::new();
    for (i, p) in planned.iter().enumerate() {
        if p.scenario.is_ok() && p.options.is_some() {
            items.extend(p.seeds.seeds().map(|seed| (i, seed)));
        }
    }
    let items: Vec<(usize, u64)> = items
        .into_iter()
        .enumerate()
        .filter(|(k, _)| opts.shard.is_none_or(|s| s.owns(*k)))
        .map(|(_, item)| item)
        .collect();
    let progress = &opts.experiment.progress;
    progress.start("seeds", items.len() as u64);
    let runnable = |i: usize| match (&planned[i].scenario, &planned[i].options) {
        (Ok(scn), Some(options)) => (scn, options),
        _ => unreachable!("only runnable scenarios are planned"),
    };
    let results: Vec<SeedResult> = run_bounded(
        &items,
        &|&(i, _)| {
            let (scn, options) = runnable(i);
            seed_memory_mb(scn, options)
        },
        SEEDS_IN_FLIGHT_MB,
        &|&(i, seed)| {
            let (scn, options) = runnable(i);
            let r = run_seed(scn, seed, options);
            progress.step();
            r
        },
    );
    progress.done();
    let mut prov = Provenance::new(opts.command_line.clone());
    for p in &planned {
        match &p.scenario {
            Ok(scn) => prov.add_inputs(provenance::scenario_inputs(
                &scn.sim,
                &scn.recognizer,
                &scn.evaluation,
                &scn.expect,
            )),
            Err(_) => prov.add_inputs([provenance::file_input("scenario", Path::new(&p.file))]),
        }
    }
    prov.add_seeds(results.iter().map(|r| r.seed));
    prov.lap_cache = opts.experiment.cache.as_ref().map(|c| c.used());
    let mut suite = SuiteReport::new(opts.shard, opts.gate, assemble(planned, items, results));
    suite.provenance = prov;
    suite.wall_seconds = started.elapsed().as_secs_f64();
    suite
}

/// Memory the seeds in flight may be estimated to hold together, MB ([`seed_memory_mb`]): with
/// the process's own and the finished seeds' reports, the peak of `check scenarios/*.toml`
/// stays under 1.5 GB.
const SEEDS_IN_FLIGHT_MB: f64 = 900.0;

/// What one seed of `scn` is estimated to hold at its peak, MB. A seed is run streamed
/// ([`run_seed`]): at most a few laps of scans, plus per lap and per subject the truth, the
/// recognizer's words and the pairs the scoring keeps (about 0.3 MB per lap for one subject of
/// the 1000-lap scenario, BENCHMARKS.md), plus a fixed part (world, grids, buffers).
pub fn seed_memory_mb(scn: &Scenario, options: &ExperimentOptions) -> f64 {
    let laps: usize = scn
        .sim
        .runs
        .iter()
        .map(|r| options.laps.unwrap_or(r.laps))
        .sum();
    let subjects = options.levels.len()
        + usize::from(options.icp)
        + usize::from(options.scan_context)
        + options.external.len();
    40.0 + 0.4 * (laps * subjects.max(1)) as f64
}

/// Runs `work` on every item, as many at once as there are cores, but no more than the memory
/// `budget_mb` admits by `estimate_mb` (an item that alone exceeds it runs alone); results in
/// item order. Items go to threads of their own rather than to rayon's tasks: a rayon task that
/// waits for the parallel part of its own work steals the next item, so seeds in flight would
/// not be bounded by the cores (each holding its laps); the work inside an item still runs on
/// rayon's pool, so the cores stay busy.
fn run_bounded<T: Sync, R: Send>(
    items: &[T],
    estimate_mb: &(dyn Fn(&T) -> f64 + Sync),
    budget_mb: f64,
    work: &(dyn Fn(&T) -> R + Sync),
) -> Vec<R> {
    use std::sync::{Condvar, Mutex};
    struct State {
        next: usize,
        running: usize,
        held_mb: f64,
    }
    let state = Mutex::new(State {
        next: 0,
        running: 0,
        held_mb: 0.0,
    });
    let freed = Condvar::new();
    let results: Mutex<Vec<Option<R>>> = Mutex::new(items.iter().map(|_| None).collect());
    let workers = rayon::current_num_threads().clamp(1, items.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let mut st = state.lock().expect("no worker panics holding the lock");
                    let (k, need) = loop {
                        let Some(item) = items.get(st.next) else {
                            return;
                        };
                        let need = estimate_mb(item);
                        if st.running == 0 || st.held_mb + need <= budget_mb {
                            break (st.next, need);
                        }
                        st = freed.wait(st).expect("no worker panics holding the lock");
                    };
                    st.next += 1;
                    st.running += 1;
                    st.held_mb += need;
                    drop(st);
                    let r = work(&items[k]);
                    results.lock().expect("no worker panics holding the lock")[k] = Some(r);
                    let mut st = state.lock().expect("no worker panics holding the lock");
                    st.running -= 1;
                    st.held_mb -= need;
                    freed.notify_all();
                }
            });
        }
    });
    results
        .into_inner()
        .expect("no worker panics holding the lock")
        .into_iter()
        .map(|r| r.expect("every item ran"))
        .collect()
}

/// Runs `scn` at `seed`, timing it. The laps are streamed to the recognizers and scored as
/// they come ([`super::run_scenario_streamed`], the same report as holding them): a seed holds
/// a few laps of scans, not all of them.
pub fn run_seed(scn: &Scenario, seed: u64, options: &ExperimentOptions) -> SeedResult {
    let t = Instant::now();
    let mut scn = scn.clone();
    scn.sim.seed = seed;
    let options = ExperimentOptions {
        progress: ProgressSink::none(),
        ..options.clone()
    };
    let (report, error, lap_cache) = match super::run_scenario_streamed(&scn, &options) {
        Ok(exp) => (Some(exp.report), None, exp.lap_source),
        Err(e) => (None, Some(e.to_string()), None),
    };
    SeedResult {
        seed,
        seconds: t.elapsed().as_secs_f64(),
        report,
        error,
        simulation_key: provenance::simulation_key(&scn.sim, options.laps),
        lap_cache,
    }
}

/// One [`ScenarioResult`] per planned scenario, holding its items' results.
fn assemble(
    planned: Vec<Planned>,
    items: Vec<(usize, u64)>,
    results: Vec<SeedResult>,
) -> Vec<ScenarioResult> {
    let names: Vec<(String, String)> = planned
        .iter()
        .map(|p| {
            let name = match &p.scenario {
                Ok(s) => s.sim.name.clone(),
                Err(_) => stem(&p.file),
            };
            (name, p.file.clone())
        })
        .collect();
    let labels = labels(&names);
    let mut out: Vec<ScenarioResult> = planned
        .into_iter()
        .zip(names.into_iter().zip(labels))
        .map(|(p, ((name, file), label))| ScenarioResult {
            label,
            name,
            file,
            seeds: p.seeds,
            reproduce_flags: p.options.as_ref().map(flags_of).unwrap_or_default(),
            expect: p
                .scenario
                .as_ref()
                .map(|s| s.expect.clone())
                .unwrap_or_default(),
            error: p.scenario.err(),
            results: Vec::new(),
            summary: Vec::new(),
            outcomes: Vec::new(),
        })
        .collect();
    for ((i, _), r) in items.into_iter().zip(results) {
        out[i].results.push(r);
    }
    out
}

/// What a command reproducing a seed run with `o` needs besides the file and seed: the
/// baselines it ran and the external subjects a flag gave (`eval::suite::reproduce_command`).
fn flags_of(o: &ExperimentOptions) -> String {
    let baselines = [(o.icp, "--icp"), (o.scan_context, "--scan-context")]
        .into_iter()
        .filter(|&(on, _)| on)
        .map(|(_, flag)| flag.to_string());
    let external = crate::external::reproduce_flags(&o.external);
    baselines
        .chain((!external.is_empty()).then_some(external))
        .collect::<Vec<_>>()
        .join(" ")
}

fn stem(file: &str) -> String {
    std::path::Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| file.to_string())
}

/// Why parts could not be read and merged, or outputs written.
#[derive(Debug, thiserror::Error)]
pub enum StressError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Parse(crate::spec::diag::Diagnostic),
    #[error(transparent)]
    Merge(#[from] crate::eval::suite::MergeError),
    #[error("{path}: cannot write: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
    #[error(transparent)]
    Output(#[from] crate::io::atomic::StageError),
    #[error(transparent)]
    Compare(#[from] crate::eval::compare::CompareError),
}

/// Reads a suite report (`check --report`, `check -o DIR`'s `report.json`, a part, a merge),
/// `what` saying in the error what the file should have been.
pub fn read_suite(path: &Path, what: &str) -> Result<SuiteReport, StressError> {
    let file = path.display().to_string();
    // An output set (`check --report`, `-o DIR`) a kill interrupted after its commit is
    // finished first.
    crate::io::atomic::settle(path);
    let parent = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = parent.filter(|_| path.ends_with(DIR_FILES[0])) {
        crate::io::atomic::settle(dir);
    }
    // Invalid UTF-8 is located at its first bad byte, as in every text file.
    let text = crate::spec::diag::read_text(path).map_err(|e| match e {
        crate::spec::SpecError::Io { source, .. } => StressError::Read {
            path: file.clone(),
            source,
        },
        crate::spec::SpecError::Invalid(d) => StressError::Parse(
            d.into_iter()
                .next()
                .unwrap_or_else(|| crate::spec::diag::Diagnostic::error(&file, (1, 1), "not text")),
        ),
    })?;
    let located = |at: (usize, usize), msg: String| {
        StressError::Parse(crate::spec::diag::Diagnostic::error(&file, at, msg))
    };
    let suite = SuiteReport::from_json(&text).map_err(|e| {
        StressError::Parse(crate::spec::diag::json_diagnostic(
            &file,
            &e,
            &format!("not {what}"),
        ))
    })?;
    if suite.format != crate::eval::suite::FORMAT {
        return Err(located(
            (1, 1),
            format!(
                "not {what}: its format is `{}`, not `{}`",
                suite.format,
                crate::eval::suite::FORMAT
            ),
        ));
    }
    Ok(suite)
}

/// What a baseline file must be, for messages.
const BASELINE: &str = "a report of `placewords check` (`--report FILE` or `-o DIR`'s report.json)";

/// Reads a baseline report (`check --baseline`, `compare`).
pub fn read_baseline(path: &Path) -> Result<SuiteReport, StressError> {
    read_suite(path, BASELINE)
}

/// Compares the run `new` (`new_name` in messages) with the baseline `base` read from
/// `base_path`.
pub fn compare_with(
    base_path: &Path,
    base: &SuiteReport,
    new_name: &str,
    new: &SuiteReport,
    overrides: crate::eval::compare::ToleranceOverride,
) -> Result<crate::eval::compare::Comparison, StressError> {
    let base_name = base_path.display().to_string();
    Ok(crate::eval::compare::compare(
        &base_name, base, new_name, new, overrides,
    )?)
}

/// Compares two report files (`placewords compare BASE NEW`).
pub fn compare_files(
    base: &Path,
    new: &Path,
    overrides: crate::eval::compare::ToleranceOverride,
) -> Result<crate::eval::compare::Comparison, StressError> {
    let b = read_baseline(base)?;
    let n = read_suite(new, BASELINE)?;
    compare_with(base, &b, &new.display().to_string(), &n, overrides)
}

/// Reads the parts at `paths` and merges them into the whole run's report; its provenance is
/// the parts' (build, inputs, seeds) with `command_line` and every part file's hash.
pub fn merge_files(
    paths: &[PathBuf],
    command_line: Vec<String>,
) -> Result<SuiteReport, StressError> {
    let mut parts = Vec::new();
    for path in paths {
        let part = read_suite(path, "a part written by `check --shard K/N --report`")?;
        parts.push((path.display().to_string(), part));
    }
    let mut whole = crate::eval::suite::merge(parts)?;
    whole.provenance.command_line = command_line;
    whole
        .provenance
        .add_inputs(paths.iter().map(|p| provenance::file_input("part", p)));
    Ok(whole)
}

/// Writes `file` atomically, naming it in the error.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), StressError> {
    crate::io::atomic::write_atomic(path, bytes).map_err(|source| StressError::Write {
        path: path.display().to_string(),
        source,
    })
}

/// GitHub Actions `::error` annotations for the run's missed bounds (on each scenario's
/// `[expect]` line, read from the file again) and failed runs.
pub fn github_annotations(suite: &SuiteReport) -> Vec<String> {
    crate::report::suite::github_annotations(suite, |file| {
        let src = std::fs::read_to_string(file).ok()?;
        crate::spec::scenario::expect_line(&src)
    })
}

/// Appends Markdown `md` to GitHub's step summary file at `path`.
pub fn append_markdown(md: &str, path: &Path) -> Result<(), StressError> {
    use std::io::Write;
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .and_then(|mut f| f.write_all(format!("{md}\n").as_bytes()))
        .map_err(|source| StressError::Write {
            path: path.display().to_string(),
            source,
        })
}

/// The files [`write_dir_files`] writes.
pub const DIR_FILES: [&str; 3] = ["report.json", "table.md", "junit.xml"];

/// Whether folder `dir` is an earlier output of [`write_dir_files`] (only its files, and hidden
/// ones), which a new output may replace whole.
pub fn is_check_output(dir: &Path) -> bool {
    holds_only(dir, &|n| DIR_FILES.contains(&n))
}

/// Writes `report.json` (the whole report), `table.md` and `junit.xml` into folder `at` (the
/// staging folder of the output, put in place whole by the caller: `crate::io::atomic`), with
/// a comparison with a baseline if given: its Markdown section follows the table in
/// `table.md`, its test cases follow the gate's in `junit.xml`.
pub fn write_dir_files(
    suite: &SuiteReport,
    baseline: Option<&crate::eval::compare::Comparison>,
    at: &Path,
) -> Result<(), StressError> {
    use crate::report::{junit, suite as format};
    write_file(&at.join(DIR_FILES[0]), suite.to_json().as_bytes())?;
    let mut md = format::markdown(suite);
    if let Some(c) = baseline {
        md.push('\n');
        md.push_str(&crate::report::compare::markdown(c));
    }
    write_file(&at.join(DIR_FILES[1]), md.as_bytes())?;
    let xml = junit::document_with(suite, baseline);
    write_file(&at.join(DIR_FILES[2]), xml.as_bytes())
}
