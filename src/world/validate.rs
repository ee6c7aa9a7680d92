//! Checks of a world file beyond its syntax: ids, number ranges, size limits, and geometry
//! (doors in wall gaps, doors that swing through walls, route clearance, home pose, areas).
//!
//! Clearances are exact f64 distances between centre lines minus half the thickness of the wall
//! or door (thick segments treated as capsules, so slightly conservative at wall ends). Route
//! legs are checked by the exact segment-to-segment distance between the leg (the path of the
//! robot's centre) and each obstacle's centre line: the robot's disc (radius `WorldCheck::robot_radius_m`, 0.25 m by default) sweeps the
//! leg without touching an obstacle exactly when that clearance is at least the radius. Legs are
//! checked with all doors closed and with all doors open.

use crate::geom::{Segment, Vec2, wrap_angle};
use crate::spec::diag::{Diags, fmt_number};
use crate::spec::suggest::{length_unit_hint, radians_as_degrees, radians_hint};
use crate::spec::world::{
    DoorLoc, DoorSpec, RouteLoc, RouteSpec, Unread, WallLoc, WallSpec, WorldLoc, WorldSpec,
};
use crate::world::geometry::{SegmentIndex, ThickSegment};
use std::collections::HashMap;

/// Robot radius, metres (Pioneer 3-DX): the default robot a world is checked for.
pub const ROBOT_RADIUS_M: f64 = 0.25;

/// What a world is checked for: the robot that must fit its home pose and drive its routes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldCheck {
    /// Radius of the robot's disc, metres. Default `ROBOT_RADIUS_M` (0.25 m).
    pub robot_radius_m: f64,
}

impl Default for WorldCheck {
    fn default() -> Self {
        WorldCheck {
            robot_radius_m: ROBOT_RADIUS_M,
        }
    }
}
/// Extra clearance route waypoints keep beyond the robot radius, metres.
pub const WAYPOINT_MARGIN_M: f64 = 0.05;
/// How far each end of a closed door may be from a wall, metres.
pub const DOOR_GAP_TOLERANCE_M: f64 = 0.05;
/// Largest world extent, metres.
pub const MAX_EXTENT_M: f64 = 10_000.0;
/// Largest absolute coordinate, metres (see [`crate::spec::world::MAX_ABS_COORD_M`]).
pub const MAX_ABS_COORD_M: f64 = crate::spec::world::MAX_ABS_COORD_M;
/// Most wall segments, door panels and route legs a world may hold.
pub const MAX_SEGMENTS: usize = crate::spec::world::MAX_SEGMENTS;
/// Half the width of a walking person, metres (scenario A's pedestrians are about 0.3 m across).
pub const PEDESTRIAN_RADIUS_M: f64 = 0.15;
/// Wall thickness must lie in (0, this), metres.
pub const MAX_WALL_THICKNESS_M: f64 = 2.0;
/// Door panel width range, metres.
pub const DOOR_WIDTH_RANGE_M: (f64, f64) = (0.5, 3.0);
/// Door panel thickness must lie in (0, this], metres.
pub const MAX_DOOR_THICKNESS_M: f64 = 0.2;
/// Smallest swing between closed and open headings, degrees.
pub const MIN_DOOR_SWING_DEG: f64 = 10.0;
/// Ordinary values, metres: a number outside its range that fits it once read as millimetres or
/// centimetres gets a hint naming that unit (a door 900 wide is 900 mm).
const TYPICAL_DOOR_WIDTH_M: (f64, f64) = (0.6, 1.5);
const TYPICAL_DOOR_THICKNESS_M: (f64, f64) = (0.02, 0.1);
const TYPICAL_WALL_THICKNESS_M: (f64, f64) = (0.05, 0.5);
/// Largest angle, degrees, between a closed heading and the heading that spans the gap at
/// which the two count as the same (a 0.9 m panel's tip moves 5 cm in 3 degrees).
const SAME_HEADING_DEG: f64 = 3.0;
/// Shortest stretch two closed door panels may share before they count as two doors in one gap
/// (leaves of a double door meet tip to tip and share none), metres.
const DOORS_OVERLAP_M: f64 = 0.1;
fn v(p: &[f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

/// A coordinate for a message: plain when ordinary, in exponent form when huge.
fn fmt_m(x: f64) -> String {
    if x < 0.0 {
        "inside".to_string()
    } else {
        format!("{x:.2} m from")
    }
}

/// Reports ids used twice within one namespace.
fn duplicates<'s>(ids: impl Iterator<Item = (&'s str, usize)>, kind: &str, d: &mut Diags) {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (id, at) in ids {
        if let Some(&first) = seen.get(id) {
            let line = d.line_of(first);
            d.at(
                at,
                format!(
                    "duplicate {kind} id '{id}' (first used on line {line}); give each {kind} its own id"
                ),
            );
        } else {
            seen.insert(id, at);
        }
    }
}

/// All checks after reading; see the module docs.
pub fn validate(spec: &WorldSpec, loc: &WorldLoc, check: &WorldCheck, d: &mut Diags) {
    duplicate_ids(spec, loc, d);
    // Size limits first, before anything proportional to the geometry is built.
    if !segment_count_ok(spec, loc, d) || !extent_ok(spec, loc, d) {
        return;
    }
    // Numbers and shapes of single entities.
    let good_walls = walls_ok(spec, loc, d);
    let good_doors = doors_ok(spec, loc, d);
    routes_and_areas(spec, loc, d);
    if d.is_full() {
        return;
    }
    // The geometry of what read and is in range; what did not is set aside, and each check
    // that depends on it says so.
    let mut unread = loc.unread.clone();
    let (spec, loc) = usable(spec, loc, &good_walls, &good_doors, &mut unread);
    geometry(&spec, &loc, &unread, check.robot_radius_m, d);
}

/// The world without the walls and doors whose values are out of range (`good` false), which
/// join `unread`.
fn usable(
    spec: &WorldSpec,
    loc: &WorldLoc,
    good_walls: &[bool],
    good_doors: &[bool],
    unread: &mut Vec<Unread>,
) -> (WorldSpec, WorldLoc) {
    set_aside_walls(spec, loc, good_walls, unread);
    set_aside_doors(spec, loc, good_doors, unread);
    let (mut spec, mut loc) = (spec.clone(), loc.clone());
    let keep = |good: &[bool], i: usize| good.get(i).copied().unwrap_or(true);
    let mut i = 0;
    spec.walls.retain(|_| (keep(good_walls, i), i += 1).0);
    i = 0;
    loc.walls.retain(|_| (keep(good_walls, i), i += 1).0);
    i = 0;
    spec.doors.retain(|_| (keep(good_doors, i), i += 1).0);
    i = 0;
    loc.doors.retain(|_| (keep(good_doors, i), i += 1).0);
    (spec, loc)
}

/// Adds to `unread` the walls whose values are out of range (`good` false).
fn set_aside_walls(spec: &WorldSpec, loc: &WorldLoc, good: &[bool], unread: &mut Vec<Unread>) {
    for (w, (l, _)) in spec
        .walls
        .iter()
        .zip(loc.walls.iter().zip(good))
        .filter(|(_, (_, g))| !**g)
    {
        unread.push(Unread {
            kind: "wall",
            name: format!("wall '{}'", w.id),
            at: l.table,
            points_m: w.points_m.clone(),
        });
    }
}

/// Adds to `unread` the doors whose values are out of range (`good` false).
fn set_aside_doors(spec: &WorldSpec, loc: &WorldLoc, good: &[bool], unread: &mut Vec<Unread>) {
    for (door, (l, _)) in spec
        .doors
        .iter()
        .zip(loc.doors.iter().zip(good))
        .filter(|(_, (_, g))| !**g)
    {
        unread.push(Unread {
            kind: "door",
            name: format!("door '{}'", door.id),
            at: l.table,
            points_m: vec![door.hinge_m],
        });
    }
}

/// The centre-line segments of what read of an unread wall or door (a closed wall's closing
/// segment included, as it may be closed); a single point as a zero-length segment.
fn unread_segments(u: &Unread) -> Vec<Segment> {
    let p: Vec<Vec2> = u.points_m.iter().map(v).collect();
    match p.len() {
        0 => Vec::new(),
        1 => vec![Segment::new(p[0], p[0])],
        n => (0..n).map(|k| Segment::new(p[k], p[(k + 1) % n])).collect(),
    }
}

/// The first unread wall (`kind`) that may lie within `within_m` of `s`: one whose points did
/// not read may lie anywhere.
fn unread_near<'u>(
    unread: &'u [Unread],
    kind: &str,
    s: Segment,
    within_m: f64,
) -> Option<&'u Unread> {
    unread.iter().filter(|u| u.kind == kind).find(|u| {
        let segs = unread_segments(u);
        segs.is_empty()
            || segs
                .iter()
                .any(|t| crate::geom::segment_distance(s, *t) <= within_m)
    })
}

/// Ids used twice among walls, doors, routes or areas.
fn duplicate_ids(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    duplicates(
        spec.walls
            .iter()
            .zip(&loc.walls)
            .map(|(w, l)| (w.id.as_str(), l.id)),
        "wall",
        d,
    );
    duplicates(
        spec.doors
            .iter()
            .zip(&loc.doors)
            .map(|(w, l)| (w.id.as_str(), l.id)),
        "door",
        d,
    );
    duplicates(
        spec.routes
            .iter()
            .zip(&loc.routes)
            .map(|(w, l)| (w.id.as_str(), l.id)),
        "route",
        d,
    );
    duplicates(
        spec.areas
            .iter()
            .zip(&loc.areas)
            .map(|(w, l)| (w.id.as_str(), l.id)),
        "area",
        d,
    );
}

/// The number of wall segments, door panels and route legs.
fn segment_count(spec: &WorldSpec) -> usize {
    spec.walls
        .iter()
        .map(|w| {
            let n = w.points_m.len();
            if w.closed { n } else { n.saturating_sub(1) }
        })
        .sum::<usize>()
        + spec.doors.len()
        + spec
            .routes
            .iter()
            .map(|r| r.waypoints_m.len())
            .sum::<usize>()
}

/// Whether the world holds at most [`MAX_SEGMENTS`] wall segments, door panels and route legs.
fn segment_count_ok(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) -> bool {
    let segments = segment_count(spec);
    if segments > MAX_SEGMENTS {
        // Reported on the wall that holds most of them, when one does.
        let biggest = spec
            .walls
            .iter()
            .zip(&loc.walls)
            .map(|(w, l)| (w.points_m.len(), w, l))
            .max_by_key(|(n, _, _)| *n)
            .filter(|(n, _, _)| *n > segments / 2);
        let (at, which) = match biggest {
            Some((n, w, l)) => (
                l.points_key,
                format!(", {n} of them points of wall '{}'", w.id),
            ),
            None => (loc.walls_key, String::new()),
        };
        d.at(
            at,
            format!(
                "the world has {segments} wall segments, door panels and route legs (limit {MAX_SEGMENTS}){which}; simplify the walls or split the world into smaller ones"
            ),
        );
        return false;
    }
    true
}

/// Wall thicknesses, point counts and repeated points; per wall, whether its geometry can be
/// checked.
fn walls_ok(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) -> Vec<bool> {
    let mut good = Vec::with_capacity(spec.walls.len());
    for (w, l) in spec.walls.iter().zip(&loc.walls) {
        let ok = wall_thickness_ok(w, l, d);
        let n = w.points_m.len();
        if n < 2 || (w.closed && n < 3) {
            let need = if w.closed { 3 } else { 2 };
            d.at(
                l.points_key,
                format!(
                    "wall '{}' has {n} point(s) but a{} wall needs at least {need}; add points or remove the wall",
                    w.id,
                    if w.closed { " closed" } else { "" }
                ),
            );
            good.push(false);
            continue;
        }
        good.push(ok);
        repeated_wall_points(w, l, d);
    }
    good
}

/// Whether a wall's thickness is in range; an error when not.
fn wall_thickness_ok(w: &WallSpec, l: &WallLoc, d: &mut Diags) -> bool {
    if w.thickness_m > 0.0 && w.thickness_m < MAX_WALL_THICKNESS_M {
        return true;
    }
    d.at(
        l.thickness,
        format!(
            "wall '{}' has thickness_m = {}, outside (0, {MAX_WALL_THICKNESS_M}) m; {}",
            w.id,
            fmt_number(w.thickness_m),
            length_unit_hint("thickness_m", w.thickness_m, TYPICAL_WALL_THICKNESS_M)
                .unwrap_or_else(|| "use the wall's real thickness, e.g. 0.1".into())
        ),
    );
    false
}

/// An error per zero-length segment of a wall of at least two points.
fn repeated_wall_points(w: &WallSpec, l: &WallLoc, d: &mut Diags) {
    let n = w.points_m.len();
    let m = if w.closed { n } else { n - 1 };
    for j in 0..m {
        let (a, b) = (w.points_m[j], w.points_m[(j + 1) % n]);
        if a == b {
            let at = l.points.get((j + 1) % n).copied().unwrap_or(l.points_key);
            d.at(
                at,
                format!(
                    "wall '{}' has a zero-length segment (point {} repeats point {}); remove the repeated point",
                    w.id,
                    (j + 1) % n,
                    j
                ),
            );
        }
    }
}

/// Door widths, thicknesses, headings and swings; per door, whether its geometry can be
/// checked.
fn doors_ok(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) -> Vec<bool> {
    let mut good = Vec::with_capacity(spec.doors.len());
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        // Every check runs, so that each problem is reported.
        let ok = [
            door_width_ok(door, l, d),
            door_thickness_ok(door, l, d),
            door_headings_ok(door, l, d),
            door_swing_ok(door, l, d),
        ];
        good.push(ok.iter().all(|&o| o));
    }
    good
}

/// Whether a door's width is in [`DOOR_WIDTH_RANGE_M`]; an error when not.
fn door_width_ok(door: &DoorSpec, l: &DoorLoc, d: &mut Diags) -> bool {
    let (lo, hi) = DOOR_WIDTH_RANGE_M;
    if door.width_m >= lo && door.width_m <= hi {
        return true;
    }
    d.at(
        l.width,
        format!(
            "door '{}' has width_m = {}, outside {lo}-{hi} m; {}",
            door.id,
            fmt_number(door.width_m),
            length_unit_hint("width_m", door.width_m, TYPICAL_DOOR_WIDTH_M)
                .unwrap_or_else(|| "doors are usually 0.8-1.0 m wide".into())
        ),
    );
    false
}

/// Whether a door's thickness is in range; an error when not.
fn door_thickness_ok(door: &DoorSpec, l: &DoorLoc, d: &mut Diags) -> bool {
    if door.thickness_m > 0.0 && door.thickness_m <= MAX_DOOR_THICKNESS_M {
        return true;
    }
    d.at(
        l.thickness,
        format!(
            "door '{}' has thickness_m = {}, outside (0, {MAX_DOOR_THICKNESS_M}] m; {}",
            door.id,
            fmt_number(door.thickness_m),
            length_unit_hint("thickness_m", door.thickness_m, TYPICAL_DOOR_THICKNESS_M)
                .unwrap_or_else(|| "leave it out for the default 0.04".into())
        ),
    );
    false
}

/// Whether a door's closed and open headings are within -360..360; an error per one that is not.
fn door_headings_ok(door: &DoorSpec, l: &DoorLoc, d: &mut Diags) -> bool {
    let mut ok = true;
    for (h, at, key) in [
        (
            door.closed_heading_deg,
            l.closed_heading,
            "closed_heading_deg",
        ),
        (door.open_heading_deg, l.open_heading, "open_heading_deg"),
    ] {
        if h.abs() > 360.0 {
            d.at(
                at,
                format!(
                    "door '{}' has {key} = {}, outside -360..360; give the heading in degrees",
                    door.id,
                    fmt_number(h)
                ),
            );
            ok = false;
        }
    }
    ok
}

/// Whether a door swings at least [`MIN_DOOR_SWING_DEG`]; an error when not.
fn door_swing_ok(door: &DoorSpec, l: &DoorLoc, d: &mut Diags) -> bool {
    let swing = wrap_angle((door.open_heading_deg - door.closed_heading_deg).to_radians())
        .to_degrees()
        .abs();
    if swing < MIN_DOOR_SWING_DEG {
        d.at(
            l.open_heading,
            format!(
                "door '{}' swings only {swing:.1} degrees between closed and open; {}",
                door.id,
                small_swing_fix(door)
            ),
        );
        return false;
    }
    true
}

/// How to fix a door that swings too little: headings written in radians swing a few
/// degrees, so say so rather than "differ".
fn small_swing_fix(door: &DoorSpec) -> String {
    let radians: Vec<String> = [
        ("closed_heading_deg", door.closed_heading_deg),
        ("open_heading_deg", door.open_heading_deg),
    ]
    .into_iter()
    .filter_map(|(key, h)| radians_hint(key, h))
    .collect();
    if radians.is_empty() {
        "make open_heading_deg differ from closed_heading_deg, usually by 90".to_string()
    } else {
        radians.join("; ")
    }
}

/// Route waypoints, area corners and the home heading.
fn routes_and_areas(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        route_waypoints(r, l, d);
    }
    for (a, l) in spec.areas.iter().zip(&loc.areas) {
        if !(a.min_m[0] < a.max_m[0] && a.min_m[1] < a.max_m[1]) {
            d.at(
                l.max,
                format!(
                    "area '{}' is empty: max_m must be greater than min_m in x and in y; swap or fix the corners",
                    a.id
                ),
            );
        }
    }
    home_heading(spec, loc, d);
}

/// A route's waypoint count and repeated waypoints.
fn route_waypoints(r: &RouteSpec, l: &RouteLoc, d: &mut Diags) {
    let n = r.waypoints_m.len();
    if n < 3 {
        d.at(
            l.waypoints_key,
            format!(
                "route '{}' has {n} waypoint(s) but a route is a closed loop of at least 3; add waypoints",
                r.id
            ),
        );
        return;
    }
    repeated_waypoints(r, l, d);
}

/// An error per waypoint of a route (of at least 3) that repeats the one before it.
fn repeated_waypoints(r: &RouteSpec, l: &RouteLoc, d: &mut Diags) {
    let n = r.waypoints_m.len();
    for j in 0..n {
        if r.waypoints_m[j] == r.waypoints_m[(j + 1) % n] {
            let k = (j + 1) % n;
            d.at(
                l.waypoints.get(k).copied().unwrap_or(l.waypoints_key),
                format!(
                    "route '{}' waypoint {} repeats waypoint {} (a zero-length leg); remove it{}",
                    r.id,
                    k,
                    j,
                    if k == 0 {
                        " (the route closes by itself: do not repeat the first waypoint at the end)"
                    } else {
                        ""
                    }
                ),
            );
        }
    }
}

/// The robot home's heading: an error outside -360..360, a warning when it looks like radians.
fn home_heading(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    if loc.home.valid && spec.robot_home.heading_deg.abs() > 360.0 {
        d.at(
            loc.home.heading,
            "robot home heading_deg is outside -360..360; give the heading in degrees".into(),
        );
    } else if loc.home.valid
        && let Some(hint) = radians_hint("heading_deg", spec.robot_home.heading_deg)
    {
        // A heading of 1.57 degrees is legal but almost surely meant as 90.
        d.warn(loc.home.heading, format!("robot home {hint}"));
    }
}

/// Rejects worlds more than [`MAX_EXTENT_M`] across, pointing at the farthest coordinate.
fn extent_ok(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) -> bool {
    let pts = located_points(spec, loc);
    if pts.is_empty() {
        return true;
    }
    if let Some((p, at)) = pts
        .iter()
        .find(|(p, _)| p[0].abs() > MAX_ABS_COORD_M || p[1].abs() > MAX_ABS_COORD_M)
    {
        d.at(
            *at,
            format!(
                "the point [{}, {}] is more than {:.0} km from the origin; coordinates are metres: check this value or move the world near [0, 0]",
                fmt_number(p[0]),
                fmt_number(p[1]),
                MAX_ABS_COORD_M / 1000.0
            ),
        );
        return false;
    }
    span_ok(&pts, d)
}

/// Every coordinate of the world with where it was written: wall points, door hinges, route
/// waypoints, area corners and the robot's home.
fn located_points(spec: &WorldSpec, loc: &WorldLoc) -> Vec<([f64; 2], usize)> {
    let mut pts: Vec<([f64; 2], usize)> = Vec::new();
    for (w, l) in spec.walls.iter().zip(&loc.walls) {
        for (k, p) in w.points_m.iter().enumerate() {
            pts.push((*p, l.points.get(k).copied().unwrap_or(l.points_key)));
        }
    }
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        pts.push((door.hinge_m, l.hinge));
    }
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        for (k, p) in r.waypoints_m.iter().enumerate() {
            pts.push((*p, l.waypoints.get(k).copied().unwrap_or(l.waypoints_key)));
        }
    }
    for (a, l) in spec.areas.iter().zip(&loc.areas) {
        pts.push((a.min_m, l.min));
        pts.push((a.max_m, l.max));
    }
    if loc.home.valid {
        pts.push(([spec.robot_home.x_m, spec.robot_home.y_m], loc.home.x));
    }
    pts
}

/// Whether the points span at most [`MAX_EXTENT_M`] in x and in y; an error at the point
/// farthest from the median when not.
fn span_ok(pts: &[([f64; 2], usize)], d: &mut Diags) -> bool {
    let span = |axis: usize| {
        let vals = pts.iter().map(|(p, _)| p[axis]);
        vals.clone().fold(f64::NEG_INFINITY, f64::max) - vals.fold(f64::INFINITY, f64::min)
    };
    let millimetres = millimetre_hint(pts, [span(0), span(1)]);
    for axis in 0..2 {
        let mut vals: Vec<f64> = pts.iter().map(|(p, _)| p[axis]).collect();
        let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if hi - lo > MAX_EXTENT_M {
            let (p, at) = farthest_from_median(pts, &mut vals, axis);
            d.at(
                at,
                format!(
                    "the world is {:.0} m across in {} (limit {MAX_EXTENT_M:.0} m), because of the point [{}, {}]; {}",
                    hi - lo,
                    if axis == 0 { "x" } else { "y" },
                    fmt_number(p[0]),
                    fmt_number(p[1]),
                    millimetres.clone().unwrap_or_else(|| "coordinates are metres: check this value".into())
                ),
            );
            return false;
        }
    }
    true
}

/// The point farthest along `axis` from the median of `vals` (the points' values on that axis).
fn farthest_from_median(
    pts: &[([f64; 2], usize)],
    vals: &mut [f64],
    axis: usize,
) -> ([f64; 2], usize) {
    let mid = vals.len() / 2;
    vals.select_nth_unstable_by(mid, f64::total_cmp);
    let median = vals[mid];
    pts.iter()
        .max_by(|a, b| {
            (a.0[axis] - median)
                .abs()
                .total_cmp(&(b.0[axis] - median).abs())
        })
        .copied()
        .unwrap_or(([0.0, 0.0], 0))
}

/// `the coordinates look like millimetres…` when a world too large in metres is an ordinary
/// building in millimetres: most of its points lie more than 100 (m) from the origin, not just
/// one stray value, and it spans 1 to 2000 m once divided by 1000.
fn millimetre_hint(pts: &[([f64; 2], usize)], span_m: [f64; 2]) -> Option<String> {
    let far = pts
        .iter()
        .filter(|(p, _)| p[0].abs().max(p[1].abs()) > 100.0)
        .count();
    let (x, y) = (span_m[0] / 1000.0, span_m[1] / 1000.0);
    (2 * far > pts.len() && x.max(y) >= 1.0 && x.max(y) <= 2000.0).then(|| {
        format!(
            "the coordinates look like millimetres (in metres the world would be {} m x {} m); coordinates are metres: divide them by 1000",
            fmt_number((x * 10.0).round() / 10.0),
            fmt_number((y * 10.0).round() / 10.0)
        )
    })
}

/// What an obstacle in a clearance query is.
#[derive(Clone, Copy)]
enum Owner {
    Wall(usize),
    Door(usize),
}

fn owner_name(spec: &WorldSpec, o: Owner, state: &str) -> String {
    match o {
        Owner::Wall(i) => format!("wall '{}'", spec.walls[i].id),
        Owner::Door(i) => format!("door '{}' ({state})", spec.doors[i].id),
    }
}

fn door_panel(door: &DoorSpec, open: bool) -> Segment {
    let h = if open {
        door.open_heading_deg
    } else {
        door.closed_heading_deg
    }
    .to_radians();
    let a = v(&door.hinge_m);
    Segment::new(a, a + Vec2::new(h.cos(), h.sin()) * door.width_m)
}

struct Obstacles {
    index: SegmentIndex,
    owner: Vec<Owner>,
}

impl Obstacles {
    /// The nearest obstacle with clearance below `limit` to segment `s`.
    fn nearest(&self, s: Segment, limit: f64) -> Option<(Owner, f64)> {
        self.index
            .nearest_within(s, limit)
            .map(|(i, c)| (self.owner[i], c))
    }
}

/// The geometric checks of what read (`unread`: what did not, for the notes of the checks
/// that depend on it).
fn geometry(
    spec: &WorldSpec,
    loc: &WorldLoc,
    unread: &[Unread],
    robot_radius_m: f64,
    d: &mut Diags,
) {
    let walls = wall_obstacles(spec);
    let closed = door_obstacles(spec, false);
    let open = door_obstacles(spec, true);
    let all = [(&walls, ""), (&closed, "closed"), (&open, "open")];
    let spans = doors_span_their_gaps(spec, loc, &walls, unread, d);
    home_in_free_space(spec, loc, &all, robot_radius_m, d);
    doors_fit_their_gaps(spec, loc, &walls, &spans, d);
    doors_do_not_share_a_gap(spec, loc, d);
    walls_do_not_cross(spec, loc, d);
    walls_do_not_overlap(spec, loc, d);
    inside_the_building(spec, loc, unread, d);
    routes_are_drivable(spec, loc, &all, robot_radius_m, d);
    routes_near_unread(spec, loc, unread, robot_radius_m, d);
    areas_are_walkable(spec, loc, &walls, d);
}

/// A note per route leg that passes within the robot's radius of a wall or door that did not
/// read (or per route, when where it lies is unknown): the leg was not checked against it.
fn routes_near_unread(
    spec: &WorldSpec,
    loc: &WorldLoc,
    unread: &[Unread],
    robot_radius_m: f64,
    d: &mut Diags,
) {
    for u in unread.iter().filter(|u| matches!(u.kind, "wall" | "door")) {
        let (segs, reach) = unread_reach(u, robot_radius_m);
        for (r, l) in spec.routes.iter().zip(&loc.routes) {
            let n = r.waypoints_m.len();
            if n < 3 {
                continue;
            }
            let near = (0..n).find(|&k| {
                let leg = Segment::new(v(&r.waypoints_m[k]), v(&r.waypoints_m[(k + 1) % n]));
                segs.is_empty()
                    || segs
                        .iter()
                        .any(|t| crate::geom::segment_distance(leg, *t) <= reach)
            });
            let Some(k) = near else { continue };
            let line = d.line_of(u.at);
            let (at, message) = unchecked_leg_note(r, l, u, k, segs.is_empty(), line);
            d.note(at, message);
        }
    }
}

/// Where and what to note about route `r`'s leg from waypoint `k` that was not checked against
/// `u` (written on `line`): the whole route when where `u` lies is unknown (`nowhere`).
fn unchecked_leg_note(
    r: &RouteSpec,
    l: &RouteLoc,
    u: &Unread,
    k: usize,
    nowhere: bool,
    line: usize,
) -> (usize, String) {
    if nowhere {
        (
            l.waypoints_key,
            format!(
                "route '{}' was not checked against {}, whose place did not read (line {line}); fix it and check again",
                r.id, u.name
            ),
        )
    } else {
        (
            l.waypoints.get(k).copied().unwrap_or(l.waypoints_key),
            format!(
                "route '{}' leg from waypoint {k} to {} passes near {} and was not checked against it: that {} has errors (line {line}); fix them and check again",
                r.id,
                (k + 1) % r.waypoints_m.len(),
                u.name,
                u.kind
            ),
        )
    }
}

/// What of an unread wall or door a route leg must keep clear of, and how far: a door reaches
/// its width around its hinge whichever way it swings (the hinge to tip distance when both
/// read, the widest door otherwise).
fn unread_reach(u: &Unread, robot_radius_m: f64) -> (Vec<Segment>, f64) {
    match (u.kind, u.points_m.as_slice()) {
        ("door", [h, tip, ..]) => (
            vec![Segment::new(v(h), v(h))],
            robot_radius_m + (v(tip) - v(h)).norm(),
        ),
        ("door", [h]) => (
            vec![Segment::new(v(h), v(h))],
            robot_radius_m + DOOR_WIDTH_RANGE_M.1,
        ),
        _ => (unread_segments(u), robot_radius_m),
    }
}

/// Every segment of every wall (closed walls include the closing one), zero-length ones too:
/// (wall index, segment index, the segment with half the wall's thickness).
fn wall_segments(spec: &WorldSpec) -> impl Iterator<Item = (usize, usize, ThickSegment)> + '_ {
    spec.walls.iter().enumerate().flat_map(|(wi, w)| {
        let n = w.points_m.len();
        let m = if w.closed { n } else { n.saturating_sub(1) };
        (0..m).map(move |j| {
            let seg = Segment::new(v(&w.points_m[j]), v(&w.points_m[(j + 1) % n]));
            let half_thickness_m = w.thickness_m / 2.0;
            (
                wi,
                j,
                ThickSegment {
                    seg,
                    half_thickness_m,
                },
            )
        })
    })
}

/// Every wall segment of positive length, as a thick segment owned by its wall.
fn wall_obstacles(spec: &WorldSpec) -> Obstacles {
    let (owner, items) = wall_segments(spec)
        .filter(|(_, _, t)| t.seg.length() > 0.0)
        .map(|(wi, _, t)| (Owner::Wall(wi), t))
        .unzip();
    Obstacles {
        index: SegmentIndex::new(items),
        owner,
    }
}

/// Every door panel, closed or `open`.
fn door_obstacles(spec: &WorldSpec, open: bool) -> Obstacles {
    let items = spec
        .doors
        .iter()
        .map(|door| ThickSegment {
            seg: door_panel(door, open),
            half_thickness_m: door.thickness_m / 2.0,
        })
        .collect();
    Obstacles {
        index: SegmentIndex::new(items),
        owner: (0..spec.doors.len()).map(Owner::Door).collect(),
    }
}

/// The nearest obstacle within `limit` of `s` among `all` (walls, closed and open doors), with
/// its clearance and door state.
fn nearest_of<'a>(
    all: &[(&Obstacles, &'a str); 3],
    s: Segment,
    limit: f64,
) -> Option<(Owner, f64, &'a str)> {
    all.iter()
        .filter_map(|(o, state)| o.nearest(s, limit).map(|(w, c)| (w, c, *state)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// Doors: closed they fill a wall gap; open they do not cut through a wall. Per door, whether
/// its closed panel spans a gap (the fit checks look only at those).
fn doors_span_their_gaps(
    spec: &WorldSpec,
    loc: &WorldLoc,
    walls: &Obstacles,
    unread: &[Unread],
    d: &mut Diags,
) -> Vec<bool> {
    let mut spans = Vec::with_capacity(spec.doors.len());
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        spans.push(closed_door_spans(spec, door, l, walls, unread, d));
        open_door_clears_walls(spec, door, l, walls, d);
    }
    spans
}

/// Clearance of a point from the nearest wall within `probe` metres.
fn wall_clearance(walls: &Obstacles, p: Vec2, probe: f64) -> Option<f64> {
    walls.nearest(Segment::new(p, p), probe).map(|(_, c)| c)
}

/// Whether the closed panel of `door` spans a wall gap; reports it (or notes that its wall did
/// not read) when not. When the hinge is on a wall and another heading spans a gap from it,
/// the message names that heading and why the stated one misses (radians, off by 180 degrees).
fn closed_door_spans(
    spec: &WorldSpec,
    door: &DoorSpec,
    l: &crate::spec::world::DoorLoc,
    walls: &Obstacles,
    unread: &[Unread],
    d: &mut Diags,
) -> bool {
    let panel = door_panel(door, false);
    let probe = 1.0;
    let along = wall_along(walls, panel);
    if !off_wall(walls, panel.a, probe)
        && (off_wall(walls, panel.b, probe) || along.is_some())
        && let Some(gap) = gap_heading(door, walls)
    {
        let message = misses_hinge_gap(spec, door, along, panel.b, walls, probe, gap);
        d.at(l.closed_heading, message);
        return false;
    }
    let ends_ok = panel_ends_on_walls(door, l, panel, walls, unread, probe, d);
    if let Some(wi) = along {
        lies_along(door, l, &spec.walls[wi], d);
        return false;
    }
    ends_ok
}

/// The error for a closed door that lies along `wall` rather than in a gap of it.
fn lies_along(door: &DoorSpec, l: &crate::spec::world::DoorLoc, wall: &WallSpec, d: &mut Diags) {
    d.at(
        l.hinge,
        format!(
            "closed door '{}' lies along wall '{}' instead of filling a gap in it; leave a gap in the wall where the door is",
            door.id, wall.id
        ),
    );
}

/// The error for a closed door whose hinge is on a wall but whose panel (ending at `tip`)
/// misses the gap there, which heading `gap` would span.
fn misses_hinge_gap(
    spec: &WorldSpec,
    door: &DoorSpec,
    along: Option<usize>,
    tip: Vec2,
    walls: &Obstacles,
    probe: f64,
    gap: f64,
) -> String {
    let what = panel_miss(spec, along, tip, walls, probe);
    format!(
        "closed door '{}' does not span the gap at its hinge: {what}; {}",
        door.id,
        heading_cause(door.closed_heading_deg, gap)
    )
}

/// Whether `p` is farther than [`DOOR_GAP_TOLERANCE_M`] from every wall (within `probe` m).
fn off_wall(walls: &Obstacles, p: Vec2, probe: f64) -> bool {
    wall_clearance(walls, p, probe).is_none_or(|c| c > DOOR_GAP_TOLERANCE_M)
}

/// The wall whose inside holds the middle of `panel`, when one does.
fn wall_along(walls: &Obstacles, panel: Segment) -> Option<usize> {
    let mid = (panel.a + panel.b) / 2.0;
    match walls.nearest(Segment::new(mid, mid), 0.0) {
        Some((Owner::Wall(wi), c)) if c < -0.001 => Some(wi),
        _ => None,
    }
}

/// Whether both ends of a closed door's `panel` touch a wall; an error per end that does not,
/// or a single note when a wall that did not read may be the one it touches.
fn panel_ends_on_walls(
    door: &DoorSpec,
    l: &crate::spec::world::DoorLoc,
    panel: Segment,
    walls: &Obstacles,
    unread: &[Unread],
    probe: f64,
    d: &mut Diags,
) -> bool {
    let off_ends: Vec<_> = panel_ends(panel, l)
        .into_iter()
        .filter(|&(end, ..)| off_wall(walls, end, probe))
        .collect();
    let mut noted = false;
    for &(end, at, which, fix) in &off_ends {
        if let Some(u) = unread_near(unread, "wall", Segment::new(end, end), probe) {
            // Its wall may be the one that did not read: not checked, said once.
            if !noted {
                note_unread_wall(door, l.hinge, u, d);
            }
            noted = true;
        } else {
            let clearance = wall_clearance(walls, end, probe);
            d.at(at, end_off_wall(door, end, which, fix, clearance, probe));
        }
    }
    off_ends.is_empty()
}

/// Notes at `at` that closed `door` was not checked for spanning a gap, as its wall may be `u`.
fn note_unread_wall(door: &DoorSpec, at: usize, u: &Unread, d: &mut Diags) {
    let line = d.line_of(u.at);
    d.note(
        at,
        format!(
            "closed door '{}' not checked for spanning a wall gap: its wall may be {}, which has errors (line {line}); fix them and check again",
            door.id, u.name
        ),
    );
}

/// The error for a closed door's end (`which`) that lies `clearance` m from the nearest wall
/// (unknown: more than `probe` m).
fn end_off_wall(
    door: &DoorSpec,
    end: Vec2,
    which: &str,
    fix: &str,
    clearance: Option<f64>,
    probe: f64,
) -> String {
    let dist = clearance
        .map(|c| format!("{c:.2} m"))
        .unwrap_or_else(|| format!("more than {probe} m"));
    format!(
        "closed door '{}' does not span a wall gap: its {which} at [{:.2}, {:.2}] is {dist} from the nearest wall (at most {DOOR_GAP_TOLERANCE_M} m); {fix}",
        door.id, end.x, end.y
    )
}

/// A closed panel's hinge and tip: each with where it is written, its name and how to fix it
/// when it does not touch a wall.
fn panel_ends(
    panel: Segment,
    l: &crate::spec::world::DoorLoc,
) -> [(Vec2, usize, &'static str, &'static str); 2] {
    [
        (
            panel.a,
            l.hinge,
            "hinge",
            "move hinge_m onto the end of a wall",
        ),
        (
            panel.b,
            l.closed_heading,
            "tip",
            "check width_m and closed_heading_deg so the panel reaches the wall across the gap",
        ),
    ]
}

/// What keeps a closed panel from spanning the gap at its hinge: it lies along wall `along`,
/// or its `tip` is off the walls (`probe` metres the farthest looked).
fn panel_miss(
    spec: &WorldSpec,
    along: Option<usize>,
    tip: Vec2,
    walls: &Obstacles,
    probe: f64,
) -> String {
    match along {
        Some(wi) => format!("its panel lies along wall '{}'", spec.walls[wi].id),
        None => format!(
            "its tip at [{:.2}, {:.2}] is {} from the nearest wall",
            tip.x,
            tip.y,
            wall_clearance(walls, tip, probe)
                .map(|c| format!("{c:.2} m"))
                .unwrap_or_else(|| format!("more than {probe} m"))
        ),
    }
}

/// Why a closed heading misses the gap that `gap_deg` spans, and the heading to write.
fn heading_cause(stated_deg: f64, gap_deg: f64) -> String {
    let apart = |a: f64, b: f64| wrap_angle((a - b).to_radians()).to_degrees().abs();
    let write = format!("write closed_heading_deg = {}", fmt_number(gap_deg));
    if radians_as_degrees(stated_deg).is_some_and(|r| apart(r, gap_deg) <= SAME_HEADING_DEG) {
        return radians_hint("closed_heading_deg", stated_deg).unwrap_or(write);
    }
    if apart(stated_deg + 180.0, gap_deg) <= SAME_HEADING_DEG {
        return format!(
            "closed_heading_deg = {} points away from the gap (off by 180 degrees); {write}",
            fmt_number(stated_deg)
        );
    }
    format!(
        "the gap lies at {} degrees from the hinge; {write}",
        fmt_number(gap_deg)
    )
}

/// The whole-degree closed heading, in -180..180, at which the panel of `door` spans a wall gap
/// from its hinge: its tip on a wall (within the tolerance) and its middle in free space.
/// Among such headings, the one whose tip lies deepest in the wall (the gap's far end), then
/// the nearest to the stated heading.
fn gap_heading(door: &DoorSpec, walls: &Obstacles) -> Option<f64> {
    let hinge = v(&door.hinge_m);
    let stated = door.closed_heading_deg;
    (-179..=180)
        .filter_map(|deg| {
            let h = (deg as f64).to_radians();
            let dir = Vec2::new(h.cos(), h.sin());
            let tip = wall_clearance(walls, hinge + dir * door.width_m, 1.0)?;
            let mid_free = wall_clearance(walls, hinge + dir * (door.width_m / 2.0), 1.0)
                .is_none_or(|c| c > 0.0);
            (tip <= DOOR_GAP_TOLERANCE_M && mid_free).then_some((deg as f64, tip))
        })
        .min_by(|a, b| {
            let off = |h: f64| wrap_angle((h - stated).to_radians()).abs();
            (a.1, off(a.0))
                .partial_cmp(&(b.1, off(b.0)))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .map(|(deg, _)| deg)
}

/// An open door must not cut through a wall (beyond the hinge's first 10 cm, which sit in the
/// gap's end).
fn open_door_clears_walls(
    spec: &WorldSpec,
    door: &DoorSpec,
    l: &crate::spec::world::DoorLoc,
    walls: &Obstacles,
    d: &mut Diags,
) {
    if let Some(wi) = open_panel_cuts(door, door.open_heading_deg, walls) {
        let fix = radians_hint("open_heading_deg", door.open_heading_deg).unwrap_or_else(|| {
            "turn open_heading_deg so the door swings into free space in its room".into()
        });
        d.at(
            l.open_heading,
            format!(
                "open door '{}' cuts through wall '{}'; {fix}",
                door.id, spec.walls[wi].id
            ),
        );
    }
}

/// The wall the panel of `door` cuts through when open at `heading_deg`, if any.
fn open_panel_cuts(door: &DoorSpec, heading_deg: f64, walls: &Obstacles) -> Option<usize> {
    let h = heading_deg.to_radians();
    let a = v(&door.hinge_m);
    let dir = Vec2::new(h.cos(), h.sin());
    let part = Segment::new(
        a + dir * 0.1f64.min(door.width_m / 2.0),
        a + dir * door.width_m,
    );
    match walls.nearest(part, door.thickness_m / 2.0 - 0.005) {
        Some((Owner::Wall(wi), _)) => Some(wi),
        _ => None,
    }
}

/// Home pose: in free space, the robot's radius from walls and doors.
fn home_in_free_space(
    spec: &WorldSpec,
    loc: &WorldLoc,
    all: &[(&Obstacles, &str); 3],
    robot_radius_m: f64,
    d: &mut Diags,
) {
    if loc.home.valid {
        let p = Vec2::new(spec.robot_home.x_m, spec.robot_home.y_m);
        let s = Segment::new(p, p);
        let worst = nearest_of(all, s, robot_radius_m);
        if let Some((o, c, state)) = worst {
            d.at(
                loc.home.x,
                format!(
                    "robot home is {} {}; put it in free space, at least {robot_radius_m} m (the robot's radius) from walls and doors",
                    fmt_m(c),
                    owner_name(spec, o, state)
                ),
            );
        }
    }
}

/// Routes: waypoints keep radius + margin; legs let the disc through in both door states.
fn routes_are_drivable(
    spec: &WorldSpec,
    loc: &WorldLoc,
    all: &[(&Obstacles, &str); 3],
    robot_radius_m: f64,
    d: &mut Diags,
) {
    let [(walls, _), (closed, _), (open, _)] = *all;
    let mut opens_into_route = std::collections::HashSet::new();
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        let n = r.waypoints_m.len();
        if n < 3 {
            continue;
        }
        let bad = waypoints_too_close(spec, r, l, all, robot_radius_m, d);
        for k in 0..n {
            let k2 = (k + 1) % n;
            if bad[k] || bad[k2] {
                continue;
            }
            let leg = Segment::new(v(&r.waypoints_m[k]), v(&r.waypoints_m[k2]));
            let at = l.waypoints.get(k).copied().unwrap_or(l.waypoints_key);
            let checks = [
                (walls.nearest(leg, robot_radius_m), "", ""),
                (
                    closed.nearest(leg, robot_radius_m),
                    "closed",
                    " with all doors closed",
                ),
                (
                    open.nearest(leg, robot_radius_m),
                    "open",
                    " with all doors open",
                ),
            ];
            let mut blocked = false;
            for (hit, state, when) in checks {
                if let Some((o, c)) = hit {
                    blocked = true;
                    if let (Owner::Door(i), "open") = (o, state)
                        && let Some(other) = other_way(&spec.doors[i], walls, leg, robot_radius_m)
                    {
                        // The door, not the route, is what is wrong: said once, at the door.
                        if opens_into_route.insert(i) {
                            d.at(
                                loc.doors[i].open_heading,
                                format!(
                                    "open door '{}' swings into route '{}': the leg from waypoint {k} to {k2} passes {} it and the robot's disc (radius {robot_radius_m} m) cannot drive through; the door opens into the corridor: make it open into its room, open_heading_deg = {}",
                                    spec.doors[i].id,
                                    r.id,
                                    fmt_m(c),
                                    fmt_number(other)
                                ),
                            );
                        }
                        continue;
                    }
                    d.at(
                        at,
                        format!(
                            "route '{}' leg from waypoint {} to {} is blocked{when}: it passes {} {} and the robot's disc (radius {robot_radius_m} m) cannot drive through; move the waypoints so the leg keeps {robot_radius_m} m from walls and doors",
                            r.id,
                            k,
                            k2,
                            fmt_m(c),
                            owner_name(spec, o, state)
                        ),
                    );
                }
            }
            if !blocked {
                let tight = [(&walls, ""), (&closed, "closed"), (&open, "open")]
                    .into_iter()
                    .filter_map(|(obs, state)| {
                        obs.nearest(leg, robot_radius_m + WAYPOINT_MARGIN_M)
                            .map(|(o, c)| (o, c, state))
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((o, c, state)) = tight {
                    d.warn(
                        at,
                        format!(
                            "route '{}' leg from waypoint {} to {} passes {} {}: the robot's disc (radius {robot_radius_m} m) clears it by less than {WAYPOINT_MARGIN_M} m, so lap variation has no room there and a noisy robot may touch it; move the waypoints away from it",
                            r.id,
                            k,
                            k2,
                            fmt_m(c),
                            owner_name(spec, o, state)
                        ),
                    );
                }
            }
        }
    }
}

/// Whether each waypoint of route `r` is closer than radius + margin to a wall or a door (in
/// either state); each one that is reported at its key of `l`.
fn waypoints_too_close(
    spec: &WorldSpec,
    r: &crate::spec::world::RouteSpec,
    l: &crate::spec::world::RouteLoc,
    all: &[(&Obstacles, &str); 3],
    robot_radius_m: f64,
    d: &mut Diags,
) -> Vec<bool> {
    let need_wp = robot_radius_m + WAYPOINT_MARGIN_M;
    let n = r.waypoints_m.len();
    let mut bad = vec![false; n];
    for (k, p) in r.waypoints_m.iter().enumerate() {
        let p = v(p);
        let s = Segment::new(p, p);
        let worst = nearest_of(all, s, need_wp);
        if let Some((o, c, state)) = worst {
            bad[k] = true;
            let what = format!("{} {}", fmt_m(c), owner_name(spec, o, state));
            d.at(
                l.waypoints.get(k).copied().unwrap_or(l.waypoints_key),
                waypoint_too_close(&r.id, k, &what, robot_radius_m),
            );
        }
    }
    bad
}

/// The error for waypoint `k` of route `id` that is `what` (how near to what).
fn waypoint_too_close(id: &str, k: usize, what: &str, robot_radius_m: f64) -> String {
    let need_wp = robot_radius_m + WAYPOINT_MARGIN_M;
    format!(
        "route '{id}' waypoint {k} is {what}; keep waypoints at least {need_wp:.2} m (robot radius {robot_radius_m} m + {WAYPOINT_MARGIN_M} m) from walls and doors"
    )
}

/// The open heading, degrees, of `door` swung the other way (mirrored in its closed panel),
/// when that way it cuts no wall and leaves `leg` the robot's radius: the door opens into the
/// route's corridor and should open into its room.
fn other_way(door: &DoorSpec, walls: &Obstacles, leg: Segment, robot_radius_m: f64) -> Option<f64> {
    let mirrored = wrap_angle((2.0 * door.closed_heading_deg - door.open_heading_deg).to_radians())
        .to_degrees();
    let mirrored = (mirrored * 10.0).round() / 10.0 + 0.0;
    let h = mirrored.to_radians();
    let a = v(&door.hinge_m);
    let panel = Segment::new(a, a + Vec2::new(h.cos(), h.sin()) * door.width_m);
    let clear = crate::geom::segment_distance(leg, panel) - door.thickness_m / 2.0;
    (open_panel_cuts(door, mirrored, walls).is_none() && clear >= robot_radius_m)
        .then_some(mirrored)
}

/// Walking areas: people walk along the centre line of the longer side.
fn areas_are_walkable(spec: &WorldSpec, loc: &WorldLoc, walls: &Obstacles, d: &mut Diags) {
    for (a, l) in spec.areas.iter().zip(&loc.areas) {
        let (lo, hi) = (v(&a.min_m), v(&a.max_m));
        if !(lo.x < hi.x && lo.y < hi.y) {
            continue;
        }
        let c = (lo + hi) / 2.0;
        let line = if hi.x - lo.x >= hi.y - lo.y {
            Segment::new(Vec2::new(lo.x, c.y), Vec2::new(hi.x, c.y))
        } else {
            Segment::new(Vec2::new(c.x, lo.y), Vec2::new(c.x, hi.y))
        };
        if let Some((o, c)) = walls.nearest(line, PEDESTRIAN_RADIUS_M) {
            d.at(
                l.min,
                format!(
                    "area '{}': its centre line, where people walk, passes {} {}; keep walking areas inside corridors, the centre line at least {PEDESTRIAN_RADIUS_M} m from walls",
                    a.id,
                    fmt_m(c),
                    owner_name(spec, o, "")
                ),
            );
        }
    }
}

/// Closed doors whose panel runs into the wall beyond its gap (the panel is longer than the
/// gap, or the hinge sits inside the wall): the length of panel inside a wall at each end,
/// beyond the wall's end cap, measured every centimetre.
fn doors_fit_their_gaps(
    spec: &WorldSpec,
    loc: &WorldLoc,
    walls: &Obstacles,
    spans: &[bool],
    d: &mut Diags,
) {
    for ((door, l), _) in spec
        .doors
        .iter()
        .zip(&loc.doors)
        .zip(spans)
        .filter(|(_, s)| **s)
    {
        let panel = door_panel(door, false);
        // A door whose ends are off the walls is reported as not spanning a gap already.
        let off_wall = |p: Vec2| {
            walls
                .nearest(Segment::new(p, p), 1.0)
                .is_none_or(|(_, c)| c > DOOR_GAP_TOLERANCE_M)
        };
        if off_wall(panel.a) || off_wall(panel.b) {
            continue;
        }
        let steps = (door.width_m / 0.01).round().max(1.0) as usize;
        let inside = |k: usize| -> Option<usize> {
            let p = panel.a + (panel.b - panel.a) * (k as f64 / steps as f64);
            match walls.nearest(Segment::new(p, p), 0.0) {
                Some((Owner::Wall(wi), c)) if c < -0.002 => Some(wi),
                _ => None,
            }
        };
        let run = |ks: &mut dyn Iterator<Item = usize>| -> Option<(usize, f64)> {
            let mut wall = None;
            let mut n = 0;
            for k in ks {
                match inside(k) {
                    Some(wi) => (wall, n) = (Some(wi), n + 1),
                    None => break,
                }
            }
            wall.map(|wi| (wi, (n as f64 - 1.0).max(0.0) * door.width_m / steps as f64))
        };
        let ends = [
            (run(&mut (0..=steps).rev()), l.width, "tip"),
            (run(&mut (0..=steps)), l.hinge, "hinge end"),
        ];
        for (hit, at, which) in ends {
            let Some((wi, depth)) = hit else { continue };
            let over = depth - spec.walls[wi].thickness_m / 2.0;
            if over > DOOR_GAP_TOLERANCE_M && depth < door.width_m * 0.5 {
                d.at(
                    at,
                    format!(
                        "closed door '{}' is longer than its gap: its {which} runs {over:.2} m into wall '{}'; make width_m the gap's width (about {:.2} m) or widen the gap",
                        door.id,
                        spec.walls[wi].id,
                        door.width_m - over
                    ),
                );
            }
        }
    }
}

/// Shortest overlap of two parallel wall segments that counts as overlapping walls, metres
/// (longer than a pillar set against a wall, as the institute floor has).
pub const WALL_OVERLAP_M: f64 = 0.5;

/// A wall segment of non-zero length: (wall, index of its first point, segment).
type WallSegment = (usize, usize, ThickSegment);

/// The wall segments of `spec` of non-zero length and, for each, the earlier ones whose boxes
/// touch it: the pairs the overlap and crossing checks test.
fn near_wall_segments(spec: &WorldSpec) -> (Vec<WallSegment>, Vec<Vec<usize>>) {
    let segs: Vec<WallSegment> = wall_segments(spec)
        .filter(|(_, _, t)| t.seg.length() > 0.0)
        .collect();
    let index = SegmentIndex::new(segs.iter().map(|x| x.2).collect());
    let near = segs
        .iter()
        .enumerate()
        .map(|(i, (_, _, t))| {
            index
                .candidates(t.seg, 0.0)
                .into_iter()
                .filter(|&k| k < i)
                .collect()
        })
        .collect();
    (segs, near)
}

/// Walls drawn twice or over each other: two parallel wall segments less than half their
/// thicknesses apart that share more than [`WALL_OVERLAP_M`] of length.
fn walls_do_not_overlap(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    let (segs, near) = near_wall_segments(spec);
    // One message per pair of walls: a duplicated wall overlaps its twin on every segment.
    let mut reported = std::collections::HashSet::new();
    for (i, &(wi, j, t)) in segs.iter().enumerate() {
        for &k in &near[i] {
            let (wk, _, u) = segs[k];
            if reported.contains(&(wi, wk)) {
                continue;
            }
            let Some((len, from, to)) = overlap(&u, &t, WALL_OVERLAP_M) else {
                continue;
            };
            reported.insert((wi, wk));
            let w = &spec.walls[wi];
            let at = loc.walls[wi]
                .points
                .get(j)
                .copied()
                .unwrap_or(loc.walls[wi].points_key);
            let other = if wk == wi {
                "itself".to_string()
            } else {
                format!("wall '{}'", spec.walls[wk].id)
            };
            d.at(
                at,
                format!(
                    "wall '{}' (points {} to {}) overlaps {other} for {len:.2} m, from [{:.2}, {:.2}] to [{:.2}, {:.2}]; draw each wall once: remove the duplicate or shorten one of them",
                    w.id,
                    j,
                    (j + 1) % w.points_m.len(),
                    from.x,
                    from.y,
                    to.x,
                    to.y
                ),
            );
            break;
        }
    }
}

/// Length and ends of the shared stretch, longer than `min_m`, of two parallel thick segments
/// lying on each other.
fn overlap(a: &ThickSegment, b: &ThickSegment, min_m: f64) -> Option<(f64, Vec2, Vec2)> {
    let la = a.seg.length();
    let u = (a.seg.b - a.seg.a) / la;
    let db = b.seg.b - b.seg.a;
    let cross = |p: Vec2, q: Vec2| p.x * q.y - p.y * q.x;
    if cross(u, db / db.norm()).abs() > 0.02 {
        return None;
    }
    let lateral = cross(u, b.seg.a - a.seg.a)
        .abs()
        .max(cross(u, b.seg.b - a.seg.a).abs());
    if lateral >= 0.5 * (a.half_thickness_m + b.half_thickness_m) {
        return None;
    }
    let (t0, t1) = ((b.seg.a - a.seg.a).dot(&u), (b.seg.b - a.seg.a).dot(&u));
    let (lo, hi) = (t0.min(t1).max(0.0), t0.max(t1).min(la));
    (hi - lo > min_m).then(|| (hi - lo, a.seg.a + u * lo, a.seg.a + u * hi))
}

/// Two doors in one gap: closed panels that lie on each other for more than
/// [`DOORS_OVERLAP_M`] (a double door's leaves meet tip to tip and pass).
fn doors_do_not_share_a_gap(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    let panels: Vec<ThickSegment> = spec
        .doors
        .iter()
        .map(|door| ThickSegment {
            seg: door_panel(door, false),
            half_thickness_m: door.thickness_m / 2.0,
        })
        .collect();
    let index = SegmentIndex::new(panels.clone());
    for (i, t) in panels.iter().enumerate() {
        let first = index
            .candidates(t.seg, 0.0)
            .into_iter()
            .filter(|&k| k < i && panels[k].seg.length() > 0.0 && t.seg.length() > 0.0)
            .find_map(|k| overlap(&panels[k], t, DOORS_OVERLAP_M).map(|(len, ..)| (k, len)));
        let Some((k, len)) = first else { continue };
        d.at(
            loc.doors[i].hinge,
            format!(
                "door '{}' fills the same gap as door '{}' (line {}): their closed panels overlap for {len:.2} m; remove one, or for a double door give each leaf its share of the gap, hinged at the gap's two ends",
                spec.doors[i].id,
                spec.doors[k].id,
                d.line_of(loc.doors[k].table)
            ),
        );
    }
}

/// Shortest arm, metres, on every side of a crossing of two walls for it to count as walls
/// that cross: shorter arms are a wall's end run a little past another (the shipped floors
/// may end a wall a little past a pillar or an outline).
pub const WALL_CROSSING_ARM_M: f64 = 0.5;

/// Walls that cross like an X where that is a drawing mistake: a wall that crosses itself, or
/// any wall through a closed wall (a room's outline), with arms longer than
/// [`WALL_CROSSING_ARM_M`] on all four sides (a T, a corner or an end run a little past another
/// wall is fine, and so are two open walls crossing where four rooms meet).
fn walls_do_not_cross(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) {
    let (segs, near) = near_wall_segments(spec);
    let mut reported = std::collections::HashSet::new();
    for (i, &(wi, j, t)) in segs.iter().enumerate() {
        for &k in &near[i] {
            let (wk, jk, u) = segs[k];
            if reported.contains(&(wi, wk)) {
                continue;
            }
            let Some(x) = crate::geom::crossing_point(u.seg, t.seg) else {
                continue;
            };
            let long_arms = |s: &ThickSegment| {
                (x - s.seg.a).norm().min((x - s.seg.b).norm()) > WALL_CROSSING_ARM_M
            };
            // Two open walls crossing are where four rooms meet (the shipped floors draw their
            // junctions so); a wall through its own line or through a room's closed outline is
            // a drawing mistake.
            let outline = wi == wk || spec.walls[wi].closed || spec.walls[wk].closed;
            if !(outline && long_arms(&t) && long_arms(&u)) {
                continue;
            }
            reported.insert((wi, wk));
            let w = &spec.walls[wi];
            let l = &loc.walls[wi];
            let points = |w: &crate::spec::world::WallSpec, j: usize| {
                format!("points {} to {}", j, (j + 1) % w.points_m.len())
            };
            let other = if wk == wi {
                format!("itself ({})", points(w, jk))
            } else {
                format!(
                    "wall '{}' ({})",
                    spec.walls[wk].id,
                    points(&spec.walls[wk], jk)
                )
            };
            d.at(
                l.points.get(j).copied().unwrap_or(l.points_key),
                format!(
                    "wall '{}' ({}) crosses {other} at [{:.2}, {:.2}]; walls meet at their ends or one ends on the other: check these points (if the walls are meant to cross, end each at the crossing)",
                    w.id,
                    points(w, j),
                    x.x,
                    x.y
                ),
            );
            break;
        }
    }
}

/// The robot's home and every walking area must lie inside the building (free space around
/// them does not reach past the walls) and in the part of it the routes drive through (not in
/// a room closed off all round), or the robot never meets the people who walk there. Doors are
/// taken open: a home behind a door is fine.
fn inside_the_building(spec: &WorldSpec, loc: &WorldLoc, unread: &[Unread], d: &mut Diags) {
    let Some(first) = spec.routes.iter().find_map(|r| r.waypoints_m.first()) else {
        return;
    };
    let home = Vec2::new(spec.robot_home.x_m, spec.robot_home.y_m);
    // (where it is reported, how messages name it, where it is, its point, the fix)
    let mut places: Vec<(usize, String, String, Vec2, String)> = Vec::new();
    let beside = format!(
        "put it beside the route, e.g. near the first waypoint of route '{}' [{}, {}]",
        spec.routes[0].id, first[0], first[1]
    );
    if loc.home.valid {
        places.push((
            loc.home.x,
            "robot home".into(),
            format!(" [{}, {}]", fmt_number(home.x), fmt_number(home.y)),
            home,
            beside,
        ));
    }
    for (a, l) in spec.areas.iter().zip(&loc.areas) {
        if a.min_m[0] < a.max_m[0] && a.min_m[1] < a.max_m[1] {
            places.push((
                l.min,
                format!("area '{}'", a.id),
                String::new(),
                (v(&a.min_m) + v(&a.max_m)) / 2.0,
                "people walk where the robot can meet them: move it into a corridor a route drives through".into(),
            ));
        }
    }
    if places.is_empty() {
        return;
    }
    let items: Vec<ThickSegment> = wall_segments(spec).map(|(_, _, t)| t).collect();
    let points: Vec<Vec2> = places.iter().map(|p| p.3).collect();
    let raster = crate::world::raster::Raster::new(&items, &points, 0.1, 1.0, 0.05);
    let on_route = |region: &[bool]| {
        spec.routes.iter().flat_map(|r| &r.waypoints_m).any(|p| {
            raster
                .cell(v(p))
                .is_some_and(|(x, y)| region[y * raster.width + x])
        })
    };
    // A wall (or route) that did not read may close the loop (or pass by the place).
    let broken = unread.iter().find(|u| matches!(u.kind, "wall" | "route"));
    for (at, name, where_, p, fix) in places {
        let region = raster.reachable(&[p]);
        if !region.iter().any(|r| *r) {
            continue; // on a wall: reported with its clearance
        }
        let message = if raster.touches_border(&region) {
            "is outside every wall loop (free space around it reaches past all walls)"
        } else if !on_route(&region) {
            "is in a room closed off all round (no route passes there, even with every door open)"
        } else {
            continue;
        };
        match broken {
            Some(u) => d.note(
                at,
                format!(
                    "{name} not checked for lying inside the building beside a route: {} has errors (line {}); fix them and check again",
                    u.name,
                    d.line_of(u.at)
                ),
            ),
            None => d.at(at, format!("{name}{where_} {message}; {fix}")),
        }
    }
}
