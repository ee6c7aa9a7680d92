//! Where a log's or scenario's Ψ lies against the density class boundaries: the histogram of Ψ
//! (32 bins, `|` at each class boundary of 8 classes) and, for class offsets 0, 1/16, …, 15/16
//! (`[recognizer.words] class_offset`), the share of observations within 0.16 of a class of a
//! boundary, where their words flicker between two classes.
//!
//! ```text
//! cargo run --release --example psi_boundaries -- scenarios/A.toml
//! cargo run --release --example psi_boundaries -- ../shared/data/carmen/intel-corrected.log.gz --seed 1
//! ```

use anyhow::Result;
use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;

#[derive(Parser)]
#[command(about = "Ψ of a log or scenario against the density class boundaries")]
struct Args {
    /// A CARMEN log (plain or gzip) or a scenario file (.toml).
    input: PathBuf,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// How close to a boundary, in classes, an observation counts as on it.
const NEAR_CLASSES: f64 = 0.16;

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

fn run(args: &Args) -> Result<()> {
    let (runs, cfg) = input::load(&args.input, args.seed)?;
    let classes = cfg.words.classes as f64;
    let rec = input::recognize(&runs, cfg)?;
    let psi = rec.words().psi();
    let n = psi.len().max(1) as f64;
    let mut bins = [0usize; 32];
    for &v in psi {
        bins[((v * 32.0).max(0.0) as usize).min(31)] += 1;
    }
    let per_mille: Vec<String> = (bins.iter().enumerate())
        .map(|(i, &c)| {
            let mark = if i % 4 == 0 { "|" } else { " " };
            format!("{mark}{:.0}", c as f64 / n * 1000.0)
        })
        .collect();
    println!(
        "Ψ in 32 bins over [0, 1], per mille of {} observations:",
        psi.len()
    );
    println!("{}", per_mille.join(""));
    println!("share within {NEAR_CLASSES} of a class of an inner boundary, by class_offset:");
    let shares: Vec<String> = (0..16)
        .map(|k| {
            let offset = k as f64 / 16.0;
            let near = (psi.iter())
                .filter(|&&v| {
                    let x = v * classes + offset;
                    let b = x.round();
                    (x - b).abs() < NEAR_CLASSES && (1.0..=classes - 1.0).contains(&b)
                })
                .count();
            format!("{offset:.4}: {:.3}", near as f64 / n)
        })
        .collect();
    println!("{}", shares.join("  "));
    Ok(())
}
