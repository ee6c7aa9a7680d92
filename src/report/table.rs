//! Tables from reports: a plain-text table for the terminal, and the paper's Table I in Markdown.

use crate::eval::ranking::RankingScores;
use crate::eval::scores::{Report, Scores, SubjectReport};
use crate::place::Direction;
use std::fmt::Write;

/// Rows of a terminal table, one per subject: (label, scores).
fn rows(report: &Report) -> Vec<(String, &Scores)> {
    report
        .subjects
        .iter()
        .map(|s| (s.label(), &s.scores))
        .collect()
}

/// `rows` with, under each row that has opposite revisits or matches, a row per direction
/// (marked `true`: one direction's row of a subject).
fn rows_with_directions(report: &Report) -> Vec<(String, Scores, bool)> {
    let mut out = Vec::new();
    for (label, s) in rows(report) {
        out.push((label, s.clone(), false));
        if s.has_opposite() {
            out.push(("  same".to_string(), s.of_direction(Direction::Same), true));
            out.push((
                "  opposite".to_string(),
                s.of_direction(Direction::Opposite),
                true,
            ));
        }
    }
    out
}

/// Left-aligned first column, right-aligned others, two spaces apart.
pub(crate) fn render(header: &[&str], body: &[Vec<String>]) -> String {
    let width = column_widths(header, body);
    let mut out = String::new();
    let line = |cells: Vec<&str>, out: &mut String| {
        let mut s = String::new();
        for (i, c) in cells.iter().enumerate() {
            let pad = width[i] - c.chars().count();
            if i == 0 {
                s.push_str(c);
                s.push_str(&" ".repeat(pad));
            } else {
                s.push_str("  ");
                s.push_str(&" ".repeat(pad));
                s.push_str(c);
            }
        }
        out.push_str(s.trim_end());
        out.push('\n');
    };
    line(header.to_vec(), &mut out);
    let rule: Vec<String> = width.iter().map(|w| "-".repeat(*w)).collect();
    line(rule.iter().map(|s| s.as_str()).collect(), &mut out);
    for r in body {
        line(r.iter().map(|s| s.as_str()).collect(), &mut out);
    }
    out
}

/// The width of each column: its widest cell, header included, in characters.
fn column_widths(header: &[&str], body: &[Vec<String>]) -> Vec<usize> {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in body {
        for (i, c) in r.iter().enumerate() {
            width[i] = width[i].max(c.chars().count());
        }
    }
    width
}

/// The terminal summary of one report: what was run and how it was judged, one headline per
/// subject (the paper's precision and recall, with what they count), the main table with a
/// legend line per column, the other recalls in a block of their own, the notes, then the
/// figures by radius and by door configuration per subject.
pub fn text_table(report: &Report) -> String {
    let mut out = header(report);
    headlines(report, &mut out);
    main_table(report, &mut out);
    other_recalls(report, &mut out);
    ranking(report, &mut out);
    notes(report, &mut out);
    breakdowns(report, &mut out);
    out
}

/// What was run (a scenario's laps, or a real log's scans and metres) and the ground-truth rule.
fn header(report: &Report) -> String {
    let mut out = String::new();
    match &report.log {
        Some(log) => {
            let _ = writeln!(
                out,
                "log {}  noise seed {}  {} scans over {:.0} m of travel",
                report.scenario, report.seed, log.scans, log.travel_m
            );
        }
        None => {
            let _ = writeln!(
                out,
                "scenario {}  seed {}  {} laps  (simulated in {:.2} CPU s per lap)",
                report.scenario, report.seed, report.laps, report.simulate_seconds_per_lap
            );
        }
    }
    truth_rule(report, &mut out);
    out
}

/// The ground-truth rule the report was counted with, wrapped, and a blank line.
fn truth_rule(report: &Report, out: &mut String) {
    let e = &report.evaluation;
    let truth = format!(
        "ground truth: an observation has a revisit when an earlier one, at least {} m of true \
         travel before, lies within {} m facing within {}° (the same way, or the opposite way); \
         {} observations have one. A pair the recognizer claims is correct within {} m.",
        e.min_gap_m, e.tp_radius_m, e.heading_tolerance_deg, report.revisits, e.tp_radius_m
    );
    for l in textwrap::wrap(&truth, TEXT_WIDTH) {
        let _ = writeln!(out, "{l}");
    }
    out.push('\n');
}

/// The width prose in the terminal summary is wrapped to, characters.
const TEXT_WIDTH: usize = 100;

/// One line per subject: the two figures of the paper's Table I, each with what it counts.
/// The paper counts recall over the revisits driven the same way (its search runs one way).
fn headlines(report: &Report, out: &mut String) {
    let _ = writeln!(
        out,
        "as the paper's Table I reports them (its recall counts the revisits driven the same way):"
    );
    let cells = headline_cells(report);
    let width = |i: usize| {
        cells
            .iter()
            .map(|c| c[i].chars().count())
            .max()
            .unwrap_or(0)
    };
    let (w0, w1) = (width(0), width(1));
    for [label, precision, recall] in &cells {
        let _ = writeln!(
            out,
            "  {label}{}  {precision}{}  {recall}",
            " ".repeat(w0 - label.chars().count()),
            " ".repeat(w1 - precision.chars().count())
        );
    }
    out.push('\n');
}

/// Per subject: its label, precision and same-direction recall, each with what it counts.
fn headline_cells(report: &Report) -> Vec<[String; 3]> {
    report
        .subjects
        .iter()
        .map(|sub| {
            let (s, same) = (&sub.scores, &sub.scores.directions.same);
            let precision = if s.no_pairs {
                "no matches".to_string()
            } else {
                format!(
                    "precision {:.3} ({} of {} pairs)",
                    s.precision, s.correct_pairs, s.pairs
                )
            };
            let recall = format!(
                "recall {:.3} ({} of {} revisits)",
                same.recall, same.recalled, same.revisits
            );
            [sub.label(), precision, recall]
        })
        .collect()
}

/// The main table, a row per subject (and per direction where the other way has revisits or
/// matches), then a legend line per column.
fn main_table(report: &Report, out: &mut String) {
    let body: Vec<Vec<String>> = rows_with_directions(report)
        .into_iter()
        .map(|(label, s, direction)| {
            // A direction's row has no time of its own: one recognizer matched both ways, and
            // its time repeated on each row would add up to more than it took.
            let time = if direction {
                String::new()
            } else {
                format!("{:.3}", s.recognize_seconds_per_lap)
            };
            vec![
                label,
                fmt_p(&s),
                format!("{:.3}", s.recall),
                s.pairs.to_string(),
                s.matches.to_string(),
                s.revisits.to_string(),
                time,
            ]
        })
        .collect();
    // A real log is one run, not laps: its time is the whole log's.
    let (time, time_meaning) = match report.log {
        Some(_) => ("CPU s", "the recognizer's CPU seconds over the whole log"),
        None => (
            "CPU s/lap",
            "the recognizer's CPU seconds per lap (its own thread's: subjects run side by side, \
             so theirs may add up to more than the wall time)",
        ),
    };
    let split = if report.subjects.iter().any(|s| s.scores.has_opposite()) {
        " (both directions; the same and opposite rows count each direction's revisits, and \
         an observation with a revisit both ways is in both, so their revisits can add up to \
         more; their pairs add up)"
    } else {
        ""
    };
    let recall = format!(
        "observations with a revisit that are the newer side of a correct pair ÷ observations \
         with a revisit{split}"
    );
    let header = [
        "subject [τ]",
        "precision",
        "recall",
        "pairs",
        "matches",
        "revisits",
        time,
    ];
    out.push_str(&render(&header, &body));
    let legend = [
        (
            "subject [τ]",
            "the recognizer; words-N is the paper's at N levels, τ the fewest matching words a \
             chain needs at each level",
        ),
        ("precision", "correct pairs ÷ pairs"),
        ("recall", recall.as_str()),
        (
            "pairs",
            "(newer, earlier) observation pairs the matches claim, each once: one observation \
             can be in many",
        ),
        (
            "matches",
            "the matches the recognizer reported (a chain of words for words-N)",
        ),
        (
            "revisits",
            "observations that have a revisit: a count of observations, not pairs",
        ),
        (time, time_meaning),
    ];
    legend_lines(&legend, out);
}

/// `  key   meaning` lines, the keys aligned and each meaning wrapped under itself.
fn legend_lines(legend: &[(&str, &str)], out: &mut String) {
    let width = legend
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let indent = " ".repeat(width + 4);
    for (k, v) in legend {
        let first = format!("  {k}{}  ", " ".repeat(width - k.chars().count()));
        let opts = textwrap::Options::new(TEXT_WIDTH)
            .initial_indent(&first)
            .subsequent_indent(&indent);
        for l in textwrap::wrap(v, opts) {
            let _ = writeln!(out, "{l}");
        }
    }
}

/// The recalls beside the paper's, and match precision, in a block of their own.
fn other_recalls(report: &Report, out: &mut String) {
    let _ = writeln!(out, "\nother recalls");
    let body = other_recall_rows(report);
    out.push_str(&render(
        &["subject [τ]", "visit R", "pair R", "match P"],
        &body,
    ));
    legend_lines(
        &[
            (
                "visit R",
                "(observation, earlier lap through the same spot) combinations recognized ÷ all \
                 such: rewards matching across door changes",
            ),
            (
                "pair R",
                "correct pairs ÷ every (observation, earlier observation) pair the truth allows",
            ),
            (
                "match P",
                "matches most of whose pairs are correct ÷ matches",
            ),
        ],
        out,
    );
}

/// A row of [`other_recalls`] per subject and direction shown.
fn other_recall_rows(report: &Report) -> Vec<Vec<String>> {
    rows_with_directions(report)
        .into_iter()
        .map(|(label, s, _)| {
            vec![
                label,
                format!("{:.3}", s.visit_recall),
                format!("{:.3}", s.pair_recall),
                format!("{:.3}", s.match_precision),
            ]
        })
        .collect()
}

/// The field's figures over each subject's match score (`eval::ranking`), in a block of their
/// own, with the ground-truth rule they were counted with.
fn ranking(report: &Report, out: &mut String) {
    let ranked: Vec<(String, &RankingScores)> = rows(report)
        .into_iter()
        .filter_map(|(label, s)| Some((label, s.ranking.as_ref()?)))
        .collect();
    let Some((_, first)) = ranked.first() else {
        return;
    };
    let head = format!(
        "over the match score, per query observation (right answer: a true revisit {})",
        crate::report::explain::truth_rule(&first.rule)
    );
    out.push('\n');
    for l in textwrap::wrap(&head, TEXT_WIDTH) {
        let _ = writeln!(out, "{l}");
    }
    let body: Vec<Vec<String>> = ranked
        .iter()
        .map(|(label, r)| {
            vec![
                label.clone(),
                format!("{:.3}", r.average_precision),
                format!("{:.3}", r.max_f1),
                r.max_f1_threshold.map_or("–".into(), |t| format!("{t:.2}")),
                format!("{:.3}", r.recall_at_100_precision),
                format!("{:.3}", r.recall_at_99_precision),
                format!("{:.0}", r.queries_per_cpu_second),
            ]
        })
        .collect();
    out.push_str(&render(
        &[
            "subject [τ]",
            "AP",
            "max F1",
            "at t",
            "R@P100",
            "R@P99",
            "queries/CPU s",
        ],
        &body,
    ));
    legend_lines(
        &[
            (
                "AP",
                "average precision, scikit-learn's step-wise sum Σ (Rn − Rn−1)·Pn over the score \
                 thresholds; a query's answer is its best-scoring pair, recall counts the queries \
                 with a revisit",
            ),
            ("max F1", "the highest F1 over the thresholds, at score t"),
            (
                "R@P100",
                "the highest recall at precision 1 (R@P99: at precision ≥ 0.99)",
            ),
            (
                "queries/CPU s",
                "observations the recognizer made per second of its CPU",
            ),
        ],
        out,
    );
}

/// What each level adds, why a subject has no pair, the recognizers' notes, and what
/// verification turned down.
fn notes(report: &Report, out: &mut String) {
    let mut lines: Vec<String> = Vec::new();
    for l in &report.subjects {
        if let Some(g) = &l.only_here {
            lines.push(format!(
                "{} claims {} pair(s) that {} does not ({} correct)",
                l.name,
                g.pairs,
                crate::spec::evaluation::words_subject_name(g.than_levels),
                g.correct_pairs
            ));
        }
    }
    for (label, s) in rows(report) {
        if let Some(why) = &s.no_pairs_reason {
            lines.push(format!("{label}: no matches: {why}"));
        }
    }
    // Every configuration sees the same scans; say it once, where the reason did not.
    for (_, s) in rows(report) {
        if s.no_pairs_reason.is_none() {
            for n in &s.notes {
                let n = format!("note: {n}");
                if !lines.contains(&n) {
                    lines.push(n);
                }
            }
        }
    }
    // Where there are pairs (the reason says it otherwise): what verification turned down,
    // and why a direction with revisits got none.
    for (label, s) in rows(report) {
        if let (None, Some(r)) = (&s.no_pairs_reason, &s.rejected_candidates) {
            lines.push(format!(
                "{label}: {}",
                super::explain::turned_down_sentence(r)
            ));
        }
        for d in &s.direction_no_pairs_reasons {
            let way = d.direction.name();
            lines.push(format!("{label} {way}: no matches: {}", d.reason));
        }
    }
    if !lines.is_empty() {
        out.push('\n');
        let opts = textwrap::Options::new(TEXT_WIDTH).subsequent_indent("    ");
        for l in lines {
            for w in textwrap::wrap(&l, &opts) {
                let _ = writeln!(out, "{w}");
            }
        }
    }
}

/// Per subject: the figures at each sensitivity radius, and (for simulated runs) per door
/// configuration of the newer observation's lap.
fn breakdowns(report: &Report, out: &mut String) {
    let simulated = report.log.is_none();
    let ratio = |x: f64, of: usize| {
        if of == 0 {
            "–".to_string()
        } else {
            format!("{x:.3}")
        }
    };
    let mut any = false;
    for (label, s) in rows(report) {
        let doors = if simulated { &s.door_configs[..] } else { &[] };
        if s.sensitivity.is_empty() && doors.is_empty() {
            continue;
        }
        any = true;
        let _ = writeln!(out, "\n{label}");
        let mut body: Vec<Vec<String>> = s
            .sensitivity
            .iter()
            .map(|m| {
                vec![
                    format!("correct within {} m", m.radius_m),
                    ratio(m.precision, m.pairs),
                    ratio(m.recall, m.revisits),
                    m.pairs.to_string(),
                    m.revisits.to_string(),
                ]
            })
            .collect();
        body.extend(doors.iter().map(|d| {
            let laps = if d.laps == 1 { "lap" } else { "laps" };
            vec![
                format!("doors {} ({} {laps})", d.door_config, d.laps),
                ratio(d.metrics.precision, d.metrics.pairs),
                ratio(d.metrics.recall, d.metrics.revisits),
                d.metrics.pairs.to_string(),
                d.metrics.revisits.to_string(),
            ]
        }));
        out.push_str(&render(
            &[
                "  by radius and doors",
                "precision",
                "recall",
                "pairs",
                "revisits",
            ],
            &body
                .into_iter()
                .map(|mut r| {
                    r[0] = format!("  {}", r[0]);
                    r
                })
                .collect::<Vec<_>>(),
        ));
    }
    if any {
        let doors = if simulated {
            "; doors X: the pairs and revisits whose newer observation was made in a lap with \
             door configuration X"
        } else {
            ""
        };
        let text = format!(
            "correct within R m: the figures with a pair (and a revisit) counted within R m \
             instead of {} m{doors}; – where nothing was there to count",
            report.evaluation.tp_radius_m
        );
        out.push('\n');
        let opts = textwrap::Options::new(TEXT_WIDTH)
            .initial_indent("  ")
            .subsequent_indent("  ");
        for l in textwrap::wrap(&text, opts) {
            let _ = writeln!(out, "{l}");
        }
    }
}

fn fmt_p(s: &Scores) -> String {
    if s.no_pairs {
        "no matches".to_string()
    } else {
        format!("{:.3}", s.precision)
    }
}

/// The paper's Table I for several scenarios, in Markdown: a row per subject (words-1, words-2,
/// words-3, icp, …)
/// (those present in any report), per scenario a "P – R" column and a "CPU s/lap" column.
pub fn markdown_table_i(reports: &[Report]) -> String {
    markdown_by_level(reports, &["P – R", "CPU s/lap"], |s, direction| {
        // A direction's row has no time of its own (one recognizer matched both ways).
        let time = if direction {
            String::new()
        } else {
            format!("{:.2}", s.recognize_seconds_per_lap)
        };
        vec![format!("{} – {:.3}", fmt_p(s), s.recall), time]
    })
}

/// Recall at 99 % precision and max F1 over the match score per subject and scenario
/// (`eval::ranking`), in Markdown; – where a subject has no ranking.
pub fn markdown_ranking(reports: &[Report]) -> String {
    markdown_by_level(reports, &["R@P99", "max F1"], |s, _| match &s.ranking {
        Some(r) => vec![
            format!("{:.3}", r.recall_at_99_precision),
            format!("{:.3}", r.max_f1),
        ],
        None => vec!["–".into(), "–".into()],
    })
}

/// Visit recall and pair recall per level row and scenario (the companions of Table I that
/// reward matching across door changes and count every pair that could be found), in Markdown.
pub fn markdown_visit_recall(reports: &[Report]) -> String {
    markdown_by_level(reports, &["visit R", "pair R"], |s, _| {
        vec![
            format!("{:.3}", s.visit_recall),
            format!("{:.3}", s.pair_recall),
        ]
    })
}

/// A Markdown table with a row per subject found in any report (words subjects by levels, then
/// the others) and, per scenario, one column per entry of `columns`, filled by `cells` (told
/// whether the row is one direction's of a subject).
fn markdown_by_level(
    reports: &[Report],
    columns: &[&str],
    cells: impl Fn(&Scores, bool) -> Vec<String>,
) -> String {
    let rows = subject_names(reports);
    let mut out = String::from("| subject |");
    for r in reports {
        for c in columns {
            let _ = write!(out, " {} {c} |", r.scenario);
        }
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(reports.len() * columns.len()));
    out.push('\n');
    let mut line = |label: String, direction: bool, scores: &dyn Fn(&Report) -> Option<Scores>| {
        let _ = write!(out, "| {label} |");
        for r in reports {
            match scores(r) {
                Some(s) => cells(&s, direction).iter().for_each(|c| {
                    let _ = write!(out, " {c} |");
                }),
                None => out.push_str(&" – |".repeat(columns.len())),
            }
        }
        out.push('\n');
    };
    for name in rows {
        fn of<'r>(r: &'r Report, name: &str) -> Option<&'r Scores> {
            r.subject(name).map(|s| &s.scores)
        }
        line(name.clone(), false, &|r| of(r, &name).cloned());
        if reports
            .iter()
            .any(|r| of(r, &name).is_some_and(Scores::has_opposite))
        {
            for d in Direction::BOTH {
                line(format!("{name} {}", d.name()), true, &|r| {
                    of(r, &name).map(|s| s.of_direction(d))
                });
            }
        }
    }
    out
}

/// The subjects of any of `reports`, words subjects by levels first, then the others in the
/// order first seen.
fn subject_names(reports: &[Report]) -> Vec<String> {
    let mut seen: Vec<&SubjectReport> = Vec::new();
    for s in reports.iter().flat_map(|r| &r.subjects) {
        if !seen.iter().any(|x| x.name == s.name) {
            seen.push(s);
        }
    }
    seen.sort_by_key(|s| (s.levels.is_none(), s.levels.unwrap_or(0)));
    seen.into_iter().map(|s| s.name.clone()).collect()
}

/// Thresholds per words subject of Table I, as a Markdown note (`words-1: [6]; words-2: [6,
/// 9]`) taken from the first report that has each.
pub fn thresholds_note(reports: &[Report]) -> String {
    let mut seen: Vec<(usize, &str, &[usize])> = Vec::new();
    for s in reports.iter().flat_map(|r| &r.subjects) {
        if let Some(lv) = s.levels
            && !seen.iter().any(|x| x.0 == lv)
        {
            seen.push((lv, &s.name, &s.thresholds));
        }
    }
    seen.sort_by_key(|x| x.0);
    let parts: Vec<String> = seen
        .iter()
        .map(|(_, name, th)| format!("{name}: {th:?}"))
        .collect();
    format!(
        "Minimum n-gram sizes τ per level (words-N: the paper's recognizer with N levels): {}.",
        parts.join("; ")
    )
}

/// One line per PR curve: its max-F1 point and its best recall at precision ≥ 0.9.
pub fn curves_table(curves: &[crate::eval::sweep::PrCurve]) -> String {
    let floor = crate::eval::sweep::PRECISION_FLOOR;
    let body: Vec<Vec<String>> = curves
        .iter()
        .map(|c| {
            let (f1, f1_at) = match &c.max_f1 {
                Some(p) => (
                    format!("{:.3}", p.f1),
                    format!("t={} P {:.3} R {:.3}", p.threshold, p.precision, p.recall),
                ),
                None => ("-".into(), "-".into()),
            };
            let best = match &c.best_recall_at_precision {
                Some(p) => format!("{:.3} (t={}, P {:.3})", p.recall, p.threshold, p.precision),
                None => "-".into(),
            };
            vec![c.label.clone(), f1, f1_at, best]
        })
        .collect();
    let best_header = format!("best R at P≥{floor}");
    render(&["curve", "max F1", "at", &best_header], &body)
}

/// One line per subject of a sweep: its figures over the match score (`eval::ranking`).
pub fn score_curves_table(subjects: &[crate::eval::ranking::SubjectRanking]) -> String {
    let body: Vec<Vec<String>> = subjects
        .iter()
        .map(|s| {
            let r = &s.ranking;
            vec![
                s.name.clone(),
                format!("{:.3}", r.average_precision),
                format!("{:.3}", r.max_f1),
                r.max_f1_threshold.map_or("–".into(), |t| format!("{t:.2}")),
                format!("{:.3}", r.recall_at_100_precision),
                format!("{:.3}", r.recall_at_99_precision),
            ]
        })
        .collect();
    let rule = subjects.first().map_or(String::new(), |s| {
        crate::report::explain::truth_rule(&s.ranking.rule)
    });
    format!(
        "over the match score, per query observation (right answer: a true revisit {rule})\n{}",
        render(
            &["subject", "AP", "max F1", "at t", "R@P100", "R@P99"],
            &body
        )
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;

    #[test]
    fn markdown_table_has_a_row_per_configuration_and_columns_per_scenario() {
        let a = sample("A", [0.935, 0.91, 0.905], [0.103, 0.238, 0.346]);
        let b = sample("B", [0.931, 0.903, 0.89], [0.106, 0.274, 0.308]);
        let md = markdown_table_i(&[a, b]);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), 6, "{md}");
        assert_eq!(
            lines[0],
            "| subject | A P – R | A CPU s/lap | B P – R | B CPU s/lap |"
        );
        assert_eq!(
            lines[2],
            "| words-1 | 0.935 – 0.103 | 0.50 | 0.931 – 0.106 | 0.50 |"
        );
        assert!(lines[5].starts_with("| icp | 0.050 – 0.040 | 9.00 |"));
    }

    #[test]
    fn curves_table_has_a_line_per_curve() {
        use crate::eval::metrics::Metrics;
        use crate::eval::sweep::{GridPoint, SweepResult, pr_curves};
        let r = |l: usize, th: &[usize], p: f64, rc: f64| SweepResult {
            point: GridPoint::new(l, th),
            metrics: Metrics {
                precision: p,
                recall: rc,
                pairs: 1,
                ..Metrics::default()
            },
            recognize_seconds_per_lap: 0.0,
        };
        let c = pr_curves(&[r(1, &[5], 0.95, 0.1), r(2, &[6, 3], 0.5, 0.5)]);
        let t = curves_table(&c);
        assert_eq!(t.lines().count(), 4, "{t}");
        assert!(t.contains("0.100 (t=5, P 0.950)"), "{t}");
    }

    /// Where opposite revisits exist, the terminal table and Table I add a row per direction
    /// under the level row; without them, neither does.
    /// Steps too long to observe along their length are noted once when there are pairs (and
    /// are part of the reason when there are none).
    /// With pairs, each level's line says how many true revisits (and how many of those were
    /// recognized later all the same, and lost) and look-alikes verification turned down;
    /// without, its reason says it and the line is not repeated.
    #[test]
    fn turned_down_candidates_are_told_per_level() {
        let mut rep = sample("A", [0.9; 3], [0.2; 3]);
        assert!(!text_table(&rep).contains("verification turned down"));
        for l in rep.subjects.iter_mut().filter(|s| s.levels.is_some()) {
            l.scores.rejected_candidates = Some(crate::eval::scores::RejectedScores {
                sampled: 25,
                correct: 22,
                correct_recognized: 20,
                ..Default::default()
            });
        }
        rep.subjects[0].scores.no_pairs_reason = Some("every candidate was rejected".into());
        let t = text_table(&rep);
        assert_eq!(t.matches("verification turned down").count(), 2, "{t}");
        // The lines are wrapped to the table's width; the sentence is read unwrapped.
        let unwrapped = t.replace("\n    ", " ");
        assert!(
            unwrapped.contains(
                "verification turned down 22 true revisits (20 recognized later all the same, 2 \
                 lost) and 3 look-alikes (of 25 candidates sampled)"
            ),
            "{t}"
        );
    }

    #[test]
    fn long_steps_are_noted_once() {
        let mut rep = sample("A", [0.9; 3], [0.2; 3]);
        assert!(!text_table(&rep).contains("max_interpolation_m"));
        for l in &mut rep.subjects {
            let d = crate::recognizer::MatchDiagnostics {
                long_steps: 2,
                ..Default::default()
            };
            l.scores.notes = crate::place::Diagnostics::notes(&d);
        }
        let t = text_table(&rep);
        assert_eq!(t.matches("max_interpolation_m").count(), 1, "{t}");
        assert!(t.contains("note: 2 steps between scans were longer"), "{t}");
    }

    #[test]
    fn rows_per_direction_where_opposite_revisits_exist() {
        let plain = sample("A", [0.9; 3], [0.2; 3]);
        let direction_rows = |t: &str| t.lines().any(|l| l.starts_with("  opposite"));
        assert!(
            !direction_rows(&text_table(&plain)),
            "{}",
            text_table(&plain)
        );
        assert!(!text_table(&plain).contains("same and opposite rows"));
        assert!(!markdown_table_i(std::slice::from_ref(&plain)).contains("opposite"));
        let mut both = plain.clone();
        let s = &mut both.subjects[2].scores;
        s.directions.same.precision = 0.97;
        s.directions.opposite.revisits = 100;
        s.directions.opposite.pairs = 10;
        s.directions.opposite.precision = 0.8;
        let t = text_table(&both);
        let opposite = t.lines().find(|l| l.starts_with("  opposite")).unwrap();
        assert!(opposite.contains("0.800"), "{t}");
        // A direction's row repeats no time (the words-3 row has 1.500).
        assert!(
            t.lines()
                .any(|l| l.starts_with("words-3") && l.ends_with("1.500")),
            "{t}"
        );
        assert!(opposite.ends_with("100"), "{t}");
        // The rows do not split the revisits: one observation can have a revisit both ways.
        assert!(
            t.replace("\n               ", " ")
                .contains("a revisit both ways is in both"),
            "{t}"
        );
        assert!(
            t.lines()
                .any(|l| l.starts_with("  same") && l.contains("0.970")),
            "{t}"
        );
        let md = markdown_table_i(&[both]);
        assert!(md.contains("| words-3 same | 0.970 – "), "{md}");
        assert!(md.contains("| words-3 opposite | 0.800 – "), "{md}");
        let md_row = |label: &str| {
            md.lines()
                .find(|l| l.starts_with(label))
                .unwrap()
                .to_string()
        };
        assert!(md_row("| words-3 |").ends_with(" 1.50 |"), "{md}");
        assert!(md_row("| words-3 opposite |").ends_with("|  |"), "{md}");
    }

    /// Each subject leads with the paper's two figures and what they count; a real log's
    /// summary speaks of scans and metres, with no laps, door configurations or time per lap.
    #[test]
    fn headlines_and_a_real_logs_header() {
        let mut rep = sample("B", [0.9; 3], [0.2; 3]);
        for s in &mut rep.subjects {
            s.scores.correct_pairs = 90;
            s.scores.pairs = 100;
            s.scores.directions.same.recall = 0.25;
            s.scores.directions.same.recalled = 50;
            s.scores.directions.same.revisits = 200;
            s.scores.door_configs = vec![crate::eval::metrics::DoorConfigMetrics {
                door_config: "all-closed".into(),
                laps: 3,
                ..Default::default()
            }];
        }
        let t = text_table(&rep);
        let headline = t.lines().find(|l| l.starts_with("  words-3")).unwrap();
        assert!(
            headline.contains("precision 0.900 (90 of 100 pairs)"),
            "{t}"
        );
        assert!(
            headline.contains("recall 0.250 (50 of 200 revisits)"),
            "{t}"
        );
        // Per-lap times are CPU seconds, and the header says so.
        assert!(t.contains("40 laps") && t.contains("CPU s/lap"), "{t}");
        assert!(t.contains("doors all-closed (3 laps)"), "{t}");
        rep.log = Some(crate::eval::scores::LogSummary {
            scans: 910,
            travel_m: 500.4,
        });
        let t = text_table(&rep);
        assert!(
            t.starts_with("log B  noise seed 7  910 scans over 500 m"),
            "{t}"
        );
        for absent in ["laps", "doors", "s/lap", "simulated"] {
            assert!(
                !t.contains(absent),
                "`{absent}` in a real log's summary:\n{t}"
            );
        }
        assert!(t.contains("CPU s"), "{t}");
    }

    /// The figures over the match score get a block of their own in the terminal, with the
    /// ground-truth rule, and a Markdown table of recall at 99 % precision and max F1.
    #[test]
    fn ranking_figures_are_printed_with_their_truth_rule() {
        let mut rep = sample("B", [0.9; 3], [0.2; 3]);
        let r = crate::eval::ranking::curve(&[(7.0, true), (6.0, true), (5.0, false)], 4);
        rep.subjects[2].scores.ranking = Some(crate::eval::ranking::RankingScores {
            rule: crate::eval::ranking::TruthRule::of(&rep.evaluation),
            ..r
        });
        let t = text_table(&rep);
        assert!(
            t.contains("right answer: a true revisit within 1 m, 20 m of travel"),
            "{t}"
        );
        let row = t
            .lines()
            .find(|l| l.starts_with("words-3") && l.contains("0.500"))
            .unwrap();
        // AP 0.5, max F1 (P 1, R 0.5) 0.667 at t = 6, R@P100 0.5, R@P99 0.5.
        assert!(row.contains("0.667") && row.contains("6.00"), "{t}");
        let md = markdown_ranking(std::slice::from_ref(&rep));
        assert!(md.contains("| words-3 | 0.500 | 0.667 |"), "{md}");
        assert!(md.contains("| words-1 | – | – |"), "{md}");
    }

    #[test]
    fn text_table_lists_every_recognizer() {
        let t = text_table(&sample("B", [0.9; 3], [0.2; 3]));
        if std::env::var_os("PLACEWORDS_SHOW_TABLE").is_some() {
            eprintln!("{t}");
        }
        for needle in [
            "words-1 [6]",
            "words-2 [6, 9]",
            "words-3 [6, 9, 12]",
            "icp",
            "5000 observations have one",
        ] {
            assert!(t.contains(needle), "{needle} missing in\n{t}");
        }
    }
}
