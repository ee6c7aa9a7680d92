//! Recognizers in any language (`--recognizer NAME=exec:COMMAND`, docs/plugin.md): the Python
//! example is scored and gated beside the paper's recognizer, and every way a program can go
//! wrong ends in a message naming it and what it printed, exit 2, and no output file.

use super::common::{placewords, root, smoke_variant};

/// The example recognizer's command, with extra flags.
fn example(flags: &str) -> String {
    let script = root().join("examples/plugin_recognizer.py");
    format!("ring=exec:python3 {} {flags}", script.display())
}

/// `check` runs the Python example as subject `ring` beside words-3 and gates both: a bound
/// that holds passes, one it cannot meet fails with exit 1, and the report and the JUnit file
/// name the subject.
#[test]
fn check_gates_an_external_recognizer_beside_the_words() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = smoke_variant(
        dir.path(),
        "plugin",
        "[[expect.subjects]]\nsubject = \"words-3\"\nmin_precision = 0.5\n\n\
         [[expect.subjects]]\nsubject = \"ring\"\nmin_recall = 0.01\n\n\
         [[expect.subjects]]\nsubject = \"ring\"\nmin_precision = 0.999\n",
    );
    let (report, junit) = (dir.path().join("r.json"), dir.path().join("j.xml"));
    let o = placewords(&[
        "check",
        "-q",
        "--seeds",
        "1..2",
        scenario.to_str().unwrap(),
        "--recognizer",
        &example(""),
        "--report",
        report.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains("PASS smoke words-3 precision"), "{out}");
    assert!(out.contains("PASS smoke ring recall"), "{out}");
    assert!(out.contains("FAIL smoke ring precision"), "{out}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(xml.contains("smoke/ring/precision"), "{xml}");
    let text = std::fs::read_to_string(&report).unwrap();
    assert!(
        text.contains("\"kind\": \"external\""),
        "the report names the kind"
    );
    // The failed bound's reproducing command gives the subject again, and it runs.
    let line = reproduce_line(&out, "FAIL smoke ring precision");
    assert!(line.contains("--recognizer 'ring=exec:python3 "), "{line}");
    assert!(
        xml.contains("--recognizer &apos;ring=exec:python3")
            || xml.contains("--recognizer 'ring=exec:python3"),
        "the JUnit reproduce property gives the flag: {xml}"
    );
    let reproduced = run_reproduce_line(&line);
    assert!(reproduced.contains("\"name\": \"ring\""), "{reproduced}");
}

/// The `reproduce: …` command at the end of the output line starting with `start`.
fn reproduce_line(out: &str, start: &str) -> String {
    let line = out
        .lines()
        .find(|l| l.starts_with(start))
        .unwrap_or_else(|| panic!("no line `{start}` in {out}"));
    line.split_once("reproduce: ")
        .unwrap_or_else(|| panic!("no reproduce: in {line}"))
        .1
        .to_string()
}

/// Runs a reproducing command line (`placewords run FILE --seed N …`) as a shell would split
/// it, for one lap, writing a report; returns the report.
fn run_reproduce_line(line: &str) -> String {
    let words = shlex::split(line).expect("the line splits as a shell would");
    assert_eq!(words[0], "placewords", "{line}");
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("again.json");
    let mut args: Vec<&str> = words[1..].iter().map(String::as_str).collect();
    args.extend(["-q", "--laps", "1", "--levels", "1", "--report"]);
    args.push(report.to_str().unwrap());
    let o = placewords(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{line}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::read_to_string(&report).unwrap()
}

/// A scenario can declare its external subject in `[[subjects]]`: `check` runs and gates it
/// without a flag, its relative command resolves against the scenario's folder (the test runs
/// from the project root, the script sits beside the scenario), its arguments reach the
/// program, and a failed bound's reproducing command needs no `--recognizer`.
#[test]
fn a_scenario_declares_its_external_subject() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("my bin");
    std::fs::create_dir(&bin).unwrap();
    std::fs::copy(
        root().join("examples/plugin_recognizer.py"),
        bin.join("ring.py"),
    )
    .unwrap();
    let subjects = "[[subjects]]\nname = \"ring\"\nexec = \"python3\"\n\
                    args = [\"my bin/ring.py\"]\ntimeout_s = 20\n\n";
    let scenario = smoke_variant(
        dir.path(),
        "declared",
        &format!(
            "{subjects}[[expect.subjects]]\nsubject = \"ring\"\nmin_recall = 0.01\n\n\
             [[expect.subjects]]\nsubject = \"ring\"\nmin_precision = 0.999\n"
        ),
    );
    let o = placewords(&["check", "-q", "--seeds", "1..1", scenario.to_str().unwrap()]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains("PASS smoke ring recall"), "{out}");
    let line = reproduce_line(&out, "FAIL smoke ring precision");
    assert!(line.ends_with("--seed 1"), "no flag is needed: {line}");
    let reproduced = run_reproduce_line(&line);
    assert!(reproduced.contains("\"name\": \"ring\""), "{reproduced}");

    // A program that fails is named as with the flag: here, arguments that crash it at once.
    let crashing = smoke_variant(
        dir.path(),
        "crashing",
        "[[subjects]]\nname = \"ring\"\nexec = \"python3 'my bin/ring.py'\"\n\
         args = [\"--crash-at\", \"0\"]\n",
    );
    let o = placewords(&[
        "run",
        "-q",
        "--laps",
        "1",
        "--levels",
        "1",
        crashing.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("external recognizer `ring`") && err.contains("crashing on purpose"),
        "{err}"
    );
}

/// Each mistake in a `[[subjects]]` entry is refused by `scenario check` at its place, with
/// what to write; an `[expect]` subject close to a declared name is taken for a typo of it.
#[test]
fn a_bad_subjects_entry_is_refused_at_its_place() {
    let dir = tempfile::tempdir().unwrap();
    for (name, body, line, want) in [
        (
            "misspelt",
            "[[subjects]]\nname = \"ring\"\nexce = \"true\"\n",
            3,
            "unknown key `exce` in [[subjects]] #0; did you mean `exec`",
        ),
        (
            "builtin",
            "[[subjects]]\nname = \"icp\"\nexec = \"true\"\n",
            2,
            "`icp` in [[subjects]] #0 is the name of a built-in subject",
        ),
        (
            "twice",
            "[[subjects]]\nname = \"ring\"\nexec = \"true\"\n\
             [[subjects]]\nname = \"ring\"\nexec = \"true\"\n",
            5,
            "subject `ring` is declared twice in [[subjects]] (first on line",
        ),
        (
            "timeout",
            "[[subjects]]\nname = \"ring\"\nexec = \"true\"\ntimeout_s = 0\n",
            4,
            "timeout_s = 0 in [[subjects]] #0 is out of range",
        ),
        (
            "noexec",
            "[[subjects]]\nname = \"ring\"\n",
            1,
            "missing key `exec` in [[subjects]] #0",
        ),
        (
            "expecttypo",
            "[[subjects]]\nname = \"ring\"\nexec = \"true\"\n\
             [[expect.subjects]]\nsubject = \"rign\"\nmin_recall = 0.1\n",
            5,
            "unknown subject `rign` in [[expect.subjects]] #0; did you mean `ring`?",
        ),
    ] {
        let path = smoke_variant(dir.path(), name, body);
        let base = std::fs::read_to_string(&path).unwrap().lines().count() - body.lines().count();
        let o = placewords(&["scenario", "check", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        let at = format!("{}:{}:", path.display(), base + line);
        assert!(
            err.contains(&at) && err.contains(want),
            "{name}: want {at} {want}: {err}"
        );
    }
}

/// `table` scores the Python example and Scan Context beside the paper's recognizer, each with
/// its figures and its time per lap, in table.md and table.json.
#[test]
fn table_puts_the_python_example_and_scan_context_beside_the_words() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("table");
    let o = placewords(&[
        "table",
        "scenarios/smoke.toml",
        "-q",
        "--no-icp",
        "--laps",
        "2",
        "--recognizer",
        &example(""),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let md = std::fs::read_to_string(out.join("table.md")).unwrap();
    for row in ["words-3", "scan-context", "ring"] {
        let line = md
            .lines()
            .find(|l| l.starts_with(&format!("| {row} ")))
            .unwrap_or_else(|| panic!("no {row} row in {md}"));
        // precision – recall, then seconds per lap.
        assert!(
            line.contains(" – ") && line.matches('|').count() >= 4,
            "{line}"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report-smoke.json")).unwrap())
            .unwrap();
    let subjects = json["subjects"].as_array().expect("subjects");
    for (name, kind) in [("ring", "external"), ("scan-context", "scan-context")] {
        let s = subjects
            .iter()
            .find(|s| s["name"] == name)
            .unwrap_or_else(|| panic!("no subject {name} in {json}"));
        assert_eq!(s["kind"], kind);
        let t = s["recognize_seconds_per_lap"].as_f64().unwrap();
        assert!(t > 0.0, "{name} is timed: {t}");
    }
}

/// `[expect]` naming an external subject that `check` was not given is an error (exit 2) that
/// says how to give it; a mistyped built-in name is refused by `scenario check` at its line.
#[test]
fn an_external_subject_must_be_given_and_a_typo_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = smoke_variant(
        dir.path(),
        "missing",
        "[[expect.subjects]]\nsubject = \"ring\"\nmin_recall = 0.01\n",
    );
    let o = placewords(&["check", "-q", scenario.to_str().unwrap()]);
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(o.status.code(), Some(2), "{all}");
    assert!(all.contains("--recognizer ring=exec:COMMAND"), "{all}");

    let typo = smoke_variant(
        dir.path(),
        "typo",
        "[[expect.subjects]]\nsubject = \"wrods-3\"\nmin_recall = 0.01\n",
    );
    let o = placewords(&["scenario", "check", typo.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("typo.toml:") && err.contains("did you mean `words-3`"),
        "{err}"
    );
}

/// Runs the smoke scenario for one lap with the example misbehaving as `flags` asks, and
/// returns stderr after checking exit 2 and that no report was written.
fn failing_run(flags: &str, timeout_s: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.json");
    let o = placewords(&[
        "run",
        "scenarios/smoke.toml",
        "-q",
        "--laps",
        "1",
        "--levels",
        "1",
        "--recognizer",
        &example(flags),
        "--recognizer-timeout-s",
        timeout_s,
        "--report",
        report.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{flags}: {err}");
    assert!(!report.exists(), "{flags}: nothing is written");
    assert!(err.contains("external recognizer `ring`"), "{flags}: {err}");
    assert!(!err.contains("panicked"), "{flags}: {err}");
    err
}

#[test]
fn a_crash_is_named_with_its_exit_status_and_last_stderr_lines() {
    let err = failing_run("--crash-at 30", "30");
    assert!(
        err.contains("exited") && err.contains("crashing on purpose"),
        "{err}"
    );
    // Frames 0..=29 were answered (lines 3..=32); the crash is located after the last of them.
    assert!(err.contains("after printing 32 line(s)"), "{err}");
}

/// A program that stops answering is stopped, and so is what the shell started for it: the
/// Python process, not only `sh -c`, is gone once the run has ended (it used to spin on).
#[test]
fn a_hang_is_stopped_after_the_timeout() {
    // A tag only this test's program carries on its command line.
    let tag = format!("--hang-tag-{}", std::process::id());
    let err = failing_run(&format!("--hang-at 30 {tag}"), "1");
    assert!(err.contains("no answer within 1 s"), "{err}");
    let mut left = Vec::new();
    for _ in 0..50 {
        left = processes_with(&tag);
        if left.is_empty() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(left.is_empty(), "still running after the run: {left:?}");
}

/// The command lines of the running processes that contain `tag` (from `/proc`; zombies, which
/// have an empty command line, are not running).
fn processes_with(tag: &str) -> Vec<String> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.filter_map(|e| std::fs::read(e.ok()?.path().join("cmdline")).ok())
        .map(|c| String::from_utf8_lossy(&c).replace('\0', " "))
        .filter(|c| c.contains(tag))
        .collect()
}

#[test]
fn garbage_is_named_with_its_line_number_and_text() {
    let err = failing_run("--garbage-at 30", "30");
    // hello is line 1, start_run line 2, frames 0..=29 lines 3..=32: frame 30's is line 33.
    assert!(err.contains("line 33 is not a reply"), "{err}");
    assert!(err.contains("this is not JSON"), "{err}");
}

#[test]
fn a_match_naming_an_unknown_frame_is_refused() {
    let err = failing_run("--unknown-frame-at 30", "30");
    assert!(
        err.contains("line 35 names frame 1000000000, which it has not observed"),
        "{err}"
    );
}

#[test]
fn another_protocol_version_is_refused_at_hello() {
    let err = failing_run("--protocol 2", "30");
    assert!(
        err.contains("line 1 answers hello")
            && err.contains("protocol 2; this harness speaks protocol 1"),
        "{err}"
    );
}

/// A `--recognizer` value that is not NAME=exec:COMMAND, or takes a built-in name, is refused
/// by the argument parser with what to write.
#[test]
fn a_malformed_recognizer_flag_says_what_to_write() {
    for (flag, want) in [
        ("ring", "write NAME=exec:COMMAND"),
        ("ring=python3 x.py", "only `exec:COMMAND` is supported"),
        ("icp=exec:true", "built-in subject"),
    ] {
        let o = placewords(&["run", "scenarios/smoke.toml", "--recognizer", flag]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains(want), "{flag}: {err}");
    }
}
