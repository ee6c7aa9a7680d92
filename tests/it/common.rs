//! What every test area needs: the project root and the binary, run from it.

use std::path::PathBuf;
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
