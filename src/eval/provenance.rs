//! What made a result: the tool's version and the git commit it was built from, the report
//! schema's version, the command line, the seeds, and a content hash of every input that
//! shaped it; plus the **simulation key** of each simulated seed, the hash of exactly what its
//! laps depend on.
//!
//! Every report (`run`, `check`, `recognize`, `table`, `sweep`, `score`, `merge`, and each part
//! of a sharded `check`) carries a [`Provenance`] under the key `provenance`:
//!
//! ```json
//! "provenance": {
//!   "tool": "placewords", "version": "0.1.0", "commit": "c864de6…", "report_version": 3,
//!   "command_line": ["placewords", "check", "scenarios/B.toml"], "seeds": [1, 2, 3],
//!   "inputs": [
//!     { "role": "scenario", "name": "scenarios/B.toml", "blake3": "…" },
//!     { "role": "world", "name": "scenarios/../worlds/ward.toml", "blake3": "…" },
//!     { "role": "recognizer", "name": "scenarios/B.toml", "blake3": "…" },
//!     { "role": "evaluation", "name": "scenarios/B.toml", "blake3": "…" },
//!     { "role": "expect", "name": "scenarios/B.toml", "blake3": "…" },
//!     { "role": "simulation", "name": "scenarios/B.toml seed 1", "blake3": "…" }
//!   ]
//! }
//! ```
//!
//! Files (scenario, world, real log, matches file, part) are hashed as bytes; settings
//! (recognizer, evaluation, expect) as their canonical serialization, the JSON of the effective
//! settings after defaults, so two files that say the same thing in other words hash alike.
//! The hash is BLAKE3 (the `blake3` crate), 64 hex digits.
//!
//! The simulation key hashes the simulator's whole plan (world model, route, runs with their
//! lap counts after `--laps`, doors, people, robot, laser, odometry, seed) through its `Debug`
//! form, which prints every number exactly (Rust's shortest round-trip form) and every field in
//! declaration order, and [`SIMULATOR_VERSION`]; the scenario's name and the file paths are left
//! out (renaming a file does not change a lap), and so are the world's name and description,
//! the recognizer, evaluation and gate.
//! Two seeds with one key give the same laps, so a baseline and a new run that agree on a
//! seed's key can be compared seed by seed.

use crate::recognizer::RecognizerConfig;
use crate::sim::plan::SimPlan;
use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The version of the report schema (the JSON every command writes). Raised when a key
/// changes meaning or goes away; `merge` and baselines refuse another version. 2: the
/// level-wide `longest_revisit_m` became the longer of the two directions' and is written
/// whenever there are revisits; each subject gained `ranking` (`eval::ranking`). 3: a gate
/// outcome's `missing` is data (`{"kind": "no_matches"}`, `eval::gate::Missing`), not words.
pub const REPORT_VERSION: u32 = 3;

/// The version of what the simulator makes of a plan. Raised whenever a change of the
/// simulator (kinematics, laser, odometry, people, lap variation, random streams) makes other
/// laps from the same plan and seed, so old and new laps never share a simulation key. It is
/// not the crate's version or commit: a recognizer change leaves the laps, and their key, alone.
pub const SIMULATOR_VERSION: u32 = 1;

/// The crate's version (`CARGO_PKG_VERSION`).
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The git commit the binary was built from (`build.rs`), `unknown` outside a git checkout.
pub const GIT_COMMIT: &str = env!("PLACEWORDS_GIT_COMMIT");

/// One input of a result and its content hash.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Input {
    /// What it is: `scenario`, `world`, `recognizer`, `evaluation`, `expect`, `simulation`,
    /// `real_log`, `config`, `matches`, `logs`, `part`.
    pub role: String,
    /// Which one: the file as given, or the file a setting comes from (`… seed N` for a
    /// simulation key).
    pub name: String,
    /// BLAKE3 of its content, 64 hex digits.
    pub blake3: String,
}

impl Input {
    pub fn new(role: &str, name: impl Into<String>, blake3: String) -> Self {
        Input {
            role: role.into(),
            name: name.into(),
            blake3,
        }
    }

    /// `role name` for messages.
    pub fn label(&self) -> String {
        format!("{} {}", self.role, self.name)
    }
}

/// What made a result.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Provenance {
    /// `placewords`.
    pub tool: String,
    /// [`TOOL_VERSION`] of the binary that wrote the report.
    pub version: String,
    /// [`GIT_COMMIT`] of that binary.
    pub commit: String,
    /// [`REPORT_VERSION`] (0 when read from a report older than provenance).
    pub report_version: u32,
    /// The command line, program name first.
    pub command_line: Vec<String>,
    /// Every seed that ran, increasing.
    pub seeds: Vec<u64>,
    /// Every input, in the order the command met them.
    pub inputs: Vec<Input>,
    /// With `--cache DIR`: how many seeds' laps came from the lap cache and how many were
    /// simulated (absent without a cache). Not an input: the figures are the same either way.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lap_cache: Option<LapCacheUse>,
}

/// Where a simulated seed's laps came from, with a lap cache (`experiment::cache`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LapSource {
    /// Read from the cache: an intact entry under the seed's key.
    Hit,
    /// Simulated: no entry under the key (and then stored).
    Miss,
    /// Simulated again: the entry under the key was corrupt or truncated (and then replaced).
    Corrupt,
}

/// What a lap cache did for one command (`provenance.lap_cache`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LapCacheUse {
    /// The cache folder, as given.
    pub dir: String,
    /// Seeds (scenario × seed) whose laps were read from the cache.
    pub hits: usize,
    /// Seeds simulated (no entry, or a corrupt one), corrupt ones included.
    pub misses: usize,
    /// Every corrupt entry found, with why (`FILE: record 3: its checksum differs`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub corrupt: Vec<String>,
    /// Entries that could not be stored, with why (the run went on without storing them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_stored: Vec<String>,
}

impl LapCacheUse {
    /// Adds `other`'s counts and notes (the parts of a sharded run).
    pub fn add(&mut self, other: &LapCacheUse) {
        self.hits += other.hits;
        self.misses += other.misses;
        self.corrupt.extend(other.corrupt.iter().cloned());
        self.not_stored.extend(other.not_stored.iter().cloned());
    }
}

impl Default for Provenance {
    /// What a report written before provenance reads back as: version 0, nothing known.
    fn default() -> Self {
        Provenance {
            tool: String::new(),
            version: String::new(),
            commit: String::new(),
            report_version: 0,
            command_line: Vec::new(),
            seeds: Vec::new(),
            inputs: Vec::new(),
            lap_cache: None,
        }
    }
}

impl Provenance {
    /// This binary's provenance for `command_line`, with no seeds or inputs yet.
    pub fn new(command_line: Vec<String>) -> Self {
        Provenance {
            tool: "placewords".into(),
            version: TOOL_VERSION.into(),
            commit: GIT_COMMIT.into(),
            report_version: REPORT_VERSION,
            command_line,
            seeds: Vec::new(),
            inputs: Vec::new(),
            lap_cache: None,
        }
    }

    /// Adds `seeds`, keeping the list increasing and without repeats.
    pub fn add_seeds(&mut self, seeds: impl IntoIterator<Item = u64>) {
        self.seeds.extend(seeds);
        self.seeds.sort_unstable();
        self.seeds.dedup();
    }

    /// Adds inputs, skipping any already there.
    pub fn add_inputs(&mut self, inputs: impl IntoIterator<Item = Input>) {
        for i in inputs {
            if !self.inputs.contains(&i) {
                self.inputs.push(i);
            }
        }
    }

    /// The inputs of one role.
    pub fn inputs_of<'a>(&'a self, role: &'a str) -> impl Iterator<Item = &'a Input> + 'a {
        self.inputs.iter().filter(move |i| i.role == role)
    }
}

/// BLAKE3 of `bytes`, 64 hex digits.
pub fn hash_bytes(bytes: &[u8]) -> String {
    blake3::hash(bytes).to_hex().to_string()
}

/// BLAKE3 of a file's bytes, read in pieces (a real log may be large).
pub fn hash_file(path: &Path) -> std::io::Result<String> {
    let mut h = blake3::Hasher::new();
    h.update_reader(std::fs::File::open(path)?)?;
    Ok(h.finalize().to_hex().to_string())
}

/// A file as an input: its hash, or, when it cannot be read (it was read a moment ago to make
/// the result), `unreadable` so the report still says which file it was.
pub fn file_input(role: &str, path: &Path) -> Input {
    let hash = hash_file(path).unwrap_or_else(|e| format!("unreadable: {e}"));
    Input::new(role, path.display().to_string(), hash)
}

/// BLAKE3 of the canonical serialization (JSON, fields in declaration order) of settings.
pub fn hash_settings(settings: &impl Serialize) -> String {
    // Settings hold only numbers, strings, maps and vectors: serializing cannot fail.
    let json = serde_json::to_vec(settings).expect("settings always serialize");
    hash_bytes(&json)
}

/// The simulation key of `plan` at its seed, with every run's lap count replaced by `laps`
/// when given (`--laps`): see the module doc for what it covers.
pub fn simulation_key(plan: &SimPlan, laps: Option<usize>) -> String {
    let mut p = plan.clone();
    p.name = String::new();
    p.path = PathBuf::new();
    p.world_path = PathBuf::new();
    p.world.name = String::new();
    p.world.description = None;
    if let Some(n) = laps {
        for r in &mut p.runs {
            r.laps = n;
        }
    }
    hash_bytes(format!("placewords-simulator/{SIMULATOR_VERSION}\n{p:?}").as_bytes())
}

/// The inputs of a simulated scenario that do not depend on the seed: its file and its
/// world's (bytes), and its effective recognizer, evaluation and gate settings.
pub fn scenario_inputs(
    plan: &SimPlan,
    recognizer: &RecognizerConfig,
    evaluation: &EvaluationSpec,
    expect: &ExpectSpec,
) -> Vec<Input> {
    let file = plan.path.display().to_string();
    vec![
        file_input("scenario", &plan.path),
        file_input("world", &plan.world_path),
        Input::new("recognizer", file.clone(), hash_settings(recognizer)),
        Input::new("evaluation", file.clone(), hash_settings(evaluation)),
        Input::new("expect", file, hash_settings(expect)),
    ]
}

/// The simulation key of `plan` at `seed` as an input named `FILE seed N`.
pub fn simulation_input(plan: &SimPlan, seed: u64, laps: Option<usize>) -> Input {
    let mut p = plan.clone();
    p.seed = seed;
    Input::new(
        "simulation",
        format!("{} seed {seed}", plan.path.display()),
        simulation_key(&p, laps),
    )
}

/// The first difference between two parts' inputs, as `(what, this part's, the other's)`:
/// a differing hash names the input; an input only one of them has is named too.
pub fn first_difference(a: &[Input], b: &[Input]) -> Option<(String, String, String)> {
    let short = |h: &str| format!("{}…", h.chars().take(12).collect::<String>());
    for x in a {
        match b.iter().find(|y| y.role == x.role && y.name == x.name) {
            Some(y) if y.blake3 != x.blake3 => {
                return Some((x.label(), short(&x.blake3), short(&y.blake3)));
            }
            Some(_) => {}
            None => return Some((x.label(), short(&x.blake3), "absent".into())),
        }
    }
    b.iter()
        .find(|y| !a.iter().any(|x| x.role == y.role && x.name == y.name))
        .map(|y| (y.label(), "absent".into(), short(&y.blake3)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_are_blake3_hex_and_differ_with_content() {
        let h = hash_bytes(b"abc");
        assert_eq!(h.len(), 64);
        assert!(h.chars().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(h, hash_bytes(b"abd"));
        let mut cfg = RecognizerConfig::default();
        let before = hash_settings(&cfg);
        assert_eq!(before, hash_settings(&cfg.clone()));
        cfg.levels += 1;
        assert_ne!(before, hash_settings(&cfg));
    }

    #[test]
    fn the_first_difference_names_the_input() {
        let i = |role: &str, h: &str| Input::new(role, "s.toml", h.into());
        let a = [i("scenario", "aa"), i("world", "bb")];
        let b = [i("scenario", "aa"), i("world", "cc")];
        assert_eq!(first_difference(&a, &a), None);
        let (what, x, y) = first_difference(&a, &b).unwrap();
        assert_eq!(
            (what.as_str(), x.as_str(), y.as_str()),
            ("world s.toml", "bb…", "cc…")
        );
        let (what, _, y) = first_difference(&a, &a[..1]).unwrap();
        assert_eq!((what.as_str(), y.as_str()), ("world s.toml", "absent"));
    }
}
