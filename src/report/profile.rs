//! The `--profile` summary of `run` and `check`: where the time went, per stage (simulate,
//! recognize per subject, score per subject, write), summed over the reports given (the seeds
//! and scenarios of a check). CPU seconds of the threads that did the work
//! ([`crate::clock`]), so stages that ran side by side add up to the CPU the command used; the
//! recognizers' wall clock is given beside theirs, and the writing is wall clock. One exception:
//! level configurations that share a density front end are each charged the whole of it
//! (`experiment::shared_front`), so with more than one `words-*` subject their recognize lines
//! count it once per subject and the total is more than the CPU used (a note line says so).

use crate::eval::scores::{Report, Scores};
use std::fmt::Write;

/// One line's figures: CPU seconds, and the wall-clock seconds where measured.
#[derive(Clone, Copy, Default)]
struct Stage {
    cpu_s: f64,
    wall_s: Option<f64>,
}

/// The summary of `reports` (with `write_wall_s` spent writing the outputs).
pub fn profile_text<'r>(
    reports: impl IntoIterator<Item = &'r Report>,
    write_wall_s: f64,
) -> String {
    let mut laps = 0usize;
    let mut simulate = 0.0;
    // (subject, recognize, score), in order of first appearance.
    let mut subjects: Vec<(String, Stage, f64)> = Vec::new();
    let mut add = |name: String, s: &Scores, laps: usize| {
        let i = match subjects.iter().position(|(n, ..)| *n == name) {
            Some(i) => i,
            None => {
                subjects.push((name, Stage::default(), 0.0));
                subjects.len() - 1
            }
        };
        let (_, rec, score) = &mut subjects[i];
        rec.cpu_s += s.recognize_seconds_per_lap * laps as f64;
        *rec.wall_s.get_or_insert(0.0) += s.recognize_wall_seconds_per_lap * laps as f64;
        *score += s.score_seconds;
    };
    for r in reports {
        laps += r.laps;
        simulate += r.simulate_seconds_per_lap * r.laps as f64;
        for subject in &r.subjects {
            add(subject.name.clone(), &subject.scores, r.laps);
        }
    }
    let mut rows: Vec<(String, Stage)> = vec![(
        "simulate".into(),
        Stage {
            cpu_s: simulate,
            wall_s: None,
        },
    )];
    for (name, rec, _) in &subjects {
        rows.push((format!("recognize {name}"), *rec));
    }
    for (name, _, score) in &subjects {
        rows.push((
            format!("score {name}"),
            Stage {
                cpu_s: *score,
                wall_s: None,
            },
        ));
    }
    let total: f64 = rows.iter().map(|(_, s)| s.cpu_s).sum();
    let scoring: f64 = subjects.iter().map(|(.., s)| s).sum();
    let share = |x: f64| if total > 0.0 { 100.0 * x / total } else { 0.0 };
    let per_lap = |x: f64| x / laps.max(1) as f64;
    let mut out = format!("profile ({laps} laps; CPU seconds of the threads that did the work)\n");
    for (name, s) in &rows {
        let _ = write!(
            out,
            "  {name:<22} {:>9.3} s  {:>5.1} %  {:>8.4} s/lap",
            s.cpu_s,
            share(s.cpu_s),
            per_lap(s.cpu_s)
        );
        if let Some(w) = s.wall_s {
            let _ = write!(out, "  (wall {w:.3} s, {:.4} s/lap)", per_lap(w));
        }
        out.push('\n');
    }
    let _ = writeln!(out, "  {:<22} {write_wall_s:>9.3} s  (wall)", "write");
    let _ = writeln!(
        out,
        "  {:<22} {total:>9.3} s  scoring {:.1} %",
        "total CPU",
        share(scoring)
    );
    let words = subjects
        .iter()
        .filter(|(n, ..)| crate::eval::scores::words_subject_levels(n).is_some());
    if words.count() > 1 {
        out.push_str(
            "  (the words subjects share one front end and each counts the whole of it: \
             the total overstates the CPU used)\n",
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::SubjectReport;
    use crate::spec::evaluation::EvaluationSpec;

    /// Stages add over reports, per subject; the scoring share is of the CPU listed.
    #[test]
    fn stages_add_over_reports_per_subject() {
        let report = |sim: f64| {
            let mut r = Report::new("B", 1, 10, EvaluationSpec::default());
            r.simulate_seconds_per_lap = sim;
            let scores = Scores {
                recognize_seconds_per_lap: 0.5,
                recognize_wall_seconds_per_lap: 1.0,
                score_seconds: 4.0,
                ..Scores::default()
            };
            r.subjects
                .push(SubjectReport::words(3, &[6, 9, 12], scores));
            r
        };
        let (a, b) = (report(0.1), report(0.3));
        let text = profile_text([&a, &b], 0.25);
        // 20 laps: simulate 1 + 3 = 4 s, recognize 5 + 5 = 10 s (wall 20), score 8 s.
        assert!(text.contains("20 laps"), "{text}");
        let line = |name: &str| text.lines().find(|l| l.contains(name)).unwrap().to_string();
        assert!(line("simulate").contains("4.000 s"), "{text}");
        assert!(line("recognize words-3").contains("10.000 s"), "{text}");
        assert!(
            line("recognize words-3").contains("wall 20.000 s"),
            "{text}"
        );
        assert!(line("score words-3").contains("8.000 s"), "{text}");
        assert!(line("total CPU").contains("22.000 s"), "{text}");
        assert!(line("total CPU").contains("scoring 36.4 %"), "{text}");
        assert!(line("write").contains("0.250 s"), "{text}");
    }
}
