//! A comparison with a baseline (`eval::compare`) for people and machines: the terminal lines
//! (one per metric that moved, every regression with the commands reproducing its worst seed
//! on both sides), the Markdown table of what moved both ways (for a pull-request comment and
//! GitHub's step summary), and the JUnit test cases `B/words-3/precision/vs-baseline`.

use crate::eval::compare::{
    ALPHA, Basis, Comparison, Decision, MIN_PAIRED_SEEDS, MetricComparison, NotCompared,
    ScenarioComparison,
};
use crate::report::xml::escape;
use std::fmt::Write;

/// A figure as printed: ratios with 3 decimals, seconds with 4.
fn value(m: &MetricComparison, v: f64) -> String {
    if m.is_time() {
        format!("{v:.4}s")
    } else {
        format!("{v:.3}")
    }
}

/// A change: `-0.012` / `+0.004`, or for time `×1.27`.
fn change(m: &MetricComparison, c: f64) -> String {
    if m.is_time() {
        format!("×{c:.2}")
    } else {
        format!("{c:+.3}")
    }
}

fn seeds(s: &[u64]) -> String {
    crate::eval::compare::seed_list(s)
}

/// A decision as printed: `REGRESSION`, `no change (identical)`.
pub fn decision_name(d: Decision) -> &'static str {
    match d {
        Decision::Identical => "no change (identical)",
        Decision::NoChange => "no change",
        Decision::Regression => "REGRESSION",
        Decision::Improvement => "improvement",
    }
}

/// How the decision was reached, in words, with the seeds left out.
pub fn basis_words(m: &MetricComparison) -> String {
    let n = m.seeds.len();
    let mut s = match m.basis {
        Basis::SameAtEverySeed => "the same figure at every seed".to_string(),
        Basis::EverySeedBeyond => format!(
            "{n} seed{} is too few for the signed-rank test to reach {ALPHA} (it needs \
             {MIN_PAIRED_SEEDS}): decided on every seed being beyond the tolerance",
            if n == 1 { "" } else { "s" }
        ),
        Basis::SignedRank => "Wilcoxon signed-rank, exact, one-sided".to_string(),
        Basis::RankSum => "Mann–Whitney, two samples (not paired), one-sided".to_string(),
    };
    if !m.left_out_seeds.is_empty() {
        let _ = write!(
            s,
            "; seeds {} left out (no matches on one side)",
            seeds(&m.left_out_seeds)
        );
    }
    s
}

/// How the seeds of a scenario are compared, in words: paired by seed when no seed's
/// simulation keys differ, as two samples otherwise (with the input files that changed).
pub fn pairing_words(sc: &ScenarioComparison) -> String {
    if sc.paired {
        return format!(
            "paired by seed: seeds {} have the same simulation keys in both reports, so each \
             seed ran the same laps and its change is the recognizer's alone",
            seeds(&sc.seeds)
        );
    }
    let changed: Vec<String> = sc
        .changed_inputs
        .iter()
        .map(|c| format!("the {} file {} differs", c.role, c.name))
        .collect();
    let changed = if changed.is_empty() {
        String::new()
    } else {
        format!(" ({})", changed.join(", "))
    };
    format!(
        "not paired: the simulation keys differ at seeds {}{changed}, so the laps are not the \
         same and a seed means nothing to the other side; the two sets of seeds are \
         compared as two samples (Mann–Whitney), which needs a larger change to be sure",
        seeds(&sc.differing_seeds),
    )
}

/// What of scenario `label` was not compared, and why, in words.
pub fn not_compared_words(label: &str, n: &NotCompared) -> String {
    match n {
        NotCompared::FailedSeeds { seeds: s } => {
            format!(
                "{label}: seeds {} failed in the new run, not compared",
                seeds(s)
            )
        }
        NotCompared::SubjectNotInBaseline { subject } => {
            format!("{label}/{subject}: not in every seed of the baseline, not compared")
        }
        NotCompared::NoFigure { subject, metric } => format!(
            "{label}/{subject}/{}: no seed has the figure on both sides (no matches)",
            metric.name()
        ),
    }
}

/// The closing line: `1 regression, 0 improvements, 13 no change`.
pub fn closing_line(c: &Comparison) -> String {
    let r = c.count(Decision::Regression);
    let i = c.count(Decision::Improvement);
    let same = c.metrics().count() - r - i;
    format!(
        "{r} regression{}, {i} improvement{}, {same} no change",
        if r == 1 { "" } else { "s" },
        if i == 1 { "" } else { "s" }
    )
}

/// The baseline's build in words: `0.1.0 at commit …`.
fn base_build(c: &Comparison) -> String {
    format!("{} at commit {}", c.base_version, c.base_commit)
}

/// The test's p-values, `p(worse) 0.002, p(better) 0.99`, or why there is none.
fn test_words(m: &MetricComparison) -> String {
    let p = |x: Option<f64>| x.map_or("–".to_string(), |p| format!("{p:.3}"));
    format!(
        "{}: p(worse beyond tolerance) {}, p(better beyond it) {}",
        basis_words(m),
        p(m.p_worse),
        p(m.p_better)
    )
}

/// What the tolerance is, in words: `max_drop 0.01` or `max_slowdown ×1.50`.
fn tolerance(m: &MetricComparison) -> String {
    if m.is_time() {
        format!("max_slowdown ×{:.2}", m.tolerance)
    } else {
        format!("max_drop {}", m.tolerance)
    }
}

/// One metric's line: decision, name, mean and worst change, seeds that got worse, the test.
pub fn metric_line(m: &MetricComparison) -> String {
    let mut s = format!(
        "{} {}: mean {} → {} ({}), worst {} (seed {}) → {} (seed {}) ({})",
        decision_name(m.decision),
        m.name(),
        value(m, m.base_mean),
        value(m, m.new_mean),
        change(m, m.mean_change),
        value(m, m.base_worst),
        m.base_worst_seed,
        value(m, m.new_worst),
        m.new_worst_seed,
        change(m, m.worst_change),
    );
    if m.decision == Decision::Identical {
        return s;
    }
    if m.decision == Decision::NoChange && m.beyond_seeds.is_empty() && m.paired {
        let _ = write!(s, "; within {}", tolerance(m));
        return s;
    }
    let _ = write!(s, "; {}; {}", seeds_against_tolerance(m), test_words(m));
    s
}

/// Paired, how many seeds got worse and which went beyond the tolerance; unpaired, how many
/// seeds were held against it.
fn seeds_against_tolerance(m: &MetricComparison) -> String {
    if m.paired {
        format!(
            "worse at {} of {} seeds {}, beyond {} at {}",
            m.worse_seeds.len(),
            m.seeds.len(),
            seeds(&m.worse_seeds),
            tolerance(m),
            seeds(&m.beyond_seeds)
        )
    } else {
        format!("{} against {}", m.seeds.len(), tolerance(m))
    }
}

/// The commands reproducing the worst seed of both sides: paired, the seed that got most
/// worse; unpaired, each side's worst seed.
pub fn reproduce_lines(sc: &ScenarioComparison, m: &MetricComparison, commit: &str) -> Vec<String> {
    let (new_seed, base_seed) = match m.most_worse_seed {
        Some(s) if m.paired => (s, s),
        _ => (m.new_worst_seed, m.base_worst_seed),
    };
    let (new, _) = sc.reproduce(new_seed, commit);
    let (_, base) = sc.reproduce(base_seed, commit);
    vec![
        format!("  reproduce new seed {new_seed}: {new}"),
        format!("  reproduce baseline seed {base_seed}: {base}"),
    ]
}

/// The terminal text: the baseline, per scenario how seeds pair, every metric that moved (and
/// how many did not), the reproducing commands of each regression, and the closing line.
pub fn text(c: &Comparison) -> String {
    let mut out = format!(
        "compared with the baseline {} ({})\n",
        c.base,
        base_build(c)
    );
    for sc in &c.scenarios {
        scenario_text(sc, &c.base_commit, &mut out);
    }
    let _ = writeln!(out, "vs baseline: {}", closing_line(c));
    out
}

/// One scenario's part of [`text`]: pairing, moved metrics (with commands for regressions),
/// identical ones counted, the metrics not compared.
fn scenario_text(sc: &ScenarioComparison, base_commit: &str, out: &mut String) {
    let _ = writeln!(out, "{}: {}", sc.label, pairing_words(sc));
    let mut quiet = 0;
    for m in &sc.metrics {
        if m.decision == Decision::Identical {
            quiet += 1;
            continue;
        }
        let _ = writeln!(out, "{}", metric_line(m));
        if m.decision == Decision::Regression {
            for l in reproduce_lines(sc, m, base_commit) {
                let _ = writeln!(out, "{l}");
            }
        }
    }
    if quiet > 0 {
        let _ = writeln!(
            out,
            "{}: {quiet} metric{} identical at every seed",
            sc.label,
            if quiet == 1 { "" } else { "s" }
        );
    }
    for n in &sc.not_compared {
        let _ = writeln!(out, "note: {}", not_compared_words(&sc.label, n));
    }
}

/// The Markdown section: per scenario its pairing and a table of every metric that moved
/// (both ways), regressions first; identical metrics counted below the table.
pub fn markdown(c: &Comparison) -> String {
    let mut out = format!(
        "# placewords vs baseline\n\nBaseline `{}` ({}): {}\n",
        c.base,
        base_build(c),
        closing_line(c)
    );
    for sc in &c.scenarios {
        let _ = writeln!(
            out,
            "\n## {} (`{}`)\n\n{}\n",
            sc.label,
            sc.file,
            pairing_words(sc)
        );
        let mut moved: Vec<&MetricComparison> = sc
            .metrics
            .iter()
            .filter(|m| m.decision != Decision::Identical)
            .collect();
        let rank = |d: Decision| match d {
            Decision::Regression => 0,
            Decision::Improvement => 1,
            _ => 2,
        };
        moved.sort_by_key(|m| rank(m.decision));
        if !moved.is_empty() {
            out.push_str(
                "| test case | baseline mean | new mean | mean change | worst change | \
                 seeds worse | p (worse) | decision |\n|---|---|---|---|---|---|---|---|\n",
            );
        }
        for m in &moved {
            let worse = if m.paired {
                format!("{} of {}", m.worse_seeds.len(), m.seeds.len())
            } else {
                "unpaired".into()
            };
            let p = m.p_worse.map_or("–".into(), |p| format!("{p:.3}"));
            let decision = match m.decision {
                Decision::Regression => "**REGRESSION**".to_string(),
                d => decision_name(d).to_string(),
            };
            let _ = writeln!(
                out,
                "| `{}` | {} | {} | {} | {} | {worse} | {p} | {decision} |",
                m.name(),
                value(m, m.base_mean),
                value(m, m.new_mean),
                change(m, m.mean_change),
                change(m, m.worst_change),
            );
        }
        let same = sc.metrics.len() - moved.len();
        if same > 0 {
            let _ = writeln!(out, "\n{same} metric(s) identical at every seed.");
        }
        for n in &sc.not_compared {
            let _ = writeln!(out, "\n- {}", not_compared_words(&sc.label, n));
        }
    }
    out
}

/// The `<testsuite>` elements of the comparison: one per scenario (`B vs baseline`), one test
/// case per compared metric, a `<failure>` for a regression. Returns (tests, failures, XML).
pub fn junit_suites(c: &Comparison) -> (usize, usize, String) {
    let mut x = String::new();
    let (mut tests, mut failures) = (0, 0);
    for sc in &c.scenarios {
        let fails = sc
            .metrics
            .iter()
            .filter(|m| m.decision == Decision::Regression)
            .count();
        tests += sc.metrics.len();
        failures += fails;
        let _ = writeln!(
            x,
            "  <testsuite name=\"{} vs baseline\" tests=\"{}\" failures=\"{fails}\" errors=\"0\" \
             skipped=\"0\" time=\"0.000\">",
            escape(&sc.label),
            sc.metrics.len()
        );
        for m in &sc.metrics {
            let _ = writeln!(
                x,
                "    <testcase name=\"{}\" classname=\"{}\" file=\"{}\" time=\"0.000\">\n      \
                 <properties>",
                escape(&m.name()),
                escape(&sc.file),
                escape(&sc.file)
            );
            let props = [
                ("baseline", c.base.clone()),
                ("paired", m.paired.to_string()),
                ("baseline_mean", value(m, m.base_mean)),
                ("new_mean", value(m, m.new_mean)),
                ("mean_change", change(m, m.mean_change)),
                ("worst_change", change(m, m.worst_change)),
                ("seeds_worse", seeds(&m.worse_seeds)),
                ("tolerance", tolerance(m)),
                (
                    "p_worse",
                    m.p_worse.map_or("none".into(), |p| format!("{p:.4}")),
                ),
                ("decision", decision_name(m.decision).to_string()),
            ];
            for (k, v) in props {
                let _ = writeln!(
                    x,
                    "        <property name=\"{k}\" value=\"{}\"/>",
                    escape(&v)
                );
            }
            x.push_str("      </properties>\n");
            if m.decision == Decision::Regression {
                let mut text = metric_line(m);
                for l in reproduce_lines(sc, m, &c.base_commit) {
                    text.push('\n');
                    text.push_str(l.trim());
                }
                let _ = writeln!(
                    x,
                    "      <failure message=\"{}\" type=\"regression\">{}</failure>",
                    escape(&metric_line(m)),
                    escape(&text)
                );
            }
            x.push_str("    </testcase>\n");
        }
        x.push_str("  </testsuite>\n");
    }
    (tests, failures, x)
}

/// A JUnit document of the comparison alone (`placewords compare --junit`).
pub fn junit_document(c: &Comparison) -> String {
    let (tests, failures, suites) = junit_suites(c);
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"placewords compare\" \
         tests=\"{tests}\" failures=\"{failures}\" errors=\"0\" time=\"0.000\">\n{suites}\
         </testsuites>\n"
    )
}

/// GitHub Actions `::error` workflow commands, one per regression, on its scenario file.
pub fn github_annotations(c: &Comparison) -> Vec<String> {
    use crate::report::suite::{gh_data, gh_property};
    let mut out = Vec::new();
    for sc in &c.scenarios {
        for m in sc
            .metrics
            .iter()
            .filter(|m| m.decision == Decision::Regression)
        {
            let mut text = metric_line(m);
            for l in reproduce_lines(sc, m, &c.base_commit) {
                text.push('\n');
                text.push_str(l.trim());
            }
            out.push(format!(
                "::error file={},title={}::{}",
                gh_property(&sc.file),
                gh_property(&m.name()),
                gh_data(&text)
            ));
        }
    }
    out
}

/// The `--json` form of a comparison: the decisions, the closing line and the exit code.
pub fn json(c: &Comparison) -> String {
    #[derive(serde::Serialize)]
    struct J<'a> {
        line: String,
        exit_code: u8,
        comparison: &'a Comparison,
    }
    serde_json::to_string_pretty(&J {
        line: closing_line(c),
        exit_code: c.exit_code(),
        comparison: c,
    })
    .expect("a comparison always serializes")
}
