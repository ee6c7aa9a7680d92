//! Front-end costs, apart from the rest of the recognizer so that a profiler or callgrind sees
//! only them: grid update per scan, density Ψ per observation, and the whole front end for one
//! lap of the synthetic loop floor (5000 scans, ~2000 observations; see `tests/support/synth.rs`).
//! Setup is outside the timed part. Without `--bench` (`cargo test --benches`, CI, callgrind)
//! criterion runs each benchmark once. Times are the thread's CPU time (`ThreadCpu`), not wall
//! clock: on a shared machine wall clock counts the waits for a core. Figures and the machine
//! are in BENCHMARKS.md.

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use placewords::geom::OdomPose;
#[path = "../tests/support/synth.rs"]
mod synth;
use placewords::recognizer::{DensityFrontEnd, DensityKernel, LocalGrid, RecognizerConfig};
use placewords::scan::Scan;
use std::hint::black_box;
use std::time::Duration;
use synth::{LoopFloor, SplitMix};

/// The calling thread's CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), in nanoseconds;
/// wall clock when `FRONT_END_BENCH_WALL_CLOCK` is set: under valgrind (callgrind's instruction
/// counts), rustix's vDSO lookup for the CPU clock reads past valgrind's vDSO and crashes.
struct ThreadCpu;

/// Seconds on the clock `ThreadCpu` reads.
fn clock_s() -> f64 {
    static WALL: std::sync::OnceLock<Option<std::time::Instant>> = std::sync::OnceLock::new();
    match WALL.get_or_init(|| {
        std::env::var_os("FRONT_END_BENCH_WALL_CLOCK").map(|_| std::time::Instant::now())
    }) {
        Some(origin) => origin.elapsed().as_secs_f64(),
        None => placewords::clock::thread_cpu_s(),
    }
}

impl Measurement for ThreadCpu {
    type Intermediate = f64;
    type Value = f64;
    fn start(&self) -> f64 {
        clock_s()
    }
    fn end(&self, started_s: f64) -> f64 {
        (clock_s() - started_s) * 1e9
    }
    fn add(&self, a: &f64, b: &f64) -> f64 {
        a + b
    }
    fn zero(&self) -> f64 {
        0.0
    }
    fn to_f64(&self, ns: &f64) -> f64 {
        *ns
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

/// Nanoseconds shown in the unit that suits them.
struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, typical_ns: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = if typical_ns < 1e3 {
            (1.0, "ns")
        } else if typical_ns < 1e6 {
            (1e-3, "µs")
        } else {
            (1e-6, "ms")
        };
        values.iter_mut().for_each(|v| *v *= factor);
        unit
    }
    fn scale_throughputs(&self, _: f64, _: &Throughput, _: &mut [f64]) -> &'static str {
        "(no throughput)"
    }
    fn scale_for_machines(&self, _: &mut [f64]) -> &'static str {
        "ns"
    }
}

/// One lap of (odometry, scan) on the 200 m loop floor, doors drawn from `seed`.
fn lap_inputs(seed: u64) -> Vec<(OdomPose, Scan)> {
    let floor = LoopFloor::institute();
    let mut r = SplitMix::new(seed);
    let open: Vec<bool> = (0..floor.door_count()).map(|_| r.unit() < 0.3).collect();
    floor.lap_inputs(&open, &synth::lms200())
}

fn front_end(c: &mut Criterion<ThreadCpu>) {
    let cfg = RecognizerConfig::default();
    let inputs = lap_inputs(1);
    let mut g = c.benchmark_group("front_end");
    g.measurement_time(Duration::from_secs(3));

    let mut grid = LocalGrid::new(cfg.grid.grid_cell_m, cfg.grid.grid_radius_m);
    let mut i = 0usize;
    g.bench_function("grid_update_per_scan_181_beams", |b| {
        b.iter(|| {
            let (o, s) = &inputs[i % inputs.len()];
            grid.integrate(o, s);
            i += 1;
        })
    });

    // A grid as the robot has it in the middle of the lap.
    let kernel = DensityKernel::new(cfg.kernel_radius_cells(), cfg.density.ray_step_deg);
    let mut grid = LocalGrid::new(cfg.grid.grid_cell_m, cfg.grid.grid_radius_m);
    let deltas = kernel.deltas(grid.side());
    let mid = inputs.len() / 3;
    for (o, s) in &inputs[mid - 100..mid] {
        grid.integrate(o, s);
    }
    let at = inputs[mid - 1].0.0;
    g.bench_function("density_per_observation_2.5m_1deg", |b| {
        b.iter(|| black_box(grid.psi_at(&kernel, &deltas, at.x, at.y)))
    });

    g.sample_size(10);
    // The default front end (the fast one of docs/design.md, "The front end's approximation":
    // every 4th beam a scan, every 2nd density ray) and the exact one (the authors').
    let exact = cfg.clone().with_exact_front_end();
    for (name, cfg) in [
        ("front_end_per_lap_5000_scans", &cfg),
        ("exact_front_end_per_lap_5000_scans", &exact),
    ] {
        g.bench_function(name, |b| {
            b.iter_batched(
                || DensityFrontEnd::new(cfg).unwrap(),
                |mut fe| {
                    let mut n = 0;
                    for (o, s) in &inputs {
                        n += fe.push(*o, s).len();
                    }
                    n
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = front_end
}
criterion_main!(benches);
