//! The one reader of TOML files people write (worlds and scenarios): toml's spanned document
//! ([`toml::de::DeTable`]) walked by hand, key by key.
//!
//! Why a hand reader and not serde: serde stops at the first problem, while an author wants
//! every problem of a file at once (unknown keys with a "did you mean", missing keys, wrong
//! types, bad numbers), each at the line and column of the offending value. Over `DeTable` each
//! key is looked up, checked and located independently, so one mistake never hides the next.
//! The file structs stay plain (`WorldSpec`, `ScenarioSpec`), with their defaults in one place.

use crate::spec::diag::{Diags, echo};
use crate::spec::suggest;
use crate::spec::world::MAX_SEGMENTS;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// Parses TOML text into a spanned document; every syntax error goes to `d`.
pub(crate) fn parse_document<'i>(src: &'i str, d: &mut Diags) -> Option<Spanned<DeTable<'i>>> {
    let (doc, errors) = DeTable::parse_recoverable(src);
    if errors.is_empty() {
        return Some(doc);
    }
    // One message, at the first error: those after it are the parser losing its footing.
    let first = errors
        .iter()
        .min_by_key(|e| e.span().map(|s| s.start).unwrap_or(0));
    if let Some(e) = first {
        report_syntax_error(src, e, d);
    }
    None
}

/// Words one parser error for an author: a key set twice gets its own message, an error just
/// after an unclosed bracket is put at the end of the line that lacks it.
fn report_syntax_error(src: &str, e: &toml::de::Error, d: &mut Diags) {
    let msg = e
        .message()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    let msg = lowercase_first(msg.trim_end_matches('.'));
    let at = e.span().map(|s| s.start).unwrap_or(0);
    if msg == "duplicate key"
        && let Some(span) = e.span()
        && let Some(text) = duplicate_key(src, span)
    {
        d.at(at, text);
        return;
    }
    match unclosed_before(src, at) {
        Some(end) => d.at(
            end,
            format!("toml syntax error: {msg} on the next line; a `]` or `}}` is probably missing at the end of this line"),
        ),
        None => d.at(
            at,
            format!("toml syntax error: {msg}; check quotes, brackets, commas and `=` here"),
        ),
    }
}

/// The message for a key set twice, the second time at `span`: the key, the table it is in
/// (named by its header and id) and the line it was first set on. `None` when the first time is
/// not found (e.g. a dotted key), to fall back to the parser's words.
fn duplicate_key(src: &str, span: std::ops::Range<usize>) -> Option<String> {
    let key = src.get(span.clone())?.trim().trim_matches('"');
    let lines: Vec<&str> = src.lines().collect();
    let here = src[..span.start].matches('\n').count();
    let header = |l: &str| l.trim_start().starts_with('[');
    let is_key = |l: &str| {
        l.trim_start()
            .strip_prefix(key)
            .is_some_and(|rest| rest.trim_start().starts_with('='))
    };
    if header(lines.get(here)?) {
        return duplicate_table(&lines, here);
    }
    let start = lines[..here]
        .iter()
        .rposition(|l| header(l))
        .map_or(0, |k| k + 1);
    let first = start + lines[start..here].iter().position(|l| is_key(l))?;
    let table = table_named(&lines, start);
    Some(format!(
        "duplicate key `{}` in {table} (first set on line {}); keep one of the two",
        echo(key),
        first + 1
    ))
}

/// The message for a table header given twice (on line `here`), naming the first header of the
/// same text.
fn duplicate_table(lines: &[&str], here: usize) -> Option<String> {
    let first = lines[..here]
        .iter()
        .position(|l| l.trim() == lines[here].trim())?;
    Some(format!(
        "duplicate table `{}` (first on line {}); merge the two into one",
        lines[here].trim(),
        first + 1
    ))
}

/// The table whose keys start on line `start`, as a message names it: "the file" before any
/// header, "door 'd1'" for an entry of an array of tables with an id, "[kind]" otherwise.
fn table_named(lines: &[&str], start: usize) -> String {
    let header = |l: &str| l.trim_start().starts_with('[');
    match start.checked_sub(1).map(|k| lines[k].trim()) {
        None => "the file".to_string(),
        Some(h) => {
            let kind = h.trim_matches(|c| c == '[' || c == ']');
            let id = lines[start..]
                .iter()
                .take_while(|l| !header(l))
                .find_map(|l| {
                    let rest = l
                        .trim_start()
                        .strip_prefix("id")?
                        .trim_start()
                        .strip_prefix('=')?;
                    Some(rest.trim().trim_matches('"').to_string())
                });
            match (h.starts_with("[["), id) {
                (true, Some(id)) => format!("{} '{id}'", kind.strip_suffix('s').unwrap_or(kind)),
                _ => format!("[{kind}]"),
            }
        }
    }
}

/// When an error sits at the start of a line while an array or inline table opened on an
/// earlier line is still open, the end of the last non-blank line before it (where the closing
/// bracket belongs).
fn unclosed_before(src: &str, at: usize) -> Option<usize> {
    let before = &src[..at.min(src.len())];
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    if !before[line_start..].trim().is_empty() || line_start == 0 {
        return None;
    }
    let prev = before[..line_start].trim_end();
    let depth = prev.bytes().fold(0i64, |n, b| match b {
        b'[' | b'{' => n + 1,
        b']' | b'}' => n - 1,
        _ => n,
    });
    (depth > 0 && !prev.ends_with(',')).then_some(prev.len())
}

pub(crate) fn lowercase_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

pub(crate) type Val<'i> = Spanned<DeValue<'i>>;

/// Looks a key up in a table: (key start, value).
pub(crate) fn get<'t, 'i>(t: &'t DeTable<'i>, key: &str) -> Option<(usize, &'t Val<'i>)> {
    t.iter()
        .find(|(k, _)| k.get_ref().as_ref() == key)
        .map(|(k, v)| (k.span().start, v))
}

/// Reports keys of `t` that are not in `known`.
pub(crate) fn unknown_keys(t: &DeTable<'_>, known: &[&str], ctx: &str, d: &mut Diags) {
    for (k, _) in t.iter() {
        let name = k.get_ref().as_ref();
        if !known.contains(&name) {
            let hint = suggest::hint(name, known.iter().copied(), "keys here");
            d.at(
                k.span().start,
                format!("unknown key `{}` in {ctx}; {hint}", echo(name)),
            );
        }
    }
}

/// Whether `t` holds an unknown key that looks like a misspelling of `key` (then the
/// unknown-key message, with its "did you mean", already says what is wrong).
pub(crate) fn misspelt(t: &DeTable<'_>, key: &str, known: &[&str]) -> bool {
    t.iter().any(|(k, _)| {
        let name = k.get_ref().as_ref();
        !known.contains(&name) && suggest::closest(name, known.iter().copied()) == Some(key)
    })
}

/// Reports a missing key unless a misspelling of it is already reported.
pub(crate) fn missing(
    t: &DeTable<'_>,
    key: &str,
    known: &[&str],
    at: usize,
    msg: String,
    d: &mut Diags,
) {
    if !misspelt(t, key, known) {
        d.at(at, msg);
    }
}

pub(crate) fn type_name(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a number",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

pub(crate) fn parse_int(s: &str, radix: u32) -> Option<i64> {
    i64::from_str_radix(s, radix)
        .ok()
        .or_else(|| i64::from_str_radix(&s.replace('_', ""), radix).ok())
}

/// A finite number (integers accepted); reports wrong types and non-finite values.
pub(crate) fn number(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<f64> {
    let at = v.span().start;
    let x = match v.get_ref() {
        DeValue::Integer(i) => parse_int(i.as_str(), i.radix()).map(|n| n as f64),
        DeValue::Float(f) => {
            let s = f.as_str();
            s.parse::<f64>()
                .ok()
                .or_else(|| s.replace('_', "").parse::<f64>().ok())
        }
        other => {
            d.at(
                at,
                format!(
                    "`{key}` in {ctx} must be a number, found {}; write a plain number such as `{key} = 1.0`",
                    type_name(other)
                ),
            );
            return None;
        }
    };
    finite(x, at, key, ctx, d)
}

/// `x` when it was read and is finite; otherwise reports why not at `at`.
fn finite(x: Option<f64>, at: usize, key: &str, ctx: &str, d: &mut Diags) -> Option<f64> {
    match x {
        Some(x) if x.is_finite() => Some(x),
        Some(_) => {
            d.at(
                at,
                format!("`{key}` in {ctx} is not a finite number; use an ordinary number, not nan or inf"),
            );
            None
        }
        None => {
            d.at(
                at,
                format!("`{key}` in {ctx} is out of range; use an ordinary number"),
            );
            None
        }
    }
}

/// A point `[x, y]` in metres.
pub(crate) fn point(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<[f64; 2]> {
    let DeValue::Array(a) = v.get_ref() else {
        d.at(
            v.span().start,
            format!(
                "`{key}` in {ctx} must be a point [x, y] in metres, found {}; write e.g. `[1.0, 2.0]`",
                type_name(v.get_ref())
            ),
        );
        return None;
    };
    if a.len() != 2 {
        d.at(
            v.span().start,
            format!(
                "`{key}` in {ctx} must be a point of 2 numbers [x, y], found {} value(s); write e.g. `[1.0, 2.0]`",
                a.len()
            ),
        );
        return None;
    }
    let x = number(&a[0], key, ctx, d);
    let y = number(&a[1], key, ctx, d);
    Some([x?, y?])
}

/// A list of points; each point's start offset goes to `spans`.
pub(crate) fn points(
    v: &Val<'_>,
    key: &str,
    ctx: &str,
    d: &mut Diags,
    spans: &mut Vec<usize>,
) -> Option<Vec<[f64; 2]>> {
    let DeValue::Array(a) = v.get_ref() else {
        d.at(
            v.span().start,
            format!(
                "`{key}` in {ctx} must be a list of points, found {}; write e.g. `[[0.0, 0.0], [4.0, 0.0]]`",
                type_name(v.get_ref())
            ),
        );
        return None;
    };
    each_point(a, key, ctx, d, spans)
}

/// Reads every point of the list `a` (all of them, so each bad one is reported); `None` if any
/// is bad or `d` fills up.
fn each_point(
    a: &toml::de::DeArray<'_>,
    key: &str,
    ctx: &str,
    d: &mut Diags,
    spans: &mut Vec<usize>,
) -> Option<Vec<[f64; 2]>> {
    let mut out = Vec::with_capacity(a.len().min(MAX_SEGMENTS + 1));
    let mut ok = true;
    for p in a.iter() {
        spans.push(p.span().start);
        match point(p, key, ctx, d) {
            Some(p) => out.push(p),
            None => ok = false,
        }
        if d.is_full() {
            return None;
        }
    }
    ok.then_some(out)
}

pub(crate) fn string(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<String> {
    match v.get_ref() {
        DeValue::String(s) => Some(s.to_string()),
        other => {
            d.at(
                v.span().start,
                format!(
                    "`{key}` in {ctx} must be a string, found {}; put it in quotes, e.g. `{key} = \"text\"`",
                    type_name(other)
                ),
            );
            None
        }
    }
}

pub(crate) fn boolean(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<bool> {
    match v.get_ref() {
        DeValue::Boolean(b) => Some(*b),
        other => {
            d.at(
                v.span().start,
                format!(
                    "`{key}` in {ctx} must be true or false, found {}; write `{key} = true` or `{key} = false`",
                    type_name(other)
                ),
            );
            None
        }
    }
}

/// An entity id: non-empty, letters, digits, `-`, `_`, `.` (ids appear in comma lists on the
/// command line).
pub(crate) fn id(
    t: &DeTable<'_>,
    known: &[&str],
    at_table: usize,
    ctx: &str,
    d: &mut Diags,
) -> (Option<String>, usize) {
    let Some((_, v)) = get(t, "id") else {
        missing(
            t,
            "id",
            known,
            at_table,
            format!("missing key `id` in {ctx}; add a unique `id = \"...\"`"),
            d,
        );
        return (None, at_table);
    };
    let at = v.span().start;
    let Some(s) = string(v, "id", ctx, d) else {
        return (None, at);
    };
    (plain_id(s, at, ctx, d), at)
}

/// `s` when it is a plain id (non-empty; letters, digits, `-`, `_`, `.`); otherwise reports it.
fn plain_id(s: String, at: usize, ctx: &str, d: &mut Diags) -> Option<String> {
    if s.is_empty()
        || !s
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
    {
        d.at(
            at,
            format!(
                "id {:?} in {ctx} is not a plain id; use letters, digits, `-`, `_` or `.` only (e.g. \"n-03\")",
                echo(&s)
            ),
        );
        return None;
    }
    Some(s)
}

/// The array of tables under `key` (e.g. `[[doors]]`), or an error when it is something else.
pub(crate) fn table_array<'t, 'i>(
    top: &'t DeTable<'i>,
    key: &str,
    d: &mut Diags,
) -> Vec<(usize, &'t DeTable<'i>)> {
    let Some((kat, v)) = get(top, key) else {
        return Vec::new();
    };
    let DeValue::Array(a) = v.get_ref() else {
        d.at(
            kat,
            format!(
                "`{key}` must be a list of tables, found {}; write each entry as a `[[{key}]]` section",
                type_name(v.get_ref())
            ),
        );
        return Vec::new();
    };
    tables_of(a, key, d)
}

/// The tables of the array under `key`; each entry that is not a table is reported.
fn tables_of<'t, 'i>(
    a: &'t toml::de::DeArray<'i>,
    key: &str,
    d: &mut Diags,
) -> Vec<(usize, &'t DeTable<'i>)> {
    let mut out = Vec::new();
    for e in a.iter() {
        match e.get_ref() {
            DeValue::Table(t) => out.push((e.span().start, t)),
            other => d.at(
                e.span().start,
                format!(
                    "each entry of `{key}` must be a table, found {}; write each entry as a `[[{key}]]` section",
                    type_name(other)
                ),
            ),
        }
    }
    out
}

pub(crate) fn ctx_of(kind: &str, id: &Option<String>, i: usize) -> String {
    match id {
        Some(id) => format!("{kind} '{id}'"),
        None => format!("{kind} #{i}"),
    }
}

/// Reads a required key of an entity with `read`, storing the offset of its value (or of the
/// table, when missing) in `slot`; a missing key is reported as "missing key `key` in ctx;
/// add {add}", with a "did you mean" for near misses.
#[allow(clippy::too_many_arguments)] // private helper; each argument is one piece of context
fn required<'t, 'i, T>(
    t: &'t DeTable<'i>,
    known: &[&str],
    key: &str,
    ctx: &str,
    at_table: usize,
    add: &str,
    d: &mut Diags,
    slot: &mut usize,
    read: impl FnOnce(&'t Val<'i>, &mut Diags) -> Option<T>,
) -> Option<T> {
    match get(t, key) {
        None => {
            let message = format!("missing key `{key}` in {ctx}; add {add}");
            missing(t, key, known, at_table, message, d);
            *slot = at_table;
            None
        }
        Some((_, v)) => {
            *slot = v.span().start;
            read(v, d)
        }
    }
}

/// Reads a required number key of an entity; stores the value's offset in `slot`.
#[allow(clippy::too_many_arguments)] // private helper; each argument is one piece of context
pub(crate) fn req_number(
    t: &DeTable<'_>,
    known: &[&str],
    key: &str,
    ctx: &str,
    at_table: usize,
    what: &str,
    d: &mut Diags,
    slot: &mut usize,
) -> Option<f64> {
    let add = format!("`{key} = ...` ({what})");
    required(t, known, key, ctx, at_table, &add, d, slot, |v, d| {
        number(v, key, ctx, d)
    })
}

pub(crate) fn opt_number(
    t: &DeTable<'_>,
    key: &str,
    ctx: &str,
    default: f64,
    at_table: usize,
    d: &mut Diags,
    slot: &mut usize,
) -> Option<f64> {
    match get(t, key) {
        None => {
            *slot = at_table;
            Some(default)
        }
        Some((_, v)) => {
            *slot = v.span().start;
            number(v, key, ctx, d)
        }
    }
}

#[allow(clippy::too_many_arguments)] // private helper; each argument is one piece of context
pub(crate) fn req_point(
    t: &DeTable<'_>,
    known: &[&str],
    key: &str,
    ctx: &str,
    at_table: usize,
    d: &mut Diags,
    slot: &mut usize,
) -> Option<[f64; 2]> {
    let add = format!("`{key} = [x, y]` (metres)");
    required(t, known, key, ctx, at_table, &add, d, slot, |v, d| {
        point(v, key, ctx, d)
    })
}

#[allow(clippy::too_many_arguments)] // private helper; each argument is one piece of context
pub(crate) fn req_points(
    t: &DeTable<'_>,
    known: &[&str],
    key: &str,
    ctx: &str,
    at_table: usize,
    d: &mut Diags,
    key_slot: &mut usize,
    spans: &mut Vec<usize>,
) -> Option<Vec<[f64; 2]>> {
    let add = format!("`{key} = [[x, y], ...]` (metres)");
    required(t, known, key, ctx, at_table, &add, d, key_slot, |v, d| {
        points(v, key, ctx, d, spans)
    })
}

/// Reads every table of an array of entries (walls, doors, ...) with `read`, keeping the
/// locations of those that read cleanly; `ok` turns false when one does not, and
/// `on_fail(index, table offset, table)` of it goes to `failed`. `None` when the problem list is
/// full.
#[allow(clippy::too_many_arguments)] // private helper; each argument is one piece of context
pub(crate) fn read_entries_with<T, L, F>(
    tables: Vec<(usize, &DeTable<'_>)>,
    d: &mut Diags,
    ok: &mut bool,
    read: fn(&DeTable<'_>, usize, usize, &mut Diags, &mut L) -> Option<T>,
    new_loc: impl Fn(usize) -> L,
    failed: &mut Vec<F>,
    on_fail: impl Fn(usize, usize, &DeTable<'_>) -> F,
) -> Option<(Vec<T>, Vec<L>)> {
    let (mut items, mut locs) = (Vec::new(), Vec::new());
    for (i, (at, t)) in tables.into_iter().enumerate() {
        let mut l = new_loc(at);
        match read(t, at, i, d, &mut l) {
            Some(x) => {
                items.push(x);
                locs.push(l);
            }
            None => {
                *ok = false;
                failed.push(on_fail(i, at, t));
            }
        }
        if d.is_full() {
            return None;
        }
    }
    Some((items, locs))
}

/// The table under `key`, or an error when it is something else; `None` when absent.
pub(crate) fn table<'t, 'i>(
    top: &'t DeTable<'i>,
    key: &str,
    d: &mut Diags,
) -> Option<(usize, &'t DeTable<'i>)> {
    let (kat, v) = get(top, key)?;
    match v.get_ref() {
        DeValue::Table(t) => Some((v.span().start, t)),
        other => {
            d.at(
                kat,
                format!(
                    "`{key}` must be a table, found {}; write it as a `[{key}]` section",
                    type_name(other)
                ),
            );
            None
        }
    }
}

/// An integer; reports other types.
pub(crate) fn integer(v: &Val<'_>, key: &str, ctx: &str, d: &mut Diags) -> Option<i64> {
    let at = v.span().start;
    match v.get_ref() {
        DeValue::Integer(i) => {
            let n = parse_int(i.as_str(), i.radix());
            if n.is_none() {
                d.at(
                    at,
                    format!("`{key}` in {ctx} is out of range; use a smaller whole number"),
                );
            }
            n
        }
        other => {
            d.at(
                at,
                format!(
                    "`{key}` in {ctx} must be a whole number, found {}; write e.g. `{key} = 1`",
                    type_name(other)
                ),
            );
            None
        }
    }
}

/// A list of strings, each with its offset.
pub(crate) fn strings(
    v: &Val<'_>,
    key: &str,
    ctx: &str,
    d: &mut Diags,
) -> Option<Vec<Spanned<String>>> {
    let DeValue::Array(a) = v.get_ref() else {
        d.at(
            v.span().start,
            format!(
                "`{key}` in {ctx} must be a list of strings, found {}; write e.g. `[\"a\", \"b\"]`",
                type_name(v.get_ref())
            ),
        );
        return None;
    };
    let mut out = Vec::with_capacity(a.len().min(MAX_SEGMENTS));
    for e in a.iter() {
        let s = string(e, key, ctx, d)?;
        out.push(Spanned::new(e.span(), s));
    }
    Some(out)
}

/// A value as a plain `toml::Value` (for tables whose keys a model above `spec` knows).
pub(crate) fn plain(v: &DeValue<'_>) -> Option<toml::Value> {
    use toml::Value;
    Some(match v {
        DeValue::String(s) => Value::String(s.to_string()),
        DeValue::Integer(i) => Value::Integer(parse_int(i.as_str(), i.radix())?),
        DeValue::Float(f) => Value::Float(f.as_str().replace('_', "").parse().ok()?),
        DeValue::Boolean(b) => Value::Boolean(*b),
        DeValue::Datetime(t) => Value::Datetime(*t),
        DeValue::Array(a) => Value::Array(
            a.iter()
                .map(|e| plain(e.get_ref()))
                .collect::<Option<_>>()?,
        ),
        DeValue::Table(t) => Value::Table(
            t.iter()
                .map(|(k, e)| Some((k.get_ref().to_string(), plain(e.get_ref())?)))
                .collect::<Option<_>>()?,
        ),
    })
}
