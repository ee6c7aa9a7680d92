//! Simulator benchmarks: one 181-beam scan on an institute-floor-sized world at both laser
//! presets, one simulation step (physics, controller, odometry, and a scan every other step),
//! and one full lap. Setup stays outside the timed part.
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
    for (name, preset) in [
        ("scan_181_lms200", LaserPreset::Lms200),
        ("scan_181_lms200_mm", LaserPreset::Lms200Mm),
    ] {
        let mut rng = stream(1, 0, 0, Purpose::LaserAngles);
        let laser = Laser::new(LaserConfig::preset(preset), &mut rng);
        let mut noise = stream(1, 0, 0, Purpose::LaserNoise);
        let mut ranges = Vec::with_capacity(181);
        let mut i = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                i = (i + 1) % poses.len();
                laser.exact_ranges(&caster, poses[i], &[], &mut ranges);
                laser.add_noise(&mut ranges, &mut noise);
                black_box(&ranges);
            })
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

criterion_group!(benches, bench_scan, bench_step, bench_lap);

fn main() {
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
