//! What CI pipelines rely on beyond the verdict: `simulate --seed`, a JUnit file whose times
//! are true, and GitHub Actions annotations and step summary.

use super::common::{placewords, root};
use std::process::Command;

/// `simulate --seed N` simulates seed N: the manifest says so and the logs differ from the
/// scenario's own seed's.
#[test]
fn simulate_takes_the_seed_to_reproduce() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |seed: Option<&str>, out: &str| {
        let out = dir.path().join(out);
        let mut args = vec![
            "simulate",
            "scenarios/smoke.toml",
            "--laps",
            "1",
            "-q",
            "-o",
        ];
        args.push(out.to_str().unwrap());
        if let Some(s) = seed {
            args.extend(["--seed", s]);
        }
        let o = placewords(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
        let log = std::fs::read_to_string(out.join("run-000.log")).unwrap();
        (manifest, log)
    };
    let (m7, l7) = sim(Some("7"), "s7");
    let (m, l) = sim(None, "s42");
    let seed = |m: &str| serde_json::from_str::<serde_json::Value>(m).unwrap()["seed"].clone();
    assert_eq!(seed(&m7), 7, "{m7}");
    assert_eq!(seed(&m), 42);
    assert_ne!(l7, l, "another seed, other laps");
}

/// The JUnit file's top-level time is the run's wall time (not the seeds' times added up), and
/// a scenario that cannot run has time 0.000, not -0.000.
#[test]
fn junit_time_is_the_wall_time_and_never_negative() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.toml");
    std::fs::write(&broken, "format_version = 1\nlapz = 3\n").unwrap();
    let junit = dir.path().join("junit.xml");
    let started = std::time::Instant::now();
    let o = placewords(&[
        "check",
        "-q",
        "scenarios/smoke.toml",
        broken.to_str().unwrap(),
        "--seeds",
        "1..3",
        "--junit",
        junit.to_str().unwrap(),
    ]);
    let wall = started.elapsed().as_secs_f64();
    assert_eq!(o.status.code(), Some(2));
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(!xml.contains("\"-0.000\""), "{xml}");
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let time: f64 = doc
        .root_element()
        .attribute("time")
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        time > 0.0 && time <= wall,
        "time {time} against a wall time of {wall}"
    );
    let seeds = doc
        .descendants()
        .filter(|n| n.attribute("name") == Some("seeds"))
        .map(|n| n.attribute("value").unwrap())
        .collect::<Vec<_>>();
    assert!(
        !seeds.is_empty() && seeds.iter().all(|s| *s == "3"),
        "every seed run: {seeds:?}"
    );
}

/// Under GitHub Actions a missed bound is an `::error` annotation on the scenario's `[expect]`
/// line and the Markdown table is appended to the step summary.
#[test]
fn github_actions_get_annotations_and_a_step_summary() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(root().join("scenarios/smoke.toml")).unwrap();
    let world = root().join("worlds/loop-small.toml");
    let src = src.replace(
        "\"../worlds/loop-small.toml\"",
        &format!("{:?}", world.display().to_string()),
    );
    let cut = src.find("[expect]").unwrap();
    let body = format!(
        "{}[expect]\nsubjects = [{{ subject = \"words-1\", min_recall = 1.0 }}]\n",
        &src[..cut]
    );
    let line = body[..body.find("[expect]").unwrap()].lines().count() + 1;
    let scenario = dir.path().join("gate.toml");
    std::fs::write(&scenario, &body).unwrap();
    let summary = dir.path().join("summary.md");
    std::fs::write(&summary, "earlier step\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(["check", "-q", scenario.to_str().unwrap(), "--seed", "1"])
        .env("GITHUB_ACTIONS", "true")
        .env("GITHUB_STEP_SUMMARY", &summary)
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    let want = format!("::error file={},line={line},title=", scenario.display());
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with(&want) && l.contains("recall")),
        "{want} in {stdout}"
    );
    let md = std::fs::read_to_string(&summary).unwrap();
    assert!(
        md.starts_with("earlier step\n# placewords stress run"),
        "{md}"
    );
    assert!(md.contains("**FAIL**"), "{md}");

    let o = placewords(&["check", "-q", scenario.to_str().unwrap(), "--seed", "1"]);
    assert!(
        !String::from_utf8_lossy(&o.stdout).contains("::error"),
        "only under GitHub"
    );
}
