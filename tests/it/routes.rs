//! Routes that can be driven: the robot turns on the spot where a route reverses or turns
//! sharply in a narrow space, `world check` / `scenario check` test-drive each route and refuse
//! one the robot cannot drive at its waypoint, and a blocked run's error is printed once.

use super::common::{placewords, root};
use placewords::experiment::load_scenario;
use placewords::sim::simulate;
use placewords::sim::test_drive::check_world_text;
use std::path::{Path, PathBuf};

const UNDRIVABLE: &str = "tests/fixtures/undrivable";

fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml") && !is_scenario(p))
        .collect();
    files.sort();
    files
}

fn is_scenario(p: &Path) -> bool {
    p.to_string_lossy().ends_with(".scenario.toml")
}

/// The route into the 2 m dead-end spur and back out is driven, both ways round, on every seed
/// of the scenario's range: every lap ends, and each lap reaches the turning point 0.5 m short
/// of the end wall and turns there (the robot faces back out of the spur).
#[test]
fn a_route_that_reverses_in_a_2_m_dead_end_is_driven_on_every_seed() {
    let path = root().join("tests/fixtures/drivable/dead-end-spur.scenario.toml");
    let scn = load_scenario(&path).unwrap();
    for seed in 1..=4u64 {
        let mut plan = scn.sim.clone();
        plan.seed = seed;
        let runs = simulate(&plan, None, &|| {}).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        for (run, log) in runs.iter().enumerate() {
            assert_eq!(log.laps.len(), plan.runs[run].laps, "seed {seed} run {run}");
            for lap in &log.laps {
                let deep = lap
                    .frames
                    .iter()
                    .map(|f| f.truth.0)
                    .filter(|p| p.y > 10.3)
                    .collect::<Vec<_>>();
                assert!(
                    !deep.is_empty(),
                    "seed {seed} run {run} lap {}: never reached the end of the spur",
                    lap.lap
                );
                let out = lap.frames.iter().any(|f| {
                    let p = f.truth.0;
                    p.y > 7.0 && (p.theta + std::f64::consts::FRAC_PI_2).abs() < 0.2
                });
                assert!(
                    out,
                    "seed {seed} run {run} lap {}: never faced back out",
                    lap.lap
                );
            }
        }
    }
}

/// A loop of corridors too narrow for a smooth 90° corner (the wall ahead stops the robot
/// before it has turned) is driven by turning on the spot at each corner: `world check`
/// accepts it.
#[test]
fn corners_in_narrow_corridors_are_turned_on_the_spot() {
    let shown = "tests/fixtures/drivable/narrow-corners.toml";
    let src = std::fs::read_to_string(root().join(shown)).unwrap();
    check_world_text(&src, shown).unwrap_or_else(|e| panic!("{e}"));
}

/// Every shipped world's routes pass the test drive.
#[test]
fn every_shipped_world_route_is_driven_by_the_test_drive() {
    for f in std::fs::read_dir(root().join("worlds")).unwrap() {
        let f = f.unwrap().path();
        let src = std::fs::read_to_string(&f).unwrap();
        check_world_text(&src, &f.display().to_string()).unwrap_or_else(|e| panic!("{e}"));
    }
}

/// Each `NAME.toml` in the undrivable fixtures passes every check of the file itself but is
/// refused by the test drive with exactly the lines of `NAME.expected` (the waypoint's
/// `file:line:col`, the place and the cause). Re-mint with `PLACEWORDS_BLESS=1`.
#[test]
fn undrivable_fixtures_give_their_messages() {
    let files = toml_files(&root().join(UNDRIVABLE));
    assert!(!files.is_empty());
    let bless = std::env::var_os("PLACEWORDS_BLESS").is_some();
    let mut failures = Vec::new();
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let shown = format!("{UNDRIVABLE}/{name}");
        let src = std::fs::read_to_string(&f).unwrap();
        placewords::world::parse_world(&src, &shown)
            .unwrap_or_else(|e| panic!("{shown} must pass the file checks: {e}"));
        let got = match check_world_text(&src, &shown) {
            Ok(_) => {
                failures.push(format!("{shown}: driven, but it is an undrivable fixture"));
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
                "{shown}:\n  expected: {expected}\n  got:      {got}"
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-mint with PLACEWORDS_BLESS=1 if intended)",
        failures.join("\n")
    );
}

/// `world check` and `scenario check` refuse the narrow gap (exit 2) at the waypoint, with the
/// place; the scenario's message points into the world file.
#[test]
fn world_check_and_scenario_check_refuse_an_undrivable_route() {
    let world = format!("{UNDRIVABLE}/narrow-gap.toml");
    let out = placewords(&["world", "check", &world]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("{world}:"))
            && err.contains("cannot be driven")
            && err.contains("at (5.")
            && err.contains("wall 'gap-"),
        "{err}"
    );
    let scenario = format!("{UNDRIVABLE}/narrow-gap.scenario.toml");
    let out = placewords(&["scenario", "check", &scenario]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("narrow-gap.toml:") && err.contains("cannot be driven"),
        "{err}"
    );
}

/// A blocked run's error is printed once by `check` (the bound that could not be tested cites
/// it, but each seed's error appears once, not on stderr and again in the summary).
#[test]
fn a_blocked_runs_error_is_printed_once() {
    let scenario = format!("{UNDRIVABLE}/narrow-gap.scenario.toml");
    let out = placewords(&["check", "-q", &scenario, "--seeds", "1..2"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    for seed in [1, 2] {
        let line = format!("seed {seed}: simulation failed");
        assert_eq!(all.matches(&line).count(), 1, "{line}:\n{all}");
    }
    assert!(all.contains("was blocked"), "{all}");
}
