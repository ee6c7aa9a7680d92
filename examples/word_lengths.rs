//! The level-0 words a recognizer makes of a log or a scenario's first run: each word's class,
//! length in metres and where it starts (true position), and the distribution of lengths.
//!
//! ```text
//! cargo run --release --example word_lengths -- scenarios/hall.toml --seed 1
//! cargo run --release --example word_lengths -- ../shared/data/carmen/intel-corrected.log.gz --wide-radius-m 0
//! ```

use anyhow::Result;
use clap::Parser;
use placewords::eval::GroundTruth;
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;

#[derive(Parser)]
#[command(about = "Level-0 words of a log or scenario, with their lengths")]
struct Args {
    /// A CARMEN log (plain or gzip) or a scenario file (.toml).
    input: PathBuf,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print every word of the first run (else only the summary).
    #[arg(long)]
    list: bool,
    /// `[recognizer.density] wide_radius_m` instead of the settings' (0: no wide window).
    #[arg(long)]
    wide_radius_m: Option<f64>,
}

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

fn run(args: &Args) -> Result<()> {
    let (runs, mut cfg) = input::load(&args.input, args.seed)?;
    if let Some(r) = args.wide_radius_m {
        cfg.density.wide_radius_m = r;
    }
    let truth = GroundTruth::from_runs(&runs);
    let rec = input::recognize(&runs, cfg)?;
    let words = rec.words();
    let obs = rec.observations();
    let mut lengths: Vec<f64> = Vec::new();
    for w in words.level(0) {
        let len = w.end_travel_m - w.start_travel_m;
        lengths.push(len);
        if args.list && w.run == 0 {
            let at = truth.observation_pose(&obs[w.first_obs]).map(|p| p.0);
            let (x, y) = at.map_or((f64::NAN, f64::NAN), |p| (p.x, p.y));
            println!(
                "class {:2}  {:6.2} m  from travel {:7.2} m  at ({x:6.1}, {y:6.1})",
                w.class, len, w.start_travel_m
            );
        }
    }
    lengths.sort_by(f64::total_cmp);
    let n = lengths.len().max(1);
    let mean = lengths.iter().sum::<f64>() / n as f64;
    let q = |p: f64| lengths[((n - 1) as f64 * p) as usize];
    println!(
        "{} level-0 words: mean {mean:.2} m, median {:.2}, p90 {:.2}, max {:.2}",
        lengths.len(),
        q(0.5),
        q(0.9),
        q(1.0)
    );
    Ok(())
}
