//! `placewords simulate SCENARIO [--laps N] [--format carmen|mcap] -o DIR [--quiet]`: one CARMEN
//! log (or ROS 2 bag) per run and a JSON manifest, all written atomically.

use clap::{Args, ValueEnum};
use placewords::sim::logs::RunFormat;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Laps per run, replacing the scenario's counts (up to a million: laps are written as they
    /// are made, so memory does not grow with them).
    #[arg(long, value_parser = super::scenario::streamed_laps_flag)]
    pub laps: Option<usize>,
    /// Simulate this seed instead of the scenario's `seed` (to reproduce one seed of `check`).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Output folder for the logs and manifest.
    #[arg(short, long)]
    pub out: PathBuf,
    /// How each run is written: `carmen` (`run-NNN.log`) or `mcap`, a ROS 2 bag (`run-NNN.mcap`:
    /// /scan, /odom, /tf, /ground_truth, /doors; docs/ros2.md). Example:
    /// `placewords simulate scenarios/smoke.toml --format mcap -o sim/`.
    #[arg(long, value_enum, default_value = "carmen")]
    pub format: FormatArg,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also draw each run (world, true path, odometry path) as `run-NNN.svg` in the output folder.
    #[arg(long)]
    pub svg: bool,
    #[command(flatten)]
    pub cache: super::common::CacheArg,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum FormatArg {
    /// CARMEN text logs.
    Carmen,
    /// ROS 2 bags (MCAP, CDR).
    Mcap,
}

pub fn run(args: SimulateArgs) -> anyhow::Result<ExitCode> {
    let mut scn = placewords::experiment::load_scenario(&args.scenario)?;
    if let Some(seed) = args.seed {
        scn.sim.seed = seed;
    }
    let total: usize = scn
        .sim
        .runs
        .iter()
        .map(|r| args.laps.unwrap_or(r.laps))
        .sum();
    let cache = args.cache.open()?;
    let started = std::time::Instant::now();
    let files = placewords::experiment::output::simulate_to_folder(
        &scn,
        args.laps,
        &args.out,
        run_format(args.format),
        args.svg,
        &super::progress::bar(args.quiet),
        cache.as_deref(),
    )?;
    super::common::report_cache(cache.as_deref());
    if !args.quiet {
        print_written(total, &files, started);
    }
    Ok(ExitCode::SUCCESS)
}

/// The log format named on the command line.
fn run_format(f: FormatArg) -> RunFormat {
    match f {
        FormatArg::Carmen => RunFormat::Carmen,
        FormatArg::Mcap => RunFormat::Mcap,
    }
}

/// How many laps were simulated in how long, and each file written.
fn print_written(total_laps: usize, files: &[PathBuf], started: std::time::Instant) {
    errln!(
        "simulated {total_laps} laps and wrote {} files in {:.2} s",
        files.len(),
        started.elapsed().as_secs_f64()
    );
    for f in files {
        errln!("wrote {}", f.display());
    }
}
