//! The matches file any place recognizer can write for `placewords score`: one line per matched
//! scan pair, comma separated, after a header line.
//!
//! ```text
//! query_run,query_scan,matched_run,matched_scan,score,direction
//! 0,1520,0,312,0.93,same
//! 1,88,0,2204,,opposite
//! 2,40,0,17
//! ```
//!
//! - `query_run`, `matched_run`: the run (the `NNN` of `run-NNN.log`, the `run` of
//!   `manifest.json`) of the newer and of the older scan;
//! - `query_scan`, `matched_scan`: 0-based index of the laser line (FLASER) within its run's log;
//! - `score`: optional (may be empty or missing), any number the tool uses for confidence; kept
//!   for reference and not used for scoring;
//! - `direction`: optional, `same` (the older scan was driven the way the newer one is, the
//!   default when the column or the field is missing or empty) or `opposite` (driven the other
//!   way: the true headings must be 180° apart, within the tolerance, for the pair to count).
//!
//! The first four columns are required, in this order; `score` and `direction` may follow in
//! either order, each at most once, and the header says which. A line may leave out trailing
//! optional fields. A header of the first four columns alone (or with `score`) reads as before
//! the direction column existed: lines of 4 or 5 fields, the fifth the score, every pair
//! `same`.
//!
//! Blank lines and lines starting with `#` are ignored. A bad line is an error naming
//! `file:line:col`. Six columns of numbers and words do not need a CSV crate.

use crate::spec::diag::Diagnostic;

use crate::place::Direction;

/// One matched pair of scans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MatchRow {
    pub query_run: usize,
    pub query_scan: usize,
    pub matched_run: usize,
    pub matched_scan: usize,
    pub score: Option<f64>,
    /// The direction the pair claims. Default `Same`.
    pub direction: Direction,
}

/// The header line [`write_matches`] writes (every column).
pub const HEADER: &str = "query_run,query_scan,matched_run,matched_scan,score,direction";

/// The required columns, in order.
const REQUIRED: [&str; 4] = ["query_run", "query_scan", "matched_run", "matched_scan"];

/// An optional column after the required ones.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Optional {
    Score,
    Direction,
}

/// Why a matches file could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MatchesCsvError(pub Diagnostic);

/// The text of a matches file holding `rows`.
pub fn write_matches(rows: &[MatchRow]) -> String {
    let mut out = String::with_capacity(40 * (rows.len() + 1));
    out.push_str(HEADER);
    out.push('\n');
    for r in rows {
        let score = r.score.map(|s| s.to_string()).unwrap_or_default();
        out.push_str(&format!(
            "{},{},{},{},{score},{}\n",
            r.query_run,
            r.query_scan,
            r.matched_run,
            r.matched_scan,
            r.direction.name()
        ));
    }
    out
}

/// A matches file as read: its rows and the 1-based line each came from (so a later check of
/// a row, e.g. a scan the logs do not hold, can name its line).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MatchesFile {
    pub rows: Vec<MatchRow>,
    /// `lines[k]` is the line of `rows[k]`.
    pub lines: Vec<usize>,
}

/// Parses a matches file; `path` names it in errors.
pub fn parse_matches(src: &str, path: &str) -> Result<Vec<MatchRow>, MatchesCsvError> {
    read_matches(src, path).map(|f| f.rows)
}

/// [`parse_matches`] keeping each row's line.
pub fn read_matches(src: &str, path: &str) -> Result<MatchesFile, MatchesCsvError> {
    let err = |line: usize, col: usize, message: String| {
        MatchesCsvError(Diagnostic::error(path, (line, col), message))
    };
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut layout: Option<Vec<Optional>> = None;
    for (i, text) in src.lines().enumerate() {
        let line = i + 1;
        let t = text.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        match &layout {
            None => layout = Some(parse_header(text).map_err(|(col, m)| err(line, col, m))?),
            Some(cols) => {
                rows.push(parse_row(text, cols).map_err(|(col, m)| err(line, col, m))?);
                lines.push(line);
            }
        }
    }
    if layout.is_none() {
        return Err(err(
            1,
            1,
            format!("empty file; the first line must be `{HEADER}`"),
        ));
    }
    Ok(MatchesFile { rows, lines })
}

/// Comma-separated fields, trimmed, with their 1-based columns.
fn fields(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut col = 1;
    for f in text.split(',') {
        out.push((col + (f.len() - f.trim_start().len()), f.trim()));
        col += f.len() + 1;
    }
    out
}

/// The optional column named `name` (at column `col`).
fn optional_column(col: usize, name: &str) -> Result<Optional, (usize, String)> {
    match name {
        "score" => Ok(Optional::Score),
        "direction" => Ok(Optional::Direction),
        _ => Err((
            col,
            format!(
                "unknown column `{name}`; after matched_scan come the optional \
                 columns `score` and `direction`"
            ),
        )),
    }
}

/// The header: the required columns, then the optional ones it names, in its order. A header
/// without optional columns takes a score as fifth field (as before `direction` existed).
fn parse_header(text: &str) -> Result<Vec<Optional>, (usize, String)> {
    let got = fields(text);
    if got.len() < 4 || got[..4].iter().map(|f| f.1).ne(REQUIRED) {
        return Err((
            1,
            format!(
                "expected the header `{HEADER}` (score and direction optional); found `{}`",
                text.trim()
            ),
        ));
    }
    let mut cols = Vec::new();
    for &(col, name) in &got[4..] {
        let c = optional_column(col, name)?;
        if cols.contains(&c) {
            return Err((col, format!("column `{name}` appears twice")));
        }
        cols.push(c);
    }
    if cols.is_empty() {
        cols.push(Optional::Score);
    }
    Ok(cols)
}

/// The four required whole numbers of a row (query run and scan, matched run and scan).
fn required_fields(fields: &[(usize, &str)]) -> Result<[usize; 4], (usize, String)> {
    let mut ints = [0usize; 4];
    for (k, name) in REQUIRED.iter().enumerate() {
        let (c, f) = fields[k];
        ints[k] = f
            .parse()
            .map_err(|_| (c, format!("{name} `{f}` is not a whole number ≥ 0")))?;
    }
    Ok(ints)
}

/// An error unless a row has from 4 to `most` fields (`found`).
fn field_count_ok(found: usize, most: usize) -> Result<(), (usize, String)> {
    if (4..=most).contains(&found) {
        return Ok(());
    }
    let range = if most == 5 {
        "4 or 5".to_string()
    } else {
        format!("4 to {most}")
    };
    Err((
        1,
        format!("expected {range} comma-separated fields, as the header says; found {found}"),
    ))
}

/// One data line laid out as the header says; errors carry the 1-based column.
fn parse_row(text: &str, layout: &[Optional]) -> Result<MatchRow, (usize, String)> {
    let fields = fields(text);
    field_count_ok(fields.len(), 4 + layout.len())?;
    let ints = required_fields(&fields)?;
    let mut row = MatchRow {
        query_run: ints[0],
        query_scan: ints[1],
        matched_run: ints[2],
        matched_scan: ints[3],
        score: None,
        direction: Direction::Same,
    };
    for (&(c, f), column) in fields[4..].iter().zip(layout) {
        match column {
            _ if f.is_empty() => {}
            Optional::Score => row.score = Some(parse_score(c, f)?),
            Optional::Direction => row.direction = parse_direction(c, f)?,
        }
    }
    Ok(row)
}

fn parse_score(c: usize, f: &str) -> Result<f64, (usize, String)> {
    f.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or((
        c,
        format!("score `{f}` is not a number; leave it empty if unknown"),
    ))
}

fn parse_direction(c: usize, f: &str) -> Result<Direction, (usize, String)> {
    match f {
        "same" => Ok(Direction::Same),
        "opposite" => Ok(Direction::Opposite),
        _ => Err((
            c,
            format!("direction `{f}` is neither `same` nor `opposite`; leave it empty for `same`"),
        )),
    }
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
                direction: Direction::Opposite,
            },
            MatchRow {
                query_run: 0,
                query_scan: 9,
                matched_run: 0,
                matched_scan: 1,
                score: None,
                direction: Direction::Same,
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
        assert!(e.to_string().contains("4 to 6"), "{e}");
        let e = parse_matches(
            "query_run,query_scan,matched_run,matched_scan\n1,2,3\n",
            "m.csv",
        );
        assert!(e.unwrap_err().to_string().contains("4 or 5"));
    }

    /// Files without the direction column read as before (every pair `same`, a fifth field is
    /// the score); with it, the header says where the column is and lines may leave it out.
    #[test]
    fn the_direction_column_is_optional_and_placed_by_the_header() {
        let old = "query_run,query_scan,matched_run,matched_scan,score\n0,5,0,1,0.5\n0,6,0,2\n";
        let rows = parse_matches(old, "m.csv").unwrap();
        assert_eq!(rows[0].score, Some(0.5));
        assert!(rows.iter().all(|r| r.direction == Direction::Same));
        let swapped = "query_run,query_scan,matched_run,matched_scan,direction,score\n\
                       0,5,0,1,opposite,0.5\n0,6,0,2,,\n0,7,0,3\n0,8,0,4, opposite\n";
        let rows = parse_matches(swapped, "m.csv").unwrap();
        let dirs: Vec<_> = rows.iter().map(|r| (r.direction, r.score)).collect();
        use Direction::{Opposite, Same};
        assert_eq!(
            dirs,
            [
                (Opposite, Some(0.5)),
                (Same, None),
                (Same, None),
                (Opposite, None)
            ]
        );
    }

    #[test]
    fn bad_directions_and_columns_are_located() {
        let e = parse_matches(&format!("{HEADER}\n0,5,0,1,,reverse\n"), "m.csv").unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.csv:2:10: direction `reverse` is neither `same` nor `opposite`; leave it empty for `same`"
        );
        let e = parse_matches(
            "query_run,query_scan,matched_run,matched_scan,dir\n",
            "m.csv",
        );
        let e = e.unwrap_err().to_string();
        assert!(e.starts_with("m.csv:1:47: unknown column `dir`"), "{e}");
        let twice = "query_run,query_scan,matched_run,matched_scan,direction,direction\n";
        let e = parse_matches(twice, "m.csv").unwrap_err().to_string();
        assert!(
            e.starts_with("m.csv:1:57: column `direction` appears twice"),
            "{e}"
        );
        let e = parse_matches(&format!("{HEADER}\n0,5,0,1,0.2,same,x\n"), "m.csv").unwrap_err();
        assert!(
            e.to_string().starts_with("m.csv:2:1: expected 4 to 6"),
            "{e}"
        );
    }
}
