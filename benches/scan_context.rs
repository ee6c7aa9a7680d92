//! The Scan Context baseline's cost per lap as its history grows: one lap of scenario B (the
//! simulator's laps of `worlds/institute-floor.toml`, seed 1) fed after 1 and after 40 laps of
//! history. Simulation and the history are setup, outside the timed part; each sample feeds
//! the lap to a copy of the recognizer holding the history. Figures and the machine are in
//! BENCHMARKS.md.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use placewords::baseline::scan_context::{ScanContextConfig, ScanContextRecognizer};
use placewords::experiment::{ExperimentOptions, load_scenario, simulate};
use placewords::log::{LapLog, RunLog};
use placewords::place::PlaceRecognizer;
use std::path::Path;
use std::time::Duration;

/// `cargo bench` passes `--bench`; without it (`cargo test --benches`) each runs once, with a
/// short history.
fn full_run() -> bool {
    std::env::args().any(|a| a == "--bench")
}

/// Scenario B at seed 1 with `laps_per_run` laps in each of its 4 runs.
fn runs(laps_per_run: usize) -> Vec<RunLog> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/B.toml");
    let mut scn = load_scenario(&path).expect("scenarios/B.toml is valid");
    scn.sim.seed = 1;
    let opts = ExperimentOptions {
        laps: Some(laps_per_run),
        ..ExperimentOptions::default()
    };
    simulate(&scn, &opts).expect("B simulates").0
}

/// Feeds `lap` (of run `run`) to `rec`, starting a run when it changes; returns the pairs
/// matched. Frame ids count on from `first_frame`.
fn feed(
    rec: &mut ScanContextRecognizer,
    (run, lap): (usize, &LapLog),
    last_run: &mut Option<usize>,
    first_frame: usize,
) -> usize {
    let mut pairs = 0;
    if *last_run != Some(run) {
        rec.start_run();
        *last_run = Some(run);
    }
    for (i, f) in lap.frames.iter().enumerate() {
        pairs += rec
            .push(first_frame + i, f.odom, &f.scan)
            .iter()
            .map(|m| m.pair_count())
            .sum::<usize>();
    }
    pairs
}

fn per_lap(c: &mut Criterion) {
    let histories: &[usize] = if full_run() { &[1, 40] } else { &[1] };
    let last = *histories.last().expect("a history");
    // 4 runs of enough laps that lap `last` follows the history within a run.
    let runs = runs(last / 4 + 2);
    let laps: Vec<(usize, &LapLog)> = runs
        .iter()
        .flat_map(|r| r.laps.iter().map(move |l| (r.run, l)))
        .collect();
    let mut g = c.benchmark_group("scan_context_per_lap");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(20));
    let cfg = ScanContextConfig::default();
    let mut rec = ScanContextRecognizer::new(cfg).expect("the defaults are valid");
    let (mut done, mut frames, mut last_run) = (0usize, 0usize, None);
    for &history in histories {
        while done < history {
            feed(&mut rec, laps[done], &mut last_run, frames);
            frames += laps[done].1.frames.len();
            done += 1;
        }
        let next = laps[history];
        g.bench_function(format!("{history}_laps_history"), |b| {
            b.iter_batched(
                || (rec.clone(), last_run),
                |(mut r, mut lr)| {
                    let pairs = feed(&mut r, next, &mut lr, frames);
                    (r, pairs)
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, per_lap);
criterion_main!(benches);
