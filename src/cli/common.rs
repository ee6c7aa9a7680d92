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

/// Checks, before any work starts, that each output file can be written (exit 2 naming it).
pub fn check_outputs<'a>(files: impl IntoIterator<Item = Option<&'a Path>>) -> anyhow::Result<()> {
    for path in files.into_iter().flatten() {
        placewords::io::atomic::check_writable(path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// Checks, before any work starts, that files can be written into each output folder.
pub fn check_output_dirs<'a>(
    dirs: impl IntoIterator<Item = Option<&'a Path>>,
) -> anyhow::Result<()> {
    for dir in dirs.into_iter().flatten() {
        placewords::io::atomic::check_writable_dir(dir)
            .with_context(|| format!("{}: cannot write into this folder", dir.display()))?;
    }
    Ok(())
}

/// The command line as given (program name first), for the reports' provenance; an argument
/// that is not UTF-8 is kept with its bad bytes replaced rather than refused.
pub fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

/// Prints the experiment's table, then writes its JSON report (with `provenance`) and pictures
/// where asked: the true and odometry paths, and the matched pairs of each level configuration
/// (and ICP).
pub fn print_and_write(
    exp: &placewords::experiment::Experiment,
    world: &placewords::world::World,
    radius_m: f64,
    report: Option<(&Path, &placewords::eval::provenance::Provenance)>,
    svg_dir: Option<&Path>,
) -> anyhow::Result<()> {
    out!("{}", placewords::report::table::text_table(&exp.report))?;
    if let Some((path, provenance)) = report {
        write_file(
            path,
            placewords::report::json::to_json_with(&exp.report, provenance).as_bytes(),
        )?;
        eprintln!("report: {}", path.display());
    }
    if let Some(dir) = svg_dir {
        placewords::experiment::picture::write_pictures(exp, world, radius_m, dir)?;
        eprintln!("pictures: {}", dir.display());
    }
    Ok(())
}

/// `--seeds A..B` or `--seed N`: which seeds to run.
#[derive(Debug, Args)]
pub struct SeedsArg {
    /// Run every seed from A to B (both included), e.g. 1..20. Each seed re-draws everything
    /// random: noise, doors drawn at random, people, lap variation.
    #[arg(long, value_name = "A..B", conflicts_with = "seed")]
    pub seeds: Option<placewords::spec::seeds::SeedRange>,
    /// Run this seed only (the scenario's `seed` is replaced).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
}

impl SeedsArg {
    /// The seeds asked for, if any.
    pub fn range(&self) -> Option<placewords::spec::seeds::SeedRange> {
        self.seeds
            .or(self.seed.map(placewords::spec::seeds::SeedRange::one))
    }
}
