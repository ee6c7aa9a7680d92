//! What every test area needs: the project root and the binary, run from it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The project root (where `worlds/`, `scenarios/` and `tests/fixtures/` are).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the `placewords` binary with `args` from the project root.
pub fn placewords(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_placewords"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the placewords binary runs")
}

/// The smoke scenario with its world path made absolute and `extra` appended, in `dir`.
pub fn smoke_variant(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let src = std::fs::read_to_string(root().join("scenarios/smoke.toml")).unwrap();
    let world = root().join("worlds/loop-small.toml");
    let src = src.replace(
        "\"../worlds/loop-small.toml\"",
        &format!("{:?}", world.display().to_string()),
    );
    let src = match src.find("[expect]") {
        Some(i) => src[..i].to_string(),
        None => src,
    };
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{src}\n{extra}")).unwrap();
    path
}

/// Inputs per fuzz target: `PLACEWORDS_FUZZ_CASES` (default 48, to keep the suite short).
pub fn fuzz_cases() -> u32 {
    std::env::var("PLACEWORDS_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48)
}

/// Per fuzz target: inputs run and the slowest so far.
static FUZZ_CAMPAIGN: std::sync::Mutex<
    std::collections::BTreeMap<&'static str, (u32, std::time::Duration)>,
> = std::sync::Mutex::new(std::collections::BTreeMap::new());

/// Runs one fuzz input of `target` and keeps the campaign's record: a new slowest input is
/// printed (with `input`, to reproduce it), and after the last input of a campaign
/// ([`fuzz_cases`]) one line says how many ran and how long the slowest took (seen with
/// `--nocapture`; speed is reported, not asserted).
pub fn fuzz_timed<T>(
    target: &'static str,
    input: &dyn Fn() -> String,
    run: impl FnOnce() -> T,
) -> T {
    let t = std::time::Instant::now();
    let out = run();
    let took = t.elapsed();
    let mut campaign = FUZZ_CAMPAIGN.lock().unwrap_or_else(|e| e.into_inner());
    let (count, slowest) = campaign.entry(target).or_default();
    *count += 1;
    if took > *slowest {
        *slowest = took;
        eprintln!("{target}: slowest input so far {took:?}: {}", input());
    }
    if *count == fuzz_cases() {
        eprintln!("fuzz campaign {target}: {count} inputs, 0 panics, slowest {slowest:?}");
    }
    out
}
