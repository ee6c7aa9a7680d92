//! `placewords world ...`: check, render, info.

use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Subcommand)]
pub enum WorldCommand {
    /// Validate world files; every problem is printed as file:line:col.
    Check(CheckArgs),
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// World files (TOML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

pub fn run(cmd: WorldCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        WorldCommand::Check(a) => check(a),
    }
}

fn check(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let mut failed = false;
    for f in &args.files {
        match placewords::spec::world::load_world(f) {
            Ok(w) => println!(
                "{}: ok ({} walls, {} doors)",
                f.display(),
                w.walls.len(),
                w.doors.len()
            ),
            Err(e) => {
                eprintln!("{e}");
                failed = true;
            }
        }
    }
    Ok(if failed {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    })
}
