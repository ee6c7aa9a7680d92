//! World files: every shipped file loads, invalid fixtures give their located messages, random
//! input never panics, the SVG render is well-formed, and the `world` commands behave.

use super::common::{placewords, root};
use placewords::report::{PathOverlay, RenderOptions, SegmentOverlay, render_world_svg};
use placewords::spec::SpecError;
use placewords::world::info::world_info;
use placewords::world::{DoorStates, World};
use placewords::world::{load_world, parse_world};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Checks one authored file; `Err` holds every problem as text.
type Loader = fn(&Path) -> Result<(), String>;

fn check_world_file(path: &Path) -> Result<(), String> {
    load_world(path).map(|_| ()).map_err(|e| e.to_string())
}

/// Scenario files load with their world, runs, door configurations and recognizer settings.
fn check_scenario_file(path: &Path) -> Result<(), String> {
    placewords::experiment::load_scenario(path)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Each folder of authored files with the loader that checks its files. Extend here.
fn loaders() -> Vec<(&'static str, Loader)> {
    vec![
        ("worlds", check_world_file as Loader),
        ("scenarios", check_scenario_file as Loader),
    ]
}

fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

#[test]
fn every_authored_file_loads() {
    let mut checked = 0;
    let mut problems = Vec::new();
    for (folder, loader) in loaders() {
        for f in toml_files(&root().join(folder)) {
            checked += 1;
            if let Err(e) = loader(&f) {
                problems.push(e);
            }
        }
    }
    assert!(
        checked >= 3,
        "expected the shipped worlds, found {checked} files"
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

fn shipped(name: &str) -> World {
    load_world(&root().join("worlds").join(name)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn shipped_worlds_meet_their_briefs() {
    for f in toml_files(&root().join("worlds")) {
        let w = load_world(&f).unwrap();
        assert!(w.route("lap").is_some(), "{}: no route 'lap'", f.display());
        assert!(!w.areas.is_empty(), "{}: no walking areas", f.display());
        assert!(!w.doors.is_empty(), "{}: no doors", f.display());
    }
    let inst = world_info(&shipped("institute-floor.toml"));
    assert!(inst.doors >= 30, "{} doors", inst.doors);
    let lap = inst.routes.iter().find(|r| r.id == "lap").unwrap();
    assert!(lap.length_m >= 150.0, "lap {} m", lap.length_m);
    assert!(lap.corners >= 6, "{} corners", lap.corners);

    let small = world_info(&shipped("loop-small.toml"));
    let lap = small.routes.iter().find(|r| r.id == "lap").unwrap();
    assert!(
        (40.0..=60.0).contains(&lap.length_m),
        "lap {} m",
        lap.length_m
    );
    assert!(small.doors >= 6);

    // The open-space world (issue 28): a wall-free rectangle of at least 40 m x 30 m (the hall,
    // x 0.5..43.5 m, y 0.5..33.5 m inside its walls) that the lap crosses for at least 40 m.
    let hall = shipped("hall.toml");
    let (lo, hi) = ((0.5, 0.5), (43.5, 33.5));
    assert!(hi.0 - lo.0 >= 40.0 && hi.1 - lo.1 >= 30.0);
    let inside =
        |p: placewords::geom::Vec2| (lo.0..=hi.0).contains(&p.x) && (lo.1..=hi.1).contains(&p.y);
    let on = |s: placewords::geom::Segment, step_m: f64| {
        let n = (s.length() / step_m).ceil().max(1.0) as usize;
        (0..=n).map(move |k| s.point_at(k as f64 / n as f64))
    };
    for w in &hall.walls {
        for s in w.segments() {
            assert!(!on(s, 0.05).any(inside), "wall {} enters the hall", w.id);
        }
    }
    let legs = hall.route("lap").unwrap().legs();
    let open_m: f64 = (legs.iter())
        .map(|leg| on(*leg, 0.1).filter(|&p| inside(p)).count() as f64 * 0.1)
        .sum();
    assert!(
        open_m >= 40.0,
        "the hall's lap crosses only {open_m:.1} m of the hall"
    );
}

/// Where the fixtures live, spelt as messages show them (relative to the crate root).
const INVALID: &str = "tests/fixtures/invalid";

/// Each `NAME.toml` in the invalid fixtures gives exactly the lines of `NAME.expected`.
/// To re-mint the expected files after an intended wording change, run the test with
/// `PLACEWORDS_BLESS=1` and review the diff.
#[test]
fn invalid_fixtures_give_their_messages() {
    let dir = root().join(INVALID);
    let files = toml_files(&dir);
    assert!(files.len() >= 15, "only {} invalid fixtures", files.len());
    let bless = std::env::var_os("PLACEWORDS_BLESS").is_some();
    let mut failures = Vec::new();
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let shown = format!("{INVALID}/{name}");
        let src = std::fs::read_to_string(&f).unwrap();
        let got = match parse_world(&src, &shown) {
            Ok(_) => {
                failures.push(format!("{shown}: accepted, but it is an invalid fixture"));
                continue;
            }
            Err(e) => e.to_string(),
        };
        let expected_path = f.with_extension("expected");
        if bless {
            std::fs::write(&expected_path, format!("{got}\n")).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|_| panic!("{} is missing", expected_path.display()));
        if expected.trim_end() != got.trim_end() {
            failures.push(format!(
                "{shown}:\n  expected: {}\n  got:      {}",
                expected.trim_end().replace('\n', "\n            "),
                got.replace('\n', "\n            ")
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-mint with PLACEWORDS_BLESS=1 if the change is intended)",
        failures.join("\n")
    );
}

/// The invalid fixtures are each one mistake away from `tests/fixtures/valid-base.toml`, which
/// must itself be valid (so each fixture's message is about its own mistake).
#[test]
fn the_fixtures_base_is_valid() {
    if let Err(e) = load_world(&root().join("tests/fixtures/valid-base.toml")) {
        panic!("{e}");
    }
}

#[test]
fn a_file_with_several_mistakes_reports_them_all() {
    let src = std::fs::read_to_string(root().join(INVALID).join("many-problems.toml")).unwrap();
    let err = parse_world(&src, "x.toml").unwrap_err();
    assert!(err.diagnostics().len() >= 3, "{err}");
}

/// A key typo, a number error and a geometric mistake in one file: all three are reported,
/// each at its place (the parts that read are checked geometrically).
#[test]
fn three_mistakes_of_different_kinds_are_all_reported() {
    use placewords::spec::diag::Severity;
    let src = std::fs::read_to_string(root().join(INVALID).join("three-kinds.toml")).unwrap();
    let err = parse_world(&src, "x.toml").unwrap_err();
    let errors: Vec<_> = err
        .diagnostics()
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .map(|d| (d.line, d.col, d.message.as_str()))
        .collect();
    assert_eq!(errors.len(), 3, "{err}");
    assert!(
        errors[0]
            .2
            .contains("`thickness_m` in wall 'room' is not a finite number"),
        "{err}"
    );
    assert_eq!((errors[0].0, errors[0].1), (17, 15));
    assert!(errors[1].2.contains("unknown key `widht_m`"), "{err}");
    assert_eq!((errors[1].0, errors[1].1), (23, 1));
    assert!(
        errors[2]
            .2
            .contains("waypoint 3 is 0.05 m from wall 'outer'"),
        "{err}"
    );
    assert_eq!((errors[2].0, errors[2].1), (29, 54));
}

/// A check that depends on a part that did not read is skipped with a note at its place, not
/// reported wrongly (the door does not "fail to span a gap" because its wall is missing).
#[test]
fn a_check_on_a_broken_part_is_skipped_with_a_note() {
    use placewords::spec::diag::Severity;
    let src = std::fs::read_to_string(root().join(INVALID).join("door-wall-unread.toml")).unwrap();
    let err = parse_world(&src, "x.toml").unwrap_err();
    let d = err.diagnostics();
    assert_eq!(
        d.iter().filter(|d| d.severity == Severity::Error).count(),
        1,
        "{err}"
    );
    assert!(
        !err.to_string().contains("does not span a wall gap"),
        "{err}"
    );
    let note = d
        .iter()
        .find(|d| d.severity == Severity::Note && d.message.contains("door 'd-1' not checked"))
        .unwrap_or_else(|| panic!("no note for the door: {err}"));
    assert_eq!((note.line, note.col), (21, 11), "{note}");
    assert!(note.message.contains("wall 'room'"), "{note}");
}

/// Refused at the segment limit, located (how fast: `benches/world.rs`).
#[test]
fn too_many_segments_are_refused() {
    let src = crate::big_world::zigzag_wall_world();
    let err = parse_world(&src, "big.toml").unwrap_err();
    let text = err.to_string();
    assert!(text.contains("limit 10000)"), "{text}");
    assert!(text.starts_with("big.toml:"), "{text}");
}

fn assert_located(err: &SpecError, src_lines: usize) {
    let d = err.diagnostics();
    assert!(!d.is_empty(), "an error without a location: {err}");
    for x in d {
        assert!(x.line >= 1 && x.col >= 1, "{x}");
        assert!(
            x.line <= src_lines + 1,
            "line {} beyond the file: {x}",
            x.line
        );
        assert!(!x.message.is_empty());
    }
}

/// Mutations of a valid file: delete, duplicate or replace characters or lines.
#[derive(Clone, Debug)]
enum Mutation {
    DeleteChar(usize),
    DuplicateChar(usize),
    ReplaceChar(usize, char),
    DeleteLine(usize),
    DuplicateLine(usize),
    ReplaceLine(usize, String),
    /// Replaces the i-th number of the file with another, often extreme, value.
    ReplaceNumber(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteChar),
        any::<usize>().prop_map(Mutation::DuplicateChar),
        (
            any::<usize>(),
            prop::sample::select(vec![
                '[', ']', '"', '=', ',', '.', '-', '0', '9', 'x', '\n', ' ', '#', 'é'
            ])
        )
            .prop_map(|(i, c)| Mutation::ReplaceChar(i, c)),
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), "[ -~]{0,30}").prop_map(|(i, s)| Mutation::ReplaceLine(i, s)),
        (
            any::<usize>(),
            prop_oneof![
                prop::sample::select(vec![
                    "0",
                    "-0.0",
                    "nan",
                    "inf",
                    "-inf",
                    "1e300",
                    "-1e9",
                    "0.3",
                    "3.0",
                    "360",
                    "99999999999999999999",
                    "1e-300",
                    "0x10",
                    "0.25",
                    "20000"
                ])
                .prop_map(str::to_string),
                (-50.0f64..50.0).prop_map(|x| format!("{x:.2}")),
            ]
        )
            .prop_map(|(i, s)| Mutation::ReplaceNumber(i, s)),
    ]
}

fn apply(src: &str, m: &Mutation) -> String {
    let chars: Vec<char> = src.chars().collect();
    let mut lines: Vec<String> = src.lines().map(str::to_string).collect();
    match m {
        Mutation::DeleteChar(i) => {
            let i = i % chars.len();
            chars[..i].iter().chain(&chars[i + 1..]).collect()
        }
        Mutation::DuplicateChar(i) => {
            let i = i % chars.len();
            chars[..=i].iter().chain(&chars[i..]).collect()
        }
        Mutation::ReplaceChar(i, c) => {
            let i = i % chars.len();
            let mut v = chars.clone();
            v[i] = *c;
            v.into_iter().collect()
        }
        Mutation::DeleteLine(i) => {
            let i = i % lines.len();
            lines.remove(i);
            lines.join("\n")
        }
        Mutation::DuplicateLine(i) => {
            let i = i % lines.len();
            let l = lines[i].clone();
            lines.insert(i, l);
            lines.join("\n")
        }
        Mutation::ReplaceLine(i, s) => {
            let i = i % lines.len();
            lines[i] = s.clone();
            lines.join("\n")
        }
        Mutation::ReplaceNumber(i, s) => {
            // Numbers: maximal runs of digits, '.', '-' and 'e' that start with a digit or '-'.
            let bytes = src.as_bytes();
            let mut spans = Vec::new();
            let mut k = 0;
            while k < bytes.len() {
                let b = bytes[k];
                let starts = (b.is_ascii_digit() || b == b'-')
                    && (k == 0 || matches!(bytes[k - 1], b' ' | b'[' | b','));
                if starts {
                    let start = k;
                    k += 1;
                    while k < bytes.len()
                        && (bytes[k].is_ascii_digit() || matches!(bytes[k], b'.' | b'e' | b'-'))
                    {
                        k += 1;
                    }
                    spans.push((start, k));
                } else {
                    k += 1;
                }
            }
            if spans.is_empty() {
                return src.to_string();
            }
            let (a, b) = spans[i % spans.len()];
            format!("{}{}{}", &src[..a], s, &src[b..])
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let src = String::from_utf8_lossy(&bytes);
        if let Err(e) = parse_world(&src, "random.toml") {
            assert_located(&e, src.lines().count());
        }
    }

    #[test]
    fn mutated_worlds_never_panic(
        muts in prop::collection::vec(mutation(), 1..4),
        which in prop::sample::select(vec!["loop-small.toml", "two-loops.toml"]),
    ) {
        let base = std::fs::read_to_string(root().join("worlds").join(which)).unwrap();
        let mut src = base;
        for m in &muts {
            src = apply(&src, m);
        }
        if let Err(e) = parse_world(&src, "mutated.toml") {
            assert_located(&e, src.lines().count());
        }
    }
}

fn parse_svg(svg: &str) -> roxmltree::Document<'_> {
    roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("the SVG is not XML: {e}"))
}

fn with_class<'a>(doc: &'a roxmltree::Document, class: &str) -> Vec<roxmltree::Node<'a, 'a>> {
    doc.descendants()
        .filter(|n| {
            n.attribute("class")
                .is_some_and(|c| c.split_whitespace().any(|x| x == class))
        })
        .collect()
}

#[test]
fn rendered_svg_parses_and_holds_every_wall_and_door() {
    for name in ["institute-floor.toml", "loop-small.toml", "two-loops.toml"] {
        let w = shipped(name);
        let mut states = DoorStates::all_closed(&w);
        for i in (0..w.doors.len()).step_by(3) {
            states.open[i] = true;
        }
        let opts = RenderOptions {
            doors: states.clone(),
            title: Some("a <title> & more".into()),
            paths: vec![PathOverlay {
                label: "trajectory".into(),
                color: "#d62728".into(),
                points: w.route("lap").unwrap().waypoints.clone(),
                dashed: true,
                width_px: 1.5,
            }],
            segments: vec![SegmentOverlay {
                color: "#000".into(),
                a: w.home.position(),
                b: w.home.position() + placewords::geom::Vec2::new(1.0, 1.0),
                dashed: false,
            }],
            ..RenderOptions::default()
        };
        let svg = render_world_svg(&w, &opts);
        let doc = parse_svg(&svg);
        let wall_segments: usize = w.walls.iter().map(|x| x.segments().len()).sum();
        assert_eq!(with_class(&doc, "wall").len(), wall_segments, "{name}");
        let doors = with_class(&doc, "door");
        assert_eq!(doors.len(), w.doors.len(), "{name}");
        let open = with_class(&doc, "open").len();
        assert_eq!(open, states.open.iter().filter(|o| **o).count(), "{name}");
        for d in &w.doors {
            let id = format!("door-{}", d.id);
            assert!(
                doors.iter().any(|n| n.attribute("id") == Some(id.as_str())),
                "{name}: no element for {id}"
            );
        }
        assert_eq!(with_class(&doc, "door-label").len(), w.doors.len());
        assert_eq!(with_class(&doc, "route").len(), w.routes.len());
        assert!(svg.contains("a &lt;title&gt; &amp; more"));
    }
}

#[test]
fn cli_check_reports_located_problems_and_exits_2() {
    let f = format!("{INVALID}/unknown-key-typo.toml");
    let out = placewords(&["world", "check", &f]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let expected =
        std::fs::read_to_string(root().join(INVALID).join("unknown-key-typo.expected")).unwrap();
    // The command prints the fixture's messages with their severity, as compilers do.
    let expected = expected.replacen(": unknown key", ": error: unknown key", 1);
    for line in expected.lines() {
        assert!(err.contains(line), "missing {line:?} in:\n{err}");
    }
    // A world with errors is not test-driven, and `world check` says so.
    assert!(
        err.contains(&format!("{f}:26:1: note: the routes were not test-driven")),
        "{err}"
    );
    assert!(
        err.contains(&format!("{f}:22:1: error: unknown key `widht_m`")),
        "{err}"
    );
}

#[test]
fn cli_check_passes_the_shipped_worlds() {
    let files: Vec<String> = toml_files(&root().join("worlds"))
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let mut args = vec!["world", "check"];
    args.extend(files.iter().map(String::as_str));
    let out = placewords(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn cli_info_json_has_the_promised_fields() {
    let out = placewords(&["world", "info", "worlds/institute-floor.toml", "--json"]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["name"], "institute-floor");
    assert!(v["doors"].as_u64().unwrap() >= 30);
    assert!(v["walls"].as_u64().unwrap() > 0);
    assert_eq!(v["bounds_m"].as_array().unwrap().len(), 2);
    let lap = &v["routes"][0];
    assert_eq!(lap["id"], "lap");
    assert!(lap["length_m"].as_f64().unwrap() >= 150.0);
    assert!(lap["corners"].as_u64().unwrap() >= 6);
}

#[test]
fn cli_render_writes_svg_and_suggests_door_ids() {
    let dir = tempfile::tempdir().unwrap();
    // An output file's folder must exist (it is not created).
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let out_svg = dir.path().join("sub/floor.svg");
    let o = out_svg.to_str().unwrap();
    let out = placewords(&[
        "world",
        "render",
        "worlds/loop-small.toml",
        "-o",
        o,
        "--open",
        "s-01,n-02",
        "--title",
        "two doors open",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&out_svg).unwrap();
    let doc = parse_svg(&svg);
    assert_eq!(with_class(&doc, "open").len(), 2);

    let out = placewords(&[
        "world",
        "render",
        "worlds/loop-small.toml",
        "-o",
        o,
        "--open",
        "s-1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no door 's-1'") && err.contains("did you mean"),
        "{err}"
    );

    let out = placewords(&[
        "world",
        "render",
        "worlds/loop-small.toml",
        "-o",
        o,
        "--all-open",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let svg = std::fs::read_to_string(&out_svg).unwrap();
    let w = shipped("loop-small.toml");
    assert_eq!(with_class(&parse_svg(&svg), "open").len(), w.doors.len());
}

/// The example in `src/spec/world.rs`'s module docs is a valid world.
#[test]
fn the_documented_example_is_valid() {
    let src = std::fs::read_to_string(root().join("src/spec/world.rs")).unwrap();
    let mut inside = false;
    let mut example = String::new();
    for line in src.lines() {
        let Some(doc) = line.strip_prefix("//!") else {
            continue;
        };
        let doc = doc.strip_prefix(' ').unwrap_or(doc);
        if doc.starts_with("```") {
            if inside {
                break;
            }
            inside = doc.trim() == "```toml";
            continue;
        }
        if inside {
            example.push_str(doc);
            example.push('\n');
        }
    }
    assert!(example.contains("[[doors]]"), "no example found");
    if let Err(e) = parse_world(&example, "doc-example.toml") {
        panic!("{e}");
    }
}

/// Free space reachable from the robot's home on a 0.1 m raster with the doors in `states`, or
/// `None` when it leaks out of the building (reaches the raster's border).
fn reachable_cells(w: &World, states: &DoorStates) -> Option<usize> {
    use placewords::geom::{Segment, Vec2};
    const CELL: f64 = 0.1;
    let (lo, hi) = w.bounds();
    let lo = lo - Vec2::new(1.0, 1.0);
    let hi = hi + Vec2::new(1.0, 1.0);
    let nx = ((hi.x - lo.x) / CELL).ceil() as usize + 1;
    let ny = ((hi.y - lo.y) / CELL).ceil() as usize + 1;
    let mut blocked = vec![false; nx * ny];
    let mut mark = |s: Segment| {
        let steps = (s.length() / (CELL / 2.0)).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let p = s.a + (s.b - s.a) * (k as f64 / steps as f64);
            let (cx, cy) = (
                ((p.x - lo.x) / CELL) as isize,
                ((p.y - lo.y) / CELL) as isize,
            );
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let (x, y) = (cx + dx, cy + dy);
                    if x >= 0 && y >= 0 && (x as usize) < nx && (y as usize) < ny {
                        blocked[y as usize * nx + x as usize] = true;
                    }
                }
            }
        }
    };
    w.wall_segments().into_iter().for_each(&mut mark);
    for (i, d) in w.doors.iter().enumerate() {
        mark(d.panel(states.is_open(i)));
    }
    let start = (
        ((w.home.x - lo.x) / CELL) as usize,
        ((w.home.y - lo.y) / CELL) as usize,
    );
    let mut seen = vec![false; nx * ny];
    let mut stack = vec![start];
    seen[start.1 * nx + start.0] = true;
    let mut count = 0;
    while let Some((x, y)) = stack.pop() {
        count += 1;
        if x == 0 || y == 0 || x + 1 == nx || y + 1 == ny {
            return None;
        }
        for (a, b) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
            let i = b * nx + a;
            if !seen[i] && !blocked[i] {
                seen[i] = true;
                stack.push((a, b));
            }
        }
    }
    Some(count)
}

/// Layout sanity of every shipped world: the building is closed with all doors closed and with
/// all open, and opening any single door reveals a room (at least 3 m² more free space).
#[test]
fn shipped_worlds_are_closed_and_every_door_opens_onto_a_room() {
    for f in toml_files(&root().join("worlds")) {
        let w = load_world(&f).unwrap();
        let name = f.display();
        let closed = reachable_cells(&w, &DoorStates::all_closed(&w))
            .unwrap_or_else(|| panic!("{name}: free space leaks out with all doors closed"));
        reachable_cells(&w, &DoorStates::all_open(&w))
            .unwrap_or_else(|| panic!("{name}: free space leaks out with all doors open"));
        for (i, d) in w.doors.iter().enumerate() {
            let mut s = DoorStates::all_closed(&w);
            s.open[i] = true;
            let open = reachable_cells(&w, &s)
                .unwrap_or_else(|| panic!("{name}: door '{}' opens onto the outside", d.id));
            let gained_m2 = (open as f64 - closed as f64) * 0.01;
            assert!(
                gained_m2 >= 3.0,
                "{name}: opening door '{}' adds only {gained_m2:.1} m² of free space",
                d.id
            );
        }
    }
}

/// A leg that clears a wall by less than the margin is usable, so `world check` passes (exit 0)
/// but says where and why as `file:line:col: warning: …`, in human and JSON form; the shipped
/// worlds give no warning.
#[test]
fn world_check_warns_about_a_tight_leg_and_still_passes() {
    let f = root().join("tests/fixtures/warnings/tight-leg.toml");
    let f = f.to_str().unwrap();
    let out = placewords(&["world", "check", f]);
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("tight-leg.toml:32:16: warning: route 'lap' leg from waypoint 0 to 1 passes"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("1 warning(s)"));
    let out = placewords(&["world", "check", "--message-format", "json", f]);
    let line = String::from_utf8_lossy(&out.stderr);
    let v: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(v["severity"], "warning");
    assert_eq!(v["line"], 32);
    for w in ["institute-floor", "loop-small", "two-loops", "hall"] {
        let p = root().join(format!("worlds/{w}.toml"));
        let out = placewords(&["world", "check", p.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(0));
        assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    }
}

/// A home heading that looks like radians is a warning (the world stays usable) at its value,
/// saying what it is in degrees.
#[test]
fn a_home_heading_in_radians_is_a_warning_with_its_degrees() {
    let f = root().join("tests/fixtures/warnings/home-heading-radians.toml");
    let (_, warnings) = placewords::world::check_world(&f).unwrap_or_else(|e| panic!("{e}"));
    let text: Vec<String> = warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        text.iter().any(|w| w.ends_with(
            "home-heading-radians.toml:8:15: warning: robot home heading_deg = 1.5708 looks like radians (90 degrees); headings are degrees: write heading_deg = 90"
        )),
        "{text:?}"
    );
}

/// Grid labels read "0" where the axis crosses zero, never "-0" (a world whose frame starts
/// just below zero rounds its first grid line up to minus zero).
#[test]
fn grid_labels_never_read_minus_zero() {
    for name in ["drivable/narrow-corners.toml", "valid-base.toml"] {
        let w = load_world(&root().join("tests/fixtures").join(name)).unwrap();
        let opts = RenderOptions {
            show_grid: true,
            ..RenderOptions::default()
        };
        let svg = render_world_svg(&w, &opts);
        assert!(!svg.contains(">-0<"), "{name}: a grid label reads -0");
        assert!(svg.contains(">0<"), "{name}: no grid label at 0");
    }
}
