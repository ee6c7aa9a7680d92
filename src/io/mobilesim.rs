//! MobileSim line maps (`.map`) → world files.
//!
//! The format: header lines (`2D-Map`, `Resolution:`, `LineMinPos:`, `LineMaxPos:`, `NumLines:`,
//! `LinesAreSorted:`, `Cairn: RobotHome x y heading …`), then `LINES` followed by one wall segment
//! per line (`x1 y1 x2 y2`, millimetres), optionally ending with `DATA` (points, ignored).
//!
//! The import turns segments into walls (touching segments chained into polylines, closed when
//! they come back to their start; thickness [`WALL_THICKNESS_M`]) and `RobotHome` into the home
//! pose. Doors cannot be inferred from a line map; the generated file says so. A closed route is
//! generated through the free space so the world can be simulated at once:
//!
//! 1. rasterise at [`ImportOptions::resolution_m`]: a cell is free when its centre is at least
//!    robot radius + margin (0.25 + 0.10 m) from every wall surface (exact point–segment
//!    distances);
//! 2. keep the 4-connected free component holding the home (or the free cell nearest to it);
//! 3. thin it to a one-cell skeleton (Zhang–Suen; it keeps the component's holes, i.e. the
//!    obstacles one can drive around);
//! 4. in the skeleton's 8-connected graph, rooted at the pixel nearest the home, take the
//!    fundamental cycles of a breadth-first tree, drop those enclosing less than 2 m² (pixel
//!    noise), and keep the one maximising `length − 2 × distance to home`;
//! 5. rotate it to start nearest the home and simplify it (Douglas–Peucker, 0.35 m) without ever
//!    accepting a leg closer than [`ImportOptions::leg_clearance_m`] to a wall surface.
//!
//! With no loop, an out-and-back route along the longest skeleton branch from the home is used;
//! failing that, the import fails and explains how to add a `[[routes]]` block by hand.

use crate::geom::{Segment, Vec2, segment_distance};
use crate::spec::diag::Diagnostic;
use crate::spec::world::{HomeSpec, RouteSpec, WallSpec, WorldSpec};
use std::collections::{HashMap, VecDeque};

/// Thickness given to imported walls, metres.
pub const WALL_THICKNESS_M: f64 = 0.05;

/// Most wall segments a world may hold (the world checks' limit).
pub const MAX_SEGMENTS: usize = crate::spec::world::MAX_SEGMENTS;

/// Largest extent of a world, corner to corner, metres (the world checks' limit).
pub const MAX_EXTENT_M: f64 = 10_000.0;

/// Settings of the route generator.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportOptions {
    /// Raster cell size, metres.
    pub resolution_m: f64,
    /// Robot radius, metres.
    pub robot_radius_m: f64,
    /// Extra clearance kept around the robot disc when choosing free cells, metres.
    pub margin_m: f64,
    /// Smallest distance from a route leg to a wall surface, metres.
    pub leg_clearance_m: f64,
    /// Douglas–Peucker tolerance, metres.
    pub simplify_tolerance_m: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            resolution_m: 0.05,
            robot_radius_m: 0.25,
            margin_m: 0.10,
            leg_clearance_m: 0.30,
            simplify_tolerance_m: 0.35,
        }
    }
}

/// Why a map could not be imported.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MapError {
    /// A line that does not parse.
    #[error("{0}")]
    Malformed(Diagnostic),
    /// The map parsed but no drivable route could be generated.
    ///
    /// `partial` holds the world without a route when walls and home were imported; a caller
    /// may write it so the user only has to add the `[[routes]]` block. `line` is where the
    /// problem shows: the home (the route grows from it), the first segment past the limit,
    /// the segment farthest out, or line 1 for what the file lacks.
    #[error("{path}:{line}:1: {message}")]
    NoRoute {
        path: String,
        line: usize,
        message: String,
        partial: Option<Box<WorldSpec>>,
    },
}

/// A parsed MobileSim map, in metres and degrees.
#[derive(Clone, Debug, PartialEq)]
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
) -> Result<[f64; N], MapError> {
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
) -> Result<(), MapError> {
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

fn malformed(path: &str, line: usize, col: usize, message: impl Into<String>) -> MapError {
    MapError::Malformed(Diagnostic::error(path, (line, col), message))
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

/// Parses a MobileSim map; `name` only names it in messages.
pub fn parse_map(src: &str, name: &str) -> Result<MobileSimMap, MapError> {
    #[derive(PartialEq)]
    enum Section {
        Header,
        Lines,
        Data,
    }
    let mut section = Section::Header;
    let mut segments = Vec::new();
    let mut segment_lines = Vec::new();
    let mut home = None;
    let mut home_line = 0;
    let mut seen_magic = false;
    for (idx, raw) in src.lines().enumerate() {
        let line_no = idx + 1;
        let toks = tokens(raw);
        let Some(&(col0, first)) = toks.first() else {
            continue;
        };
        if first.starts_with(';') || first.starts_with('#') {
            continue;
        }
        if !seen_magic {
            if first != "2D-Map" {
                return Err(malformed(
                    name,
                    line_no,
                    col0,
                    format!(
                        "expected `2D-Map` as the first line, found `{first}`; is this a MobileSim .map file?"
                    ),
                ));
            }
            seen_magic = true;
            continue;
        }
        match first {
            "LINES" => {
                section = Section::Lines;
                continue;
            }
            "DATA" => {
                section = Section::Data;
                continue;
            }
            _ => {}
        }
        match section {
            Section::Data => {}
            Section::Header => {
                if first == "Cairn:" && toks.get(1).map(|t| t.1) == Some("RobotHome") {
                    let v: [f64; 3] = numbers(
                        (name, line_no, raw),
                        &toks[2..],
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
                    )?;
                    far_coordinate((name, line_no), &toks[2..], &v[..2], &["x", "y"])?;
                    if home.is_none() {
                        home = Some((v[0] / 1000.0, v[1] / 1000.0, v[2]));
                        home_line = line_no;
                    }
                }
                // Other header lines (Resolution, LineMinPos, NumLines, other cairns…) are not needed.
            }
            Section::Lines => {
                let v: [f64; 4] = numbers(
                    (name, line_no, raw),
                    &toks,
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
                )?;
                far_coordinate((name, line_no), &toks, &v, &["x1", "y1", "x2", "y2"])?;
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
                segments.push(Segment::new(
                    Vec2::new(v[0] / 1000.0, v[1] / 1000.0),
                    Vec2::new(v[2] / 1000.0, v[3] / 1000.0),
                ));
                segment_lines.push(line_no);
            }
        }
    }
    if !seen_magic {
        return Err(malformed(
            name,
            1,
            1,
            "the file is empty; expected a MobileSim map starting with `2D-Map`",
        ));
    }
    Ok(MobileSimMap {
        segments,
        segment_lines,
        home,
        home_line,
    })
}

/// Chains touching segments into polylines (zero-length segments dropped). Returns
/// (points, closed) per polyline.
pub fn chain_segments(segments: &[Segment]) -> Vec<(Vec<Vec2>, bool)> {
    let key = |p: Vec2| ((p.x * 1000.0).round() as i64, (p.y * 1000.0).round() as i64);
    let segs: Vec<&Segment> = segments.iter().filter(|s| key(s.a) != key(s.b)).collect();
    let mut at: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in segs.iter().enumerate() {
        at.entry(key(s.a)).or_default().push(i);
        at.entry(key(s.b)).or_default().push(i);
    }
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    for i in 0..segs.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let mut chain: VecDeque<Vec2> = VecDeque::from(vec![segs[i].a, segs[i].b]);
        for forward in [true, false] {
            loop {
                let end = if forward {
                    *chain.back().unwrap()
                } else {
                    *chain.front().unwrap()
                };
                let k = key(end);
                let next = at
                    .get(&k)
                    .and_then(|v| v.iter().copied().find(|&j| !used[j]));
                let Some(j) = next else { break };
                used[j] = true;
                let other = if key(segs[j].a) == k {
                    segs[j].b
                } else {
                    segs[j].a
                };
                if forward {
                    chain.push_back(other);
                } else {
                    chain.push_front(other);
                }
            }
        }
        let mut pts: Vec<Vec2> = chain.into_iter().collect();
        let closed = pts.len() >= 4 && key(pts[0]) == key(*pts.last().unwrap());
        if closed {
            pts.pop();
        }
        out.push((pts, closed));
    }
    out
}

/// Distance from a point to the nearest wall surface (centre-line distance − thickness/2).
pub fn point_clearance(walls: &[Segment], thickness_m: f64, p: Vec2) -> f64 {
    walls
        .iter()
        .map(|w| w.distance_to_point(p))
        .fold(f64::INFINITY, f64::min)
        - thickness_m / 2.0
}

/// Distance from a route leg to the nearest wall surface.
pub fn leg_clearance(walls: &[Segment], thickness_m: f64, leg: &Segment) -> f64 {
    walls
        .iter()
        .map(|w| segment_distance(*w, *leg))
        .fold(f64::INFINITY, f64::min)
        - thickness_m / 2.0
}

/// Whether a leg keeps at least `clearance_m` from every wall surface; walls whose bounding box
/// is farther than that from the leg's are not measured.
fn leg_clear(walls: &[Segment], thickness_m: f64, leg: &Segment, clearance_m: f64) -> bool {
    let r = clearance_m + thickness_m / 2.0;
    let (lo, hi) = (leg.a.inf(&leg.b), leg.a.sup(&leg.b));
    walls.iter().all(|w| {
        let (a, b) = (w.a.inf(&w.b), w.a.sup(&w.b));
        b.x < lo.x - r
            || a.x > hi.x + r
            || b.y < lo.y - r
            || a.y > hi.y + r
            || segment_distance(*w, *leg) - thickness_m / 2.0 >= clearance_m
    })
}

/// Imports a MobileSim map as a world with walls, the home pose and a generated route.
pub fn import_mobilesim(src: &str, name: &str) -> Result<WorldSpec, MapError> {
    import_mobilesim_with(src, name, &ImportOptions::default())
}

/// How far outside the walls' bounding box the home may lie, metres.
pub const HOME_MARGIN_M: f64 = 1.0;

/// The home must lie within the walls' bounding box (plus [`HOME_MARGIN_M`]): the route is
/// grown from it, and a far-away home makes route generation slow and the route wrong.
fn home_inside_walls(
    src: &str,
    name: &str,
    segments: &[Segment],
    home: Vec2,
) -> Result<(), MapError> {
    let Some(first) = segments.first() else {
        return Ok(());
    };
    let (mut lo, mut hi) = (first.a, first.a);
    for p in segments.iter().flat_map(|s| [s.a, s.b]) {
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    let outside = (lo - home).sup(&(home - hi)).sup(&Vec2::zeros()).norm();
    if outside <= HOME_MARGIN_M {
        return Ok(());
    }
    let line = src
        .lines()
        .position(|l| l.contains("RobotHome"))
        .map_or(1, |i| i + 1);
    let col = src
        .lines()
        .nth(line - 1)
        .and_then(|l| l.find("RobotHome"))
        .map_or(1, |c| c + 1);
    Err(malformed(
        name,
        line,
        col,
        format!(
            "RobotHome ({:.2}, {:.2}) m is {outside:.1} m outside the map's walls (limit {HOME_MARGIN_M} m); \
         put the home inside the building, in millimetres like the lines",
            home.x, home.y
        ),
    ))
}

/// [`import_mobilesim`] with explicit route-generation settings.
pub fn import_mobilesim_with(
    src: &str,
    name: &str,
    opts: &ImportOptions,
) -> Result<WorldSpec, MapError> {
    import_mobilesim_repaired(src, name, opts).map(|m| m.spec)
}

/// A map imported as a world, with what the import repaired on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedMap {
    pub spec: WorldSpec,
    /// Warnings at the map's lines, one per repair (see [`repair_map`]).
    pub repairs: Vec<Diagnostic>,
}

/// The repairs the import makes so that a map drawn carelessly still gives a world `world
/// check` accepts, each a warning at its line of the map:
///
/// - a segment drawn twice (the same two end points, in millimetres, in either order) is kept
///   once: the world check refuses a wall that overlaps itself;
/// - a RobotHome heading outside -180..180 degrees is brought into it (1000 → -80): the world
///   check takes headings within ±360 only.
pub fn repair_map(map: &mut MobileSimMap, name: &str) -> Vec<Diagnostic> {
    let mut repairs = Vec::new();
    type Mm = (i64, i64);
    let key = |p: Vec2| -> Mm { ((p.x * 1000.0).round() as i64, (p.y * 1000.0).round() as i64) };
    let mut first: HashMap<(Mm, Mm), usize> = HashMap::new();
    let mut keep = Vec::with_capacity(map.segments.len());
    for (s, &line) in map.segments.iter().zip(&map.segment_lines) {
        let (a, b) = (key(s.a), key(s.b));
        let k = (a.min(b), a.max(b));
        match first.get(&k) {
            Some(&was) if a != b => {
                repairs.push(Diagnostic::warning(
                    name,
                    (line, 1),
                    format!(
                        "this segment repeats line {was} (the same wall drawn twice); imported once"
                    ),
                ));
                keep.push(false);
            }
            _ => {
                first.entry(k).or_insert(line);
                keep.push(true);
            }
        }
    }
    let mut it = keep.iter();
    map.segments.retain(|_| *it.next().unwrap_or(&true));
    let mut it = keep.iter();
    map.segment_lines.retain(|_| *it.next().unwrap_or(&true));
    if let Some((_, _, h)) = map.home.as_mut()
        && !(-180.0..=180.0).contains(h)
    {
        let mut w = h.rem_euclid(360.0);
        if w > 180.0 {
            w -= 360.0;
        }
        repairs.push(Diagnostic::warning(
            name,
            (map.home_line.max(1), 1),
            format!(
                "RobotHome heading {} degrees is outside -180..180; imported as {}",
                crate::spec::diag::fmt_number(*h),
                crate::spec::diag::fmt_number(w)
            ),
        ));
        *h = w;
    }
    repairs
}

/// [`import_mobilesim_with`] keeping the repairs it made ([`repair_map`]).
pub fn import_mobilesim_repaired(
    src: &str,
    name: &str,
    opts: &ImportOptions,
) -> Result<ImportedMap, MapError> {
    let mut map = parse_map(src, name)?;
    let repairs = repair_map(&mut map, name);
    let no_route = |line: usize, message: String| MapError::NoRoute {
        path: name.to_string(),
        line: line.max(1),
        message,
        partial: None,
    };
    let Some((hx, hy, hdeg)) = map.home else {
        return Err(no_route(
            1,
            "the map has no `Cairn: RobotHome x y heading` line, so there is no home pose; \
             add one to the header (millimetres and degrees)"
                .into(),
        ));
    };
    // The world checks' limits, reported here with the map's own numbers.
    if map.segments.len() > MAX_SEGMENTS {
        return Err(no_route(
            map.segment_lines[MAX_SEGMENTS],
            format!(
                "the map has {} wall segments, more than a world may hold ({MAX_SEGMENTS}); \
             split the map or merge collinear segments",
                map.segments.len()
            ),
        ));
    }
    home_inside_walls(src, name, &map.segments, Vec2::new(hx, hy))?;
    let (mut lo, mut hi) = (Vec2::new(hx, hy), Vec2::new(hx, hy));
    for s in &map.segments {
        for p in [s.a, s.b] {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    if (hi - lo).norm() > MAX_EXTENT_M {
        let home = Vec2::new(hx, hy);
        let farthest = map
            .segments
            .iter()
            .zip(&map.segment_lines)
            .map(|(s, &l)| ((s.a - home).norm().max((s.b - home).norm()), l))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(1, |(_, l)| l);
        return Err(no_route(
            farthest,
            format!(
                "the map (with its home) spans {:.0} m corner to corner, more than a world may ({MAX_EXTENT_M} m); \
             check the units (the format is in millimetres) or remove stray far-away lines \
             (this one is the farthest from the home)",
                (hi - lo).norm()
            ),
        ));
    }
    let chains = chain_segments(&map.segments);
    if chains.is_empty() {
        return Err(no_route(
            1,
            "the map has no wall segments after `LINES`; add one `x1 y1 x2 y2` line (millimetres) \
             per wall segment after a `LINES` line"
                .into(),
        ));
    }
    let walls: Vec<Segment> = map
        .segments
        .iter()
        .copied()
        .filter(|s| s.length() > 0.0)
        .collect();
    let home = Vec2::new(hx, hy);
    let stem = std::path::Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imported".into());
    let r3 = |v: f64| (v * 1000.0).round() / 1000.0;
    let file_name = std::path::Path::new(name)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut spec = WorldSpec {
        format_version: 1,
        name: stem,
        description: Some(format!(
            "imported from the MobileSim map {file_name}; no doors (a line map cannot show them)"
        )),
        robot_home: HomeSpec {
            x_m: r3(hx),
            y_m: r3(hy),
            heading_deg: hdeg,
        },
        walls: chains
            .into_iter()
            .enumerate()
            .map(|(i, (pts, closed))| WallSpec {
                id: format!("w{}", i + 1),
                points_m: pts.iter().map(|p| [r3(p.x), r3(p.y)]).collect(),
                closed,
                thickness_m: WALL_THICKNESS_M,
            })
            .collect(),
        doors: Vec::new(),
        routes: Vec::new(),
        areas: Vec::new(),
    };
    match generate_route(&walls, WALL_THICKNESS_M, home, opts) {
        Ok(route) => {
            if let Some(d) = spec.description.as_mut() {
                d.push_str("; route generated from the free-space skeleton");
            }
            spec.routes.push(RouteSpec {
                id: "loop".into(),
                waypoints_m: route.iter().map(|p| [r3(p.x), r3(p.y)]).collect(),
            });
            Ok(ImportedMap { spec, repairs })
        }
        Err(message) => Err(MapError::NoRoute {
            path: name.to_string(),
            line: map.home_line.max(1),
            message,
            partial: Some(Box::new(spec)),
        }),
    }
}

/// The world file text for an imported world, with a header naming the source.
pub fn world_to_toml(spec: &WorldSpec, source: &str) -> Result<String, toml::ser::Error> {
    // Point lists one `[x, y]` pair per line (toml writes them either on one long line or one
    // number per line).
    let body = toml::to_string(spec)?;
    let body: String = body
        .lines()
        .map(|l| match l.split_once(" = [[") {
            Some((key, rest)) if rest.ends_with("]]") => format!(
                "{key} = [\n    [{}],\n]\n",
                rest[..rest.len() - 2].replace("], [", "],\n    [")
            ),
            // Empty arrays would clash with the [[doors]] / [[routes]] blocks a user adds.
            _ if l.ends_with(" = []") => String::new(),
            _ => format!("{l}\n"),
        })
        .collect();
    let route_note = if spec.routes.is_empty() {
        "# NO ROUTE: none could be generated through the free space. Add a [[routes]] block by hand\n\
         # (id = \"loop\", waypoints_m = [[x1, y1], [x2, y2], [x3, y3], ...]: at least 3 waypoints, each\n\
         # >= 0.30 m from every wall, legs clear of walls by the 0.25 m robot radius), then run\n\
         # `placewords world check` on this file.\n"
    } else {
        "# The route \"loop\" was generated from the skeleton of the free space (waypoints >= 0.30 m\n\
         # from walls, legs a 0.25 m robot disc can drive); edit or replace it freely.\n"
    };
    Ok(format!(
        "# Imported by `placewords world import` from the MobileSim map {source}.\n\
         # Walls: the map's LINES (millimetres -> metres), touching segments chained into polylines,\n\
         # {WALL_THICKNESS_M} m thick. Home: the RobotHome cairn.\n\
         # Doors cannot be inferred from a line map: add [[doors]] blocks by hand (id, hinge_m,\n\
         # width_m, closed_heading_deg, open_heading_deg) where the real building has them.\n\
         {route_note}\n{body}"
    ))
}

/// Generates a drivable closed route; the error explains how to add one by hand.
pub fn generate_route(
    walls: &[Segment],
    thickness_m: f64,
    home: Vec2,
    opts: &ImportOptions,
) -> Result<Vec<Vec2>, String> {
    let hand = "add a route by hand: a [[routes]] block with `id = \"loop\"` and \
                `waypoints_m = [[x1, y1], [x2, y2], [x3, y3], …]` (at least 3 waypoints, each >= 0.30 m from \
                every wall, legs clear of walls by the robot radius 0.25 m), then run `placewords world check`";
    let res = opts.resolution_m;
    let need = opts.robot_radius_m + opts.margin_m;
    let (mut lo, mut hi) = (home, home);
    for w in walls {
        for p in [w.a, w.b] {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    lo -= Vec2::new(1.0, 1.0);
    hi += Vec2::new(1.0, 1.0);
    // 5 cm cells, coarsened (up to 10 cm) for large maps so the raster stays under 16 M cells.
    let area = (hi.x - lo.x) * (hi.y - lo.y);
    let res = res.max((area / 16.0e6).sqrt());
    if res.is_nan() || res > 0.1 + 1e-12 {
        return Err(format!(
            "the map spans {:.0} × {:.0} m, too large to rasterise for route generation; {hand}",
            hi.x - lo.x,
            hi.y - lo.y
        ));
    }
    let nx = ((hi.x - lo.x) / res).ceil() as usize;
    let ny = ((hi.y - lo.y) / res).ceil() as usize;
    let center = |i: usize, j: usize| {
        Vec2::new(lo.x + (i as f64 + 0.5) * res, lo.y + (j as f64 + 0.5) * res)
    };
    let idx = |i: usize, j: usize| j * nx + i;
    // Blocked: cell centres within `need` of a wall surface. Each segment only visits the cells
    // of its own bounding box grown by that distance (exact distances, no full scan per cell).
    let mut free = vec![true; nx * ny];
    let reach = need + thickness_m / 2.0;
    let cell_of =
        |v: f64, o: f64, n: usize| (((v - o) / res - 0.5).floor().max(0.0) as usize).min(n - 1);
    for w in walls {
        let (a, b) = (w.a.inf(&w.b), w.a.sup(&w.b));
        let (i0, i1) = (
            cell_of(a.x - reach, lo.x, nx),
            cell_of(b.x + reach, lo.x, nx) + 1,
        );
        let (j0, j1) = (
            cell_of(a.y - reach, lo.y, ny),
            cell_of(b.y + reach, lo.y, ny) + 1,
        );
        for j in j0..=j1.min(ny - 1) {
            for i in i0..=i1.min(nx - 1) {
                let k = idx(i, j);
                if free[k] && w.distance_to_point(center(i, j)) - thickness_m / 2.0 < need {
                    free[k] = false;
                }
            }
        }
    }
    // The free cell nearest the home that the home can see (no wall between them), so a home
    // in a tight spot never lands the route outside the building.
    let hc = ((home.x - lo.x) / res - 0.5, (home.y - lo.y) / res - 0.5);
    let reach = (2.0 / res).ceil() as i64;
    let mut cand: Vec<(f64, (usize, usize))> = Vec::new();
    for j in (hc.1 as i64 - reach).max(0)..=(hc.1 as i64 + reach).min(ny as i64 - 1) {
        for i in (hc.0 as i64 - reach).max(0)..=(hc.0 as i64 + reach).min(nx as i64 - 1) {
            let (i, j) = (i as usize, j as usize);
            let d = ((i as f64 - hc.0).powi(2) + (j as f64 - hc.1).powi(2)).sqrt() * res;
            if free[idx(i, j)] && d <= 2.0 {
                cand.push((d, (i, j)));
            }
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0));
    let start = cand
        .iter()
        .find(|(_, (i, j))| leg_clear(walls, 0.0, &Segment::new(home, center(*i, *j)), 1e-9))
        .map(|c| c.1);
    let Some(start) = start else {
        return Err(format!(
            "no free space within 2 m of the home ({:.2}, {:.2}) where the robot fits with {need:.2} m clearance; {hand}",
            home.x, home.y
        ));
    };
    // The 4-connected free component holding it.
    let mut comp = vec![false; nx * ny];
    let mut queue = VecDeque::from([start]);
    comp[idx(start.0, start.1)] = true;
    while let Some((i, j)) = queue.pop_front() {
        let mut push = |a: usize, b: usize| {
            let k = idx(a, b);
            if free[k] && !comp[k] {
                comp[k] = true;
                queue.push_back((a, b));
            }
        };
        if i > 0 {
            push(i - 1, j);
        }
        if i + 1 < nx {
            push(i + 1, j);
        }
        if j > 0 {
            push(i, j - 1);
        }
        if j + 1 < ny {
            push(i, j + 1);
        }
    }
    let skel = zhang_suen(comp, nx, ny);
    // Skeleton graph, BFS from the pixel nearest the start.
    let pix: Vec<usize> = (0..nx * ny).filter(|&k| skel[k]).collect();
    if pix.is_empty() {
        return Err(format!(
            "the free space around the home is too small to drive in; {hand}"
        ));
    }
    let root = *pix
        .iter()
        .min_by_key(|&&k| {
            let (i, j) = (k % nx, k / nx);
            (i as i64 - start.0 as i64).pow(2) + (j as i64 - start.1 as i64).pow(2)
        })
        .unwrap();
    let neighbours = |k: usize| {
        let (i, j) = ((k % nx) as i64, (k / nx) as i64);
        let mut v = Vec::with_capacity(8);
        for dj in -1..=1i64 {
            for di in -1..=1i64 {
                if di == 0 && dj == 0 {
                    continue;
                }
                let (a, b) = (i + di, j + dj);
                if a >= 0 && b >= 0 && (a as usize) < nx && (b as usize) < ny {
                    let q = b as usize * nx + a as usize;
                    if skel[q] {
                        v.push(q);
                    }
                }
            }
        }
        v
    };
    let mut parent: HashMap<usize, usize> = HashMap::new();
    let mut depth: HashMap<usize, usize> = HashMap::new();
    parent.insert(root, root);
    depth.insert(root, 0);
    let mut order = vec![root];
    let mut q = VecDeque::from([root]);
    while let Some(u) = q.pop_front() {
        for v in neighbours(u) {
            if let std::collections::hash_map::Entry::Vacant(e) = parent.entry(v) {
                e.insert(u);
                depth.insert(v, depth[&u] + 1);
                order.push(v);
                q.push_back(v);
            }
        }
    }
    let pt = |k: usize| center(k % nx, k / nx);
    // Fundamental cycles.
    let mut best_cycle: Option<(f64, Vec<usize>)> = None;
    for &u in &order {
        for v in neighbours(u) {
            if v <= u || parent[&v] == u || parent[&u] == v {
                continue;
            }
            let (mut a, mut b) = (u, v);
            let mut left = vec![a];
            let mut right = vec![b];
            while a != b {
                if depth[&a] >= depth[&b] {
                    a = parent[&a];
                    left.push(a);
                } else {
                    b = parent[&b];
                    right.push(b);
                }
            }
            right.pop(); // the common ancestor is already in `left`
            left.extend(right.into_iter().rev());
            let cyc = left;
            if cyc.len() < 8 {
                continue;
            }
            let pts: Vec<Vec2> = cyc.iter().map(|&k| pt(k)).collect();
            let n = pts.len();
            let mut area2 = 0.0;
            let mut len = 0.0;
            for t in 0..n {
                let (p, r) = (pts[t], pts[(t + 1) % n]);
                area2 += p.x * r.y - r.x * p.y;
                len += (r - p).norm();
            }
            if area2.abs() / 2.0 < 2.0 {
                continue;
            }
            let dhome = pts
                .iter()
                .map(|p| (p - home).norm())
                .fold(f64::INFINITY, f64::min);
            let score = len - 2.0 * dhome;
            if best_cycle.as_ref().is_none_or(|(s, _)| score > *s) {
                best_cycle = Some((score, cyc));
            }
        }
    }
    let leg_ok = |a: Vec2, b: Vec2| {
        leg_clear(
            walls,
            thickness_m,
            &Segment::new(a, b),
            opts.leg_clearance_m,
        )
    };
    let route = if let Some((_, cyc)) = best_cycle {
        let mut pts: Vec<Vec2> = cyc.iter().map(|&k| pt(k)).collect();
        let s = (0..pts.len())
            .min_by(|&a, &b| (pts[a] - home).norm().total_cmp(&(pts[b] - home).norm()))
            .unwrap();
        pts.rotate_left(s);
        pts.push(pts[0]);
        let mut simp = simplify(&pts, opts.simplify_tolerance_m, &leg_ok);
        simp.pop();
        simp
    } else {
        // Out and back along the longest branch from the root.
        let far = *order.last().unwrap();
        let mut path = vec![far];
        let mut k = far;
        while k != root {
            k = parent[&k];
            path.push(k);
        }
        path.reverse();
        let pts: Vec<Vec2> = path.iter().map(|&k| pt(k)).collect();
        let simp = simplify(&pts, opts.simplify_tolerance_m, &leg_ok);
        let length: f64 = simp.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        if length < 1.0 {
            return Err(format!(
                "the free space around the home ({:.2}, {:.2}) holds neither a loop nor a branch of 1 m to drive out and back; {hand}",
                home.x, home.y
            ));
        }
        let mut route = simp.clone();
        if simp.len() == 2 {
            route.push((simp[0] + simp[1]) / 2.0);
        } else {
            route.extend(simp[1..simp.len() - 1].iter().rev());
        }
        route
    };
    // Final check, with the rounding the file applies.
    let r3 = |v: f64| (v * 1000.0).round() / 1000.0;
    let route: Vec<Vec2> = route.iter().map(|p| Vec2::new(r3(p.x), r3(p.y))).collect();
    let n = route.len();
    let ok = n >= 3
        && route
            .iter()
            .all(|&p| point_clearance(walls, thickness_m, p) >= 0.30)
        && (0..n).all(|i| {
            leg_clearance(
                walls,
                thickness_m,
                &Segment::new(route[i], route[(i + 1) % n]),
            ) >= opts.robot_radius_m
        });
    if !ok {
        return Err(format!(
            "the generated route failed its clearance check; {hand}"
        ));
    }
    Ok(route)
}

/// Douglas–Peucker that also splits any leg failing `leg_ok`. Keeps both ends.
fn simplify(pts: &[Vec2], tol: f64, leg_ok: &dyn Fn(Vec2, Vec2) -> bool) -> Vec<Vec2> {
    let n = pts.len();
    if n <= 2 {
        return pts.to_vec();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0usize, n - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let seg = Segment::new(pts[a], pts[b]);
        let (mut far, mut dmax) = (a + 1, -1.0);
        for (k, p) in pts.iter().enumerate().take(b).skip(a + 1) {
            let d = seg.distance_to_point(*p);
            if d > dmax {
                dmax = d;
                far = k;
            }
        }
        if dmax > tol || !leg_ok(pts[a], pts[b]) {
            // A closed ring starts and ends on one point: split in the middle, not at the far point.
            let m = if (pts[a] - pts[b]).norm() < 1e-9 {
                (a + b) / 2
            } else {
                far
            };
            keep[m] = true;
            stack.push((a, m));
            stack.push((m, b));
        }
    }
    pts.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(p, _)| *p)
        .collect()
}

/// Zhang–Suen thinning of a binary image (row-major, `nx` wide).
///
/// Each sub-iteration decides every pixel from the image as it stood at the sub-iteration's
/// start, and a pixel's decision depends only on its 3×3 neighbourhood. So after the first
/// full pass only pixels next to one deleted since their last look under the same rule (north-
/// east or south-west) are looked at again: the same deletions, in work proportional to the
/// image plus the pixels removed, not to the image times the passes (a 350 m open map thinned
/// in thousands of full passes took a minute).
fn zhang_suen(mut img: Vec<bool>, nx: usize, ny: usize) -> Vec<bool> {
    if nx < 3 || ny < 3 {
        return img;
    }
    let interior = |k: usize| {
        let (i, j) = (k % nx, k / nx);
        i >= 1 && i + 1 < nx && j >= 1 && j + 1 < ny
    };
    let ring = |k: usize| {
        [
            k + nx,
            k + nx + 1,
            k + 1,
            k - nx + 1,
            k - nx,
            k - nx - 1,
            k - 1,
            k + nx - 1,
        ]
    };
    // Pixels to look at under each rule, and whether they are queued already. At first the
    // foreground pixels on its border: one whose 8 neighbours are all foreground is kept by
    // both rules until a neighbour goes (and then it is queued).
    // The image's edge is never looked at: marked queued for good, it is never queued.
    let mut todo: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
    let edge: Vec<bool> = (0..nx * ny).map(|k| !interior(k)).collect();
    let mut queued = [edge.clone(), edge];
    for k in 0..nx * ny {
        if img[k] && interior(k) && ring(k).iter().any(|&q| !img[q]) {
            for step in 0..2 {
                todo[step].push(k);
                queued[step][k] = true;
            }
        }
    }
    let mut del = Vec::new();
    loop {
        let mut changed = false;
        for step in 0..2 {
            del.clear();
            let mut look = std::mem::take(&mut todo[step]);
            for &k in &look {
                queued[step][k] = false;
                if !img[k] {
                    continue;
                }
                // P2..P9 clockwise from north (north = +y row, direction does not matter).
                let p = ring(k).map(|q| img[q]);
                let b = p.iter().filter(|&&x| x).count();
                if !(2..=6).contains(&b) {
                    continue;
                }
                let a = (0..8).filter(|&t| !p[t] && p[(t + 1) % 8]).count();
                if a != 1 {
                    continue;
                }
                let (p2, p4, p6, p8) = (p[0], p[2], p[4], p[6]);
                let cond = if step == 0 {
                    !(p4 && p6 && (p2 || p8))
                } else {
                    !(p2 && p8 && (p4 || p6))
                };
                if cond {
                    del.push(k);
                }
            }
            look.clear();
            todo[step] = look;
            if del.is_empty() {
                continue;
            }
            changed = true;
            for &k in &del {
                img[k] = false;
            }
            for &k in &del {
                for q in ring(k) {
                    if img[q] {
                        for rule in 0..2 {
                            if !queued[rule][q] {
                                queued[rule][q] = true;
                                todo[rule].push(q);
                            }
                        }
                    }
                }
            }
        }
        if !changed {
            return img;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zhang–Suen as first written: every pixel every sub-iteration.
    fn zhang_suen_full_passes(mut img: Vec<bool>, nx: usize, ny: usize) -> Vec<bool> {
        let mut changed = true;
        while changed {
            changed = false;
            for step in 0..2 {
                let mut del = Vec::new();
                for j in 1..ny - 1 {
                    for i in 1..nx - 1 {
                        let k = j * nx + i;
                        if !img[k] {
                            continue;
                        }
                        let p = [
                            img[k + nx],
                            img[k + nx + 1],
                            img[k + 1],
                            img[k - nx + 1],
                            img[k - nx],
                            img[k - nx - 1],
                            img[k - 1],
                            img[k + nx - 1],
                        ];
                        let b = p.iter().filter(|&&x| x).count();
                        let a = (0..8).filter(|&t| !p[t] && p[(t + 1) % 8]).count();
                        let (p2, p4, p6, p8) = (p[0], p[2], p[4], p[6]);
                        let cond = if step == 0 {
                            !(p4 && p6 && (p2 || p8))
                        } else {
                            !(p2 && p8 && (p4 || p6))
                        };
                        if (2..=6).contains(&b) && a == 1 && cond {
                            del.push(k);
                        }
                    }
                }
                changed |= !del.is_empty();
                del.iter().for_each(|&k| img[k] = false);
            }
        }
        img
    }

    /// Looking again only where a neighbour went gives the skeleton of full passes, on blobs,
    /// noise and a large open square (the shape that took a minute).
    #[test]
    fn thinning_revisits_only_changed_neighbourhoods_with_the_same_skeleton() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for (nx, ny, fill) in [
            (40, 30, 0.9),
            (64, 64, 0.6),
            (17, 90, 0.97),
            (120, 120, 1.0),
        ] {
            let img: Vec<bool> = (0..nx * ny)
                .map(|k| {
                    let (i, j) = (k % nx, k / nx);
                    let edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
                    rng.random_bool(fill) && !edge
                })
                .collect();
            let want = zhang_suen_full_passes(img.clone(), nx, ny);
            assert_eq!(zhang_suen(img, nx, ny), want, "{nx}x{ny} at {fill}");
        }
    }

    /// A segment drawn twice is imported once and a heading of 1000 degrees as -80, each said
    /// at its line.
    #[test]
    fn duplicate_segments_and_wild_headings_are_repaired_at_their_lines() {
        let src = "2D-Map\nCairn: RobotHome 1000 1000 1000\nLINES\n0 0 6000 0\n6000 0 0 0\n\
                   6000 0 6000 6000\n6000 6000 0 6000\n0 6000 0 0\n\
                   2500 2500 3500 2500\n3500 2500 3500 3500\n3500 3500 2500 3500\n2500 3500 2500 2500\n";
        let m = import_mobilesim_repaired(src, "r.map", &ImportOptions::default()).unwrap();
        let said: Vec<String> = m.repairs.iter().map(ToString::to_string).collect();
        assert_eq!(
            said,
            [
                "r.map:5:1: warning: this segment repeats line 4 (the same wall drawn twice); imported once",
                "r.map:2:1: warning: RobotHome heading 1000 degrees is outside -180..180; imported as -80",
            ]
        );
        assert_eq!(m.spec.robot_home.heading_deg, -80.0);
        assert!(
            m.spec
                .walls
                .iter()
                .all(|w| w.closed && w.points_m.len() == 4)
        );
    }

    #[test]
    fn square_room_with_pillar_gets_a_loop() {
        let src = "2D-Map\nResolution: 0\nCairn: RobotHome 1000 1000 90 \"\" ICON \"\"\nLINES\n\
                   0 0 6000 0\n6000 0 6000 6000\n6000 6000 0 6000\n0 6000 0 0\n\
                   2500 2500 3500 2500\n3500 2500 3500 3500\n3500 3500 2500 3500\n2500 3500 2500 2500\nDATA\n1 2\n";
        let w = import_mobilesim(src, "sq.map").unwrap();
        assert_eq!(w.walls.len(), 2);
        assert!(w.walls.iter().all(|w| w.closed && w.points_m.len() == 4));
        assert_eq!(w.robot_home.heading_deg, 90.0);
        assert!(w.routes[0].waypoints_m.len() >= 3);
    }

    #[test]
    fn empty_room_gets_out_and_back_or_loop() {
        let src = "2D-Map\nCairn: RobotHome 1000 1000 0\nLINES\n0 0 5000 0\n5000 0 5000 2000\n5000 2000 0 2000\n0 2000 0 0\n";
        let w = import_mobilesim(src, "r.map").unwrap();
        assert!(w.routes[0].waypoints_m.len() >= 3);
    }

    #[test]
    fn bad_lines_are_located() {
        let e = parse_map("2D-Map\nLINES\n0 0 x 1\n", "m.map").unwrap_err();
        assert!(
            e.to_string().starts_with("m.map:3:5: segment x2 is `x`"),
            "{e}"
        );
        let e = parse_map("hello\n", "m.map").unwrap_err();
        assert!(e.to_string().starts_with("m.map:1:1:"), "{e}");
        let e = import_mobilesim("2D-Map\nLINES\n0 0 1 1\n", "m.map").unwrap_err();
        assert!(e.to_string().starts_with("m.map:1:1: "), "{e}");
        assert!(e.to_string().contains("RobotHome"), "{e}");
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

    #[test]
    fn tiny_room_fails_with_advice() {
        let src = "2D-Map\nCairn: RobotHome 300 300 0\nLINES\n0 0 600 0\n600 0 600 600\n600 600 0 600\n0 600 0 0\n";
        let e = import_mobilesim(src, "t.map").unwrap_err();
        assert!(e.to_string().contains("[[routes]]"), "{e}");
    }

    #[test]
    fn too_large_maps_are_refused() {
        let src = "2D-Map\nCairn: RobotHome 0 0 0\nLINES\n0 0 20000000 0\n";
        let e = import_mobilesim(src, "big.map").unwrap_err();
        assert!(e.to_string().contains("millimetres"), "{e}");
    }
}
