//! The README's commands, run as written: every `placewords …` line of "A short tour" in one
//! scratch folder, in order (later lines use what earlier ones wrote), with the repository's
//! `worlds/`, `scenarios/` and `docs/` and the shared data beside it as a fresh clone sees them.
//! A line whose comment ends in `[…; short: FLAGS]` runs with FLAGS added, as the README tells
//! a reader in a hurry. A README line that no longer works fails here.

use super::common::root;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One command of the README: its arguments (without `placewords`) and the flags that shorten it.
#[derive(Debug)]
struct TourLine {
    text: String,
    args: Vec<String>,
    short: Vec<String>,
}

/// The lines of the first fenced block after `heading` (up to the closing fence).
fn block_after<'a>(readme: &'a str, heading: &str) -> Vec<&'a str> {
    let at = readme
        .find(heading)
        .unwrap_or_else(|| panic!("README has {heading:?}"));
    let mut lines = readme[at..].lines().skip_while(|l| !l.starts_with("```"));
    lines.next();
    lines.take_while(|l| !l.starts_with("```")).collect()
}

/// A command line of a block, `prefix` (`placewords ` or `cargo run --release -- `) stripped.
fn parse(line: &str, prefix: &str) -> Option<TourLine> {
    let rest = line.trim().strip_prefix(prefix)?;
    let (command, comment) = match rest.find(" #") {
        Some(i) => (&rest[..i], &rest[i + 2..]),
        None => (rest, ""),
    };
    let short = match comment.find("short:") {
        Some(i) => {
            let flags = &comment[i + "short:".len()..];
            let end = flags.find(']').expect("`short:` ends at `]`");
            flags[..end].split_whitespace().map(String::from).collect()
        }
        None => Vec::new(),
    };
    Some(TourLine {
        text: line.trim().to_string(),
        args: command.split_whitespace().map(String::from).collect(),
        short,
    })
}

/// `arg` with a `*` in its file name expanded against `dir` (sorted), as a shell would.
fn expand(arg: &str, dir: &Path) -> Vec<String> {
    let Some((parent, pattern)) = arg.rsplit_once('/').filter(|(_, p)| p.contains('*')) else {
        return vec![arg.to_string()];
    };
    let (head, tail) = pattern.split_once('*').expect("one `*`");
    let mut names: Vec<String> = std::fs::read_dir(dir.join(parent))
        .unwrap_or_else(|e| panic!("{arg}: {e}"))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(head) && n.ends_with(tail) && n.len() >= head.len() + tail.len())
        .map(|n| format!("{parent}/{n}"))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "{arg} matches nothing");
    names
}

/// A scratch copy of what a fresh clone holds: `T/shared` (the data) and `T/clone` with the
/// repository's input folders; commands run in `T/clone`.
fn scratch() -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().expect("temp dir");
    let clone = t.path().join("clone");
    std::fs::create_dir(&clone).unwrap();
    for sub in ["worlds", "scenarios", "docs"] {
        std::os::unix::fs::symlink(root().join(sub), clone.join(sub)).unwrap();
    }
    let shared = root().join("../shared");
    if shared.exists() {
        std::os::unix::fs::symlink(shared, t.path().join("shared")).unwrap();
    }
    (t, clone)
}

/// Runs `line` (shortened) in `dir`; panics naming the line unless it exits with 0 (or 1, an
/// expectation missed, for a shortened `check`: its bounds were set at full length).
fn run_line(line: &TourLine, dir: &Path) {
    let mut args: Vec<String> = line.args.iter().flat_map(|a| expand(a, dir)).collect();
    args.extend(line.short.iter().cloned());
    let out = Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(&args)
        .current_dir(dir)
        .output()
        .expect("the placewords binary runs");
    let code = out.status.code();
    let ok = code == Some(0) || (code == Some(1) && args[0] == "check" && !line.short.is_empty());
    assert!(
        ok,
        "README line `{}` (run as `placewords {}`) exited {code:?}\nstderr:\n{}",
        line.text,
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Whether the line reads shared data absent here (a checkout without `../shared`).
fn needs_absent_data(line: &TourLine, dir: &Path) -> bool {
    line.args
        .iter()
        .any(|a| a.starts_with("../shared/") && !dir.join(a).exists())
}

#[test]
fn every_readme_tour_line_runs_as_written() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = block_after(&readme, "## A short tour");
    let lines: Vec<TourLine> = block
        .iter()
        .filter_map(|l| parse(l, "placewords "))
        .collect();
    assert!(lines.len() >= 15, "the tour has its commands: {lines:?}");
    // Every line in the block is a command or blank: nothing the test would skip.
    for l in &block {
        assert!(
            l.trim().is_empty() || l.trim().starts_with("placewords "),
            "a tour line the test cannot run: {l}"
        );
    }
    let (_t, dir) = scratch();
    for line in &lines {
        if needs_absent_data(line, &dir) {
            eprintln!("skipping (../shared/data is absent): {}", line.text);
            continue;
        }
        run_line(line, &dir);
    }
    // What the tour promises to leave behind.
    for file in [
        "floor.svg",
        "logs/manifest.json",
        "m.csv",
        "s.json",
        "a.json",
        "junit.xml",
    ] {
        assert!(dir.join(file).exists(), "the tour wrote {file}");
    }
}

/// "Two commands": exactly two, the main job runnable as written (shortened as it says).
#[test]
fn the_two_commands_are_two_and_the_main_job_runs() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = block_after(&readme, "## Two commands");
    let commands: Vec<&&str> = block.iter().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(commands.len(), 2, "{commands:?}");
    assert!(commands[1].starts_with("cargo test --release --all-targets"));
    let main_job = parse(commands[0], "cargo run --release -- ").expect("the main job");
    let (_t, dir) = scratch();
    run_line(&main_job, &dir);
}

/// A long line's note gives its time on 2 cores before the flags that shorten it (which the
/// tests above run, so they are real flags).
#[test]
fn long_readme_lines_say_how_long_and_how_to_shorten() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let mut block = block_after(&readme, "## A short tour");
    block.extend(block_after(&readme, "## Two commands"));
    let mut notes = 0;
    for l in block {
        // A note closes the line: `… [TIME; short: FLAGS]`.
        if let Some(i) = l.trim_end().strip_suffix(']').and_then(|l| l.rfind(" [")) {
            let note = &l[i..];
            let time = note.find(" s").or(note.find(" min"));
            let short = note.find("short:");
            assert!(
                matches!((time, short), (Some(t), Some(s)) if t < s),
                "a note on a long line gives its time, then `short:` flags: {l}"
            );
            notes += 1;
        }
    }
    assert!(notes >= 4, "check, table, sweep and long-term are long");
}

/// The README's example report: the first ```json block after "## The report", and where it
/// sits in the README (byte range of its body).
fn readme_report_block(readme: &str) -> (std::ops::Range<usize>, &str) {
    let at = readme
        .find("## The report")
        .expect("README has `## The report`");
    let open = at + readme[at..].find("```json\n").expect("a ```json block") + "```json\n".len();
    let close = open + readme[open..].find("```").expect("the block closes");
    (open..close, &readme[open..close])
}

/// A report's JSON as the README shows it: the subject with the most levels (the last), the
/// first entry of each list longer than 5 or holding objects, numbers to 4 decimals.
fn trim_for_readme(v: &serde_json::Value, key: &str) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .map(|(k, v)| (k.clone(), trim_for_readme(v, k)))
                .collect(),
        ),
        Value::Array(a) => {
            let short = a.len() <= 5 && a.iter().all(|x| !x.is_object() && !x.is_array());
            let kept: Vec<&Value> = if short {
                a.iter().collect()
            } else if key == "subjects" {
                a.last().into_iter().collect()
            } else {
                a.first().into_iter().collect()
            };
            Value::Array(kept.into_iter().map(|x| trim_for_readme(x, "")).collect())
        }
        Value::Number(n) if n.is_f64() => {
            let x = (n.as_f64().unwrap() * 1e4).round() / 1e4;
            serde_json::json!(x)
        }
        other => other.clone(),
    }
}

/// The example report in the README is what the report writer writes: read back as a report
/// (and its provenance) and written again, it gives the same JSON, so a field added, renamed or
/// dropped in the report fails here until the example is regenerated
/// (`regenerate_readme_report`). Its figures agree with each other, as a real run's do.
#[test]
fn the_readme_example_report_is_a_report() {
    use serde_json::Value;
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let (_, block) = readme_report_block(&readme);
    let shown: Value = serde_json::from_str(block)
        .unwrap_or_else(|e| panic!("the README's example report is JSON: {e}"));
    let report = placewords::report::json::report_from_json(block)
        .unwrap_or_else(|e| panic!("the README's example reads as a report: {e}"));
    let provenance = placewords::report::json::provenance_from_json(block)
        .unwrap_or_else(|e| panic!("the README's example has a provenance: {e}"));
    let again: Value = serde_json::from_str(&placewords::report::json::to_json_with(
        &report,
        &provenance,
    ))
    .unwrap();
    assert_eq!(
        again, shown,
        "the README's example report differs from what the report writer writes: \
         regenerate it (cargo test --release --test it regenerate_readme_report -- --ignored)"
    );
    assert_eq!(report.scenario, "B", "the example is the main job's");
    let s = &report.subjects[0];
    assert_eq!(s.name, "words-3");
    let ratio = |a: usize, b: usize| (a as f64 / b as f64 * 1e4).round() / 1e4;
    assert_eq!(
        s.scores.precision,
        ratio(s.scores.correct_pairs, s.scores.pairs)
    );
    assert_eq!(s.scores.revisits, report.revisits);
}

/// Rewrites the README's example report from a new run of the main job (about 15 s of CPU):
/// `cargo test --release --test it regenerate_readme_report -- --ignored`.
#[test]
#[ignore = "rewrites README.md; run by hand after the report changes"]
fn regenerate_readme_report() {
    let (_t, dir) = scratch();
    let out = Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(["run", "scenarios/B.toml", "--report", "b.json"])
        .current_dir(&dir)
        .output()
        .expect("the placewords binary runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let full: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("b.json")).unwrap()).unwrap();
    let shown = serde_json::to_string_pretty(&trim_for_readme(&full, "")).unwrap();
    let path = root().join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let (range, _) = readme_report_block(&readme);
    let mut new = readme.clone();
    new.replace_range(range, &format!("{shown}\n"));
    std::fs::write(&path, new).unwrap();
}
