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

/// Per documented key (`subtable.key`): a value other than the default, settings it needs to
/// matter (`context`, dotted keys of `[recognizer]`), and the input it matters on.
const TRIES: &[(&str, &str, &str, Input)] = &[
    ("front_end.observation_spacing_m", "0.15", "", Input::Dense),
    ("front_end.integrate_every_scan", "true", "", Input::Dense),
    ("grid.grid_cell_m", "0.1", "", Input::Dense),
    ("grid.grid_radius_m", "2.5", "", Input::Dense),
    ("grid.beam_stride", "2", "", Input::Dense),
    ("density.kernel_radius_m", "1.5", "", Input::Dense),
    ("density.ray_step_deg", "5.0", "", Input::Dense),
    ("density.ray_stride", "4", "", Input::Dense),
    ("words.classes", "5", "", Input::Dense),
    // Smoke has no open space: with two classes, its junctions reach the top class, and a
    // 3 m window sees half of it free there.
    (
        "density.wide_radius_m",
        "3",
        "words.classes = 2",
        Input::Dense,
    ),
    (
        "words.wide_classes",
        "0",
        "words.classes = 2\ndensity.wide_radius_m = 3",
        Input::Dense,
    ),
    ("words.min_word_size", "3", "", Input::Dense),
    ("words.psi_window", "5", "", Input::Dense),
    ("words.class_offset", "0.5", "", Input::Dense),
    (
        "words.psi_window_statistic",
        "\"mean\"",
        "words.psi_window = 5",
        Input::Dense,
    ),
    ("matcher.size_tolerance_ratio", "0.6", "", Input::Dense),
    (
        "matcher.reverse_size_tolerance_observations",
        "30",
        "",
        Input::Dense,
    ),
    ("matcher.reverse_sampling_slack", "2", "", Input::Sparse),
    ("matcher.angle_tolerance_deg", "90", "", Input::Dense),
    (
        "matcher.angle_slack",
        "false",
        "matcher.angle_tolerance_deg = 4",
        Input::Sparse,
    ),
    ("matcher.min_ngram", "[2, 3, 4, 5]", "", Input::Dense),
    (
        "alignment.max_alignment_offset",
        "2",
        "alignment.mode = \"paper\"",
        Input::Dense,
    ),
    ("matcher.candidate_gap_m", "80", "", Input::Dense),
    ("matcher.max_candidates", "1", "", Input::Dense),
    ("front_end.max_interpolation_m", "0.5", "", Input::Sparse),
    ("grid.grid_memory_m", "3.0", "", Input::Sparse),
    (
        "words.multi_level",
        "\"paper\"",
        "matcher.min_ngram = [2, 3, 4, 5]",
        Input::Dense,
    ),
    ("alignment.mode", "\"paper\"", "", Input::Dense),
    (
        "alignment.chain_alignment_offset",
        "0",
        "matcher.min_ngram = [2, 3, 4, 5]",
        Input::Dense,
    ),
    ("alignment.chain_alignment_tie", "0.05", "", Input::Dense),
    ("alignment.fill_max_psi_diff", "0", "", Input::Dense),
    ("matcher.reverse", "false", "", Input::Dense),
    ("matcher.reverse_extra_ngram", "0", "", Input::Dense),
    // Smoke's chains of τ words take three classes or more: with n-grams of two words, some
    // take two.
    (
        "matcher.two_class_extra_ngram",
        "0",
        "matcher.min_ngram = [2, 3, 4, 5]",
        Input::Dense,
    ),
    (
        "matcher.substitutions",
        "false",
        "matcher.min_ngram = [4, 6, 8, 10]",
        Input::Dense,
    ),
    ("matcher.substitution_size_ratio", "1.0", "", Input::Dense),
    ("matcher.ngram_travel_m", "5", "", Input::Dense),
    (
        "matcher.ngram_travel_min_words",
        "2",
        "matcher.ngram_travel_m = 5",
        Input::Dense,
    ),
    ("matcher.reverse_ngram_travel_m", "5", "", Input::Dense),
    ("matcher.reverse_short_ngram_words", "2", "", Input::Dense),
    (
        "matcher.reverse_short_ngram_travel_m",
        "5",
        "",
        Input::Dense,
    ),
    ("verify.enabled", "false", "", Input::Dense),
    ("verify.verify_travel_ratio", "0.01", "", Input::Dense),
    (
        "verify.verify_travel_slack_m",
        "0.01",
        "verify.verify_travel_ratio = 0.01",
        Input::Dense,
    ),
    ("verify.verify_turn_deg", "2", "", Input::Dense),
    ("verify.verify_max_psi_rms", "0.005", "", Input::Dense),
    (
        "verify.verify_max_lateral_rms",
        "0.001",
        LOOSE,
        Input::Dense,
    ),
    (
        "verify.reverse_verify_max_lateral_rms",
        "0.001",
        LOOSE,
        Input::Dense,
    ),
    ("verify.reverse_min_turn_deg", "0", LOOSE, Input::Dense),
    (
        "verify.verify_travel_outliers",
        "1",
        "matcher.min_ngram = [2, 3, 4, 5]\nmatcher.reverse_extra_ngram = 0\n\
         verify.verify_max_psi_rms = 1.0\nverify.verify_travel_ratio = 0.01\n\
         verify.verify_travel_slack_m = 0.05",
        Input::Dense,
    ),
    (
        "verify.verify_turn_outliers",
        "0",
        "matcher.min_ngram = [2, 3, 4, 5]\nmatcher.reverse_extra_ngram = 0\n\
         verify.verify_max_psi_rms = 1.0\nverify.verify_turn_deg = 5",
        Input::Dense,
    ),
    (
        "verify.reverse_short_max_lateral_rms",
        "0.001",
        "matcher.reverse_short_ngram_travel_m = 5",
        Input::Dense,
    ),
    (
        "verify.reverse_trim_to_short",
        "false",
        "matcher.min_ngram = [2, 3, 4, 5]\nmatcher.reverse_extra_ngram = 0\n\
         matcher.reverse_short_ngram_words = 2\nmatcher.reverse_short_ngram_travel_m = 1\n\
         verify.verify_max_psi_rms = 1.0\nverify.verify_turn_deg = 5",
        Input::Dense,
    ),
];

/// Short chains, read backwards as readily, with a loose density check: candidates reach the
/// later checks (sides, turn) in numbers.
const LOOSE: &str = "matcher.min_ngram = [2, 3, 4, 5]\nmatcher.reverse_extra_ngram = 0\n\
                     verify.verify_max_psi_rms = 1.0";

/// Keys a file may not set, with a word the refusal must contain.
const REFUSED: &[(&str, &str, &str)] = &[("levels", "1", "--levels")];

/// The keys `docs/scenario-format.md` documents in the tables of its `[recognizer]` section,
/// as `subtable.key` (each table under a heading `` ### `[recognizer.subtable]` ``).
fn documented_keys() -> Vec<String> {
    let doc = std::fs::read_to_string(root().join("docs/scenario-format.md")).unwrap();
    let at = doc
        .find("## `[recognizer]`")
        .expect("the format documents [recognizer]");
    let section = &doc[at..];
    let end = section[3..].find("\n## ").map_or(section.len(), |i| i + 3);
    let mut table = None;
    let mut keys = Vec::new();
    for l in section[..end].lines() {
        if let Some(h) = l.strip_prefix("### `[recognizer.") {
            table = h.split_once(']').map(|(t, _)| t.to_string());
        } else if let Some(row) = l.strip_prefix("| `") {
            let key = row.split_once('`').map(|(k, _)| k).unwrap();
            let table = table
                .as_deref()
                .expect("a key row under a [recognizer.…] heading");
            keys.push(format!("{table}.{key}"));
        }
    }
    keys
}

/// Every key of the settings as `subtable.key` (or `key` at the top).
fn setting_keys() -> Vec<String> {
    let defaults =
        toml::Table::try_from(placewords::recognizer::RecognizerConfig::default()).unwrap();
    let mut out = Vec::new();
    for (k, v) in &defaults {
        match v.as_table() {
            Some(t) => out.extend(t.keys().map(|k2| format!("{k}.{k2}"))),
            None => out.push(k.clone()),
        }
    }
    out
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
    let mut documented = documented_keys();
    let mut tried: Vec<&str> = TRIES.iter().map(|t| t.0).collect();
    documented.sort();
    tried.sort();
    assert_eq!(
        documented, tried,
        "docs/scenario-format.md's [recognizer.…] keys and the keys tried here"
    );
    tried.extend(REFUSED.iter().map(|t| t.0));
    tried.sort();
    let mut fields = setting_keys();
    fields.sort();
    assert_eq!(
        tried, fields,
        "every RecognizerConfig field is documented and tried, or refused"
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
        "[recognizer.alignment]\nmode = \"paper\"\n[recognizer.verify]\nenabled = false\n",
        path,
    )
    .unwrap();
    assert_eq!(
        c.alignment.mode,
        placewords::recognizer::AlignmentMode::Paper
    );
    assert!(!c.verify.enabled);
    let e = parse_recognizer_config("[recognizer.verify]\n\nverfy_turn_deg = 3\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("my.toml:3:1: ") && e.contains("did you mean `verify_turn_deg`"),
        "{e}"
    );
    let e = parse_recognizer_config("[recognizer]\nlevels = 1\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("my.toml:2:1: ") && e.contains("--levels"),
        "{e}"
    );
    let e = parse_recognizer_config("x = 1\n[recognizer.words]\nclasses = 0\n", path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("my.toml:1:1: ") && e.contains("[recognizer] table only"),
        "{e}"
    );
    assert!(
        e.contains("my.toml:3:1: [recognizer.words] classes: must be between 1 and 255"),
        "{e}"
    );
    // A Ψ window as long as a run would make the word builder quadratic: refused, located.
    for window in ["4", "1001"] {
        let text = format!("[recognizer.words]\npsi_window = {window}\n");
        let e = parse_recognizer_config(&text, path)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("my.toml:2:1: [recognizer.words] psi_window: must be an odd count"),
            "{e}"
        );
    }
}

/// A file written before the subtables: each flat key of `[recognizer]` is refused at its
/// place with the subtable it moved to (and its new name, for the two renamed); a key in the
/// wrong subtable names the right one; a misspelt key or subtable gets a "did you mean".
#[test]
fn flat_keys_say_where_they_moved() {
    let path = Path::new("old.toml");
    let err = |src: &str| parse_recognizer_config(src, path).unwrap_err().to_string();
    for key in setting_keys() {
        let Some((table, new)) = key.split_once('.') else {
            continue;
        };
        let renamed = [("mode", "alignment"), ("enabled", "verify")];
        let old = renamed.iter().find(|r| r.0 == new).map_or(new, |r| r.1);
        let defaults =
            toml::Table::try_from(placewords::recognizer::RecognizerConfig::default()).unwrap();
        let value = defaults[table][new].to_string();
        let e = err(&format!("[recognizer]\n# before\n{old} = {value}\n"));
        let want = format!(
            "old.toml:3:1: `{old}` is no longer a key of [recognizer] itself: move {old} into [recognizer.{table}]"
        );
        assert!(e.starts_with(&want), "{key}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        if old != new {
            assert!(e.contains(&format!("as `{new} = {value}`")), "{e}");
        }
    }
    let e = err("[recognizer.grid]\nkernel_radius_m = 2.0\n");
    assert!(
        e.starts_with("old.toml:2:1: ") && e.contains("move it into [recognizer.density]"),
        "{e}"
    );
    let e = err("[recognizer]\nkernal_radius_m = 2.0\n");
    assert!(
        e.starts_with("old.toml:2:1: ")
            && e.contains("did you mean `kernel_radius_m` in [recognizer.density]"),
        "{e}"
    );
    let e = err("[recognizer.grd]\ngrid_cell_m = 0.1\n");
    assert!(e.contains("did you mean `grid`"), "{e}");
}
