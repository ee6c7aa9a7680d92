//! Recognizer costs past the front end (grid and density: `benches/front_end.rs`): word building
//! per lap, matching per lap (1, 2, 3 level configurations × 1, 10, 40 laps of history), and the whole
//! recognizer per lap. Inputs are synthetic (see `tests/support/synth.rs`); setup is outside the
//! timed part. Figures and the machine are in BENCHMARKS.md.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use placewords::geom::OdomPose;
#[path = "../tests/support/synth.rs"]
mod synth;
use placewords::recognizer::{
    DensityObservation, Recognizer, RecognizerConfig, WordLevels, WordMatcher,
};
use placewords::scan::Scan;
use std::hint::black_box;
use std::time::Duration;
use synth::{LoopFloor, SplitMix};

const FLOOR_SEED: u64 = 42;

/// `cargo bench` passes `--bench`; without it (`cargo test --benches`, CI) criterion runs each
/// benchmark once, and short histories keep that quick.
fn full_run() -> bool {
    std::env::args().any(|a| a == "--bench")
}

/// One lap of (odometry, scan) on the 200 m loop floor, doors drawn from `seed`.
fn lap_inputs(seed: u64) -> Vec<(OdomPose, Scan)> {
    let floor = LoopFloor::institute();
    let mut r = SplitMix::new(seed);
    let open: Vec<bool> = (0..floor.door_count()).map(|_| r.unit() < 0.3).collect();
    floor.lap_inputs(&open, &synth::lms200())
}

/// `n` consecutive procedural observation laps (~2000 observations each) after `after`.
fn observation_laps(
    n: usize,
    first_seed: u64,
    after: Option<DensityObservation>,
) -> Vec<Vec<DensityObservation>> {
    let mut last = after;
    (0..n)
        .map(|i| {
            let lap = synth::procedural_lap(FLOOR_SEED, first_seed + i as u64, last.as_ref());
            last = lap.last().copied();
            lap
        })
        .collect()
}

fn word_building(c: &mut Criterion) {
    let lap = observation_laps(1, 1, None).remove(0);
    let mut g = c.benchmark_group("back_end");
    g.bench_function("word_building_per_lap_3_levels", |b| {
        b.iter_batched(
            || WordLevels::new(8, 5, 3),
            |mut w| {
                for o in &lap {
                    black_box(w.push(o));
                }
                w
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn matching(c: &mut Criterion) {
    let mut g = c.benchmark_group("matching_per_lap");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(4));
    let histories: &[usize] = if full_run() { &[1, 10, 40] } else { &[1, 2] };
    let laps = observation_laps(histories[histories.len() - 1] + 1, 1, None);
    for levels in 1..=3 {
        let cfg = RecognizerConfig::default().with_levels(levels);
        for &history in histories {
            let mut m = WordMatcher::new(&cfg).unwrap();
            for lap in &laps[..history] {
                for o in lap {
                    m.push_observation(o);
                }
            }
            // The timed lap continues the last history lap.
            let next = observation_laps(1, 1000, laps[history - 1].last().copied()).remove(0);
            g.bench_function(format!("{levels}_levels/{history}_laps_history"), |b| {
                b.iter_batched(
                    || m.clone(),
                    |mut m| {
                        let mut pairs = 0;
                        for o in &next {
                            for mt in m.push_observation(o) {
                                pairs += mt.pair_count();
                            }
                        }
                        (m, pairs)
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

fn whole_recognizer(c: &mut Criterion) {
    let mut g = c.benchmark_group("recognizer_per_lap");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(5));
    let laps: Vec<Vec<(OdomPose, Scan)>> = (0..4).map(|s| lap_inputs(100 + s)).collect();
    // The default front end (the fast one of docs/design.md, "The front end's approximation":
    // every 4th beam a scan, every 2nd density ray), and the exact one (the authors').
    let exact = RecognizerConfig::default().with_exact_front_end();
    for (name, cfg) in [
        ("3_levels", RecognizerConfig::default()),
        ("3_levels_exact_front_end", exact),
    ] {
        let mut rec = Recognizer::new(cfg).unwrap();
        let mut done = 0usize;
        let histories: &[usize] = if full_run() { &[1, 40] } else { &[1, 2] };
        for &history in histories {
            while done < history {
                for (o, s) in &laps[done % laps.len()] {
                    rec.push(*o, s);
                }
                done += 1;
            }
            // Lap inputs restart at the same odometry: the loop is closed in odometry too.
            let next = &laps[history % laps.len()];
            one_lap_cpu(&rec, next, &format!("{name}/{history}_laps_history"));
            g.bench_function(format!("{name}/{history}_laps_history"), |b| {
                b.iter_batched(
                    || rec.clone(),
                    |mut r| {
                        let mut pairs = 0;
                        for (o, s) in next {
                            for mt in r.push(*o, s) {
                                pairs += mt.pair_count();
                            }
                        }
                        (r, pairs)
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

/// Prints one lap's thread CPU (clock_gettime, sub-microsecond), five times on clones of the
/// recognizer: criterion's figures are wall clock.
fn one_lap_cpu(rec: &Recognizer, next: &[(OdomPose, Scan)], name: &str) {
    let mut lap_ms = Vec::new();
    let mut pairs = 0usize;
    for _ in 0..if full_run() { 5 } else { 1 } {
        let mut r = rec.clone();
        let c1 = placewords::clock::thread_cpu_s();
        pairs = next
            .iter()
            .flat_map(|(o, s)| r.push(*o, s))
            .map(|m| m.pair_count())
            .sum();
        lap_ms.push((placewords::clock::thread_cpu_s() - c1) * 1e3);
    }
    let mean_ms = lap_ms.iter().sum::<f64>() / lap_ms.len() as f64;
    let min_ms = lap_ms.iter().copied().fold(f64::INFINITY, f64::min);
    eprintln!(
        "recognizer_per_lap/{name}: thread CPU per lap {mean_ms:.1} ms mean, {min_ms:.1} ms least of {} ({pairs} aligned pairs)",
        lap_ms.len()
    );
}

criterion_group!(benches, word_building, matching, whole_recognizer);
criterion_main!(benches);
