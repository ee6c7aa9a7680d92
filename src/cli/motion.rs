//! `placewords motion INPUT…`: how a robot weaves along its route, measured on real logs'
//! corrected paths and on scenarios' simulated laps (issue 28 point 1).

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct MotionArgs {
    /// CARMEN logs (plain or .gz; their corrected poses are the path) and scenario files
    /// (.toml; their simulated laps' true paths). The first is the one the others are compared
    /// with.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Simulate the scenarios at this seed instead of their own.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Laps per run of the scenarios, replacing their counts.
    #[arg(long, value_parser = super::scenario::streamed_laps_flag)]
    pub laps: Option<usize>,
}

pub fn run(args: MotionArgs) -> anyhow::Result<ExitCode> {
    use placewords::experiment::motion;
    let mut rows = Vec::new();
    for input in &args.inputs {
        let is_scenario = input.extension().is_some_and(|e| e == "toml");
        let m = if is_scenario {
            motion::of_scenario(input, args.seed, args.laps)
        } else {
            motion::of_log(input)
        };
        let m = m.map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?;
        rows.push((input.display().to_string(), m));
    }
    print!("{}", placewords::report::motion::text(&rows));
    Ok(ExitCode::SUCCESS)
}
