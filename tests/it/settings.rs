//! Settings are honoured or refused: every documented key of `[recognizer]` changes what the
//! recognizer finds, or is an error that says why; `recognize --config` reads the table as a
//! scenario does (one reader, `experiment::parse_recognizer_config`).

use super::common::{placewords, root};
use placewords::experiment::{
    ExperimentOptions, evaluate_runs, load_scenario, parse_recognizer_config,
};
use placewords::log::RunLog;
use placewords::spec::evaluation::EvaluationSpec;
use std::path::Path;

/// Which simulated input a key is tried on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Input {
    /// The smoke scenario with its second run driven in reverse (same and opposite revisits).
    Dense,
    /// The same with every 25th scan only (steps of about 1 m): observations interpolated along
    /// the steps, kernels reaching back along them.
    Sparse,
}

/// Per documented key: a value other than the default, settings it needs to matter (`context`),
/// and the input it matters on.
const TRIES: &[(&str, &str, &str, Input)] = &[
    ("observation_spacing_m", "0.15", "", Input::Dense),
    ("integrate_every_scan", "true", "", Input::Dense),
    ("grid_cell_m", "0.1", "", Input::Dense),
    ("grid_radius_m", "2.5", "", Input::Dense),
    ("kernel_radius_m", "1.5", "", Input::Dense),
    ("ray_step_deg", "5.0", "", Input::Dense),
    ("classes", "5", "", Input::Dense),
    ("min_word_size", "3", "", Input::Dense),
    ("size_tolerance_ratio", "0.6", "", Input::Dense),
    ("angle_tolerance_deg", "90", "", Input::Dense),
    ("min_ngram", "[2, 3, 4, 5]", "", Input::Dense),
    (
        "max_alignment_offset",
        "2",
        "alignment = \"paper\"",
        Input::Dense,
    ),
    ("candidate_gap_m", "80", "", Input::Dense),
    ("max_candidates", "1", "", Input::Dense),
    ("max_interpolation_m", "0.5", "", Input::Sparse),
    ("grid_memory_m", "3.0", "", Input::Sparse),
    (
        "multi_level",
        "\"paper\"",
        "min_ngram = [2, 3, 4, 5]",
        Input::Dense,
    ),
    ("alignment", "\"paper\"", "", Input::Dense),
    ("chain_alignment_offset", "0", "", Input::Dense),
    ("chain_alignment_tie", "0.05", "", Input::Dense),
    ("reverse", "false", "", Input::Dense),
    ("reverse_extra_ngram", "0", "", Input::Dense),
    ("substitutions", "false", "", Input::Dense),
    ("substitution_size_ratio", "1.0", "", Input::Dense),
    ("ngram_travel_m", "5", "", Input::Dense),
    (
        "ngram_travel_min_words",
        "2",
        "ngram_travel_m = 5",
        Input::Dense,
    ),
    ("reverse_ngram_travel_m", "5", "", Input::Dense),
    ("verify", "false", "", Input::Dense),
    ("verify_travel_ratio", "0.01", "", Input::Dense),
    (
        "verify_travel_slack_m",
        "0.01",
        "verify_travel_ratio = 0.01",
        Input::Dense,
    ),
    ("verify_turn_deg", "2", "", Input::Dense),
    ("verify_max_psi_rms", "0.005", "", Input::Dense),
    ("verify_max_lateral_rms", "0.001", LOOSE, Input::Dense),
    (
        "reverse_verify_max_lateral_rms",
        "0.001",
        LOOSE,
        Input::Dense,
    ),
    ("reverse_min_turn_deg", "0", LOOSE, Input::Dense),
];

/// Short chains, read backwards as readily, with a loose density check: candidates reach the
/// later checks (sides, turn) in numbers.
const LOOSE: &str = "min_ngram = [2, 3, 4, 5]\nreverse_extra_ngram = 0\nverify_max_psi_rms = 1.0";

/// Keys a file may not set, with a word the refusal must contain.
const REFUSED: &[(&str, &str, &str)] = &[("levels", "1", "--levels")];

/// The keys `docs/scenario-format.md` documents in its `[recognizer]` table.
fn documented_keys() -> Vec<String> {
    let doc = std::fs::read_to_string(root().join("docs/scenario-format.md")).unwrap();
    let at = doc
        .find("## `[recognizer]`")
        .expect("the format documents [recognizer]");
    let section = &doc[at..];
    let end = section[3..].find("\n## ").map_or(section.len(), |i| i + 3);
    section[..end]
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split_once('`').map(|(k, _)| k.to_string()))
        .collect()
}

fn reverse_smoke(dir: &Path) -> placewords::experiment::Scenario {
    let src = std::fs::read_to_string(root().join("scenarios/smoke.toml")).unwrap();
    let world = root().join("worlds/loop-small.toml");
    let src = src
        .replace(
            "\"../worlds/loop-small.toml\"",
            &format!("{:?}", world.display().to_string()),
        )
        .replace(
            "start_waypoint = 2\n",
            "start_waypoint = 2\ndirection = \"reverse\"\n",
        );
    assert!(
        src.contains("direction = \"reverse\""),
        "smoke's second run moved"
    );
    let path = dir.join("reverse-smoke.toml");
    std::fs::write(&path, src).unwrap();
    load_scenario(&path).expect("reverse smoke loads")
}

/// Every 25th scan of `runs` (each lap's first kept).
fn sparse(runs: &[RunLog]) -> Vec<RunLog> {
    let mut runs = runs.to_vec();
    for lap in runs.iter_mut().flat_map(|r| r.laps.iter_mut()) {
        let mut k = 0;
        lap.frames.retain(|_| {
            k += 1;
            (k - 1) % 25 == 0
        });
    }
    runs
}

/// What the recognizer found with `settings` (a `[recognizer]` table's body) on `runs`, at 3
/// levels: its observations, matches and what verification turned down.
fn found(settings: &str, runs: &[RunLog], seed: u64) -> String {
    let cfg = parse_recognizer_config(&format!("[recognizer]\n{settings}\n"), Path::new("t.toml"))
        .unwrap_or_else(|e| panic!("{settings}: {e}"));
    let opts = ExperimentOptions {
        levels: vec![3],
        ..ExperimentOptions::default()
    };
    let exp = evaluate_runs(
        "t",
        seed,
        runs.to_vec(),
        &cfg,
        &EvaluationSpec::default(),
        &opts,
    )
    .unwrap_or_else(|e| panic!("{settings}: {e}"));
    let rec = &exp.recognitions[0].1;
    format!(
        "{:?}\n{:?}\n{:?}\n{:?}",
        rec.observations, rec.matches, rec.diagnostics, rec.rejected
    )
}

#[test]
fn every_documented_recognizer_key_changes_the_run_or_is_refused() {
    let documented = documented_keys();
    let mut tried: Vec<&str> = TRIES.iter().map(|t| t.0).collect();
    tried.extend(REFUSED.iter().map(|t| t.0));
    let mut a = documented.clone();
    a.sort();
    tried.sort();
    assert_eq!(
        a, tried,
        "docs/scenario-format.md's [recognizer] keys and the keys tried here"
    );
    let defaults =
        toml::Table::try_from(placewords::recognizer::RecognizerConfig::default()).unwrap();
    let mut fields: Vec<&str> = defaults.keys().map(String::as_str).collect();
    fields.sort();
    assert_eq!(
        tried, fields,
        "every RecognizerConfig field is documented and tried"
    );

    for (key, value, word) in REFUSED {
        let src = format!("[recognizer]\n{key} = {value}\n");
        let e = parse_recognizer_config(&src, Path::new("t.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.toml:2:1: ") && e.contains(word),
            "{key}: {e}"
        );
    }

    let dir = tempfile::tempdir().unwrap();
    let scn = reverse_smoke(dir.path());
    let dense = placewords::sim::simulate(&scn.sim, None, &|| {}).expect("simulates");
    let thin = sparse(&dense);
    let seed = scn.sim.seed;
    let mut base = std::collections::HashMap::new();
    let mut unchanged = Vec::new();
    for &(key, value, context, input) in TRIES {
        let runs = match input {
            Input::Dense => &dense,
            Input::Sparse => &thin,
        };
        let before = base
            .entry((context, input))
            .or_insert_with(|| found(context, runs, seed))
            .clone();
        let after = found(&format!("{context}\n{key} = {value}"), runs, seed);
        if after == before {
            unchanged.push(format!("{key} = {value} ({context})"));
        }
    }
    assert!(
        unchanged.is_empty(),
        "keys that changed nothing: {unchanged:?}"
    );
}

/// A scenario's `[recognizer] levels` is refused at its place, as `--config`'s is, and both
/// entry points print it the same way.
#[test]
fn levels_is_refused_by_scenarios_and_by_config_files_alike() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(root().join("scenarios/smoke.toml")).unwrap();
    let world = root().join("worlds/loop-small.toml");
    let src = src.replace(
        "\"../worlds/loop-small.toml\"",
        &format!("{:?}", world.display().to_string()),
    ) + "\n[recognizer]\nlevels = 1\n";
    let scenario = dir.path().join("s.toml");
    std::fs::write(&scenario, &src).unwrap();
    let line = src.lines().position(|l| l == "levels = 1").unwrap() + 1;
    let config = dir.path().join("c.toml");
    std::fs::write(&config, "[recognizer]\nlevels = 1\n").unwrap();

    let run = placewords(&["run", scenario.to_str().unwrap(), "--laps", "1"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("s.toml:{line}:1: ")) && err.contains("--levels"),
        "{err}"
    );

    let log = root().join("tests/fixtures/carmen/mixed.log");
    let rec = placewords(&[
        "recognize",
        log.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&rec.stderr);
    assert_eq!(rec.status.code(), Some(2), "{err}");
    assert!(
        err.contains("c.toml:2:1: ") && err.contains("--levels"),
        "{err}"
    );
}
/// `recognize --config` reads the `[recognizer]` table of a TOML file as a scenario does, with
/// the scenario checker's messages: each problem at `file:line:col`, "did you mean" for a
/// misspelt key, `levels` refused (the harness runs every level configuration), and a key
/// outside `[recognizer]` refused rather than ignored.
#[test]
fn settings_from_a_toml_file() {
    use placewords::experiment::parse_recognizer_config;
    let path = std::path::Path::new("my.toml");
    let c = parse_recognizer_config(
        "[recognizer]\nalignment = \"paper\"\nverify = false\n",
        path,
    )
    .unwrap();
    assert_eq!(c.alignment, placewords::recognizer::AlignmentMode::Paper);
    assert!(!c.verify);
    let e = parse_recognizer_config("[recognizer]\n\nverfy = false\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("my.toml:3:1: ") && e.contains("did you mean `verify`"),
        "{e}"
    );
    let e = parse_recognizer_config("[recognizer]\nlevels = 1\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("my.toml:2:1: ") && e.contains("--levels"),
        "{e}"
    );
    let e = parse_recognizer_config("x = 1\n[recognizer]\nclasses = 0\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("my.toml:1:1: ") && e.contains("[recognizer] table only"),
        "{e}"
    );
    assert!(e.contains("my.toml:3:1: ") && e.contains("classes"), "{e}");
}
