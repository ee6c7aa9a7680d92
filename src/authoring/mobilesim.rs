//! A MobileSim map ([`crate::io::mobilesim`] reads the file) as a world: walls, home, and a
//! route generated through the free space ([`crate::authoring::route`]).
//!
//! Touching segments are chained into polylines (closed when they come back to their start;
//! thickness [`WALL_THICKNESS_M`]) and `RobotHome` becomes the home pose. What a careless map
//! holds that a world may not is repaired with a warning ([`repair_map`]) or refused at its
//! line, with the world checks' limits in the map's own numbers. Doors cannot be inferred from
//! a line map; the generated file says so.

use crate::authoring::route::{RouteOptions, generate_route};
use crate::geom::{Segment, Vec2};
use crate::io::mobilesim::{MobileSimMap, parse_map};
use crate::spec::diag::Diagnostic;
use crate::spec::world::{HomeSpec, RouteSpec, WallSpec, WorldSpec};
use std::collections::{HashMap, VecDeque};

/// Thickness given to imported walls, metres.
pub const WALL_THICKNESS_M: f64 = 0.05;

/// Most wall segments a world may hold (the world checks' limit).
pub const MAX_SEGMENTS: usize = crate::spec::world::MAX_SEGMENTS;

/// Largest extent of a world, corner to corner, metres (the world checks' limit).
pub const MAX_EXTENT_M: f64 = 10_000.0;

/// Why a map could not be imported.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MapError {
    /// A line that does not parse, or a home the route cannot grow from.
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

impl From<Diagnostic> for MapError {
    fn from(d: Diagnostic) -> Self {
        MapError::Malformed(d)
    }
}

/// A map imported as a world, with what the import repaired on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedMap {
    pub spec: WorldSpec,
    /// Warnings at the map's lines, one per repair (see [`repair_map`]).
    pub repairs: Vec<Diagnostic>,
}

/// Imports a MobileSim map as a world with walls, the home pose and a generated route.
pub fn import_mobilesim(src: &str, name: &str) -> Result<WorldSpec, MapError> {
    import_mobilesim_with(src, name, &RouteOptions::default())
}

/// [`import_mobilesim`] with explicit route-generation settings.
pub fn import_mobilesim_with(
    src: &str,
    name: &str,
    opts: &RouteOptions,
) -> Result<WorldSpec, MapError> {
    import_mobilesim_repaired(src, name, opts).map(|m| m.spec)
}

/// [`import_mobilesim_with`] keeping the repairs it made ([`repair_map`]).
pub fn import_mobilesim_repaired(
    src: &str,
    name: &str,
    opts: &RouteOptions,
) -> Result<ImportedMap, MapError> {
    let mut map = parse_map(src, name)?;
    let repairs = repair_map(&mut map, name);
    let home = within_limits(src, name, &map)?;
    let chains = chain_segments(&map.segments);
    if chains.is_empty() {
        return Err(no_route(
            name,
            1,
            "the map has no wall segments after `LINES`; add one `x1 y1 x2 y2` line (millimetres) \
             per wall segment after a `LINES` line"
                .into(),
        ));
    }
    let mut spec = world_without_route(name, home, chains);
    let walls: Vec<Segment> = map
        .segments
        .iter()
        .copied()
        .filter(|s| s.length() > 0.0)
        .collect();
    match generate_route(&walls, WALL_THICKNESS_M, Vec2::new(home.0, home.1), opts) {
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

/// Millimetres, as the world file writes coordinates.
fn r3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// A [`MapError::NoRoute`] without a partial world, at `line` (1 at least).
fn no_route(name: &str, line: usize, message: String) -> MapError {
    MapError::NoRoute {
        path: name.to_string(),
        line: line.max(1),
        message,
        partial: None,
    }
}

/// The home (x m, y m, heading degrees), once the map is checked against the world checks'
/// limits, reported here with the map's own numbers: a home, not too many segments, the home
/// inside the walls, not too wide.
fn within_limits(src: &str, name: &str, map: &MobileSimMap) -> Result<(f64, f64, f64), MapError> {
    let Some((hx, hy, hdeg)) = map.home else {
        return Err(no_route(
            name,
            1,
            "the map has no `Cairn: RobotHome x y heading` line, so there is no home pose; \
             add one to the header (millimetres and degrees)"
                .into(),
        ));
    };
    if map.segments.len() > MAX_SEGMENTS {
        return Err(no_route(
            name,
            map.segment_lines[MAX_SEGMENTS],
            format!(
                "the map has {} wall segments, more than a world may hold ({MAX_SEGMENTS}); \
             split the map or merge collinear segments",
                map.segments.len()
            ),
        ));
    }
    let home = Vec2::new(hx, hy);
    home_inside_walls(src, name, &map.segments, home)?;
    let (mut lo, mut hi) = (home, home);
    for s in &map.segments {
        for p in [s.a, s.b] {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    if (hi - lo).norm() > MAX_EXTENT_M {
        let farthest = map
            .segments
            .iter()
            .zip(&map.segment_lines)
            .map(|(s, &l)| ((s.a - home).norm().max((s.b - home).norm()), l))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(1, |(_, l)| l);
        return Err(no_route(
            name,
            farthest,
            format!(
                "the map (with its home) spans {:.0} m corner to corner, more than a world may ({MAX_EXTENT_M} m); \
             check the units (the format is in millimetres) or remove stray far-away lines \
             (this one is the farthest from the home)",
                (hi - lo).norm()
            ),
        ));
    }
    within_route_budget(src, name, map, home)?;
    Ok((hx, hy, hdeg))
}

/// Route generation's work grows with the area it rasterises (the walls' and home's bounding
/// box, [`crate::authoring::route::MAX_AREA_M2`] at most): a map over it is refused before any
/// planning, at the segment farthest from the home (the column of its farthest coordinate),
/// with an end for it that would fit (the rest of the map's box) when there is one.
fn within_route_budget(
    src: &str,
    name: &str,
    map: &MobileSimMap,
    home: Vec2,
) -> Result<(), Diagnostic> {
    use crate::authoring::route::{
        COARSEST_M, MAX_AREA_M2, MAX_CELLS, bounding_box, cell_size_m, raster_area_m2,
    };
    // The raster's own rule at its coarsest cell, so this refusal and route generation's agree.
    let bbox = |skip: Option<usize>| {
        let kept = (map.segments.iter().enumerate())
            .filter(move |(i, _)| Some(*i) != skip)
            .map(|(_, s)| s);
        bounding_box(home, kept)
    };
    let area = raster_area_m2;
    let fits = |b| cell_size_m(area(b), 0.0).is_some();
    let (lo, hi) = bbox(None);
    if fits((lo, hi)) {
        return Ok(());
    }
    let far = |p: Vec2| (p - home).norm();
    let Some((i, s)) = map.segments.iter().enumerate().max_by(|a, b| {
        far(a.1.a)
            .max(far(a.1.b))
            .total_cmp(&far(b.1.a).max(far(b.1.b)))
    }) else {
        return Ok(());
    };
    let (end, p) = if far(s.a) >= far(s.b) {
        (0, s.a)
    } else {
        (1, s.b)
    };
    // x or y of that end, whichever lies farther from the home: tokens x1 y1 x2 y2.
    let token = 2 * end + usize::from((p.y - home.y).abs() > (p.x - home.x).abs());
    let line = map.segment_lines[i];
    let col = src
        .lines()
        .nth(line - 1)
        .and_then(|l| token_column(l, token))
        .unwrap_or(1);
    let rest = bbox(Some(i));
    let fits = if fits(rest) {
        let q = p.sup(&rest.0).inf(&rest.1);
        format!(
            "an end within the rest of the map, e.g. `{:.0} {:.0}`, would fit",
            q.x * 1000.0,
            q.y * 1000.0
        )
    } else {
        "the rest of the map is too large as well: split it".to_string()
    };
    Err(Diagnostic::error(
        name,
        (line, col),
        format!(
            "this line stretches the map (with its home) to {:.0} × {:.0} m, {:.0} m² to plan a route over, \
             more than route generation takes ({MAX_AREA_M2:.0} m²: {:.0} million cells of {:.0} cm); \
             its end ({:.0}, {:.0}) mm is the farthest from the home; {fits}",
            hi.x - lo.x,
            hi.y - lo.y,
            area((lo, hi)),
            MAX_CELLS / 1e6,
            COARSEST_M * 100.0,
            p.x * 1000.0,
            p.y * 1000.0,
        ),
    ))
}

/// The 1-based column (in characters) of the `k`-th whitespace-separated token of `line`.
fn token_column(line: &str, k: usize) -> Option<usize> {
    let mut tokens = 0;
    let mut in_token = false;
    for (col, ch) in line.chars().enumerate() {
        if ch.is_whitespace() {
            in_token = false;
        } else if !in_token {
            if tokens == k {
                return Some(col + 1);
            }
            tokens += 1;
            in_token = true;
        }
    }
    None
}

/// The world the map gives before its route: walls from the chains, the home, a description
/// naming the map.
fn world_without_route(
    name: &str,
    (hx, hy, hdeg): (f64, f64, f64),
    chains: Vec<(Vec<Vec2>, bool)>,
) -> WorldSpec {
    let stem = std::path::Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imported".into());
    let file_name = std::path::Path::new(name)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    WorldSpec {
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
        walls: chain_walls(chains),
        doors: Vec::new(),
        routes: Vec::new(),
        areas: Vec::new(),
    }
}

/// A wall per chain of points (closed or not), named `w1`, `w2`… in their order.
fn chain_walls(chains: Vec<(Vec<Vec2>, bool)>) -> Vec<WallSpec> {
    chains
        .into_iter()
        .enumerate()
        .map(|(i, (pts, closed))| WallSpec {
            id: format!("w{}", i + 1),
            points_m: pts.iter().map(|p| [r3(p.x), r3(p.y)]).collect(),
            closed,
            thickness_m: WALL_THICKNESS_M,
        })
        .collect()
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
) -> Result<(), Diagnostic> {
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
    Err(Diagnostic::error(
        name,
        robot_home_at(src),
        format!(
            "RobotHome ({:.2}, {:.2}) m is {outside:.1} m outside the map's walls (limit {HOME_MARGIN_M} m); \
         put the home inside the building, in millimetres like the lines",
            home.x, home.y
        ),
    ))
}

/// The (line, column) of the first `RobotHome` in `src`, 1-based ((1, 1) without one).
fn robot_home_at(src: &str) -> (usize, usize) {
    let line = src
        .lines()
        .position(|l| l.contains("RobotHome"))
        .map_or(1, |i| i + 1);
    let col = src
        .lines()
        .nth(line - 1)
        .and_then(|l| l.find("RobotHome"))
        .map_or(1, |c| c + 1);
    (line, col)
}

/// The repairs the import makes so that a map drawn carelessly still gives a world `world
/// check` accepts, each a warning at its line of the map:
///
/// - a segment drawn twice (the same two end points, in millimetres, in either order) is kept
///   once: the world check refuses a wall that overlaps itself;
/// - a RobotHome heading outside -180..180 degrees is brought into it (1000 → -80): the world
///   check takes headings within ±360 only.
pub fn repair_map(map: &mut MobileSimMap, name: &str) -> Vec<Diagnostic> {
    let mut repairs = drop_repeated_segments(map, name);
    repairs.extend(wrap_home_heading(map, name));
    repairs
}

/// Millimetre key of a point: end points that meet in the file meet here.
fn mm(p: Vec2) -> (i64, i64) {
    ((p.x * 1000.0).round() as i64, (p.y * 1000.0).round() as i64)
}

/// Keeps the first of segments with the same two end points (either order), a warning for
/// each other one.
/// A segment's two end points in map units, the smaller first.
type SegmentKey = ((i64, i64), (i64, i64));

fn drop_repeated_segments(map: &mut MobileSimMap, name: &str) -> Vec<Diagnostic> {
    let mut repairs = Vec::new();
    let mut first: HashMap<SegmentKey, usize> = HashMap::new();
    let mut keep = Vec::with_capacity(map.segments.len());
    for (s, &line) in map.segments.iter().zip(&map.segment_lines) {
        let (a, b) = (mm(s.a), mm(s.b));
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
    repairs
}

/// A home heading outside -180..180 degrees brought into it, with a warning at its line.
fn wrap_home_heading(map: &mut MobileSimMap, name: &str) -> Option<Diagnostic> {
    let (_, _, h) = map.home.as_mut()?;
    if (-180.0..=180.0).contains(h) {
        return None;
    }
    let mut w = h.rem_euclid(360.0);
    if w > 180.0 {
        w -= 360.0;
    }
    let said = Diagnostic::warning(
        name,
        (map.home_line.max(1), 1),
        format!(
            "RobotHome heading {} degrees is outside -180..180; imported as {}",
            crate::spec::diag::fmt_number(*h),
            crate::spec::diag::fmt_number(w)
        ),
    );
    *h = w;
    Some(said)
}

/// Chains touching segments into polylines (zero-length segments dropped). Returns
/// (points, closed) per polyline.
pub fn chain_segments(segments: &[Segment]) -> Vec<(Vec<Vec2>, bool)> {
    let segs: Vec<&Segment> = segments.iter().filter(|s| mm(s.a) != mm(s.b)).collect();
    let mut at: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, s) in segs.iter().enumerate() {
        at.entry(mm(s.a)).or_default().push(i);
        at.entry(mm(s.b)).or_default().push(i);
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
            extend_chain(&mut chain, forward, &segs, &at, &mut used);
        }
        let mut pts: Vec<Vec2> = chain.into_iter().collect();
        let closed = pts.len() >= 4 && mm(pts[0]) == mm(*pts.last().unwrap());
        if closed {
            pts.pop();
        }
        out.push((pts, closed));
    }
    out
}

/// Grows `chain` at its back (`forward`) or front with unused segments touching its end, one
/// after another, until none touches.
fn extend_chain(
    chain: &mut VecDeque<Vec2>,
    forward: bool,
    segs: &[&Segment],
    at: &HashMap<(i64, i64), Vec<usize>>,
    used: &mut [bool],
) {
    loop {
        let end = if forward {
            *chain.back().unwrap()
        } else {
            *chain.front().unwrap()
        };
        let k = mm(end);
        let next = at
            .get(&k)
            .and_then(|v| v.iter().copied().find(|&j| !used[j]));
        let Some(j) = next else { break };
        used[j] = true;
        let other = far_end(segs[j], k);
        if forward {
            chain.push_back(other);
        } else {
            chain.push_front(other);
        }
    }
}

/// The end of `seg` that is not at `k` (millimetre key).
fn far_end(seg: &Segment, k: (i64, i64)) -> Vec2 {
    if mm(seg.a) == k { seg.b } else { seg.a }
}

/// `body` (toml) with point lists one `[x, y]` pair per line (toml writes them either on one
/// long line or one number per line) and without empty arrays.
fn pairs_per_line(body: &str) -> String {
    body.lines()
        .map(|l| match l.split_once(" = [[") {
            Some((key, rest)) if rest.ends_with("]]") => format!(
                "{key} = [\n    [{}],\n]\n",
                rest[..rest.len() - 2].replace("], [", "],\n    [")
            ),
            // Empty arrays would clash with the [[doors]] / [[routes]] blocks a user adds.
            _ if l.ends_with(" = []") => String::new(),
            _ => format!("{l}\n"),
        })
        .collect()
}

/// The world file text for an imported world, with a header naming the source.
pub fn world_to_toml(spec: &WorldSpec, source: &str) -> Result<String, toml::ser::Error> {
    let body = pairs_per_line(&toml::to_string(spec)?);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment drawn twice is imported once and a heading of 1000 degrees as -80, each said
    /// at its line.
    #[test]
    fn duplicate_segments_and_wild_headings_are_repaired_at_their_lines() {
        let src = "2D-Map\nCairn: RobotHome 1000 1000 1000\nLINES\n0 0 6000 0\n6000 0 0 0\n\
                   6000 0 6000 6000\n6000 6000 0 6000\n0 6000 0 0\n\
                   2500 2500 3500 2500\n3500 2500 3500 3500\n3500 3500 2500 3500\n2500 3500 2500 2500\n";
        let m = import_mobilesim_repaired(src, "r.map", &RouteOptions::default()).unwrap();
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
    fn a_map_without_a_home_is_refused_at_line_1() {
        let e = import_mobilesim("2D-Map\nLINES\n0 0 1 1\n", "m.map").unwrap_err();
        assert!(e.to_string().starts_with("m.map:1:1: "), "{e}");
        assert!(e.to_string().contains("RobotHome"), "{e}");
    }

    #[test]
    fn tiny_room_fails_with_advice() {
        let src = "2D-Map\nCairn: RobotHome 300 300 0\nLINES\n0 0 600 0\n600 0 600 600\n600 600 0 600\n0 600 0 0\n";
        let e = import_mobilesim(src, "t.map").unwrap_err();
        assert!(e.to_string().contains("[[routes]]"), "{e}");
    }

    #[test]
    fn a_line_stretched_far_is_refused_at_its_column_before_planning() {
        let src = "2D-Map\nCairn: RobotHome 1000 1000 0\nLINES\n0 0 4000 0\n4000 0 4000 4000\n\
                   4000 4000 300000 350000\n0 4000 0 0\n";
        let e = import_mobilesim(src, "far.map").unwrap_err().to_string();
        // Line 6, its fourth number (the far end's y, farther from the home than its x).
        assert!(
            e.starts_with("far.map:6:18: this line stretches the map"),
            "{e}"
        );
        // The far end clamped into the rest of the map's box.
        assert!(e.contains("e.g. `4000 4000`, would fit"), "{e}");
        let fixed = src.replace("300000 350000", "0 4000");
        let e = import_mobilesim(&fixed, "far.map")
            .err()
            .map(|e| e.to_string());
        assert!(
            e.as_ref().is_none_or(|e| !e.contains("plan a route over")),
            "{e:?}"
        );
    }

    #[test]
    fn too_large_maps_are_refused() {
        let src = "2D-Map\nCairn: RobotHome 0 0 0\nLINES\n0 0 20000000 0\n";
        let e = import_mobilesim(src, "big.map").unwrap_err();
        assert!(e.to_string().contains("millimetres"), "{e}");
    }
}
