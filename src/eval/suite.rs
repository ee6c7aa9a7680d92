//! The results of a stress run: scenarios × seeds, each seed's report, the figures over seeds
//! (`eval::distribution`) and the gate's outcomes; and the merge of the parts a sharded run
//! wrote into the result an unsharded run would have given.
//!
//! A part (`check --shard K/N --report PART.json`) holds the whole plan (every scenario, its
//! seeds and its `[expect]`) and the results of its own seeds; [`merge`] checks that parts
//! 1..N of one plan are all there, joins their seeds, and computes figures and outcomes once.

use crate::eval::distribution::{self, ConfigSpread};
use crate::eval::gate::{self, Outcome};
use crate::eval::provenance::{self, Provenance, REPORT_VERSION};
use crate::eval::scores::Report;
use crate::spec::evaluation::ExpectSpec;
use crate::spec::seeds::{SeedRange, Shard};
use serde::{Deserialize, Serialize};

/// The format tag of a suite report file.
pub const FORMAT: &str = "placewords-suite/1";

/// One seed of one scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeedResult {
    pub seed: u64,
    /// Wall-clock seconds the seed took (simulation, recognition, evaluation).
    pub seconds: f64,
    /// The report, or `None` when the seed failed (see `error`).
    pub report: Option<Report>,
    pub error: Option<String>,
    /// The seed's simulation key (`eval::provenance`): equal keys, equal laps. Empty when read
    /// from a report older than provenance.
    #[serde(default)]
    pub simulation_key: String,
    /// With `--cache`: whether the seed's laps came from the lap cache (absent without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lap_cache: Option<provenance::LapSource>,
}

/// One scenario over its seeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScenarioResult {
    /// How outputs name the scenario: its name, followed by its file when another scenario of
    /// the run has the same name (`B (scenarios/B.toml)`).
    pub label: String,
    pub name: String,
    /// The scenario file, as given on the command line.
    pub file: String,
    /// Every seed of the plan (a shard runs only some of them).
    pub seeds: SeedRange,
    /// The flags a command reproducing one of its seeds needs besides the file and seed: the
    /// baselines run (`--icp`, `--scan-context`) and the external subjects given by flag
    /// (`--recognizer NAME=exec:…`); a scenario's own `[[subjects]]` come with it. Empty for
    /// none (and in a report written before it).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reproduce_flags: String,
    pub expect: ExpectSpec,
    /// Why the scenario could not be run at all.
    pub error: Option<String>,
    /// This run's seeds, in increasing order.
    pub results: Vec<SeedResult>,
    /// Figures over the seeds (empty in a part).
    pub summary: Vec<ConfigSpread>,
    /// The gate (empty in a part, and for `run`).
    pub outcomes: Vec<Outcome>,
}

impl ScenarioResult {
    /// The reports of the seeds that ran.
    pub fn reports(&self) -> Vec<Report> {
        self.results
            .iter()
            .filter_map(|r| r.report.clone())
            .collect()
    }

    /// Wall-clock seconds over all seeds.
    pub fn seconds(&self) -> f64 {
        self.results.iter().map(|r| r.seconds).sum()
    }

    /// The command that reproduces `seed` of this scenario.
    pub fn reproduce(&self, seed: u64) -> String {
        reproduce_command(&self.file, seed, &self.reproduce_flags)
    }

    /// Every problem of the scenario: its own error, then each failed seed's.
    pub fn errors(&self) -> Vec<String> {
        let seeds = self.results.iter().filter_map(|r| {
            r.error
                .as_ref()
                .map(|e| format!("{} seed {}: {e}", self.file, r.seed))
        });
        self.error.iter().cloned().chain(seeds).collect()
    }
}

/// `placewords run FILE --seed N FLAGS` (the file quoted when it holds a space or a quote;
/// `flags` already quoted, as [`ScenarioResult::reproduce_flags`]).
pub fn reproduce_command(file: &str, seed: u64, flags: &str) -> String {
    let file = if file.contains([' ', '\'', '"', '$']) {
        format!("'{}'", file.replace('\'', r"'\''"))
    } else {
        file.to_string()
    };
    if flags.is_empty() {
        format!("placewords run {file} --seed {seed}")
    } else {
        format!("placewords run {file} --seed {seed} {flags}")
    }
}

/// A stress run, or one part of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SuiteReport {
    /// [`FORMAT`].
    pub format: String,
    /// The part this file holds; `None` for a whole run.
    pub shard: Option<Shard>,
    /// Whether the `[expect]` blocks are checked (`check`, `merge`) or not (`run`).
    pub gated: bool,
    pub scenarios: Vec<ScenarioResult>,
    /// Wall-clock seconds of the whole run, start to end (for a merge, its longest part's:
    /// parts run side by side). 0 when read from an older report.
    #[serde(default)]
    pub wall_seconds: f64,
    /// What made it (`eval::provenance`); `report_version` 0 when read from an older report.
    #[serde(default)]
    pub provenance: Provenance,
}

/// What a suite amounts to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    pub passed: usize,
    pub failed: usize,
    /// Scenarios that could not be run plus seeds that failed.
    pub errors: usize,
}

impl SuiteReport {
    /// A suite of `scenarios` whose figures (and, if `gated` and whole, outcomes) are computed.
    pub fn new(shard: Option<Shard>, gated: bool, scenarios: Vec<ScenarioResult>) -> Self {
        let mut s = SuiteReport {
            format: FORMAT.into(),
            shard,
            gated,
            scenarios,
            wall_seconds: 0.0,
            provenance: Provenance::default(),
        };
        s.finish();
        s
    }

    /// Computes figures and outcomes from the seeds' reports (a part gets neither: its seeds
    /// are not the distribution).
    fn finish(&mut self) {
        for sc in &mut self.scenarios {
            sc.results.sort_by_key(|r| r.seed);
            let reports = sc.reports();
            let whole = self.shard.is_none();
            sc.summary = if whole {
                distribution::summarize(&reports)
            } else {
                Vec::new()
            };
            sc.outcomes = if whole && self.gated && sc.error.is_none() {
                gate::check_seeds(&sc.label, &reports, &sc.expect)
            } else {
                Vec::new()
            };
            // No seed ran to the end: each bound says why instead of "not in the report".
            if reports.is_empty()
                && let Some(why) = sc.results.iter().find_map(|r| r.error.as_deref())
            {
                let why = why.lines().next().unwrap_or(why);
                for o in &mut sc.outcomes {
                    o.missing = Some(gate::Missing::EverySeedFailed {
                        error: why.to_string(),
                    });
                }
            }
        }
    }

    /// Outcomes passed and failed, and errors.
    pub fn tally(&self) -> Tally {
        let outcomes = self.scenarios.iter().flat_map(|s| &s.outcomes);
        let passed = outcomes.clone().filter(|o| o.passed).count();
        let failed = outcomes.count() - passed;
        let errors = self.scenarios.iter().map(|s| s.errors().len()).sum();
        Tally {
            passed,
            failed,
            errors,
        }
    }

    /// The exit code of `check` and `merge`: the tally's for a whole run; a part exits 0
    /// unless something failed to run (2), since its seeds are not the distribution.
    pub fn exit_code(&self) -> u8 {
        let errors = self.tally().errors;
        match self.shard {
            Some(_) => gate::gate_exit_code(errors, []),
            None => gate::gate_exit_code(errors, self.scenarios.iter().flat_map(|s| &s.outcomes)),
        }
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a suite report always serializes")
    }

    /// Every seed's report, scenario by scenario (the seeds that ran).
    pub fn reports(&self) -> impl Iterator<Item = &Report> + '_ {
        self.scenarios
            .iter()
            .flat_map(|s| &s.results)
            .filter_map(|r| r.report.as_ref())
    }

    pub fn from_json(s: &str) -> serde_json::Result<Self> {
        serde_json::from_str(s)
    }
}

/// Labels for scenarios given as (name, file): the name, or `name (file)` when another
/// scenario has the same name.
pub fn labels(scenarios: &[(String, String)]) -> Vec<String> {
    scenarios
        .iter()
        .map(|(name, file)| {
            let twins = scenarios.iter().filter(|(n, _)| n == name).count();
            if twins > 1 {
                format!("{name} ({file})")
            } else {
                name.clone()
            }
        })
        .collect()
}

/// Why parts cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    #[error("no parts to merge; give the PART.json files of every shard")]
    NoParts,
    #[error(
        "{0} is a whole run, not a part; merge takes the files of `check --shard K/N --report`"
    )]
    NotAPart(String),
    #[error("{file} is part {shard}, but {first} is a part of {count}; merge the parts of one run")]
    OtherCount {
        file: String,
        shard: Shard,
        first: String,
        count: usize,
    },
    #[error("part {0} is given twice ({1} and {2})")]
    Twice(Shard, String, String),
    #[error("part {index}/{count} is missing; give every part 1..{count}")]
    Missing { index: usize, count: usize },
    #[error(
        "{file} was planned with other scenarios, seeds or [expect] than {first}; \
         run every shard with the same arguments"
    )]
    OtherPlan { file: String, first: String },
    #[error("{label} seed {seed} is in {n} parts; run every shard with the same arguments")]
    SeedTwice { label: String, seed: u64, n: usize },
    #[error(
        "{file} was written with report_version {found}, this placewords reads \
         {REPORT_VERSION}; make every part with one placewords"
    )]
    OtherReportVersion { file: String, found: u32 },
    #[error(
        "{file} (part {shard}) was made by placewords {build}, but {first} by {first_build}; \
         make every part with one build"
    )]
    OtherBuild {
        file: String,
        shard: Shard,
        /// `0.1.0 at commit …`.
        build: String,
        first: String,
        first_build: String,
    },
    #[error(
        "{file} (part {shard}) was made from other inputs than {first}: {input} differs \
         ({hashes}); the input changed between the shards, run every shard on the same files"
    )]
    OtherInputs {
        file: String,
        shard: Shard,
        first: String,
        input: String,
        /// `blake3 1a2b… against 3c4d…`.
        hashes: String,
    },
    #[error(
        "{file} (part {shard}) holds {label} seeds {got}, but part {shard} of its plan runs \
         seeds {want}; run every shard with the same arguments"
    )]
    OtherSeeds {
        file: String,
        shard: Shard,
        label: String,
        got: String,
        want: String,
    },
}

/// Joins parts (with the files they came from, for messages) into the whole run's suite.
pub fn merge(parts: Vec<(String, SuiteReport)>) -> Result<SuiteReport, MergeError> {
    check_parts(&parts)?;
    let first = &parts[0].1;
    let mut scenarios = first.scenarios.clone();
    for (i, sc) in scenarios.iter_mut().enumerate() {
        sc.results = parts
            .iter()
            .flat_map(|(_, p)| p.scenarios[i].results.iter().cloned())
            .collect();
        sc.results.sort_by_key(|r| r.seed);
        if let Some(w) = sc.results.windows(2).find(|w| w[0].seed == w[1].seed) {
            let n = sc.results.iter().filter(|r| r.seed == w[0].seed).count();
            return Err(MergeError::SeedTwice {
                label: sc.label.clone(),
                seed: w[0].seed,
                n,
            });
        }
    }
    let mut whole = SuiteReport::new(None, first.gated, scenarios);
    whole.wall_seconds = parts
        .iter()
        .map(|(_, p)| p.wall_seconds)
        .fold(0.0, f64::max);
    // The figures are the parts' (one build, one set of inputs, checked above): their
    // version, commit and inputs; the caller adds its command line and the part files.
    whole.provenance = Provenance {
        command_line: Vec::new(),
        seeds: Vec::new(),
        ..first.provenance.clone()
    };
    whole.provenance.lap_cache = None;
    for (_, p) in &parts {
        whole
            .provenance
            .add_seeds(p.provenance.seeds.iter().copied());
        if let Some(c) = &p.provenance.lap_cache {
            whole
                .provenance
                .lap_cache
                .get_or_insert_with(|| provenance::LapCacheUse {
                    dir: c.dir.clone(),
                    ..Default::default()
                })
                .add(c);
        }
    }
    Ok(whole)
}

/// Checks that `parts` are parts 1..N of one plan, each once.
fn check_parts(parts: &[(String, SuiteReport)]) -> Result<(), MergeError> {
    let (first_file, first) = parts.first().ok_or(MergeError::NoParts)?;
    let count = first
        .shard
        .ok_or_else(|| MergeError::NotAPart(first_file.clone()))?
        .count;
    let mut seen: Vec<Option<&String>> = vec![None; count];
    for (file, part) in parts {
        let shard = part
            .shard
            .ok_or_else(|| MergeError::NotAPart(file.clone()))?;
        if shard.count != count {
            return Err(MergeError::OtherCount {
                file: file.clone(),
                shard,
                first: first_file.clone(),
                count,
            });
        }
        if let Some(other) = seen[shard.index - 1] {
            return Err(MergeError::Twice(shard, other.clone(), file.clone()));
        }
        seen[shard.index - 1] = Some(file);
        if !same_plan(first, part) {
            return Err(MergeError::OtherPlan {
                file: file.clone(),
                first: first_file.clone(),
            });
        }
        check_seeds(file, shard, part)?;
        check_provenance(file, shard, part, first_file, first)?;
    }
    match seen.iter().position(Option::is_none) {
        Some(i) => Err(MergeError::Missing {
            index: i + 1,
            count,
        }),
        None => Ok(()),
    }
}

/// Checks that a part holds exactly the seeds its shard owns in its plan: the plan's work
/// items are every runnable scenario's seeds in order, dealt round-robin (`Shard::owns`).
fn check_seeds(file: &str, shard: Shard, part: &SuiteReport) -> Result<(), MergeError> {
    let mut item = 0;
    for sc in &part.scenarios {
        let runnable = sc.error.is_none() && (!part.gated || !sc.expect.is_empty());
        let want: Vec<u64> = if runnable {
            let seeds: Vec<u64> = sc.seeds.seeds().collect();
            let owned = seeds
                .iter()
                .enumerate()
                .filter(|(k, _)| shard.owns(item + k))
                .map(|(_, &s)| s)
                .collect();
            item += seeds.len();
            owned
        } else {
            Vec::new()
        };
        let got: Vec<u64> = sc.results.iter().map(|r| r.seed).collect();
        if got != want {
            return Err(MergeError::OtherSeeds {
                file: file.to_string(),
                shard,
                label: sc.label.clone(),
                got: seed_list(&got),
                want: seed_list(&want),
            });
        }
    }
    Ok(())
}

/// Checks that a part was made by the build and from the inputs of the first part.
fn check_provenance(
    file: &str,
    shard: Shard,
    part: &SuiteReport,
    first_file: &str,
    first: &SuiteReport,
) -> Result<(), MergeError> {
    let (p, f) = (&part.provenance, &first.provenance);
    if p.report_version != REPORT_VERSION {
        return Err(MergeError::OtherReportVersion {
            file: file.to_string(),
            found: p.report_version,
        });
    }
    if (&p.version, &p.commit) != (&f.version, &f.commit) {
        let build = |p: &Provenance| format!("{} at commit {}", p.version, p.commit);
        return Err(MergeError::OtherBuild {
            file: file.to_string(),
            shard,
            build: build(p),
            first: first_file.to_string(),
            first_build: build(f),
        });
    }
    match provenance::first_difference(&p.inputs, &f.inputs) {
        Some((input, this, other)) => Err(MergeError::OtherInputs {
            file: file.to_string(),
            shard,
            first: first_file.to_string(),
            input,
            hashes: format!("blake3 {this} against {other}"),
        }),
        None => Ok(()),
    }
}

/// `[1, 5, 9]`, cut after a few seeds, or `none`.
fn seed_list(seeds: &[u64]) -> String {
    const SHOWN: usize = 8;
    if seeds.is_empty() {
        return "none".into();
    }
    let head: Vec<String> = seeds.iter().take(SHOWN).map(u64::to_string).collect();
    let more = seeds.len().saturating_sub(SHOWN);
    let tail = if more > 0 {
        format!(", … {more} more")
    } else {
        String::new()
    };
    format!("[{}{tail}]", head.join(", "))
}

/// Whether two parts were planned alike: same scenarios, seeds, expectations and errors.
fn same_plan(a: &SuiteReport, b: &SuiteReport) -> bool {
    a.gated == b.gated
        && a.scenarios.len() == b.scenarios.len()
        && a.scenarios.iter().zip(&b.scenarios).all(|(x, y)| {
            (&x.label, &x.file, x.seeds, &x.expect, &x.error)
                == (&y.label, &y.file, y.seeds, &y.expect, &y.error)
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::scores::tests::sample;
    use crate::spec::evaluation::SubjectExpectation;

    fn scenario(seeds: &[u64]) -> ScenarioResult {
        ScenarioResult {
            label: "B".into(),
            name: "B".into(),
            file: "scenarios/B.toml".into(),
            seeds: SeedRange { first: 1, last: 4 },
            reproduce_flags: String::new(),
            expect: ExpectSpec {
                subjects: vec![SubjectExpectation {
                    subject: "words-3".into(),
                    min_precision: Some(0.5),
                    min_recall: None,
                    min_visit_recall: None,
                    min_pair_recall: None,
                    max_seconds_per_lap: None,
                    same: None,
                    opposite: None,
                }],
                quantile: None,
                regression: None,
            },
            error: None,
            results: seeds
                .iter()
                .map(|&seed| {
                    let mut r = sample("B", [0.9; 3], [0.5; 3]);
                    r.seed = seed;
                    r.subjects[2].scores.precision = 0.5 + seed as f64 / 10.0;
                    SeedResult {
                        seed,
                        seconds: 1.0,
                        report: Some(r),
                        error: None,
                        simulation_key: format!("key{seed}"),
                        lap_cache: None,
                    }
                })
                .collect(),
            summary: Vec::new(),
            outcomes: Vec::new(),
        }
    }

    fn part(k: usize, seeds: &[u64]) -> (String, SuiteReport) {
        let shard = Shard::new(k, 2).unwrap();
        let mut p = SuiteReport::new(Some(shard), true, vec![scenario(seeds)]);
        p.provenance = Provenance::new(vec!["placewords".into(), "check".into()]);
        p.provenance.add_seeds(seeds.iter().copied());
        p.provenance.inputs = vec![provenance::Input::new("world", "w.toml", "a".repeat(64))];
        (format!("p{k}.json"), p)
    }

    #[test]
    fn merged_parts_equal_the_whole_run() {
        let whole = SuiteReport::new(None, true, vec![scenario(&[1, 2, 3, 4])]);
        let mut merged = merge(vec![part(2, &[2, 4]), part(1, &[1, 3])]).unwrap();
        assert_eq!(merged.provenance.seeds, [1, 2, 3, 4]);
        assert_eq!(merged.provenance.inputs, part(1, &[1]).1.provenance.inputs);
        merged.provenance = Provenance::default();
        assert_eq!(merged, whole);
        assert_eq!(whole.scenarios[0].outcomes[0].seed, Some(1));
        assert_eq!(
            (
                whole.tally().passed,
                whole.tally().failed,
                whole.tally().errors
            ),
            (1, 0, 0)
        );
        assert!(part(1, &[1, 3]).1.scenarios[0].outcomes.is_empty());
    }

    #[test]
    fn merge_refuses_a_missing_a_doubled_or_a_foreign_part() {
        let e = merge(vec![part(1, &[1, 3])]).unwrap_err();
        assert_eq!(e.to_string(), "part 2/2 is missing; give every part 1..2");
        let e = merge(vec![part(1, &[1, 3]), part(1, &[1, 3])]).unwrap_err();
        assert!(e.to_string().contains("given twice"), "{e}");
        let mut other = part(2, &[2, 4]);
        other.1.scenarios[0].seeds.last = 9;
        let e = merge(vec![part(1, &[1, 3]), other]).unwrap_err();
        assert!(e.to_string().contains("same arguments"), "{e}");
    }

    #[test]
    fn merge_refuses_parts_of_other_inputs_builds_or_report_versions() {
        let mut other = part(2, &[2, 4]);
        other.1.provenance.inputs[0].blake3 = "b".repeat(64);
        let e = merge(vec![part(1, &[1, 3]), other])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "p2.json (part 2/2) was made from other inputs than p1.json: world w.toml differs"
            ),
            "{e}"
        );
        let mut other = part(2, &[2, 4]);
        other.1.provenance.commit = "0123abc".into();
        let e = merge(vec![part(1, &[1, 3]), other])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("at commit 0123abc") && e.contains("one build"),
            "{e}"
        );
        let mut old = part(2, &[2, 4]);
        old.1.provenance = Provenance::default();
        let e = merge(vec![part(1, &[1, 3]), old]).unwrap_err().to_string();
        assert!(e.contains("report_version 0"), "{e}");
    }

    #[test]
    fn bounds_of_a_scenario_whose_every_seed_failed_say_why() {
        let mut sc = scenario(&[1, 2]);
        for r in &mut sc.results {
            r.report = None;
            r.error = Some("simulation failed: robot blocked at (3.0, 1.0) for 20 s".into());
        }
        let s = SuiteReport::new(None, true, vec![sc]);
        let o = &s.scenarios[0].outcomes[0];
        assert!(!o.passed);
        assert_eq!(
            o.missing,
            Some(gate::Missing::EverySeedFailed {
                error: "simulation failed: robot blocked at (3.0, 1.0) for 20 s".into()
            })
        );
    }

    #[test]
    fn merge_refuses_a_part_holding_other_seeds_than_its_shard_runs() {
        let e = merge(vec![part(1, &[1, 2]), part(2, &[3, 4])]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "p1.json (part 1/2) holds B seeds [1, 2], but part 1/2 of its plan runs seeds \
             [1, 3]; run every shard with the same arguments"
        );
        let e = merge(vec![part(1, &[1, 3]), part(2, &[2])]).unwrap_err();
        assert!(e.to_string().contains("holds B seeds [2]"), "{e}");
    }

    #[test]
    fn twins_are_told_apart_by_file() {
        let l = labels(&[
            ("A".into(), "x/A.toml".into()),
            ("A".into(), "y/A.toml".into()),
            ("B".into(), "B.toml".into()),
        ]);
        assert_eq!(l, ["A (x/A.toml)", "A (y/A.toml)", "B"]);
        assert_eq!(
            reproduce_command("my dir/B.toml", 7, ""),
            "placewords run 'my dir/B.toml' --seed 7"
        );
    }
}
