//! World authoring aids: the density map, the ambiguity map, the world generator.

use super::common::{placewords, root};
use placewords::authoring::ambiguity::ambiguity;
use placewords::authoring::density::{DEFAULT_SAMPLE_M, density_map, density_svg};
use placewords::authoring::generate::{GenerateOptions, generate_toml};
use placewords::geom::Vec2;
use placewords::recognizer::RecognizerConfig;
use placewords::world::{DoorStates, World};
use placewords::world::{load_world, parse_world};

/// A corridor loop whose south and north corridors are the same: three niches each at the same
/// distances along travel. The east corridor is wider than the west one, so nothing else
/// repeats. `extra_niche` adds a fourth niche to the north corridor only.
fn twin_corridors(extra_niche: bool) -> World {
    parse_world(&twin_corridors_src(extra_niche), "twin-corridors")
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The file text of [`twin_corridors`].
fn twin_corridors_src(extra_niche: bool) -> String {
    let north_extra = if extra_niche {
        "[18.6, 11.0], [18.6, 12.5], [17.4, 12.5], [17.4, 11.0], "
    } else {
        ""
    };
    format!(
        r#"format_version = 1
name = "twin-corridors"

[robot_home]
x_m = 1.0
y_m = 0.0

[[walls]]
id = "outer"
points_m = [[-1.0, -1.0], [8.0, -1.0], [8.0, -2.5], [10.0, -2.5], [10.0, -1.0], [14.0, -1.0], [14.0, -2.5], [16.0, -2.5], [16.0, -1.0], [20.0, -1.0], [20.0, -2.5], [22.0, -2.5], [22.0, -1.0], [31.6, -1.0], [31.6, 11.0], [22.0, 11.0], [22.0, 12.5], [20.0, 12.5], [20.0, 11.0], {north_extra}[16.0, 11.0], [16.0, 12.5], [14.0, 12.5], [14.0, 11.0], [10.0, 11.0], [10.0, 12.5], [8.0, 12.5], [8.0, 11.0], [-1.0, 11.0]]
closed = true

[[walls]]
id = "inner"
points_m = [[1.0, 1.0], [28.4, 1.0], [28.4, 9.0], [1.0, 9.0]]
closed = true

[[routes]]
id = "lap"
waypoints_m = [[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [0.0, 10.0]]
"#
    )
}

fn config(levels: usize) -> RecognizerConfig {
    RecognizerConfig::default().with_levels(levels)
}

#[test]
fn two_identical_corridors_are_flagged_and_a_niche_removes_the_flag() {
    for levels in [1, 3] {
        let twins = twin_corridors(false);
        let closed = DoorStates::all_closed(&twins);
        let (report, _) = ambiguity(&twins, "lap", &closed, &config(levels), 1.0).unwrap();
        assert_eq!(report.pairs, 1, "levels {levels}: {}", report.summary());
        // The pair is the south corridor (0-30 m along the route) and the north one (40-70 m).
        let (a, b) = (&report.stretches[0], &report.stretches[1]);
        // Counted from 0, as every number a person reads: stretches 0 and 1, pair 0.
        assert_eq!((a.number, b.number, a.pair, b.pair), (0, 1, 0, 0));
        assert_eq!((a.partners.clone(), b.partners.clone()), (vec![1], vec![0]));
        let centre = |s: &placewords::authoring::AmbiguousStretch| s.from_m + s.length_m / 2.0;
        assert!((0.0..30.0).contains(&centre(a)), "{}", report.summary());
        assert!((40.0..70.0).contains(&centre(b)), "{}", report.summary());

        let fixed = twin_corridors(true);
        let (report, _) = ambiguity(&fixed, "lap", &closed, &config(levels), 1.0).unwrap();
        assert!(
            report.stretches.is_empty(),
            "levels {levels}: {}",
            report.summary()
        );
    }
}

#[test]
fn ambiguity_cli_writes_a_picture_and_json_with_the_stretches() {
    let dir = tempfile::tempdir().unwrap();
    let world = dir.path().join("gen.toml");
    let out = dir.path().join("amb.svg");
    let gen_out = placewords(&[
        "world",
        "generate",
        "--seed",
        "7",
        "--doors",
        "8",
        "-o",
        world.to_str().unwrap(),
    ]);
    assert!(
        gen_out.status.success(),
        "{}",
        String::from_utf8_lossy(&gen_out.stderr)
    );
    let run = placewords(&[
        "world",
        "ambiguity",
        world.to_str().unwrap(),
        "--route",
        "lap",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let stretches = json["stretches"].as_array().unwrap();
    for s in stretches {
        for key in ["from_m", "to_m", "length_m"] {
            assert!(s[key].as_f64().is_some(), "{s}");
        }
        assert!(!s["partners"].as_array().unwrap().is_empty(), "{s}");
    }
    let svg = std::fs::read_to_string(&out).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let bands = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("band"))
        .count();
    let slips = json["slips"].as_array().unwrap().len();
    assert_eq!(bands, stretches.len() + slips);
}

/// Issue 26 point 1: a long corridor with nothing along it is a slip (the alignment can slide
/// along it), even where no two places have the same words; a corridor with niches is not.
#[test]
fn a_featureless_corridor_is_flagged_as_a_slip_with_its_uncertainty() {
    let plain = parse_world(
        r#"format_version = 1
name = "plain-loop"

[robot_home]
x_m = 1.0
y_m = 0.0

[[walls]]
id = "outer"
points_m = [[-1.0, -1.0], [41.0, -1.0], [41.0, 11.0], [-1.0, 11.0]]
closed = true

[[walls]]
id = "inner"
points_m = [[1.0, 1.0], [39.0, 1.0], [39.0, 9.0], [1.0, 9.0]]
closed = true

[[routes]]
id = "lap"
waypoints_m = [[0.0, 0.0], [40.0, 0.0], [40.0, 10.0], [0.0, 10.0]]
"#,
        "plain-loop",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let closed = DoorStates::all_closed(&plain);
    let (report, _) = ambiguity(&plain, "lap", &closed, &config(3), 1.0).unwrap();
    // The 40 m corridors (0-40 m and 50-90 m along the route) slip in their middles, by more
    // than twice the radius.
    let covers = |s: &placewords::authoring::slip::SlipStretch, x: f64| {
        (x - s.from_m).rem_euclid(report.route_length_m) <= s.length_m
    };
    for middle in [20.0, 70.0] {
        let slip = report.slips.iter().find(|s| covers(s, middle));
        assert!(
            slip.is_some_and(|s| s.uncertainty_m > 2.0),
            "{middle} m: {}",
            report.summary()
        );
    }
    assert!(report.flagged_share >= report.slip_share && report.slip_share > 0.0);
    assert!(report.summary().contains("slide"), "{}", report.summary());
    // Niches every few metres pin the alignment: the south corridor of the twins does not slip
    // around its niches (8-22 m).
    let twins = twin_corridors(false);
    let twins_closed = DoorStates::all_closed(&twins);
    let (report, _) = ambiguity(&twins, "lap", &twins_closed, &config(3), 1.0).unwrap();
    let covers = |s: &placewords::authoring::slip::SlipStretch, x: f64| {
        (x - s.from_m).rem_euclid(report.route_length_m) <= s.length_m
    };
    assert!(
        !report.slips.iter().any(|s| covers(s, 15.0)),
        "{}",
        report.summary()
    );
}

/// Issue 26 point 1: a scenario's map drives every door set its runs use; a random-door run
/// stands for its distribution by a few draws.
#[test]
fn a_scenario_map_drives_each_door_set_of_its_runs_once() {
    use placewords::authoring::prediction::{RANDOM_DOOR_DRAWS, scenario_drive_settings};
    let b = placewords::experiment::load_scenario(&root().join("scenarios/B.toml")).unwrap();
    let names: Vec<String> = scenario_drive_settings(&b)
        .door_sets
        .iter()
        .map(|d| d.name.clone())
        .collect();
    assert_eq!(
        names,
        ["all-closed", "one-per-corridor-a", "one-per-corridor-b"]
    );
    let smoke =
        placewords::experiment::load_scenario(&root().join("scenarios/smoke.toml")).unwrap();
    let sets = scenario_drive_settings(&smoke).door_sets;
    // Three cycled sets, then up to RANDOM_DOOR_DRAWS distinct draws of the random run.
    assert!(
        sets.len() > 3 && sets.len() <= 3 + RANDOM_DOOR_DRAWS,
        "{}",
        sets.len()
    );
    assert!(sets[3..].iter().all(|d| d.name.starts_with("random")));
    for (i, a) in sets.iter().enumerate() {
        assert!(
            sets[i + 1..].iter().all(|b| b.states != a.states),
            "a set driven twice"
        );
    }
}

/// Issue 26 point 1: `world ambiguity --scenario … --measure SEEDS` runs the scenario, places
/// each false pair on the route and says how many lie in flagged stretches. On the twin
/// corridors the recognizer's wrong pairs join the two corridors, which the map flags.
#[test]
fn measuring_the_map_against_the_recognizer_places_false_pairs_in_flagged_stretches() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("twins.toml"), twin_corridors_src(false)).unwrap();
    let scenario = dir.path().join("twins.scenario.toml");
    std::fs::write(
        &scenario,
        r#"format_version = 1
name = "twins"
world = "twins.toml"
route = "lap"
seed = 1

[[runs]]
start_waypoint = 0
laps = 6

[[runs]]
start_waypoint = 2
laps = 6

[laser]
preset = "lms200"

[odometry]
model = "proportional"
"#,
    )
    .unwrap();
    let svg = dir.path().join("a.svg");
    let out = placewords(&[
        "world",
        "ambiguity",
        "--scenario",
        scenario.to_str().unwrap(),
        "--measure",
        "1..2",
        "-o",
        svg.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &json["prediction"];
    let (wrong, hit) = (
        p["false_pairs"].as_u64().unwrap(),
        p["predicted"].as_u64().unwrap(),
    );
    let per_seed = p["per_seed"].as_array().unwrap();
    assert_eq!(per_seed.len(), 2);
    let sum = |k: usize| per_seed.iter().map(|s| s[k].as_u64().unwrap()).sum::<u64>();
    assert_eq!((sum(1), sum(2)), (wrong, hit));
    assert_eq!(p["places_m"].as_array().unwrap().len() as u64, wrong);
    let flagged = p["flagged_share"].as_f64().unwrap();
    assert!(flagged > 0.0 && flagged < 1.0, "{p}");
    assert!(wrong > 0, "the twins confuse the recognizer: {p}");
    assert!(hit as f64 >= 0.7 * wrong as f64, "{p}");
    assert!(svg.exists());
}

#[test]
fn unknown_route_is_an_error_naming_the_routes() {
    // Not `-o /dev/null`: an atomic write renames its temporary file onto the target.
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("a.svg");
    let out = placewords(&[
        "world",
        "ambiguity",
        "worlds/loop-small.toml",
        "--route",
        "lapp",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no route 'lapp'") && err.contains("lap"),
        "{err}"
    );
}

#[test]
fn density_map_uses_the_recognizer_classes_and_sees_the_hall_wider_than_a_corridor() {
    let w = load_world(&root().join("worlds/institute-floor.toml")).unwrap();
    let closed = DoorStates::all_closed(&w);
    let cfg = RecognizerConfig::default();
    let map = density_map(&w, &closed, &cfg, DEFAULT_SAMPLE_M);
    // The entrance hall at A (6.5 m x 6.5 m) is wider than the south corridor's middle.
    let hall = map.class_at(Vec2::new(2.5, 2.5)).expect("hall is free");
    let corridor = map
        .class_at(Vec2::new(20.0, 0.0))
        .expect("corridor is free");
    assert!(hall > corridor, "hall {hall}, corridor {corridor}");
    // Inside a closed office nothing is coloured; its door open, it is.
    let room_door = w.door_index("s-12").unwrap();
    let d = &w.doors[room_door];
    let inside = d.panel(true).b;
    assert_eq!(map.class_at(inside), None);
    let mut open = closed.clone();
    open.open[room_door] = true;
    let map_open = density_map(&w, &open, &cfg, DEFAULT_SAMPLE_M);
    assert!(
        map_open
            .class_at(inside + (inside - d.hinge) * 0.5)
            .is_some()
    );
    let svg = density_svg(&w, &closed, &map, "t");
    let doc = roxmltree::Document::parse(&svg).unwrap();
    assert!(
        doc.descendants()
            .any(|n| n.attribute("id") == Some("tiles"))
    );
}

#[test]
fn a_hundred_generated_floors_pass_the_checks() {
    for seed in 0..100u64 {
        let opts = GenerateOptions {
            seed,
            size_m: (
                50.0 + 10.0 * (seed % 3) as f64,
                40.0 + 10.0 * (seed % 2) as f64,
            ),
            doors: 2 + (seed % 3) as usize,
            corridors: 4 + 2 * (seed % 5) as usize,
            double_loaded: seed % 4 == 1,
            look_alike: seed % 7 == 3,
        };
        let text = generate_toml(&opts).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let w = parse_world(&text, "generated").unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(w.doors.len(), opts.doors);
        assert_eq!(w.route("lap").unwrap().waypoints.len(), opts.corridors);
    }
}

/// Issue 26's done-when on a few seeds (the report has 20): a double-loaded 60 x 30 m floor with
/// 30 offices passes `world check`, test drive included, with a walking area per corridor.
#[test]
fn double_loaded_floors_with_thirty_rooms_pass_world_check() {
    for seed in [0u64, 7, 19] {
        let opts = GenerateOptions {
            seed,
            size_m: (60.0, 30.0),
            doors: 30,
            double_loaded: true,
            ..GenerateOptions::default()
        };
        let text = generate_toml(&opts).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let w = placewords::sim::test_drive::check_world_text(&text, "ward")
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(w.doors.len(), 30);
        assert_eq!(w.areas.len(), 4, "seed {seed}: a walking area per corridor");
        // Both sides: some doors open into the courtyard side of the loop, some outwards.
        let lap = w.route("lap").unwrap();
        let (lo, hi) = lap.waypoints.iter().fold(
            (Vec2::new(f64::MAX, f64::MAX), Vec2::new(f64::MIN, f64::MIN)),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let inside = w
            .doors
            .iter()
            .filter(|d| {
                let h = d.hinge;
                h.x > lo.x && h.x < hi.x && h.y > lo.y && h.y < hi.y
            })
            .count();
        assert!(
            inside > 0 && inside < 30,
            "seed {seed}: {inside} doors inside the loop"
        );
    }
}

/// `--look-alike` makes every office the same width with its door at the same place.
#[test]
fn look_alike_floors_repeat_one_office() {
    let opts = GenerateOptions {
        seed: 4,
        size_m: (60.0, 30.0),
        doors: 20,
        double_loaded: true,
        look_alike: true,
        ..GenerateOptions::default()
    };
    let spec = placewords::authoring::generate::generate_spec(&opts).unwrap();
    let offices: Vec<_> = spec
        .walls
        .iter()
        .filter(|w| w.id.starts_with("office-"))
        .collect();
    assert_eq!(offices.len(), 20);
    for (w, d) in offices.iter().zip(&spec.doors) {
        let (a, b) = (w.points_m[1], w.points_m[2]);
        let width = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        assert!((width - 4.0).abs() < 1e-6, "{}: {width} m wide", w.id);
        let f = w.points_m[0];
        let at = ((d.hinge_m[0] - f[0]).powi(2) + (d.hinge_m[1] - f[1]).powi(2)).sqrt();
        assert!(
            (at - 0.5).abs() < 1e-6,
            "{}: door {at} m from the office's side",
            d.id
        );
    }
    assert!(generate_toml(&opts).is_ok());
}

#[test]
fn generate_cli_is_deterministic_and_refuses_impossible_floors() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.toml"), dir.path().join("b.toml"));
    for p in [&a, &b] {
        let out = placewords(&[
            "world",
            "generate",
            "--seed",
            "3",
            "--size-m",
            "50,40",
            "-o",
            p.to_str().unwrap(),
        ]);
        assert!(out.status.success());
    }
    // `--size-m` in the form its default shows and in the spaced form (issue 27) give the same.
    let c = dir.path().join("c.toml");
    let spaced = placewords(&[
        "world",
        "generate",
        "--seed",
        "3",
        "--size-m",
        "50 40",
        "-o",
        c.to_str().unwrap(),
    ]);
    assert!(
        spaced.status.success(),
        "{}",
        String::from_utf8_lossy(&spaced.stderr)
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());
    let help = placewords(&["world", "generate", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    let shown = help
        .split("[default: ")
        .nth(1)
        .and_then(|t| t.split(']').next())
        .unwrap_or_else(|| panic!("no default in:\n{help}"))
        .to_string();
    let d = dir.path().join("d.toml");
    let default_form = placewords(&[
        "world",
        "generate",
        "--seed",
        "3",
        "--size-m",
        &shown,
        "-o",
        d.to_str().unwrap(),
    ]);
    assert!(
        default_form.status.success(),
        "--size-m {shown}: {}",
        String::from_utf8_lossy(&default_form.stderr)
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let check = placewords(&["world", "check", a.to_str().unwrap()]);
    assert!(check.status.success());
    let bad = placewords(&[
        "world",
        "generate",
        "--seed",
        "3",
        "--corridors",
        "5",
        "-o",
        a.to_str().unwrap(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn a_scenario_over_a_generated_floor_runs() {
    let out = placewords(&[
        "run",
        "tests/fixtures/generated/laps.toml",
        "--levels",
        "1",
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("generated-laps"));
}

#[test]
fn render_of_an_invalid_world_marks_each_problem_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad.svg");
    let run = placewords(&[
        "world",
        "render",
        "tests/fixtures/invalid/leg-through-wall.toml",
        "-o",
        out.to_str().unwrap(),
        "--grid",
        "--waypoints",
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("leg-through-wall.toml:28:"));
    let svg = std::fs::read_to_string(&out).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let class = |c: &str| {
        doc.descendants()
            .filter(|n| n.attribute("class") == Some(c))
            .count()
    };
    assert_eq!(class("problem"), 1);
    assert_eq!(class("waypoint"), 6);
    assert!(doc.descendants().any(|n| n.attribute("id") == Some("grid")));
    // The problem sits on the waypoint its message points at (waypoint 4 of the route).
    let mark = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("problem"))
        .and_then(|g| g.first_element_child())
        .unwrap();
    let wp4 = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("waypoint"))
        .nth(3)
        .and_then(|g| g.first_element_child())
        .unwrap();
    assert_eq!(mark.attribute("cx"), wp4.attribute("cx"));
    assert_eq!(mark.attribute("cy"), wp4.attribute("cy"));
}

#[test]
fn render_of_a_file_that_is_not_toml_writes_no_picture() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad.svg");
    let run = placewords(&[
        "world",
        "render",
        "tests/fixtures/invalid/syntax-unclosed-string.toml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(!out.exists());
}

/// Renders an invalid fixture; the picture's document text.
fn problem_picture(fixture: &str, extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad.svg");
    let file = format!("tests/fixtures/invalid/{fixture}.toml");
    let mut args = vec![
        "world",
        "render",
        file.as_str(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let run = placewords(&args);
    assert_eq!(run.status.code(), Some(2));
    std::fs::read_to_string(&out).unwrap()
}

fn by_class<'a>(doc: &'a roxmltree::Document, c: &str) -> Vec<roxmltree::Node<'a, 'a>> {
    doc.descendants()
        .filter(|n| n.attribute("class") == Some(c))
        .collect()
}

/// The (cx, cy) of the ring of a mark group.
fn ring(g: roxmltree::Node) -> (String, String) {
    let c = g.first_element_child().unwrap();
    (
        c.attribute("cx").unwrap().to_string(),
        c.attribute("cy").unwrap().to_string(),
    )
}

/// A problem in a door that did not read (a misspelt key) is marked on that door's hinge, not
/// on the entity before it in the file, and the note under the picture says so; marks count
/// from 0.
#[test]
fn a_problem_in_an_unread_door_is_marked_on_its_hinge() {
    let svg = problem_picture("unknown-key-typo", &[]);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let problems = by_class(&doc, "problem");
    let first = problems[0];
    assert_eq!(first.last_element_child().unwrap().text(), Some("0"));
    // The door's hinge [5, 2] is where wall 'room' starts.
    let wall = doc
        .descendants()
        .find(|n| n.attribute("id") == Some("wall-room-0"))
        .unwrap();
    let hinge = (
        wall.attribute("x1").unwrap().to_string(),
        wall.attribute("y1").unwrap().to_string(),
    );
    assert_eq!(ring(first), hinge);
    assert!(
        svg.contains("drawn at what read of door &apos;d-1&apos;")
            || svg.contains("drawn at what read of door 'd-1'"),
        "{svg}"
    );
}

/// Marks on one spot (a problem on a waypoint) fan their numbers out, each with a leader line,
/// while their rings stay on the spot; every message is written whole, wrapped.
#[test]
fn stacked_marks_fan_out_and_messages_are_written_whole() {
    let svg = problem_picture("leg-through-wall", &["--waypoints"]);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let problem = by_class(&doc, "problem")[0];
    let waypoint = by_class(&doc, "waypoint")[3];
    assert_eq!(ring(problem), ring(waypoint));
    let text_x = |g: roxmltree::Node| {
        g.descendants()
            .find(|n| n.has_tag_name("text"))
            .and_then(|t| t.attribute("x"))
            .map(str::to_string)
    };
    assert_ne!(text_x(problem), text_x(waypoint));
    assert!(problem.descendants().any(|n| n.has_tag_name("line")));
    let notes: String = doc
        .descendants()
        .find(|n| n.attribute("id") == Some("notes"))
        .unwrap()
        .descendants()
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join(" ");
    let words = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        words(&notes).contains("so the leg keeps 0.25 m from walls and doors"),
        "{notes}"
    );
}

/// A door whose open heading is at fault is drawn open, so the panel that cuts the wall shows.
#[test]
fn the_offending_open_panel_is_drawn() {
    let svg = problem_picture("door-open-through-wall", &[]);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    assert!(
        doc.descendants()
            .any(|n| n.attribute("class") == Some("door open")
                && n.attribute("id") == Some("door-d-1")),
        "door d-1 is not drawn open"
    );
}

/// The density map draws the route over its colours, on a white casing.
#[test]
fn the_density_map_shows_the_route() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d.svg");
    let run = placewords(&[
        "world",
        "density",
        "worlds/loop-small.toml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    let (tiles, casing) = (
        svg.find(r#"id="tiles""#).unwrap(),
        svg.find("route-casing").unwrap(),
    );
    assert!(
        casing > tiles,
        "the route is drawn under the density colours"
    );
}
