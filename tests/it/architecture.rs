//! The module graph runs one way (ARCHITECTURE.md): every `crate::X` (library) or
//! `placewords::X` (command line) reference in `src/<module>/**` or `src/<module>.rs` must point
//! to a module on a lower layer. A failure names the file:line of each import that breaks it.

use std::fs;
use std::path::{Path, PathBuf};

/// Top-level modules of `src/`, top layer first. A module may import modules on lower layers
/// only; modules on one layer do not import each other. Keep in step with ARCHITECTURE.md.
const LAYERS: &[&[&str]] = &[
    &["cli"],
    &["authoring"],
    &["experiment", "schema"],
    &["report"],
    &["eval"],
    &["baseline", "sim", "external"],
    &["recognizer"],
    &["world", "io"],
    &["spec"],
    &["log"],
    &["place"],
    &["scan"],
    &["geom", "clock"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn allowed(from: &str, to: &str) -> bool {
    if from == to {
        return true;
    }
    matches!((layer(from), layer(to)), (Some(a), Some(b)) if a < b)
}

/// The top-level modules a line of code names through `prefix` (`crate::` or `placewords::`),
/// including groups such as `use crate::{geom::Pose2, scan}`.
fn referenced_modules(line: &str, prefix: &str) -> Vec<String> {
    let code = line.split("//").next().unwrap_or("");
    let mut found = Vec::new();
    for (i, _) in code.match_indices(prefix) {
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$' || c == ':') {
            continue;
        }
        let rest = &code[i + prefix.len()..];
        match rest.strip_prefix('{') {
            Some(group) => found.extend(group_heads(group)),
            None => found.push(ident(rest)),
        }
    }
    found.retain(|m| !m.is_empty() && m != "self" && m != "super");
    found
}

/// The first path segment of every top-level item of a `{...}` group.
fn group_heads(group: &str) -> Vec<String> {
    let mut heads = Vec::new();
    let (mut depth, mut start) = (0usize, true);
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => break,
            '}' => depth -= 1,
            ',' if depth == 0 => start = true,
            c if start && (c.is_alphanumeric() || c == '_') => {
                heads.push(ident(&group[i..]));
                start = false;
            }
            _ => {}
        }
    }
    heads
}

fn ident(s: &str) -> String {
    s.chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`main.rs` is the command line).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    match first {
        "lib.rs" => None,
        "main.rs" => Some("cli".into()),
        f => Some(f.trim_end_matches(".rs").to_string()),
    }
}

/// `file:line: from -> to` for every reference in `text` that breaks the order.
fn violations(from: &str, file: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for prefix in ["crate::", "placewords::"] {
            for to in referenced_modules(line, prefix) {
                if !allowed(from, &to) {
                    out.push(format!("{file}:{}: {from} -> {to}: {}", n + 1, line.trim()));
                }
            }
        }
    }
    out
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn every_import_between_top_level_modules_points_down_the_layers() {
    let src = src_dir();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut broken = Vec::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let text = fs::read_to_string(file).unwrap();
        let name = file.strip_prefix(src.parent().unwrap()).unwrap();
        broken.extend(violations(&module, &name.display().to_string(), &text));
    }
    assert!(
        broken.is_empty(),
        "imports against the allowed directions of ARCHITECTURE.md:\n{}",
        broken.join("\n")
    );
}

#[test]
fn every_top_level_module_has_a_layer() {
    let src = src_dir();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut missing: Vec<String> = files
        .iter()
        .filter_map(|f| module_of(&src, f))
        .filter(|m| layer(m).is_none())
        .collect();
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "modules missing from LAYERS (and ARCHITECTURE.md): {missing:?}"
    );
}

#[test]
fn an_upward_import_is_reported_with_its_line() {
    let text = "//! eval\nuse crate::geom::Pose2;\nuse crate::{scan::Scan, report::json};\n";
    let v = violations("eval", "src/eval/x.rs", text);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        v[0].starts_with("src/eval/x.rs:3: eval -> report"),
        "{}",
        v[0]
    );
    // Same layer is not allowed either; comments and `$crate::` are not imports.
    assert_eq!(violations("sim", "f", "use crate::baseline::x;").len(), 1);
    assert!(violations("io", "f", "// crate::experiment\nlet _ = $crate::sim::x;").is_empty());
}
