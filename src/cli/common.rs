//! Argument pieces and helpers several subcommands share.

use anyhow::Context;
use clap::Args;
use std::path::Path;

/// `--levels N`: run only the configuration with N levels (default: 1, 2 and 3).
#[derive(Debug, Args)]
pub struct LevelsArg {
    /// Run only the level configuration with this many levels (default: 1, 2 and 3).
    #[arg(long = "levels", value_name = "1|2|3|4", value_parser = clap::value_parser!(u8).range(1..=4))]
    pub only: Option<u8>,
}

impl LevelsArg {
    pub fn levels(&self) -> Vec<usize> {
        match self.only {
            Some(n) => vec![n as usize],
            None => vec![1, 2, 3],
        }
    }
}

/// Writes a file atomically, naming it in the error.
pub fn write_file(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    placewords::io::atomic::write_atomic(path, bytes)
        .with_context(|| format!("{}: cannot write", path.display()))
}
