//! The matches file any place recognizer can write for `placewords score`: one line per matched
//! scan pair, comma separated, after a header line.
//!
//! ```text
//! query_run,query_scan,matched_run,matched_scan,score
//! 0,1520,0,312,0.93
//! 1,88,0,2204,
//! ```
//!
//! - `query_run`, `matched_run`: the run (the `NNN` of `run-NNN.log`, the `run` of
//!   `manifest.json`) of the newer and of the older scan;
//! - `query_scan`, `matched_scan`: 0-based index of the laser line (FLASER) within its run's log;
//! - `score`: optional (may be empty or missing), any number the tool uses for confidence; kept
//!   for reference and not used for scoring.
//!
//! Blank lines and lines starting with `#` are ignored. A bad line is an error naming
//! `file:line:col`. Five columns of numbers do not need a CSV crate.

use crate::spec::diag::Diagnostic;

/// One matched pair of scans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MatchRow {
    pub query_run: usize,
    pub query_scan: usize,
    pub matched_run: usize,
    pub matched_scan: usize,
    pub score: Option<f64>,
}

/// The header line.
pub const HEADER: &str = "query_run,query_scan,matched_run,matched_scan,score";

/// Why a matches file could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MatchesCsvError(pub Diagnostic);

/// The text of a matches file holding `rows`.
pub fn write_matches(rows: &[MatchRow]) -> String {
    let mut out = String::with_capacity(32 * (rows.len() + 1));
    out.push_str(HEADER);
    out.push('\n');
    for r in rows {
        let score = r.score.map(|s| s.to_string()).unwrap_or_default();
        out.push_str(&format!(
            "{},{},{},{},{score}\n",
            r.query_run, r.query_scan, r.matched_run, r.matched_scan
        ));
    }
    out
}

/// Parses a matches file; `path` names it in errors.
pub fn parse_matches(src: &str, path: &str) -> Result<Vec<MatchRow>, MatchesCsvError> {
    let err = |line: usize, col: usize, message: String| {
        MatchesCsvError(Diagnostic::error(path, (line, col), message))
    };
    let mut rows = Vec::new();
    let mut header_seen = false;
    for (i, text) in src.lines().enumerate() {
        let line = i + 1;
        let t = text.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        if !header_seen {
            let got: Vec<&str> = t.split(',').map(str::trim).collect();
            let want: Vec<&str> = HEADER.split(',').collect();
            if got.len() < 4 || got[..4] != want[..4] {
                return Err(err(
                    line,
                    1,
                    format!("expected the header `{HEADER}` (score optional); found `{t}`"),
                ));
            }
            header_seen = true;
            continue;
        }
        rows.push(parse_row(text, line).map_err(|(col, m)| err(line, col, m))?);
    }
    if !header_seen {
        return Err(err(
            1,
            1,
            format!("empty file; the first line must be `{HEADER}`"),
        ));
    }
    Ok(rows)
}

/// One data line; errors carry the 1-based column.
fn parse_row(text: &str, _line: usize) -> Result<MatchRow, (usize, String)> {
    let mut fields = Vec::new();
    let mut col = 1;
    for f in text.split(',') {
        fields.push((col, f.trim()));
        col += f.len() + 1;
    }
    if !(4..=5).contains(&fields.len()) {
        return Err((
            1,
            format!(
                "expected 4 or 5 comma-separated fields ({HEADER}); found {}",
                fields.len()
            ),
        ));
    }
    let names = ["query_run", "query_scan", "matched_run", "matched_scan"];
    let mut ints = [0usize; 4];
    for (k, name) in names.iter().enumerate() {
        let (c, f) = fields[k];
        ints[k] = f
            .parse()
            .map_err(|_| (c, format!("{name} `{f}` is not a whole number ≥ 0")))?;
    }
    let score = match fields.get(4) {
        None | Some((_, "")) => None,
        Some(&(c, f)) => Some(f.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or((
            c,
            format!("score `{f}` is not a number; leave it empty if unknown"),
        ))?),
    };
    Ok(MatchRow {
        query_run: ints[0],
        query_scan: ints[1],
        matched_run: ints[2],
        matched_scan: ints[3],
        score,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_with_and_without_score() {
        let rows = vec![
            MatchRow {
                query_run: 1,
                query_scan: 20,
                matched_run: 0,
                matched_scan: 3,
                score: Some(0.5),
            },
            MatchRow {
                query_run: 0,
                query_scan: 9,
                matched_run: 0,
                matched_scan: 1,
                score: None,
            },
        ];
        let text = write_matches(&rows);
        assert_eq!(parse_matches(&text, "m.csv").unwrap(), rows);
        let short = "query_run,query_scan,matched_run,matched_scan\n# c\n\n0,5,0,1\n";
        assert_eq!(parse_matches(short, "m.csv").unwrap().len(), 1);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse_matches(&format!("{HEADER}\n0,5,x,1,\n"), "m.csv").unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.csv:2:5: matched_run `x` is not a whole number ≥ 0"
        );
        let e = parse_matches("a,b\n", "m.csv").unwrap_err();
        assert!(
            e.to_string().starts_with("m.csv:1:1: expected the header"),
            "{e}"
        );
        assert!(parse_matches("", "m.csv").is_err());
        let e = parse_matches(&format!("{HEADER}\n1,2,3\n"), "m.csv").unwrap_err();
        assert!(e.to_string().contains("4 or 5"), "{e}");
    }
}
