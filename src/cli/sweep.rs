//! `placewords sweep SCENARIO -o DIR`: the paper's Fig. 8. Simulates once, computes the
//! observations once, then runs the back end at every threshold configuration in parallel;
//! writes PR curves as SVG and JSON, and each words subject's PR curve over its match score.

use super::common::write_file;
use anyhow::Context;
use clap::Args;
use placewords::eval::scores::SweepReport;
use placewords::eval::sweep::fig8_grid;
use placewords::experiment::{self, ExperimentOptions};
use placewords::report::plot::{pr_curves_svg, score_curves_svg};
use placewords::report::table::{curves_table, score_curves_table};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Output folder for sweep.json, pr-curves.svg (the τ sweep) and score-pr.svg (each words
    /// subject's curve over its match score).
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace every run's lap count (for a quick look; 1 to 1000).
    #[arg(long, value_name = "N", value_parser = super::scenario::laps_flag)]
    pub laps: Option<usize>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub cache: super::common::CacheArg,
}

pub fn run(args: SweepArgs) -> anyhow::Result<ExitCode> {
    // Staged whole and put in place at the end: the folder holds the old sweep or the new one.
    let stage = placewords::io::atomic::StagedDir::begin(&args.out, &|d| {
        placewords::io::atomic::holds_only(d, &|n| {
            matches!(n, "sweep.json" | "pr-curves.svg" | "score-pr.svg")
        })
    })?;
    let grid = fig8_grid();
    let work = placewords::experiment::Workload {
        laps: args.laps,
        passes: experiment::sweep_passes(&grid),
        scan_context: false,
    };
    let scn = placewords::experiment::load_scenario_for(&args.scenario, &work)?;
    let opts = ExperimentOptions {
        laps: args.laps,
        progress: super::progress::bar(args.quiet),
        cache: args.cache.open()?,
        ..ExperimentOptions::default()
    };
    let (results, laps, score_curves) = experiment::sweep(&scn, &opts, &grid)?;
    super::common::report_cache(opts.cache.as_deref());
    let report = SweepReport::new(
        &scn.sim.name,
        scn.sim.seed,
        laps,
        scn.evaluation.clone(),
        results,
        score_curves,
    );
    out!("{}", curves_table(&report.curves))?;
    out!("{}", score_curves_table(&report.score_curves))?;
    write_file(
        &stage.path().join("sweep.json"),
        placewords::report::json::to_json_with(&report, &{
            let mut p =
                experiment::scenario_provenance(&[&scn], args.laps, super::common::command_line());
            p.lap_cache = opts.cache.as_ref().map(|c| c.used());
            p
        })
        .as_bytes(),
    )?;
    let title = format!("{}: precision / recall (Fig. 8)", scn.sim.name);
    write_file(
        &stage.path().join("pr-curves.svg"),
        pr_curves_svg(&report.curves, &title).as_bytes(),
    )?;
    let subjects: Vec<_> = (report.score_curves.iter())
        .map(|s| (s.name.clone(), &s.ranking))
        .collect();
    let title = format!("{}: precision / recall over the match score", scn.sim.name);
    write_file(
        &stage.path().join("score-pr.svg"),
        score_curves_svg(&subjects, &title).as_bytes(),
    )?;
    stage
        .commit()
        .with_context(|| format!("{}: cannot write", args.out.display()))?;
    errln!("sweep: {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}
