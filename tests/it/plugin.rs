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
}

#[test]
fn a_hang_is_stopped_after_the_timeout() {
    let err = failing_run("--hang-at 30", "1");
    assert!(err.contains("no answer within 1 s"), "{err}");
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
        err.contains("names frame 1000000000, which it has not observed"),
        "{err}"
    );
}

#[test]
fn another_protocol_version_is_refused_at_hello() {
    let err = failing_run("--protocol 2", "30");
    assert!(
        err.contains("protocol 2; this harness speaks protocol 1"),
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
