//! `placewords simulate SCENARIO -o DIR`.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Output folder for the logs and manifest.
    #[arg(short, long)]
    pub out: PathBuf,
}

pub fn run(_args: SimulateArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("simulate is being built (issue 3)")
}
