//! Located diagnostics: `file:line:col: what is wrong; what to try`, and the error type every
//! file loader returns.

use std::fmt;
use std::path::{Path, PathBuf};

/// Whether a problem stops the file from being used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// The file is refused (exit 2).
    #[default]
    Error,
    /// The file is used, but probably not as its author meant.
    Warning,
    /// Not a problem itself: a check that was skipped, and why (it depends on a part of the
    /// file that did not read).
    Note,
}

impl Severity {
    /// `error` or `warning`, as printed.
    pub fn name(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

/// One problem found in a file, with its 1-based line and column.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub path: String,
    pub line: usize,
    pub col: usize,
    /// `what is wrong; what to try`, lowercase.
    pub message: String,
    pub severity: Severity,
}

impl Diagnostic {
    /// A problem at `(line, col)` (1-based) of `path`.
    pub fn error(path: &str, (line, col): (usize, usize), message: impl Into<String>) -> Self {
        Diagnostic {
            path: path.to_string(),
            line,
            col,
            message: message.into(),
            severity: Severity::Error,
        }
    }

    /// A warning at `(line, col)` (1-based) of `path`: the file is used as repaired or read.
    pub fn warning(path: &str, at: (usize, usize), message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(path, at, message)
        }
    }
}

/// Longest piece of a file echoed in a message, characters: a 10 MB key is not printed back.
pub const MAX_ECHO_CHARS: usize = 60;

/// A number as a person writes it: `1e308` and `1e-9` in exponent form rather than as a
/// 300-digit expansion, others as Rust prints them (`0.25`, `1000`).
pub fn fmt_number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `text` cut to [`MAX_ECHO_CHARS`] characters, with `...` when cut.
pub fn echo(text: &str) -> String {
    match text.char_indices().nth(MAX_ECHO_CHARS) {
        None => text.to_string(),
        Some((cut, _)) => format!("{}...", &text[..cut]),
    }
}

/// Reads a text file; invalid UTF-8 is a located problem at the first bad byte.
pub fn read_text(path: &Path) -> Result<String, SpecError> {
    let bytes = std::fs::read(path).map_err(|e| SpecError::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let good = e.utf8_error().valid_up_to();
        // The valid prefix is text, so lines and columns count as everywhere else.
        let prefix = std::str::from_utf8(&bytes[..good]).unwrap_or("");
        let at = line_col(prefix, good);
        SpecError::Invalid(vec![Diagnostic::error(
            &path.display().to_string(),
            at,
            format!(
                "the file is not valid UTF-8 (byte 0x{:02x}); save it as UTF-8 text",
                bytes[good]
            ),
        )])
    })
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let tag = match self.severity {
            Severity::Error => "",
            Severity::Warning => "warning: ",
            Severity::Note => "note: ",
        };
        write!(
            f,
            "{}:{}:{}: {tag}{}",
            self.path, self.line, self.col, self.message
        )
    }
}

/// A JSON parse error of `path` at serde_json's line and column, `what` before its message;
/// serde_json's own " at line L column C" is dropped so the place is said once.
pub fn json_diagnostic(path: &str, e: &serde_json::Error, what: &str) -> Diagnostic {
    let text = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = text.strip_suffix(&suffix).unwrap_or(&text);
    let at = (e.line().max(1), e.column().max(1));
    let sep = if what.is_empty() { "" } else { ": " };
    Diagnostic::error(path, at, format!("{what}{sep}{message}"))
}

/// 1-based (line, column) of a byte offset in `src`; the column counts characters.
pub fn line_col(src: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(src.len());
    let mut cut = offset;
    while !src.is_char_boundary(cut) {
        cut -= 1;
    }
    let before = &src[..cut];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    let col = before[line_start..].chars().count() + 1;
    (line, col)
}

/// Why a file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Every problem of the file, in file order.
    #[error("{}", join(.0))]
    Invalid(Vec<Diagnostic>),
}

impl SpecError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        SpecError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// The located problems (empty for an I/O error).
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            SpecError::Invalid(d) => d,
            SpecError::Io { .. } => &[],
        }
    }
}

/// How problems are printed: for people, or one JSON object per line for editors and CI (as
/// cargo's `--message-format json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MessageFormat {
    /// `file:line:col: error: what is wrong; what to try`, the first [`SHOWN_PROBLEMS`], then a
    /// count.
    #[default]
    Human,
    /// `{"path":..,"line":..,"col":..,"severity":"error"|"warning"|"note","message":..}`, every
    /// problem.
    Json,
}

impl MessageFormat {
    /// The format named `human` or `json`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "human" => Some(MessageFormat::Human),
            "json" => Some(MessageFormat::Json),
            _ => None,
        }
    }
}

/// Problems printed in human form before the rest are only counted.
pub const SHOWN_PROBLEMS: usize = 20;

impl Diagnostic {
    /// One line in `format`.
    pub fn render(&self, format: MessageFormat) -> String {
        match format {
            MessageFormat::Human => format!(
                "{}:{}:{}: {}: {}",
                self.path,
                self.line,
                self.col,
                self.severity.name(),
                self.message
            ),
            MessageFormat::Json => serde_json::json!({
                "path": self.path,
                "line": self.line,
                "col": self.col,
                "severity": self.severity.name(),
                "message": self.message,
            })
            .to_string(),
        }
    }
}

impl SpecError {
    /// Every problem as lines in `format` (human form: the first few, then a count).
    pub fn render(&self, format: MessageFormat) -> Vec<String> {
        let diags = match self {
            SpecError::Invalid(d) => d.clone(),
            SpecError::Io { path, source } => vec![Diagnostic::error(
                &path.display().to_string(),
                (1, 1),
                format!("cannot read: {source}; check the path"),
            )],
        };
        let shown = match format {
            MessageFormat::Human => SHOWN_PROBLEMS.min(diags.len()),
            MessageFormat::Json => diags.len(),
        };
        let mut out: Vec<String> = diags[..shown].iter().map(|d| d.render(format)).collect();
        if shown < diags.len() {
            out.push(format!(
                "{} more problems not shown; fix the ones above and check again",
                diags.len() - shown
            ));
        }
        out
    }
}

fn join(d: &[Diagnostic]) -> String {
    d.iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Most diagnostics reported for one file.
pub const MAX_DIAGNOSTICS: usize = 500;

/// Collects located problems of one file; offsets are bytes into the source.
pub struct Diags<'a> {
    src: &'a str,
    path: &'a str,
    list: Vec<(usize, String, Severity)>,
    overflow: usize,
}

impl<'a> Diags<'a> {
    pub fn new(src: &'a str, path: &'a str) -> Self {
        Diags {
            src,
            path,
            list: Vec::new(),
            overflow: 0,
        }
    }

    /// Records a problem at byte `offset`.
    pub fn at(&mut self, offset: usize, message: String) {
        self.push(offset, message, Severity::Error);
    }

    /// Records a warning at byte `offset`: the file stays usable.
    pub fn warn(&mut self, offset: usize, message: String) {
        self.push(offset, message, Severity::Warning);
    }

    /// Records a note at byte `offset`: a check skipped, and why.
    pub fn note(&mut self, offset: usize, message: String) {
        self.push(offset, message, Severity::Note);
    }

    fn push(&mut self, offset: usize, message: String, severity: Severity) {
        if self.list.len() >= MAX_DIAGNOSTICS {
            self.overflow += 1;
        } else {
            self.list.push((offset, message, severity));
        }
    }

    /// Whether any error (not a warning) was recorded.
    pub fn has_errors(&self) -> bool {
        self.overflow > 0 || self.list.iter().any(|(_, _, s)| *s == Severity::Error)
    }

    /// Whether the report is full (further problems are only counted).
    pub fn is_full(&self) -> bool {
        self.list.len() >= MAX_DIAGNOSTICS
    }

    /// 1-based line of byte `offset`.
    pub fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.src.len());
        self.src.as_bytes()[..end]
            .iter()
            .filter(|b| **b == b'\n')
            .count()
            + 1
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The problems in file order, with 1-based lines and columns (columns count characters).
    pub fn into_sorted(self) -> Vec<Diagnostic> {
        let mut line_starts = vec![0usize];
        line_starts.extend(
            self.src
                .bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i + 1),
        );
        let mut list = self.list;
        list.sort_by_key(|(o, _, _)| *o);
        list.dedup();
        let mut out: Vec<Diagnostic> = list
            .into_iter()
            .map(|(offset, message, severity)| {
                let mut cut = offset.min(self.src.len());
                while !self.src.is_char_boundary(cut) {
                    cut -= 1;
                }
                let line_idx = line_starts.partition_point(|&s| s <= cut) - 1;
                let start = line_starts[line_idx];
                let col = self.src[start..cut].chars().count() + 1;
                Diagnostic {
                    path: self.path.to_string(),
                    line: line_idx + 1,
                    col,
                    message,
                    severity,
                }
            })
            .collect();
        if self.overflow > 0 {
            let last = out.last().map(|d| (d.line, d.col)).unwrap_or((1, 1));
            out.push(Diagnostic {
                path: self.path.to_string(),
                line: last.0,
                col: last.1,
                message: format!(
                    "{} more problems not shown; fix the ones above and check again",
                    self.overflow
                ),
                severity: Severity::Error,
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_from_one() {
        let s = "ab\ncd\nef";
        assert_eq!(line_col(s, 0), (1, 1));
        assert_eq!(line_col(s, 4), (2, 2));
        assert_eq!(line_col(s, 100), (3, 3));
    }
}
