//! JUnit XML for `placewords check --junit` and `merge`: one `<testsuite>` per scenario, one
//! `<testcase>` per checked bound, `<failure>` for a missed bound, `<error>` for a scenario or
//! seed that could not run. The dialect is the common one Jenkins, GitLab and GitHub test
//! reporters read.
//!
//! Test case names do not change when a bound does (`B/words-3/precision`); the class name
//! is the scenario file, so two scenarios of one name stay apart. Each test case carries the
//! measured value, the bound, the statistic (worst or a quantile), the seed it came from and
//! the command reproducing it as `<properties>` (`seeds`: every seed the scenario ran, failed
//! ones included), and its `time` is the seconds its configuration spent recognizing over all
//! seeds. Each `<testsuite>` names the placewords version and commit that made it as
//! properties (`placewords_version`, `placewords_commit`); the top-level `time` is the run's
//! wall time (for a merge, the longest part's), never negative.

pub use super::xml::escape;
use crate::eval::compare::Comparison;
use crate::eval::gate::Outcome;
use crate::eval::provenance::{GIT_COMMIT, TOOL_VERSION};
use crate::eval::suite::{SuiteReport, reproduce_command};
use crate::report::suite::{fmt_value, outcome_line};
use std::fmt::Write;

/// What `check` knows about one scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Suite {
    /// Scenario label (the testsuite name).
    pub scenario: String,
    /// The scenario file (the class name of its test cases).
    pub file: String,
    /// The flags a reproducing command needs besides file and seed
    /// (`ScenarioResult::reproduce_flags`).
    pub reproduce_flags: String,
    /// The gate's outcomes (empty when the scenario failed to run).
    pub outcomes: Vec<Outcome>,
    /// Why the scenario (or some of its seeds) could not run (exit code 2), if so.
    pub error: Option<String>,
    /// Wall-clock seconds the scenario took, over all seeds.
    pub seconds: f64,
    /// Seeds the scenario ran, failed ones included.
    pub seeds_run: usize,
}

/// What the document says about the whole run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunInfo {
    /// The placewords version and commit that made the results.
    pub version: String,
    pub commit: String,
    /// The run's wall time; `None`: the suites' seconds added up.
    pub wall_seconds: Option<f64>,
}

impl Default for RunInfo {
    /// This binary's version and commit, no wall time.
    fn default() -> Self {
        RunInfo {
            version: TOOL_VERSION.into(),
            commit: GIT_COMMIT.into(),
            wall_seconds: None,
        }
    }
}

/// The JUnit document of a stress run (or a merge): its suites, version, commit, wall time.
pub fn document(report: &SuiteReport) -> String {
    document_with(report, None)
}

/// [`document`] with, after the gate's suites, one suite per scenario of a comparison with a
/// baseline (`report::compare::junit_suites`).
pub fn document_with(report: &SuiteReport, baseline: Option<&Comparison>) -> String {
    let p = &report.provenance;
    let known = |s: &str| {
        if s.is_empty() {
            "unknown".to_string()
        } else {
            s.to_string()
        }
    };
    let run = RunInfo {
        version: known(&p.version),
        commit: known(&p.commit),
        wall_seconds: Some(report.wall_seconds),
    };
    let extra = baseline.map(super::compare::junit_suites);
    junit_xml_with(&suites(report), &run, extra.as_ref())
}

/// Seconds as JUnit writes them: three decimals, never `-0.000` or a negative time.
fn secs(s: f64) -> String {
    let s = if s.is_finite() && s > 0.0 { s } else { 0.0 };
    format!("{s:.3}")
}

/// The JUnit suites of a stress run.
pub fn suites(report: &SuiteReport) -> Vec<Suite> {
    report
        .scenarios
        .iter()
        .map(|sc| {
            let errors = sc.errors();
            Suite {
                scenario: sc.label.clone(),
                file: sc.file.clone(),
                reproduce_flags: sc.reproduce_flags.clone(),
                outcomes: sc.outcomes.clone(),
                error: (!errors.is_empty()).then(|| errors.join("\n")),
                seconds: sc.seconds(),
                seeds_run: sc.results.len(),
            }
        })
        .collect()
}

/// The JUnit XML document of `suites`, made by this binary (see [`document`]).
pub fn junit_xml(suites: &[Suite]) -> String {
    junit_xml_of(suites, &RunInfo::default())
}

/// The JUnit XML document of `suites` with `run`'s version, commit and wall time.
pub fn junit_xml_of(suites: &[Suite], run: &RunInfo) -> String {
    junit_xml_with(suites, run, None)
}

/// [`junit_xml_of`] with `extra` (tests, failures, `<testsuite>` elements) after the suites.
fn junit_xml_with(
    suites: &[Suite],
    run: &RunInfo,
    extra: Option<&(usize, usize, String)>,
) -> String {
    let count = |s: &Suite| s.outcomes.len() + s.error.is_some() as usize;
    let fails = |s: &Suite| s.outcomes.iter().filter(|o| !o.passed).count();
    let (extra_tests, extra_failures, extra_xml) = extra.map_or((0, 0, ""), |e| (e.0, e.1, &e.2));
    let tests: usize = suites.iter().map(count).sum::<usize>() + extra_tests;
    let failures: usize = suites.iter().map(fails).sum::<usize>() + extra_failures;
    let errors = suites.iter().filter(|s| s.error.is_some()).count();
    let time = run
        .wall_seconds
        .unwrap_or_else(|| suites.iter().map(|s| s.seconds).sum());
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"placewords check\" tests=\"{tests}\" failures=\"{failures}\" \
         errors=\"{errors}\" time=\"{}\">",
        secs(time)
    );
    for s in suites {
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" \
             skipped=\"0\" time=\"{}\">",
            escape(&s.scenario),
            count(s),
            fails(s),
            s.error.is_some() as usize,
            secs(s.seconds)
        );
        let _ = writeln!(
            x,
            "    <properties>\n      <property name=\"placewords_version\" value=\"{}\"/>\n      \
             <property name=\"placewords_commit\" value=\"{}\"/>\n    </properties>",
            escape(&run.version),
            escape(&run.commit)
        );
        if let Some(err) = &s.error {
            x.push_str(&error_case(s, err));
        }
        for o in &s.outcomes {
            x.push_str(&testcase(o, s));
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str(extra_xml);
    x.push_str("</testsuites>\n");
    x
}

/// The `<testcase>` of a scenario (or some of its seeds) that could not run.
fn error_case(s: &Suite, err: &str) -> String {
    format!(
        "    <testcase name=\"{}/run\" classname=\"{}\" time=\"{}\">\n      \
         <error message=\"{}\" type=\"error\">{}</error>\n    </testcase>\n",
        escape(&s.scenario),
        escape(&s.file),
        secs(s.seconds),
        escape(first_line(err)),
        escape(rest_lines(err))
    )
}

/// The properties of a test case: measured value, statistic, bound, seeds run, seed, command.
fn properties(o: &Outcome, s: &Suite) -> Vec<(&'static str, String)> {
    let seeds_run = s.seeds_run;
    let mut props = vec![
        ("statistic", o.statistic()),
        ("bound", fmt_value(o.bound, o.limit)),
        ("seeds", seeds_run.to_string()),
    ];
    if let Some(a) = o.actual {
        props.insert(0, ("value", fmt_value(o.bound, a)));
    }
    if let Some(d) = o.direction {
        props.push(("direction", d.name().to_string()));
    }
    if let Some(seed) = o.seed {
        props.push(("seed", seed.to_string()));
        props.push((
            "reproduce",
            reproduce_command(&s.file, seed, &s.reproduce_flags),
        ));
    }
    props
}

/// One `<testcase>` with its properties and, if missed, its failure.
fn testcase(o: &Outcome, s: &Suite) -> String {
    let file = &s.file;
    let mut x = format!(
        "    <testcase name=\"{}\" classname=\"{}\" file=\"{}\" time=\"{}\">\n      <properties>\n",
        escape(&o.name()),
        escape(file),
        escape(file),
        secs(o.seconds)
    );
    for (k, v) in properties(o, s) {
        let _ = writeln!(
            x,
            "        <property name=\"{k}\" value=\"{}\"/>",
            escape(&v)
        );
    }
    x.push_str("      </properties>\n");
    if !o.passed {
        x.push_str(&failure(o, s));
    }
    x.push_str("    </testcase>\n");
    x
}

/// The `<failure>` element of a failed outcome: what missed, and how to reproduce it.
fn failure(o: &Outcome, s: &Suite) -> String {
    let mut text = outcome_line(o);
    if let Some(seed) = o.seed {
        let _ = write!(
            text,
            "; reproduce: {}",
            reproduce_command(&s.file, seed, &s.reproduce_flags)
        );
    }
    let line = escape(&outcome_line(o));
    format!(
        "      <failure message=\"{line}\" type=\"expectation\">{}</failure>\n",
        escape(&text)
    )
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

/// The lines after the first (the `message` attribute holds the first; the text adds the rest,
/// so a one-line error is not said twice).
fn rest_lines(s: &str) -> &str {
    s.split_once('\n').map_or("", |(_, rest)| rest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::gate::{Bound, check};
    use crate::eval::scores::tests::sample;
    use crate::spec::evaluation::{ExpectSpec, SubjectExpectation};

    #[test]
    fn escapes_markup_and_control_characters() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\u{1}"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;\u{FFFD}"
        );
    }

    #[test]
    fn parses_and_reports_a_failure() {
        let rep = sample("B<&>", [0.93, 0.91, 0.9], [0.1, 0.25, 0.33]);
        let spec = ExpectSpec {
            subjects: vec![SubjectExpectation {
                subject: "words-3".into(),
                min_precision: Some(0.95),
                min_recall: Some(0.3),
                min_visit_recall: None,
                min_pair_recall: None,
                max_seconds_per_lap: None,
                same: None,
                opposite: None,
            }],
            quantile: None,
            regression: None,
        };
        let outcomes = check(&rep, &spec);
        assert_eq!(outcomes[0].bound, Bound::MinPrecision);
        let xml = junit_xml(&[
            Suite {
                scenario: rep.scenario.clone(),
                file: "scenarios/B.toml".into(),
                reproduce_flags: String::new(),
                outcomes,
                error: None,
                seconds: 1.5,
                seeds_run: 1,
            },
            Suite {
                scenario: "broken".into(),
                file: "x.toml".into(),
                reproduce_flags: String::new(),
                outcomes: vec![],
                error: Some("scenarios/x.toml:3:1: unknown field `lapz`\n\"hint\"".into()),
                seconds: -0.0,
                seeds_run: 0,
            },
        ]);
        assert!(!xml.contains("-0.000"), "{xml}");
        assert!(
            xml.contains("<property name=\"placewords_commit\""),
            "{xml}"
        );
        let doc = roxmltree::Document::parse(&xml).expect("valid XML");
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "testsuites");
        assert_eq!(root.attribute("tests"), Some("3"));
        assert_eq!(root.attribute("failures"), Some("1"));
        assert_eq!(root.attribute("errors"), Some("1"));
        let suites: Vec<_> = root.children().filter(|n| n.is_element()).collect();
        assert_eq!(suites.len(), 2);
        assert_eq!(suites[0].attribute("name"), Some("B<&>"));
        let cases: Vec<_> = suites[0]
            .children()
            .filter(|n| n.has_tag_name("testcase"))
            .collect();
        assert_eq!(cases.len(), 2);
        let failure = cases[0]
            .children()
            .find(|n| n.has_tag_name("failure"))
            .expect("a failure element");
        assert_eq!(
            failure.attribute("message"),
            Some("FAIL B<&> words-3 precision worst 0.900 < 0.950 (seed 7, over 1 seed)")
        );
        assert_eq!(cases[0].attribute("name"), Some("B<&>/words-3/precision"));
        assert!(
            failure
                .text()
                .unwrap()
                .contains("placewords run scenarios/B.toml --seed 7")
        );
        let value = cases[0]
            .descendants()
            .find(|n| n.attribute("name") == Some("value"))
            .and_then(|n| n.attribute("value"));
        assert_eq!(value, Some("0.900"));
        assert!(!cases[1].children().any(|n| n.has_tag_name("failure")));
        let error = suites[1]
            .descendants()
            .find(|n| n.has_tag_name("error"))
            .unwrap();
        assert_eq!(
            error.attribute("message"),
            Some("scenarios/x.toml:3:1: unknown field `lapz`")
        );
        assert!(error.text().unwrap().contains("\"hint\""));
        // The located line is the message; the text does not say it again.
        assert!(!error.text().unwrap().contains("unknown field"));
    }
}
