//! `placewords run SCENARIO`: simulate, recognize at 1, 2 and 3 levels, evaluate, report; over
//! a range of seeds with `--seeds A..B` (mean and worst per configuration).

use super::common::{ExperimentOutputs, ExternalArg, LevelsArg, SeedsArg, write_file};
use clap::Args;
use placewords::clock::Stopwatch;
use placewords::experiment::stress::{self, StressOptions};
use placewords::experiment::{self, ExperimentOptions};
use placewords::report::profile::profile_text;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub levels: LevelsArg,
    #[command(flatten)]
    pub seeds: SeedsArg,
    #[command(flatten)]
    pub external: ExternalArg,
    #[command(flatten)]
    pub cache: super::common::CacheArg,
    /// Also run the ICP baseline (slow: every region is aligned with every past region).
    #[arg(long)]
    pub icp: bool,
    /// Also run the Scan Context baseline (settings: the scenario's `[scan_context]` table),
    /// e.g. `placewords run scenarios/A.toml --scan-context --seeds 1..5`.
    #[arg(long)]
    pub scan_context: bool,
    /// Replace every run's lap count (for a quick look).
    #[arg(long, value_name = "N", value_parser = super::scenario::laps_flag)]
    pub laps: Option<usize>,
    /// Write the JSON report here (schema in the README; with --seeds, every seed's report and
    /// the figures over seeds).
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write pictures here: the true and odometry paths; per level configuration, the true path
    /// coloured where revisits were recognized, wrong or missed, and recall and precision per lap.
    /// One seed only.
    #[arg(long, value_name = "DIR", conflicts_with = "seeds")]
    pub svg: Option<PathBuf>,
    /// Write the matched scan pairs of the last level configuration run (`--levels N`) as a
    /// matches file for `placewords score` (docs/scoring.md). One seed only.
    #[arg(long, value_name = "FILE", conflicts_with = "seeds")]
    pub export_matches: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print where the time went on stderr: CPU seconds per stage (simulate, recognize and
    /// score per subject) and the wall clock of writing the outputs.
    #[arg(long)]
    pub profile: bool,
}

pub fn run(args: RunArgs) -> anyhow::Result<ExitCode> {
    // With --seeds only the report is written (pictures and matches are of one seed).
    if args.seeds.seeds.is_some() {
        super::common::check_outputs([args.report.as_deref()])?;
    }
    let outputs = match args.seeds.seeds {
        Some(_) => None,
        None => Some(ExperimentOutputs::begin(
            args.report.as_deref(),
            args.export_matches.as_deref(),
            args.svg.as_deref(),
        )?),
    };
    let opts = ExperimentOptions {
        levels: args.levels.levels(),
        icp: args.icp,
        scan_context: args.scan_context,
        scan_context_config: Default::default(),
        external: args.external.specs(),
        laps: args.laps,
        progress: super::progress::bar(args.quiet),
        cache: args.cache.open()?,
    };
    let cache = opts.cache.clone();
    if let Some(seeds) = args.seeds.seeds {
        let stress_opts = StressOptions {
            seeds: Some(seeds),
            experiment: opts,
            command_line: super::common::command_line(),
            ..StressOptions::default()
        };
        let suite = stress::run_stress(std::slice::from_ref(&args.scenario), &stress_opts);
        super::common::report_cache(cache.as_deref());
        let w = Stopwatch::start();
        out!("{}", placewords::report::suite::text_table(&suite))?;
        if let Some(path) = &args.report {
            write_file(path, suite.to_json().as_bytes())?;
            errln!("report: {}", path.display());
        }
        if args.profile {
            eprint!("{}", profile_text(suite.reports(), w.wall_s()));
        }
        let errors: Vec<String> = suite.scenarios.iter().flat_map(|s| s.errors()).collect();
        if !errors.is_empty() {
            errors.iter().for_each(|e| errln!("error: {e}"));
            return Ok(ExitCode::from(placewords::eval::gate::EXIT_ERROR));
        }
        return Ok(ExitCode::SUCCESS);
    }
    // The work budget counts `--laps` and the level configurations this run makes.
    let work = placewords::experiment::Workload {
        laps: args.laps,
        passes: opts.levels.len(),
        scan_context: opts.scan_context,
    };
    let mut scn = placewords::experiment::load_scenario_for(&args.scenario, &work)?;
    if let Some(seed) = args.seeds.seed {
        scn.sim.seed = seed;
    }
    // Without pictures or exported matches nothing needs the scans afterwards: stream the laps.
    let exp = if args.svg.is_none() && args.export_matches.is_none() {
        experiment::run_scenario_streamed(&scn, &opts)?
    } else {
        experiment::run_scenario(&scn, &opts)?
    };
    let w = Stopwatch::start();
    super::common::report_cache(cache.as_deref());
    let mut provenance =
        experiment::scenario_provenance(&[&scn], args.laps, super::common::command_line());
    provenance.lap_cache = cache.map(|c| c.used());
    outputs
        .expect("begun for one seed")
        .print_and_write(&exp, &scn.sim.world, &provenance)?;
    if args.profile {
        eprint!("{}", profile_text([&exp.report], w.wall_s()));
    }
    Ok(ExitCode::SUCCESS)
}
