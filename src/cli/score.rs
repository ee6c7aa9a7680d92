//! `placewords score LOGDIR --matches FILE [--report OUT.json]`: scores any recognizer's matches
//! against the logs `placewords simulate` wrote (docs/scoring.md).

use super::common::write_file;
use clap::Args;
use placewords::experiment::score;
use placewords::io::matches_csv;
use placewords::spec::evaluation::EvaluationSpec;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct ScoreArgs {
    /// Folder `placewords simulate -o` wrote (run-NNN.log or run-NNN.mcap files and
    /// manifest.json).
    pub logdir: PathBuf,
    /// Matches file: `query_run,query_scan,matched_run,matched_scan,score` (score optional).
    #[arg(long, value_name = "FILE")]
    pub matches: PathBuf,
    /// Write the JSON report here (the schema of `run`'s).
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Label the result `words-N`, the paper's recognizer at N levels, as `run` labels it: for
    /// matches `run --export-matches` wrote (its last level configuration, the most levels).
    /// Without it the row is `external`: any other tool's matches.
    #[arg(long, value_name = "N")]
    pub levels: Option<usize>,
}

pub fn run(args: ScoreArgs) -> anyhow::Result<ExitCode> {
    super::common::check_outputs([args.report.as_deref()])?;
    let logs = score::load_logged_runs(&args.logdir)?;
    let name = args.matches.display().to_string();
    // A `run --export-matches` a kill interrupted after its commit is finished first.
    placewords::io::atomic::settle(&args.matches);
    let text = placewords::spec::diag::read_text(&args.matches)?;
    let file = matches_csv::read_matches(&text, &name)?;
    let report = score::score_file(&logs, &file, &name, &EvaluationSpec::default(), args.levels)?;
    out!("{}", placewords::report::table::text_table(&report))?;
    if let Some(path) = &args.report {
        let prov = provenance(&args, &name);
        write_file(
            path,
            placewords::report::json::to_json_with(&report, &prov).as_bytes(),
        )?;
        errln!("report: {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The report's provenance: the logs, the matches file (`name`) and the evaluation settings.
fn provenance(args: &ScoreArgs, name: &str) -> placewords::eval::provenance::Provenance {
    use placewords::eval::provenance::{self as p, Input};
    let mut prov = p::Provenance::new(super::common::command_line());
    prov.add_inputs(
        log_files(&args.logdir)
            .iter()
            .map(|f| p::file_input("logs", f)),
    );
    prov.add_inputs([
        p::file_input("matches", &args.matches),
        Input::new(
            "evaluation",
            name,
            p::hash_settings(&EvaluationSpec::default()),
        ),
    ]);
    prov
}

/// The logs of a folder: its manifest and every log beside it, in name order.
fn log_files(logdir: &std::path::Path) -> Vec<PathBuf> {
    let mut logs = vec![logdir.join("manifest.json")];
    let mut files: Vec<PathBuf> = std::fs::read_dir(logdir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|f| f.extension().is_some_and(|e| e == "log" || e == "mcap"));
    files.sort();
    logs.extend(files);
    logs
}
