//! `placewords table SCENARIO... -o DIR`: the paper's Table I (precision–recall at 1, 2 and 3
//! levels, for ICP and for Scan Context, with each one's time per lap, measured in the same run), as Markdown and
//! JSON.

use super::common::write_file;
use anyhow::Context;
use clap::Args;
use placewords::eval::scores::TableReport;
use placewords::experiment::{self, ExperimentOptions};
use placewords::report::table::{
    markdown_ranking, markdown_table_i, markdown_visit_recall, thresholds_note,
};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct TableArgs {
    /// Scenario files (TOML), one column each.
    #[arg(required = true)]
    pub scenarios: Vec<PathBuf>,
    /// Output folder for table.md, table.json and one report per scenario.
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Leave out the ICP baseline (it dominates the run time).
    #[arg(long)]
    pub no_icp: bool,
    /// Leave out the Scan Context baseline (settings: each scenario's `[scan_context]` table).
    #[arg(long)]
    pub no_scan_context: bool,
    /// Replace every run's lap count (for a quick look; 1 to 1000).
    #[arg(long, value_name = "N", value_parser = super::scenario::laps_flag)]
    pub laps: Option<usize>,
    #[command(flatten)]
    pub external: super::common::ExternalArg,
    #[command(flatten)]
    pub cache: super::common::CacheArg,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: TableArgs) -> anyhow::Result<ExitCode> {
    // Staged whole and put in place at the end: the folder holds the old table or the new one.
    let stage = placewords::io::atomic::StagedDir::begin(&args.out, &|d| {
        placewords::io::atomic::holds_only(d, &|n| {
            matches!(n, "table.md" | "table.json")
                || (n.starts_with("report-") && n.ends_with(".json"))
        })
    })?;
    let opts = ExperimentOptions {
        levels: vec![1, 2, 3],
        icp: !args.no_icp,
        scan_context: !args.no_scan_context,
        scan_context_config: Default::default(),
        external: args.external.specs(),
        laps: args.laps,
        progress: super::progress::bar(args.quiet),
        cache: args.cache.open()?,
    };
    // One back-end pass per level configuration, and Scan Context's descriptors (ICP's work is
    // not counted).
    let work = placewords::experiment::Workload {
        laps: args.laps,
        passes: opts.levels.len(),
        scan_context: opts.scan_context,
    };
    // Load every scenario first, so a broken file is reported before minutes of simulation.
    let scenarios = args
        .scenarios
        .iter()
        .map(|p| placewords::experiment::load_scenario_for(p, &work))
        .collect::<Result<Vec<_>, _>>()?;
    let mut reports = Vec::new();
    let command_line = super::common::command_line();
    for scn in &scenarios {
        errln!("scenario {}", scn.sim.name);
        // Streamed: nothing here needs the scans after the recognizers saw them.
        let exp = experiment::run_scenario_streamed(scn, &opts)?;
        let mut provenance =
            experiment::scenario_provenance(&[scn], args.laps, command_line.clone());
        provenance.lap_cache = opts.cache.as_ref().map(|c| {
            let mut u = c.used();
            // This scenario's seed alone: its source, not the counts so far.
            (u.hits, u.misses) = match exp.lap_source {
                Some(placewords::eval::provenance::LapSource::Hit) => (1, 0),
                _ => (0, 1),
            };
            u
        });
        write_file(
            &stage.path().join(format!("report-{}.json", scn.sim.name)),
            placewords::report::json::to_json_with(&exp.report, &provenance).as_bytes(),
        )?;
        reports.push(exp.report);
    }
    let rule = reports
        .first()
        .map(|r| {
            placewords::report::explain::truth_rule(&placewords::eval::ranking::TruthRule::of(
                &r.evaluation,
            ))
        })
        .unwrap_or_default();
    let md = format!(
        "{}\n{}\nVisit recall (share of the earlier laps through each spot that were recognized) and pair recall (share of every pair that could be found):\n\n{}\nOver the match score, per query observation (a query's answer is its best-scoring pair, right when it is a true revisit {rule}): recall at 99 % precision and max F1:\n\n{}",
        markdown_table_i(&reports),
        thresholds_note(&reports),
        markdown_visit_recall(&reports),
        markdown_ranking(&reports)
    );
    out!("{md}")?;
    write_file(&stage.path().join("table.md"), md.as_bytes())?;
    let all: Vec<_> = scenarios.iter().collect();
    let mut provenance = experiment::scenario_provenance(&all, args.laps, command_line);
    provenance.lap_cache = opts.cache.as_ref().map(|c| c.used());
    super::common::report_cache(opts.cache.as_deref());
    let json = placewords::report::json::to_json_with(&TableReport::new(reports), &provenance);
    write_file(&stage.path().join("table.json"), json.as_bytes())?;
    stage
        .commit()
        .with_context(|| format!("{}: cannot write", args.out.display()))?;
    errln!("table: {}", args.out.join("table.md").display());
    Ok(ExitCode::SUCCESS)
}
