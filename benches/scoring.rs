//! Scoring costs as the laps grow (issue 30): a whole evaluation (every match counted as it
//! arrives, then the revisits, visit recall and pair recall at the end) of 100 and 1000 laps of
//! one 47 m loop, one observation per 0.1 m as the recognizer makes them, each observation
//! matched with the same place on the 5 laps before. The reference k-d tree searches
//! (`evaluate_by_site_tree`) are measured at 100 laps only: they grow with the square of the
//! laps. Setup is outside the timed part; figures and the machine are in BENCHMARKS.md.

use criterion::{Criterion, criterion_group, criterion_main};
use placewords::eval::{GroundTruth, LapInfo, Recognition, evaluate, evaluate_by_site_tree};
use placewords::geom::{OdomPose, Pose2, TruePose};
use placewords::place::{Match, Observation};
use placewords::spec::evaluation::EvaluationSpec;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

/// Observations per lap (47 m at 0.1 m, as on `long-term`'s loop).
const PER_LAP: usize = 470;

/// `cargo bench` passes `--bench`; without it (`cargo test --benches`) each runs once, small.
fn full_run() -> bool {
    std::env::args().any(|a| a == "--bench")
}

/// `laps` laps of a circle, each wandering up to 0.2 m off it (a deterministic wobble), with
/// one match per observation and earlier lap (up to 5 back) at the same place.
fn recognition(laps: usize) -> Recognition {
    let perimeter = PER_LAP as f64 * 0.1;
    let radius = perimeter / (2.0 * std::f64::consts::PI);
    let mut truth = GroundTruth::default();
    let mut observations = Vec::new();
    let mut matches = Vec::new();
    for lap in 0..laps {
        truth.start_lap(LapInfo {
            run: lap / 25,
            lap: lap % 25,
            door_config: format!("day-{}", lap / 25),
            open_doors: vec![],
        });
        let off = 0.2 * ((lap as f64 * 0.77).sin());
        for k in 0..PER_LAP {
            let a = k as f64 / PER_LAP as f64 * 2.0 * std::f64::consts::PI;
            let r = radius + off * (3.0 * a).cos();
            let pose = Pose2::new(r * a.cos(), r * a.sin(), a + std::f64::consts::FRAC_PI_2);
            let i = observations.len();
            truth.push_frame(TruePose(pose), OdomPose(pose));
            observations.push(Observation::new(
                i,
                lap / 25,
                i,
                OdomPose(pose),
                i as f64 * 0.1,
            ));
            if k % 20 == 19 {
                for back in 1..=lap.min(5) {
                    let past = i - back * PER_LAP;
                    matches.push(Match::from_pairs((0..20).map(|d| (i - d, past - d)), 1.0));
                }
            }
        }
    }
    Recognition::new("bench", observations, matches, laps, Arc::new(truth))
}

fn scoring(c: &mut Criterion) {
    let spec = EvaluationSpec::default();
    let (small, large) = if full_run() { (100, 1000) } else { (4, 8) };
    let mut g = c.benchmark_group("scoring");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(if full_run() { 20 } else { 1 }));
    for laps in [small, large] {
        let rec = recognition(laps);
        g.bench_function(format!("evaluate_{laps}_laps"), |b| {
            b.iter(|| black_box(evaluate(&rec, &spec)))
        });
        if laps == small {
            g.bench_function(format!("evaluate_by_site_tree_{laps}_laps"), |b| {
                b.iter(|| black_box(evaluate_by_site_tree(&rec, &spec)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, scoring);
criterion_main!(benches);
