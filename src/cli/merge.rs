//! `placewords merge PART.json... -o DIR`: joins the parts of a sharded `check` into the
//! report, table and JUnit file the unsharded run would have written, and exits as it would
//! have (0 all pass, 1 any missed, 2 error or a missing part).

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The parts, written by `check --shard K/N --report PART.json` (every K of one N).
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Write DIR/report.json, DIR/table.md and DIR/junit.xml.
    #[arg(long, short, value_name = "DIR", required = true)]
    pub out: PathBuf,
    /// Print a JSON summary on stdout instead of the tables and lines.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub baseline: super::common::BaselineArg,
}

pub fn run(args: MergeArgs) -> anyhow::Result<ExitCode> {
    let outputs = super::check::CheckOutputs::begin(None, None, Some(&args.out))?;
    let baseline = super::check::read_baseline(&args.baseline)?;
    let suite =
        placewords::experiment::stress::merge_files(&args.parts, super::common::command_line())?;
    super::check::finish(
        &suite,
        outputs,
        args.json,
        baseline
            .as_ref()
            .map(|(p, b)| (p.as_path(), b, &args.baseline.tolerance)),
    )
}
