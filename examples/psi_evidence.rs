//! How far raw density evidence goes, without words: for every observation, the earlier stretch
//! of Ψ most like the last `--window-m` metres before it (driven the same way, or read
//! backwards), found by brute force over the whole past, and whether the truth agrees.
//!
//! This is the study behind RESULTS.md's "Evidence without words" (eighth session): where a
//! recognizer's words fail on short revisits, would matching the raw Ψ profile do? The picks
//! are accepted as a ratio test would: the best window's RMS difference at most `--max-rms`,
//! and at most `--ratio` times the best one elsewhere (beyond 3 m of travel from it). Precision
//! is the share of accepted picks whose true positions are within 1 m with headings that agree
//! with the pick's direction (as `eval` scores pairs).
//!
//! ```text
//! cargo run --release --example psi_evidence -- ../shared/data/carmen/csail-corrected.log.gz --seed 1
//! cargo run --release --example psi_evidence -- scenarios/A.toml --seed 1
//! ```
//!
//! Work is quadratic in the observations (brute force, on purpose: nothing is missed); CSAIL
//! takes about a second, a scenario of 14,000 observations about a minute.

use anyhow::Result;
use clap::Parser;
use placewords::eval::GroundTruth;
use placewords::geom::{Pose2, wrap_angle};
use placewords::log::RunLog;
use placewords::recognizer::RecognizerConfig;
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;

#[derive(Parser)]
#[command(about = "Nearest earlier Ψ windows, with the truth's verdict")]
struct Args {
    /// A CARMEN log (plain or gzip) or a scenario file (.toml).
    input: PathBuf,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Length of the Ψ window compared, metres.
    #[arg(long, default_value_t = 4.0)]
    window_m: f64,
    /// Accept a pick whose window's RMS Ψ difference is at most this (comma-separated list).
    #[arg(long, default_value = "0.007,0.01,0.017", value_delimiter = ',')]
    max_rms: Vec<f64>,
    /// Accept a pick at most this times the best window elsewhere (comma-separated list).
    #[arg(long, default_value = "1,0.5,0.3", value_delimiter = ',')]
    ratio: Vec<f64>,
    /// Odometric travel an earlier window must end before the current one begins, metres.
    #[arg(long, default_value_t = 20.0)]
    min_gap_m: f64,
    /// Only windows whose sides agree: RMS difference of the lateral moment (the past side's
    /// negated read backwards) at most this; 0 = no check.
    #[arg(long, default_value_t = 0.0)]
    max_lateral_rms: f64,
    /// Only windows that turn alike: the odometric heading change over the window of both sides
    /// (the past's negated read backwards) within this, degrees; 0 = no check.
    #[arg(long, default_value_t = 0.0)]
    max_turn_deg: f64,
}

/// One observation as the study needs it.
struct Obs {
    travel_m: f64,
    psi: f64,
    lateral: f64,
    heading: f64,
    truth: Option<Pose2>,
}

/// The best earlier window of one observation.
struct Pick {
    i: usize,
    j: usize,
    opposite: bool,
    mse: f64,
    elsewhere: f64,
}

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

fn run(args: &Args) -> Result<()> {
    let (runs, cfg) = input::load(&args.input, args.seed)?;
    let obs = observe(&runs, cfg)?;
    let window =
        (args.window_m / RecognizerConfig::default().front_end.observation_spacing_m).round();
    let window = (window as usize).max(1);
    let max_mse = args.max_rms.iter().fold(0.0f64, |a, &b| a.max(b)).powi(2);
    let picks = nearest_windows(&obs, window, args, max_mse);
    let correct = |p: &Pick| is_correct(&obs, p);
    println!(
        "{}  seed {}  {} observations  window {} m ({} observations)  {} picks, {} correct",
        args.input.display(),
        args.seed,
        obs.len(),
        args.window_m,
        window,
        picks.len(),
        picks.iter().filter(|p| correct(p)).count()
    );
    println!("max RMS  ratio  accepted  correct  precision");
    for &rms in &args.max_rms {
        for &ratio in &args.ratio {
            let ok: Vec<bool> = picks
                .iter()
                .filter(|p| p.mse <= rms * rms && p.mse <= ratio * p.elsewhere)
                .map(correct)
                .collect();
            let n = ok.len();
            let c = ok.iter().filter(|&&x| x).count();
            let precision = if n == 0 {
                "-".to_string()
            } else {
                format!("{:.3}", c as f64 / n as f64)
            };
            println!("{rms:>7.4}  {ratio:>5.2}  {n:>8}  {c:>7}  {precision:>9}");
        }
    }
    Ok(())
}

/// Every observation the recognizer makes of `runs`, with its truth.
fn observe(runs: &[RunLog], cfg: RecognizerConfig) -> Result<Vec<Obs>> {
    let truth = GroundTruth::from_runs(runs);
    let rec = input::recognize(runs, cfg)?;
    let words = rec.words();
    Ok(rec
        .observations()
        .iter()
        .zip(words.psi().iter().zip(words.lateral_moments()))
        .map(|(o, (&psi, &lateral))| Obs {
            travel_m: o.travel_m,
            psi,
            lateral,
            heading: o.odom_pose.0.theta,
            truth: truth.observation_pose(o).map(|p| p.0),
        })
        .collect())
}

/// For each observation i with a full window behind it, the earlier window ending at j (same
/// direction: Ψ[i−k] against Ψ[j−k]; read backwards: Ψ[i−k] against Ψ[j+k]) with the least mean
/// squared difference, and the least one beyond 3 m of travel from it. Windows that could be
/// accepted (mean squared difference at most `max_mse`) take part only if their sides and turns
/// agree as `args` asks.
fn nearest_windows(obs: &[Obs], window: usize, args: &Args, max_mse: f64) -> Vec<Pick> {
    let min_gap_m = args.min_gap_m;
    let psi: Vec<f64> = obs.iter().map(|o| o.psi).collect();
    // Sides and turns are checked on the windows that could be accepted only.
    let consistent = |i: usize, j: usize, opposite: bool| {
        let sign = if opposite { -1.0 } else { 1.0 };
        let past = |k: usize| if opposite { j + k } else { j - k };
        if args.max_lateral_rms > 0.0 {
            let e: f64 = (0..window)
                .map(|k| (obs[i - k].lateral - sign * obs[past(k)].lateral).powi(2))
                .sum();
            if (e / window as f64).sqrt() > args.max_lateral_rms {
                return false;
            }
        }
        if args.max_turn_deg > 0.0 {
            let w = window - 1;
            let current = wrap_angle(obs[i].heading - obs[i - w].heading);
            let past_turn = if opposite {
                wrap_angle(obs[j].heading - obs[j + w].heading)
            } else {
                wrap_angle(obs[j].heading - obs[j - w].heading)
            };
            if wrap_angle(current - past_turn).abs() > args.max_turn_deg.to_radians() {
                return false;
            }
        }
        true
    };
    let n = obs.len();
    let mut picks = Vec::new();
    let mut row: Vec<(f64, usize, bool)> = Vec::new();
    for i in window..n {
        row.clear();
        let begins_m = obs[i + 1 - window].travel_m;
        for j in 0..i {
            // The earlier window (either reading) must end `min_gap_m` before this one begins.
            let same_ok = j + 1 >= window && begins_m - obs[j].travel_m >= min_gap_m;
            let opp_end = j + window - 1;
            let opp_ok = opp_end < n && begins_m - obs[opp_end].travel_m >= min_gap_m;
            if same_ok {
                let d: f64 = (0..window).map(|k| (psi[i - k] - psi[j - k]).powi(2)).sum();
                let mse = d / window as f64;
                if mse > max_mse || consistent(i, j, false) {
                    row.push((mse, j, false));
                }
            }
            if opp_ok {
                let d: f64 = (0..window).map(|k| (psi[i - k] - psi[j + k]).powi(2)).sum();
                let mse = d / window as f64;
                if mse > max_mse || consistent(i, j, true) {
                    row.push((mse, j, true));
                }
            }
        }
        let Some(&(mse, j, opposite)) = row.iter().min_by(|a, b| a.0.total_cmp(&b.0)) else {
            continue;
        };
        let elsewhere = row
            .iter()
            .filter(|r| (obs[r.1].travel_m - obs[j].travel_m).abs() >= 3.0)
            .map(|r| r.0)
            .fold(f64::INFINITY, f64::min);
        picks.push(Pick {
            i,
            j,
            opposite,
            mse,
            elsewhere,
        });
    }
    picks
}

/// Whether a pick's true positions are within 1 m, facing as its direction says (45°).
fn is_correct(obs: &[Obs], p: &Pick) -> bool {
    let (Some(a), Some(b)) = (obs[p.i].truth, obs[p.j].truth) else {
        return false;
    };
    let turn = wrap_angle(a.theta - b.theta).abs();
    let facing = if p.opposite {
        turn >= 135f64.to_radians()
    } else {
        turn <= 45f64.to_radians()
    };
    a.distance(&b) <= 1.0 && facing
}
