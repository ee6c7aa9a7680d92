//! The `[evaluation]` and `[expect]` blocks of a scenario file: how matches are scored, and the
//! CI gate a scenario must pass.

use crate::spec::diag::{Diags, fmt_number};
use crate::spec::read::{Val, get, number, table, table_array, unknown_keys};
use serde::{Deserialize, Serialize};
use toml::de::{DeTable, DeValue};

/// How matches are scored against ground truth (docs/design.md, Evaluation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct EvaluationSpec {
    /// A pair is correct when its two true positions are within this distance, metres. Default 1.0.
    pub tp_radius_m: f64,
    /// Observations closer than this in true travel (the harness's, not the odometry) are never
    /// a revisit, metres. Default 20.
    pub min_gap_m: f64,
    /// A revisit must face the same way within this angle, degrees. Default 45.
    pub heading_tolerance_deg: f64,
    /// Extra radii at which precision and recall are also reported, metres. Default [0.5, 2, 3].
    pub sensitivity_radii_m: Vec<f64>,
}

impl Default for EvaluationSpec {
    fn default() -> Self {
        EvaluationSpec {
            tp_radius_m: 1.0,
            min_gap_m: 20.0,
            heading_tolerance_deg: 45.0,
            sensitivity_radii_m: vec![0.5, 2.0, 3.0],
        }
    }
}

/// The CI gate: `[[expect.subjects]]` entries, each naming a subject (`words-3`, `icp`),
/// checked over the seeds run: each bound applies to the worst seed, or with `quantile = q` to
/// the q-quantile (nearest rank, counted from the worst seed; `quantile = 0.1` lets the worst
/// tenth miss).
///
/// An entry may also bound the figures of one direction alone in its sub-tables
/// `[expect.subjects.same]` and `[expect.subjects.opposite]` (the report's `directions`).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ExpectSpec {
    pub subjects: Vec<SubjectExpectation>,
    /// Bounds apply to this quantile of the seeds instead of the worst seed, in [0, 1).
    /// Default: none (the worst seed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantile: Option<f64>,
    /// `[expect.regression]`: how much worse than a baseline (`check --baseline`, `compare`)
    /// a figure may get. Default: none (the defaults of [`RegressionSpec`] apply).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub regression: Option<RegressionSpec>,
}

/// `[expect.regression]`: the tolerance of a comparison with a baseline report. A metric is a
/// regression when, over the compared seeds, it got worse by more than this with confidence
/// (`eval::compare`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RegressionSpec {
    /// How much precision and each recall may drop (new − baseline, a ratio in [0, 1)).
    /// Default 0.003 (docs/ci.md: paired runs of a deterministic recognizer have no noise).
    pub max_drop: f64,
    /// How many times slower the recognition time per lap (CPU seconds) may get, at least 1.
    /// Default 1.5.
    pub max_slowdown: f64,
}

impl Default for RegressionSpec {
    fn default() -> Self {
        RegressionSpec {
            max_drop: 0.003,
            max_slowdown: 1.5,
        }
    }
}

/// Keys of `[expect.regression]`.
pub const EXPECT_REGRESSION_KEYS: &[&str] = &["max_drop", "max_slowdown"];

/// Whether `max_drop` may be `x`: a ratio in [0, 1).
pub fn valid_max_drop(x: f64) -> bool {
    (0.0..1.0).contains(&x)
}

/// Whether `max_slowdown` may be `x`: a finite factor of at least 1.
pub fn valid_max_slowdown(x: f64) -> bool {
    x.is_finite() && x >= 1.0
}

impl ExpectSpec {
    /// Whether the block sets no bound at all.
    pub fn is_empty(&self) -> bool {
        self.subjects.is_empty()
    }

    /// The levels of the paper recognizer's subjects the block bounds, in increasing order.
    pub fn word_levels(&self) -> Vec<usize> {
        let mut levels: Vec<usize> = self
            .subjects
            .iter()
            .filter_map(|e| words_subject_levels(&e.subject))
            .collect();
        levels.sort_unstable();
        levels.dedup();
        levels
    }

    /// Whether the block bounds the subject `name`.
    pub fn names(&self, name: &str) -> bool {
        self.subjects.iter().any(|e| e.subject == name)
    }
}

/// The name of the paper recognizer's subject with `levels` levels: `words-3`.
pub fn words_subject_name(levels: usize) -> String {
    format!("words-{levels}")
}

/// The levels of a words subject's name (`words-3` → 3), if it is one.
pub fn words_subject_levels(name: &str) -> Option<usize> {
    name.strip_prefix("words-")?.parse().ok()
}

/// The subjects a scenario's `[expect]` may name today: the paper's recognizer at 1, 2 or 3
/// levels, the ICP baseline and the Scan Context baseline.
pub const KNOWN_SUBJECTS: &[&str] = &["words-1", "words-2", "words-3", "icp", "scan-context"];

/// Whether `name` is spelt as a subject's name may be: non-empty, of ASCII letters, digits,
/// `-` and `_` (so it is safe in file names, JUnit names and reproducing commands).
pub fn is_subject_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// Whether `name` belongs to the built-in subjects: one of [`KNOWN_SUBJECTS`] or the paper
/// recognizer's `words-…` family. An external recognizer may not take such a name.
pub fn is_builtin_subject_name(name: &str) -> bool {
    KNOWN_SUBJECTS.contains(&name) || name.starts_with("words-")
}

/// What one subject must achieve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SubjectExpectation {
    /// The subject bounded: `words-1`, `words-2`, `words-3` (the paper's recognizer at that
    /// many levels), `icp`, `scan-context`, or the name of an external recognizer given to `check` with
    /// `--recognizer NAME=exec:COMMAND`.
    pub subject: String,
    /// Minimum pair precision in [0, 1].
    #[serde(default)]
    pub min_precision: Option<f64>,
    /// Minimum recall in [0, 1] (revisits of both directions).
    #[serde(default)]
    pub min_recall: Option<f64>,
    /// Minimum visit recall in [0, 1].
    #[serde(default)]
    pub min_visit_recall: Option<f64>,
    /// Minimum pair recall in [0, 1].
    #[serde(default)]
    pub min_pair_recall: Option<f64>,
    /// Maximum recognition time per lap, seconds.
    #[serde(default)]
    pub max_seconds_per_lap: Option<f64>,
    /// Bounds on the same-direction figures alone (`[expect.subjects.same]`): the matches that
    /// claim the same direction against the same-direction revisits. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub same: Option<DirectionExpectation>,
    /// Bounds on the opposite-direction figures alone (`[expect.subjects.opposite]`). Default:
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opposite: Option<DirectionExpectation>,
}

/// Bounds on the figures of one direction: those of [`Expectation`] but time, which is not
/// counted per direction.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct DirectionExpectation {
    /// Minimum precision of this direction's pairs in [0, 1]. Default: none.
    pub min_precision: Option<f64>,
    /// Minimum recall of this direction's revisits in [0, 1]. Default: none.
    pub min_recall: Option<f64>,
    /// Minimum visit recall in [0, 1]. Default: none.
    pub min_visit_recall: Option<f64>,
    /// Minimum pair recall in [0, 1]. Default: none.
    pub min_pair_recall: Option<f64>,
}

impl DirectionExpectation {
    /// The thresholds as an [`Expectation`] without a time budget.
    pub fn expectation(&self) -> Expectation {
        Expectation {
            min_precision: self.min_precision,
            min_recall: self.min_recall,
            min_visit_recall: self.min_visit_recall,
            min_pair_recall: self.min_pair_recall,
            max_seconds_per_lap: None,
        }
    }
}

impl SubjectExpectation {
    /// The thresholds alone.
    pub fn expectation(&self) -> Expectation {
        Expectation {
            min_precision: self.min_precision,
            min_recall: self.min_recall,
            min_visit_recall: self.min_visit_recall,
            min_pair_recall: self.min_pair_recall,
            max_seconds_per_lap: self.max_seconds_per_lap,
        }
    }
}

/// Minimum precision and recall, and optionally a time budget.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Expectation {
    /// Minimum pair precision in [0, 1].
    pub min_precision: Option<f64>,
    /// Minimum recall in [0, 1] (revisits of both directions).
    pub min_recall: Option<f64>,
    /// Minimum visit recall in [0, 1].
    pub min_visit_recall: Option<f64>,
    /// Minimum pair recall in [0, 1].
    pub min_pair_recall: Option<f64>,
    /// Maximum recognition time per lap, seconds.
    pub max_seconds_per_lap: Option<f64>,
}

/// Keys of `[evaluation]`.
pub const EVALUATION_KEYS: &[&str] = &[
    "tp_radius_m",
    "min_gap_m",
    "heading_tolerance_deg",
    "sensitivity_radii_m",
];
/// Keys of `[expect]`.
pub const EXPECT_KEYS: &[&str] = &["subjects", "quantile", "regression"];
/// Keys of an `[[expect.subjects]]` entry.
pub const EXPECT_SUBJECT_KEYS: &[&str] = &[
    "subject",
    "min_precision",
    "min_recall",
    "max_seconds_per_lap",
    "min_visit_recall",
    "min_pair_recall",
    "same",
    "opposite",
];
/// Keys of an `[expect.subjects.same]` or `[expect.subjects.opposite]` sub-table.
pub const EXPECT_DIRECTION_KEYS: &[&str] = &[
    "min_precision",
    "min_recall",
    "min_visit_recall",
    "min_pair_recall",
];
/// A key, its slot, the rule it must meet and the rule in words.
type Check<'a> = (&'a str, &'a mut f64, fn(f64) -> bool, &'a str);

/// Sets each `checks` key that `t` holds and that meets its rule; reports the others at their
/// value.
fn set_checked<'a>(
    t: &DeTable<'_>,
    checks: impl IntoIterator<Item = Check<'a>>,
    ctx: &str,
    d: &mut Diags,
) {
    for (key, slot, ok, what) in checks {
        let Some((_, v)) = get(t, key) else { continue };
        match number(v, key, ctx, d) {
            Some(x) if ok(x) => *slot = x,
            Some(x) => d.at(
                v.span().start,
                format!("{key} = {} in {ctx} must be {what}", fmt_number(x)),
            ),
            None => {}
        }
    }
}

/// `[evaluation]` over [`EvaluationSpec::default`]; each bad value reported at its key.
pub(crate) fn read_evaluation(top: &DeTable<'_>, d: &mut Diags) -> EvaluationSpec {
    let mut ev = EvaluationSpec::default();
    let Some((_, t)) = table(top, "evaluation", d) else {
        return ev;
    };
    let ctx = "[evaluation]";
    unknown_keys(t, EVALUATION_KEYS, ctx, d);
    let checks: [Check; 3] = [
        ("tp_radius_m", &mut ev.tp_radius_m, |x| x > 0.0, "positive"),
        ("min_gap_m", &mut ev.min_gap_m, |x| x >= 0.0, "0 or more"),
        (
            "heading_tolerance_deg",
            &mut ev.heading_tolerance_deg,
            |x| x > 0.0,
            "positive",
        ),
    ];
    set_checked(t, checks, ctx, d);
    if let Some((_, v)) = get(t, "sensitivity_radii_m") {
        let radii = numbers(v, "sensitivity_radii_m", ctx, d);
        ev.sensitivity_radii_m = radii.unwrap_or_default();
    }
    ev
}

fn numbers(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<Vec<f64>> {
    let DeValue::Array(a) = v.get_ref() else {
        d.at(
            v.span().start,
            format!("`{key}` in {ctx} must be a list of numbers; write e.g. `[0.5, 2.0]`"),
        );
        return None;
    };
    a.iter().map(|x| number(x, key, ctx, d)).collect()
}

/// `[expect]`: `[[expect.subjects]]` entries and `quantile`. The form before subjects
/// (`[[expect.levels]]` with `levels = N`, `[expect.icp]`) is refused with how to update it.
/// `declared`: the names of the scenario's own `[[subjects]]` (a name close to one of them,
/// or to a built-in one, is taken for a typo).
pub(crate) fn read_expect(top: &DeTable<'_>, declared: &[&str], d: &mut Diags) -> ExpectSpec {
    let mut ex = ExpectSpec::default();
    let Some((_, t)) = table(top, "expect", d) else {
        return ex;
    };
    old_expect_form(t, d);
    let known: Vec<&str> = [EXPECT_KEYS, &["levels", "icp"]].concat();
    unknown_keys(t, &known, "[expect]", d);
    for (i, (_, lt)) in table_array(t, "subjects", d).into_iter().enumerate() {
        let ctx = format!("[[expect.subjects]] #{i}");
        unknown_keys(lt, EXPECT_SUBJECT_KEYS, &ctx, d);
        let subject = expect_subject_name(lt, declared, &ctx, d);
        let e = expectation(lt, &ctx, d);
        ex.subjects.push(SubjectExpectation {
            subject,
            min_precision: e.min_precision,
            min_recall: e.min_recall,
            max_seconds_per_lap: e.max_seconds_per_lap,
            min_visit_recall: e.min_visit_recall,
            min_pair_recall: e.min_pair_recall,
            same: direction_expectation(lt, "same", &ctx, d),
            opposite: direction_expectation(lt, "opposite", &ctx, d),
        });
    }
    if let Some(q) = read_quantile(t, d) {
        ex.quantile = Some(q);
    }
    ex.regression = read_regression(t, d);
    ex
}

/// `quantile` of `[expect]` when given and in 0..1; a value outside is reported.
fn read_quantile(t: &DeTable<'_>, d: &mut Diags) -> Option<f64> {
    let (_, v) = get(t, "quantile")?;
    let q = number(v, "quantile", "[expect]", d)?;
    if (0.0..1.0).contains(&q) {
        return Some(q);
    }
    d.at(
        v.span().start,
        format!(
            "quantile = {} is outside 0..1; use 0.1 for the 10th percentile",
            fmt_number(q)
        ),
    );
    None
}

/// The `subject` of one `[[expect.subjects]]` entry (`ctx` names it): a built-in or declared
/// name, or an external recognizer's; empty, with the error reported, when missing, mistyped
/// or not a name.
fn expect_subject_name(lt: &DeTable<'_>, declared: &[&str], ctx: &str, d: &mut Diags) -> String {
    match get(lt, "subject") {
        None => {
            d.at(0, missing_subject(ctx));
            String::new()
        }
        Some((_, v)) => match v.get_ref() {
            DeValue::String(name)
                if KNOWN_SUBJECTS.contains(&name.as_ref()) || declared.contains(&name.as_ref()) =>
            {
                name.to_string()
            }
            DeValue::String(name) => external_subject(name, v.span().start, declared, ctx, d),
            _ => {
                d.at(
                    v.span().start,
                    format!(
                        "`subject` in {ctx} must be a name in quotes, e.g. \
                         `subject = \"words-3\"`"
                    ),
                );
                String::new()
            }
        },
    }
}

/// The message for an entry (`ctx`) without `subject`, listing the built-in ones.
fn missing_subject(ctx: &str) -> String {
    format!(
        "missing key `subject` in {ctx}; add e.g. `subject = \"words-3\"` \
         (one of {})",
        KNOWN_SUBJECTS.join(", ")
    )
}

/// Any name neither built in nor declared is an external subject's (`--recognizer NAME=…`),
/// unless it looks like a built-in or declared one mistyped: then it is reported, and empty.
fn external_subject(name: &str, at: usize, declared: &[&str], ctx: &str, d: &mut Diags) -> String {
    let near = crate::spec::suggest::closest(name, KNOWN_SUBJECTS.iter().chain(declared).copied());
    if near.is_some() || is_builtin_subject_name(name) || !is_subject_name(name) {
        unknown_subject(name, near, at, declared, ctx, d);
        String::new()
    } else {
        name.to_string()
    }
}

/// Reports the unknown subject `name` at `at`, with the close name `near` if any and the names
/// the scenario knows.
fn unknown_subject(
    name: &str,
    near: Option<&str>,
    at: usize,
    declared: &[&str],
    ctx: &str,
    d: &mut Diags,
) {
    let hint = match near {
        Some(k) => format!("did you mean `{k}`? "),
        None => String::new(),
    };
    let own = if declared.is_empty() {
        String::new()
    } else {
        format!(", the scenario's [[subjects]] {}", declared.join(", "))
    };
    d.at(
        at,
        format!(
            "unknown subject `{name}` in {ctx}; {hint}the built-in subjects \
             are {}{own} (an external recognizer's name is made of \
             letters, digits, `-` and `_`)",
            KNOWN_SUBJECTS.join(", ")
        ),
    );
}

/// `[expect.regression]` over [`RegressionSpec::default`]; each bad value reported at its key.
fn read_regression(expect: &DeTable<'_>, d: &mut Diags) -> Option<RegressionSpec> {
    let (_, t) = table(expect, "regression", d)?;
    let ctx = "[expect.regression]";
    unknown_keys(t, EXPECT_REGRESSION_KEYS, ctx, d);
    let mut r = RegressionSpec::default();
    let checks: [Check; 2] = [
        (
            "max_drop",
            &mut r.max_drop,
            valid_max_drop,
            "in 0..1 (a drop of precision or recall, e.g. 0.01)",
        ),
        (
            "max_slowdown",
            &mut r.max_slowdown,
            valid_max_slowdown,
            "at least 1 (a factor on the time per lap, e.g. 1.5)",
        ),
    ];
    set_checked(t, checks, ctx, d);
    Some(r)
}

/// Refuses the `[expect]` form before subjects, at each old key, saying what to write instead.
fn old_expect_form(t: &DeTable<'_>, d: &mut Diags) {
    if let Some((kat, v)) = get(t, "levels") {
        let entries = old_levels(v);
        let example = entries.first().map_or("3".to_string(), |n| n.clone());
        d.at(
            kat,
            format!(
                "`[[expect.levels]]` is the form before subjects; each entry is now \
                 `[[expect.subjects]]` with `subject = \"words-{example}\"` in place of \
                 `levels = {example}` (and `[expect.levels.same]` becomes \
                 `[expect.subjects.same]`); the other keys stay as they are"
            ),
        );
    }
    if let Some((kat, _)) = get(t, "icp") {
        d.at(
            kat,
            "`[expect.icp]` is the form before subjects; write it as `[[expect.subjects]]` \
             with `subject = \"icp\"` and the same bounds"
                .to_string(),
        );
    }
}

/// The `levels = N` of each entry of an old `[[expect.levels]]`, as written.
fn old_levels(v: &Val<'_>) -> Vec<String> {
    match v.get_ref() {
        DeValue::Array(a) => a
            .iter()
            .filter_map(|e| match e.get_ref() {
                DeValue::Table(lt) => get(lt, "levels").and_then(|(_, n)| match n.get_ref() {
                    DeValue::Integer(i) => Some(i.as_str().to_string()),
                    _ => None,
                }),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The `[expect.subjects.<dir>]` sub-table of a subject entry (`dir` is `same` or
/// `opposite`).
fn direction_expectation(
    lt: &DeTable<'_>,
    dir: &str,
    entry: &str,
    d: &mut Diags,
) -> Option<DirectionExpectation> {
    let (kat, v) = get(lt, dir)?;
    let DeValue::Table(t) = v.get_ref() else {
        d.at(
            kat,
            format!(
                "`{dir}` in {entry} must be a table of bounds on the {dir}-direction figures; \
                 write a `[expect.subjects.{dir}]` section with e.g. `min_precision = 0.9`"
            ),
        );
        return None;
    };
    let ctx = format!("[expect.subjects.{dir}] of {entry}");
    refuse_direction_time(t, &ctx, d);
    let known = [EXPECT_DIRECTION_KEYS, &["max_seconds_per_lap"]].concat();
    unknown_keys(t, &known, &ctx, d);
    let e = expectation(t, &ctx, d);
    Some(DirectionExpectation {
        min_precision: e.min_precision,
        min_recall: e.min_recall,
        min_visit_recall: e.min_visit_recall,
        min_pair_recall: e.min_pair_recall,
    })
}

/// Refuses `max_seconds_per_lap` in a direction's table (`ctx`): time is per subject only.
fn refuse_direction_time(t: &DeTable<'_>, ctx: &str, d: &mut Diags) {
    if let Some((kat, _)) = get(t, "max_seconds_per_lap") {
        d.at(
            kat,
            format!(
                "`max_seconds_per_lap` in {ctx}: time is not counted per direction; \
                 bound it in the subject entry itself"
            ),
        );
    }
}

fn expectation(t: &DeTable<'_>, ctx: &str, d: &mut Diags) -> Expectation {
    let mut bound = |key: &str, unit: bool| -> Option<f64> {
        let (_, v) = get(t, key)?;
        let x = number(v, key, ctx, d)?;
        let ok = if unit {
            (0.0..=1.0).contains(&x)
        } else {
            x > 0.0
        };
        if !ok {
            let range = if unit { "outside 0..1" } else { "not positive" };
            d.at(
                v.span().start,
                format!("{key} = {} in {ctx} is {range}", fmt_number(x)),
            );
        }
        ok.then_some(x)
    };
    Expectation {
        min_precision: bound("min_precision", true),
        min_recall: bound("min_recall", true),
        max_seconds_per_lap: bound("max_seconds_per_lap", false),
        min_visit_recall: bound("min_visit_recall", true),
        min_pair_recall: bound("min_pair_recall", true),
    }
}
