//! The lap cache (issue 25 point 3, `--cache DIR`): results with and without it are the same
//! apart from timings and the cache's own counts; corrupt entries are simulated again and
//! reported; a recognizer change reuses the laps and a world or robot change does not.

use crate::common::{placewords, root, smoke_variant};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The gate every variant carries: one bound that always holds.
const GATE: &str = "[expect]\nsubjects = [{ subject = \"words-3\", min_recall = 0.0 }]\n";

fn ok(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{err}{}",
        String::from_utf8_lossy(&o.stdout)
    );
    err
}

/// `value` without what legitimately differs between a cached and an uncached run: timings
/// (`*seconds*`), the cache's counts (`lap_cache`) and the provenance (command line).
fn figures(path: &Path) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| !k.contains("second") && k != "lap_cache" && k != "provenance");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    strip(&mut v);
    v
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Each seed's `lap_cache` of a check report.
fn sources(report: &serde_json::Value) -> Vec<String> {
    report["scenarios"][0]["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["lap_cache"].as_str().unwrap_or("absent").to_string())
        .collect()
}

/// `check SCENARIO --seeds 1..2 --report OUT` with `--cache DIR` when given.
fn check(scenario: &Path, out: &Path, cache: Option<&Path>) -> Output {
    let mut args = vec![
        "check",
        "-q",
        scenario.to_str().unwrap(),
        "--seeds",
        "1..2",
        "--report",
        out.to_str().unwrap(),
    ];
    if let Some(c) = cache {
        args.extend(["--cache", c.to_str().unwrap()]);
    }
    placewords(&args)
}

fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "laps"))
        .collect();
    v.sort();
    v
}

/// `check` over 2 seeds gives the same report uncached, with a cold cache (2 misses, entries
/// stored) and with a warm one (2 hits), timings and the cache's counts apart; so do `run`
/// (laps streamed from the entry) and `simulate` (the same log files, byte for byte).
#[test]
fn cached_laps_give_the_uncached_results() {
    let dir = tempfile::tempdir().unwrap();
    let scn = smoke_variant(dir.path(), "smoke", GATE);
    let cache = dir.path().join("cache");
    let (plain, cold, warm) = (
        dir.path().join("plain.json"),
        dir.path().join("cold.json"),
        dir.path().join("warm.json"),
    );
    ok(&check(&scn, &plain, None));
    let err = ok(&check(&scn, &cold, Some(&cache)));
    assert!(err.contains(": 0 hits, 2 misses"), "{err}");
    assert_eq!(entries(&cache).len(), 2, "one entry per seed");
    let err = ok(&check(&scn, &warm, Some(&cache)));
    assert!(err.contains(": 2 hits, 0 misses"), "{err}");
    assert_eq!(figures(&plain), figures(&cold));
    assert_eq!(figures(&plain), figures(&warm));
    assert_eq!(sources(&json(&plain)), ["absent", "absent"]);
    assert_eq!(sources(&json(&cold)), ["miss", "miss"]);
    assert_eq!(sources(&json(&warm)), ["hit", "hit"]);
    let used = &json(&warm)["provenance"]["lap_cache"];
    assert_eq!(
        (used["hits"].as_u64(), used["misses"].as_u64()),
        (Some(2), Some(0))
    );
    assert!(json(&plain)["provenance"].get("lap_cache").is_none());

    // `run` (one seed, laps streamed) and `simulate`, the cache given by PLACEWORDS_CACHE.
    let with_env = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_placewords"))
            .args(args)
            .current_dir(root())
            .env("PLACEWORDS_CACHE", &cache)
            .output()
            .unwrap()
    };
    let s = scn.to_str().unwrap();
    let run_out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    ok(&placewords(&[
        "run",
        s,
        "-q",
        "--levels",
        "3",
        "--report",
        &run_out("r0.json"),
    ]));
    for (k, want) in [(1, ": 0 hits, 1 miss"), (2, ": 1 hit, 0 misses")] {
        let r = run_out(&format!("r{k}.json"));
        let err = ok(&with_env(&[
            "run", s, "-q", "--levels", "3", "--report", &r,
        ]));
        assert!(err.contains(want), "run {k}: {err}");
        assert_eq!(
            figures(Path::new(&r)),
            figures(Path::new(&run_out("r0.json")))
        );
    }
    ok(&placewords(&["simulate", s, "-q", "-o", &run_out("logs0")]));
    for k in 1..=2 {
        ok(&with_env(&[
            "simulate",
            s,
            "-q",
            "-o",
            &run_out(&format!("logs{k}")),
        ]));
        for f in ["run-000.log", "run-001.log", "manifest.json"] {
            let read = |d: &str| std::fs::read(Path::new(&run_out(d)).join(f)).unwrap();
            assert!(
                read("logs0") == read(&format!("logs{k}")),
                "{f} differs ({k})"
            );
        }
    }
}

/// A truncated entry and one with a flipped byte are never used: their seeds are simulated
/// again (the report's figures are the uncached ones), reported as corrupt on stderr and in
/// the report, and replaced, so the next run hits both.
#[test]
fn a_corrupt_entry_is_simulated_again_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let scn = smoke_variant(dir.path(), "smoke", GATE);
    let cache = dir.path().join("cache");
    let (plain, out) = (dir.path().join("plain.json"), dir.path().join("out.json"));
    ok(&check(&scn, &plain, Some(&cache)));
    let found = entries(&cache);
    assert_eq!(found.len(), 2);
    let bytes = std::fs::read(&found[0]).unwrap();
    std::fs::write(&found[0], &bytes[..bytes.len() / 2]).unwrap();
    let mut bytes = std::fs::read(&found[1]).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x01;
    std::fs::write(&found[1], &bytes).unwrap();

    let err = ok(&check(&scn, &out, Some(&cache)));
    assert!(err.contains(": 0 hits, 2 misses"), "{err}");
    assert_eq!(
        err.matches("corrupt entry simulated again").count(),
        2,
        "{err}"
    );
    assert!(
        err.contains("truncated") && err.contains("checksum differs"),
        "{err}"
    );
    assert_eq!(figures(&plain), figures(&out));
    let report = json(&out);
    assert_eq!(sources(&report), ["corrupt", "corrupt"]);
    let corrupt = report["provenance"]["lap_cache"]["corrupt"]
        .as_array()
        .unwrap();
    assert_eq!(corrupt.len(), 2);

    let err = ok(&check(&scn, &out, Some(&cache)));
    assert!(err.contains(": 2 hits, 0 misses"), "replaced: {err}");
    assert_eq!(figures(&plain), figures(&out));
}

/// A change to `[recognizer]` only (or to the world's description) finds every seed's laps
/// (hits == seeds); a change to `[robot]` or to the world's walking areas finds none.
#[test]
fn a_recognizer_change_reuses_the_laps_and_a_world_or_robot_change_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let base = smoke_variant(dir.path(), "base", GATE);
    let out = dir.path().join("out.json");
    ok(&check(&base, &out, Some(&cache)));
    let hits_misses = |scn: &Path| {
        ok(&check(scn, &out, Some(&cache)));
        let used = &json(&out)["provenance"]["lap_cache"];
        (
            used["hits"].as_u64().unwrap(),
            used["misses"].as_u64().unwrap(),
        )
    };
    let recognizer = smoke_variant(
        dir.path(),
        "recognizer",
        &format!("[recognizer.verify]\nverify_max_lateral_rms = 0.12\n{GATE}"),
    );
    assert_eq!(hits_misses(&recognizer), (2, 0), "a recognizer change");

    let src = std::fs::read_to_string(&base).unwrap();
    let world_src = std::fs::read_to_string(root().join("worlds/loop-small.toml")).unwrap();
    let world_path = root().join("worlds/loop-small.toml").display().to_string();
    let variant = |name: &str, world_edit: (&str, &str), scenario_edit: (&str, &str)| {
        assert!(world_src.contains(world_edit.0) && src.contains(scenario_edit.0));
        let world = dir.path().join(format!("{name}-world.toml"));
        std::fs::write(&world, world_src.replace(world_edit.0, world_edit.1)).unwrap();
        let scn = dir.path().join(format!("{name}.toml"));
        let text = src.replace(scenario_edit.0, scenario_edit.1).replace(
            &format!("{world_path:?}"),
            &format!("{:?}", world.display().to_string()),
        );
        std::fs::write(&scn, text).unwrap();
        scn
    };
    let none = ("[robot]", "[robot]");
    let described = variant("described", ("for fast tests\"", "for tests\""), none);
    assert_eq!(hits_misses(&described), (2, 0), "the world's description");
    let robot = variant(
        "robot",
        ("", ""),
        ("path_wander_m = 0.2", "path_wander_m = 0.15"),
    );
    assert_eq!(hits_misses(&robot), (0, 2), "a [robot] change");
    let world = variant(
        "world",
        ("max_m = [14.0, 8.6]", "max_m = [14.0, 8.5]"),
        none,
    );
    assert_eq!(hits_misses(&world), (0, 2), "a world change");
}

/// A cache folder that cannot be made is refused before any work: exit 2 naming it.
#[test]
fn an_unusable_cache_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let o = placewords(&[
        "run",
        "scenarios/smoke.toml",
        "-q",
        "--cache",
        file.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--cache") && err.contains("a-file"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
