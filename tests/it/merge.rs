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

/// The smoke scenario and its world copied into `dir` (`dir/scenarios`, `dir/worlds`).
fn copy_smoke(dir: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    std::fs::create_dir_all(dir.join("worlds")).unwrap();
    std::fs::create_dir_all(dir.join("scenarios")).unwrap();
    let world = dir.join("worlds/loop-small.toml");
    std::fs::copy(root().join("worlds/loop-small.toml"), &world).unwrap();
    let scenario = dir.join("scenarios/smoke.toml");
    std::fs::copy(root().join("scenarios/smoke.toml"), &scenario).unwrap();
    (scenario, world)
}

/// Parts made before and after an edit of the world, or of the scenario's `[robot]`, are
/// refused: exit 2, naming the part file, the part and the input that differs.
#[test]
fn parts_of_edited_inputs_are_refused_naming_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let (scenario, world) = copy_smoke(dir.path());
    let s = scenario.to_str().unwrap();
    let part = |k: usize| {
        let path = dir.path().join(format!("part{k}.json"));
        let o = placewords(&[
            "check",
            s,
            "-q",
            "--seeds",
            "1..2",
            "--shard",
            &format!("{k}/2"),
            "--report",
            path.to_str().unwrap(),
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        path.to_str().unwrap().to_string()
    };
    let merge = |a: &str, b: &str| {
        let out = tempfile::tempdir().unwrap();
        let o = placewords(&["merge", a, b, "-o", out.path().to_str().unwrap()]);
        let code = o.status.code();
        let written = out.path().join("report.json").exists();
        assert_eq!(
            written,
            code != Some(2),
            "a report only from parts that merge"
        );
        (code, String::from_utf8_lossy(&o.stderr).to_string())
    };
    let p1 = part(1);
    let text = std::fs::read_to_string(&world).unwrap();
    std::fs::write(&world, text.replacen("width_m = 0.9", "width_m = 0.8", 1)).unwrap();
    let p2 = part(2);
    let (code, err) = merge(&p1, &p2);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "{p2} (part 2/2) was made from other inputs than {p1}: world "
        )) && err.contains("loop-small.toml differs"),
        "{err}"
    );

    std::fs::write(&world, &text).unwrap();
    let p2 = part(2);
    let (code, err) = merge(&p1, &p2);
    // Merged (exit 0, or 1 when the smoke scenario's bounds miss on these two seeds).
    assert_ne!(code, Some(2), "the same inputs merge: {err}");
    let src = std::fs::read_to_string(&scenario).unwrap();
    let slower = src.replacen("[robot]\n", "[robot]\ncruise_speed_m_s = 0.5\n", 1);
    assert_ne!(slower, src);
    std::fs::write(&scenario, slower).unwrap();
    let p2 = part(2);
    let (code, err) = merge(&p1, &p2);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(": scenario ") && err.contains("smoke.toml differs"),
        "{err}"
    );
}

/// A part or a baseline that is not UTF-8 is refused at the first bad byte's line and column,
/// and bad JSON says its place once (serde_json's "at line L column C" is not repeated).
#[test]
fn parts_and_baselines_that_do_not_read_are_located_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let bin = dir.path().join("part.json");
    std::fs::write(&bin, b"{\"format\":\n  \"placewords-suite/1\xff\"}").unwrap();
    let comma = dir.path().join("comma.json");
    std::fs::write(&comma, "{\"format\":\n 1,}").unwrap();
    let (bin, comma) = (bin.to_str().unwrap(), comma.to_str().unwrap());
    for (args, at) in [
        (
            vec!["merge", bin, "-o", out.to_str().unwrap()],
            format!("{bin}:2:22: the file is not valid UTF-8"),
        ),
        (
            vec!["compare", bin, bin],
            format!("{bin}:2:22: the file is not valid UTF-8"),
        ),
        (
            vec!["merge", comma, "-o", out.to_str().unwrap()],
            format!("{comma}:2:2: not a part"),
        ),
    ] {
        let o = placewords(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(&at), "{args:?}: {err}");
        assert!(
            !err.contains(" at line "),
            "{args:?}: the place twice: {err}"
        );
    }
}
