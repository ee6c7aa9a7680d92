//! The work budget (issue 31): a command whose laps and back-end passes imply more candidate
//! pairs than `MAX_CANDIDATE_PAIRS` is refused before any work, at the key that sets the work,
//! with a value that fits; `--laps` counts as the file's laps would.

use super::common::{placewords, root, smoke_variant};
use placewords::eval::sweep::fig8_grid;
use placewords::experiment::{Workload, parse_scenario_for, sweep_passes};
use placewords::spec::diag::MessageFormat;
use std::path::Path;

/// The smoke scenario's text with its world path absolute and `extra` appended.
fn smoke_with(extra: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = smoke_variant(dir.path(), "smoke", extra);
    std::fs::read_to_string(path).unwrap()
}

/// The problems of `src` for `work`, rendered; `None` when it is within the budget.
fn refusal(src: &str, work: &Workload) -> Option<String> {
    let loader = &placewords::world::load_world_for;
    let e = parse_scenario_for(src, Path::new("smoke.toml"), loader, work).err()?;
    Some(e.render(MessageFormat::Human).join("\n"))
}

/// The `max_candidates = K or less` a refusal names.
fn named_bound(message: &str) -> usize {
    let (_, after) = message
        .split_once("max_candidates = ")
        .unwrap_or_else(|| panic!("no bound named: {message}"));
    let digits: String = after.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().unwrap()
}

#[test]
fn a_sweep_of_a_thousand_laps_names_the_largest_candidate_bound_that_fits() {
    let work = Workload {
        laps: Some(1000),
        passes: sweep_passes(&fig8_grid()),
        ..Workload::default()
    };
    let message = refusal(&smoke_with(""), &work).expect("every candidate at 1000 laps is over");
    assert!(message.contains("--laps 1000"), "{message}");
    assert!(message.contains("[recognizer.matcher]"), "{message}");
    let k = named_bound(&message);
    assert!(k >= 1, "{message}");
    let with = |k: usize| smoke_with(&format!("[recognizer.matcher]\nmax_candidates = {k}\n"));
    assert_eq!(refusal(&with(k), &work), None, "the named bound fits");
    let over = refusal(&with(k + 1), &work).expect("one more is over");
    // Refused at the key the file sets, with the same bound.
    assert!(
        over.contains("max_candidates = ") && named_bound(&over) == k,
        "{over}"
    );
    let key_line = with(k + 1)
        .lines()
        .position(|l| l.starts_with("max_candidates"))
        .unwrap()
        + 1;
    assert!(
        over.starts_with(&format!("smoke.toml:{key_line}:1: error:")),
        "{over}"
    );
}

#[test]
fn the_file_alone_is_within_the_budget_that_its_laps_flag_exceeds() {
    let src = smoke_with("");
    let sweep = |laps| Workload {
        laps,
        passes: sweep_passes(&fig8_grid()),
        ..Workload::default()
    };
    assert_eq!(refusal(&src, &sweep(None)), None);
    assert_eq!(refusal(&src, &sweep(Some(20))), None);
    assert!(refusal(&src, &sweep(Some(1000))).is_some());
    // One pass (`scenario check`, `run --levels 1`) of the same laps is less work.
    let one = Workload {
        laps: Some(400),
        ..Workload::default()
    };
    assert_eq!(refusal(&src, &one), None);
}

#[test]
fn scan_context_observations_are_counted_only_when_it_runs() {
    let src = smoke_with("[recognizer.matcher]\nmax_candidates = 8\n");
    let table = |scan_context| Workload {
        laps: Some(600),
        passes: 3,
        scan_context,
    };
    assert_eq!(refusal(&src, &table(false)), None);
    let message = refusal(&src, &table(true)).expect("600 laps a run of Scan Context is over");
    assert!(message.contains("Scan Context observations"), "{message}");
    assert!(message.contains("--no-scan-context"), "{message}");
    let (_, after) = message.split_once("use observation_spacing_m = ").unwrap();
    let fits: f64 = after.split_whitespace().next().unwrap().parse().unwrap();
    let wider = smoke_with(&format!(
        "[recognizer.matcher]\nmax_candidates = 8\n\n[scan_context]\nobservation_spacing_m = {fits}\n"
    ));
    assert_eq!(
        refusal(&wider, &table(true)),
        None,
        "the named spacing fits"
    );
}

#[test]
fn over_budget_sweep_table_and_check_exit_2_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let smoke = "scenarios/smoke.toml";
    // A scenario of three short runs whose `--laps 1000` makes 3000 laps in all.
    let three = smoke_variant(
        dir.path(),
        "three",
        "[[runs]]\nstart_waypoint = 1\nlaps = 2\n\n[expect]\nsubjects = [{ subject = \
         \"words-1\", min_precision = 0.5 }]\n",
    );
    let three = three.to_str().unwrap();
    for args in [
        vec!["sweep", smoke, "--laps", "1000", "-q", "-o", out],
        vec![
            "table", smoke, "--no-icp", "--laps", "1000", "-q", "-o", out,
        ],
        vec!["check", three, "--laps", "1000", "-q"],
        // One seed: its three level configurations (words-1 to words-3) are three passes.
        vec!["run", smoke, "--laps", "1000", "-q"],
    ] {
        let o = placewords(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("candidate pairs"), "{args:?}: {err}");
        assert!(err.contains("--laps 1000"), "{args:?}: {err}");
        assert!(err.contains("max_candidates = "), "{args:?}: {err}");
        // Located in the file: `PATH:LINE:COL:` on the line that says it.
        let file = Path::new(args[1]).file_name().unwrap().to_str().unwrap();
        let located = err.lines().any(|l| {
            l.split_once(&format!("{file}:")).is_some_and(|(_, at)| {
                let mut parts = at.splitn(3, ':');
                let mut number = || parts.next().is_some_and(|p| p.parse::<usize>().is_ok());
                number() && number()
            }) && l.contains("candidate pairs")
        });
        assert!(located, "{args:?}: {err}");
    }
    assert!(root().join(smoke).exists());
}
