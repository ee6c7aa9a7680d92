//! Every report says what made it: version, commit, report version, command line, seeds and
//! the hashes of its inputs (`eval::provenance`), read back here from each kind of report; and
//! the simulation key follows exactly what the laps depend on.

use super::common::{placewords, root};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn ok(args: &[&str]) {
    let o = placewords(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Runs a gated command (`check`, `merge`): whether the smoke scenario's bounds hold on two
/// seeds is not what is tested here, only that it ran and wrote its report (exit 0 or 1, not 2).
fn gated(args: &[&str]) {
    let o = placewords(args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{args:?}: {:?} {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The provenance of the report at `path`, checked for what every report must say; returns it
/// with the roles of its inputs.
fn provenance(path: &Path, command: &str) -> (Value, Vec<String>) {
    let p = json(path)["provenance"].clone();
    let what = path.display();
    assert_eq!(p["tool"], "placewords", "{what}");
    assert_eq!(p["version"], env!("CARGO_PKG_VERSION"), "{what}");
    let commit = p["commit"].as_str().unwrap();
    assert!(
        commit == "unknown"
            || (commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit())),
        "{what}: commit {commit}"
    );
    assert_eq!(
        p["report_version"],
        placewords::eval::provenance::REPORT_VERSION,
        "{what}"
    );
    assert_eq!(p["command_line"][1], command, "{what}");
    let mut roles = Vec::new();
    for i in p["inputs"].as_array().unwrap() {
        let h = i["blake3"].as_str().unwrap();
        assert!(
            h.len() == 64 && h.chars().all(|c| c.is_ascii_hexdigit()),
            "{what}: {i}"
        );
        roles.push(i["role"].as_str().unwrap().to_string());
    }
    (p, roles)
}

fn has(roles: &[String], want: &[&str], what: &str) {
    for w in want {
        assert!(
            roles.iter().any(|r| r == w),
            "{what}: no {w} input in {roles:?}"
        );
    }
}

const SCENARIO: [&str; 5] = [
    "scenario",
    "world",
    "recognizer",
    "evaluation",
    "simulation",
];

#[test]
fn every_report_names_its_version_commit_seeds_and_input_hashes() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let smoke = "scenarios/smoke.toml";

    ok(&[
        "run",
        smoke,
        "--laps",
        "1",
        "--levels",
        "1",
        "-q",
        "--report",
        &d("run.json"),
    ]);
    let (p, roles) = provenance(&dir.path().join("run.json"), "run");
    has(&roles, &SCENARIO, "run");
    assert_eq!(p["seeds"], serde_json::json!([42]));

    gated(&["check", smoke, "--seeds", "1..2", "-q", "-o", &d("check")]);
    let (p, roles) = provenance(&dir.path().join("check/report.json"), "check");
    has(&roles, &SCENARIO[..4], "check");
    assert_eq!(p["seeds"], serde_json::json!([1, 2]));
    let report = json(&dir.path().join("check/report.json"));
    let keys: Vec<&str> = report["scenarios"][0]["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["simulation_key"].as_str().unwrap())
        .collect();
    assert!(
        keys.len() == 2 && keys[0].len() == 64 && keys[0] != keys[1],
        "{keys:?}"
    );
    let xml = std::fs::read_to_string(dir.path().join("check/junit.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let prop = |name: &str| {
        doc.descendants()
            .find(|n| n.attribute("name") == Some(name))
            .and_then(|n| n.attribute("value"))
            .map(str::to_string)
    };
    assert_eq!(
        prop("placewords_version").as_deref(),
        Some(env!("CARGO_PKG_VERSION"))
    );
    assert_eq!(prop("placewords_commit").as_deref(), p["commit"].as_str());

    for k in 1..=2 {
        let shard = format!("{k}/2");
        let part = d(&format!("part{k}.json"));
        gated(&[
            "check", smoke, "--seeds", "1..2", "-q", "--shard", &shard, "--report", &part,
        ]);
        let (p, roles) = provenance(Path::new(&part), "check");
        has(&roles, &SCENARIO[..4], "part");
        assert_eq!(p["seeds"], serde_json::json!([k]));
    }
    gated(&[
        "merge",
        &d("part1.json"),
        &d("part2.json"),
        "-o",
        &d("merged"),
    ]);
    let (p, roles) = provenance(&dir.path().join("merged/report.json"), "merge");
    has(&roles, &["scenario", "world", "part"], "merge");
    assert_eq!(roles.iter().filter(|r| *r == "part").count(), 2);
    assert_eq!(p["seeds"], serde_json::json!([1, 2]));

    ok(&[
        "table",
        smoke,
        "--no-icp",
        "--laps",
        "1",
        "-q",
        "-o",
        &d("table"),
    ]);
    let (_, roles) = provenance(&dir.path().join("table/table.json"), "table");
    has(&roles, &SCENARIO, "table");
    let (_, roles) = provenance(&dir.path().join("table/report-smoke.json"), "table");
    has(&roles, &SCENARIO, "table report");

    ok(&["sweep", smoke, "--laps", "1", "-q", "-o", &d("sweep")]);
    let (_, roles) = provenance(&dir.path().join("sweep/sweep.json"), "sweep");
    has(&roles, &SCENARIO, "sweep");

    ok(&["simulate", smoke, "--laps", "1", "-q", "-o", &d("logs")]);
    let m = d("m.csv");
    ok(&[
        "run",
        smoke,
        "--laps",
        "1",
        "--levels",
        "1",
        "-q",
        "--export-matches",
        &m,
    ]);
    ok(&[
        "score",
        &d("logs"),
        "--matches",
        &m,
        "--report",
        &d("score.json"),
    ]);
    let (_, roles) = provenance(&dir.path().join("score.json"), "score");
    has(&roles, &["logs", "matches", "evaluation"], "score");

    let log = root().join("../shared/data/carmen/intel-corrected.log.gz");
    if log.exists() {
        let log = log.to_str().unwrap();
        ok(&[
            "recognize",
            log,
            "--levels",
            "1",
            "-q",
            "--scan-step",
            "4",
            "--report",
            &d("rec.json"),
        ]);
        let (p, roles) = provenance(&dir.path().join("rec.json"), "recognize");
        has(
            &roles,
            &["real_log", "recognizer", "evaluation"],
            "recognize",
        );
        assert_eq!(p["seeds"], serde_json::json!([1]));
    } else {
        eprintln!("recognize skipped: {} is absent", log.display());
    }
}

/// The smoke scenario and its world copied into `dir` (the world beside it), `edit` applied to
/// the scenario's text.
fn copy_smoke(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    std::fs::create_dir_all(dir.join("worlds")).unwrap();
    std::fs::create_dir_all(dir.join("scenarios")).unwrap();
    std::fs::copy(
        root().join("worlds/loop-small.toml"),
        dir.join("worlds/loop-small.toml"),
    )
    .unwrap();
    let src = std::fs::read_to_string(root().join("scenarios/smoke.toml")).unwrap();
    let path = dir.join("scenarios/smoke.toml");
    std::fs::write(&path, edit(src)).unwrap();
    path
}

/// `(role → blake3)` of a `run` report of `scenario`.
fn hashes(scenario: &Path, out: &Path) -> Vec<(String, String)> {
    let s = scenario.to_str().unwrap();
    ok(&[
        "run",
        s,
        "--laps",
        "1",
        "--levels",
        "1",
        "-q",
        "--report",
        out.to_str().unwrap(),
    ]);
    json(out)["provenance"]["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            (
                i["role"].as_str().unwrap().into(),
                i["blake3"].as_str().unwrap().into(),
            )
        })
        .collect()
}

fn of<'a>(h: &'a [(String, String)], role: &str) -> &'a str {
    &h.iter().find(|(r, _)| r == role).unwrap().1
}

/// A recognizer change leaves the simulation key alone; a world edit or another seed moves it;
/// the same files give the same hashes wherever they lie.
#[test]
fn the_simulation_key_follows_the_laps_not_the_recognizer() {
    let dir = tempfile::tempdir().unwrap();
    let base = copy_smoke(&dir.path().join("base"), |s| s);
    let other_dir = copy_smoke(&dir.path().join("same"), |s| s);
    let recognizer = copy_smoke(&dir.path().join("rec"), |s| {
        format!("{s}\n[recognizer.matcher]\nmax_candidates = 8\n")
    });
    let reseeded = copy_smoke(&dir.path().join("seed"), |s| {
        s.replace("seed = 42", "seed = 43")
    });
    let a = hashes(&base, &dir.path().join("a.json"));
    assert_eq!(
        a,
        hashes(&other_dir, &dir.path().join("b.json")),
        "same files, same hashes"
    );
    let r = hashes(&recognizer, &dir.path().join("r.json"));
    assert_eq!(of(&a, "simulation"), of(&r, "simulation"));
    assert_ne!(of(&a, "recognizer"), of(&r, "recognizer"));
    assert_ne!(of(&a, "scenario"), of(&r, "scenario"));
    let s = hashes(&reseeded, &dir.path().join("s.json"));
    assert_ne!(of(&a, "simulation"), of(&s, "simulation"));
    assert_eq!(of(&a, "recognizer"), of(&s, "recognizer"));

    let world = dir.path().join("base/worlds/loop-small.toml");
    let text = std::fs::read_to_string(&world).unwrap();
    std::fs::write(
        &world,
        format!("{text}\n# an edit that changes nothing but the bytes\n"),
    )
    .unwrap();
    let w = hashes(&base, &dir.path().join("w.json"));
    assert_ne!(of(&a, "world"), of(&w, "world"));
    assert_eq!(
        of(&a, "simulation"),
        of(&w, "simulation"),
        "a comment leaves the world model, so the laps, alone"
    );
    std::fs::write(&world, text.replacen("width_m = 0.9", "width_m = 0.8", 1)).unwrap();
    let w = hashes(&base, &dir.path().join("w2.json"));
    assert_ne!(
        of(&a, "simulation"),
        of(&w, "simulation"),
        "a narrower door"
    );
    assert_eq!(of(&a, "recognizer"), of(&w, "recognizer"));
}
