//! A scenario's `[[subjects]]`: recognizers in other processes (docs/plugin.md) that the
//! scenario itself puts beside the built-in subjects, the file form of `--recognizer
//! NAME=exec:COMMAND`. Read here with every value's place; `experiment::scenario` turns them into
//! the runnable `external::ExternalSpec` (the command run in the scenario file's folder).

use crate::spec::diag::{Diags, echo, fmt_number};
use crate::spec::evaluation::{KNOWN_SUBJECTS, is_builtin_subject_name, is_subject_name};
use crate::spec::read::{get, missing, number, string, strings, table_array, unknown_keys};
use toml::Spanned;
use toml::de::DeTable;

/// Keys of a `[[subjects]]` entry.
pub const SUBJECT_KEYS: &[&str] = &["name", "exec", "timeout_s", "args"];

/// Longest time a program may be given to answer one line, seconds: past an hour a hung
/// program would hold a CI job for longer than any job runs.
pub const MAX_TIMEOUT_S: f64 = 3600.0;

/// One `[[subjects]]` entry as written.
#[derive(Clone, Debug)]
pub struct SubjectSpec {
    /// The subject's name in reports and `[expect]` (not a built-in one's).
    pub name: Spanned<String>,
    /// The command line, run by `sh -c` in the scenario file's folder.
    pub exec: Spanned<String>,
    /// Seconds the program may take to answer one line; `None`: the harness's default.
    pub timeout_s: Option<Spanned<f64>>,
    /// Words appended to `exec`, each passed to the program as one argument.
    pub args: Vec<Spanned<String>>,
}

/// Reads the `[[subjects]]` entries of `top`, each problem at its place.
pub(crate) fn read_subjects(top: &DeTable<'_>, d: &mut Diags) -> Vec<SubjectSpec> {
    let mut out: Vec<SubjectSpec> = Vec::new();
    for (i, (at, t)) in table_array(top, "subjects", d).into_iter().enumerate() {
        let ctx = format!("[[subjects]] #{i}");
        unknown_keys(t, SUBJECT_KEYS, &ctx, d);
        let name = required(t, "name", at, &ctx, "name = \"mine\"", d).and_then(|name| {
            check_name(&name, &ctx, d)?;
            if let Some(first) = out.iter().find(|s| s.name.get_ref() == name.get_ref()) {
                d.at(
                    name.span().start,
                    format!(
                        "subject `{}` is declared twice in [[subjects]] (first on line {}); \
                         give each its own name",
                        name.get_ref(),
                        d.line_of(first.name.span().start)
                    ),
                );
                return None;
            }
            Some(name)
        });
        let exec = required(
            t,
            "exec",
            at,
            &ctx,
            "exec = \"python3 my_recognizer.py\"",
            d,
        )
        .and_then(|exec| {
            if exec.get_ref().trim().is_empty() {
                d.at(
                    exec.span().start,
                    format!(
                        "`exec` in {ctx} names no command; write the command line, e.g. \
                         `exec = \"python3 my_recognizer.py\"`"
                    ),
                );
                return None;
            }
            Some(exec)
        });
        let timeout_s = get(t, "timeout_s").and_then(|(_, v)| {
            let s = number(v, "timeout_s", &ctx, d)?;
            if !(s > 0.0 && s <= MAX_TIMEOUT_S) {
                d.at(
                    v.span().start,
                    format!(
                        "timeout_s = {} in {ctx} is out of range; give the seconds the program \
                         may take to answer one line, more than 0 and at most {} (default 30)",
                        fmt_number(s),
                        fmt_number(MAX_TIMEOUT_S)
                    ),
                );
                return None;
            }
            Some(Spanned::new(v.span(), s))
        });
        let args = get(t, "args")
            .and_then(|(_, v)| strings(v, "args", &ctx, d))
            .unwrap_or_default();
        if let (Some(name), Some(exec)) = (name, exec) {
            out.push(SubjectSpec {
                name,
                exec,
                timeout_s,
                args,
            });
        }
    }
    out
}

/// The string `key` of an entry, or a located "missing key" naming an example.
fn required(
    t: &DeTable<'_>,
    key: &str,
    at: usize,
    ctx: &str,
    example: &str,
    d: &mut Diags,
) -> Option<Spanned<String>> {
    match get(t, key) {
        None => {
            let msg = format!("missing key `{key}` in {ctx}; add e.g. `{example}`");
            missing(t, key, SUBJECT_KEYS, at, msg, d);
            None
        }
        Some((_, v)) => string(v, key, ctx, d).map(|s| Spanned::new(v.span(), s)),
    }
}

/// Refuses a name that is not spelt as a subject's, or that a built-in subject owns.
fn check_name(name: &Spanned<String>, ctx: &str, d: &mut Diags) -> Option<()> {
    let n = name.get_ref();
    let at = name.span().start;
    if !is_subject_name(n) {
        d.at(
            at,
            format!(
                "`{}` in {ctx} cannot name a subject; use letters, digits, `-` and `_`, e.g. \
                 `name = \"mine\"`",
                echo(n)
            ),
        );
        return None;
    }
    if is_builtin_subject_name(n) {
        d.at(
            at,
            format!(
                "`{n}` in {ctx} is the name of a built-in subject ({}); give the external \
                 recognizer another name",
                KNOWN_SUBJECTS.join(", ")
            ),
        );
        return None;
    }
    Some(())
}
