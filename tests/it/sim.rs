//! The simulator: laser geometry, doors, people, odometry statistics, determinism, located
//! scenario errors, the golden digest and the `simulate` command.

use super::common::root;
use placewords::experiment::{Scenario, load_scenario, parse_scenario};
use placewords::geom::{Pose2, Segment, Vec2};
use placewords::sim::laser::{Laser, LaserConfig, LaserPreset};
use placewords::sim::logs::carmen_log;
use placewords::sim::{RunLog, SimError, simulate};
use placewords::spec::SpecError;
use placewords::world::parse_world;
use placewords::world::raycast::{Disc, SweepCaster};
use placewords::world::{DoorStates, World};
use proptest::prelude::*;
use std::path::Path;

/// The small loop as these tests know it (a copy, so that edits to `worlds/` do not move the
/// geometry the assertions rely on): 20 × 8 m, corridors 2 m wide, doors `d-south` (hinge
/// (5, 2), closed along +x, opens to +y) and `d-north`, route `lap`.
const LOOP_WORLD: &str = r#"format_version = 1
name = "loop-small"

[robot_home]
x_m = 1.0
y_m = 1.0
heading_deg = 0.0

[[walls]]
id = "outer"
points_m = [[0.0, 0.0], [20.0, 0.0], [20.0, 8.0], [0.0, 8.0]]
closed = true

[[walls]]
id = "inner-south-east"
points_m = [[5.9, 2.0], [18.0, 2.0], [18.0, 6.0], [12.9, 6.0]]

[[walls]]
id = "inner-north-west"
points_m = [[12.0, 6.0], [2.0, 6.0], [2.0, 2.0], [5.0, 2.0]]

[[doors]]
id = "d-south"
hinge_m = [5.0, 2.0]
width_m = 0.9
closed_heading_deg = 0.0
open_heading_deg = 90.0

[[doors]]
id = "d-north"
hinge_m = [12.9, 6.0]
width_m = 0.9
closed_heading_deg = 180.0
open_heading_deg = 270.0

[[routes]]
id = "lap"
waypoints_m = [[1.0, 1.0], [19.0, 1.0], [19.0, 7.0], [1.0, 7.0]]
"#;

fn loop_small() -> World {
    parse_world(LOOP_WORLD, "loop-small.toml").unwrap()
}

/// A scenario over an in-memory world.
fn scenario(world_toml: &str, scenario_toml: &str) -> Result<Scenario, SpecError> {
    let w = world_toml.to_string();
    parse_scenario(
        scenario_toml,
        Path::new("mem/test.toml"),
        &move |_p: &Path, _c: &placewords::world::WorldCheck| parse_world(&w, "mem/world.toml"),
    )
}

/// A world built from its file without validation: for geometry the validator would refuse on
/// purpose (a bare corridor without a route, a door that blocks the route).
fn unchecked_world(src: &str) -> World {
    let spec: placewords::spec::world::WorldSpec = toml::from_str(src).unwrap();
    World::from_spec(&spec)
}

fn exact_laser(preset: LaserPreset) -> Laser {
    let cfg = LaserConfig {
        angle_error_rad: 0.0,
        range_noise_m: 0.0,
        ..LaserConfig::preset(preset)
    };
    Laser::with_angle_errors(cfg, vec![])
}

fn fnv1a(bytes: &[u8], mut h: u64) -> u64 {
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}

fn digest(scn: &Scenario, runs: &[RunLog]) -> String {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for r in runs {
        h = fnv1a(carmen_log(&scn.sim, r).as_bytes(), h);
    }
    format!("{h:016x}")
}

const CORRIDOR: &str = r#"
format_version = 1
name = "corridor"
[robot_home]
x_m = 0.0
y_m = 0.0
[[walls]]
id = "north"
points_m = [[-20.0, 1.0], [20.0, 1.0]]
[[walls]]
id = "south"
points_m = [[-20.0, -1.0], [20.0, -1.0]]
"#;

/// Beams in a straight corridor (walls' faces at y = ±0.95) hit where trigonometry says.
#[test]
fn scan_in_a_known_corridor_matches_analytic_distances() {
    let world = unchecked_world(CORRIDOR);
    let caster = SweepCaster::for_world(&world, &DoorStates::all_closed(&world));
    let laser = exact_laser(LaserPreset::Lms200);
    let robot = Pose2::new(0.0, 0.2, 0.0);
    let mut ranges = Vec::new();
    laser.exact_ranges(&caster, robot, &[], &mut ranges);
    assert_eq!(ranges.len(), 181);
    let sensor = Vec2::new(0.021, 0.2);
    for (i, r) in ranges.iter().enumerate() {
        let a = laser.layout().beam_angle_rad(i);
        let (s, c) = a.sin_cos();
        let mut exact = f64::INFINITY;
        if s > 1e-9 {
            exact = (0.95 - sensor.y) / s;
        } else if s < -1e-9 {
            exact = (-0.95 - sensor.y) / s;
        }
        // Beyond the corridor's ends (x = ±20) the wall stops: the end caps of the wall
        // rectangles are hit instead; only check beams that land on the long faces.
        let x = sensor.x + exact * c;
        if exact.is_finite() && x.abs() < 19.9 && exact < 32.767 {
            assert!((r - exact).abs() < 0.01, "beam {i}: {r} vs {exact}");
        }
    }
    // Straight ahead: 20 m to the end of the wall ... past it nothing: no return.
    assert_eq!(ranges[90], 32.767);
}

/// Opening a door changes exactly the beams that pass through its doorway.
#[test]
fn opening_a_door_changes_only_the_beams_through_its_doorway() {
    let world = loop_small();
    let d = world.door_index("d-south").unwrap();
    let closed = DoorStates::all_closed(&world);
    let mut open = closed.clone();
    open.open[d] = true;
    let laser = exact_laser(LaserPreset::Lms200);
    // In the south corridor, below the door (x 5..5.9 on y = 2), facing east.
    let robot = Pose2::new(4.0, 1.0, 0.0);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    laser.exact_ranges(&SweepCaster::for_world(&world, &closed), robot, &[], &mut a);
    laser.exact_ranges(&SweepCaster::for_world(&world, &open), robot, &[], &mut b);
    let sensor = laser.sensor_pose(robot);
    let doorway = Segment::new(Vec2::new(5.0, 1.95), Vec2::new(5.9, 1.95));
    let mut changed = 0;
    for i in 0..181 {
        let ang = sensor.theta + laser.layout().beam_angle_rad(i);
        let hit = sensor.position() + Vec2::new(ang.cos(), ang.sin()) * a[i];
        let through = doorway.distance_to_point(hit) < 0.1 + 1e-9 && hit.y > 1.9;
        if a[i] != b[i] {
            changed += 1;
            assert!(
                through,
                "beam {i} changed ({} -> {}) but its hit {hit:?} is not in the doorway",
                a[i], b[i]
            );
            assert!(
                b[i] > a[i],
                "beam {i} got shorter through an opened doorway"
            );
        } else {
            assert!(!through || (b[i] - a[i]).abs() < 1e-12, "beam {i}");
        }
    }
    assert!(changed >= 3, "only {changed} beams saw through the doorway");
}

/// A person in front of the laser shortens the beams that hit them.
#[test]
fn pedestrians_show_up_in_scans() {
    let world = unchecked_world(CORRIDOR);
    let caster = SweepCaster::for_world(&world, &DoorStates::all_closed(&world));
    let laser = exact_laser(LaserPreset::Lms200);
    let disc = Disc {
        centre: Vec2::new(3.0, 0.0),
        radius_m: 0.2,
    };
    let (mut r, mut bare) = (Vec::new(), Vec::new());
    laser.exact_ranges(&caster, Pose2::IDENTITY, &[disc], &mut r);
    laser.exact_ranges(&caster, Pose2::IDENTITY, &[], &mut bare);
    assert!((r[90] - (3.0 - 0.2 - 0.021)).abs() < 1e-9, "{}", r[90]);
    let blocked = r.iter().zip(&bare).filter(|(a, b)| a < b).count();
    assert!(
        (6..=10).contains(&blocked),
        "{blocked} beams on a 0.4 m person at 3 m"
    );
}

/// In a simulation with people walking the robot's corridor, some laser hits are explained by
/// no wall or door.
#[test]
fn pedestrians_show_up_in_simulated_scans() {
    let scn = scenario(
        LOOP_WORLD,
        r#"
format_version = 1
world = "w.toml"
route = "lap"
seed = 3
[[runs]]
laps = 1
[pedestrians]
count = 2
paths_m = [[[3.0, 0.6], [17.0, 0.6]], [[19.4, 1.0], [19.4, 7.0]]]
"#,
    )
    .unwrap();
    let runs = simulate(&scn.sim, None, &|| {}).unwrap();
    let outline = scn
        .sim
        .world
        .obstacle_outline(&DoorStates::all_closed(&scn.sim.world));
    let mut unexplained = 0;
    for f in runs[0].frames() {
        let sensor = Pose2::new(
            f.truth.0.x + 0.021 * f.truth.0.theta.cos(),
            f.truth.0.y + 0.021 * f.truth.0.theta.sin(),
            f.truth.0.theta,
        );
        for i in 0..181 {
            if !f.scan.is_hit(i) {
                continue;
            }
            let a = sensor.theta + f.scan.layout.beam_angle_rad(i);
            let p = sensor.position() + Vec2::new(a.cos(), a.sin()) * f.scan.ranges_m[i];
            let d = outline
                .iter()
                .map(|s| s.distance_to_point(p))
                .fold(f64::INFINITY, f64::min);
            if d > 0.1 {
                unexplained += 1;
            }
        }
    }
    assert!(unexplained > 100, "only {unexplained} hits off the walls");
}

/// The controller keeps the robot's body off the walls all round the small loop, and a person
/// walking on the route makes it stop and wait, then carry on.
#[test]
fn the_robot_keeps_off_walls_and_waits_for_people() {
    let world = LOOP_WORLD.to_string();
    let base = "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 5\n[[runs]]\nlaps = 2\ndoors = \"all-open\"\n";
    let scn = scenario(&world, base).unwrap();
    let mut sim = placewords::sim::runner::RunSim::new(&scn.sim, 0);
    for lap in 0..2 {
        sim.run_lap(lap).unwrap();
    }
    assert_eq!(sim.contact_steps(), 0, "the robot touched a wall or door");

    let scn = scenario(
        &world,
        &format!("{base}[pedestrians]\ncount = 1\npaths_m = [[[4.0, 1.0], [17.0, 1.0]]]\nspeed_min_m_s = 0.5\nspeed_max_m_s = 0.5\n"),
    )
    .unwrap();
    let runs = simulate(&scn.sim, Some(1), &|| {}).unwrap();
    let frames: Vec<_> = runs[0].frames().collect();
    let stopped = frames
        .windows(2)
        .filter(|w| w[0].time_s > 3.0 && w[0].truth.0.distance(&w[1].truth.0) < 1e-3)
        .count();
    assert!(
        stopped >= 5,
        "the robot never waited ({stopped} still frames)"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Ranges are never NaN, never negative and never beyond the maximum range, wherever the
    /// robot is (inside walls too) and whoever stands around.
    #[test]
    fn ranges_stay_within_zero_and_max(x in -2.0f64..22.0, y in -2.0f64..10.0, th in -4.0f64..4.0,
                                       px in 0.0f64..20.0, py in 0.0f64..8.0, mm in any::<bool>(), seed in 0u64..1000) {
        let world = loop_small();
        let caster = SweepCaster::for_world(&world, &DoorStates::all_open(&world));
        let preset = if mm { LaserPreset::Lms200Mm } else { LaserPreset::Lms200 };
        let mut rng = placewords::sim::rng::stream(seed, 0, 0, placewords::sim::rng::Purpose::LaserNoise);
        let laser = Laser::new(LaserConfig::preset(preset), &mut rng);
        let disc = Disc { centre: Vec2::new(px, py), radius_m: 0.2 };
        let scan = laser.scan(&caster, Pose2::new(x, y, th), &[disc], &mut rng, 0.0);
        let max = laser.config.max_range_m;
        prop_assert_eq!(scan.ranges_m.len(), 181);
        for r in &scan.ranges_m {
            prop_assert!(!r.is_nan() && *r >= 0.0 && *r <= max, "range {}", r);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]
    /// Culling the faces seen from inside a solid changes no range for a sensor in free space.
    #[test]
    fn face_culling_changes_no_range(x in 0.3f64..19.7, y in 0.3f64..7.7, th in -4.0f64..4.0, doors in 0usize..4) {
        let world = loop_small();
        let st = DoorStates { open: vec![doors & 1 == 1, doors & 2 == 2] };
        let outline = world.obstacle_outline(&st);
        let sensor = Vec2::new(x, y);
        prop_assume!(outline.iter().all(|s| s.distance_to_point(sensor) > 0.1));
        let laser = exact_laser(LaserPreset::Lms200);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let pose = Pose2::new(x - 0.021 * th.cos(), y - 0.021 * th.sin(), th);
        laser.exact_ranges(&SweepCaster::for_world(&world, &st), pose, &[], &mut a);
        laser.exact_ranges(&SweepCaster::new(&outline), pose, &[], &mut b);
        prop_assert_eq!(&a, &b);
        // And both agree with a brute-force cast of every beam against every segment.
        let s = laser.sensor_pose(pose);
        for (i, got) in a.iter().enumerate() {
            let ang = s.theta + laser.layout().beam_angle_rad(i);
            let want = brute_force_range(s.position(), Vec2::new(ang.cos(), ang.sin()), &outline, 32.767);
            prop_assert!((got - want).abs() < 1e-9, "beam {}: sweep {} vs brute force {}", i, got, want);
        }
    }
}

fn brute_force_range(o: Vec2, d: Vec2, segs: &[Segment], max: f64) -> f64 {
    let mut best = max;
    for s in segs {
        let e = s.b - s.a;
        let p = s.a - o;
        let denom = d.x * e.y - d.y * e.x;
        if denom == 0.0 {
            continue;
        }
        let t = (p.x * e.y - p.y * e.x) / denom;
        let u = (p.x * d.y - p.y * d.x) / denom;
        if t > 0.0 && (0.0..=1.0).contains(&u) && t < best {
            best = t;
        }
    }
    best
}

const TINY_LOOP: &str = r#"
format_version = 1
name = "tiny"
[robot_home]
x_m = 1.0
y_m = 1.0
[[walls]]
id = "outer"
points_m = [[0.0, 0.0], [9.0, 0.0], [9.0, 6.0], [0.0, 6.0]]
closed = true
[[walls]]
id = "inner"
points_m = [[2.0, 2.0], [7.0, 2.0], [7.0, 4.0], [2.0, 4.0]]
closed = true
[[routes]]
id = "lap"
waypoints_m = [[1.0, 1.0], [8.0, 1.0], [8.0, 5.0], [1.0, 5.0]]
"#;

fn stats(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
    )
}

/// Over 400 laps, per-lap odometry errors in distance and turned angle have the configured
/// bias and spread (within 10 %), for the random-walk form of the proportional model (the
/// each-update form is checked in `sim::odometry`'s unit tests).
#[test]
fn odometry_error_statistics_over_many_laps_match_the_model() {
    let runs: String = (0..80).map(|_| "[[runs]]\nlaps = 5\n").collect();
    let scn = scenario(
        TINY_LOOP,
        &format!(
            r#"
format_version = 1
world = "w.toml"
route = "lap"
seed = 11
[odometry]
model = "proportional"
proportional_error = "random-walk"
translation_error_ratio = 0.0075
rotation_error_ratio = 0.0075
wheel_radius_bias_ratio = 0.02
[laser]
preset = "lms200-mm"
{runs}"#
        ),
    )
    .unwrap();
    let logs = simulate(&scn.sim, None, &|| {}).unwrap();
    let (mut scale, mut z_trans, mut z_rot) = (Vec::new(), Vec::new(), Vec::new());
    for lap in logs.iter().flat_map(|r| r.laps.iter()) {
        let (mut lt, mut lo, mut tt, mut to, mut turned) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for w in lap.frames.windows(2) {
            let (t0, t1) = (w[0].truth.0, w[1].truth.0);
            let (o0, o1) = (w[0].odom.0, w[1].odom.0);
            lt += t0.distance(&t1);
            lo += o0.distance(&o1);
            let dt = placewords::geom::wrap_angle(t1.theta - t0.theta);
            tt += dt;
            turned += dt.abs();
            to += placewords::geom::wrap_angle(o1.theta - o0.theta);
        }
        scale.push(lo / lt - 1.0);
        z_trans.push((lo - 1.02 * lt) / (0.0075 * (1.02 * lt).sqrt()));
        z_rot.push((to - 1.02 * tt) / (0.0075 * (1.02 * turned).sqrt()));
    }
    assert_eq!(scale.len(), 400);
    let (m, _) = stats(&scale);
    assert!(
        (m / 0.02 - 1.0).abs() < 0.1,
        "mean scale error {m}, configured 0.02"
    );
    let (zm, zs) = stats(&z_trans);
    assert!(
        zm.abs() < 0.1 * 2.0 && (zs - 1.0).abs() < 0.1,
        "translation z: mean {zm}, sd {zs}"
    );
    let (rm, rs) = stats(&z_rot);
    eprintln!("translation z {zm} {zs}; rotation z {rm} {rs}");
    assert!(
        rm.abs() < 0.2 && (rs - 1.0).abs() < 0.1,
        "rotation z: mean {rm}, sd {rs}"
    );
}

/// Same seed, same logs, whether rayon has 1 or 2 threads.
#[test]
fn same_seed_gives_identical_runs_with_one_and_two_threads() {
    let scn = load_scenario(&root().join("scenarios/smoke.toml")).unwrap();
    let run_with = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| simulate(&scn.sim, Some(1), &|| {}).unwrap())
    };
    let one = run_with(1);
    let two = run_with(2);
    assert_eq!(one, two);
    assert_eq!(digest(&scn, &one), digest(&scn, &two));
}

/// The smoke scenario's logs hash to the stored digest. After an intended change to the
/// simulation, re-mint with `PLACEWORDS_REMINT=1 cargo test --release sim::golden`.
#[test]
fn golden_digest_of_the_smoke_scenario() {
    let scn = load_scenario(&root().join("scenarios/smoke.toml")).unwrap();
    let runs = simulate(&scn.sim, None, &|| {}).unwrap();
    let got = digest(&scn, &runs);
    let file = root().join("tests/golden/sim-smoke.digest");
    if std::env::var_os("PLACEWORDS_REMINT").is_some() {
        std::fs::write(&file, format!("{got}\n")).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&file).unwrap_or_default();
    assert_eq!(
        want.trim(),
        got,
        "the simulation of scenarios/smoke.toml changed (digest in {}). If the change is \
         intended, re-mint it with: PLACEWORDS_REMINT=1 cargo test --release golden_digest",
        file.display()
    );
}

/// `simulate` writes each lap as it is made; its files are the text the in-memory writer gives
/// (`carmen_log`), byte for byte: they hash to the golden digest of the smoke scenario (minted
/// from the in-memory path before the logs were streamed).
#[test]
fn simulate_command_streams_the_golden_logs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("logs");
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(["simulate", "scenarios/smoke.toml", "--quiet", "-o"])
        .arg(&out)
        .current_dir(root())
        .status()
        .unwrap();
    assert!(st.success());
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for run in 0..2 {
        h = fnv1a(
            &std::fs::read(out.join(format!("run-{run:03}.log"))).unwrap(),
            h,
        );
    }
    let want = std::fs::read_to_string(root().join("tests/golden/sim-smoke.digest")).unwrap();
    assert_eq!(want.trim(), format!("{h:016x}"));
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names.len(),
        3,
        "two logs and the manifest, no temporary: {names:?}"
    );
}

/// `simulate --laps` takes more laps than a scenario file may hold (it keeps no lap), but not
/// none, a negative count or garbage.
#[test]
fn simulate_takes_more_laps_than_a_file_but_not_none() {
    use placewords::spec::scenario::{MAX_LAPS, check_laps, check_streamed_laps};
    assert!(check_laps(MAX_LAPS as i64 + 1).is_err());
    assert_eq!(check_streamed_laps(100_000), Ok(100_000));
    assert!(
        check_streamed_laps(0)
            .unwrap_err()
            .contains("1 lap or more")
    );
    assert!(check_streamed_laps(-5).is_err());
    assert!(check_streamed_laps(i64::MAX).is_err());
    for bad in ["0", "x", "1e3", ""] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
            .args(["simulate", "scenarios/smoke.toml", "--laps", bad, "-o"])
            .arg(std::env::temp_dir().join("placewords-never-written"))
            .current_dir(root())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "--laps {bad:?}");
    }
}

/// A corridor closed by a door: the run ends with an error naming the place and the lap.
#[test]
fn a_blocked_robot_ends_the_run_with_an_error_naming_the_place() {
    let world = format!(
        "{TINY_LOOP}\n[[doors]]\nid = \"gate\"\nhinge_m = [5.0, 0.0]\nwidth_m = 2.0\nclosed_heading_deg = 90.0\nopen_heading_deg = 0.0\n"
    );
    let scn = parse_scenario(
        "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\n[[runs]]\nlaps = 1\ndoors = \"all-closed\"\n",
        Path::new("mem/test.toml"),
        &move |_p: &Path, _c: &placewords::world::WorldCheck| Ok(unchecked_world(&world)),
    )
    .unwrap();
    match simulate(&scn.sim, None, &|| {}) {
        Err(e @ SimError::Blocked { lap: 0, x_m, .. }) => {
            assert!(x_m > 3.0 && x_m < 5.0, "{e}");
            let msg = e.to_string();
            assert!(msg.contains("lap 0") && msg.contains("blocked"), "{msg}");
        }
        other => panic!("expected a blocked error, got {other:?}"),
    }
}

/// Problems in a scenario are reported with their line and column, all at once.
#[test]
fn a_malformed_scenario_gives_located_errors() {
    let world = LOOP_WORLD.to_string();
    let src = r#"format_version = 1
world = "w.toml"
route = "lapp"
seed = 1

[door_configs]
one = ["d-soth"]

[[runs]]
laps = 0
doors = "onee"
"#;
    let err = scenario(&world, src).unwrap_err();
    let msgs: Vec<String> = err.diagnostics().iter().map(|d| d.to_string()).collect();
    let all = msgs.join("\n");
    assert!(
        all.contains("mem/test.toml:3:9: unknown route `lapp`; did you mean `lap`?"),
        "{all}"
    );
    assert!(
        all.contains("mem/test.toml:7:8: unknown door `d-soth`; did you mean `d-south`?"),
        "{all}"
    );
    assert!(all.contains("mem/test.toml:10:8: laps = 0"), "{all}");
    assert!(
        all.contains("mem/test.toml:11:9: unknown door configuration `onee`; did you mean `one`?"),
        "{all}"
    );

    let err = scenario(
        &world,
        "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\nrunz = []\n",
    )
    .unwrap_err();
    let all = err.to_string();
    assert!(
        all.starts_with(
            "mem/test.toml:5:1: unknown key `runz` in the scenario file; did you mean `runs`?"
        ),
        "{all}"
    );

    let err = scenario(&world, "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\n[[runs]]\nlaps = 1\n[laser]\npreset = \"lms300\"\n[odometry]\nalpha1 = 0.1\n").unwrap_err();
    let all = err.to_string();
    assert!(
        all.contains(":8:10: unknown laser preset `lms300`; did you mean `lms200`?"),
        "{all}"
    );
    assert!(
        all.contains(":10:10: alpha1 applies to model = \"thrun\""),
        "{all}"
    );
}

/// Every scenario in `scenarios/` loads.
#[test]
fn every_scenario_file_loads() {
    for e in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            load_scenario(&p).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// `placewords simulate` writes 181-range FLASER lines and TRUEPOS lines on the route, and the
/// same files twice.
#[test]
fn simulate_command_writes_carmen_logs_and_a_manifest() {
    let exe = env!("CARGO_BIN_EXE_placewords");
    let scn_path = root().join("scenarios/smoke.toml");
    let dirs: Vec<tempfile::TempDir> = (0..2).map(|_| tempfile::tempdir().unwrap()).collect();
    for d in &dirs {
        let st = std::process::Command::new(exe)
            .args([
                "simulate",
                scn_path.to_str().unwrap(),
                "--laps",
                "1",
                "--quiet",
                "--svg",
                "-o",
            ])
            .arg(d.path())
            .status()
            .unwrap();
        assert!(st.success());
    }
    let scn = load_scenario(&scn_path).unwrap();
    let legs = scn.sim.route.legs();
    for run in 0..scn.sim.runs.len() {
        let name = format!("run-{run:03}.log");
        let a = std::fs::read(dirs[0].path().join(&name)).unwrap();
        let b = std::fs::read(dirs[1].path().join(&name)).unwrap();
        assert!(a == b, "{name} differs between two runs with the same seed");
        let text = String::from_utf8(a).unwrap();
        let (mut lasers, mut truths) = (0, 0);
        for line in text.lines() {
            let f: Vec<&str> = line.split_whitespace().collect();
            match f.first() {
                Some(&"FLASER") => {
                    lasers += 1;
                    assert_eq!(f[1], "181");
                    assert_eq!(f.len(), 2 + 181 + 6 + 3);
                }
                Some(&"TRUEPOS") => {
                    truths += 1;
                    let p = Vec2::new(f[1].parse().unwrap(), f[2].parse().unwrap());
                    let d = legs
                        .iter()
                        .map(|l| l.distance_to_point(p))
                        .fold(f64::INFINITY, f64::min);
                    assert!(d < 0.5, "TRUEPOS {p:?} is {d} m off the route");
                }
                _ => {}
            }
        }
        assert!(
            lasers > 400 && lasers == truths,
            "{lasers} FLASER, {truths} TRUEPOS"
        );
    }
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dirs[0].path().join("manifest.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["seed"], 42);
    assert_eq!(manifest["runs"][0]["file"], "run-000.log");
    assert_eq!(manifest["runs"][0]["laps"][0]["door_config"], "all-closed");
    let svg = std::fs::read_to_string(dirs[0].path().join("run-000.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("<polyline"));
}

/// Presets, overrides, the Thrun model, door plans and the pass-through blocks are read as
/// written.
#[test]
fn scenario_settings_are_read_with_units_converted() {
    use placewords::sim::DoorPlan;
    use placewords::sim::odometry::OdometryModel;
    let world = LOOP_WORLD.to_string();
    let scn = scenario(
        &world,
        r#"format_version = 1
world = "w"
route = "lap"
seed = 3
[door_configs]
north = ["d-north"]
[[runs]]
laps = 3
start_waypoint = 2
doors_cycle = ["all-closed", "north", "all-open"]
[[runs]]
laps = 1
doors_random = { open_probability = 0.25 }
[laser]
preset = "lms200-mm"
angle_error_deg = 0.1
[odometry]
model = "thrun"
alpha1 = 0.02
alpha3 = 0.03
wheel_radius_mismatch_ratio = 0.001
[robot]
cruise_speed_m_s = 0.5
max_turn_rate_deg_s = 90
[recognizer.words]
min_word_size = 4
[evaluation]
tp_radius_m = 1.5
[[expect.subjects]]
subject = "words-2"
min_precision = 0.9
"#,
    )
    .unwrap();
    assert_eq!(scn.sim.laser.max_range_m, 8.191);
    assert!((scn.sim.laser.angle_error_rad - 0.1f64.to_radians()).abs() < 1e-15);
    assert_eq!(
        scn.sim.odometry.model,
        OdometryModel::Thrun {
            alpha: [0.02, 0.01, 0.03, 0.01]
        }
    );
    assert_eq!(scn.sim.odometry.wheel_radius_mismatch_ratio, 0.001);
    assert_eq!(scn.sim.robot.cruise_speed_m_s, 0.5);
    assert!((scn.sim.robot.max_turn_rate_rad_s - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(scn.sim.runs[0].start_waypoint, 2);
    match &scn.sim.runs[0].doors {
        DoorPlan::Cycle(c) => {
            let names: Vec<&str> = c.iter().map(|d| d.name.as_str()).collect();
            assert_eq!(names, ["all-closed", "north", "all-open"]);
            assert_eq!(c[1].states.open, [false, true]);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        scn.sim.runs[1].doors,
        DoorPlan::Random {
            open_probability: 0.25
        }
    );
    assert_eq!(scn.recognizer.words.min_word_size, 4);
    assert_eq!(scn.evaluation.tp_radius_m, 1.5);
    assert_eq!(scn.expect.subjects[0].min_precision, Some(0.9));
    // Door states per lap follow the plan.
    let (name, st) = placewords::sim::runner::door_states(&scn.sim, 0, 4);
    assert_eq!(
        (name.as_str(), st.open.as_slice()),
        ("north", &[false, true][..])
    );
}

/// The logs `simulate` writes load back through the CARMEN reader: one FLASER of 181 ranges per
/// frame, odometry poses as written, and TRUEPOS lines on the route.
#[test]
fn simulated_logs_read_back_through_the_carmen_reader() {
    use placewords::io::carmen::{LogRecord, ReadOptions, read_log};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scn = load_scenario(&root.join("scenarios/smoke.toml")).unwrap();
    let runs = simulate(&scn.sim, Some(1), &|| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let files = placewords::sim::logs::write_logs(&scn.sim, &runs, Some(1), dir.path()).unwrap();
    let log = files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == "log"))
        .expect("a log file");
    let read = read_log(log, ReadOptions { lenient: false }).unwrap();
    let lasers: Vec<_> = read
        .records
        .iter()
        .filter_map(|r| match r {
            LogRecord::Laser(l) => Some(l),
            _ => None,
        })
        .collect();
    let frames: Vec<_> = runs[0].frames().collect();
    assert_eq!(lasers.len(), frames.len());
    for (l, f) in lasers.iter().zip(&frames) {
        assert_eq!(l.ranges_m.len(), 181);
        assert!((l.odom.x - f.odom.0.x).abs() < 1e-5 && (l.odom.y - f.odom.0.y).abs() < 1e-5);
    }
    let route = &scn.sim.route;
    for r in &read.records {
        if let LogRecord::TruePos(t) = r {
            let d = route
                .legs()
                .iter()
                .map(|s| s.distance_to_point(t.truth.position()))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.6, "true pose {:?} is {d:.2} m off the route", t.truth);
        }
    }
}

/// `direction = "reverse"` drives the route's waypoints in reverse order from the same start
/// waypoint: on the loop (1,1) → (19,1) → (19,7) → (1,7), a reverse run leaves (1,1) heading
/// north, towards (1,7), and reaches the west side before the east side. A bad value is a
/// located error.
#[test]
fn a_reverse_run_drives_the_waypoints_backwards() {
    let head = "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\n[[runs]]\nlaps = 1\n";
    let scn = scenario(LOOP_WORLD, &format!("{head}direction = \"reverse\"\n")).unwrap();
    assert!(scn.sim.runs[0].reverse);
    let runs = simulate(&scn.sim, None, &|| {}).unwrap();
    let truth: Vec<Pose2> = runs[0].frames().map(|f| f.truth.0).collect();
    assert!(
        (truth[0].theta - std::f64::consts::FRAC_PI_2).abs() < 0.2,
        "starts facing north: {:?}",
        truth[0]
    );
    let first = |f: &dyn Fn(&Pose2) -> bool| truth.iter().position(f).unwrap();
    let west_top = first(&|p| p.x < 3.0 && p.y > 6.0);
    let east = first(&|p| p.x > 17.0);
    assert!(
        west_top < east,
        "reaches (1, 7) at frame {west_top}, x > 17 at {east}"
    );

    let err = scenario(LOOP_WORLD, &format!("{head}direction = \"backwards\"\n")).unwrap_err();
    let all: Vec<String> = err.diagnostics().iter().map(|d| d.to_string()).collect();
    assert!(
        all.iter()
            .any(|m| m.starts_with("mem/test.toml:7:13:") && m.contains("\"reverse\"")),
        "{all:?}"
    );
}

/// No silent failure: a run that yields no pair says so in words in the table ("no matches",
/// not a precision of 0) and its report says why (here one lap: nothing is revisited, and no
/// chain of matching words reaches τ).
#[test]
fn a_run_without_pairs_says_why() {
    use placewords::experiment::{ExperimentOptions, evaluate_runs};
    let src = "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\n[[runs]]\nlaps = 1\n";
    let scn = scenario(LOOP_WORLD, src).unwrap();
    let runs = simulate(&scn.sim, None, &|| {}).unwrap();
    let opts = ExperimentOptions {
        levels: vec![1],
        ..Default::default()
    };
    let exp = evaluate_runs("tiny", 1, runs, &scn.recognizer, &scn.evaluation, &opts).unwrap();
    let s = &exp.report.subjects[0].scores;
    assert_eq!(s.pairs, 0);
    let why = s.no_pairs_reason.as_deref().unwrap_or_default();
    assert!(why.contains("no observation has a revisit"), "{why}");
    assert!(why.contains("longest chain of matching words is"), "{why}");
    let json = serde_json::to_string(&exp.report).unwrap();
    assert!(json.contains("\"no_pairs_reason\""), "{json}");
    let table = placewords::report::table::text_table(&exp.report);
    assert!(table.contains("no matches"), "{table}");
    // The table wraps long lines: compare the words.
    let words = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words(&table).contains(&words(why)), "{table}");
}

/// The `real-weave` lap preset (issue 28 point 1): its laps sway about their lane and turn on
/// the spot as real robots do (median heading off the corridor, weave per metre and turns on
/// the spot above the smooth laps' on every seed), keep the robot's body off every wall and
/// door of 2 m corridors, and one seed drives the same laps twice.
#[test]
fn real_weave_laps_weave_more_than_smooth_ones_and_keep_off_walls() {
    use placewords::eval::motion::{Motion, measure};
    let base = "format_version = 1\nworld = \"w\"\nroute = \"lap\"\nseed = 1\n[[runs]]\nlaps = 3\ndoors = \"all-open\"\n";
    let drive = |preset: &str, seed: u64| -> (Motion, Vec<Pose2>) {
        let text = format!("{base}[robot]\nlap_variation = \"{preset}\"\n");
        let mut scn = scenario(LOOP_WORLD, &text).unwrap();
        scn.sim.seed = seed;
        let mut sim = placewords::sim::runner::RunSim::new(&scn.sim, 0);
        let (mut m, mut path) = (Motion::default(), Vec::new());
        for lap in 0..3 {
            let log = sim.run_lap(lap).unwrap();
            let p: Vec<_> = log.frames.iter().map(|f| (f.time_s, f.truth.0)).collect();
            m.add(&measure(&p));
            path.extend(p.iter().map(|x| x.1));
        }
        let contact = sim.contact_steps();
        assert_eq!(
            contact, 0,
            "{preset}, seed {seed}: the robot touched a wall or door"
        );
        (m, path)
    };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let deviation = |m: &Motion| median(m.heading_deviation_rad.iter().map(|d| d.abs()).collect());
    for seed in 1..=3 {
        let (weave, path) = drive("real-weave", seed);
        let (smooth, _) = drive("smooth", seed);
        let (dw, ds) = (deviation(&weave), deviation(&smooth));
        assert!(
            dw > 2.0 * ds && dw > 1f64.to_radians(),
            "seed {seed}: median heading deviation {dw} rad, smooth {ds}"
        );
        let (ww, ws) = (
            median(weave.weave_m.clone()),
            median(smooth.weave_m.clone()),
        );
        assert!(
            ww > ws + 0.005,
            "seed {seed}: median weave {ww} m/m, smooth {ws}"
        );
        assert!(weave.spins_per_100_m() > smooth.spins_per_100_m());
        if seed == 1 {
            assert_eq!(
                drive("real-weave", 1).1,
                path,
                "the same seed drives the same laps"
            );
        }
    }
    let err = scenario(
        LOOP_WORLD,
        &format!("{base}[robot]\nlap_variation = \"real-wave\"\n"),
    );
    let msg = err.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        msg.contains("real-weave"),
        "a misspelt preset names the real one: {msg}"
    );
    let swapped = "[robot]\nweave_wavelength_min_m = 6.0\nweave_wavelength_max_m = 4.0\n";
    let err = scenario(LOOP_WORLD, &format!("{base}{swapped}"));
    let msg = err.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(msg.contains(":9:26") && msg.contains("swap"), "{msg}");
}
