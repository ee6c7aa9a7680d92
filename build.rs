//! Records the git commit the crate is built from as `PLACEWORDS_GIT_COMMIT`, for the
//! provenance every report carries (`eval::provenance`). Outside a git checkout, or without
//! git, it is `unknown`: the build never fails for it and never touches the network.
//!
//! Also records `PLACEWORDS_SIM_SOURCES`, a fingerprint of the sources simulated laps depend on
//! (`src/sim`, `src/world`, `src/geom.rs`, `src/scan.rs`, `src/log.rs`, `Cargo.lock`, the
//! target), which the lap cache (`experiment::cache`) keys its entries with beside the
//! simulation key: a binary whose simulator differs never reads another's laps, even when
//! `SIMULATOR_VERSION` was not raised.

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
    println!(
        "cargo:rustc-env=PLACEWORDS_SIM_SOURCES={}",
        sim_sources(&dir)
    );
}

/// The files under `p` (or `p` itself), sorted, recursively.
fn files(p: &Path, out: &mut Vec<PathBuf>) {
    match std::fs::read_dir(p) {
        Ok(entries) => {
            let mut v: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
            v.sort();
            v.iter().for_each(|e| files(e, out));
        }
        Err(_) if p.is_file() => out.push(p.to_path_buf()),
        Err(_) => {}
    }
}

/// 32 hex digits of two FNV-1a hashes over the simulator's source files (name and bytes) and
/// the target triple: a fingerprint, not a security hash.
fn sim_sources(dir: &Path) -> String {
    let mut paths = Vec::new();
    for p in [
        "src/sim",
        "src/world",
        "src/geom.rs",
        "src/scan.rs",
        "src/log.rs",
        "Cargo.lock",
    ] {
        println!("cargo:rerun-if-changed={p}");
        files(&dir.join(p), &mut paths);
    }
    let mut h = [0xcbf2_9ce4_8422_2325u64, 0x6c62_272e_07bb_0142u64];
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            for x in &mut h {
                *x = (*x ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    };
    eat(std::env::var("TARGET").unwrap_or_default().as_bytes());
    for p in paths {
        eat(p
            .strip_prefix(dir)
            .unwrap_or(&p)
            .to_string_lossy()
            .as_bytes());
        eat(&std::fs::read(&p).unwrap_or_default());
    }
    format!("{:016x}{:016x}", h[0], h[1])
}
