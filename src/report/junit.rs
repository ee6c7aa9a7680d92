//! JUnit XML for `placewords check --junit`: one `<testsuite>` per scenario, one `<testcase>` per
//! checked bound, `<failure>` for a missed bound, `<error>` for a scenario that could not run.
//! The dialect is the common one Jenkins, GitLab and GitHub test reporters read.

pub use super::xml::escape;
use crate::eval::gate::Outcome;

/// What `check` knows about one scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Suite {
    /// Scenario name (the testsuite name).
    pub scenario: String,
    /// The gate's outcomes (empty when the scenario failed to run).
    pub outcomes: Vec<Outcome>,
    /// Why the scenario could not run (exit code 2), if it could not.
    pub error: Option<String>,
    /// Wall-clock seconds the scenario took.
    pub seconds: f64,
}

/// The JUnit XML document of `suites`.
pub fn junit_xml(suites: &[Suite]) -> String {
    let count = |s: &Suite| s.outcomes.len() + s.error.is_some() as usize;
    let fails = |s: &Suite| s.outcomes.iter().filter(|o| !o.passed).count();
    let tests: usize = suites.iter().map(count).sum();
    let failures: usize = suites.iter().map(fails).sum();
    let errors = suites.iter().filter(|s| s.error.is_some()).count();
    let time: f64 = suites.iter().map(|s| s.seconds).sum();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(&format!(
        "<testsuites name=\"placewords check\" tests=\"{tests}\" failures=\"{failures}\" \
         errors=\"{errors}\" time=\"{time:.3}\">\n"
    ));
    for s in suites {
        let name = escape(&s.scenario);
        x.push_str(&format!(
            "  <testsuite name=\"{name}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" \
             skipped=\"0\" time=\"{:.3}\">\n",
            count(s),
            fails(s),
            s.error.is_some() as usize,
            s.seconds
        ));
        let classname = escape(&format!("placewords.{}", s.scenario));
        if let Some(err) = &s.error {
            x.push_str(&format!(
                "    <testcase name=\"run\" classname=\"{classname}\" time=\"{:.3}\">\n      \
                 <error message=\"{}\" type=\"error\">{}</error>\n    </testcase>\n",
                s.seconds,
                escape(first_line(err)),
                escape(err)
            ));
        }
        for o in &s.outcomes {
            let name = escape(&o.name());
            if o.passed {
                x.push_str(&format!(
                    "    <testcase name=\"{name}\" classname=\"{classname}\" time=\"0\"/>\n"
                ));
            } else {
                let line = escape(&o.line());
                x.push_str(&format!(
                    "    <testcase name=\"{name}\" classname=\"{classname}\" time=\"0\">\n      \
                     <failure message=\"{line}\" type=\"expectation\">{line}</failure>\n    \
                     </testcase>\n"
                ));
            }
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::gate::{Bound, check};
    use crate::eval::scores::tests::sample;
    use crate::spec::evaluation::{ExpectSpec, LevelExpectation};

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
            levels: vec![LevelExpectation {
                levels: 3,
                min_precision: Some(0.95),
                min_recall: Some(0.3),
                min_visit_recall: None,
                min_pair_recall: None,
                max_seconds_per_lap: None,
            }],
            icp: None,
        };
        let outcomes = check(&rep, &spec);
        assert_eq!(outcomes[0].bound, Bound::MinPrecision);
        let xml = junit_xml(&[
            Suite {
                scenario: rep.scenario.clone(),
                outcomes,
                error: None,
                seconds: 1.5,
            },
            Suite {
                scenario: "broken".into(),
                outcomes: vec![],
                error: Some("scenarios/x.toml:3:1: unknown field `lapz`\n\"hint\"".into()),
                seconds: 0.0,
            },
        ]);
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
            Some("FAIL B<&> levels=3 precision 0.900 < 0.950")
        );
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
    }
}
