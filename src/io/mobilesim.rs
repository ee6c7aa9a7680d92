//! MobileSim line maps (`.map`): the file read into segments and a home, in metres.
//!
//! The format: header lines (`2D-Map`, `Resolution:`, `LineMinPos:`, `LineMaxPos:`, `NumLines:`,
//! `LinesAreSorted:`, `Cairn: RobotHome x y heading …`), then `LINES` followed by one wall segment
//! per line (`x1 y1 x2 y2`, millimetres), optionally ending with `DATA` (points, ignored).
//!
//! Only the file is read here; turning the map into a world (walls, repairs, a generated route)
//! is `world import`'s, in [`crate::authoring::mobilesim`] and [`crate::authoring::route`].

use crate::geom::{Segment, Vec2};
use crate::spec::diag::Diagnostic;

/// A parsed MobileSim map, in metres and degrees.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MobileSimMap {
    pub segments: Vec<Segment>,
    /// The 1-based line of each segment.
    pub segment_lines: Vec<usize>,
    /// (x m, y m, heading degrees).
    pub home: Option<(f64, f64, f64)>,
    /// The 1-based line of the `RobotHome` cairn used (0 with none).
    pub home_line: usize,
}

/// The first N tokens of a line as finite numbers. A missing one is reported at the line's end
/// with `missing(what)`, a bad one at its column with `bad(what, text)`.
fn numbers<const N: usize>(
    (name, line_no, raw): (&str, usize, &str),
    toks: &[(usize, &str)],
    names: [&str; N],
    missing: impl Fn(&str) -> String,
    bad: impl Fn(&str, &str) -> String,
) -> Result<[f64; N], Diagnostic> {
    let mut v = [0.0; N];
    for (k, what) in names.iter().enumerate() {
        let Some(&(c, s)) = toks.get(k) else {
            let end = raw.trim_end().chars().count() + 1;
            return Err(malformed(name, line_no, end, missing(what)));
        };
        v[k] = match s.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            _ => return Err(malformed(name, line_no, c, bad(what, s))),
        };
    }
    Ok(v)
}

/// The first coordinate (millimetres) among `toks` farther than the world's
/// [`crate::spec::world::MAX_ABS_COORD_M`] from the origin, as an error at its column.
fn far_coordinate(
    (name, line_no): (&str, usize),
    toks: &[(usize, &str)],
    values: &[f64],
    names: &[&str],
) -> Result<(), Diagnostic> {
    let limit_mm = crate::spec::world::MAX_ABS_COORD_M * 1000.0;
    match values.iter().position(|v| v.abs() > limit_mm) {
        None => Ok(()),
        Some(k) => Err(malformed(
            name,
            line_no,
            toks.get(k).map_or(1, |t| t.0),
            format!(
                "{} = {} mm is more than {} km from the origin; the map is in millimetres: \
                 check this value",
                names[k],
                crate::spec::diag::fmt_number(values[k]),
                crate::spec::world::MAX_ABS_COORD_M / 1000.0
            ),
        )),
    }
}

fn malformed(path: &str, line: usize, col: usize, message: impl Into<String>) -> Diagnostic {
    Diagnostic::error(path, (line, col), message)
}

/// Tokens with 1-based character columns.
fn tokens(line: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None;
    for (col0, (i, ch)) in line.char_indices().enumerate() {
        if ch.is_whitespace() {
            if let Some((b, c)) = start.take() {
                out.push((c, &line[b..i]));
            }
        } else if start.is_none() {
            start = Some((i, col0 + 1));
        }
    }
    if let Some((b, c)) = start {
        out.push((c, &line[b..]));
    }
    out
}

/// Where the reader is in the file.
#[derive(Clone, Copy, PartialEq)]
enum Section {
    Header,
    Lines,
    Data,
}

/// Parses a MobileSim map; `name` only names it in messages, each error at its line and column.
pub fn parse_map(src: &str, name: &str) -> Result<MobileSimMap, Diagnostic> {
    let mut map = MobileSimMap::default();
    let mut section = None;
    for (idx, raw) in src.lines().enumerate() {
        let line_no = idx + 1;
        let toks = tokens(raw);
        let Some(&(col0, first)) = toks.first().filter(|(_, t)| !is_comment(t)) else {
            continue;
        };
        let Some(current) = section else {
            expect_map_start(name, line_no, col0, first)?;
            section = Some(Section::Header);
            continue;
        };
        let at = (name, line_no, raw);
        match (first, current) {
            ("LINES", _) => section = Some(Section::Lines),
            ("DATA", _) => section = Some(Section::Data),
            (_, Section::Data) => {}
            (_, Section::Header) => read_header_line(at, &toks, &mut map)?,
            (_, Section::Lines) => read_segment_line(at, &toks, &mut map)?,
        }
    }
    if section.is_none() {
        return Err(empty_map(name));
    }
    Ok(map)
}

/// Whether a line whose first token is `first` is a comment.
fn is_comment(first: &str) -> bool {
    first.starts_with(';') || first.starts_with('#')
}

/// The error for a map without a line that is not blank or a comment.
fn empty_map(name: &str) -> Diagnostic {
    malformed(
        name,
        1,
        1,
        "the file is empty; expected a MobileSim map starting with `2D-Map`",
    )
}

/// An error unless the first line's first token, `first`, is `2D-Map`.
fn expect_map_start(
    name: &str,
    line_no: usize,
    col0: usize,
    first: &str,
) -> Result<(), Diagnostic> {
    if first == "2D-Map" {
        return Ok(());
    }
    Err(malformed(
        name,
        line_no,
        col0,
        format!(
            "expected `2D-Map` as the first line, found `{first}`; is this a MobileSim .map file?"
        ),
    ))
}

/// A header line: the first `Cairn: RobotHome x y heading` gives the home. Other header lines
/// (Resolution, LineMinPos, NumLines, other cairns…) are not needed.
fn read_header_line(
    (name, line_no, raw): (&str, usize, &str),
    toks: &[(usize, &str)],
    map: &mut MobileSimMap,
) -> Result<(), Diagnostic> {
    if toks.first().map(|t| t.1) != Some("Cairn:") || toks.get(1).map(|t| t.1) != Some("RobotHome")
    {
        return Ok(());
    }
    let v = home_numbers((name, line_no, raw), &toks[2..])?;
    far_coordinate((name, line_no), &toks[2..], &v[..2], &["x", "y"])?;
    if map.home.is_none() {
        map.home = Some((v[0] / 1000.0, v[1] / 1000.0, v[2]));
        map.home_line = line_no;
    }
    Ok(())
}

/// The x (mm), y (mm) and heading (degrees) of a RobotHome cairn, from its tokens after
/// `Cairn: RobotHome`.
fn home_numbers(at: (&str, usize, &str), toks: &[(usize, &str)]) -> Result<[f64; 3], Diagnostic> {
    numbers(
        at,
        toks,
        ["x (mm)", "y (mm)", "heading (degrees)"],
        |what| {
            format!(
                "RobotHome cairn ends before its {what}; write `Cairn: RobotHome x y heading \"\" ICON \"\"`"
            )
        },
        |what, s| {
            format!(
                "RobotHome {what} is `{s}`, not a number; write `Cairn: RobotHome x y heading …`"
            )
        },
    )
}

/// A line after `LINES`: one segment `x1 y1 x2 y2` in millimetres, nothing after it.
fn read_segment_line(
    (name, line_no, raw): (&str, usize, &str),
    toks: &[(usize, &str)],
    map: &mut MobileSimMap,
) -> Result<(), Diagnostic> {
    let v = segment_numbers((name, line_no, raw), toks)?;
    far_coordinate((name, line_no), toks, &v, &["x1", "y1", "x2", "y2"])?;
    if let Some(&(c, s)) = toks.get(4) {
        return Err(malformed(
            name,
            line_no,
            c,
            format!(
                "unexpected `{s}` after the four coordinates; each line after LINES is `x1 y1 x2 y2`"
            ),
        ));
    }
    map.segments.push(Segment::new(
        Vec2::new(v[0] / 1000.0, v[1] / 1000.0),
        Vec2::new(v[2] / 1000.0, v[3] / 1000.0),
    ));
    map.segment_lines.push(line_no);
    Ok(())
}

/// The four coordinates (mm) of a segment line.
fn segment_numbers(
    at: (&str, usize, &str),
    toks: &[(usize, &str)],
) -> Result<[f64; 4], Diagnostic> {
    numbers(
        at,
        toks,
        ["x1", "y1", "x2", "y2"],
        |what| {
            format!(
                "line segment ends before its {what}; each line after LINES is `x1 y1 x2 y2` in millimetres"
            )
        },
        |what, s| {
            format!(
                "segment {what} is `{s}`, not a number; each line after LINES is `x1 y1 x2 y2` in millimetres"
            )
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_lines_are_located() {
        let e = parse_map("2D-Map\nLINES\n0 0 x 1\n", "m.map").unwrap_err();
        assert!(
            e.to_string().starts_with("m.map:3:5: segment x2 is `x`"),
            "{e}"
        );
        let e = parse_map("hello\n", "m.map").unwrap_err();
        assert!(e.to_string().starts_with("m.map:1:1:"), "{e}");
        // Coordinates past the world's limit at their column, in exponent form (they were
        // printed as 300 digits, or overflowed to a span of `inf` m).
        let e = parse_map("2D-Map\nCairn: RobotHome 1e300 0 0\n", "m.map").unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.map:2:18: x = 1e300 mm is more than 1000 km from the origin; the map is in \
             millimetres: check this value"
        );
        let e = parse_map("2D-Map\nLINES\n0 0 6000 -1e300\n", "m.map").unwrap_err();
        assert!(
            e.to_string().starts_with("m.map:3:10: y2 = -1e300 mm"),
            "{e}"
        );
    }
}
