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
         [expect]\nlevels = [{{ levels = 1, min_precision = 0.5 }}]\n",
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
