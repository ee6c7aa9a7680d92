//! Records the git commit the crate is built from as `PLACEWORDS_GIT_COMMIT`, for the
//! provenance every report carries (`eval::provenance`). Outside a git checkout, or without
//! git, it is `unknown`: the build never fails for it and never touches the network.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `git ARGS` in the crate's folder, its trimmed output if it succeeded.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(dir)
        .output()
        .ok()?;
    let s = String::from_utf8(out.stdout).ok()?;
    (out.status.success() && !s.trim().is_empty()).then(|| s.trim().to_string())
}

fn main() {
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=PLACEWORDS_GIT_COMMIT");
    // A packager without .git may say which commit the sources are (`PLACEWORDS_GIT_COMMIT=…`).
    let commit = std::env::var("PLACEWORDS_GIT_COMMIT")
        .ok()
        .filter(|c| !c.trim().is_empty())
        .or_else(|| git(&dir, &["rev-parse", "HEAD"]))
        .unwrap_or_else(|| "unknown".into());
    // Rebuild when HEAD moves: HEAD itself (a checkout), the branch it names (a commit) and
    // packed-refs (a `git gc`). In a worktree HEAD lives in the worktree's git folder and the
    // refs in the common one, so both are asked of git rather than assumed at .git/.
    let abs = |p: String| {
        let p = PathBuf::from(p);
        if p.is_absolute() { p } else { dir.join(p) }
    };
    // Only files that exist: cargo reruns the script on every build for a missing one.
    let watch = |p: PathBuf| {
        if p.is_file() {
            println!("cargo:rerun-if-changed={}", p.display());
        }
    };
    if let Some(git_dir) = git(&dir, &["rev-parse", "--git-dir"]).map(abs) {
        watch(git_dir.join("HEAD"));
        let common = git(&dir, &["rev-parse", "--git-common-dir"])
            .map(abs)
            .unwrap_or_else(|| git_dir.clone());
        if let Some(branch) = git(&dir, &["symbolic-ref", "-q", "HEAD"]) {
            watch(common.join(branch));
        }
        watch(common.join("packed-refs"));
    }
    println!("cargo:rustc-env=PLACEWORDS_GIT_COMMIT={commit}");
}
