//! `placewords scenario check FILE...`: every problem of every scenario file (and of the worlds
//! they name), without running anything; exit 2 on any.

use clap::{Args, Subcommand};
use placewords::spec::diag::MessageFormat;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Subcommand)]
pub enum ScenarioCommand {
    /// Check scenario files; every problem is printed as file:line:col on stderr (exit 2).
    #[command(after_help = "Example:\n  placewords scenario check scenarios/*.toml")]
    Check(CheckArgs),
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario files (TOML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[command(flatten)]
    pub format: super::MessageFormatArg,
}

pub fn run(cmd: ScenarioCommand) -> anyhow::Result<ExitCode> {
    let ScenarioCommand::Check(args) = cmd;
    let format = MessageFormat::from_name(&args.format.message_format).unwrap_or_default();
    let mut failed = false;
    for f in &args.files {
        match placewords::experiment::check_scenario(f) {
            Ok(s) if format == MessageFormat::Human => outln!(
                "{}: ok ({} runs, world {})",
                f.display(),
                s.sim.runs.len(),
                s.sim.world.name
            )?,
            Ok(_) => {}
            Err(e) => {
                failed = true;
                super::print_problems(&e, format)?;
            }
        }
    }
    Ok(if failed {
        ExitCode::from(placewords::eval::gate::EXIT_ERROR)
    } else {
        ExitCode::SUCCESS
    })
}

/// `--laps N`: the same limit as `laps` in a file.
pub fn laps_flag(s: &str) -> Result<usize, String> {
    placewords::spec::scenario::check_laps(whole_number(s)?)
}

/// `simulate --laps N`: any count from 1 to `MAX_STREAMED_LAPS` (laps are written as made).
pub fn streamed_laps_flag(s: &str) -> Result<usize, String> {
    placewords::spec::scenario::check_streamed_laps(whole_number(s)?)
}

/// A whole number, one too large for `i64` read as `i64::MAX` (far too many, not garbage).
fn whole_number(s: &str) -> Result<i64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) => Ok(i64::try_from(n).unwrap_or(i64::MAX)),
        Err(_) => s
            .trim()
            .parse()
            .map_err(|_| format!("`{s}` is not a whole number")),
    }
}
