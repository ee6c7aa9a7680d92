//! `placewords compare BASE.json NEW.json`: two reports of `check` compared, paired by seed
//! when their simulation keys agree; exit 0 no regression, 1 a regression, 2 an error.

use super::common::ToleranceArg;
use clap::Args;
use placewords::experiment::stress;
use placewords::report::compare as format;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The baseline report (`check --report` or `-o DIR`'s report.json), e.g. main's.
    pub base: PathBuf,
    /// The new report, made the same way.
    pub new: PathBuf,
    #[command(flatten)]
    pub tolerance: ToleranceArg,
    /// Also write a JUnit XML file (one test case per compared metric).
    #[arg(long, value_name = "OUT.xml")]
    pub junit: Option<PathBuf>,
    /// Also write the Markdown table of what moved (for a pull-request comment).
    #[arg(long, value_name = "OUT.md")]
    pub markdown: Option<PathBuf>,
    /// Print the comparison as JSON on stdout instead of the lines.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: CompareArgs) -> anyhow::Result<ExitCode> {
    super::common::check_outputs([args.junit.as_deref(), args.markdown.as_deref()])?;
    let c = stress::compare_files(&args.base, &args.new, args.tolerance.overrides())?;
    if let Some(path) = &args.junit {
        stress::write_file(path, format::junit_document(&c).as_bytes())?;
    }
    if let Some(path) = &args.markdown {
        stress::write_file(path, format::markdown(&c).as_bytes())?;
    }
    if args.json {
        outln!("{}", format::json(&c))?;
    } else {
        out!("{}", format::text(&c))?;
    }
    super::check::step_summary(&format::markdown(&c))?;
    Ok(ExitCode::from(c.exit_code()))
}
