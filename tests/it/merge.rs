//! `merge` refuses what it cannot join: parts whose shard is out of range (the fuzz finds of
//! 2026-12-02 under `tests/fixtures/fuzz-finds/`, each a panic or an abort before), parts
//! holding other seeds than their shard runs, and parts made from other inputs.

use super::common::{placewords, root};

/// Every fuzz-found part file is refused with exit 2 and a message at `file:line:col`, not a
/// panic or an allocation failure.
#[test]
fn fuzz_found_parts_are_located_errors_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut n = 0;
    for entry in std::fs::read_dir(root().join("tests/fixtures/fuzz-finds")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "json") {
            continue;
        }
        let rel = path
            .strip_prefix(root())
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        let o = placewords(&["merge", &rel, "-o", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{rel}: {err}");
        assert!(
            err.contains(&format!("{rel}:1:")),
            "{rel}: not located: {err}"
        );
        assert!(
            err.contains("shard ") && err.contains("part"),
            "{rel}: {err}"
        );
        assert!(
            !out.join("report.json").exists(),
            "{rel}: no output is written"
        );
        n += 1;
    }
    assert_eq!(n, 5, "every merge fuzz find has its fixture");
}
