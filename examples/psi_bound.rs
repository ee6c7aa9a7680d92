//! The exact front end and a candidate (or the default) side by side over the same inputs: per
//! dataset the |ΔΨ| of each observation (max, p99, mean), the share of observations whose class
//! (the word builder's, Φ included) changes, the level-0 words each makes (count, mean length)
//! and each front end's thread CPU. The exact front end is the default settings with every ray
//! to the rim (`ray_step_deg` 1, `ray_stride` 1) and every beam
//! traced (`beam_stride` 1); the candidate is the default settings (the fast front end:
//! `beam_stride` 4, `ray_stride` 2) with the options given.
//!
//! ```text
//! # the approximate front end (the default), every scenario (first 4 runs) and log
//! cargo run --release --example psi_bound -- --runs 4
//! cargo run --release --example psi_bound -- --ray-step-deg 2 scenarios/A.toml
//! cargo run --release --example psi_bound -- --floor-laps 5 --beam-stride 4 --ray-stride 2
//! cargo run --release --example psi_bound -- --scan-step 3 ../shared/data/carmen/intel-corrected.log.gz
//! ```

use anyhow::Result;
use clap::Parser;
use placewords::log::RunLog;
use placewords::recognizer::{
    DensityFrontEnd, DensityObservation, PsiGap, RecognizerConfig, WordLevels,
};
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "support/input.rs"]
mod input;
#[path = "../tests/support/synth.rs"]
mod synth;

#[derive(Parser)]
#[command(about = "Ψ of a candidate front end against the exact one")]
struct Args {
    /// Logs (plain or gzip) and scenario files (.toml); none: every scenario in scenarios/
    /// and every *-corrected.log.gz in ../shared/data/carmen/.
    inputs: Vec<PathBuf>,
    /// Odometry noise seed (log) or the scenario's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Runs of a scenario to read (the first ones; 0: all).
    #[arg(long, default_value_t = 0)]
    runs: usize,
    /// Keep every n-th scan of a log (1: all).
    #[arg(long, default_value_t = 1)]
    scan_step: usize,
    /// Candidate `[recognizer.density] ray_step_deg`.
    #[arg(long)]
    ray_step_deg: Option<f64>,
    /// Candidate `[recognizer.density] ray_stride`.
    #[arg(long)]
    ray_stride: Option<usize>,
    /// Candidate `[recognizer.grid] beam_stride`.
    #[arg(long)]
    beam_stride: Option<usize>,
    /// Candidate `[recognizer.grid] grid_radius_m`.
    #[arg(long)]
    grid_radius_m: Option<f64>,
    /// Instead of the datasets: the thread CPU of both front ends on one lap of the benches'
    /// synthetic loop floor (5000 scans), least of this many laps each, interleaved.
    #[arg(long, default_value_t = 0)]
    floor_laps: usize,
    /// Print the observations of the n largest |ΔΨ| of each dataset.
    #[arg(long, default_value_t = 0)]
    worst: usize,
    /// With `--floor-laps`: run the candidate only (for callgrind).
    #[arg(long)]
    candidate_only: bool,
}

/// The thread's CPU time, seconds; wall clock when `PSI_BOUND_WALL_CLOCK` is set (under
/// valgrind the CPU clock's vDSO lookup crashes, as the front-end bench says).
fn thread_cpu_s() -> f64 {
    static WALL: std::sync::OnceLock<Option<std::time::Instant>> = std::sync::OnceLock::new();
    match WALL
        .get_or_init(|| std::env::var_os("PSI_BOUND_WALL_CLOCK").map(|_| std::time::Instant::now()))
    {
        Some(origin) => origin.elapsed().as_secs_f64(),
        None => placewords::clock::thread_cpu_s(),
    }
}

fn main() -> ExitCode {
    input::exit_code(run(&Args::parse()))
}

fn default_inputs() -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for dir in ["scenarios", "../shared/data/carmen"] {
        let mut found: Vec<PathBuf> = std::fs::read_dir(dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let name = p.to_string_lossy();
                name.ends_with(".toml") || name.ends_with("-corrected.log.gz")
            })
            .collect();
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

fn run(args: &Args) -> Result<()> {
    if args.floor_laps > 0 {
        return floor(args);
    }
    let inputs = if args.inputs.is_empty() {
        default_inputs()?
    } else {
        args.inputs.clone()
    };
    println!(
        "{:<28} {:>6} {:>7} {:>7} {:>8} {:>7} {:>13} {:>13} {:>7} {:>7}",
        "dataset",
        "obs",
        "max|dΨ|",
        "p99",
        "mean",
        "class%",
        "words exact",
        "words cand",
        "cpu ex",
        "cpu ca"
    );
    for path in &inputs {
        let (mut runs, base) = input::load(path, args.seed)?;
        if args.runs > 0 {
            runs.truncate(args.runs);
        }
        let step = if path.extension().is_some_and(|e| e == "toml") {
            1
        } else {
            args.scan_step.max(1)
        };
        let (exact, candidate) = configs(&base, args);
        let (a, cpu_a) = observe(&runs, &exact, step)?;
        let (b, cpu_b) = observe(&runs, &candidate, step)?;
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        report(&name, &exact, &a, &b, (cpu_a, cpu_b));
        if a.len() == b.len() {
            worst(&a, &b, args.worst);
        }
    }
    Ok(())
}

/// The exact settings and the candidate's, both from a dataset's settings.
fn configs(base: &RecognizerConfig, args: &Args) -> (RecognizerConfig, RecognizerConfig) {
    let mut exact = base.clone().with_exact_front_end();
    exact.density.ray_step_deg = 1.0;
    let mut cand = base.clone();
    if let Some(v) = args.ray_step_deg {
        cand.density.ray_step_deg = v;
    }
    if let Some(v) = args.ray_stride {
        cand.density.ray_stride = v;
    }
    if let Some(v) = args.beam_stride {
        cand.grid.beam_stride = v;
    }
    if let Some(v) = args.grid_radius_m {
        cand.grid.grid_radius_m = v;
    }
    (exact, cand)
}

/// Every observation of `runs` (every `step`-th frame) and the front end's thread CPU, seconds.
fn observe(
    runs: &[RunLog],
    cfg: &RecognizerConfig,
    step: usize,
) -> Result<(Vec<DensityObservation>, f64)> {
    let mut fe = DensityFrontEnd::new(cfg)?;
    let mut out = Vec::new();
    let t0 = thread_cpu_s();
    let mut frame = 0;
    for run in runs {
        fe.start_run();
        for (i, f) in run.frames().enumerate() {
            if i % step == 0 {
                out.extend(fe.push_frame(frame, f.odom, &f.scan));
            }
            frame += 1;
        }
    }
    Ok((out, thread_cpu_s() - t0))
}

/// Level-0 words of `obs`: count and mean length, metres.
fn words(cfg: &RecognizerConfig, obs: &[DensityObservation]) -> (usize, f64) {
    let w = &cfg.words;
    let mut levels = WordLevels::with_rule(w.classes, w.min_word_size, 1, w.multi_level)
        .with_wide_classes(cfg.wide_classes_in_use());
    let mut run = None;
    for o in obs {
        if run != Some(o.observation.run) {
            levels.begin_run(o.observation.run);
            run = Some(o.observation.run);
        }
        levels.push(o);
    }
    levels.finish_run();
    let lens: Vec<f64> = levels
        .level(0)
        .map(|w| w.end_travel_m - w.start_travel_m)
        .collect();
    let n = lens.len();
    (n, lens.iter().sum::<f64>() / n.max(1) as f64)
}

fn report(
    name: &str,
    cfg: &RecognizerConfig,
    a: &[DensityObservation],
    b: &[DensityObservation],
    cpu_s: (f64, f64),
) {
    if a.len() != b.len() {
        println!(
            "{name:<28} observations differ: {} against {}",
            a.len(),
            b.len()
        );
        return;
    }
    let Some(gap) = PsiGap::between(cfg, a, b) else {
        println!("{name:<28} no observations");
        return;
    };
    let (wa, la) = words(cfg, a);
    let (wb, lb) = words(cfg, b);
    println!(
        "{name:<28} {:>6} {:>7.4} {:>7.4} {:>8.5} {:>6.2}% {:>6} {:>5.2}m {:>6} {:>5.2}m {:>6.2}s {:>6.2}s",
        gap.observations,
        gap.max,
        gap.p99,
        gap.mean,
        100.0 * gap.class_share,
        wa,
        la,
        wb,
        lb,
        cpu_s.0,
        cpu_s.1
    );
}

/// Least thread CPU of a lap of the loop floor (the front-end bench's input) for both front ends.
fn floor(args: &Args) -> Result<()> {
    let floor = synth::LoopFloor::institute();
    let mut r = synth::SplitMix::new(1);
    let open: Vec<bool> = (0..floor.door_count()).map(|_| r.unit() < 0.3).collect();
    let inputs = floor.lap_inputs(&open, &synth::lms200());
    let (exact, cand) = configs(&RecognizerConfig::default(), args);
    let mut best = [f64::INFINITY; 2];
    for _ in 0..args.floor_laps {
        for (k, cfg) in [&exact, &cand].into_iter().enumerate() {
            if k == 0 && args.candidate_only {
                continue;
            }
            let mut fe = DensityFrontEnd::new(cfg)?;
            let t0 = thread_cpu_s();
            let mut n = 0;
            for (o, s) in &inputs {
                n += fe.push(*o, s).len();
            }
            best[k] = best[k].min(thread_cpu_s() - t0);
            std::hint::black_box(n);
        }
    }
    println!(
        "kernel nodes: exact {}, candidate {}",
        exact.density_kernel().node_count(),
        cand.density_kernel().node_count()
    );
    println!(
        "loop floor, one lap: exact {:.2} ms, candidate {:.2} ms",
        best[0] * 1e3,
        best[1] * 1e3
    );
    Ok(())
}

/// The `n` observations of largest |ΔΨ|: run, travel, Ψ exact and candidate.
fn worst(a: &[DensityObservation], b: &[DensityObservation], n: usize) {
    let mut order: Vec<usize> = (0..a.len()).collect();
    order.sort_by(|&i, &j| {
        (b[j].psi - a[j].psi)
            .abs()
            .total_cmp(&(b[i].psi - a[i].psi).abs())
    });
    let signed = a.iter().zip(b).map(|(x, y)| y.psi - x.psi).sum::<f64>() / a.len().max(1) as f64;
    let moment = a
        .iter()
        .zip(b)
        .map(|(x, y)| (y.lateral_moment - x.lateral_moment).abs())
        .fold(0.0, f64::max);
    if n > 0 {
        println!("    mean signed dPsi {signed:+.5}, max |d lateral moment| {moment:.4}");
    }
    for &i in order.iter().take(n) {
        let o = &a[i].observation;
        println!(
            "    obs {i} run {} travel {:.2} m: {:.4} -> {:.4}",
            o.run, o.travel_m, a[i].psi, b[i].psi
        );
    }
}
