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

// ---- Function length -------------------------------------------------------------------------
//
// Every `fn` item of `src/**/*.rs` with a body (free functions, methods, trait defaults, and
// functions nested in other functions), measured in lines from the line of its `fn` keyword to
// the line of its closing brace (doc comments and attributes above it not counted). Bodies of
// `#[cfg(test)] mod …` modules are left out: the rule is for the crate's own code; tests read as
// scripts. Strings, raw strings, chars and comments are blanked before braces are matched.

/// The longest a function of `src/` may be, in lines.
const MAX_FN_LINES: usize = 100;

/// `text` with every comment, string and char literal blanked to spaces (newlines kept, so
/// byte offsets and line numbers are those of `text`); lifetimes are kept.
fn code_only(text: &str) -> Vec<u8> {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in &mut out[from..to.min(b.len())] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"//") {
            let end = rest
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |n| i + n);
            blank(&mut out, i, end);
            i = end;
        } else if rest.starts_with(b"/*") {
            let (mut depth, mut j) = (0usize, i);
            while j < b.len() {
                if b[j..].starts_with(b"/*") {
                    depth += 1;
                    j += 2;
                } else if b[j..].starts_with(b"*/") {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if b[i] == b'r'
            && (i == 0 || !ident(b[i - 1]) || (b[i - 1] == b'b' && (i < 2 || !ident(b[i - 2]))))
            && rest[1..].iter().take_while(|&&c| c == b'#').count() + 1 < rest.len()
            && rest[1 + rest[1..].iter().take_while(|&&c| c == b'#').count()] == b'"'
        {
            let hashes = rest[1..].iter().take_while(|&&c| c == b'#').count();
            let mut close = vec![b'"'];
            close.extend(std::iter::repeat_n(b'#', hashes));
            let body = i + 2 + hashes;
            let end = b[body..]
                .windows(close.len())
                .position(|w| w == close.as_slice())
                .map_or(b.len(), |n| body + n + close.len());
            blank(&mut out, i, end);
            i = end;
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            blank(&mut out, i, j + 1);
            i = j + 1;
        } else if b[i] == b'\'' {
            // A char literal ('x', '\n', '\u{1F600}', '{'), or a lifetime ('a), kept.
            let next = rest.get(1).copied().unwrap_or(b' ');
            let len = match next {
                b'\\' => rest[2..].iter().position(|&c| c == b'\'').map(|n| n + 3),
                _ => {
                    let w = match next {
                        c if c < 0x80 => 1,
                        c if c >= 0xF0 => 4,
                        c if c >= 0xE0 => 3,
                        _ => 2,
                    };
                    (rest.get(1 + w) == Some(&b'\'')).then_some(w + 2)
                }
            };
            match len {
                Some(n) => {
                    blank(&mut out, i, i + n);
                    i += n;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The offset of the brace that closes the one opened at `open` (the end when unbalanced).
fn closing_brace(code: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    for (j, &c) in code.iter().enumerate().skip(open) {
        match c {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return j;
                }
            }
            _ => {}
        }
    }
    code.len()
}

/// The byte ranges of the bodies of `#[cfg(test)] mod name { … }` modules.
fn test_module_bodies(code: &[u8]) -> Vec<(usize, usize)> {
    let text = String::from_utf8_lossy(code);
    let mut out = Vec::new();
    for (i, _) in text.match_indices("#[cfg(test)]") {
        let after = text[i + "#[cfg(test)]".len()..].trim_start();
        let after = after
            .strip_prefix("pub(crate)")
            .unwrap_or(after)
            .trim_start();
        let Some(m) = after.strip_prefix("mod ") else {
            continue;
        };
        let start = text.len() - m.len();
        let Some(open) = code[start..].iter().position(|&c| c == b'{' || c == b';') else {
            continue;
        };
        if code[start + open] == b'{' {
            out.push((start + open, closing_brace(code, start + open)));
        }
    }
    out
}

/// `(line of fn, lines long, name)` of every function with a body in `text`, test modules left
/// out.
fn function_lengths(text: &str) -> Vec<(usize, usize, String)> {
    let code = code_only(text);
    let tests = test_module_bodies(&code);
    let line_of = |at: usize| code[..at].iter().filter(|&&c| c == b'\n').count() + 1;
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(n) = code[i..].windows(3).position(|w| w == b"fn ") {
        let at = i + n;
        i = at + 3;
        if (at > 0 && ident(code[at - 1])) || tests.iter().any(|&(a, z)| a < at && at < z) {
            continue;
        }
        let name: String = code[i..]
            .iter()
            .skip_while(|c| c.is_ascii_whitespace())
            .take_while(|&&c| ident(c))
            .map(|&c| c as char)
            .collect();
        if name.is_empty() {
            continue; // `fn (…)` pointer types
        }
        // The body opens at the first `{` outside parentheses and brackets; a `;` first means
        // a declaration without one (a trait's required method).
        let mut depth = 0i32;
        let mut open = None;
        for (j, &c) in code.iter().enumerate().skip(i) {
            match c {
                b'(' | b'[' => depth += 1,
                b')' | b']' => depth -= 1,
                b';' if depth == 0 => break,
                b'{' if depth == 0 => {
                    open = Some(j);
                    break;
                }
                _ => {}
            }
        }
        if let Some(open) = open {
            let close = closing_brace(&code, open);
            out.push((line_of(at), line_of(close) - line_of(at) + 1, name));
        }
    }
    out
}

#[test]
fn no_function_of_src_is_longer_than_the_limit() {
    let src = src_dir();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut lengths = Vec::new();
    let mut too_long = Vec::new();
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        let name = file.strip_prefix(src.parent().unwrap()).unwrap().display();
        for (line, len, f) in function_lengths(&text) {
            lengths.push(len);
            if len > MAX_FN_LINES {
                too_long.push((len, format!("{name}:{line}: fn {f}: {len} lines")));
            }
        }
    }
    lengths.sort_unstable();
    let pct = |p: usize| lengths[(lengths.len() - 1) * p / 100];
    println!(
        "{} functions in src/ (test modules left out): p50 {} lines, p90 {}, max {}",
        lengths.len(),
        pct(50),
        pct(90),
        lengths.last().unwrap()
    );
    too_long.sort_by_key(|t| std::cmp::Reverse(t.0));
    let list: Vec<_> = too_long.into_iter().map(|(_, s)| s).collect();
    assert!(
        list.is_empty(),
        "functions over {MAX_FN_LINES} lines:\n{}",
        list.join("\n")
    );
}

#[test]
fn function_lengths_skip_strings_comments_chars_and_test_modules() {
    let text = "fn a() {\n    let s = \"}}\"; // }\n    let c = '}';\n    let r = r#\"{\"#;\n}\n\
                /* fn b() { */\ntrait T { fn req(&self); fn def<'a>(&'a self) -> &'a str {\n\"\"\n} }\n\
                type F = fn(usize) -> usize;\n#[cfg(test)]\nmod tests {\n    fn t() {\n    }\n}\n";
    let got = function_lengths(text);
    assert_eq!(
        got,
        vec![(1, 5, "a".to_string()), (7, 3, "def".to_string())],
        "{got:?}"
    );
}
