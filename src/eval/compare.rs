//! A stress run compared with a baseline run (`check --baseline BASE.json`, `compare BASE NEW`):
//! per scenario × subject × metric, how the figures moved and whether that is a regression.
//!
//! **Pairing.** When every compared seed has the same simulation key in both reports
//! (`eval::provenance`), both sides recognized the very same laps at each seed, so the per-seed
//! difference is the recognizer's change alone: the comparison is *paired by seed*. When a key
//! differs (the world, scenario or simulator changed), the laps differ and seeds mean nothing
//! to each other: the two sets of seeds are compared as two samples (*unpaired*), and the
//! comparison says so in words.
//!
//! **Per metric** (precision, recall, visit recall, pair recall: differences new − baseline;
//! seconds per lap, CPU: ratios new / baseline): the mean and worst-seed change, the seeds that
//! got worse (and those worse beyond the tolerance), and a decision:
//!
//! - *identical*: every seed's figure is the same number on both sides; no test is needed;
//! - *regression*: worse by more than the tolerance with confidence: the one-sided Wilcoxon
//!   signed-rank test (exact, `eval::rank_test`) of the per-seed changes shifted by the
//!   tolerance gives p < [`ALPHA`] (unpaired: the Mann–Whitney test of the shifted samples).
//!   With fewer seeds than the test can ever be sure of ([`MIN_PAIRED_SEEDS`]) a paired metric
//!   is a regression when every seed is worse beyond the tolerance (its laps are the same, so
//!   each seed's change is exact, not noise);
//! - *improvement*: the same, the other way;
//! - *no change*: neither (within the tolerance, or not sure).
//!
//! The tolerance is `[expect.regression]` of the new run's scenario (`max_drop`,
//! `max_slowdown`), defaults 0.003 and 1.5, which the command line may override. Times are
//! compared as log ratios, so `max_slowdown = 1.5` reads "50 % more CPU time per lap".

use crate::eval::distribution::Metric;
use crate::eval::provenance::REPORT_VERSION;
use crate::eval::rank_test::{rank_sum_greater, signed_rank_greater};
use crate::eval::scores::Report;
use crate::eval::suite::{ScenarioResult, SuiteReport, reproduce_command};
use crate::spec::evaluation::RegressionSpec;
use serde::{Deserialize, Serialize};

/// The significance level of the decision: a change is called only when a change as large
/// would be seen by chance less often than this.
pub const ALPHA: f64 = 0.05;

/// The fewest seeds at which the one-sided signed-rank test can reach [`ALPHA`] (1/2⁵ < 0.05).
pub const MIN_PAIRED_SEEDS: usize = 5;

/// Command-line overrides of `[expect.regression]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ToleranceOverride {
    pub max_drop: Option<f64>,
    pub max_slowdown: Option<f64>,
}

impl ToleranceOverride {
    /// The scenario's tolerance (or the default) with these overrides.
    pub fn apply(&self, spec: Option<RegressionSpec>) -> RegressionSpec {
        let base = spec.unwrap_or_default();
        RegressionSpec {
            max_drop: self.max_drop.unwrap_or(base.max_drop),
            max_slowdown: self.max_slowdown.unwrap_or(base.max_slowdown),
        }
    }
}

/// What a metric's comparison concluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decision {
    /// The same number at every seed.
    Identical,
    /// Within the tolerance, or not sure.
    NoChange,
    /// Worse beyond the tolerance, with confidence.
    Regression,
    /// Better beyond the tolerance, with confidence.
    Improvement,
}

/// How a metric's decision was reached (`report::compare` words it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    /// The same figure at every seed: no test needed.
    SameAtEverySeed,
    /// Paired with fewer seeds than [`MIN_PAIRED_SEEDS`], too few for the signed-rank test to
    /// reach [`ALPHA`]: decided on every seed being beyond the tolerance.
    EverySeedBeyond,
    /// The exact one-sided Wilcoxon signed-rank test of the per-seed changes (paired).
    SignedRank,
    /// The one-sided Mann–Whitney test of the two samples (not paired).
    RankSum,
}

/// An input file whose content hash differs between the two reports.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ChangedInput {
    /// `world` or `scenario`.
    pub role: String,
    /// The new report's file name.
    pub name: String,
}

/// Something of a scenario that was not compared.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum NotCompared {
    /// These seeds failed in the new run (the gate reports them).
    FailedSeeds { seeds: Vec<u64> },
    /// The subject is missing from some seed of the baseline.
    SubjectNotInBaseline { subject: String },
    /// No seed has the figure on both sides (no matches).
    NoFigure { subject: String, metric: Metric },
}

/// One metric of one subject of one scenario, new against baseline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct MetricComparison {
    pub scenario: String,
    pub subject: String,
    pub metric: Metric,
    /// Paired by seed (same laps) or two samples.
    pub paired: bool,
    /// Seeds compared (both sides have the figure).
    pub seeds: Vec<u64>,
    pub base_mean: f64,
    pub new_mean: f64,
    pub base_worst: f64,
    pub base_worst_seed: u64,
    pub new_worst: f64,
    pub new_worst_seed: u64,
    /// Mean change: new − baseline, or for time new / baseline.
    pub mean_change: f64,
    /// Worst-seed change (each side's worst seed): new − baseline, or for time a ratio.
    pub worst_change: f64,
    /// Paired: the seed whose figure got most worse (none when no seed got worse).
    pub most_worse_seed: Option<u64>,
    /// Paired: the seeds whose figure got worse at all.
    pub worse_seeds: Vec<u64>,
    /// Paired: the seeds worse by more than the tolerance.
    pub beyond_seeds: Vec<u64>,
    /// The tolerance: `max_drop`, or `max_slowdown` for time.
    pub tolerance: f64,
    /// The test's one-sided p-value for "worse beyond the tolerance" (`None`: no test needed
    /// or possible).
    pub p_worse: Option<f64>,
    /// The same for "better beyond the tolerance".
    pub p_better: Option<f64>,
    pub decision: Decision,
    /// How the decision was reached.
    pub basis: Basis,
    /// Seeds left out because one side has no figure (no matches).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out_seeds: Vec<u64>,
}

impl MetricComparison {
    /// The test case name: `B/words-3/precision/vs-baseline`.
    pub fn name(&self) -> String {
        format!(
            "{}/{}/{}/vs-baseline",
            self.scenario,
            self.subject,
            self.metric.name()
        )
    }

    /// Whether the metric is a time (changes are ratios).
    pub fn is_time(&self) -> bool {
        !self.metric.higher_is_better()
    }
}

/// One scenario of the new run against the baseline's scenario of the same name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ScenarioComparison {
    pub label: String,
    /// The new run's scenario file.
    pub file: String,
    /// The baseline's scenario file.
    pub base_file: String,
    /// Each side's flags for a reproducing command (`ScenarioResult::reproduce_flags`).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reproduce_flags: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub base_reproduce_flags: String,
    /// Paired by seed: no compared seed's simulation keys differ.
    pub paired: bool,
    /// The seeds compared.
    pub seeds: Vec<u64>,
    /// The seeds whose simulation keys differ (empty when paired).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub differing_seeds: Vec<u64>,
    /// The world and scenario files whose content differs (when not paired).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub changed_inputs: Vec<ChangedInput>,
    pub tolerance: RegressionSpec,
    pub metrics: Vec<MetricComparison>,
    /// What was not compared and why (a subject only one side ran).
    pub not_compared: Vec<NotCompared>,
}

impl ScenarioComparison {
    /// The commands reproducing `seed` on each side: `(new, baseline)`, the baseline's run at
    /// the baseline's build.
    pub fn reproduce(&self, seed: u64, base_commit: &str) -> (String, String) {
        (
            reproduce_command(&self.file, seed, &self.reproduce_flags),
            format!(
                "{}  # at the baseline's commit {base_commit}",
                reproduce_command(&self.base_file, seed, &self.base_reproduce_flags)
            ),
        )
    }
}

/// A new run against a baseline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Comparison {
    /// The baseline file.
    pub base: String,
    /// The baseline's tool version and the commit it was built from.
    pub base_version: String,
    pub base_commit: String,
    pub scenarios: Vec<ScenarioComparison>,
}

impl Comparison {
    pub fn metrics(&self) -> impl Iterator<Item = &MetricComparison> + '_ {
        self.scenarios.iter().flat_map(|s| &s.metrics)
    }

    pub fn count(&self, d: Decision) -> usize {
        self.metrics().filter(|m| m.decision == d).count()
    }

    /// 1 when any metric regressed, else 0.
    pub fn exit_code(&self) -> u8 {
        u8::from(self.count(Decision::Regression) > 0)
    }
}

/// Why a baseline cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error(
        "{file} was written with report_version {found}, this placewords reads \
         {REPORT_VERSION}; make the baseline again with this placewords"
    )]
    OtherReportVersion { file: String, found: u32 },
    #[error("{file} is one part of a sharded run; merge the parts first (`placewords merge`)")]
    Part { file: String },
    #[error(
        "scenario {label} is not in the baseline {file} (it holds {held}); make the baseline \
         with the same scenarios"
    )]
    MissingScenario {
        label: String,
        file: String,
        held: String,
    },
    #[error(
        "{label} seed {seed} is not in the baseline {file} (it holds seeds {held}); make the \
         baseline with --seeds covering the new run's"
    )]
    MissingSeed {
        label: String,
        seed: u64,
        file: String,
        held: String,
    },
    #[error("{label} seed {seed} failed in {file}, so there is nothing to compare: {why}")]
    FailedSeed {
        label: String,
        seed: u64,
        file: String,
        why: String,
    },
}

/// Compares `new` with `base` (read from `base_file`, `new_file` for messages).
pub fn compare(
    base_file: &str,
    base: &SuiteReport,
    new_file: &str,
    new: &SuiteReport,
    overrides: ToleranceOverride,
) -> Result<Comparison, CompareError> {
    for (file, r) in [(base_file, base), (new_file, new)] {
        if r.provenance.report_version != REPORT_VERSION {
            return Err(CompareError::OtherReportVersion {
                file: file.to_string(),
                found: r.provenance.report_version,
            });
        }
        if r.shard.is_some() {
            return Err(CompareError::Part {
                file: file.to_string(),
            });
        }
    }
    let mut scenarios = Vec::new();
    for sc in new.scenarios.iter().filter(|s| s.error.is_none()) {
        let b = find_scenario(base, sc).ok_or_else(|| CompareError::MissingScenario {
            label: sc.label.clone(),
            file: base_file.to_string(),
            held: base
                .scenarios
                .iter()
                .map(|s| s.label.clone())
                .collect::<Vec<_>>()
                .join(", "),
        })?;
        let tolerance = overrides.apply(sc.expect.regression);
        scenarios.push(compare_scenario((base_file, b), sc, base, new, tolerance)?);
    }
    let p = &base.provenance;
    Ok(Comparison {
        base: base_file.to_string(),
        base_version: p.version.clone(),
        base_commit: p.commit.clone(),
        scenarios,
    })
}

/// The baseline's scenario of `sc`'s label, else of its name when only one has it.
fn find_scenario<'a>(base: &'a SuiteReport, sc: &ScenarioResult) -> Option<&'a ScenarioResult> {
    let usable = |s: &&ScenarioResult| s.error.is_none();
    base.scenarios
        .iter()
        .filter(usable)
        .find(|s| s.label == sc.label)
        .or_else(|| {
            let mut same = base
                .scenarios
                .iter()
                .filter(usable)
                .filter(|s| s.name == sc.name);
            match (same.next(), same.next()) {
                (Some(s), None) => Some(s),
                _ => None,
            }
        })
}

/// Each seed of `sc` that ran with the baseline's report of the same seed.
fn seed_pairs<'a>(
    (base_file, b): (&str, &'a ScenarioResult),
    sc: &'a ScenarioResult,
) -> Result<Vec<(u64, &'a Report, &'a Report, bool)>, CompareError> {
    let mut out = Vec::new();
    // A seed that failed in the new run is an error of the run itself (the gate reports it,
    // exit 2); the comparison goes on without it.
    for r in &sc.results {
        let Some(nr) = &r.report else {
            continue;
        };
        let Some(br) = b.results.iter().find(|x| x.seed == r.seed) else {
            return Err(CompareError::MissingSeed {
                label: sc.label.clone(),
                seed: r.seed,
                file: base_file.to_string(),
                held: b.seeds.to_string(),
            });
        };
        let Some(brep) = &br.report else {
            return Err(CompareError::FailedSeed {
                label: sc.label.clone(),
                seed: r.seed,
                file: base_file.to_string(),
                why: br.error.clone().unwrap_or_default(),
            });
        };
        let same_laps = !r.simulation_key.is_empty() && r.simulation_key == br.simulation_key;
        out.push((r.seed, brep, nr, same_laps));
    }
    Ok(out)
}

fn compare_scenario(
    (base_file, b): (&str, &ScenarioResult),
    sc: &ScenarioResult,
    base: &SuiteReport,
    new: &SuiteReport,
    tolerance: RegressionSpec,
) -> Result<ScenarioComparison, CompareError> {
    let pairs = seed_pairs((base_file, b), sc)?;
    let failed: Vec<u64> = sc
        .results
        .iter()
        .filter(|r| r.report.is_none())
        .map(|r| r.seed)
        .collect();
    let differ: Vec<u64> = pairs.iter().filter(|p| !p.3).map(|p| p.0).collect();
    let paired = differ.is_empty();
    let seeds: Vec<u64> = pairs.iter().map(|p| p.0).collect();
    let changed_inputs = if paired {
        Vec::new()
    } else {
        changed_inputs(base, new)
    };
    let mut subjects: Vec<String> = Vec::new();
    for (_, _, nr, _) in &pairs {
        for s in &nr.subjects {
            if !subjects.contains(&s.name) {
                subjects.push(s.name.clone());
            }
        }
    }
    let mut metrics = Vec::new();
    let mut not_compared = Vec::new();
    if !failed.is_empty() {
        not_compared.push(NotCompared::FailedSeeds { seeds: failed });
    }
    for subject in &subjects {
        if pairs
            .iter()
            .any(|(_, br, _, _)| br.subject(subject).is_none())
        {
            not_compared.push(NotCompared::SubjectNotInBaseline {
                subject: subject.clone(),
            });
            continue;
        }
        for metric in Metric::ALL {
            let mut values = Vec::new();
            let mut skipped = Vec::new();
            for (seed, br, nr, _) in &pairs {
                let bv = br.subject(subject).and_then(|s| metric.of(&s.scores));
                let nv = nr.subject(subject).and_then(|s| metric.of(&s.scores));
                match (bv, nv) {
                    (Some(bv), Some(nv)) => values.push((*seed, bv, nv)),
                    _ => skipped.push(*seed),
                }
            }
            if values.is_empty() {
                not_compared.push(NotCompared::NoFigure {
                    subject: subject.clone(),
                    metric,
                });
                continue;
            }
            let mut m = compare_metric(&sc.label, subject, metric, paired, &values, tolerance);
            m.left_out_seeds = skipped;
            metrics.push(m);
        }
    }
    Ok(ScenarioComparison {
        label: sc.label.clone(),
        file: sc.file.clone(),
        base_file: b.file.clone(),
        reproduce_flags: sc.reproduce_flags.clone(),
        base_reproduce_flags: b.reproduce_flags.clone(),
        paired,
        seeds,
        differing_seeds: differ,
        changed_inputs,
        tolerance,
        metrics,
        not_compared,
    })
}

/// The world and scenario files whose content hashes differ between the reports.
fn changed_inputs(base: &SuiteReport, new: &SuiteReport) -> Vec<ChangedInput> {
    let mut changed = Vec::new();
    for role in ["world", "scenario"] {
        for n in new.provenance.inputs_of(role) {
            let same_name = base
                .provenance
                .inputs_of(role)
                .find(|b| b.name == n.name)
                .or_else(|| base.provenance.inputs_of(role).next());
            if let Some(b) = same_name
                && b.blake3 != n.blake3
            {
                changed.push(ChangedInput {
                    role: role.to_string(),
                    name: n.name.clone(),
                });
            }
        }
    }
    changed
}

/// One metric over `values` = (seed, baseline, new).
fn compare_metric(
    scenario: &str,
    subject: &str,
    metric: Metric,
    paired: bool,
    values: &[(u64, f64, f64)],
    tol: RegressionSpec,
) -> MetricComparison {
    let time = !metric.higher_is_better();
    // Changes on a scale where larger is better and the tolerance is `slack`.
    let slack = if time {
        tol.max_slowdown.ln()
    } else {
        tol.max_drop
    };
    let mut m = undecided(scenario, subject, metric, paired, values, tol);
    if values.iter().all(|v| v.1 == v.2) {
        m.decision = Decision::Identical;
        m.basis = Basis::SameAtEverySeed;
        return m;
    }
    if paired {
        if let Some(decided) = signed_rank_test(&mut m, values, time, slack) {
            m.decision = decided;
            return m;
        }
    } else {
        rank_sum_test(&mut m, values, time, slack);
    }
    m.decision = match (m.p_worse, m.p_better) {
        (Some(p), _) if p < ALPHA => Decision::Regression,
        (_, Some(p)) if p < ALPHA => Decision::Improvement,
        _ => Decision::NoChange,
    };
    m
}

/// The comparison of one metric over `values` = (seed, baseline, new) with its means, worst
/// seeds and changes, before any test (no change decided).
fn undecided(
    scenario: &str,
    subject: &str,
    metric: Metric,
    paired: bool,
    values: &[(u64, f64, f64)],
    tol: RegressionSpec,
) -> MetricComparison {
    let time = !metric.higher_is_better();
    let tolerance = if time { tol.max_slowdown } else { tol.max_drop };
    let base: Vec<(u64, f64)> = values.iter().map(|v| (v.0, v.1)).collect();
    let new: Vec<(u64, f64)> = values.iter().map(|v| (v.0, v.2)).collect();
    let (base_mean, base_worst_seed, base_worst) = mean_worst(&base, time);
    let (new_mean, new_worst_seed, new_worst) = mean_worst(&new, time);
    let change = |b: f64, n: f64| if time { n / b } else { n - b };
    MetricComparison {
        scenario: scenario.to_string(),
        subject: subject.to_string(),
        metric,
        paired,
        seeds: values.iter().map(|v| v.0).collect(),
        base_mean,
        new_mean,
        base_worst,
        base_worst_seed,
        new_worst,
        new_worst_seed,
        mean_change: change(base_mean, new_mean),
        worst_change: change(base_worst, new_worst),
        most_worse_seed: None,
        worse_seeds: Vec::new(),
        beyond_seeds: Vec::new(),
        tolerance,
        p_worse: None,
        p_better: None,
        decision: Decision::NoChange,
        basis: if paired {
            Basis::SignedRank
        } else {
            Basis::RankSum
        },
        left_out_seeds: Vec::new(),
    }
}

/// The paired test of `m` (Wilcoxon signed-rank on each seed's change beyond `slack`), with
/// the seeds that got worse; `Some` decision when there are too few seeds for the test (then
/// every seed must be beyond the tolerance).
fn signed_rank_test(
    m: &mut MetricComparison,
    values: &[(u64, f64, f64)],
    time: bool,
    slack: f64,
) -> Option<Decision> {
    let better = |b: f64, n: f64| if time { (b / n).ln() } else { n - b };
    let n = values.len();
    let g: Vec<(u64, f64)> = values
        .iter()
        .map(|&(s, b, nv)| (s, better(b, nv)))
        .filter(|(_, x)| x.is_finite())
        .collect();
    m.worse_seeds = g.iter().filter(|x| x.1 < 0.0).map(|x| x.0).collect();
    m.beyond_seeds = g.iter().filter(|x| x.1 < -slack).map(|x| x.0).collect();
    m.most_worse_seed = g
        .iter()
        .filter(|x| x.1 < 0.0)
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map(|x| x.0);
    let worse: Vec<f64> = g.iter().map(|x| -x.1 - slack).collect();
    let gain: Vec<f64> = g.iter().map(|x| x.1 - slack).collect();
    m.p_worse = signed_rank_greater(&worse);
    m.p_better = signed_rank_greater(&gain);
    if n < MIN_PAIRED_SEEDS {
        let all = |v: &[f64]| v.iter().all(|x| *x > 0.0);
        m.basis = Basis::EverySeedBeyond;
        return Some(if all(&worse) {
            Decision::Regression
        } else if all(&gain) {
            Decision::Improvement
        } else {
            Decision::NoChange
        });
    }
    m.basis = Basis::SignedRank;
    None
}

/// The two-sample test of `m` (Mann–Whitney, the new values shifted by `slack`), for seeds
/// that did not run the same laps; times compared on a log scale.
fn rank_sum_test(m: &mut MetricComparison, values: &[(u64, f64, f64)], time: bool, slack: f64) {
    let (b, nv): (Vec<f64>, Vec<f64>) = if time {
        (
            values.iter().map(|v| -v.1.ln()).collect(),
            values.iter().map(|v| -v.2.ln()).collect(),
        )
    } else {
        (
            values.iter().map(|v| v.1).collect(),
            values.iter().map(|v| v.2).collect(),
        )
    };
    let shift = |v: &[f64], by: f64| v.iter().map(|x| x + by).collect::<Vec<_>>();
    m.p_worse = rank_sum_greater(&b, &shift(&nv, slack));
    m.p_better = rank_sum_greater(&shift(&nv, -slack), &b);
    m.basis = Basis::RankSum;
}

/// Mean, and the worst seed and its value.
fn mean_worst(v: &[(u64, f64)], time: bool) -> (f64, u64, f64) {
    let mean = v.iter().map(|x| x.1).sum::<f64>() / v.len() as f64;
    let (seed, worst) =
        crate::eval::distribution::quantile(v, 0.0, !time).expect("at least one value");
    (mean, seed, worst)
}

/// `[1, 2, 3]`, or `1..10` for a run of consecutive seeds.
pub fn seed_list(seeds: &[u64]) -> String {
    match seeds {
        [] => "none".into(),
        [a, .., b] if seeds.windows(2).all(|w| w[1] == w[0] + 1) && seeds.len() > 2 => {
            format!("{a}..{b}")
        }
        _ => format!(
            "[{}]",
            seeds
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(base: &[f64], new: &[f64]) -> Vec<(u64, f64, f64)> {
        base.iter()
            .zip(new)
            .enumerate()
            .map(|(i, (b, n))| (i as u64 + 1, *b, *n))
            .collect()
    }

    #[test]
    fn identical_figures_need_no_test() {
        let v = values(&[0.9, 0.95, 0.97], &[0.9, 0.95, 0.97]);
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Precision,
            true,
            &v,
            Default::default(),
        );
        assert_eq!(m.decision, Decision::Identical);
        assert_eq!(m.p_worse, None);
        assert_eq!(m.name(), "B/words-3/precision/vs-baseline");
    }

    #[test]
    fn a_drop_beyond_the_tolerance_at_most_seeds_is_a_regression() {
        let base = [0.99, 0.98, 0.97, 0.99, 0.96, 0.98, 0.99, 0.97, 0.98, 0.99];
        let new: Vec<f64> = base.iter().map(|b| b - 0.02).collect();
        let v = values(&base, &new);
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Precision,
            true,
            &v,
            Default::default(),
        );
        assert_eq!(m.decision, Decision::Regression, "{m:?}");
        assert_eq!(m.worse_seeds.len(), 10);
        assert!((m.mean_change + 0.02).abs() < 1e-9);
        // A drop within the tolerance (`max_drop`, 0.003 by default) is no change; a rise
        // beyond it an improvement.
        let small: Vec<f64> = base.iter().map(|b| b - 0.002).collect();
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Precision,
            true,
            &values(&base, &small),
            Default::default(),
        );
        assert_eq!(m.decision, Decision::NoChange);
        let up: Vec<f64> = base.iter().map(|b| b - 0.5).collect();
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Recall,
            true,
            &values(&up, &base),
            Default::default(),
        );
        assert_eq!(m.decision, Decision::Improvement);
    }

    #[test]
    fn time_is_compared_as_a_ratio_against_max_slowdown() {
        let base: Vec<f64> = (0..10).map(|i| 0.1 + 0.01 * i as f64).collect();
        let loaded: Vec<f64> = base.iter().map(|b| b * 1.3).collect();
        let v = values(&base, &loaded);
        let tol = RegressionSpec::default();
        let m = compare_metric("B", "words-3", Metric::SecondsPerLap, true, &v, tol);
        assert_eq!(m.decision, Decision::NoChange, "{m:?}");
        assert!((m.mean_change - 1.3).abs() < 1e-9);
        let slow: Vec<f64> = base.iter().map(|b| b * 2.0).collect();
        let m = compare_metric(
            "B",
            "words-3",
            Metric::SecondsPerLap,
            true,
            &values(&base, &slow),
            tol,
        );
        assert_eq!(m.decision, Decision::Regression);
        let m = compare_metric(
            "B",
            "words-3",
            Metric::SecondsPerLap,
            false,
            &values(&base, &slow),
            tol,
        );
        assert_eq!(m.decision, Decision::Regression, "{m:?}");
    }

    #[test]
    fn few_seeds_decide_on_every_seed() {
        let v = values(&[0.9, 0.9], &[0.85, 0.898]);
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Precision,
            true,
            &v,
            Default::default(),
        );
        assert_eq!(m.decision, Decision::NoChange);
        assert_eq!(
            (m.worse_seeds.clone(), m.beyond_seeds.clone()),
            (vec![1, 2], vec![1])
        );
        assert_eq!(m.most_worse_seed, Some(1));
        let v = values(&[0.9, 0.9], &[0.85, 0.88]);
        let m = compare_metric(
            "B",
            "words-3",
            Metric::Precision,
            true,
            &v,
            Default::default(),
        );
        assert_eq!(m.decision, Decision::Regression);
        assert_eq!(m.basis, Basis::EverySeedBeyond);
    }

    #[test]
    fn seed_lists_read_short() {
        assert_eq!(seed_list(&[1, 2, 3, 4]), "1..4");
        assert_eq!(seed_list(&[1, 3]), "[1, 3]");
        assert_eq!(seed_list(&[]), "none");
    }
}
