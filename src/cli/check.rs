//! `placewords check SCENARIO...`: the CI gate. Runs each scenario and compares it with its
//! `[expect]` block; one PASS/FAIL line per expectation; exit 0 all pass, 1 any missed, 2 error.

use super::common::write_file;
use clap::Args;
use placewords::eval::gate;
use placewords::experiment::{self, ExperimentOptions};
use placewords::report::junit::{Suite, junit_xml};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario files (TOML) with an [expect] block.
    #[arg(required = true)]
    pub scenarios: Vec<PathBuf>,
    /// Also write a JUnit XML file (one testcase per expectation).
    #[arg(long, value_name = "OUT.xml")]
    pub junit: Option<PathBuf>,
    /// Replace the scenario's seed.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let mut suites = Vec::new();
    let mut errors = 0;
    for path in &args.scenarios {
        let t = Instant::now();
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        let outcome = (|| -> anyhow::Result<Vec<gate::Outcome>> {
            let mut scn = placewords::experiment::load_scenario(path)?;
            if let Some(seed) = args.seed {
                scn.sim.seed = seed;
            }
            let mut levels: Vec<usize> = scn.expect.levels.iter().map(|e| e.levels).collect();
            levels.sort_unstable();
            levels.dedup();
            if levels.is_empty() && scn.expect.icp.is_none() {
                eprintln!(
                    "{}: no [expect] block, nothing to check; add [[expect.levels]] entries",
                    path.display()
                );
                return Ok(Vec::new());
            }
            let opts = ExperimentOptions {
                levels,
                icp: scn.expect.icp.is_some(),
                laps: None,
                quiet: args.quiet,
            };
            let exp = experiment::run_scenario(&scn, &opts)?;
            Ok(gate::check(&exp.report, &scn.expect))
        })();
        match outcome {
            Ok(outcomes) => {
                for o in &outcomes {
                    outln!("{}", o.line())?;
                }
                suites.push(Suite {
                    scenario: name,
                    outcomes,
                    error: None,
                    seconds: t.elapsed().as_secs_f64(),
                });
            }
            Err(e) => {
                errors += 1;
                eprintln!("error: {e:#}");
                outln!("ERROR {name}")?;
                suites.push(Suite {
                    scenario: name,
                    outcomes: Vec::new(),
                    error: Some(format!("{e:#}")),
                    seconds: t.elapsed().as_secs_f64(),
                });
            }
        }
    }
    if let Some(path) = &args.junit {
        write_file(path, junit_xml(&suites).as_bytes())?;
    }
    let outcomes = suites.iter().flat_map(|s| &s.outcomes);
    Ok(ExitCode::from(gate::gate_exit_code(errors, outcomes)))
}
