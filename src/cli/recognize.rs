//! `placewords recognize LOG`: the recognizer and evaluation on a real CARMEN log or a ROS 2 bag
//! (MCAP), with the same definitions and report schema as `run`.

use super::common::{ExperimentOutputs, LevelsArg};
use anyhow::bail;
use clap::{Args, ValueEnum};
use placewords::experiment::{self, ExperimentOptions, picture};
use placewords::io::real_log::TruthSource;
use placewords::recognizer::RecognizerConfig;
use placewords::spec::evaluation::EvaluationSpec;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum TruthArg {
    /// The corrected pose on each laser line.
    Corrected,
    /// TRUEPOS messages, matched to laser lines by time.
    Truepos,
}

#[derive(Debug, Args)]
pub struct RecognizeArgs {
    /// CARMEN log (plain or gzip) or ROS 2 bag (`.mcap`, told by its first bytes), e.g.
    /// `placewords recognize robot.mcap --scan-topic /scan --odom-topic /odom`.
    pub log: PathBuf,
    /// A bag's `sensor_msgs/msg/LaserScan` topic (default: the only topic of that type).
    #[arg(long, value_name = "TOPIC")]
    pub scan_topic: Option<String>,
    /// A bag's `nav_msgs/msg/Odometry` topic (default: the only topic of that type).
    #[arg(long, value_name = "TOPIC")]
    pub odom_topic: Option<String>,
    /// Where the ground truth comes from.
    #[arg(long, value_enum, default_value = "corrected")]
    pub truth: TruthArg,
    /// Odometry derived from the corrected increments through the simulator's odometry model:
    /// `none`, `proportional` (0.0075 m/m and rad/rad, random-walk form), `proportional:T,R`,
    /// or `thrun:A1,A2,A3,A4`.
    #[arg(long, value_name = "MODEL", default_value = "proportional")]
    pub odometry_noise: String,
    /// Seed of the odometry noise stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Use every K-th scan only (K = 2 halves the scan rate), to test a recognizer on sparse logs.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub scan_step: u64,
    /// Recognizer settings: a TOML file holding a `[recognizer]` table, read as in a scenario
    /// (docs/scenario-format.md; `levels` is chosen with --levels).
    #[arg(long, value_name = "FILE.toml")]
    pub config: Option<PathBuf>,
    #[command(flatten)]
    pub levels: LevelsArg,
    #[command(flatten)]
    pub external: super::common::ExternalArg,
    /// Also run the ICP baseline.
    #[arg(long)]
    pub icp: bool,
    /// Also run the Scan Context baseline (default settings; docs in `baseline::scan_context`),
    /// e.g. `placewords recognize intel.log --levels 3 --scan-context`.
    #[arg(long)]
    pub scan_context: bool,
    /// Skip malformed lines (and report how many) instead of stopping at the first.
    #[arg(long)]
    pub lenient: bool,
    /// A pair is correct when its true positions are within this distance, metres.
    #[arg(long, default_value_t = 1.0, value_name = "M")]
    pub tp_radius_m: f64,
    /// Minimum true travel (from the corrected poses) between revisiting observations
    /// (evaluation), metres.
    #[arg(long, default_value_t = 20.0, value_name = "M")]
    pub min_gap_m: f64,
    /// Write the JSON report here.
    #[arg(long, value_name = "OUT.json")]
    pub report: Option<PathBuf>,
    /// Write pictures here: paths and matched pairs per level configuration.
    #[arg(long, value_name = "DIR")]
    pub svg: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: RecognizeArgs) -> anyhow::Result<ExitCode> {
    let outputs = ExperimentOutputs::begin(args.report.as_deref(), None, args.svg.as_deref())?;
    let noise = experiment::real::parse_noise_model(&args.odometry_noise)
        .map_err(|e| anyhow::anyhow!("--odometry-noise {}: {e}", args.odometry_noise))?;
    for (flag, v) in [
        ("--tp-radius-m", args.tp_radius_m),
        ("--min-gap-m", args.min_gap_m),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bail!(
                "{flag} {}: must be a positive distance in metres",
                placewords::spec::diag::fmt_number(v)
            );
        }
    }
    let truth = match args.truth {
        TruthArg::Corrected => TruthSource::Corrected,
        TruthArg::Truepos => TruthSource::TruePos,
    };
    let base = match &args.config {
        Some(path) => experiment::load_recognizer_config(path)?,
        None => RecognizerConfig::default(),
    };
    let name = args
        .log
        .file_name()
        .map(|n| {
            n.to_string_lossy()
                .trim_end_matches(".gz")
                .trim_end_matches(".log")
                .trim_end_matches(".mcap")
                .to_string()
        })
        .unwrap_or_else(|| "log".into());
    let evaluation = EvaluationSpec {
        tp_radius_m: args.tp_radius_m,
        min_gap_m: args.min_gap_m,
        ..EvaluationSpec::default()
    };
    let opts = ExperimentOptions {
        levels: args.levels.levels(),
        icp: args.icp,
        scan_context: args.scan_context,
        scan_context_config: Default::default(),
        external: args.external.specs(),
        laps: None,
        progress: super::progress::bar(args.quiet),
        cache: None,
    };
    let log = experiment::real::RealLogOptions {
        lenient: args.lenient,
        truth,
        noise,
        seed: args.seed,
        scan_step: args.scan_step as usize,
        topics: placewords::io::ros2::bag::BagTopics {
            scan: args.scan_topic.clone(),
            odom: args.odom_topic.clone(),
        },
    };
    let keep_runs = args.svg.is_some();
    let (exp, skipped) = experiment::real::recognize_log(
        &args.log,
        &log,
        &name,
        &base,
        &evaluation,
        &opts,
        keep_runs,
    )?;
    if skipped > 0 {
        errln!(
            "{}: skipped {skipped} malformed line(s)",
            args.log.display()
        );
    }
    let world = picture::empty_world(&exp.runs, &name);
    let provenance = {
        use placewords::eval::provenance::{self as p, Input};
        let mut prov = p::Provenance::new(super::common::command_line());
        prov.add_seeds([args.seed]);
        let log_name = args.log.display().to_string();
        prov.add_inputs([p::file_input("real_log", &args.log)]);
        prov.add_inputs(args.config.iter().map(|c| p::file_input("config", c)));
        prov.add_inputs([
            Input::new("recognizer", &log_name, p::hash_settings(&base)),
            Input::new("evaluation", &log_name, p::hash_settings(&evaluation)),
            // How the log is read (truth source, added odometry noise and its seed, scan step).
            Input::new(
                "log_options",
                &log_name,
                p::hash_bytes(format!("{log:?}").as_bytes()),
            ),
        ]);
        prov
    };
    outputs.print_and_write(&exp, &world, &provenance)?;
    Ok(ExitCode::SUCCESS)
}
