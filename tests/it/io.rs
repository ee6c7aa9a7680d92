//! Real logs and imported worlds: the CARMEN reader, log → run conversion, MobileSim import.

use placewords::authoring::mobilesim::{import_mobilesim, world_to_toml};
use placewords::geom::{Pose2, Segment, Vec2};
use placewords::io::carmen::{
    CarmenError, LaserRecord, LogRecord, OdomRecord, ReadOptions, TruePosRecord, parse_log_str,
    read_log, read_log_from, write_record,
};
use placewords::io::matches_csv::{MatchRow, parse_matches, write_matches};
use placewords::io::real_log::{TruthSource, log_to_run, noise_free};
use placewords::place::Direction;
use placewords::spec::diag::Diagnostic;
use proptest::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};

fn manifest() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn fixture(name: &str) -> PathBuf {
    manifest().join("tests/fixtures/carmen").join(name)
}

fn shared(sub: &str) -> Option<PathBuf> {
    let p = manifest().join("../shared/data").join(sub);
    if p.exists() {
        Some(p)
    } else {
        println!(
            "skipping: {} is absent (real data lives in ../shared/data)",
            p.display()
        );
        None
    }
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn lasers(recs: &[LogRecord]) -> Vec<&LaserRecord> {
    recs.iter()
        .filter_map(|r| match r {
            LogRecord::Laser(l) => Some(l),
            _ => None,
        })
        .collect()
}

// ---- reader on real logs ----------------------------------------------------------------------

#[test]
fn reads_the_three_real_logs() {
    let Some(dir) = shared("carmen") else { return };
    for (file, scans, beams) in [
        ("intel-corrected.log.gz", 910, 180),
        ("freiburg-079-corrected.log.gz", 4791, 360),
        ("csail-corrected.log.gz", 406, 361),
    ] {
        let r = read_log(&dir.join(file), ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let l = lasers(&r.records);
        assert_eq!(l.len(), scans, "{file}");
        assert!(l.iter().all(|s| s.ranges_m.len() == beams), "{file}");
        assert!(
            l.iter().all(|s| s.fov_rad == std::f64::consts::PI),
            "{file}"
        );
        assert_eq!(r.skipped_lines, 0);
        assert!(
            r.unknown_lines >= scans,
            "NEFF lines are skipped as unknown"
        );
        let run = log_to_run(&r, file, TruthSource::Corrected, noise_free).unwrap();
        let frames: Vec<_> = run.frames().collect();
        assert_eq!(frames.len(), scans);
        assert!(frames.windows(2).all(|w| w[1].time_s >= w[0].time_s));
        let (run2, counts) = placewords::io::real_log::load_run(
            &dir.join(file),
            ReadOptions::default(),
            TruthSource::Corrected,
            noise_free,
        )
        .unwrap();
        assert_eq!(run2, run);
        assert_eq!(counts.skipped_lines, 0);
        // Noise-free derived odometry reproduces the corrected path.
        let last = frames.last().unwrap();
        assert!(last.odom.0.distance(&last.truth.0) < 1e-6, "{file}");
        assert_eq!(last.scan.layout.count, beams);
        // "No return" readings (~81.9 m) are not hits.
        let misses = frames
            .iter()
            .flat_map(|f| (0..f.scan.ranges_m.len()).map(move |i| (f, i)))
            .filter(|(f, i)| f.scan.ranges_m[*i] > 81.0)
            .all(|(f, i)| !f.scan.is_hit(i));
        assert!(misses, "{file}");
    }
}

// ---- fixtures ---------------------------------------------------------------------------------

#[test]
fn mixed_fixture_reads_plain_and_gzip_alike() {
    let path = fixture("mixed.log");
    let plain = read_log(&path, ReadOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let gz = read_log_from(&gzip(&bytes)[..], "mixed.log.gz", ReadOptions::default()).unwrap();
    assert_eq!(plain, gz);
    assert_eq!(lasers(&plain.records).len(), 3);
    assert_eq!(plain.unknown_lines, 2, "NEFF and SYNC");
    assert_eq!(plain.robotlaser_max_range_m, Some(30.0));
    let LogRecord::Laser(rear) = &plain.records[plain.rear_laser_indices[0]] else {
        panic!("RLASER index")
    };
    assert_eq!(
        rear.start_angle_rad,
        std::f64::consts::FRAC_PI_2,
        "the rear laser faces backwards"
    );
    // The run uses the front lasers only (FLASER and ROBOTLASER1), truth from TRUEPOS by time.
    let run = log_to_run(&plain, "mixed.log", TruthSource::TruePos, noise_free).unwrap();
    let f: Vec<_> = run.frames().collect();
    assert_eq!(f.len(), 2);
    assert_eq!(f[0].truth.0, Pose2::new(0.01, 0.02, 0.001));
    assert_eq!(f[1].truth.0, Pose2::new(0.21, 0.03, 0.012));
    assert_eq!(
        f[0].scan.layout.max_range_m, 50.0,
        "PARAM robot_front_laser_max"
    );
    assert!(!f[0].scan.is_hit(3));
    assert_eq!(f[1].scan.layout.start_angle_rad, -1.5);
    assert!((f[1].scan.layout.fov_rad() - 3.0).abs() < 1e-12);
    assert_eq!(f[1].scan.layout.count, 3);
}

#[test]
fn corrupted_line_gives_a_located_error_and_lenient_counts() {
    let path = fixture("malformed.log");
    let e = read_log(&path, ReadOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            CarmenError::Malformed(Diagnostic {
                line: 4,
                col: 16,
                ..
            })
        ),
        "{msg}"
    );
    assert!(
        msg.contains("malformed.log:4:16: FLASER field 3 (range) is `2.0x0`"),
        "{msg}"
    );
    let r = read_log(&path, ReadOptions { lenient: true }).unwrap();
    assert_eq!(r.skipped_lines, 2);
    assert_eq!(lasers(&r.records).len(), 2);
    assert!(r.first_skipped.unwrap().contains("malformed.log:4:16"));
}

#[test]
fn truncated_gzip_gives_a_located_error() {
    let mut text = String::new();
    for i in 0..2000 {
        text.push_str(&format!("ODOM {i} 0 0 0 0 0 {i}.5 host {i}.5\n"));
    }
    let gz = gzip(text.as_bytes());
    for cut in [gz.len() / 2, gz.len() - 4, 12] {
        let e = read_log_from(&gz[..cut], "cut.log.gz", ReadOptions { lenient: true }).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, CarmenError::Decompress { .. }), "{msg}");
        // At the last complete line: `file:line:col` like every other error.
        let CarmenError::Decompress { line, .. } = e else {
            unreachable!()
        };
        let at = if line == 0 {
            "cut.log.gz:1:1: the gzip stream is truncated or corrupt before its first complete line"
                .to_string()
        } else {
            format!(
                "cut.log.gz:{line}:1: the gzip stream is truncated or corrupt after this line, the last complete one"
            )
        };
        assert!(msg.starts_with(&at), "{msg}");
    }
    // On a real file, the line reached is named.
    if let Some(dir) = shared("carmen") {
        let bytes = std::fs::read(dir.join("intel-corrected.log.gz")).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let p = tmp.path().join("intel-cut.log.gz");
        std::fs::write(&p, &bytes[..bytes.len() / 3]).unwrap();
        match read_log(&p, ReadOptions::default()).unwrap_err() {
            CarmenError::Decompress { path, line, .. } => {
                assert!(path.ends_with("intel-cut.log.gz"));
                assert!(line > 1000, "{line}");
            }
            e => panic!("{e}"),
        }
    }
}

#[test]
fn corrupted_gzip_never_panics() {
    let bytes = std::fs::read(fixture("mixed.log")).unwrap();
    let gz = gzip(&bytes);
    for i in 10..gz.len() {
        let mut bad = gz.clone();
        bad[i] ^= 0x5a;
        let _ = read_log_from(&bad[..], "bad.log.gz", ReadOptions::default());
        let _ = read_log_from(&bad[..], "bad.log.gz", ReadOptions { lenient: true });
    }
}

#[test]
fn missing_file_names_it() {
    let e = read_log(Path::new("/nonexistent/x.log"), ReadOptions::default()).unwrap_err();
    assert!(
        e.to_string().starts_with("/nonexistent/x.log: cannot read"),
        "{e}"
    );
}

// ---- round trip -------------------------------------------------------------------------------

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

#[test]
fn write_record_round_trips_to_print_precision() {
    let p = |x: f64, y: f64, t: f64| Pose2::new(x, y, t);
    let recs = vec![
        LogRecord::Param {
            name: "robot_front_laser_max".into(),
            value: "32.767".into(),
        },
        LogRecord::Laser(LaserRecord {
            start_angle_rad: -std::f64::consts::FRAC_PI_2,
            fov_rad: std::f64::consts::PI,
            ranges_m: vec![1.234, 32.767, 0.5, 7.0],
            pose: p(1.5, -2.25, 0.125),
            odom: p(1.4, -2.2, 0.12),
            ipc_timestamp: 12.5,
            host: "sim".into(),
            logger_timestamp: 12.5,
        }),
        LogRecord::Odom(OdomRecord {
            pose: p(1.0, 2.0, -3.0),
            tv_m_s: 0.4,
            rv_rad_s: -0.1,
            accel_m_s2: 0.3,
            ipc_timestamp: 13.0,
            host: "sim".into(),
            logger_timestamp: 13.25,
        }),
        LogRecord::TruePos(TruePosRecord {
            truth: p(0.1, 0.2, 0.3),
            odom: p(0.4, 0.5, 0.6),
            ipc_timestamp: 14.0,
            host: "sim".into(),
            logger_timestamp: 14.0,
        }),
    ];
    let mut out = String::new();
    for r in &recs {
        write_record(&mut out, r);
    }
    let back = parse_log_str(&out, "rt.log", ReadOptions::default()).unwrap();
    assert_eq!(back.records, recs);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_records_round_trip(
        ranges in prop::collection::vec(0.0f64..80.0, 1..400),
        x in -1e4f64..1e4, y in -1e4f64..1e4, t in -3.1f64..3.1, stamp in 0.0f64..2e9,
    ) {
        let ranges: Vec<f64> = ranges.iter().map(|r| (r * 1e3).round() / 1e3).collect();
        let pose = Pose2::new(round6(x), round6(y), round6(t));
        let rec = LogRecord::Laser(LaserRecord {
            start_angle_rad: -std::f64::consts::FRAC_PI_2,
            fov_rad: std::f64::consts::PI,
            ranges_m: ranges,
            pose,
            odom: pose,
            ipc_timestamp: round6(stamp),
            host: "h".into(),
            logger_timestamp: round6(stamp),
        });
        let mut out = String::new();
        write_record(&mut out, &rec);
        let back = parse_log_str(&out, "p", ReadOptions::default()).unwrap();
        let LogRecord::Laser(a) = &back.records[0] else { panic!() };
        let LogRecord::Laser(b) = &rec else { panic!() };
        prop_assert_eq!(a.ranges_m.len(), b.ranges_m.len());
        for (u, v) in a.ranges_m.iter().zip(&b.ranges_m) {
            prop_assert!((u - v).abs() < 1e-9);
        }
        prop_assert!((a.pose.x - b.pose.x).abs() < 1e-6 && (a.pose.theta - b.pose.theta).abs() < 1e-6);
        prop_assert!((a.ipc_timestamp - b.ipc_timestamp).abs() < 1e-5);
    }
}

// ---- never a panic ----------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_text_never_panics(s in "\\PC*", lenient in any::<bool>()) {
        let _ = parse_log_str(&s, "fuzz", ReadOptions { lenient });
    }

    #[test]
    fn arbitrary_bytes_never_panic(b in prop::collection::vec(any::<u8>(), 0..600)) {
        let _ = read_log_from(&b[..], "fuzz", ReadOptions::default());
        let mut gz = vec![0x1f, 0x8b];
        gz.extend_from_slice(&b);
        let _ = read_log_from(&gz[..], "fuzz.gz", ReadOptions { lenient: true });
    }

    #[test]
    fn mutated_valid_logs_never_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0u8..4, "[ 0-9a-zA-Z.\\-#\n]{0,3}"), 1..8),
        lenient in any::<bool>(),
    ) {
        let mut s = std::fs::read_to_string(fixture("mixed.log")).unwrap();
        for (at, op, text) in edits {
            if s.is_empty() { break; }
            let mut i = at.index(s.len());
            while !s.is_char_boundary(i) { i -= 1; }
            match op {
                0 => s.insert_str(i, &text),
                1 => { let j = (i + text.len() + 1).min(s.len()); let mut j2 = j; while !s.is_char_boundary(j2) { j2 -= 1; } s.replace_range(i..j2, ""); }
                2 => { s.truncate(i); }
                _ => { let j = (i + 1).min(s.len()); let mut j2 = j; while !s.is_char_boundary(j2) { j2 -= 1; } s.replace_range(i..j2, &text); }
            }
        }
        let _ = parse_log_str(&s, "mut", ReadOptions { lenient });
    }

    #[test]
    fn truncated_gzip_prefixes_never_panic(cut in 0usize..10_000) {
        let bytes = std::fs::read(fixture("mixed.log")).unwrap();
        let gz = gzip(&bytes);
        let cut = cut % (gz.len() + 1);
        let r = read_log_from(&gz[..cut], "cut.gz", ReadOptions::default());
        if cut < gz.len() && cut >= 2 {
            prop_assert!(r.is_err(), "a prefix of {cut} of {} bytes read as complete", gz.len());
        }
    }
}

// ---- MobileSim import -------------------------------------------------------------------------

/// Exact segment–segment distance, written independently of the importer's.
fn seg_dist(p: &Segment, q: &Segment) -> f64 {
    let orient = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp(&(c - a));
    let (d1, d2) = (orient(q.a, q.b, p.a), orient(q.a, q.b, p.b));
    let (d3, d4) = (orient(p.a, p.b, q.a), orient(p.a, p.b, q.b));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    [
        p.distance_to_point(q.a),
        p.distance_to_point(q.b),
        q.distance_to_point(p.a),
        q.distance_to_point(p.b),
    ]
    .into_iter()
    .fold(f64::INFINITY, f64::min)
}

#[test]
fn mobilesim_maps_import_to_valid_worlds() {
    let Some(dir) = shared("mobilesim") else {
        return;
    };
    for file in ["office.map", "corridors.map"] {
        let src = std::fs::read_to_string(dir.join(file)).unwrap();
        let spec = import_mobilesim(&src, file).unwrap_or_else(|e| panic!("{e}"));
        let toml_text = world_to_toml(&spec, file).unwrap();
        assert!(toml_text.starts_with("# Imported by"));
        assert!(toml_text.contains("Doors cannot be inferred"));
        // Round trip through the world file parser.
        let back: placewords::spec::world::WorldSpec = toml::from_str(&toml_text).unwrap();
        assert_eq!(back, spec);
        let world =
            placewords::world::parse_world(&toml_text, file).unwrap_or_else(|e| panic!("{e}"));
        let walls = world.wall_segments();
        let half = world
            .walls
            .iter()
            .map(|w| w.thickness_m)
            .fold(0.0, f64::max)
            / 2.0;
        assert!(walls.len() <= 100_000);
        let (lo, hi) = world.bounds();
        assert!((hi - lo).norm() <= 10_000.0);
        let clear = |s: &Segment| {
            walls
                .iter()
                .map(|w| seg_dist(w, s))
                .fold(f64::INFINITY, f64::min)
                - half
        };
        let home = world.home.position();
        assert!(
            clear(&Segment::new(home, home)) >= 0.25,
            "{file}: home too close"
        );
        assert_eq!(world.routes.len(), 1);
        let route = &world.routes[0];
        assert!(route.waypoints.len() >= 3, "{file}");
        for w in &route.waypoints {
            assert!(
                clear(&Segment::new(*w, *w)) >= 0.30,
                "{file}: waypoint {w:?}"
            );
        }
        for leg in route.legs() {
            assert!(leg.length() > 0.0);
            assert!(clear(&leg) >= 0.25, "{file}: leg {leg:?}");
        }
        assert!(
            route.length_m() > 20.0,
            "{file}: a real loop, {} m",
            route.length_m()
        );
        println!(
            "{file}: {} walls, route of {} waypoints, {:.1} m",
            world.walls.len(),
            route.waypoints.len(),
            route.length_m()
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn mobilesim_import_never_panics_on_text(s in "\\PC*") {
        let _ = import_mobilesim(&s, "fuzz.map");
        let _ = import_mobilesim(&format!("2D-Map\nLINES\n{s}"), "fuzz.map");
    }

    #[test]
    fn mobilesim_import_never_panics_on_random_maps(
        segs in prop::collection::vec((-9000i32..9000, -9000i32..9000, -9000i32..9000, -9000i32..9000), 0..25),
        home in (-9000i32..9000, -9000i32..9000),
    ) {
        let mut s = format!("2D-Map\nCairn: RobotHome {} {} 45 \"\" ICON \"\"\nLINES\n", home.0, home.1);
        s.push_str("-10000 -10000 10000 -10000\n10000 -10000 10000 10000\n10000 10000 -10000 10000\n-10000 10000 -10000 -10000\n");
        for (a, b, c, d) in segs {
            s.push_str(&format!("{a} {b} {c} {d}\n"));
        }
        if let Ok(spec) = import_mobilesim(&s, "rand.map") {
            // Whatever it generates passes the clearance rules.
            let world = placewords::world::World::from_spec(&spec);
            let walls = world.wall_segments();
            let clear = |x: &Segment| walls.iter().map(|w| seg_dist(w, x)).fold(f64::INFINITY, f64::min) - 0.025;
            let route = &world.routes[0];
            prop_assert!(route.waypoints.len() >= 3);
            for w in &route.waypoints {
                prop_assert!(clear(&Segment::new(*w, *w)) >= 0.30);
            }
            for leg in route.legs() {
                prop_assert!(clear(&leg) >= 0.25);
            }
        }
    }
}

#[test]
fn endless_line_is_refused_not_swallowed() {
    let mut text = b"ODOM 0 0 0 0 0 0 1 h 1\n".to_vec();
    text.extend(std::iter::repeat_n(b'7', 20 << 20));
    let gz = gzip(&text);
    let e = read_log_from(&gz[..], "bomb.log.gz", ReadOptions { lenient: true }).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("bomb.log.gz:2:1: line longer than 16 MiB"),
        "{e}"
    );
}

#[test]
fn a_world_without_a_route_is_still_written_and_a_route_can_be_added() {
    let src = "2D-Map\nCairn: RobotHome 300 300 0\nLINES\n0 0 600 0\n600 0 600 600\n600 600 0 600\n0 600 0 0\n";
    let e = import_mobilesim(src, "tiny.map").unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("[[routes]]"), "{msg}");
    let placewords::authoring::mobilesim::MapError::NoRoute {
        partial: Some(spec),
        ..
    } = e
    else {
        panic!("{msg}")
    };
    let text = world_to_toml(&spec, "tiny.map").unwrap();
    assert!(text.contains("NO ROUTE"));
    assert!(!text.contains("= []"), "{text}");
    let fixed = format!(
        "{text}\n[[routes]]\nid = \"loop\"\nwaypoints_m = [[0.3, 0.3], [0.31, 0.3], [0.3, 0.31]]\n\n[[doors]]\nid = \"d\"\nhinge_m = [0.0, 0.1]\nwidth_m = 0.3\nclosed_heading_deg = 90\nopen_heading_deg = 0\n"
    );
    let back: placewords::spec::world::WorldSpec = toml::from_str(&fixed).unwrap();
    assert_eq!(back.routes.len(), 1);
    assert_eq!(back.doors.len(), 1);
    assert_eq!(back.walls, spec.walls);
}

/// A file written piece by piece appears under its name only when committed; abandoned (an
/// error, a panic), nothing is left, not even the temporary.
#[test]
fn an_atomic_file_appears_whole_or_not_at_all() {
    use placewords::io::atomic::AtomicFile;
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.log");
    let mut f = AtomicFile::create(&p).unwrap();
    f.write_all(b"one\n").unwrap();
    assert!(!p.exists(), "not before the commit");
    f.write_all(b"two\n").unwrap();
    f.commit().unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "one\ntwo\n");
    let q = dir.path().join("b.log");
    let mut g = AtomicFile::create(&q).unwrap();
    g.write_all(b"half").unwrap();
    drop(g);
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only a.log: {left:?}");
}

/// The frames of a log made one at a time (survey, then a second pass) are the frames of the
/// log loaded whole, truth from TRUEPOS or from the corrected poses, strict or lenient; a bad
/// line is the same located error either way.
#[test]
fn streamed_frames_are_the_frames_of_the_log_loaded_whole() {
    use placewords::io::real_log::{LogSurvey, load_run, stream_frames};
    let mut cases = vec![
        (fixture("mixed.log"), TruthSource::TruePos, false),
        (fixture("mixed.log"), TruthSource::Corrected, false),
        (fixture("malformed.log"), TruthSource::Corrected, true),
    ];
    if let Some(dir) = shared("carmen") {
        cases.push((
            dir.join("csail-corrected.log.gz"),
            TruthSource::Corrected,
            false,
        ));
    }
    for (path, truth, lenient) in cases {
        let opts = ReadOptions { lenient };
        let (run, counts) = load_run(&path, opts, truth, noise_free).unwrap();
        let survey = LogSurvey::read(&path, opts, truth).unwrap();
        let mut frames = Vec::new();
        stream_frames(&path, opts, &survey, truth, noise_free, |f| frames.push(f)).unwrap();
        let whole: Vec<_> = run.frames().cloned().collect();
        assert_eq!(frames, whole, "{} {truth:?}", path.display());
        assert_eq!(survey.frames(), whole.len());
        assert_eq!(survey.counts.skipped_lines, counts.skipped_lines);
    }
    let bad = fixture("malformed.log");
    let e = LogSurvey::read(&bad, ReadOptions::default(), TruthSource::Corrected).unwrap_err();
    assert!(
        e.to_string().contains("malformed.log:4:16: FLASER field 3"),
        "{e}"
    );
}

/// `recognize` gives the same report whether it reads the log as a stream or loads it whole
/// (for pictures): on a simulated log with TRUEPOS lines, thinned, with ICP.
#[test]
fn a_log_read_as_a_stream_gives_the_report_of_the_log_loaded_whole() {
    use placewords::experiment::real::{RealLogOptions, recognize_log};
    use placewords::experiment::{ExperimentOptions, load_scenario};
    let scn = load_scenario(&manifest().join("scenarios/smoke.toml")).unwrap();
    let runs = placewords::sim::simulate(&scn.sim, Some(4), &|| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    placewords::sim::logs::write_logs(&scn.sim, &runs, Some(4), dir.path()).unwrap();
    let log = dir.path().join("run-001.log");
    let cases = [
        (TruthSource::TruePos, "none", 1),
        (TruthSource::Corrected, "proportional", 3),
    ];
    for (truth, noise, scan_step) in cases {
        let opts = RealLogOptions {
            lenient: false,
            truth,
            noise: placewords::experiment::real::parse_noise_model(noise).unwrap(),
            seed: 7,
            scan_step,
            topics: Default::default(),
        };
        let exp = ExperimentOptions {
            icp: true,
            ..ExperimentOptions::default()
        };
        let report = |keep_runs: bool| {
            let (e, skipped) = recognize_log(
                &log,
                &opts,
                "run-000",
                &scn.recognizer,
                &scn.evaluation,
                &exp,
                keep_runs,
            )
            .unwrap();
            assert_eq!(skipped, 0);
            assert_eq!(e.runs.len(), usize::from(keep_runs));
            without_seconds(
                serde_json::from_str(&placewords::report::json::to_json(&e.report)).unwrap(),
            )
        };
        let streamed = report(false);
        let pairs = |l: &serde_json::Value| l["pairs"].as_u64().unwrap_or(0);
        let levels = streamed["subjects"].as_array().unwrap();
        assert!(levels.iter().any(|l| pairs(l) > 0), "something matched");
        assert_eq!(streamed, report(true), "{truth:?}, every {scan_step}");
    }
}

/// `v` with every value under a key naming seconds removed (timings differ run to run).
fn without_seconds(v: serde_json::Value) -> serde_json::Value {
    match v {
        serde_json::Value::Object(m) => m
            .into_iter()
            .filter(|(k, _)| !k.contains("second"))
            .map(|(k, x)| (k, without_seconds(x)))
            .collect(),
        serde_json::Value::Array(a) => a.into_iter().map(without_seconds).collect(),
        x => x,
    }
}

// ---- matches files (`placewords score`) -------------------------------------------------------

fn match_row() -> impl Strategy<Value = MatchRow> {
    (
        (0usize..5, 0usize..100_000, 0usize..5, 0usize..100_000),
        prop::option::of(-1e6f64..1e6),
        any::<bool>(),
    )
        .prop_map(|((qr, qs, mr, ms), score, opposite)| MatchRow {
            query_run: qr,
            query_scan: qs,
            matched_run: mr,
            matched_scan: ms,
            score,
            direction: if opposite {
                Direction::Opposite
            } else {
                Direction::Same
            },
        })
}

/// `rows` under a header with `direction` before `score`, padded with spaces, leaving out the
/// trailing score when there is none.
fn direction_first(rows: &[MatchRow]) -> String {
    let mut s = "query_run, query_scan, matched_run, matched_scan, direction, score\n".to_string();
    for r in rows {
        let (q, m) = ((r.query_run, r.query_scan), (r.matched_run, r.matched_scan));
        let head = format!(" {},{} ,{},{}, {}", q.0, q.1, m.0, m.1, r.direction.name());
        match r.score {
            Some(v) => s.push_str(&format!("{head},{v}\n")),
            None => s.push_str(&format!("{head}\n")),
        }
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Rows with any direction and score read back as written, whatever the order of the
    /// optional columns.
    #[test]
    fn matches_rows_round_trip_with_directions(rows in prop::collection::vec(match_row(), 0..40)) {
        prop_assert_eq!(parse_matches(&write_matches(&rows), "m.csv").unwrap(), rows.clone());
        prop_assert_eq!(parse_matches(&direction_first(&rows), "m.csv").unwrap(), rows);
    }

    /// A direction that is neither `same` nor `opposite` is an error at its line and column.
    #[test]
    fn a_bad_direction_is_located(
        rows in prop::collection::vec(match_row(), 1..20),
        at in any::<prop::sample::Index>(),
        word in "[a-zA-Z][a-zA-Z0-9_]{0,8}",
    ) {
        prop_assume!(word != "same" && word != "opposite");
        let text = write_matches(&rows);
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let k = 1 + at.index(rows.len());
        let cut = lines[k].rfind(',').unwrap() + 1;
        lines[k] = format!("{}{word}", &lines[k][..cut]);
        let e = parse_matches(&lines.join("\n"), "m.csv").unwrap_err().to_string();
        let want = format!("m.csv:{}:{}: direction `{word}` is neither", k + 1, cut + 1);
        prop_assert!(e.starts_with(&want), "{} (want {})", e, want);
    }

    /// Arbitrary lines under either header are rows or located errors, never a panic.
    #[test]
    fn arbitrary_matches_lines_never_panic(
        body in "[0-9a-z, .#\\-\n]{0,200}",
        with_direction in any::<bool>(),
    ) {
        let header = if with_direction {
            "query_run,query_scan,matched_run,matched_scan,score,direction"
        } else {
            "query_run,query_scan,matched_run,matched_scan"
        };
        let text = format!("{header}\n{body}");
        if let Err(e) = parse_matches(&text, "m.csv") {
            let e = e.to_string();
            let line: usize = e.split(':').nth(1).unwrap().parse().unwrap();
            prop_assert!(e.starts_with("m.csv:") && line >= 2 && line <= text.lines().count(), "{}", e);
        }
    }
}
