//! Subcommands, one file each. Each file holds its clap arguments and a `run` that calls the
//! library and maps the outcome to an exit code.

/// `print!` that ends quietly on a closed stdout (see [`out`]); returns `std::io::Result<()>`.
macro_rules! out {
    ($($arg:tt)*) => { crate::cli::out::write(format_args!($($arg)*)) };
}

/// `println!` that ends quietly on a closed stdout (see [`out`]); returns `std::io::Result<()>`.
macro_rules! outln {
    ($($arg:tt)*) => { crate::cli::out::write(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `eprintln!` that never panics on a closed stderr (see [`out`]).
macro_rules! errln {
    ($($arg:tt)*) => { crate::cli::out::write_err(format_args!("{}\n", format_args!($($arg)*))) };
}

use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod check;
pub mod common;
pub mod import;
pub mod merge;
pub mod out;
pub mod progress;
pub mod recognize;
pub mod run;
pub mod scenario;
pub mod score;
pub mod simulate;
pub mod sweep;
pub mod table;
pub mod world;

/// Long-term place recognition with multi-level words of spatial densities, and the harness
/// that proves it.
#[derive(Debug, Parser)]
#[command(name = "placewords", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Check, render, describe and import world layouts.
    #[command(subcommand)]
    World(world::WorldCommand),
    /// Check scenario files without running them.
    #[command(subcommand)]
    Scenario(scenario::ScenarioCommand),
    /// Drive the simulated robot through a scenario and write CARMEN logs.
    Simulate(simulate::SimulateArgs),
    /// Simulate a scenario, recognize places at 1, 2 and 3 levels, evaluate and report.
    Run(run::RunArgs),
    /// Run scenarios and compare them with their [expect] blocks (the CI gate).
    Check(check::CheckArgs),
    /// Join the parts of a sharded `check` into one report, table and JUnit file.
    Merge(merge::MergeArgs),
    /// The paper's Table I for one or more scenarios, as Markdown and JSON.
    Table(table::TableArgs),
    /// The paper's Fig. 8: precision/recall over the n-gram thresholds.
    Sweep(sweep::SweepArgs),
    /// Recognize places in a real CARMEN log and evaluate against its corrected poses.
    Recognize(recognize::RecognizeArgs),
    /// Score any recognizer's matches file against the logs `simulate` wrote.
    Score(score::ScoreArgs),
}

pub fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::World(c) => world::run(c),
        Command::Scenario(c) => scenario::run(c),
        Command::Simulate(a) => simulate::run(a),
        Command::Run(a) => run::run(a),
        Command::Check(a) => check::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Table(a) => table::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Recognize(a) => recognize::run(a),
        Command::Score(a) => score::run(a),
    }
}

/// `--message-format`, shared by every command that checks files.
#[derive(Debug, clap::Args)]
pub struct MessageFormatArg {
    /// `human` (file:line:col: error: ...) or `json` (one object per problem, on stdout).
    #[arg(long, value_name = "FORMAT", default_value = "human", value_parser = ["human", "json"])]
    pub message_format: String,
}

/// Prints a file's problems: human form on stderr, JSON lines on stdout.
pub fn print_problems(
    e: &placewords::spec::SpecError,
    format: placewords::spec::diag::MessageFormat,
) -> std::io::Result<()> {
    for line in e.render(format) {
        match format {
            placewords::spec::diag::MessageFormat::Human => errln!("{line}"),
            placewords::spec::diag::MessageFormat::Json => outln!("{line}")?,
        }
    }
    Ok(())
}
