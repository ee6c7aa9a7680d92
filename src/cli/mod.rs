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
pub mod compare;
pub mod import;
pub mod merge;
pub mod motion;
pub mod out;
pub mod progress;
pub mod recognize;
pub mod run;
pub mod scenario;
pub mod schema;
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
    /// Check, render, describe, import and generate world layouts; density and ambiguity maps.
    #[command(subcommand)]
    World(world::WorldCommand),
    /// Check scenario files without running them.
    #[command(subcommand)]
    Scenario(scenario::ScenarioCommand),
    /// Drive the simulated robot through a scenario and write CARMEN logs.
    #[command(after_help = "Example:\n  placewords simulate scenarios/smoke.toml -o logs/ --svg")]
    Simulate(simulate::SimulateArgs),
    /// Simulate a scenario, recognize places at 1, 2 and 3 levels, evaluate and report.
    #[command(
        after_help = "Example:\n  placewords run scenarios/A.toml --report a.json --svg pics/\n  placewords run scenarios/B.toml --laps 2 --levels 3   # a quick look"
    )]
    Run(run::RunArgs),
    /// Run scenarios and compare them with their [expect] blocks (the CI gate).
    #[command(
        after_help = "Example:\n  placewords check scenarios/*.toml --junit junit.xml\n  placewords check scenarios/smoke.toml --seed 1   # one seed"
    )]
    Check(check::CheckArgs),
    /// Join the parts of a sharded `check` into one report, table and JUnit file.
    #[command(
        after_help = "Example:\n  placewords check scenarios/B.toml --shard 1/2 --report part-1.json\n  placewords check scenarios/B.toml --shard 2/2 --report part-2.json\n  placewords merge part-1.json part-2.json -o gate/"
    )]
    Merge(merge::MergeArgs),
    /// Compare two reports of `check` (a baseline and a new run), paired by seed: exit 1 on a
    /// regression beyond [expect.regression].
    #[command(
        after_help = "Example:\n  placewords check scenarios/B.toml --report main.json   # on main\n  placewords check scenarios/B.toml --report pr.json     # on the branch\n  placewords compare main.json pr.json --markdown moved.md\n  placewords check scenarios/B.toml --baseline main.json   # the same in one step"
    )]
    Compare(compare::CompareArgs),
    /// The paper's Table I for one or more scenarios, as Markdown and JSON.
    #[command(
        after_help = "Example:\n  placewords table scenarios/A.toml scenarios/B.toml scenarios/C.toml -o table/\n  placewords table scenarios/A.toml -o table/ --laps 1 --no-icp   # a quick look (Scan Context stays; --no-scan-context drops it)"
    )]
    Table(table::TableArgs),
    /// The paper's Fig. 8: precision/recall over the n-gram thresholds.
    #[command(after_help = "Example:\n  placewords sweep scenarios/B.toml -o sweep/ --laps 2")]
    Sweep(sweep::SweepArgs),
    /// How a robot weaves along its route: speed, heading against the corridor, weave, turns on
    /// the spot and their spectrum, on real logs and simulated laps, with KS distances.
    #[command(
        after_help = "Example:\n  placewords motion ../shared/data/carmen/intel-corrected.log.gz scenarios/A.toml --laps 2"
    )]
    Motion(motion::MotionArgs),
    /// Recognize places in a real CARMEN log and evaluate against its corrected poses.
    #[command(
        after_help = "Example:\n  placewords recognize ../shared/data/carmen/intel-corrected.log.gz --report r.json\n  placewords recognize LOG --scan-step 2 --config docs/recognizer.toml --seed 3"
    )]
    Recognize(recognize::RecognizeArgs),
    /// Score any recognizer's matches file against the logs `simulate` wrote.
    #[command(
        after_help = "Example:\n  placewords simulate scenarios/smoke.toml -o logs/\n  placewords run scenarios/smoke.toml --export-matches m.csv\n  placewords score logs/ --matches m.csv --report s.json"
    )]
    Score(score::ScoreArgs),
    /// Print the JSON Schema (draft-07) of a world or scenario file, for editors (docs/editors.md).
    #[command(
        after_help = "Example:\n  placewords schema world\n  placewords schema scenario -o scenario.schema.json\n  # then start a TOML file with:  #:schema ./scenario.schema.json"
    )]
    Schema(schema::SchemaArgs),
}

pub fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::World(c) => world::run(c),
        Command::Scenario(c) => scenario::run(c),
        Command::Simulate(a) => simulate::run(a),
        Command::Run(a) => run::run(a),
        Command::Check(a) => check::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Table(a) => table::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Motion(a) => motion::run(a),
        Command::Recognize(a) => recognize::run(a),
        Command::Score(a) => score::run(a),
        Command::Schema(a) => schema::run(a),
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
