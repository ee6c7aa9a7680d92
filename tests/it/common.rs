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
