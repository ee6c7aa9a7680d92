//! Explanations for people, from the figures `eval` computes: why a subject has no pair
//! (`Scores::no_pairs_reason`), in sentences. `eval` finds the causes
//! ([`crate::eval::scores::NoPairsCauses`]); this module words them, and so builds the
//! [`Scores`] and the report's subjects a run writes: [`Scores::of`], [`Report::add_subject`],
//! [`Report::add_level`] (inherent methods of `eval`'s types, defined here, above `eval`).
//! Also the truth rule in words ([`truth_rule`]), what verification turned down
//! ([`turned_down_sentence`], for the text table and the matches picture) and the lap cache's
//! lines ([`lap_cache_lines`]); a comparison's and a gate's sentences are in `report::compare` and
//! `report::suite`. `eval` itself writes no sentence a person reads, only data and error messages.

use crate::eval::Recognition;
use crate::eval::scores::{
    DirectionCauses, DirectionReason, NoPairsCauses, RejectedScores, Report, Scores, SubjectKind,
    SubjectReport, words_subject_name,
};
use crate::spec::evaluation::EvaluationSpec;

impl Scores {
    /// Evaluates `rec` with `spec` and takes its timing (the scoring's included), with the
    /// reason in words when there is no pair ([`Scores::measure`], then [`no_pairs_reason`]).
    pub fn of(rec: &Recognition, spec: &EvaluationSpec) -> Self {
        let (mut scores, causes, directions) = Scores::measure(rec, spec);
        scores.no_pairs_reason = causes.map(|c| no_pairs_reason(&c, spec));
        scores.direction_no_pairs_reasons = directions
            .iter()
            .map(|c| DirectionReason::new(c.direction, direction_reason(c, spec)))
            .collect();
        scores
    }
}

impl Report {
    /// Scores `rec` (the paper's recognizer run with `levels` levels and `thresholds`) and adds
    /// it as subject `words-<levels>`.
    pub fn add_level(
        &mut self,
        levels: usize,
        thresholds: &[usize],
        rec: &Recognition,
    ) -> &SubjectReport {
        let added = self.add_subject(&words_subject_name(levels), SubjectKind::Words, rec);
        added.levels = Some(levels);
        added.thresholds = thresholds.to_vec();
        added
    }

    /// Scores `rec` ([`Scores::of`]) and adds it as the subject `name` of `kind`.
    pub fn add_subject(
        &mut self,
        name: &str,
        kind: SubjectKind,
        rec: &Recognition,
    ) -> &mut SubjectReport {
        let mut added = SubjectReport::new(name, kind, Scores::of(rec, &self.evaluation));
        added.recognize_seconds_by_lap = rec.lap_seconds.clone();
        self.subjects.push(added);
        self.subjects.last_mut().expect("just pushed")
    }
}

/// Why a run has no pair, in words: the causes `eval` found, joined by "; ".
pub fn no_pairs_reason(causes: &NoPairsCauses, spec: &EvaluationSpec) -> String {
    let mut why = Vec::new();
    if causes.no_revisit {
        why.push(format!(
            "no observation has a revisit (an earlier pass within {} m, {} m of travel before)",
            spec.tp_radius_m, spec.min_gap_m
        ));
    }
    match &causes.recognizer {
        Some(r) => {
            why.push(r.no_match_reason.clone());
            why.extend(r.revisit_length_reason.clone());
            why.extend(r.rejected.as_ref().map(|r| rejected_sentence(r, spec)));
        }
        None if why.is_empty() => why.push("the recognizer does not say why".into()),
        None => {}
    }
    why.join("; ")
}

/// Why one direction's revisits got no pair while the other's did, in words: its longest
/// revisit against the chain the recognizer needs that way, then what verification turned down
/// that way (or that no candidate of that direction reached it).
pub fn direction_reason(c: &DirectionCauses, spec: &EvaluationSpec) -> String {
    let mut why: Vec<String> = c.length_reason.iter().cloned().collect();
    why.push(match &c.rejected {
        Some(r) => rejected_sentence(r, spec),
        None => "no candidate that way reached verification: the words differ between the \
                 visits"
            .into(),
    });
    why.join("; ")
}

/// What the truth says of the rejected candidates, in words.
fn rejected_sentence(r: &RejectedScores, spec: &EvaluationSpec) -> String {
    if r.correct == 0 {
        return format!(
            "by the ground truth none of the {} rejected candidates sampled paired the same \
             place (within {} m, at both ends of a chain): verification turned down look-alikes",
            r.sampled, spec.tp_radius_m
        );
    }
    let by_check: Vec<String> = r
        .correct_by_check
        .iter()
        .map(|c| format!("{} {}", c.check, c.count))
        .collect();
    let later = if r.correct_recognized > 0 {
        format!(
            " ({} of them recognized later all the same)",
            r.correct_recognized
        )
    } else {
        String::new()
    };
    format!(
        "by the ground truth {} of the {} rejected candidates sampled paired the same place \
         (within {} m, at both ends of a chain; {}): verification turned down true revisits{later}",
        r.correct,
        r.sampled,
        spec.tp_radius_m,
        by_check.join(", ")
    )
}

/// What verification turned down, in one sentence for the text table and the matches picture:
/// the true revisits, how many of them were recognized later all the same (a later n-gram
/// through the same place passed: the check made them wait) and how many were lost, and the
/// look-alikes, of the candidates sampled.
pub fn turned_down_sentence(r: &RejectedScores) -> String {
    let s = |n: usize| if n == 1 { "" } else { "s" };
    let alike = r.sampled - r.correct;
    let fate = if r.correct == 0 {
        String::new()
    } else {
        format!(
            " ({} recognized later all the same, {} lost)",
            r.correct_recognized,
            r.correct - r.correct_recognized
        )
    };
    format!(
        "verification turned down {} true revisit{}{fate} and {alike} look-alike{} (of {} \
         candidate{} sampled)",
        r.correct,
        s(r.correct),
        s(alike),
        r.sampled,
        s(r.sampled)
    )
}

/// The truth rule in a few words: `within 1 m, 20 m of travel before, heading within 45°`.
pub fn truth_rule(rule: &crate::eval::ranking::TruthRule) -> String {
    format!(
        "within {} m, {} m of travel before, heading within {}°",
        rule.tp_radius_m, rule.min_gap_m, rule.heading_tolerance_deg
    )
}

/// `lap cache DIR: 9 hits, 1 miss`, then a line per corrupt entry and per entry not stored.
pub fn lap_cache_lines(cache: &crate::eval::provenance::LapCacheUse) -> Vec<String> {
    let s = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let mut out = vec![format!(
        "lap cache {}: {}, {}",
        cache.dir,
        s(cache.hits, "hit", "hits"),
        s(cache.misses, "miss", "misses")
    )];
    out.extend(
        cache
            .corrupt
            .iter()
            .map(|c| format!("lap cache: corrupt entry simulated again: {c}")),
    );
    out.extend(
        cache
            .not_stored
            .iter()
            .map(|c| format!("lap cache: laps not stored: {c}")),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::metrics::{Evaluation, Metrics};
    use crate::eval::scores::no_pairs_causes;
    use crate::place::Diagnostics;
    use crate::recognizer::{MatchDiagnostics, Rejection};

    /// The reason `Scores::of` would write for `e`.
    fn reason(
        e: &Evaluation,
        d: Option<&dyn Diagnostics>,
        rejected: Option<&RejectedScores>,
        spec: &EvaluationSpec,
    ) -> Option<String> {
        no_pairs_causes(e, d, rejected).map(|c| no_pairs_reason(&c, spec))
    }

    /// A run without pairs says why: verification counts when every candidate was rejected,
    /// chain lengths against τ when no chain was long enough, and missing revisits.
    #[test]
    fn no_pairs_reason_names_the_cause() {
        let spec = EvaluationSpec::default();
        let none = Evaluation {
            main: Metrics {
                revisits: 10,
                ..Metrics::default()
            },
            ..Evaluation::default()
        };
        let mut d = MatchDiagnostics {
            longest_chain: vec![7, 9],
            min_ngram: vec![6, 9],
            within_gap: 0,
            verification: Default::default(),
            long_steps: 0,
            reverse_extra_ngram: 0,
            rejected: Vec::new(),
            mean_word_m: 0.0,
        };
        d.verification.rejected_travel = 3;
        d.verification.rejected_density = 2;
        d.verification.rejected_straight = 1;
        let why = reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(
            why.contains(
                "rejected by verification: 6 (travel 3, turn 0, density 2, sides 0, straight 1)"
            ),
            "{why}"
        );
        d.verification = Default::default();
        d.longest_chain = vec![4, 8];
        let why = reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("4 (τ = 6) at 1 level, 8 (τ = 9) at 2 levels"),
            "{why}"
        );
        d.long_steps = 3;
        let why = reason(&none, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("3 steps between scans were longer than max_interpolation_m"),
            "{why}"
        );
        let why = reason(&Evaluation::default(), None, None, &spec).unwrap();
        assert!(why.starts_with("no observation has a revisit"), "{why}");
        let mut some = none.clone();
        some.main.pairs = 1;
        assert_eq!(
            reason(&some, Some(&d as &dyn Diagnostics), None, &spec),
            None
        );
    }

    /// When no chain is long enough, the reason says whether the revisits are shorter than τ
    /// words of the run's mean length (nothing to chain) or long enough (the words differ).
    #[test]
    fn no_pairs_reason_compares_revisit_length_with_tau_words() {
        let spec = EvaluationSpec::default();
        let mut e = Evaluation::default();
        e.main.revisits = 300;
        e.main.longest_revisit_m = 20.2.into();
        e.directions.same.longest_revisit_m = 11.2.into();
        e.directions.opposite.longest_revisit_m = 9.0.into();
        let d = MatchDiagnostics {
            longest_chain: vec![4],
            min_ngram: vec![6],
            mean_word_m: 2.5,
            ..MatchDiagnostics::default()
        };
        let why = reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("no word sequence long enough"), "{why}");
        assert!(
            why.contains("is 11.2 m driven the same way and 9.0 m the other way"),
            "{why}"
        );
        assert!(why.contains("a word spans 2.5 m on average"), "{why}");
        assert!(why.contains("τ = 6 words need about 15 m,"), "{why}");
        assert!(why.contains("too short for a chain"), "{why}");
        // Read backwards a chain needs more words: 16 m is enough driven the same way, not
        // the other way.
        let d = MatchDiagnostics {
            reverse_extra_ngram: 2,
            ..d
        };
        e.directions.opposite.longest_revisit_m = 16.0.into();
        let why = reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(
            why.contains("τ = 6 words need about 15 m (8 read backwards, about 20 m)"),
            "{why}"
        );
        assert!(why.contains("too short for a chain"), "{why}");
        e.directions.same.longest_revisit_m = 16.0.into();
        let why = reason(&e, Some(&d as &dyn Diagnostics), None, &spec).unwrap();
        assert!(why.contains("the words differ between visits"), "{why}");
        // Verification's counts are the reason when candidates were made.
        let mut v = d.clone();
        v.verification.rejected_turn = 2;
        let why = reason(&e, Some(&v as &dyn Diagnostics), None, &spec).unwrap();
        assert!(!why.contains("stretch"), "{why}");
    }

    /// Rejected candidates are scored at their sampled pair: right when the two true poses are
    /// within the radius and face as the candidate's direction claims; the reason then says
    /// whether verification turned down true revisits or look-alikes.
    #[test]
    fn rejected_candidates_are_scored_against_the_truth() {
        use crate::eval::RejectedTruth;
        use crate::geom::{Pose2, TruePose};
        use crate::place::Direction;
        let spec = EvaluationSpec::default();
        let at = |x: f64, theta_deg: f64| TruePose(Pose2::new(x, 0.0, theta_deg.to_radians()));
        let r = |q, p, direction, reason: Rejection| RejectedTruth {
            query_index: 0,
            query: q,
            past: p,
            direction,
            check: reason.index(),
            oldest: None,
        };
        let checks: Vec<String> = Rejection::ALL.iter().map(|r| r.name().into()).collect();
        let rejected = [
            // The same place, facing alike: a true revisit turned down by the turn check.
            r(
                at(0.0, 0.0),
                at(0.5, 10.0),
                Direction::Same,
                Rejection::Turn,
            ),
            // The same place driven the other way, claimed opposite: right too.
            r(
                at(0.0, 0.0),
                at(0.3, 175.0),
                Direction::Opposite,
                Rejection::Sides,
            ),
            // Claimed the same direction but driven the other way: wrong.
            r(
                at(0.0, 0.0),
                at(0.3, 175.0),
                Direction::Same,
                Rejection::Turn,
            ),
            // A look-alike 5 m away.
            r(
                at(0.0, 0.0),
                at(5.0, 0.0),
                Direction::Same,
                Rejection::Travel,
            ),
        ];
        // Every candidate's query observation (index 0) recognized by the end of the run: the
        // two true revisits were recognized later, the look-alikes do not count.
        let later = RejectedScores::of(&rejected, &checks, &spec, &[true]).expect("four sampled");
        assert_eq!((later.correct, later.correct_recognized), (2, 2));
        let s = RejectedScores::of(&rejected, &checks, &spec, &[false]).expect("four sampled");
        assert_eq!((s.sampled, s.correct, s.correct_recognized), (4, 2, 0));
        assert_eq!(
            (
                s.correct_by("turn"),
                s.correct_by("sides"),
                s.correct_by("travel")
            ),
            (1, 1, 0)
        );
        assert_eq!(RejectedScores::of(&[], &checks, &spec, &[]), None);
        let mut e = Evaluation::default();
        e.main.revisits = 10;
        let d = MatchDiagnostics {
            longest_chain: vec![8],
            min_ngram: vec![6],
            verification: crate::recognizer::VerificationCounts {
                rejected_turn: 2,
                rejected_sides: 1,
                rejected_travel: 1,
                ..Default::default()
            },
            ..MatchDiagnostics::default()
        };
        let why = reason(&e, Some(&d as &dyn Diagnostics), Some(&s), &spec).unwrap();
        assert!(
            why.contains("every candidate was rejected by verification: 4"),
            "{why}"
        );
        assert!(
            why.contains("2 of the 4 rejected candidates sampled paired the same place"),
            "{why}"
        );
        assert!(why.contains("turned down true revisits"), "{why}");
        let none_right = RejectedScores::of(&rejected[3..], &checks, &spec, &[]).unwrap();
        let why = reason(&e, Some(&d as &dyn Diagnostics), Some(&none_right), &spec).unwrap();
        assert!(why.contains("turned down look-alikes"), "{why}");
    }

    /// A subject with pairs whose other direction has revisits and none says why that direction
    /// got none: its longest revisit against the chain it needs read that way, and the
    /// candidates of that direction verification turned down (a look-alike here); a direction
    /// with pairs, or without revisits, says nothing, nor does a subject without any pair (its
    /// own reason covers both).
    #[test]
    fn a_direction_without_pairs_says_why() {
        use crate::eval::RejectedTruth;
        use crate::eval::scores::direction_causes;
        use crate::geom::{Pose2, TruePose};
        use crate::place::Direction;
        let spec = EvaluationSpec::default();
        let mut e = Evaluation::default();
        e.main.pairs = 40;
        e.directions.same = Metrics {
            pairs: 40,
            revisits: 100,
            ..Metrics::default()
        };
        e.directions.opposite = Metrics {
            revisits: 80,
            longest_revisit_m: crate::eval::metrics::RevisitStretch::of(65.0),
            ..Metrics::default()
        };
        let d = MatchDiagnostics {
            min_ngram: vec![6, 9],
            reverse_extra_ngram: 2,
            mean_word_m: 3.4,
            ..Default::default()
        };
        let at = |x: f64, theta_deg: f64| TruePose(Pose2::new(x, 0.0, theta_deg.to_radians()));
        let look_alike = RejectedTruth {
            query_index: 0,
            query: at(0.0, 0.0),
            past: at(5.0, 180.0),
            direction: Direction::Opposite,
            check: Rejection::Turn.index(),
            oldest: None,
        };
        let causes = direction_causes(&e, &d, &[look_alike], &spec);
        assert_eq!(causes.len(), 1);
        assert_eq!(causes[0].direction, Direction::Opposite);
        let why = direction_reason(&causes[0], &spec);
        assert!(
            why.contains(
                "revisit the other way is 65.0 m, and a chain read backwards needs 8 words, about \
                 27 m at 3.4 m a word: long enough for one"
            ),
            "{why}"
        );
        assert!(why.contains("none of the 1 rejected candidates"), "{why}");
        // No candidate read that way: the words differ; a short stretch is too short.
        e.directions.opposite.longest_revisit_m = crate::eval::metrics::RevisitStretch::of(20.0);
        let why = direction_reason(&direction_causes(&e, &d, &[], &spec)[0], &spec);
        assert!(why.contains("too short for one"), "{why}");
        assert!(
            why.contains("no candidate that way reached verification"),
            "{why}"
        );
        // Pairs both ways, or none at all: no direction reason.
        e.directions.opposite.pairs = 3;
        assert!(direction_causes(&e, &d, &[], &spec).is_empty());
        e.directions.opposite.pairs = 0;
        e.main.pairs = 0;
        assert!(direction_causes(&e, &d, &[], &spec).is_empty());
    }
}
