//! Argument pieces and helpers several subcommands share.

use anyhow::Context;
use clap::Args;
use std::path::Path;

/// `--levels N`: run only the configuration with N levels (default: 1, 2 and 3).
#[derive(Debug, Args)]
pub struct LevelsArg {
    /// Run only the level configuration with this many levels (default: 1, 2 and 3).
    #[arg(long = "levels", value_name = "1|2|3|4", value_parser = clap::value_parser!(u8).range(1..=4))]
    pub only: Option<u8>,
}

impl LevelsArg {
    pub fn levels(&self) -> Vec<usize> {
        match self.only {
            Some(n) => vec![n as usize],
            None => vec![1, 2, 3],
        }
    }
}

/// `--recognizer NAME=exec:COMMAND`: recognizers in other processes, scored beside the
/// built-in subjects (docs/plugin.md).
#[derive(Debug, Args)]
pub struct ExternalArg {
    /// Also score a recognizer in any language: a program (run by `sh -c`) that speaks the
    /// JSON-lines protocol of docs/plugin.md, as subject NAME. Repeatable.
    /// Example: --recognizer mine=exec:"python3 examples/plugin_recognizer.py"
    #[arg(long = "recognizer", value_name = "NAME=exec:COMMAND", value_parser = parse_external)]
    pub external: Vec<placewords::external::ExternalSpec>,
    /// Time an external recognizer may take to answer one line before it is stopped, seconds.
    #[arg(long, value_name = "S", default_value_t = placewords::external::DEFAULT_TIMEOUT_S)]
    pub recognizer_timeout_s: f64,
}

impl ExternalArg {
    /// The external recognizers, each with the timeout.
    pub fn specs(&self) -> Vec<placewords::external::ExternalSpec> {
        let mut out = self.external.clone();
        for s in &mut out {
            s.timeout_s = self.recognizer_timeout_s;
        }
        out
    }
}

fn parse_external(text: &str) -> Result<placewords::external::ExternalSpec, String> {
    placewords::external::ExternalSpec::parse(text)
}

/// Writes a file the user named, atomically, naming it in the error; its folder must exist.
pub fn write_file(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    placewords::io::atomic::check_parent(path)
        .and_then(|()| placewords::io::atomic::write_atomic(path, bytes))
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Refuses an output file whose extension says another format than the one written
/// (`world render -o out.png` would be SVG in a `.png`).
pub fn check_extension(path: &Path, ext: &str) -> anyhow::Result<()> {
    // A device or pipe (`-o /dev/null`) has no format to contradict.
    if path.exists() && !path.is_file() && !path.is_dir() {
        return Ok(());
    }
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case(ext) => Ok(()),
        _ => anyhow::bail!(
            "{}: this command writes .{ext}; give a file name ending in .{ext}",
            path.display()
        ),
    }
}

/// Checks, before any work starts, that each output file can be written (exit 2 naming it).
pub fn check_outputs<'a>(files: impl IntoIterator<Item = Option<&'a Path>>) -> anyhow::Result<()> {
    for path in files.into_iter().flatten() {
        placewords::io::atomic::check_writable(path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// Checks, before any work starts, that files can be written into each output folder.
pub fn check_output_dirs<'a>(
    dirs: impl IntoIterator<Item = Option<&'a Path>>,
) -> anyhow::Result<()> {
    for dir in dirs.into_iter().flatten() {
        placewords::io::atomic::check_writable_dir(dir)
            .with_context(|| format!("{}: cannot write into this folder", dir.display()))?;
    }
    Ok(())
}

/// The command line as given (program name first), for the reports' provenance; an argument
/// that is not UTF-8 is kept with its bad bytes replaced rather than refused.
pub fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

/// The outputs of one experiment (`run`, `recognize`): JSON report, exported matches and
/// pictures, begun before the work so a path another live process writes is refused then, and
/// written as one ([`placewords::io::atomic::OutputSet`]): a kill leaves the old set or the new.
pub struct ExperimentOutputs {
    set: placewords::io::atomic::OutputSet,
    report: Option<std::path::PathBuf>,
    matches: Option<std::path::PathBuf>,
    svg: Option<std::path::PathBuf>,
}

impl ExperimentOutputs {
    /// Checks the paths (as [`check_outputs`] and [`check_output_dirs`]) and begins the set.
    pub fn begin(
        report: Option<&Path>,
        matches: Option<&Path>,
        svg: Option<&Path>,
    ) -> anyhow::Result<ExperimentOutputs> {
        check_outputs([report, matches])?;
        check_output_dirs([svg])?;
        let files: Vec<&Path> = [report, matches].into_iter().flatten().collect();
        let dirs: Vec<&Path> = svg.into_iter().collect();
        Ok(ExperimentOutputs {
            set: placewords::io::atomic::OutputSet::begin(&files, &dirs, &[])?,
            report: report.map(Path::to_path_buf),
            matches: matches.map(Path::to_path_buf),
            svg: svg.map(Path::to_path_buf),
        })
    }

    /// Prints the experiment's table, then writes its JSON report (with `provenance`), the
    /// matched pairs of its last level configuration (on `runs`' scans) and its pictures
    /// where asked — the true and odometry paths, and the matched pairs of each level
    /// configuration (and ICP) — all put in place at once at the end.
    pub fn print_and_write(
        self,
        exp: &placewords::experiment::Experiment,
        world: &placewords::world::World,
        provenance: &placewords::eval::provenance::Provenance,
    ) -> anyhow::Result<()> {
        out!("{}", placewords::report::table::text_table(&exp.report))?;
        let staged = |path: &Path, e: std::io::Error| {
            anyhow::Error::new(e).context(format!("{}: cannot write", path.display()))
        };
        if let Some(path) = &self.report {
            let json = placewords::report::json::to_json_with(&exp.report, provenance);
            self.set
                .write(path, json.as_bytes())
                .map_err(|e| staged(path, e))?;
        }
        let mut pairs = None;
        if let (Some(path), Some((levels, rec))) = (&self.matches, exp.recognitions.last()) {
            use placewords::experiment::score;
            let rows = score::export_rows(rec, &score::run_frames(&exp.runs));
            let csv = placewords::io::matches_csv::write_matches(&rows);
            self.set
                .write(path, csv.as_bytes())
                .map_err(|e| staged(path, e))?;
            pairs = Some((rows.len(), *levels));
        }
        if let Some(dir) = &self.svg {
            let staging = self.set.dir(dir).expect("begun with this folder");
            placewords::experiment::picture::write_pictures(exp, world, staging)?;
        }
        let written: Vec<String> = [&self.report, &self.matches, &self.svg]
            .into_iter()
            .flatten()
            .map(|p| p.display().to_string())
            .collect();
        self.set
            .commit()
            .with_context(|| format!("{}: cannot write", written.join(", ")))?;
        if let Some(path) = &self.report {
            errln!("report: {}", path.display());
        }
        if let (Some(path), Some((n, levels))) = (&self.matches, pairs) {
            errln!(
                "matches: {} ({n} pairs of words-{levels}; `score --levels {levels}` labels them so)",
                path.display()
            );
        }
        if let Some(dir) = &self.svg {
            errln!("pictures: {}", dir.display());
        }
        Ok(())
    }
}

/// `--seeds A..B` or `--seed N`: which seeds to run.
#[derive(Debug, Args)]
pub struct SeedsArg {
    /// Run every seed from A to B (both included), e.g. 1..20. Each seed re-draws everything
    /// random: noise, doors drawn at random, people, lap variation.
    #[arg(long, value_name = "A..B", conflicts_with = "seed")]
    pub seeds: Option<placewords::spec::seeds::SeedRange>,
    /// Run this seed only (the scenario's `seed` is replaced).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
}

impl SeedsArg {
    /// The seeds asked for, if any.
    pub fn range(&self) -> Option<placewords::spec::seeds::SeedRange> {
        self.seeds
            .or(self.seed.map(placewords::spec::seeds::SeedRange::one))
    }
}

/// `--baseline BASE.json` with the tolerance flags, shared by `check` and `merge`.
#[derive(Debug, Args)]
pub struct BaselineArg {
    /// Also compare with a baseline report (`check --report` or `-o DIR`'s report.json of an
    /// earlier run, e.g. main's): per scenario × subject × metric, paired by seed when the
    /// simulation keys agree; exit 1 on a regression. Example: --baseline main/report.json
    #[arg(long, value_name = "BASE.json")]
    pub baseline: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub tolerance: ToleranceArg,
}

/// `--max-drop` and `--max-slowdown`: override `[expect.regression]`.
#[derive(Debug, Args)]
pub struct ToleranceArg {
    /// How much precision or a recall may drop before it is a regression (overrides
    /// `[expect.regression] max_drop`, default 0.003).
    #[arg(long, value_name = "X", value_parser = parse_max_drop)]
    pub max_drop: Option<f64>,
    /// How many times slower the CPU time per lap may get (overrides `[expect.regression]
    /// max_slowdown`, default 1.5).
    #[arg(long, value_name = "FACTOR", value_parser = parse_max_slowdown)]
    pub max_slowdown: Option<f64>,
}

impl ToleranceArg {
    pub fn overrides(&self) -> placewords::eval::compare::ToleranceOverride {
        placewords::eval::compare::ToleranceOverride {
            max_drop: self.max_drop,
            max_slowdown: self.max_slowdown,
        }
    }
}

fn parse_max_drop(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if placewords::spec::evaluation::valid_max_drop(x) {
        Ok(x)
    } else {
        Err(format!(
            "{s} is outside 0..1; a drop of precision or recall, e.g. 0.01"
        ))
    }
}

fn parse_max_slowdown(s: &str) -> Result<f64, String> {
    let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if placewords::spec::evaluation::valid_max_slowdown(x) {
        Ok(x)
    } else {
        Err(format!(
            "{s} is less than 1; a factor on the time per lap, e.g. 1.5"
        ))
    }
}

/// `--cache DIR` and `--cache-max-gb N`: the lap cache (`experiment::cache`), shared by
/// `simulate`, `run`, `check`, `table` and `sweep`.
#[derive(Debug, Args)]
pub struct CacheArg {
    /// Keep simulated laps in DIR under their simulation key and read them back when the key
    /// matches, so a change of `[recognizer]`, `[evaluation]` or `[expect]` re-runs only
    /// recognition and scoring (docs/ci.md, "Cached laps"). Clear it by removing DIR.
    /// Example: placewords check scenarios/B.toml --cache ~/.cache/placewords
    #[arg(long, value_name = "DIR", env = "PLACEWORDS_CACHE")]
    pub cache: Option<std::path::PathBuf>,
    /// Keep the cache's entries within this many GB (10⁹ bytes), removing the oldest first
    /// (by modification time; a hit counts as use). Default: unbounded.
    /// Example: --cache-max-gb 5
    #[arg(
        long,
        value_name = "GB",
        env = "PLACEWORDS_CACHE_MAX_GB",
        requires = "cache"
    )]
    pub cache_max_gb: Option<f64>,
}

impl CacheArg {
    /// The cache asked for, opened (its folder created and checked writable before any work).
    pub fn open(
        &self,
    ) -> anyhow::Result<Option<std::sync::Arc<placewords::experiment::cache::LapCache>>> {
        match &self.cache {
            None => Ok(None),
            Some(dir) => Ok(Some(std::sync::Arc::new(
                placewords::experiment::cache::LapCache::open(dir, self.cache_max_gb)?,
            ))),
        }
    }
}

/// Prints what the lap cache did (`lap cache DIR: 9 hits, 1 miss`, and each corrupt entry).
pub fn report_cache(cache: Option<&placewords::experiment::cache::LapCache>) {
    for line in cache
        .map(|c| placewords::report::explain::lap_cache_lines(&c.used()))
        .unwrap_or_default()
    {
        errln!("{line}");
    }
}
