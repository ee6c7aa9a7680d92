//! Baselines (issue 25, point 2): `check --baseline BASE.json` and `compare BASE NEW` on a
//! cut-down smoke scenario: the unchanged recognizer against its own baseline is "no change",
//! a worsened figure is a regression naming metric and seeds, timings under load do not flap,
//! an edited world is compared unpaired and says so, and a bad baseline is an error (exit 2).

use super::common::{placewords, root, smoke_variant};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The gate and tolerance of the cut-down smoke scenario.
const EXPECT: &str = "[expect]\nsubjects = [{ subject = \"words-3\", min_precision = 0.5 }]\n\n\
                      [expect.regression]\nmax_drop = 0.01\nmax_slowdown = 1.5\n";

/// Seeds 1..9: six or more of them match something at 3 levels (enough for the signed-rank
/// test).
const SEEDS: &str = "1..9";

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `check` of `scenario` over [`SEEDS`] with `extra` arguments.
fn check(scenario: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["check", "-q", s(scenario), "--seeds", SEEDS];
    args.extend_from_slice(extra);
    placewords(&args)
}

/// The scenario and its baseline report, made in `dir`.
fn baseline(dir: &Path) -> (PathBuf, PathBuf) {
    let scn = smoke_variant(dir, "smoke", EXPECT);
    let base = dir.join("base.json");
    let o = check(&scn, &["--report", s(&base)]);
    assert_eq!(o.status.code(), Some(0), "{:?}", text(&o));
    (scn, base)
}

/// The seeds of report `path` whose words-3 subject matched something, in order.
fn matched_seeds(path: &Path) -> Vec<u64> {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut seeds = Vec::new();
    for sc in v["scenarios"].as_array().unwrap() {
        for r in sc["results"].as_array().unwrap() {
            let matched = r["report"]["subjects"]
                .as_array()
                .unwrap()
                .iter()
                .any(|sub| sub["name"] == "words-3" && sub["pairs"].as_u64() > Some(0));
            if matched {
                seeds.push(r["seed"].as_u64().unwrap());
            }
        }
    }
    seeds
}

/// A copy of report `from` at `to` with `edit` applied to every words-3 subject of every seed.
fn edited(from: &Path, to: &Path, edit: impl Fn(&mut serde_json::Map<String, Value>)) {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(from).unwrap()).unwrap();
    for sc in v["scenarios"].as_array_mut().unwrap() {
        for r in sc["results"].as_array_mut().unwrap() {
            for sub in r["report"]["subjects"].as_array_mut().unwrap() {
                if sub["name"] == "words-3" {
                    edit(sub.as_object_mut().unwrap());
                }
            }
        }
    }
    std::fs::write(to, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

fn scale(sub: &mut serde_json::Map<String, Value>, key: &str, f: impl Fn(f64) -> f64) {
    let x = sub[key].as_f64().unwrap();
    sub.insert(key.into(), f(x).into());
}

#[test]
fn the_unchanged_recognizer_is_no_change_and_a_worse_one_a_regression() {
    let dir = tempfile::tempdir().unwrap();
    let (scn, base) = baseline(dir.path());

    // Against its own baseline: every figure but time identical, no statistic needed; exit 0.
    let out = dir.path().join("out");
    let o = check(&scn, &["--baseline", s(&base), "-o", s(&out)]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains("smoke: paired by seed: seeds 1..9"),
        "{stdout}"
    );
    assert!(
        stdout.contains("vs baseline: 0 regressions, 0 improvements"),
        "{stdout}"
    );
    assert!(stdout.contains("identical at every seed"), "{stdout}");
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    let doc = roxmltree::Document::parse(&junit).unwrap();
    let cases: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .filter_map(|n| n.attribute("name"))
        .filter(|n| n.ends_with("/vs-baseline"))
        .collect();
    assert!(
        cases.contains(&"smoke/words-3/precision/vs-baseline")
            && cases.contains(&"smoke/words-3/seconds_per_lap/vs-baseline"),
        "{cases:?}"
    );
    assert!(!junit.contains("type=\"regression\""), "{junit}");
    let md = std::fs::read_to_string(out.join("table.md")).unwrap();
    assert!(md.contains("# placewords vs baseline"), "{md}");

    // Two identical files: identical, exit 0.
    let o = placewords(&["compare", s(&base), s(&base)]);
    let (stdout, _) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("5 metrics identical at every seed"),
        "{stdout}"
    );

    // Precision 0.03 lower at every seed that matched: a regression naming metric and seeds,
    // with the commands reproducing the worst seed on both sides, in the text and the JUnit.
    let worse = dir.path().join("worse.json");
    edited(&base, &worse, |sub| scale(sub, "precision", |p| p - 0.03));
    let junit = dir.path().join("cmp.xml");
    let md = dir.path().join("moved.md");
    let o = placewords(&[
        "compare",
        s(&base),
        s(&worse),
        "--junit",
        s(&junit),
        "--markdown",
        s(&md),
    ]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("REGRESSION smoke/words-3/precision/vs-baseline"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let matched = matched_seeds(&base);
    assert!(matched.len() >= 6, "seeds that matched: {matched:?}");
    let n = matched.len();
    assert!(
        line.contains("(-0.030)")
            && line.contains(&format!("worse at {n} of {n} seeds {matched:?}")),
        "{line}"
    );
    assert!(
        stdout.contains("reproduce new seed ") && stdout.contains("# at the baseline's commit"),
        "{stdout}"
    );
    assert!(
        stdout.contains("vs baseline: 1 regression, 0 improvements"),
        "{stdout}"
    );
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let failed: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .filter(|n| n.children().any(|c| c.has_tag_name("failure")))
        .filter_map(|n| n.attribute("name"))
        .collect();
    assert_eq!(failed, ["smoke/words-3/precision/vs-baseline"]);
    let md = std::fs::read_to_string(&md).unwrap();
    assert!(
        md.contains("| `smoke/words-3/precision/vs-baseline` |") && md.contains("**REGRESSION**"),
        "{md}"
    );

    // The other way round it is an improvement, reported, exit 0.
    let o = placewords(&["compare", s(&worse), s(&base)]);
    let (stdout, _) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("improvement smoke/words-3/precision/vs-baseline"),
        "{stdout}"
    );

    // `check --baseline` against a baseline whose recall was 0.05 higher: exit 1, under
    // GitHub Actions an annotation and the table in the step summary.
    let better = dir.path().join("better.json");
    edited(&base, &better, |sub| scale(sub, "recall", |r| r + 0.05));
    let summary = dir.path().join("summary.md");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args([
            "check",
            "-q",
            s(&scn),
            "--seeds",
            SEEDS,
            "--baseline",
            s(&better),
        ])
        .env("GITHUB_ACTIONS", "true")
        .env("GITHUB_STEP_SUMMARY", &summary)
        .current_dir(root())
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stdout.contains("REGRESSION smoke/words-3/recall/vs-baseline")
            && stdout.contains("worse at 9 of 9 seeds 1..9"),
        "{stdout}"
    );
    assert!(
        stdout.contains("::error file=")
            && stdout.contains("title=smoke/words-3/recall/vs-baseline::"),
        "{stdout}"
    );
    let summary = std::fs::read_to_string(&summary).unwrap();
    assert!(
        summary.contains("# placewords stress run") && summary.contains("**REGRESSION**"),
        "{summary}"
    );
}

#[test]
fn timings_from_a_loaded_machine_do_not_flap_but_a_real_slowdown_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let (_, base) = baseline(dir.path());
    let key = "recognize_seconds_per_lap";
    // A baseline made under load (twice the CPU time per lap), and a new run 1.4 times slower
    // (a loaded machine; thread CPU time moves far less, see docs/ci.md): no regression.
    for (name, f) in [("loaded.json", 2.0), ("fast.json", 1.0 / 1.4)] {
        let b = dir.path().join(name);
        edited(&base, &b, |sub| scale(sub, key, |t| t * f));
        let o = placewords(&["compare", s(&b), s(&base)]);
        let (stdout, _) = text(&o);
        assert_eq!(o.status.code(), Some(0), "{name}: {stdout}");
        assert!(!stdout.contains("REGRESSION"), "{name}: {stdout}");
    }
    // Three times slower at every seed is a regression of seconds_per_lap, unless the flag
    // allows it.
    let slow = dir.path().join("slow.json");
    edited(&base, &slow, |sub| scale(sub, key, |t| t * 3.0));
    let o = placewords(&["compare", s(&base), s(&slow)]);
    let (stdout, _) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("REGRESSION smoke/words-3/seconds_per_lap/vs-baseline: mean")
            && stdout.contains("(×3.00)"),
        "{stdout}"
    );
    let o = placewords(&["compare", s(&base), s(&slow), "--max-slowdown", "4"]);
    assert_eq!(o.status.code(), Some(0), "{:?}", text(&o));
}

#[test]
fn an_edited_world_is_compared_unpaired_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let (scn, base) = baseline(dir.path());
    let world = std::fs::read_to_string(root().join("worlds/loop-small.toml")).unwrap();
    let edited_world = dir.path().join("loop-small-edited.toml");
    let changed = world.replacen("min_m = [2.0, 7.4]", "min_m = [2.0, 7.5]", 1);
    assert_ne!(changed, world);
    std::fs::write(&edited_world, changed).unwrap();
    let src = std::fs::read_to_string(&scn).unwrap();
    let old_world = root().join("worlds/loop-small.toml");
    let src = src.replace(
        &format!("{:?}", old_world.display().to_string()),
        &format!("{:?}", edited_world.display().to_string()),
    );
    let scn2 = dir.path().join("smoke-edited.toml");
    std::fs::write(&scn2, src).unwrap();
    let o = check(&scn2, &["--baseline", s(&base)]);
    let (stdout, stderr) = text(&o);
    assert_ne!(o.status.code(), Some(2), "{stdout}{stderr}");
    assert!(
        stdout.contains("smoke: not paired: the simulation keys differ at seeds 1..9")
            && stdout.contains("the world file")
            && stdout.contains("compared as two samples (Mann–Whitney)"),
        "{stdout}"
    );
}

#[test]
fn a_bad_baseline_is_an_error_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let (scn, base) = baseline(dir.path());
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&base).unwrap()).unwrap();
    let write = |name: &str, v: &Value| {
        let p = dir.path().join(name);
        std::fs::write(&p, serde_json::to_string_pretty(v).unwrap()).unwrap();
        p
    };
    let mut other_version = v.clone();
    other_version["provenance"]["report_version"] = 99.into();
    let mut no_scenario = v.clone();
    no_scenario["scenarios"][0]["label"] = "other".into();
    no_scenario["scenarios"][0]["name"] = "other".into();
    let mut few_seeds = v.clone();
    few_seeds["scenarios"][0]["results"]
        .as_array_mut()
        .unwrap()
        .truncate(3);
    let not_json = dir.path().join("notes.txt");
    std::fs::write(&not_json, "baseline from main\n").unwrap();
    let not_a_suite = write(
        "run.json",
        &serde_json::json!({"scenario": "smoke", "seed": 1}),
    );
    let cases = [
        (write("v99.json", &other_version), "report_version 99"),
        (
            write("other.json", &no_scenario),
            "scenario smoke is not in the baseline",
        ),
        (
            write("few.json", &few_seeds),
            "smoke seed 4 is not in the baseline",
        ),
        (
            not_json.clone(),
            "notes.txt:1:1: not a report of `placewords check`",
        ),
        (not_a_suite.clone(), "run.json:4:1: not a report"),
        (dir.path().join("missing.json"), "missing.json: cannot read"),
    ];
    for (file, want) in &cases {
        let o = placewords(&["compare", s(file), s(&base)]);
        let (stdout, stderr) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{file:?}: {stdout}{stderr}");
        assert!(
            stderr.contains(want),
            "{file:?}: wanted {want:?} in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    // `check --baseline` refuses a file that is not a report before running anything.
    let o = check(
        &scn,
        &[
            "--baseline",
            s(&not_json),
            "--report",
            s(&dir.path().join("r.json")),
        ],
    );
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("not a report of `placewords check`"),
        "{stderr}"
    );
    assert!(!dir.path().join("r.json").exists(), "no work, no output");
}

#[test]
fn expect_regression_is_read_with_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bad = smoke_variant(
        dir.path(),
        "bad",
        "[expect]\nsubjects = [{ subject = \"words-3\", min_precision = 0.5 }]\n\n\
         [expect.regression]\nmax_drop = 2\nmax_slowdwn = 1.5\n",
    );
    let o = placewords(&["scenario", "check", s(&bad)]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{stdout}{stderr}");
    let all = format!("{stdout}{stderr}");
    assert!(
        all.contains("max_drop = 2 in [expect.regression] must be in 0..1"),
        "{all}"
    );
    assert!(
        all.contains("max_slowdwn") && all.contains("max_slowdown"),
        "{all}"
    );
    assert!(all.contains("bad.toml:"), "{all}");
    // A flag out of range is refused by name.
    let o = placewords(&["compare", "a.json", "b.json", "--max-slowdown", "0.5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("less than 1"), "{:?}", text(&o));
}
