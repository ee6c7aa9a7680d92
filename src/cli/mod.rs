//! Subcommands, one file each. Each file holds its clap arguments and a `run` that calls the
//! library and maps the outcome to an exit code.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod import;
pub mod simulate;
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
    /// Drive the simulated robot through a scenario and write CARMEN logs.
    Simulate(simulate::SimulateArgs),
}

pub fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::World(c) => world::run(c),
        Command::Simulate(a) => simulate::run(a),
    }
}
