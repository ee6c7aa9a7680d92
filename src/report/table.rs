//! Tables from reports: a plain-text table for the terminal, and the paper's Table I in Markdown.

use crate::eval::scores::{Report, Scores};
use crate::recognizer::Direction;
use std::fmt::Write;

/// Rows of a terminal table: (label, scores).
fn rows(report: &Report) -> Vec<(String, &Scores)> {
    let mut rows: Vec<(String, &Scores)> = report
        .levels
        .iter()
        .map(|l| {
            let th: Vec<String> = l.thresholds.iter().map(|t| t.to_string()).collect();
            // `score` knows no thresholds: its row is labelled by `--levels` alone.
            let label = if th.is_empty() {
                l.levels.to_string()
            } else {
                format!("{} [{}]", l.levels, th.join(", "))
            };
            (label, &l.scores)
        })
        .collect();
    if let Some(icp) = &report.icp {
        rows.push(("ICP".to_string(), &icp.scores));
    }
    rows
}

/// `rows` with, under each row that has opposite revisits or matches, a row per direction.
fn rows_with_directions(report: &Report) -> Vec<(String, Scores)> {
    let mut out = Vec::new();
    for (label, s) in rows(report) {
        out.push((label, s.clone()));
        if s.has_opposite() {
            out.push(("  same".to_string(), s.of_direction(Direction::Same)));
            out.push((
                "  opposite".to_string(),
                s.of_direction(Direction::Opposite),
            ));
        }
    }
    out
}

/// Left-aligned first column, right-aligned others, two spaces apart.
pub(crate) fn render(header: &[&str], body: &[Vec<String>]) -> String {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in body {
        for (i, c) in r.iter().enumerate() {
            width[i] = width[i].max(c.chars().count());
        }
    }
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

/// The terminal summary of one report: the main table, then sensitivity and door
/// configurations per recognizer.
pub fn text_table(report: &Report) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "scenario {}  seed {}  laps {}  revisits {}  simulation {:.2} s/lap",
        report.scenario, report.seed, report.laps, report.revisits, report.simulate_seconds_per_lap
    );
    let _ = writeln!(
        out,
        "a pair is correct within {} m; revisits need {} m of travel and {}° of heading\n",
        report.evaluation.tp_radius_m,
        report.evaluation.min_gap_m,
        report.evaluation.heading_tolerance_deg
    );
    let body: Vec<Vec<String>> = rows_with_directions(report)
        .into_iter()
        .map(|(label, s)| {
            vec![
                label,
                fmt_p(&s),
                format!("{:.3}", s.recall),
                format!("{:.3}", s.visit_recall),
                format!("{:.3}", s.pair_recall),
                format!("{:.3}", s.match_precision),
                s.pairs.to_string(),
                s.matches.to_string(),
                s.revisits.to_string(),
                format!("{:.3}", s.recognize_seconds_per_lap),
            ]
        })
        .collect();
    out.push_str(&render(
        &[
            "levels [τ]",
            "precision",
            "recall",
            "visit R",
            "pair R",
            "match P",
            "pairs",
            "matches",
            "revisits",
            "s/lap",
        ],
        &body,
    ));
    for l in &report.levels {
        if let Some(g) = &l.only_here {
            let _ = writeln!(
                out,
                "{} levels found {} pair(s) that {} level(s) did not ({} correct)",
                l.levels, g.pairs, g.than_levels, g.correct_pairs
            );
        }
    }
    for (label, s) in rows(report) {
        if let Some(why) = &s.no_pairs_reason {
            let _ = writeln!(out, "{label}: no matches: {why}");
        }
    }
    // Every configuration sees the same scans; say it once, where the reason did not.
    let long_steps = rows(report)
        .into_iter()
        .filter(|(_, s)| s.no_pairs_reason.is_none())
        .find_map(|(_, s)| s.diagnostics.as_ref().map(|d| d.long_steps))
        .filter(|&n| n > 0);
    if let Some(n) = long_steps {
        let _ = writeln!(
            out,
            "note: {} (raise it to observe them along their length)",
            crate::eval::scores::long_steps_sentence(n)
        );
    }
    // Where there are pairs (the reason says it otherwise): what verification turned down.
    for (label, s) in rows(report) {
        if let (None, Some(r)) = (&s.no_pairs_reason, &s.rejected_candidates) {
            let s = |n: usize| if n == 1 { "" } else { "s" };
            let alike = r.sampled - r.correct;
            let _ = writeln!(
                out,
                "{label}: verification turned down {} true revisit{} and {alike} look-alike{} \
                 (of {} candidate{} sampled)",
                r.correct,
                s(r.correct),
                s(alike),
                r.sampled,
                s(r.sampled)
            );
        }
    }
    for (label, s) in rows(report) {
        if s.sensitivity.is_empty() && s.door_configs.is_empty() {
            continue;
        }
        let _ = writeln!(out, "\n{label}");
        let mut body: Vec<Vec<String>> = s
            .sensitivity
            .iter()
            .map(|m| {
                vec![
                    format!("radius {} m", m.radius_m),
                    format!("{:.3}", m.precision),
                    format!("{:.3}", m.recall),
                    m.pairs.to_string(),
                    m.revisits.to_string(),
                ]
            })
            .collect();
        body.extend(s.door_configs.iter().map(|d| {
            vec![
                format!("doors {} ({} laps)", d.door_config, d.laps),
                format!("{:.3}", d.metrics.precision),
                format!("{:.3}", d.metrics.recall),
                d.metrics.pairs.to_string(),
                d.metrics.revisits.to_string(),
            ]
        }));
        out.push_str(&render(
            &["  breakdown", "precision", "recall", "pairs", "revisits"],
            &body
                .into_iter()
                .map(|mut r| {
                    r[0] = format!("  {}", r[0]);
                    r
                })
                .collect::<Vec<_>>(),
        ));
    }
    out
}

fn fmt_p(s: &Scores) -> String {
    if s.no_pairs {
        "no matches".to_string()
    } else {
        format!("{:.3}", s.precision)
    }
}

/// The paper's Table I for several scenarios, in Markdown: rows 1, 2 and 3 levels and ICP
/// (those present in any report), per scenario a "P – R" column and an "s/lap" column.
pub fn markdown_table_i(reports: &[Report]) -> String {
    markdown_by_level(reports, &["P – R", "s/lap"], |s| {
        vec![
            format!("{} – {:.3}", fmt_p(s), s.recall),
            format!("{:.2}", s.recognize_seconds_per_lap),
        ]
    })
}

/// Visit recall and pair recall per level row and scenario (the companions of Table I that
/// reward matching across door changes and count every pair that could be found), in Markdown.
pub fn markdown_visit_recall(reports: &[Report]) -> String {
    markdown_by_level(reports, &["visit R", "pair R"], |s| {
        vec![
            format!("{:.3}", s.visit_recall),
            format!("{:.3}", s.pair_recall),
        ]
    })
}

/// A Markdown table with a row per level configuration (and ICP when any report has it) and,
/// per scenario, one column per entry of `columns`, filled by `cells`.
fn markdown_by_level(
    reports: &[Report],
    columns: &[&str],
    cells: impl Fn(&Scores) -> Vec<String>,
) -> String {
    let mut rows: Vec<usize> = reports
        .iter()
        .flat_map(|r| r.levels.iter().map(|l| l.levels))
        .collect();
    rows.sort_unstable();
    rows.dedup();
    let mut out = String::from("| levels |");
    for r in reports {
        for c in columns {
            let _ = write!(out, " {} {c} |", r.scenario);
        }
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(reports.len() * columns.len()));
    out.push('\n');
    let mut line = |label: String, scores: &dyn Fn(&Report) -> Option<Scores>| {
        let _ = write!(out, "| {label} |");
        for r in reports {
            match scores(r) {
                Some(s) => cells(&s).iter().for_each(|c| {
                    let _ = write!(out, " {c} |");
                }),
                None => out.push_str(&" – |".repeat(columns.len())),
            }
        }
        out.push('\n');
    };
    for lv in rows {
        line(lv.to_string(), &|r| r.level(lv).map(|l| l.scores.clone()));
        fn level(r: &Report, lv: usize) -> Option<&Scores> {
            r.level(lv).map(|l| &l.scores)
        }
        if reports
            .iter()
            .any(|r| level(r, lv).is_some_and(Scores::has_opposite))
        {
            for d in Direction::BOTH {
                line(format!("{lv} {}", d.name()), &|r| {
                    level(r, lv).map(|s| s.of_direction(d))
                });
            }
        }
    }
    if reports.iter().any(|r| r.icp.is_some()) {
        line("ICP".into(), &|r| r.icp.as_ref().map(|i| i.scores.clone()));
    }
    out
}

/// Thresholds per level row of Table I, as a Markdown note (`1 level: [6]; 2 levels: [6, 9]`) taken
/// from the first report that has each row.
pub fn thresholds_note(reports: &[Report]) -> String {
    let mut seen: Vec<(usize, Vec<usize>)> = Vec::new();
    for r in reports {
        for l in &r.levels {
            if !seen.iter().any(|(lv, _)| *lv == l.levels) {
                seen.push((l.levels, l.thresholds.clone()));
            }
        }
    }
    seen.sort();
    let parts: Vec<String> = seen
        .iter()
        .map(|(lv, th)| format!("{lv} level{}: {th:?}", if *lv == 1 { "" } else { "s" }))
        .collect();
    format!("Minimum n-gram sizes per level: {}.", parts.join("; "))
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
                    format!("τ={} P {:.3} R {:.3}", p.threshold, p.precision, p.recall),
                ),
                None => ("-".into(), "-".into()),
            };
            let best = match &c.best_recall_at_precision {
                Some(p) => format!("{:.3} (τ={}, P {:.3})", p.recall, p.threshold, p.precision),
                None => "-".into(),
            };
            vec![c.label.clone(), f1, f1_at, best]
        })
        .collect();
    let best_header = format!("best R at P≥{floor}");
    render(&["curve", "max F1", "at", &best_header], &body)
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
            "| levels | A P – R | A s/lap | B P – R | B s/lap |"
        );
        assert_eq!(
            lines[2],
            "| 1 | 0.935 – 0.103 | 0.50 | 0.931 – 0.106 | 0.50 |"
        );
        assert!(lines[5].starts_with("| ICP | 0.050 – 0.040 | 9.00 |"));
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
        assert!(t.contains("0.100 (τ=5, P 0.950)"), "{t}");
    }

    /// Where opposite revisits exist, the terminal table and Table I add a row per direction
    /// under the level row; without them, neither does.
    /// Steps too long to observe along their length are noted once when there are pairs (and
    /// are part of the reason when there are none).
    /// With pairs, each level's line says how many true revisits and look-alikes verification
    /// turned down; without, its reason says it and the line is not repeated.
    #[test]
    fn turned_down_candidates_are_told_per_level() {
        let mut rep = sample("A", [0.9; 3], [0.2; 3]);
        assert!(!text_table(&rep).contains("verification turned down"));
        for l in &mut rep.levels {
            l.scores.rejected_candidates = Some(crate::eval::scores::RejectedScores {
                sampled: 25,
                correct: 22,
                ..Default::default()
            });
        }
        rep.levels[0].scores.no_pairs_reason = Some("every candidate was rejected".into());
        let t = text_table(&rep);
        assert_eq!(t.matches("verification turned down").count(), 2, "{t}");
        assert!(
            t.contains("verification turned down 22 true revisits and 3 look-alikes (of 25"),
            "{t}"
        );
    }

    #[test]
    fn long_steps_are_noted_once() {
        let mut rep = sample("A", [0.9; 3], [0.2; 3]);
        assert!(!text_table(&rep).contains("max_interpolation_m"));
        for l in &mut rep.levels {
            l.scores.diagnostics = Some(crate::recognizer::MatchDiagnostics {
                long_steps: 2,
                ..Default::default()
            });
        }
        let t = text_table(&rep);
        assert_eq!(t.matches("max_interpolation_m").count(), 1, "{t}");
        assert!(t.contains("note: 2 steps between scans were longer"), "{t}");
    }

    #[test]
    fn rows_per_direction_where_opposite_revisits_exist() {
        let plain = sample("A", [0.9; 3], [0.2; 3]);
        assert!(!text_table(&plain).contains("opposite"));
        assert!(!markdown_table_i(std::slice::from_ref(&plain)).contains("opposite"));
        let mut both = plain.clone();
        let s = &mut both.levels[2].scores;
        s.directions.same.precision = 0.97;
        s.directions.opposite.revisits = 100;
        s.directions.opposite.pairs = 10;
        s.directions.opposite.precision = 0.8;
        let t = text_table(&both);
        let opposite = t.lines().find(|l| l.starts_with("  opposite")).unwrap();
        assert!(opposite.contains("0.800"), "{t}");
        assert!(
            t.lines()
                .any(|l| l.starts_with("  same") && l.contains("0.970")),
            "{t}"
        );
        let md = markdown_table_i(&[both]);
        assert!(md.contains("| 3 same | 0.970 – "), "{md}");
        assert!(md.contains("| 3 opposite | 0.800 – "), "{md}");
    }

    #[test]
    fn text_table_lists_every_recognizer() {
        let t = text_table(&sample("B", [0.9; 3], [0.2; 3]));
        if std::env::var_os("PLACEWORDS_SHOW_TABLE").is_some() {
            eprintln!("{t}");
        }
        for needle in ["1 [6]", "2 [6, 9]", "3 [6, 9, 12]", "ICP", "revisits 5000"] {
            assert!(t.contains(needle), "{needle} missing in\n{t}");
        }
    }
}
