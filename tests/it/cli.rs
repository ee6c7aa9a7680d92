//! The commands end to end, as CI pipelines and people call them: `run`, `check`, `recognize`.

use super::common::{placewords, root, smoke_variant};
use std::path::Path;
use std::process::Command;

fn report_of(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `run` on the smoke scenario writes the documented report, and its scores stay inside the band
/// pinned in tests/golden/smoke-scores.json.
#[test]
fn smoke_scenario_runs_end_to_end_within_its_golden_band() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let svg = dir.path().join("svg");
    let o = placewords(&[
        "run",
        "scenarios/smoke.toml",
        "-q",
        "--report",
        out.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = report_of(&out);
    for key in [
        "scenario",
        "seed",
        "laps",
        "revisits",
        "subjects",
        "simulate_seconds_per_lap",
    ] {
        assert!(r.get(key).is_some(), "report lacks `{key}`");
    }
    let levels = r["subjects"].as_array().unwrap();
    assert_eq!(levels.len(), 3, "run fills words-1, words-2 and words-3");
    for (i, l) in levels.iter().enumerate() {
        assert_eq!(l["name"], format!("words-{}", i + 1));
        assert_eq!(l["kind"], "words");
        for key in [
            "levels",
            "thresholds",
            "precision",
            "recall",
            "match_precision",
            "pairs",
            "recognize_seconds_per_lap",
        ] {
            assert!(l.get(key).is_some(), "subject entry lacks `{key}`");
        }
    }
    assert!(svg.join("trajectory.svg").exists() && svg.join("matches-levels3.svg").exists());

    let golden = root().join("tests/golden/smoke-scores.json");
    let got: Vec<(u64, f64, f64)> = levels
        .iter()
        .map(|l| {
            (
                l["levels"].as_u64().unwrap(),
                l["precision"].as_f64().unwrap(),
                l["recall"].as_f64().unwrap(),
            )
        })
        .collect();
    if std::env::var_os("PLACEWORDS_REMINT").is_some() {
        std::fs::write(&golden, serde_json::to_string_pretty(&got).unwrap()).unwrap();
    }
    let want: Vec<(u64, f64, f64)> =
        serde_json::from_str(&std::fs::read_to_string(&golden).unwrap()).unwrap();
    const BAND: f64 = 0.03;
    for (w, g) in want.iter().zip(&got) {
        assert!(
            w.0 == g.0 && (w.1 - g.1).abs() <= BAND && (w.2 - g.2).abs() <= BAND,
            "smoke scores moved out of the ±{BAND} band: want (levels, precision, recall) {w:?}, got {g:?}. \
             If the change is intended, re-mint with: PLACEWORDS_REMINT=1 cargo test --release smoke_scenario"
        );
    }
}

/// The gate: exit 0 when every expectation holds, 1 when one is missed, 2 on a broken scenario;
/// the JUnit file has a failure for the missed one.
#[test]
fn check_exits_0_when_met_1_when_missed_and_2_on_a_broken_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let easy = smoke_variant(
        dir.path(),
        "easy",
        "[[expect.subjects]]\nsubject = \"words-1\"\nmin_precision = 0.0\nmin_recall = 0.0\n",
    );
    let o = placewords(&["check", "-q", "--seed", "42", easy.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("PASS"));

    let hard = smoke_variant(
        dir.path(),
        "hard",
        "[[expect.subjects]]\nsubject = \"words-1\"\nmin_recall = 0.999\n",
    );
    let junit = dir.path().join("junit.xml");
    let o = placewords(&[
        "check",
        "-q",
        "--seed",
        "42",
        hard.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("FAIL"));
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(xml.contains("<failure"), "{xml}");

    let broken = smoke_variant(dir.path(), "broken", "[recognizer.words]\nclases = 6\n");
    let o = placewords(&["check", "-q", broken.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("broken.toml:") && err.contains("did you mean `classes`"),
        "{err}"
    );
}

/// Bounds on one direction (`[expect.subjects.same]`, `[expect.subjects.opposite]`): one that holds
/// passes; one that does not exits 1, and the line and the JUnit test case name the direction.
#[test]
fn check_gates_one_direction_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = smoke_variant(
        dir.path(),
        "directions",
        "[[expect.subjects]]\nsubject = \"words-3\"\n\n[expect.subjects.same]\nmin_precision = 0.5\n\n\
         [expect.subjects.opposite]\nmin_recall = 0.999\n",
    );
    let junit = dir.path().join("junit.xml");
    let args = ["check", "-q", "--seed", "42", scenario.to_str().unwrap()];
    let o = placewords(&[&args[..], &["--junit", junit.to_str().unwrap()]].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("PASS smoke words-3 same precision worst"),
        "{out}"
    );
    assert!(
        out.contains("FAIL smoke words-3 opposite recall worst"),
        "{out}"
    );
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains("name=\"smoke/words-3/opposite/recall\""),
        "{xml}"
    );
    assert!(
        xml.contains("<property name=\"direction\" value=\"opposite\"/>"),
        "{xml}"
    );
}

/// `recognize` on a real log writes a report with the same schema as `run`.
#[test]
fn recognize_reads_a_real_log_and_writes_the_run_schema() {
    let log = root().join("../shared/data/carmen/intel-corrected.log.gz");
    if !log.exists() {
        eprintln!("skipped: {} is absent", log.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let o = placewords(&[
        "recognize",
        log.to_str().unwrap(),
        "-q",
        "--report",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = report_of(&out);
    assert_eq!(r["subjects"].as_array().unwrap().len(), 3);
    assert!(r["revisits"].as_u64().unwrap() > 0);
}

/// A missing file is an error naming it, with exit 2 and no panic.
#[test]
fn a_missing_scenario_is_a_located_error_with_exit_2() {
    let o = placewords(&["run", "scenarios/does-not-exist.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("does-not-exist.toml") && !err.contains("panicked"),
        "{err}"
    );
}

/// `sweep` runs the whole Fig. 8 grid (τ from 0) and writes the curves as JSON and SVG.
#[test]
fn sweep_writes_the_fig8_curves() {
    let dir = tempfile::tempdir().unwrap();
    let o = placewords(&[
        "sweep",
        "scenarios/smoke.toml",
        "-q",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = report_of(&dir.path().join("sweep.json"));
    assert_eq!(r["results"].as_array().unwrap().len(), 10 + 7 * 19);
    assert_eq!(r["curves"].as_array().unwrap().len(), 1 + 7);
    let svg = std::fs::read_to_string(dir.path().join("pr-curves.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"));
}

/// `value` with every number under a key naming seconds set to 0 (timings differ run to run).
fn without_timings(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            for (k, x) in map.iter_mut() {
                // `seconds` and the query rate (`queries_per_cpu_second`).
                if k.contains("second") {
                    *x = serde_json::Value::Null;
                } else {
                    without_timings(x);
                }
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(without_timings),
        _ => {}
    }
}

/// (suite, testcase, class, properties, failure text) of one JUnit test case.
type Case = (
    String,
    String,
    String,
    Vec<(String, String)>,
    Option<String>,
);

/// Every JUnit test case of the file at `path`, without times.
fn junit_cases(path: &Path) -> Vec<Case> {
    let xml = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("valid JUnit XML");
    let attr = |n: roxmltree::Node, a: &str| n.attribute(a).unwrap_or("").to_string();
    doc.descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .map(|c| {
            let suite = attr(c.parent().unwrap(), "name");
            let props = c
                .descendants()
                .filter(|p| p.has_tag_name("property"))
                .map(|p| (attr(p, "name"), attr(p, "value")))
                .collect();
            let failure = c
                .children()
                .find(|f| f.has_tag_name("failure") || f.has_tag_name("error"))
                .map(|f| f.text().unwrap_or("").to_string());
            (suite, attr(c, "name"), attr(c, "classname"), props, failure)
        })
        .collect()
}

/// `check --shard K/4` for every K, then `merge`, gives the report, table and JUnit test cases of
/// the unsharded run (timings apart), and the same exit code; two scenarios of one name are
/// told apart by their file everywhere.
#[test]
fn sharded_check_then_merge_equals_the_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    // the same name twice; one bound that always holds, one that no seed meets
    let gate = "[expect]\nsubjects = [{ subject = \"words-1\", min_recall = 0.0 }, { subject = \"words-3\", min_recall = 1.0 }]\n";
    let s1 = smoke_variant(&a, "smoke", gate);
    let s2 = smoke_variant(&b, "smoke", gate);
    let (s1, s2) = (s1.to_str().unwrap(), s2.to_str().unwrap());
    let whole = dir.path().join("whole");
    let o = placewords(&[
        "check",
        "-q",
        s1,
        s2,
        "--seeds",
        "1..3",
        "-o",
        whole.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert_eq!(
        o.status.code(),
        Some(1),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.trim_end().ends_with("2 passed, 2 failed"),
        "{stdout}"
    );
    assert!(stdout.contains("; reproduce: placewords run "), "{stdout}");

    let mut parts = Vec::new();
    for k in 1..=4 {
        let part = dir.path().join(format!("part{k}.json"));
        let shard = format!("{k}/4");
        let o = placewords(&[
            "check",
            "-q",
            s1,
            s2,
            "--seeds",
            "1..3",
            "--shard",
            &shard,
            "--report",
            part.to_str().unwrap(),
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        parts.push(part.to_str().unwrap().to_string());
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["merge", "-o", merged.to_str().unwrap()];
    args.extend(parts.iter().rev().map(String::as_str));
    let o = placewords(&args);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("2 passed, 2 failed"));

    let cases = junit_cases(&whole.join("junit.xml"));
    assert_eq!(cases, junit_cases(&merged.join("junit.xml")));
    assert_eq!(cases.len(), 4);
    assert_ne!(
        cases[0].0, cases[2].0,
        "twins get their file in the suite name"
    );
    assert!(cases[0].0.contains("a/smoke.toml"), "{:?}", cases[0]);
    assert!(
        cases[1].2.ends_with("a/smoke.toml"),
        "the class is the file: {:?}",
        cases[1]
    );
    assert_eq!(
        cases[1].1,
        format!("{}/words-3/recall", cases[1].0),
        "no bound in a name"
    );
    let props: Vec<&str> = cases[1].3.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(
        props,
        ["value", "statistic", "bound", "seeds", "seed", "reproduce"]
    );
    let failure = cases[1].4.as_deref().expect("the recall bound fails");
    assert!(
        failure.contains("recall worst") && failure.contains("< 1.000"),
        "{failure}"
    );
    assert!(failure.contains("--seed "), "{failure}");

    let mut want = report_of(&whole.join("report.json"));
    let mut got = report_of(&merged.join("report.json"));
    without_timings(&mut want);
    without_timings(&mut got);
    // The provenance differs by the command line and the part files, and only by them.
    let (mut pw, mut pg) = (want["provenance"].take(), got["provenance"].take());
    pw["command_line"].take();
    pg["command_line"].take();
    let other_inputs = |v: &mut serde_json::Value| {
        let inputs = v["inputs"].as_array_mut().unwrap();
        inputs.retain(|i| i["role"] != "part");
        inputs.len()
    };
    assert_eq!(other_inputs(&mut pw), other_inputs(&mut pg));
    assert_eq!(pw, pg, "the merged provenance is the parts'");
    assert_eq!(
        want, got,
        "merged report.json differs from the unsharded one"
    );
    assert_eq!(want["scenarios"][0]["results"].as_array().unwrap().len(), 3);
    let table = |d: &Path| {
        std::fs::read_to_string(d.join("table.md"))
            .unwrap()
            .lines()
            .filter(|l| !l.contains("seconds_per_lap"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(table(&whole), table(&merged));

    let o = placewords(&[
        "merge",
        "-o",
        merged.to_str().unwrap(),
        &parts[0],
        &parts[1],
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("part 3/4 is missing"));
}

/// A scenario without [expect] is an error in `check` unless --allow-no-expect, and `--json`
/// gives a machine-readable verdict.
#[test]
fn check_without_expect_is_an_error_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let bare = smoke_variant(dir.path(), "bare", "");
    let bare = bare.to_str().unwrap();
    let o = placewords(&["check", "-q", bare]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no [expect] block") && err.contains("--allow-no-expect"),
        "{err}"
    );
    let o = placewords(&["check", "-q", "--json", "--allow-no-expect", bare]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    assert_eq!(
        (v["passed"].as_u64(), v["failed"].as_u64()),
        (Some(0), Some(0))
    );

    // --shard auto: the part from a Kubernetes Indexed Job's JOB_COMPLETION_INDEX (0-based)
    let part = dir.path().join("part.json");
    let o = Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(["check", "-q", "--allow-no-expect", "--shard", "auto", bare])
        .args(["--report", part.to_str().unwrap()])
        .env("JOB_COMPLETION_INDEX", "2")
        .env("PLACEWORDS_SHARD_COUNT", "4")
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        report_of(&part)["shard"],
        serde_json::json!({"index": 3, "count": 4})
    );
    // An index past the parts (u64::MAX used to wrap to "part 0 of 3") is refused in the
    // variable's own 0-based terms, before any work.
    for index in ["3", "18446744073709551615"] {
        let o = Command::new(env!("CARGO_BIN_EXE_placewords"))
            .args(["check", "-q", "--allow-no-expect", "--shard", "auto", bare])
            .args(["--report", part.to_str().unwrap()])
            .env("JOB_COMPLETION_INDEX", index)
            .env("PLACEWORDS_SHARD_COUNT", "3")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{index}: {stderr}");
        assert!(
            stderr.contains(&format!(
                "JOB_COMPLETION_INDEX = {index} is not a part of 3: it counts from 0 to 2"
            )),
            "{index}: {stderr}"
        );
    }
}

/// `placewords COMMAND | head`: the reader leaves before the output is written. Output stops
/// quietly and the command still exits 0 (it used to panic with exit 101), and it finishes its
/// other outputs (here the JSON report).
#[test]
fn a_closed_stdout_ends_quietly_with_exit_0() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.json");
    let report_arg = report.display().to_string();
    for args in [
        vec!["world", "info", "worlds/loop-small.toml"],
        vec![
            "run",
            "scenarios/smoke.toml",
            "--laps",
            "2",
            "-q",
            "--report",
            &report_arg,
        ],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_placewords"))
            .args(&args)
            .current_dir(root())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader leaves at once
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    assert!(report_of(&report)["subjects"].is_array());
}

/// Help that matches behaviour: every subcommand's help shows an example; `-o/--out` is one
/// spelling (`--output` still read); `--size-m` takes the form its default shows; an output's
/// extension must name the format written; an output file's missing folder is an error, not
/// created; a missing input is reported once; `world info` rounds to the millimetre.
#[test]
fn help_and_small_behaviours_match() {
    let commands: &[&[&str]] = &[
        &["world", "check"],
        &["world", "render"],
        &["world", "info"],
        &["world", "import"],
        &["world", "density"],
        &["world", "ambiguity"],
        &["world", "generate"],
        &["scenario", "check"],
        &["simulate"],
        &["run"],
        &["check"],
        &["merge"],
        &["table"],
        &["sweep"],
        &["recognize"],
        &["score"],
    ];
    for c in commands {
        let mut args = c.to_vec();
        args.push("--help");
        let o = placewords(&args);
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(help.contains("Example:\n  placewords "), "{c:?}: {help}");
        assert!(
            !help.contains("--output"),
            "{c:?} spells -o as --out: {help}"
        );
        assert!(!help.contains("from 1"), "{c:?} counts from 0: {help}");
    }
    let world = placewords(&["world", "--help"]);
    let help = String::from_utf8_lossy(&world.stdout);
    for sub in ["density", "ambiguity", "generate"] {
        assert!(help.contains(sub), "{help}");
    }

    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).display().to_string();
    let floor = "worlds/institute-floor.toml";
    let o = placewords(&["world", "render", floor, "-o", &at("floor.png")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(".svg"));
    assert!(!dir.path().join("floor.png").exists());
    let o = placewords(&["world", "render", floor, "--output", &at("floor.svg")]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for size in ["50 40", "50,40"] {
        let o = placewords(&[
            "world",
            "generate",
            "--seed",
            "1",
            "--size-m",
            size,
            "-o",
            &at("g.toml"),
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{size}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = placewords(&[
        "world",
        "generate",
        "--seed",
        "1",
        "--size-m",
        "50",
        "-o",
        &at("g.toml"),
    ]);
    assert_eq!(o.status.code(), Some(2));

    let missing = dir.path().join("no/such/dir/r.json");
    let o = placewords(&[
        "run",
        "scenarios/smoke.toml",
        "--laps",
        "1",
        "--report",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not exist"));
    assert!(!dir.path().join("no").exists(), "no folder is created");

    let o = placewords(&["run", "scenarios/no-such.toml"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.matches("No such file").count(), 1, "{err}");

    let o = placewords(&["world", "info", floor, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let len = v["wall_length_m"].as_f64().unwrap();
    assert_eq!(len, (len * 1000.0).round() / 1000.0, "{len}");
}

/// `motion` measures a real log's corrected path and a scenario's simulated laps side by side:
/// a row each, the smooth simulated laps with less heading deviation than the real robot, and
/// the KS distance of the second to the first; a missing input is named, exit 2.
#[test]
fn motion_compares_a_real_log_with_simulated_laps() {
    let log = root().join("../shared/data/carmen/intel-corrected.log.gz");
    // csail's stamps are unusable (six significant digits): its speed is not made up.
    let csail = root().join("../shared/data/carmen/csail-corrected.log.gz");
    let o = placewords(&[
        "motion",
        log.to_str().unwrap(),
        csail.to_str().unwrap(),
        "scenarios/smoke.toml",
        "--laps",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let row = |name: &str| {
        out.lines()
            .find(|l| l.contains(name) && l.contains(" | "))
            .unwrap_or_else(|| panic!("no row for {name} in\n{out}"))
            .to_string()
    };
    // The median |heading − corridor| is the middle figure of the third column.
    let median_deviation = |line: &str| -> f64 {
        let cols: Vec<&str> = line.split(" | ").collect();
        cols[2].split(" / ").nth(1).unwrap().parse().unwrap()
    };
    let (real, sim) = (row("intel-corrected"), row("smoke.toml"));
    assert!(
        median_deviation(&real) > median_deviation(&sim),
        "the real robot weaves more than the smooth laps:\n{out}"
    );
    assert!(out.contains("Kolmogorov–Smirnov distance to"), "{out}");
    assert!(
        row("csail-corrected").contains("– (stamps unusable)"),
        "{out}"
    );
    assert!(!row("intel-corrected").contains("stamps unusable"), "{out}");
    assert!(out.contains("smoke.toml: speed "), "{out}");
    let o = placewords(&["motion", "no-such.log"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no-such.log"));
}
