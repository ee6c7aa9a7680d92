//! Stress runs for people and machines: the terminal table (mean and worst per level
//! configuration, with the command that reproduces the worst seed), the Markdown `table.md`
//! (mean, 10th percentile, worst and its seed, and the gate), and the `--json` summary.

use crate::eval::distribution::{ConfigSpread, Metric, Spread};
use crate::eval::gate::{Bound, Missing, Outcome};
use crate::eval::suite::{ScenarioResult, SuiteReport, Tally};
use crate::recognizer::Direction;
use serde::Serialize;
use std::fmt::Write;

/// A bound or a measured value as printed: ratios with 3 decimals, times in seconds.
pub fn fmt_value(bound: Bound, v: f64) -> String {
    match bound {
        Bound::MaxSecondsPerLap => format!("{v:.2}s"),
        _ => format!("{v:.3}"),
    }
}

/// The metric's words and the comparison a bound asks for: `("precision", ">=")`.
fn what_op(bound: Bound) -> (&'static str, &'static str) {
    match bound {
        Bound::MinPrecision => ("precision", ">="),
        Bound::MinRecall => ("recall", ">="),
        Bound::MinVisitRecall => ("visit recall", ">="),
        Bound::MinPairRecall => ("pair recall", ">="),
        Bound::MaxSecondsPerLap => ("s/lap", "<="),
    }
}

/// Why a bound has no figure, in words.
pub fn missing_words(o: &Outcome) -> String {
    match &o.missing {
        None | Some(Missing::NotInReport) => "not in the report".into(),
        Some(Missing::NoMatches) => match o.direction {
            Some(d) => format!("no {} matches at any seed", d.name()),
            None => "no matches at any seed".into(),
        },
        Some(Missing::EverySeedFailed { error }) => {
            format!("every seed failed: {error}, see the error test cases")
        }
    }
}

/// The line printed for people: `PASS B words-3 precision worst 0.930 >= 0.900 (seed 7, over
/// 20 seeds)`, or with the direction a bound is on, `FAIL R words-3 opposite precision …`.
pub fn outcome_line(o: &Outcome) -> String {
    let status = if o.passed { "PASS" } else { "FAIL" };
    let (what, op) = what_op(o.bound);
    let limit = fmt_value(o.bound, o.limit);
    let target = match o.direction {
        None => o.subject.clone(),
        Some(d) => format!("{} {}", o.subject, d.name()),
    };
    let (Some(a), Some(seed)) = (o.actual, o.seed) else {
        return format!(
            "{status} {} {target} {what} {op} {limit}: {}",
            o.scenario,
            missing_words(o)
        );
    };
    let op = match (o.passed, op) {
        (true, op) => op,
        (false, ">=") => "<",
        (false, _) => ">",
    };
    let of = over_seeds(o);
    format!(
        "{status} {} {target} {what} {} {} {op} {limit} (seed {seed}, {of})",
        o.scenario,
        o.statistic(),
        fmt_value(o.bound, a),
    )
}

/// `over 20 seeds`, with how many of them matched nothing when some did.
fn over_seeds(o: &Outcome) -> String {
    let n = o.runs;
    match n - o.seeds {
        0 if n == 1 => "over 1 seed".to_string(),
        0 => format!("over {n} seeds"),
        nothing => format!("over {n} seeds; {nothing} matched nothing"),
    }
}

/// `N passed, M failed` (and `, E errors` when there are any).
pub fn tally_line(t: &Tally) -> String {
    let mut s = format!("{} passed, {} failed", t.passed, t.failed);
    if t.errors > 0 {
        let plural = if t.errors == 1 { "" } else { "s" };
        let _ = write!(s, ", {} error{plural}", t.errors);
    }
    s
}

/// `mean` of a spread, or "no matches" when no seed has a value.
fn mean(s: Option<&Spread>) -> String {
    s.map_or("no matches".into(), |s| format!("{:.3}", s.mean))
}

/// `worst (seed N)`, or "no matches".
fn worst(s: Option<&Spread>, decimals: usize) -> String {
    s.map_or("no matches".into(), |s| {
        format!("{:.decimals$} (seed {})", s.worst, s.worst_seed)
    })
}

/// Row label: the subject with its τ per level, `words-3 [6, 9, 12]`, or its name, `icp`.
fn label(c: &ConfigSpread) -> String {
    if c.thresholds.is_empty() {
        return c.subject.clone();
    }
    format!("{} {:?}", c.subject, c.thresholds)
}

/// The header line of a scenario: label, file, seeds and how many ran.
fn header(sc: &ScenarioResult) -> String {
    let laps = sc
        .results
        .iter()
        .find_map(|r| r.report.as_ref().map(|r| r.laps))
        .unwrap_or(0);
    format!(
        "scenario {} ({})  seeds {} ({} run)  laps {laps}",
        sc.label,
        sc.file,
        sc.seeds,
        sc.results.len()
    )
}

/// The terminal table of a stress run: per scenario and configuration, mean and worst of
/// precision, recall and visit recall and of seconds per lap; then the seeds that matched
/// nothing and, per worst seed, the command that reproduces it.
pub fn text_table(suite: &SuiteReport) -> String {
    let mut out = String::new();
    for sc in &suite.scenarios {
        let _ = writeln!(out, "{}", header(sc));
        // Each error is printed once, on stderr, by the command; the table only counts them.
        match sc.errors().len() {
            0 => {}
            n => {
                let _ = writeln!(out, "  {n} error(s): see the `error:` lines on stderr");
            }
        }
        if sc.summary.is_empty() {
            out.push('\n');
            continue;
        }
        out.push_str(&summary_table(sc));
        out.push_str(&worst_seeds(sc));
        out.push('\n');
    }
    out
}

/// The table of a scenario's configurations, one [`text_row`] each.
fn summary_table(sc: &ScenarioResult) -> String {
    let body: Vec<Vec<String>> = sc.summary.iter().map(text_row).collect();
    super::table::render(
        &[
            "subject [τ]",
            "precision mean",
            "worst",
            "recall mean",
            "worst",
            "visit R mean",
            "s/lap mean",
            "worst",
        ],
        &body,
    )
}

fn text_row(c: &ConfigSpread) -> Vec<String> {
    let time = c.get(Metric::SecondsPerLap);
    vec![
        label(c),
        mean(c.get(Metric::Precision)),
        worst(c.get(Metric::Precision), 3),
        mean(c.get(Metric::Recall)),
        worst(c.get(Metric::Recall), 3),
        mean(c.get(Metric::VisitRecall)),
        time.map_or("-".into(), |s| format!("{:.3}", s.mean)),
        time.map_or("-".into(), |s| format!("{:.3}", s.worst)),
    ]
}

/// Lines naming the seeds that matched nothing, and per seed that is worst at precision or
/// recall somewhere, what it is worst at and the command that reproduces it.
fn worst_seeds(sc: &ScenarioResult) -> String {
    let mut out = String::new();
    let mut seeds: Vec<(u64, Vec<String>)> = Vec::new();
    for c in &sc.summary {
        if !c.no_match_seeds.is_empty() {
            let _ = writeln!(
                out,
                "{}: no matches at seed(s) {:?}",
                label(c),
                c.no_match_seeds
            );
        }
        for m in [Metric::Precision, Metric::Recall] {
            let Some(s) = c.get(m) else { continue };
            let what = format!("{} at {}", m.name(), c.subject);
            match seeds.iter_mut().find(|(seed, _)| *seed == s.worst_seed) {
                Some((_, v)) => v.push(what),
                None => seeds.push((s.worst_seed, vec![what])),
            }
        }
    }
    if sc.results.len() > 1 {
        for (seed, what) in seeds {
            let _ = writeln!(out, "worst {}: {}", what.join(", "), sc.reproduce(seed));
        }
    }
    out
}

/// What `check` and `merge` print: the terminal table, a line per bound (with the command
/// reproducing a missed one), and `N passed, M failed`; for a part, one line saying so.
pub fn check_text(suite: &SuiteReport) -> String {
    if let Some(shard) = suite.shard {
        let seeds: usize = suite.scenarios.iter().map(|s| s.results.len()).sum();
        return format!(
            "shard {shard}: {seeds} seed(s) run; merge every part with `placewords merge` for the verdict\n"
        );
    }
    let mut out = text_table(suite);
    for sc in &suite.scenarios {
        for o in &sc.outcomes {
            match (o.passed, o.seed) {
                (false, Some(seed)) => {
                    let _ = writeln!(
                        out,
                        "{}; reproduce: {}",
                        outcome_line(o),
                        sc.reproduce(seed)
                    );
                }
                _ => {
                    let _ = writeln!(out, "{}", outcome_line(o));
                }
            }
        }
    }
    let _ = writeln!(out, "{}", tally_line(&suite.tally()));
    out
}

/// `table.md`: per scenario, a table of mean, 10th percentile and worst (seed) per
/// configuration and metric, then the gate's outcomes; the closing tally last.
pub fn markdown(suite: &SuiteReport) -> String {
    let mut out = String::from("# placewords stress run\n");
    for sc in &suite.scenarios {
        out.push_str(&md_scenario(sc));
    }
    if suite.gated {
        let _ = writeln!(out, "\n{}", tally_line(&suite.tally()));
    }
    out
}

/// One scenario's section of `table.md`.
fn md_scenario(sc: &ScenarioResult) -> String {
    let mut out = format!("\n## {} (`{}`), seeds {}\n\n", sc.label, sc.file, sc.seeds);
    for e in sc.errors() {
        let _ = writeln!(out, "- error: {}", e.replace('\n', " "));
    }
    if !sc.summary.is_empty() {
        out.push_str("| subject | metric | mean | p10 | worst | worst seed |\n");
        out.push_str("|---|---|---|---|---|---|\n");
    }
    for c in &sc.summary {
        for m in Metric::ALL {
            let cells = md_cells(c.get(m));
            let _ = writeln!(out, "| {} | {} | {cells} |", label(c), m.name());
        }
    }
    for c in sc.summary.iter().filter(|c| !c.no_match_seeds.is_empty()) {
        let seeds = &c.no_match_seeds;
        let _ = writeln!(out, "\n{}: no matches at seed(s) {seeds:?}", label(c));
    }
    if !sc.outcomes.is_empty() {
        out.push_str("\n| test case | statistic | value | bound | seed | result |\n");
        out.push_str("|---|---|---|---|---|---|\n");
        for o in &sc.outcomes {
            let _ = writeln!(out, "{}", md_outcome(o));
        }
    }
    out
}

fn md_cells(s: Option<&Spread>) -> String {
    match s {
        Some(s) => format!(
            "{:.3} | {:.3} | {:.3} | {}",
            s.mean, s.p10, s.worst, s.worst_seed
        ),
        None => "no matches | – | – | –".into(),
    }
}

fn md_outcome(o: &Outcome) -> String {
    let value = o
        .actual
        .map_or_else(|| missing_words(o), |a| fmt_value(o.bound, a));
    let seed = o.seed.map_or("–".into(), |s| s.to_string());
    let result = if o.passed { "pass" } else { "**FAIL**" };
    format!(
        "| `{}` | {} | {value} | {} | {seed} | {result} |",
        o.name(),
        o.statistic(),
        fmt_value(o.bound, o.limit),
    )
}

/// GitHub Actions workflow commands for a stress run: an `::error file=…,line=…::` per missed
/// bound, on the line of its scenario's `[expect]` (`expect_line(file)`, `None` when not
/// found: the annotation is then on the file), and one per scenario or seed that failed to run.
pub fn github_annotations(
    suite: &SuiteReport,
    expect_line: impl Fn(&str) -> Option<usize>,
) -> Vec<String> {
    let mut out = Vec::new();
    for sc in &suite.scenarios {
        scenario_annotations(sc, expect_line(&sc.file), &mut out);
    }
    out
}

/// The annotations of one scenario: its missed bounds at `line` of its file, its errors on the
/// file.
fn scenario_annotations(sc: &ScenarioResult, line: Option<usize>, out: &mut Vec<String>) {
    let at = match line {
        Some(line) => format!("file={},line={line}", gh_property(&sc.file)),
        None => format!("file={}", gh_property(&sc.file)),
    };
    for o in sc.outcomes.iter().filter(|o| !o.passed) {
        let mut text = outcome_line(o);
        if let Some(seed) = o.seed {
            let _ = write!(text, "; reproduce: {}", sc.reproduce(seed));
        }
        out.push(format!(
            "::error {at},title={}::{}",
            gh_property(&o.name()),
            gh_data(&text)
        ));
    }
    for e in sc.errors() {
        out.push(format!(
            "::error file={},title={}::{}",
            gh_property(&sc.file),
            gh_property(&format!("{}/run", sc.label)),
            gh_data(&e)
        ));
    }
}

/// A workflow command's message, escaped as GitHub's runner reads it.
pub(crate) fn gh_data(s: &str) -> String {
    s.replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A")
}

/// A workflow command's property value (also `:` and `,` escaped).
pub(crate) fn gh_property(s: &str) -> String {
    gh_data(s).replace(':', "%3A").replace(',', "%2C")
}

/// One outcome in the `--json` summary.
#[derive(Serialize)]
struct JsonOutcome<'a> {
    name: String,
    file: &'a str,
    /// `same` or `opposite` when the bound is on one direction's figures alone.
    #[serde(skip_serializing_if = "Option::is_none")]
    direction: Option<&'static str>,
    passed: bool,
    statistic: String,
    value: Option<f64>,
    bound: f64,
    seed: Option<u64>,
    seeds: usize,
    reproduce: Option<String>,
    line: String,
}

/// The `--json` summary: tally, exit code, every outcome and every error, and the provenance.
pub fn summary_json(suite: &SuiteReport) -> String {
    let t = suite.tally();
    let outcomes = json_outcomes(suite);
    let errors: Vec<String> = suite.scenarios.iter().flat_map(|s| s.errors()).collect();
    let v = serde_json::json!({
        "passed": t.passed,
        "failed": t.failed,
        "errors": t.errors,
        "exit_code": suite.exit_code(),
        "shard": suite.shard.map(|s| s.to_string()),
        "outcomes": outcomes,
        "error_messages": errors,
        "provenance": suite.provenance,
    });
    serde_json::to_string_pretty(&v).expect("a summary always serializes")
}

/// Every outcome of the run, in scenario order, as the summary lists it.
fn json_outcomes(suite: &SuiteReport) -> Vec<JsonOutcome<'_>> {
    suite
        .scenarios
        .iter()
        .flat_map(|sc| {
            sc.outcomes.iter().map(move |o| JsonOutcome {
                name: o.name(),
                file: &sc.file,
                direction: o.direction.map(Direction::name),
                passed: o.passed,
                statistic: o.statistic(),
                value: o.actual,
                bound: o.limit,
                seed: o.seed,
                seeds: o.seeds,
                reproduce: o.seed.map(|s| sc.reproduce(s)),
                line: outcome_line(o),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;
    use crate::eval::suite::SeedResult;
    use crate::spec::evaluation::{ExpectSpec, SubjectExpectation};
    use crate::spec::seeds::SeedRange;

    fn suite() -> SuiteReport {
        let results = (1..=3)
            .map(|seed| {
                let mut r = sample("B", [0.9; 3], [0.5; 3]);
                r.seed = seed;
                r.subjects.retain(|s| s.name != "icp");
                if seed == 2 {
                    r.subjects[0].scores.no_pairs = true;
                    r.subjects[2].scores.recall = 0.1;
                }
                SeedResult {
                    seed,
                    seconds: 2.0,
                    report: Some(r),
                    error: None,
                    simulation_key: String::new(),
                    lap_cache: None,
                }
            })
            .collect();
        let sc = ScenarioResult {
            label: "B".into(),
            name: "B".into(),
            file: "scenarios/B.toml".into(),
            seeds: SeedRange { first: 1, last: 3 },
            reproduce_flags: String::new(),
            expect: ExpectSpec {
                subjects: vec![SubjectExpectation {
                    subject: "words-3".into(),
                    min_precision: None,
                    min_recall: Some(0.2),
                    min_visit_recall: None,
                    min_pair_recall: None,
                    max_seconds_per_lap: None,
                    same: None,
                    opposite: None,
                }],
                ..ExpectSpec::default()
            },
            error: None,
            results,
            summary: vec![],
            outcomes: vec![],
        };
        SuiteReport::new(None, true, vec![sc])
    }

    /// An outcome of `bound` on `words-3` of scenario R: `actual` at seed 2 of `runs` seeds.
    fn outcome(bound: Bound, limit: f64, actual: Option<f64>, runs: usize) -> Outcome {
        let passed = actual.is_some_and(|a| match bound {
            Bound::MaxSecondsPerLap => a <= limit,
            _ => a >= limit,
        });
        Outcome {
            scenario: "R".into(),
            subject: "words-3".into(),
            direction: None,
            bound,
            limit,
            quantile: None,
            actual,
            seed: actual.map(|_| 2),
            seeds: if actual.is_some() { runs } else { 0 },
            runs,
            missing: if actual.is_some() {
                None
            } else {
                Some(Missing::NoMatches)
            },
            passed,
            seconds: 1.0,
        }
    }

    #[test]
    fn outcome_lines_say_pass_or_fail_the_statistic_the_bound_and_the_seed() {
        let pass = outcome(Bound::MinPrecision, 0.9, Some(0.9), 1);
        assert_eq!(
            outcome_line(&pass),
            "PASS R words-3 precision worst 0.900 >= 0.900 (seed 2, over 1 seed)"
        );
        let slow = outcome(Bound::MaxSecondsPerLap, 2.0, Some(1.5), 1);
        assert_eq!(
            outcome_line(&slow),
            "PASS R words-3 s/lap worst 1.50s <= 2.00s (seed 2, over 1 seed)"
        );
        let mut fail = outcome(Bound::MinPrecision, 0.9, Some(0.8), 3);
        fail.direction = Some(Direction::Opposite);
        assert_eq!(
            outcome_line(&fail),
            "FAIL R words-3 opposite precision worst 0.800 < 0.900 (seed 2, over 3 seeds)"
        );
        fail.quantile = Some(0.2);
        fail.seeds = 2;
        assert!(
            outcome_line(&fail)
                .contains("precision p20 0.800 < 0.900 (seed 2, over 3 seeds; 1 matched nothing)"),
            "{}",
            outcome_line(&fail)
        );
    }

    #[test]
    fn outcome_lines_without_a_figure_say_why() {
        let mut o = outcome(Bound::MinPrecision, 0.9, None, 3);
        assert!(outcome_line(&o).ends_with("precision >= 0.900: no matches at any seed"));
        o.direction = Some(Direction::Opposite);
        assert!(
            outcome_line(&o)
                .ends_with("opposite precision >= 0.900: no opposite matches at any seed"),
            "{}",
            outcome_line(&o)
        );
        o.missing = Some(Missing::NotInReport);
        assert!(outcome_line(&o).ends_with(": not in the report"));
        o.missing = Some(Missing::EverySeedFailed {
            error: "robot blocked".into(),
        });
        assert!(
            outcome_line(&o)
                .ends_with(": every seed failed: robot blocked, see the error test cases"),
            "{}",
            outcome_line(&o)
        );
    }

    #[test]
    fn the_tally_line_names_errors_only_when_there_are_some() {
        let t = Tally {
            passed: 1,
            failed: 0,
            errors: 0,
        };
        assert_eq!(tally_line(&t), "1 passed, 0 failed");
        let t = Tally { errors: 2, ..t };
        assert_eq!(tally_line(&t), "1 passed, 0 failed, 2 errors");
    }

    #[test]
    fn the_terminal_table_shows_mean_worst_and_how_to_reproduce_it() {
        let t = text_table(&suite());
        assert!(t.contains("0.367") && t.contains("0.100 (seed 2)"), "{t}");
        assert!(
            t.contains("worst recall at words-3: placewords run scenarios/B.toml --seed 2"),
            "{t}"
        );
        assert!(t.contains("no matches at seed(s) [2]"), "{t}");
    }

    #[test]
    fn markdown_and_json_carry_the_gate() {
        let s = suite();
        let md = markdown(&s);
        assert!(
            md.contains("| `B/words-3/recall` | worst | 0.100 | 0.200 | 2 | **FAIL** |"),
            "{md}"
        );
        assert!(md.ends_with("0 passed, 1 failed\n"), "{md}");
        let v: serde_json::Value = serde_json::from_str(&summary_json(&s)).unwrap();
        assert_eq!(v["failed"], 1);
        assert_eq!(
            v["provenance"]["report_version"], 0,
            "the suite's, here a default one"
        );
        assert_eq!(v["exit_code"], 1);
        assert_eq!(
            v["outcomes"][0]["reproduce"],
            "placewords run scenarios/B.toml --seed 2"
        );
    }

    #[test]
    fn a_missed_bound_is_a_github_annotation_on_the_expect_line() {
        let s = suite();
        let a = github_annotations(&s, |f| (f == "scenarios/B.toml").then_some(12));
        assert_eq!(a.len(), 1, "{a:?}");
        assert!(
            a[0].starts_with(
                "::error file=scenarios/B.toml,line=12,title=B/words-3/recall::FAIL B words-3 recall"
            ),
            "{}",
            a[0]
        );
        assert!(a[0].ends_with("reproduce: placewords run scenarios/B.toml --seed 2"));
        assert_eq!(gh_data("50%\nx"), "50%25%0Ax");
        assert_eq!(gh_property("a:b,c"), "a%3Ab%2Cc");
    }
}
