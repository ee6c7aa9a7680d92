//! `placewords run SCENARIO`: simulate, recognize at 1, 2 and 3 levels, evaluate, report.

use super::common::{LevelsArg, print_and_write};
use clap::Args;
use placewords::experiment::{self, ExperimentOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub levels: LevelsArg,
    /// Also run the ICP baseline (slow: every region is aligned with every past region).
    #[arg(long)]
    pub icp: bool,
    /// Replace every run's lap count (for a quick look).
    #[arg(long, value_name = "N", value_parser = super::scenario::laps_flag)]
    pub laps: Option<usize>,
    /// Write the JSON report here (schema in the README).
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write pictures here: the true and odometry paths; per level configuration, the true path
    /// coloured where revisits were recognized, wrong or missed, and recall and precision per lap.
    #[arg(long, value_name = "DIR")]
    pub svg: Option<PathBuf>,
    /// Replace the scenario's seed.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Write the matched scan pairs of the last level configuration run (`--levels N`) as a
    /// matches file for `placewords score` (docs/scoring.md).
    #[arg(long, value_name = "FILE")]
    pub export_matches: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: RunArgs) -> anyhow::Result<ExitCode> {
    let mut scn = placewords::experiment::load_scenario(&args.scenario)?;
    if let Some(seed) = args.seed {
        scn.sim.seed = seed;
    }
    let opts = ExperimentOptions {
        levels: args.levels.levels(),
        icp: args.icp,
        laps: args.laps,
        quiet: args.quiet,
    };
    let exp = experiment::run_scenario(&scn, &opts)?;
    if let (Some(path), Some((_, rec))) = (&args.export_matches, exp.recognitions.last()) {
        super::score::export(path, rec, &exp.runs)?;
    }
    print_and_write(
        &exp,
        &scn.sim.world,
        scn.evaluation.tp_radius_m,
        args.report.as_deref(),
        args.svg.as_deref(),
    )?;
    Ok(ExitCode::SUCCESS)
}
