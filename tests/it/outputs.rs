//! Output files and folders through the binary (fuzz finds 11, 12 and 13, and two
//! inconsistencies): a folder holds one complete run or is left as it was, temporary files do
//! not outlive an error or a killed process, and output paths are checked before the work.

use super::common::{placewords, root};
use std::path::{Path, PathBuf};
use std::process::Output;

/// A process id no system hands out (Linux caps them at 2^22), as a killed writer's.
const DEAD_PID: &str = "999999999";

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn simulate(out: &Path, scenario: &str) -> Output {
    placewords(&[
        "simulate",
        scenario,
        "--laps",
        "1",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ])
}

/// A scenario whose robot is blocked for good by a standing person (the run fails).
fn blocked_scenario(dir: &Path) -> PathBuf {
    let world = root().join("worlds/loop-small.toml");
    let path = dir.join("blocked.toml");
    let src = format!(
        "format_version = 1\nname = \"blocked\"\nworld = {:?}\nroute = \"lap\"\nseed = 1\n\
         [[runs]]\nlaps = 1\ndoors = \"all-closed\"\n\
         [pedestrians]\ncount = 1\npaths_m = [[[8.0, 0.0], [8.0, 0.0]]]\n\
         speed_min_m_s = 0.001\nspeed_max_m_s = 0.001\nradius_m = 0.5\n\
         [robot]\nblocked_timeout_s = 2\n\
         [expect]\nsubjects = [{{ subject = \"words-1\", min_precision = 0.5 }}]\n",
        world.display().to_string()
    );
    std::fs::write(&path, src).unwrap();
    path
}

/// Find 11: a second simulation into an earlier, larger result replaces it whole.
#[test]
fn simulate_replaces_an_earlier_output_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("logs");
    let o = simulate(&out, "scenarios/smoke.toml");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&out), ["manifest.json", "run-000.log", "run-001.log"]);
    // An earlier simulation with more runs left run-007.log.
    std::fs::write(out.join("run-007.log"), "# old\n").unwrap();
    let o = simulate(&out, "scenarios/smoke.toml");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&out), ["manifest.json", "run-000.log", "run-001.log"]);
    assert_eq!(
        names(dir.path()),
        ["logs"],
        "nothing left beside the folder"
    );
}

/// Find 11: a folder holding anything else is refused before the simulation, untouched.
#[test]
fn simulate_refuses_a_folder_of_other_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mine");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "keep me").unwrap();
    let o = simulate(&out, "scenarios/smoke.toml");
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.contains(&out.display().to_string()) && err.contains("other files"),
        "{err}"
    );
    assert_eq!(names(&out), ["notes.txt"]);
    assert_eq!(names(dir.path()), ["mine"]);
}

/// Finds 11 and 12: a simulation that fails leaves the earlier output as it was and no
/// temporary folder; `check --junit` says the failure once.
#[test]
fn a_failed_simulation_leaves_the_folder_and_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("logs");
    assert!(simulate(&out, "scenarios/smoke.toml").status.success());
    let before = std::fs::read(out.join("run-000.log")).unwrap();
    let blocked = blocked_scenario(dir.path());
    let o = simulate(&out, blocked.to_str().unwrap());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("blocked"), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.join("run-000.log")).unwrap(), before);
    assert_eq!(names(dir.path()), ["blocked.toml", "logs"]);

    let junit = dir.path().join("j.xml");
    let o = placewords(&[
        "check",
        blocked.to_str().unwrap(),
        "-q",
        "--junit",
        junit.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let error = doc.descendants().find(|n| n.has_tag_name("error")).unwrap();
    let said = format!(
        "{} {}",
        error.attribute("message").unwrap(),
        error.text().unwrap_or("")
    );
    assert_eq!(said.matches("the robot was blocked").count(), 1, "{xml}");
    // the bound says why it has no figure, pointing at the error case
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .unwrap();
    let message = failure.attribute("message").unwrap();
    assert!(
        message.contains("every seed failed: ") && message.contains("see the error test cases"),
        "{xml}"
    );
}

/// Find 12: the temporary file or folder a killed writer left beside an output is removed by
/// the next write of that output.
#[test]
fn temporary_files_of_a_killed_writer_are_removed_by_the_next_write() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("logs");
    std::fs::create_dir(dir.path().join(format!(".logs.tmp{DEAD_PID}"))).unwrap();
    std::fs::write(dir.path().join(format!(".logs.tmp{DEAD_PID}-old")), "x").unwrap();
    std::fs::write(dir.path().join(format!(".r.json.tmp{DEAD_PID}")), "half").unwrap();
    assert!(simulate(&out, "scenarios/smoke.toml").status.success());
    let report = dir.path().join("r.json");
    let o = placewords(&[
        "run",
        "scenarios/smoke.toml",
        "--laps",
        "1",
        "--levels",
        "1",
        "-q",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(dir.path()), ["logs", "r.json"]);
}

/// Find 13: every output path is checked before the work starts (exit 2, the path named,
/// nothing printed on stdout, where the results would go).
#[test]
fn unwritable_outputs_are_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let bad = file.join("out");
    let bad = bad.to_str().unwrap();
    let smoke = "scenarios/smoke.toml";
    let cases: Vec<Vec<&str>> = vec![
        vec!["run", smoke, "--report", bad],
        vec!["run", smoke, "--svg", bad],
        vec!["table", smoke, "-o", bad],
        vec!["sweep", smoke, "-o", bad],
        vec!["check", smoke, "-o", bad],
        vec!["check", smoke, "--junit", bad],
        vec!["check", smoke, "--report", bad],
        vec!["simulate", smoke, "-o", bad],
    ];
    for args in cases {
        let o = placewords(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(bad), "{args:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{args:?} did the work first");
    }
}

/// `simulate --laps 0` is refused like `laps = 0` in a file.
#[test]
fn zero_laps_on_the_command_line_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("logs");
    let o = simulate_with_laps(&out, "0");
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("a run needs 1 lap or more"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

fn simulate_with_laps(out: &Path, laps: &str) -> Output {
    placewords(&[
        "simulate",
        "scenarios/smoke.toml",
        "--laps",
        laps,
        "-o",
        out.to_str().unwrap(),
    ])
}

/// The visible files of `dir` and their bytes (empty when `dir` is missing).
fn snapshot(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Default::default();
    };
    entries
        .map(|e| e.unwrap())
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).unwrap())
        })
        .collect()
}

/// Runs `new_args` (with `-o DIR` appended) over an earlier output of `old_args`, killing it
/// at its first rename, then its second, and so on until a run goes through: after every kill
/// `DIR` must be the old output byte for byte, and the run that goes through must leave the new
/// output, no staging folder and no lock.
fn kill_at_every_rename(old_args: &[&str], new_args: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    let dir_s = dir.to_str().unwrap();
    let with_out = |args: &[&str]| {
        let mut v: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        v.extend(["-q".into(), "-o".into(), dir_s.into()]);
        v
    };
    let run = |args: &[String], kill_at: Option<usize>| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"));
        c.args(args).current_dir(root());
        if let Some(n) = kill_at {
            c.env(placewords::io::atomic::TEST_KILL_AT_ENV, n.to_string());
        }
        c.output().unwrap()
    };
    let o = run(&with_out(old_args), None);
    assert!(o.status.code().is_some_and(|c| c < 2), "{}", stderr(&o));
    let old = snapshot(&dir);
    assert!(!old.is_empty());
    let mut kills = 0;
    for n in 1..100 {
        let o = run(&with_out(new_args), Some(n));
        if o.status.code().is_some() {
            assert!(o.status.code().unwrap() < 2, "{}", stderr(&o));
            break;
        }
        kills += 1;
        assert!(
            snapshot(&dir) == old,
            "{new_args:?} killed at rename {n}: {dir_s} is not the old output whole (files {:?})",
            snapshot(&dir).keys().collect::<Vec<_>>()
        );
    }
    assert!(kills >= 1, "{new_args:?} renamed nothing");
    let new = snapshot(&dir);
    assert!(new != old && new.keys().eq(old.keys()), "{new_args:?}");
    let leftovers: Vec<String> = names(tmp.path())
        .into_iter()
        .filter(|n| n != "out")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Issue 31 point 3: every multi-file writer puts its folder in place in one step.
#[test]
fn a_kill_at_any_rename_leaves_the_old_output_or_the_new_one_whole() {
    let smoke = "scenarios/smoke.toml";
    kill_at_every_rename(
        &["simulate", smoke, "--laps", "1"],
        &["simulate", smoke, "--laps", "2"],
    );
    kill_at_every_rename(
        &["check", smoke, "--seed", "1"],
        &["check", smoke, "--seed", "2"],
    );
    kill_at_every_rename(
        &["table", smoke, "--no-icp", "--laps", "1"],
        &["table", smoke, "--no-icp", "--laps", "2"],
    );
    kill_at_every_rename(
        &["sweep", smoke, "--laps", "1"],
        &["sweep", smoke, "--laps", "2"],
    );
}

/// Two writers of one folder: while one holds it, the other is refused, naming its pid.
#[test]
fn a_folder_another_live_process_writes_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    // This test process is alive: its pid in the lock stands for a running writer.
    std::fs::write(tmp.path().join(".out.lock"), std::process::id().to_string()).unwrap();
    for args in [
        vec!["simulate", "scenarios/smoke.toml", "--laps", "1"],
        vec!["check", "scenarios/smoke.toml", "--seed", "1"],
        vec!["sweep", "scenarios/smoke.toml", "--laps", "1"],
        vec!["table", "scenarios/smoke.toml", "--laps", "1", "--no-icp"],
    ] {
        let mut a = args.clone();
        a.extend(["-q", "-o", dir.to_str().unwrap()]);
        let o = placewords(&a);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        let pid = format!("pid {}", std::process::id());
        assert!(e.contains("another placewords") && e.contains(&pid), "{e}");
        assert!(!dir.exists(), "{args:?} created the folder it was refused");
    }
    // A lock whose process is gone is taken over.
    std::fs::write(tmp.path().join(".out.lock"), DEAD_PID).unwrap();
    let o = placewords(&[
        "simulate",
        "scenarios/smoke.toml",
        "--laps",
        "1",
        "-q",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!tmp.path().join(".out.lock").exists());
}

/// The files of an output set: each file's bytes, and each file in each folder's
/// (`folder/name`), hidden files left out.
fn set_snapshot(files: &[&Path], dirs: &[&Path]) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    for f in files {
        if let Ok(b) = std::fs::read(f) {
            out.insert(f.file_name().unwrap().to_string_lossy().into_owned(), b);
        }
    }
    for d in dirs {
        for (name, b) in snapshot(d) {
            out.insert(
                format!("{}/{name}", d.file_name().unwrap().to_string_lossy()),
                b,
            );
        }
    }
    out
}

/// Issue 31 point 3: `run --report R --export-matches M --svg DIR` (three outputs in places of
/// the user's choosing, no one rename can swap) puts them in place as one. Killed at its first
/// rename, then its second, and so on, over an earlier run's outputs: once the next placewords
/// reader or writer has settled what the kill left (`io::atomic::settle`), every output is the
/// old one or every one is new and whole — never a new report beside old matches — and the run
/// that goes through leaves nothing hidden behind.
#[test]
fn run_outputs_are_one_set_under_a_kill_at_any_rename() {
    let tmp = tempfile::tempdir().unwrap();
    let (r, m, d) = (
        tmp.path().join("r.json"),
        tmp.path().join("m.csv"),
        tmp.path().join("pics"),
    );
    let args = |laps: &str| -> Vec<String> {
        let a = [
            "run",
            "scenarios/smoke.toml",
            "--laps",
            laps,
            "--levels",
            "1",
            "-q",
            "--report",
            r.to_str().unwrap(),
            "--export-matches",
            m.to_str().unwrap(),
            "--svg",
            d.to_str().unwrap(),
        ];
        a.iter().map(|s| s.to_string()).collect()
    };
    let run = |args: &[String], kill_at: Option<usize>| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_placewords"));
        c.args(args).current_dir(root());
        if let Some(n) = kill_at {
            c.env(placewords::io::atomic::TEST_KILL_AT_ENV, n.to_string());
        }
        c.output().unwrap()
    };
    let o = run(&args("1"), None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let old = set_snapshot(&[r.as_path(), m.as_path()], &[d.as_path()]);
    assert_eq!(old.len(), 2 + names(&d).len());
    let laps_of = |snap: &std::collections::BTreeMap<String, Vec<u8>>| {
        let v: serde_json::Value = serde_json::from_slice(&snap["r.json"]).unwrap();
        v["laps"].as_u64().unwrap()
    };
    let mut after_kills = Vec::new();
    for n in 1..200 {
        let o = run(&args("2"), Some(n));
        if o.status.code().is_some() {
            assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
            break;
        }
        for p in [&r, &m, &d] {
            placewords::io::atomic::settle(p);
        }
        after_kills.push((n, set_snapshot(&[r.as_path(), m.as_path()], &[d.as_path()])));
    }
    assert!(
        after_kills.len() >= 3,
        "{} renames before the run went through",
        after_kills.len()
    );
    let new = set_snapshot(&[r.as_path(), m.as_path()], &[d.as_path()]);
    assert_eq!(laps_of(&new), 2 * laps_of(&old));
    let mut committed_by_settle = 0;
    for (n, now) in &after_kills {
        assert!(
            now.keys().eq(old.keys()),
            "killed at rename {n}: {:?}",
            now.keys()
        );
        // The report says which run the set is of; every other output must be that run's
        // (matches and pictures carry no timings: the run that went through made the same).
        let side = if laps_of(now) == laps_of(&old) {
            &old
        } else {
            &new
        };
        committed_by_settle += usize::from(side == &new);
        for (k, bytes) in now.iter().filter(|(k, _)| *k != "r.json") {
            assert!(
                bytes == &side[k],
                "killed at rename {n}: {k} is not of the report's run"
            );
        }
    }
    assert!(committed_by_settle >= 1, "no kill fell after the commit");
    assert_eq!(
        names(tmp.path()),
        ["m.csv", "pics", "r.json"],
        "nothing hidden left"
    );
    assert!(
        names(&d).iter().all(|n| !n.starts_with('.')),
        "{:?}",
        names(&d)
    );
}

/// A commit marker's temporary file left by a killed process (as versions that wrote the marker
/// through one could leave, `..NAME.commitPID.tmpPID`) is removed by the next settle; a live
/// process's is left to it.
#[test]
fn settle_removes_the_marker_temporaries_of_dead_processes() {
    let tmp = tempfile::tempdir().unwrap();
    let dead = tmp
        .path()
        .join(format!("..r.json.commit{DEAD_PID}.tmp{DEAD_PID}"));
    let me = std::process::id();
    let live = tmp.path().join(format!("..r.json.commit{me}.tmp{me}"));
    let other = tmp
        .path()
        .join(format!("..m.csv.commit{DEAD_PID}.tmp{DEAD_PID}"));
    for p in [&dead, &live, &other] {
        std::fs::write(p, "{}").unwrap();
    }
    placewords::io::atomic::settle(&tmp.path().join("r.json"));
    assert!(!dead.exists());
    assert!(live.exists(), "a running process's temporary is its own");
    assert!(
        other.exists(),
        "another output's temporaries are its settle's"
    );
}

/// An output file another live process writes is refused, naming it and that process, before
/// the work; the earlier file stays.
#[test]
fn an_output_file_another_live_process_writes_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let r = tmp.path().join("r.json");
    std::fs::write(&r, "{}").unwrap();
    std::fs::write(
        tmp.path().join(".r.json.lock"),
        std::process::id().to_string(),
    )
    .unwrap();
    for args in [
        vec![
            "run",
            "scenarios/smoke.toml",
            "--laps",
            "1",
            "--levels",
            "1",
        ],
        vec!["check", "scenarios/smoke.toml", "--seed", "1"],
    ] {
        let mut a = args.clone();
        a.extend(["-q", "--report", r.to_str().unwrap()]);
        let o = placewords(&a);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        let pid = format!("pid {}", std::process::id());
        assert!(e.contains("another placewords") && e.contains(&pid), "{e}");
        assert!(o.stdout.is_empty(), "{args:?} did the work first");
        assert_eq!(std::fs::read_to_string(&r).unwrap(), "{}");
    }
}

/// Issue 31: a zero that means "nothing to do" is refused, exit 2, naming the flag, before
/// any output folder is made.
#[test]
fn zero_laps_is_refused_by_every_command_that_takes_laps() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let out = out.to_str().unwrap();
    let smoke = "scenarios/smoke.toml";
    for args in [
        vec!["table", smoke, "--laps", "0", "--no-icp", "-o", out],
        vec!["sweep", smoke, "--laps", "0", "-o", out],
        vec!["run", smoke, "--laps", "0"],
        vec!["check", smoke, "--laps", "0"],
        vec!["simulate", smoke, "--laps", "0", "-o", out],
    ] {
        let o = placewords(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains("--laps") && e.contains("1 lap or more"),
            "{args:?}: {e}"
        );
        assert!(
            names(tmp.path()).is_empty(),
            "{args:?} left {:?}",
            names(tmp.path())
        );
    }
}
