//! Evaluation end to end on a hand-made world: a driver, the ICP baseline, metrics, the report
//! and the gate, without the simulator (frames are ray-cast here against a few segments).

use placewords::baseline::{IcpConfig, IcpRecognizer};
use placewords::eval::gate::{check, exit_code};
use placewords::eval::scores::{Report, SubjectKind};
use placewords::eval::{PlaceRecognizer, evaluate, recognize_runs};
use placewords::geom::{OdomPose, Pose2, Segment, TruePose, Vec2};
use placewords::log::{Frame, LapLog, RunLog};
use placewords::place::{Match, Observation};
use placewords::report::junit::{Suite, junit_xml};
use placewords::scan::{BeamLayout, Scan};
use placewords::spec::evaluation::{EvaluationSpec, ExpectSpec, SubjectExpectation};

/// A corridor loop 20 × 8 m around a 16 × 4 m block, with niches and pillars so that ICP has
/// something to hold on to.
fn world() -> Vec<Segment> {
    let poly = |pts: &[(f64, f64)]| -> Vec<Segment> {
        pts.windows(2)
            .map(|w| Segment::new(Vec2::new(w[0].0, w[0].1), Vec2::new(w[1].0, w[1].1)))
            .collect()
    };
    let mut s = Vec::new();
    s.extend(poly(&[
        (0.0, 0.0),
        (6.0, 0.0),
        (6.0, -0.7),
        (7.0, -0.7),
        (7.0, 0.0),
        (20.0, 0.0),
        (20.0, 8.0),
        (13.0, 8.0),
        (13.0, 8.5),
        (11.5, 8.5),
        (11.5, 8.0),
        (0.0, 8.0),
        (0.0, 0.0),
    ]));
    s.extend(poly(&[
        (2.0, 2.0),
        (18.0, 2.0),
        (18.0, 6.0),
        (2.0, 6.0),
        (2.0, 2.0),
    ]));
    // Pillars.
    for (x, y) in [
        (10.0, 0.3),
        (15.0, 7.7),
        (19.7, 4.0),
        (3.0, 7.7),
        (0.3, 3.0),
    ] {
        s.extend(poly(&[
            (x - 0.15, y - 0.15),
            (x + 0.15, y - 0.15),
            (x + 0.15, y + 0.15),
            (x - 0.15, y + 0.15),
            (x - 0.15, y - 0.15),
        ]));
    }
    s
}

fn ray(walls: &[Segment], o: Vec2, d: Vec2, max: f64) -> f64 {
    let mut best = max;
    for w in walls {
        let e = w.b - w.a;
        let den = d.x * e.y - d.y * e.x;
        if den.abs() < 1e-12 {
            continue;
        }
        let ao = w.a - o;
        let t = (ao.x * e.y - ao.y * e.x) / den;
        let u = (ao.x * d.y - ao.y * d.x) / den;
        if t > 0.0 && (0.0..=1.0).contains(&u) && t < best {
            best = t;
        }
    }
    best
}

/// `laps` laps around the loop, counter-clockwise, a frame each 4 cm; odometry is the truth
/// seen from another frame (so nothing can use world coordinates by accident).
fn runs(runs: usize, laps: usize) -> Vec<RunLog> {
    let route = [(1.0, 1.0), (19.0, 1.0), (19.0, 7.0), (1.0, 7.0)];
    let route: Vec<Vec2> = route.iter().map(|p| Vec2::new(p.0, p.1)).collect();
    drive(&world(), &route, 0.04, runs, laps)
}

/// Drives the closed loop `route` among `walls`, a frame each `step_m`. Beams only see walls
/// within 4 m (farther ones report no return), which is all ICP uses.
fn drive(walls: &[Segment], route: &[Vec2], step_m: f64, runs: usize, laps: usize) -> Vec<RunLog> {
    let layout = BeamLayout::centered(
        181,
        std::f64::consts::PI,
        32.767,
        Pose2::new(0.021, 0.0, 0.0),
    );
    let odom_from_world = Pose2::new(5.0, -3.0, 0.4);
    let mut out = Vec::new();
    for r in 0..runs {
        let mut laps_out = Vec::new();
        let mut time_s = 0.0;
        for lap in 0..laps {
            let mut frames = Vec::new();
            for i in 0..route.len() {
                let (a, b) = (route[i], route[(i + 1) % route.len()]);
                let heading = (b - a).y.atan2((b - a).x);
                let n = ((b - a).norm() / step_m).round() as usize;
                for k in 0..n {
                    let p = a + (b - a) * (k as f64 / n as f64);
                    let truth = Pose2::new(p.x, p.y, heading);
                    let sensor = truth.compose(&layout.mount);
                    let near: Vec<Segment> = walls
                        .iter()
                        .filter(|w| w.distance_to_point(sensor.position()) < 4.0)
                        .copied()
                        .collect();
                    let ranges_m = (0..layout.count)
                        .map(|i| {
                            let ang = sensor.theta + layout.beam_angle_rad(i);
                            let d = Vec2::new(ang.cos(), ang.sin());
                            let r = ray(&near, sensor.position(), d, 32.767);
                            if r > 4.0 { 32.767 } else { r }
                        })
                        .collect();
                    frames.push(Frame {
                        time_s,
                        odom: OdomPose(odom_from_world.compose(&truth)),
                        truth: TruePose(truth),
                        scan: Scan {
                            layout: layout.clone(),
                            ranges_m,
                            time_s,
                        },
                    });
                    time_s += 0.1;
                }
            }
            laps_out.push(LapLog {
                lap,
                door_config: if lap % 2 == 0 {
                    "all-closed"
                } else {
                    "one-open"
                }
                .into(),
                open_doors: vec![],
                frames,
            });
        }
        out.push(RunLog {
            run: r,
            laps: laps_out,
        });
    }
    out
}

/// Makes an observation per frame and pairs it with the frame one lap of frames earlier, by
/// counting (it never sees truth).
struct LapBack {
    per_lap: usize,
    obs: Vec<Observation>,
    runs_started: usize,
}

impl PlaceRecognizer for LapBack {
    fn start_run(&mut self) -> Vec<Match> {
        self.runs_started += 1;
        Vec::new()
    }
    fn push(&mut self, frame_id: usize, odom: OdomPose, _scan: &Scan) -> Vec<Match> {
        let id = self.obs.len();
        self.obs.push(Observation::new(
            id,
            self.runs_started - 1,
            frame_id,
            odom,
            id as f64 * 0.04,
        ));
        if id >= self.per_lap {
            let p = id - self.per_lap;
            vec![Match::from_pairs([(id, p)], 1.0)]
        } else {
            vec![]
        }
    }
    fn observations(&self) -> &[Observation] {
        &self.obs
    }
    fn name(&self) -> String {
        "lap-back".into()
    }
}

#[test]
fn driver_counts_inputs_across_runs_and_an_oracle_scores_one() {
    let runs = runs(2, 2);
    let per_lap = runs[0].laps[0].frames.len();
    let mut rec = LapBack {
        per_lap,
        obs: vec![],
        runs_started: 0,
    };
    let r = recognize_runs(&mut rec, &runs);
    assert_eq!(rec.runs_started, 2);
    assert_eq!(r.laps, 4);
    assert_eq!(r.observations.len(), 4 * per_lap);
    assert_eq!(r.truth.frames.len(), 4 * per_lap);
    assert_eq!(r.truth.lap_of(per_lap * 3).unwrap().run, 1);
    let e = evaluate(&r, &EvaluationSpec::default());
    assert_eq!(e.main.precision, 1.0);
    // Every observation after the first lap is paired a lap back; the only revisits it misses
    // are the loop closures inside the first lap (the last 1 m near the start).
    assert!(e.main.recall > 0.97, "{:?}", e.main);
    assert_eq!(e.door_configs.len(), 2);
}

#[test]
fn icp_baseline_finds_revisits_on_a_loop_and_passes_a_gate() {
    let runs = runs(1, 3);
    let mut icp = IcpRecognizer::new(IcpConfig::default());
    let r = recognize_runs(&mut icp, &runs);
    let spec = EvaluationSpec::default();
    let all = recognize_runs(
        &mut IcpRecognizer::new(IcpConfig {
            only_best: false,
            ..IcpConfig::default()
        }),
        &runs,
    );
    let ea = evaluate(&all, &spec);
    eprintln!(
        "icp, every accepted region: {} matches, {:?}",
        all.matches.len(),
        ea.main
    );
    assert!(r.matches.len() <= icp.region_count());
    assert!(all.matches.len() >= r.matches.len());
    let e = evaluate(&r, &spec);
    eprintln!(
        "icp: {} observations, {} regions, {} matches, {:?}",
        r.observations.len(),
        icp.region_count(),
        r.matches.len(),
        e.main
    );
    // One observation per 0.1 m of travel, about 48 m a lap.
    let per_lap = r.observations.len() as f64 / 3.0;
    assert!((470.0..=490.0).contains(&per_lap), "{per_lap}");
    assert!(e.main.pairs > 0);
    // ICP accepts every corridor stretch that looks like another; the best of them is right
    // most of the time on this small loop with pillars.
    assert!(e.main.precision > 0.5, "{:?}", e.main);
    assert!(e.main.recall > 0.5, "{:?}", e.main);
    assert!(ea.main.precision < e.main.precision, "{:?}", ea.main);

    let mut report = Report::new("loop", 1, r.laps, spec.clone());
    report.add_level(1, &[6], &r);
    report.add_subject("icp", SubjectKind::Icp, &r);
    report.finish();
    assert_eq!(report.revisits, e.main.revisits);
    assert_eq!(report.subject("icp").unwrap().scores.pairs, e.main.pairs);
    let pass = ExpectSpec {
        subjects: vec![
            SubjectExpectation {
                subject: "words-1".into(),
                min_precision: Some(0.5),
                min_recall: Some(0.5),
                min_visit_recall: None,
                min_pair_recall: None,
                max_seconds_per_lap: None,
                same: None,
                opposite: None,
            },
            SubjectExpectation {
                subject: "icp".into(),
                min_precision: Some(0.5),
                min_recall: None,
                min_visit_recall: None,
                min_pair_recall: None,
                max_seconds_per_lap: None,
                same: None,
                opposite: None,
            },
        ],
        quantile: None,
        regression: None,
    };
    let outcomes = check(&report, &pass);
    assert_eq!(exit_code(&outcomes), 0, "{outcomes:?}");
    let too_high = ExpectSpec {
        subjects: vec![SubjectExpectation {
            subject: "words-1".into(),
            min_precision: Some(1.01),
            min_recall: None,
            min_visit_recall: None,
            min_pair_recall: None,
            max_seconds_per_lap: None,
            same: None,
            opposite: None,
        }],
        quantile: None,
        regression: None,
    };
    let outcomes = check(&report, &too_high);
    assert_eq!(exit_code(&outcomes), 1);
    let xml = junit_xml(&[Suite {
        scenario: "loop".into(),
        file: "loop.toml".into(),
        reproduce_flags: String::new(),
        outcomes,
        error: None,
        seconds: r.seconds,
        seeds_run: 1,
    }]);
    assert!(
        xml.contains("<failure message=\"FAIL loop words-1 precision"),
        "{xml}"
    );
}

#[test]
fn icp_is_deterministic_whatever_the_threads() {
    let runs = runs(1, 2);
    let go = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut icp = IcpRecognizer::new(IcpConfig::default());
                recognize_runs(&mut icp, &runs).matches
            })
    };
    let two = go(2);
    assert_eq!(go(1), two);
    let mut serial = IcpRecognizer::new(IcpConfig {
        parallel: false,
        ..IcpConfig::default()
    });
    assert_eq!(recognize_runs(&mut serial, &runs).matches, two);
}

/// How the ICP baseline's cost grows with laps (every new region meets every past one):
/// `cargo test --release --test it icp_cost -- --ignored --nocapture`.
#[test]
#[ignore]
fn icp_cost_over_twenty_laps() {
    let runs = runs(1, 20);
    let mut icp = IcpRecognizer::new(IcpConfig::default());
    let r = recognize_runs(&mut icp, &runs);
    let e = evaluate(&r, &EvaluationSpec::default());
    eprintln!(
        "icp over {} laps: {:.3} s/lap, {} regions, {} matches, P {:.3} R {:.3}",
        r.laps,
        r.seconds_per_lap(),
        icp.region_count(),
        r.matches.len(),
        e.main.precision,
        e.main.recall
    );
}

/// The ICP baseline on `worlds/institute-floor.toml` (all doors closed, no noise): its cost
/// per lap for a few laps, to extrapolate to scenario B:
/// `cargo test --release --test it icp_cost_on_institute -- --ignored --nocapture`.
#[test]
#[ignore]
fn icp_cost_on_institute_floor() {
    let world = placewords::world::load_world(std::path::Path::new("worlds/institute-floor.toml"))
        .expect("the shipped world loads");
    let walls = world.obstacle_outline(&placewords::world::DoorStates::all_closed(&world));
    let route = world.route("lap").expect("route lap").waypoints.clone();
    let laps = 6;
    let runs = drive(&walls, &route, 0.1, 1, laps);
    let mut icp = IcpRecognizer::new(IcpConfig::default());
    let mut per_lap = Vec::new();
    let r = placewords::eval::recognize_runs_with_progress(&mut icp, &runs, &mut |_| {
        per_lap.push(std::time::Instant::now())
    });
    let e = evaluate(&r, &EvaluationSpec::default());
    let lap_s: Vec<String> = per_lap
        .windows(2)
        .map(|w| format!("{:.2}", (w[1] - w[0]).as_secs_f64()))
        .collect();
    eprintln!(
        "icp on institute-floor, {laps} laps: {:.3} s/lap on average, lap times {:?}, {:?}, {} regions, {} matches, P {:.3} R {:.3}",
        r.seconds_per_lap(),
        lap_s,
        icp.stats(),
        icp.region_count(),
        r.matches.len(),
        e.main.precision,
        e.main.recall
    );
}
