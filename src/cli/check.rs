//! `placewords check SCENARIO...`: the CI gate. Runs each scenario over its seeds and compares
//! the worst seed (or the `[expect]` quantile) with its `[expect]` block; one PASS/FAIL line per
//! bound, then `N passed, M failed`; exit 0 all pass, 1 any missed, 2 error. With `--shard K/N`
//! it runs one part of the work and writes it for `merge`.

use super::common::{BaselineArg, SeedsArg};
use anyhow::Context;
use clap::Args;
use placewords::eval::suite::SuiteReport;
use placewords::experiment::ExperimentOptions;
use placewords::experiment::stress::{self, StressOptions};
use placewords::report::{compare as compare_format, junit, suite as format};
use placewords::spec::seeds::Shard;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario files (TOML) with an [expect] block.
    #[arg(required = true)]
    pub scenarios: Vec<PathBuf>,
    #[command(flatten)]
    pub seeds: SeedsArg,
    #[command(flatten)]
    pub external: super::common::ExternalArg,
    #[command(flatten)]
    pub cache: super::common::CacheArg,
    /// Replace every run's lap count (for a quick look: the bounds were set at the scenario's
    /// own laps, so fewer laps may miss them, exit 1).
    #[arg(long, value_name = "N", value_parser = super::scenario::laps_flag)]
    pub laps: Option<usize>,
    /// Run only part K of N of the (scenario × seed) work and write it with --report, for
    /// `placewords merge`. `auto`: K from JOB_COMPLETION_INDEX (Kubernetes Indexed Job, 0-based),
    /// N from --shard-count or PLACEWORDS_SHARD_COUNT.
    #[arg(long, value_name = "K/N|auto")]
    pub shard: Option<String>,
    /// The number of parts for `--shard auto` (default: PLACEWORDS_SHARD_COUNT).
    #[arg(long, value_name = "N")]
    pub shard_count: Option<usize>,
    /// Write the whole report (every seed's results, the figures, the gate) as JSON; with
    /// --shard, the part for `merge`.
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write DIR/report.json, DIR/table.md and DIR/junit.xml.
    #[arg(long, short, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also write a JUnit XML file (one testcase per bound).
    #[arg(long, value_name = "OUT.xml")]
    pub junit: Option<PathBuf>,
    /// Print a JSON summary on stdout instead of the tables and lines.
    #[arg(long)]
    pub json: bool,
    /// Skip a scenario without [expect] instead of failing (exit 2) on it.
    #[arg(long)]
    pub allow_no_expect: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub baseline: BaselineArg,
    /// Print where the time went on stderr: CPU seconds per stage over every scenario and seed
    /// (simulate, recognize and score per subject) and the wall clock of writing the outputs.
    #[arg(long)]
    pub profile: bool,
}

pub fn run(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let shard = match args.shard.as_deref() {
        None => None,
        Some("auto") => Some(Shard::from_env(args.shard_count).map_err(anyhow::Error::msg)?),
        Some(s) => Some(s.parse::<Shard>().map_err(anyhow::Error::msg)?),
    };
    if shard.is_some() && args.report.is_none() {
        anyhow::bail!("--shard writes a part for `merge`; add --report PART.json");
    }
    if shard.is_some() && args.baseline.baseline.is_some() {
        anyhow::bail!(
            "a part (--shard) has no verdict to compare; give --baseline to `merge` instead"
        );
    }
    // Read now, so a bad baseline is refused before the work rather than after it.
    let baseline = read_baseline(&args.baseline)?;
    // Begun now, so another output there or a live writer is refused before the work.
    let outputs = CheckOutputs::begin(
        args.report.as_deref(),
        args.junit.as_deref(),
        args.out.as_deref(),
    )?;
    let opts = StressOptions {
        seeds: args.seeds.range(),
        shard,
        gate: true,
        allow_no_expect: args.allow_no_expect,
        experiment: ExperimentOptions {
            progress: super::progress::bar(args.quiet),
            external: args.external.specs(),
            laps: args.laps,
            cache: args.cache.open()?,
            ..ExperimentOptions::default()
        },
        command_line: super::common::command_line(),
    };
    let suite = stress::run_stress(&args.scenarios, &opts);
    super::common::report_cache(opts.experiment.cache.as_deref());
    let w = placewords::clock::Stopwatch::start();
    let code = finish(
        &suite,
        outputs,
        args.json,
        baseline
            .as_ref()
            .map(|(p, b)| (p.as_path(), b, &args.baseline.tolerance)),
    );
    if args.profile {
        eprint!(
            "{}",
            placewords::report::profile::profile_text(suite.reports(), w.wall_s())
        );
    }
    code
}

/// The baseline of `--baseline`, read, with its path.
pub fn read_baseline(arg: &BaselineArg) -> anyhow::Result<Option<(PathBuf, SuiteReport)>> {
    match &arg.baseline {
        None => Ok(None),
        Some(p) => Ok(Some((p.clone(), stress::read_baseline(p)?))),
    }
}

/// Whether the process runs under GitHub Actions.
fn github_actions() -> bool {
    std::env::var("GITHUB_ACTIONS").is_ok_and(|v| v == "true")
}

/// Appends `md` to `$GITHUB_STEP_SUMMARY` when running under GitHub Actions.
pub fn step_summary(md: &str) -> anyhow::Result<()> {
    let summary = std::env::var_os("GITHUB_STEP_SUMMARY").filter(|p| !p.is_empty());
    if let Some(path) = summary.filter(|_| github_actions()) {
        stress::append_markdown(md, Path::new(&path))?;
    }
    Ok(())
}

/// What `check` and `merge` write — `--report FILE`, `--junit FILE`, `-o DIR` — begun before
/// the work (a path another live process writes is refused then) and written as one
/// ([`placewords::io::atomic::OutputSet`]): a kill leaves the old outputs or the new ones.
pub struct CheckOutputs {
    set: placewords::io::atomic::OutputSet,
    report: Option<PathBuf>,
    junit: Option<PathBuf>,
    out: Option<PathBuf>,
}

impl CheckOutputs {
    /// Checks the paths and begins the set; `out` must be new, empty or an earlier output.
    pub fn begin(
        report: Option<&Path>,
        junit: Option<&Path>,
        out: Option<&Path>,
    ) -> anyhow::Result<CheckOutputs> {
        super::common::check_outputs([report, junit])?;
        let files: Vec<&Path> = [report, junit].into_iter().flatten().collect();
        let replaceable: &dyn Fn(&Path) -> bool = &stress::is_check_output;
        let folders: Vec<placewords::io::atomic::Replaced> =
            out.into_iter().map(|d| (d, replaceable)).collect();
        let set = placewords::io::atomic::OutputSet::begin(&files, &[], &folders)
            .map_err(stress::StressError::from)?;
        Ok(CheckOutputs {
            set,
            report: report.map(Path::to_path_buf),
            junit: junit.map(Path::to_path_buf),
            out: out.map(Path::to_path_buf),
        })
    }
}

/// Prints a stress run's verdict (and its comparison with a baseline, if given), writes the
/// outputs asked for, and gives the exit code (a part exits 0 unless something failed to run:
/// its seeds are not the distribution).
pub fn finish(
    suite: &SuiteReport,
    outputs: CheckOutputs,
    json: bool,
    baseline: Option<(&Path, &SuiteReport, &super::common::ToleranceArg)>,
) -> anyhow::Result<ExitCode> {
    let cmp = match baseline {
        Some((path, base, tol)) => Some(stress::compare_with(
            path,
            base,
            "this run",
            suite,
            tol.overrides(),
        )?),
        None => None,
    };
    let cmp = cmp.as_ref();
    let set = &outputs.set;
    let staged = |path: &Path, e: std::io::Error| {
        anyhow::Error::new(e).context(format!("{}: cannot write", path.display()))
    };
    if let Some(path) = &outputs.report {
        set.write(path, suite.to_json().as_bytes())
            .map_err(|e| staged(path, e))?;
    }
    if let Some(dir) = &outputs.out {
        let at = set.dir(dir).expect("begun with this folder");
        stress::write_dir_files(suite, cmp, at).with_context(|| "writing the outputs")?;
    }
    if let Some(path) = &outputs.junit {
        let xml = junit::document_with(suite, cmp);
        set.write(path, xml.as_bytes())
            .map_err(|e| staged(path, e))?;
    }
    outputs
        .set
        .commit()
        .with_context(|| "writing the outputs")?;
    for e in suite.scenarios.iter().flat_map(|s| s.errors()) {
        errln!("error: {e}");
    }
    let code = suite.exit_code();
    let code = match cmp {
        Some(c) if code != placewords::eval::gate::EXIT_ERROR => code.max(c.exit_code()),
        _ => code,
    };
    if json {
        let summary = format::summary_json(suite);
        match cmp {
            None => outln!("{summary}")?,
            Some(c) => {
                let mut v: serde_json::Value = serde_json::from_str(&summary)?;
                v["baseline"] = serde_json::from_str(&compare_format::json(c))?;
                v["exit_code"] = code.into();
                outln!("{}", serde_json::to_string_pretty(&v)?)?;
            }
        }
    } else {
        out!("{}", format::check_text(suite))?;
        if let Some(c) = cmp {
            out!("{}", compare_format::text(c))?;
        }
    }
    if github_actions() {
        // The runner reads workflow commands from stdout and stderr; keep --json's stdout JSON.
        let mut annotations = stress::github_annotations(suite);
        annotations.extend(
            cmp.map(compare_format::github_annotations)
                .unwrap_or_default(),
        );
        for a in annotations {
            if json {
                eprintln!("{a}");
            } else {
                outln!("{a}")?;
            }
        }
        // A part has no verdict to show: the merge writes the summary.
        if suite.shard.is_none() {
            let mut md = format::markdown(suite);
            if let Some(c) = cmp {
                md.push('\n');
                md.push_str(&compare_format::markdown(c));
            }
            step_summary(&md)?;
        }
    }
    Ok(ExitCode::from(code))
}
