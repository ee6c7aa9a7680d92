//! Simulator benchmarks: one 181-beam scan on an institute-floor-sized world at both laser
//! presets (and the `lms200` scan again timed by the thread's CPU clock, `_cpu`: on a shared
//! machine wall clock counts the waits for a core), one simulation step (physics, controller, odometry, and a scan every other step),
//! and one full lap; writing and reading one lap as a lap cache entry (`io::lap_file`). Setup
//! stays outside the timed part.
//!
//! The world is `worlds/institute-floor.toml` through `scenarios/B.toml`.

use criterion::{BatchSize, Criterion, criterion_group};
use placewords::experiment::{Scenario, load_scenario};
use placewords::geom::Pose2;
use placewords::sim::laser::{Laser, LaserConfig, LaserPreset};
use placewords::sim::rng::{Purpose, stream};
use placewords::sim::runner::RunSim;
use placewords::world::DoorStates;
use placewords::world::raycast::SweepCaster;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

/// Scenario B on `worlds/institute-floor.toml` (the shipped floor: 180 m lap, 77 doors).
fn scenario() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/B.toml");
    load_scenario(&path).expect("scenarios/B.toml is valid")
}

fn bench_scan(c: &mut Criterion) {
    let scn = scenario();
    let world = &scn.sim.world;
    let caster = SweepCaster::for_world(world, &DoorStates::all_closed(world));
    eprintln!(
        "institute-floor: {} outline segments, {} doors, lap {:.1} m",
        caster.segment_count(),
        world.doors.len(),
        scn.sim.route.length_m()
    );
    // Poses every 3 m along the route.
    let legs = scn.sim.route.legs();
    let mut poses = Vec::new();
    for l in &legs {
        let d = l.b - l.a;
        let th = d.y.atan2(d.x);
        let n = (l.length() / 3.0) as usize;
        for k in 0..n {
            let p = l.a + d * (k as f64 / n as f64);
            poses.push(Pose2::new(p.x, p.y, th));
        }
    }
    for (name, preset, cpu) in [
        ("scan_181_lms200", LaserPreset::Lms200, false),
        ("scan_181_lms200_mm", LaserPreset::Lms200Mm, false),
        ("scan_181_lms200_cpu", LaserPreset::Lms200, true),
    ] {
        let mut rng = stream(1, 0, 0, Purpose::LaserAngles);
        let laser = Laser::new(LaserConfig::preset(preset), &mut rng);
        let mut noise = stream(1, 0, 0, Purpose::LaserNoise);
        let mut ranges = Vec::with_capacity(181);
        let mut i = 0;
        let mut scan = || {
            i = (i + 1) % poses.len();
            laser.exact_ranges(&caster, poses[i], &[], &mut ranges);
            laser.add_noise(&mut ranges, &mut noise);
            black_box(&ranges);
        };
        c.bench_function(name, |b| {
            if cpu {
                // Not under valgrind: rustix's vDSO lookup for the CPU clock crashes there.
                b.iter_custom(|n| {
                    let t0 = placewords::clock::thread_cpu_s();
                    (0..n).for_each(|_| scan());
                    Duration::from_secs_f64(placewords::clock::thread_cpu_s() - t0)
                })
            } else {
                b.iter(&mut scan)
            }
        });
    }
}

fn bench_step(c: &mut Criterion) {
    let scn = scenario();
    let mut sim = RunSim::new(&scn.sim, 0);
    sim.begin_lap(0);
    c.bench_function("sim_step_physics_and_scan_every_other", |b| {
        b.iter(|| black_box(sim.step().expect("not blocked")))
    });
}

fn bench_lap(c: &mut Criterion) {
    let scn = scenario();
    let mut g = c.benchmark_group("lap");
    g.sample_size(10);
    g.bench_function("full_lap_institute_floor", |b| {
        b.iter_batched(
            || RunSim::new(&scn.sim, 0),
            |mut sim| black_box(sim.run_lap(0).expect("not blocked").frames.len()),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

/// One lap of the institute floor stored in and read from a lap cache entry (in memory).
fn bench_lap_file(c: &mut Criterion) {
    use placewords::io::lap_file::{LapFileReader, LapFileWriter};
    let scn = scenario();
    let lap = RunSim::new(&scn.sim, 0).run_lap(0).expect("not blocked");
    let key = "0".repeat(64);
    let write = || {
        let mut w = LapFileWriter::new(Vec::new(), &key, &[1]).expect("in memory");
        w.push(0, &lap).expect("in memory");
        w.finish().expect("in memory")
    };
    let bytes = write();
    eprintln!(
        "lap file: {} frames, {} bytes ({:.0} % of the ranges' 8 bytes each)",
        lap.frames.len(),
        bytes.len(),
        100.0 * bytes.len() as f64
            / (8 * lap
                .frames
                .iter()
                .map(|f| f.scan.ranges_m.len())
                .sum::<usize>()) as f64
    );
    let mut g = c.benchmark_group("lap_file");
    g.sample_size(10);
    g.bench_function("write_one_lap_institute_floor", |b| {
        b.iter(|| black_box(write().len()))
    });
    g.bench_function("read_one_lap_institute_floor", |b| {
        b.iter(|| {
            let r = LapFileReader::open(&bytes[..], bytes.len() as u64).expect("intact");
            black_box(r.read_runs().expect("intact").len())
        })
    });
    g.finish();
}

criterion_group!(benches, bench_scan, bench_step, bench_lap, bench_lap_file);

fn main() {
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
