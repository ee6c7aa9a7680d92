//! Simulator benchmarks: one 181-beam scan on an institute-floor-sized world at both laser
//! presets, one simulation step (physics, controller, odometry, and a scan every other step),
//! and one full lap. Setup stays outside the timed part.
//!
//! The world is a stand-in generated here (a 2 m corridor loop of 184 m with 32 rooms on
//! both sides, each behind a door; about 380 outline segments) until `worlds/institute-floor.toml` lands.
//!
//! `PLACEWORDS_WRITE_STANDIN=DIR cargo bench --bench sim` writes the stand-in world and a
//! 40-lap scenario into DIR instead of benchmarking (for timing `placewords simulate`).

use criterion::{BatchSize, Criterion, criterion_group};
use placewords::geom::Pose2;
use placewords::sim::laser::{Laser, LaserConfig, LaserPreset};
use placewords::sim::rng::{Purpose, stream};
use placewords::sim::runner::RunSim;
use placewords::spec::scenario::{Scenario, parse_scenario};
use placewords::spec::world::parse_world;
use placewords::world::DoorStates;
use placewords::world::raycast::SweepCaster;
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;

/// A wall along one side of the corridor, from `a` to `b`, with door gaps of 0.9 m every
/// `spacing` metres; doors swing away from the corridor (`out` = unit normal into the rooms).
fn wall_with_doors(
    toml: &mut String,
    id: &str,
    a: (f64, f64),
    b: (f64, f64),
    spacing: f64,
    out: (f64, f64),
    rooms_to: f64,
) -> usize {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = (dx * dx + dy * dy).sqrt();
    let (ux, uy) = (dx / len, dy / len);
    let n = (len / spacing).floor() as usize;
    let mut start = 0.0;
    let mut doors = 0;
    let closed_deg = uy.atan2(ux).to_degrees();
    let open_deg = out.1.atan2(out.0).to_degrees();
    for k in 0..n {
        let gap = spacing * k as f64 + spacing / 2.0 - 0.45;
        let p0 = (a.0 + ux * start, a.1 + uy * start);
        let p1 = (a.0 + ux * gap, a.1 + uy * gap);
        let _ = writeln!(
            toml,
            "[[walls]]\nid = \"{id}-{k}\"\npoints_m = [[{:.3}, {:.3}], [{:.3}, {:.3}]]\n",
            p0.0, p0.1, p1.0, p1.1
        );
        let _ = writeln!(
            toml,
            "[[doors]]\nid = \"{id}-door-{k}\"\nhinge_m = [{:.3}, {:.3}]\nwidth_m = 0.9\nclosed_heading_deg = {closed_deg:.1}\nopen_heading_deg = {open_deg:.1}\n",
            p1.0, p1.1
        );
        doors += 1;
        // Partition between this room and the next, from the corridor wall to the rooms' far side.
        let wpos = spacing * (k + 1) as f64;
        if k + 1 < n {
            let q = (a.0 + ux * wpos, a.1 + uy * wpos);
            let _ = writeln!(
                toml,
                "[[walls]]\nid = \"{id}-part-{k}\"\npoints_m = [[{:.3}, {:.3}], [{:.3}, {:.3}]]\n",
                q.0,
                q.1,
                q.0 + out.0 * rooms_to,
                q.1 + out.1 * rooms_to
            );
        }
        start = gap + 0.9;
    }
    let p0 = (a.0 + ux * start, a.1 + uy * start);
    let _ = writeln!(
        toml,
        "[[walls]]\nid = \"{id}-end\"\npoints_m = [[{:.3}, {:.3}], [{:.3}, {:.3}]]\n",
        p0.0, p0.1, b.0, b.1
    );
    doors
}

/// The stand-in institute floor: building 72 × 48 m, corridor loop between (6, 6)-(66, 42) and
/// (8, 8)-(64, 40), rooms 6 m deep outside and 5 m deep inside, 10-16 m wide.
pub fn standin_world() -> String {
    let mut t = String::from(
        "format_version = 1\nname = \"institute-standin\"\n\n[robot_home]\nx_m = 7.0\ny_m = 7.0\nheading_deg = 0.0\n\n",
    );
    t.push_str("[[walls]]\nid = \"building\"\npoints_m = [[0.0, 0.0], [72.0, 0.0], [72.0, 48.0], [0.0, 48.0]]\nclosed = true\n\n");
    t.push_str("[[walls]]\nid = \"core\"\npoints_m = [[13.0, 13.0], [59.0, 13.0], [59.0, 35.0], [13.0, 35.0]]\nclosed = true\n\n");
    // Outer side of the corridor (rooms towards the building wall).
    wall_with_doors(
        &mut t,
        "os",
        (6.0, 6.0),
        (66.0, 6.0),
        10.0,
        (0.0, -1.0),
        6.0,
    );
    wall_with_doors(
        &mut t,
        "oe",
        (66.0, 6.0),
        (66.0, 42.0),
        12.0,
        (1.0, 0.0),
        6.0,
    );
    wall_with_doors(
        &mut t,
        "on",
        (66.0, 42.0),
        (6.0, 42.0),
        10.0,
        (0.0, 1.0),
        6.0,
    );
    wall_with_doors(
        &mut t,
        "ow",
        (6.0, 42.0),
        (6.0, 6.0),
        12.0,
        (-1.0, 0.0),
        6.0,
    );
    // Inner side (rooms towards the core).
    wall_with_doors(&mut t, "is", (8.0, 8.0), (64.0, 8.0), 14.0, (0.0, 1.0), 5.0);
    wall_with_doors(
        &mut t,
        "ie",
        (64.0, 8.0),
        (64.0, 40.0),
        16.0,
        (-1.0, 0.0),
        5.0,
    );
    wall_with_doors(
        &mut t,
        "in",
        (64.0, 40.0),
        (8.0, 40.0),
        14.0,
        (0.0, -1.0),
        5.0,
    );
    wall_with_doors(&mut t, "iw", (8.0, 40.0), (8.0, 8.0), 16.0, (1.0, 0.0), 5.0);
    t.push_str("[[routes]]\nid = \"loop\"\nwaypoints_m = [[7.0, 7.0], [65.0, 7.0], [65.0, 41.0], [7.0, 41.0]]\n\n");
    for (id, a, b) in [
        ("corridor-south", (8.5, 6.2), (63.5, 7.8)),
        ("corridor-north", (8.5, 40.2), (63.5, 41.8)),
        ("corridor-east", (64.2, 8.5), (65.8, 39.5)),
    ] {
        let _ = writeln!(
            t,
            "[[areas]]\nid = \"{id}\"\nmin_m = [{}, {}]\nmax_m = [{}, {}]\n",
            a.0, a.1, b.0, b.1
        );
    }
    t
}

/// A scenario on the stand-in: `runs` runs of `laps` laps from different corners, doors cycling.
pub fn standin_scenario(runs: usize, laps: usize) -> String {
    let mut s = String::from(
        "format_version = 1\nname = \"institute-standin\"\nworld = \"institute-standin.toml\"\nroute = \"loop\"\nseed = 7\n\n[door_configs]\nsouth-middle = [\"os-door-3\"]\nnorth-pair = [\"on-door-2\", \"in-door-1\"]\n\n[pedestrians]\ncount = 3\nareas = [\"corridor-south\", \"corridor-north\", \"corridor-east\"]\n\n",
    );
    for r in 0..runs {
        let _ = writeln!(
            s,
            "[[runs]]\nstart_waypoint = {}\nlaps = {laps}\ndoors_cycle = [\"all-closed\", \"south-middle\", \"north-pair\"]\n",
            r % 4
        );
    }
    s
}

fn scenario(runs: usize, laps: usize) -> Scenario {
    let world = standin_world();
    parse_scenario(
        &standin_scenario(runs, laps),
        Path::new("bench/institute-standin-scenario.toml"),
        &move |_p: &Path| parse_world(&world, "institute-standin.toml"),
    )
    .expect("stand-in scenario is valid")
}

fn bench_scan(c: &mut Criterion) {
    let scn = scenario(1, 1);
    let world = &scn.world;
    let caster = SweepCaster::for_world(world, &DoorStates::all_closed(world));
    eprintln!(
        "stand-in world: {} outline segments, {} doors, lap {:.1} m",
        caster.segment_count(),
        world.doors.len(),
        scn.route.length_m()
    );
    // Poses every 3 m along the route.
    let legs = scn.route.legs();
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
    let scn = scenario(1, 1);
    let mut sim = RunSim::new(&scn, 0);
    sim.begin_lap(0);
    c.bench_function("sim_step_physics_and_scan_every_other", |b| {
        b.iter(|| black_box(sim.step().expect("not blocked")))
    });
}

fn bench_lap(c: &mut Criterion) {
    let scn = scenario(1, 1);
    let mut g = c.benchmark_group("lap");
    g.sample_size(10);
    g.bench_function("full_lap_institute_standin", |b| {
        b.iter_batched(
            || RunSim::new(&scn, 0),
            |mut sim| black_box(sim.run_lap(0).expect("not blocked").frames.len()),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench_scan, bench_step, bench_lap);

fn main() {
    if let Some(dir) = std::env::var_os("PLACEWORDS_WRITE_STANDIN") {
        let dir = Path::new(&dir);
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join("institute-standin.toml"), standin_world()).unwrap();
        std::fs::write(dir.join("standin-40x1.toml"), standin_scenario(1, 40)).unwrap();
        std::fs::write(dir.join("standin-4x10.toml"), standin_scenario(4, 10)).unwrap();
        eprintln!(
            "wrote the stand-in world and scenarios into {}",
            dir.display()
        );
        return;
    }
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
