//! The recognizer's back end (words, matching, alignment, verification) on one lap of the
//! recognizer bench's input (`benches/recognizer.rs`, `recognizer_per_lap/3_levels/40_laps_history`)
//! after 40 laps of history, apart from the front end: the observations of all 41 laps are made
//! first, then 40 laps are matched and the 41st is timed (thread CPU) in `back_end_lap`, which
//! callgrind can count alone:
//!
//! ```text
//! cargo build --release --example back_end_lap
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*back_end_lap*' \
//!     target/release/examples/back_end_lap 0
//! ```
//!
//! The argument is how many times the lap is timed (default 5); 0 runs it once untimed, for
//! valgrind, under which rustix's vDSO lookup for the thread CPU clock crashes.

use placewords::geom::OdomPose;
use placewords::recognizer::{DensityFrontEnd, DensityObservation, RecognizerConfig, WordMatcher};
use placewords::scan::Scan;
use std::hint::black_box;
#[path = "../tests/support/synth.rs"]
mod synth;
use synth::{LoopFloor, SplitMix};

const HISTORY_LAPS: usize = 40;

/// One lap of (odometry, scan) on the 200 m loop floor, doors drawn from `seed` (as the bench).
fn lap_inputs(seed: u64) -> Vec<(OdomPose, Scan)> {
    let floor = LoopFloor::institute();
    let mut r = SplitMix::new(seed);
    let open: Vec<bool> = (0..floor.door_count()).map(|_| r.unit() < 0.3).collect();
    floor.lap_inputs(&open, &synth::lms200())
}

/// The timed lap: every observation through the matcher; the aligned pairs it reports.
#[inline(never)]
fn back_end_lap(m: &mut WordMatcher, lap: &[DensityObservation]) -> usize {
    lap.iter()
        .flat_map(|o| m.push_observation(o))
        .map(|mt| mt.pair_count())
        .sum()
}

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let cfg = RecognizerConfig::default();
    let inputs: Vec<Vec<(OdomPose, Scan)>> = (0..4).map(|s| lap_inputs(100 + s)).collect();
    let mut front = DensityFrontEnd::new(&cfg).unwrap();
    let laps: Vec<Vec<DensityObservation>> = (0..=HISTORY_LAPS)
        .map(|i| {
            inputs[i % inputs.len()]
                .iter()
                .flat_map(|(o, s)| front.push(*o, s))
                .collect()
        })
        .collect();
    let mut m = WordMatcher::new(&cfg).unwrap();
    for lap in &laps[..HISTORY_LAPS] {
        for o in lap {
            black_box(m.push_observation(o));
        }
    }
    if repeats == 0 {
        let pairs = back_end_lap(&mut m.clone(), &laps[HISTORY_LAPS]);
        println!("back end, lap {}: {pairs} aligned pairs", HISTORY_LAPS + 1);
        return;
    }
    let mut lap_ms = Vec::new();
    let mut pairs = 0;
    for _ in 0..repeats {
        let mut r = m.clone();
        let c0 = placewords::clock::thread_cpu_s();
        pairs = back_end_lap(&mut r, &laps[HISTORY_LAPS]);
        lap_ms.push((placewords::clock::thread_cpu_s() - c0) * 1e3);
    }
    let mean = lap_ms.iter().sum::<f64>() / lap_ms.len().max(1) as f64;
    let least = lap_ms.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "back end, lap {} after {HISTORY_LAPS}: thread CPU {mean:.2} ms mean, {least:.2} ms least of {repeats} ({} observations, {pairs} aligned pairs)",
        HISTORY_LAPS + 1,
        laps[HISTORY_LAPS].len()
    );
}
