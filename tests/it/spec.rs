//! Bad scenario files and the inputs fuzzing found: each fixture gives its located message.
//!
//! `tests/fixtures/invalid-scenarios/NAME.toml` and `tests/fixtures/fuzz/NAME.{toml,map}` sit
//! beside `NAME.expected`, the exact lines `placewords scenario check` (or `world check`, or
//! `world import` for `.map`) prints. Re-mint with `PLACEWORDS_BLESS=1` and review the diff.

use super::common::root;
use placewords::spec::diag::{MessageFormat, read_text};
use std::path::{Path, PathBuf};

/// The lines a file's check prints; `None` when the file is accepted.
fn problems(shown: &Path) -> Option<String> {
    let name = shown.to_string_lossy();
    let lines = if name.ends_with(".recognizer.toml") {
        let src = std::fs::read_to_string(shown).unwrap();
        placewords::experiment::parse_recognizer_config(&src, shown)
            .err()?
            .render(MessageFormat::Human)
    } else if name.ends_with(".map") {
        // `world import`: its repairs (warnings) and its error; `None` for a clean import.
        let src = match read_text(shown) {
            Err(e) => return Some(e.render(MessageFormat::Human).join("\n")),
            Ok(src) => src,
        };
        match placewords::authoring::import::import_map(&src, &name, "imported.toml") {
            Ok(w) if w.repairs.is_empty() => return None,
            Ok(w) => w.repairs.iter().map(ToString::to_string).collect(),
            Err(e) => vec![e.to_string()],
        }
    } else if name.ends_with(".world.toml") {
        placewords::world::load_world(shown)
            .err()?
            .render(MessageFormat::Human)
    } else {
        placewords::experiment::load_scenario(shown)
            .err()?
            .render(MessageFormat::Human)
    };
    Some(lines.join("\n"))
}

fn check_folder(folder: &str, at_least: usize) {
    // Paths as messages show them: relative to the crate root, where cargo runs tests.
    assert_eq!(std::env::current_dir().unwrap(), root());
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml" || x == "map"))
        .collect();
    files.sort();
    assert!(
        files.len() >= at_least,
        "only {} fixtures in {folder}",
        files.len()
    );
    let bless = std::env::var_os("PLACEWORDS_BLESS").is_some();
    let mut failures = Vec::new();
    for f in files {
        let expected_path = f.with_extension("expected");
        let expected_path = PathBuf::from(
            expected_path
                .to_string_lossy()
                .replace(".world.expected", ".expected")
                .replace(".recognizer.expected", ".expected"),
        );
        let Some(got) = problems(&f) else {
            failures.push(format!(
                "{}: accepted, but it is an invalid fixture",
                f.display()
            ));
            continue;
        };
        if bless {
            std::fs::write(&expected_path, format!("{got}\n")).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&expected_path).unwrap_or_default();
        if expected.trim_end() != got.trim_end() {
            failures.push(format!(
                "{}:\n  expected: {}\n  got:      {got}",
                f.display(),
                expected.trim_end()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-mint with PLACEWORDS_BLESS=1 if intended)",
        failures.join("\n")
    );
}

#[test]
fn invalid_scenarios_give_their_messages() {
    check_folder("tests/fixtures/invalid-scenarios", 15);
}

#[test]
fn fuzz_finds_give_located_messages() {
    check_folder("tests/fixtures/fuzz", 10);
}

/// The 2026-12-02 fuzz finds (`../shared/fuzz-finds/2026-12-02/`): numbers that passed the
/// checks and then panicked, aborted or never ended in the simulator or the recognizer.
#[test]
fn fuzz_finds_of_december_give_located_messages() {
    check_folder("tests/fixtures/fuzz-finds", 15);
}

/// The December `.map` finds through the binary: a map with a segment drawn twice or a home
/// heading of 1000 degrees imports (exit 0, the repair said at its line) to a world `world
/// check` accepts; the map with a line stretched 350 m out (a minute before) is refused before
/// any route planning, at that line's column, exit 2, and nothing is written.
#[test]
fn december_maps_import_to_worlds_that_check_or_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.toml");
    let out_arg = out.to_str().unwrap();
    for (map, repair) in [
        ("dup-line", "10:1: warning: this segment repeats line 9"),
        ("heading", "7:1: warning: RobotHome heading 1000 degrees"),
    ] {
        let map = format!("tests/fixtures/fuzz-finds/INCONSISTENT-import-ok-check-fails-{map}.map");
        let o = super::common::placewords(&["world", "import", &map, "-o", out_arg]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{map}: {err}");
        assert!(err.contains(&format!("{map}:{repair}")), "{map}: {err}");
        let o = super::common::placewords(&["world", "check", out_arg]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{map}: the import fails its check: {err}"
        );
        std::fs::remove_file(&out).unwrap();
    }
    let map = "tests/fixtures/fuzz-finds/SLOW-map-import-60s-far-line.map";
    let o = super::common::placewords(&["world", "import", map, "-o", out_arg]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    // Refused before any route planning, at the far line's far coordinate, with an end that
    // would fit (it took 4.6 s of CPU to plan over 350 × 350 m and then fail `world check`).
    assert!(
        err.contains(&format!("{map}:24:13: this line stretches the map"))
            && err.contains("e.g. `40000 20000`, would fit"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written");
}

/// The December CSV find and its kin: invalid UTF-8 in a matches file, and a row naming a scan
/// the logs do not hold, are refused at the file's line and column with exit 2.
#[test]
fn matches_files_are_refused_at_their_lines() {
    let dir = tempfile::tempdir().unwrap();
    let logs = dir.path().join("logs");
    let o = super::common::placewords(&[
        "simulate",
        "scenarios/smoke.toml",
        "--laps",
        "1",
        "-q",
        "-o",
        logs.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let far = dir.path().join("far.csv");
    std::fs::write(
        &far,
        "query_run,query_scan,matched_run,matched_scan\n0,1,0,0\n\n0,5,7,3\n",
    )
    .unwrap();
    let far = far.to_str().unwrap().to_string();
    for (csv, at) in [
        (
            "tests/fixtures/fuzz-finds/UNLOCATED-score-invalid-utf8.csv".to_string(),
            ":2:7: the file is not valid UTF-8 (byte 0xff)",
        ),
        (
            far.clone(),
            ":4:1: run 7 scan 3 is not in the logs (runs are 0, 1)",
        ),
    ] {
        let o = super::common::placewords(&["score", logs.to_str().unwrap(), "--matches", &csv]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{csv}: {err}");
        assert!(err.contains(&format!("{csv}{at}")), "{csv}: {err}");
    }
}

/// Fuzz find 8: a world of 99,000 wall segments passed the checks, then a lap never ended.
#[test]
fn a_world_of_99000_segments_is_refused() {
    let base = std::fs::read_to_string(root().join("worlds/loop-small.toml")).unwrap();
    let mut src = base + "\n[[walls]]\nid = \"zigzag\"\npoints_m = [";
    for i in 0..99_001 {
        src.push_str(&format!(
            "[{}, {}],",
            1.0 + (i % 2) as f64 * 0.01,
            1.0 + i as f64 * 1e-4
        ));
    }
    src.push_str("]\n");
    let err = placewords::world::parse_world(&src, "big.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("wall segments") && err.contains("(limit 10000)"),
        "{err}"
    );
}

/// Fuzz find 15: a 10 MB key was echoed back whole.
#[test]
fn a_huge_key_is_cut_in_the_message() {
    let key = "k".repeat(10_000_000);
    let src = format!("format_version = 1\n{key} = 1\n");
    let err = placewords::world::parse_world(&src, "huge.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("huge.toml:2:1: unknown key `kkk"),
        "{}",
        &err[..200.min(err.len())]
    );
    assert!(err.len() < 2_000, "message is {} bytes", err.len());
}

/// Fuzz find 1 (flag form): `--laps` goes through the same limit as `laps` in a file.
#[test]
fn the_laps_flag_has_the_files_limit() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args([
            "run",
            "scenarios/smoke.toml",
            "--laps",
            "18446744073709551615",
        ])
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("more than 1000"), "{err}");
}

/// `world check` given a scenario says so in one line; `scenario check` reports every problem
/// of every file, located, and exits 2.
#[test]
fn scenario_check_reports_every_file() {
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
            .args(args)
            .current_dir(root())
            .output()
            .unwrap()
    };
    let o = run(&["world", "check", "scenarios/smoke.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
    let o = run(&[
        "scenario",
        "check",
        "scenarios/smoke.toml",
        "tests/fixtures/invalid-scenarios/many-problems.toml",
        "tests/fixtures/invalid-scenarios/unknown-route.toml",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.lines().count() >= 5, "{err}");
    assert!(err.lines().all(|l| l.contains(": error: ")), "{err}");
    let o = run(&[
        "scenario",
        "check",
        "--message-format",
        "json",
        "tests/fixtures/invalid-scenarios/many-problems.toml",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    for line in out.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert!(
            v["line"].as_u64().unwrap() >= 1 && v["severity"] == "error",
            "{line}"
        );
    }
    assert!(out.lines().count() >= 4, "{out}");
}

/// Every key the readers accept is in the format reference (as `` `key` ``): the key tables
/// the readers check unknown keys against are the list.
#[test]
fn the_format_reference_names_every_key() {
    use placewords::spec::{evaluation as ev, scenario as sc, world as wo};
    let recognizer =
        toml::Table::try_from(placewords::recognizer::RecognizerConfig::default()).unwrap();
    // The keys of every subtable (`[recognizer.grid] grid_cell_m`) and of `[recognizer]` itself.
    let recognizer_keys: Vec<&str> = recognizer
        .iter()
        .flat_map(|(k, v)| match v.as_table() {
            Some(t) => t.keys().map(String::as_str).collect(),
            None => vec![k.as_str()],
        })
        .collect();
    let docs: [(&str, Vec<&[&str]>); 2] = [
        (
            "docs/world-format.md",
            vec![
                wo::TOP_KEYS,
                wo::HOME_KEYS,
                wo::WALL_KEYS,
                wo::DOOR_KEYS,
                wo::ROUTE_KEYS,
                wo::AREA_KEYS,
            ],
        ),
        (
            "docs/scenario-format.md",
            vec![
                sc::TOP_KEYS,
                sc::RUN_KEYS,
                sc::DOORS_RANDOM_KEYS,
                sc::PEDESTRIAN_KEYS,
                sc::LASER_KEYS,
                sc::ODOMETRY_KEYS,
                sc::ROBOT_KEYS,
                sc::SCAN_CONTEXT_KEYS,
                ev::EVALUATION_KEYS,
                ev::EXPECT_KEYS,
                ev::EXPECT_SUBJECT_KEYS,
                &recognizer_keys,
            ],
        ),
    ];
    let mut missing = Vec::new();
    for (doc, tables) in docs {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        for key in tables.into_iter().flatten() {
            if !text.contains(&format!("`{key}`")) {
                missing.push(format!("{doc}: `{key}`"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "keys the parser accepts but the reference lacks:\n{}",
        missing.join("\n")
    );
}

/// Runs `args` with stdout and stderr pipes whose reading ends are closed at once: every
/// command that prints must end with its own exit code, never a panic (101).
fn exit_into_closed_pipes(args: &[&str]) -> Option<i32> {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(args)
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    drop(child.stderr.take());
    child.wait().unwrap().code()
}

/// Fuzz find `MIN-pipe-world-check-json`: `world check --message-format json` (and `scenario
/// check`) into a closed pipe panicked with "failed printing to stdout". 500 problems are more
/// than a pipe holds, so the write meets the closed end every time.
#[test]
fn checks_into_a_closed_pipe_exit_2_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut src = String::from("format_version = 2\n");
    for i in 0..600 {
        src.push_str(&format!("unknown_key_number_{i} = 1\n"));
    }
    let file = dir.path().join("many-problems.toml");
    std::fs::write(&file, &src).unwrap();
    let file = file.to_str().unwrap();
    for format in ["json", "human"] {
        for command in ["world", "scenario"] {
            let code =
                exit_into_closed_pipes(&[command, "check", "--message-format", format, file]);
            assert_eq!(code, Some(2), "{command} check --message-format {format}");
        }
    }
}

/// Every size limit of a model number is in the reference, in its key's row of its table's
/// section: the limits column shows the largest (and smallest non-zero) value accepted.
#[test]
fn the_format_reference_shows_every_number_limit() {
    use placewords::spec::diag::fmt_number;
    let text = std::fs::read_to_string(root().join("docs/scenario-format.md")).unwrap();
    let mut wrong = Vec::new();
    for l in placewords::spec::scenario::NUMBER_LIMITS {
        let heading = format!("## `[{}]`", l.table);
        let section = text.split(&heading).nth(1).unwrap_or("");
        let section = section.split("\n## ").next().unwrap_or("");
        let row = section
            .lines()
            .find(|r| r.starts_with(&format!("| `{}` |", l.key)));
        let limits = row.and_then(|r| r.split('|').nth(4)).unwrap_or("").trim();
        let shown = |x: f64| {
            limits
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e'))
                .any(|n| n == fmt_number(x))
        };
        if !shown(l.max) || (l.min_nonzero > 0.0 && !shown(l.min_nonzero)) {
            wrong.push(format!("[{}] {}: limits column `{limits}`", l.table, l.key));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
