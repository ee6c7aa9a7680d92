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
