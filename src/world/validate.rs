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
use crate::spec::diag::Diags;
use crate::spec::world::{WorldLoc, WorldSpec};
use crate::world::geometry::{SegmentIndex, ThickSegment};
use std::collections::HashMap;

/// Robot radius, metres (Pioneer 3-DX): the default robot a world is checked for.
pub const ROBOT_RADIUS_M: f64 = 0.25;

/// What a world is checked for: the robot that must fit its home pose and drive its routes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldCheck {
    /// Radius of the robot's disc, metres. Default [`ROBOT_RADIUS_M`].
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
/// Largest absolute coordinate, metres: keeps every number the geometry squares or converts
/// far from overflow.
pub const MAX_ABS_COORD_M: f64 = 1_000_000.0;
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
fn v(p: &[f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

/// A coordinate for a message: plain when ordinary, in exponent form when huge.
fn fmt_coord(x: f64) -> String {
    if x.abs() >= 1e7 {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

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

    let mut geometry_ok = loc.all_read;

    // Size limits first, before anything proportional to the geometry is built.
    let segments: usize = spec
        .walls
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
            .sum::<usize>();
    if segments > MAX_SEGMENTS {
        d.at(
            loc.walls_key,
            format!(
                "the world has {segments} wall segments, door panels and route legs (limit {MAX_SEGMENTS}); simplify the walls or split the world into smaller ones"
            ),
        );
        return;
    }
    if !extent_ok(spec, loc, d) {
        return;
    }

    // Numbers and shapes of single entities.
    for (w, l) in spec.walls.iter().zip(&loc.walls) {
        if !(w.thickness_m > 0.0 && w.thickness_m < MAX_WALL_THICKNESS_M) {
            d.at(
                l.thickness,
                format!(
                    "wall '{}' has thickness_m = {}, outside (0, {MAX_WALL_THICKNESS_M}) m; use the wall's real thickness, e.g. 0.1",
                    w.id, w.thickness_m
                ),
            );
            geometry_ok = false;
        }
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
            geometry_ok = false;
            continue;
        }
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
                        (j + 1) % n + 1,
                        j + 1
                    ),
                );
            }
        }
    }
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        let (lo, hi) = DOOR_WIDTH_RANGE_M;
        if !(door.width_m >= lo && door.width_m <= hi) {
            d.at(
                l.width,
                format!(
                    "door '{}' has width_m = {}, outside {lo}-{hi} m; doors are usually 0.8-1.0 m wide",
                    door.id, door.width_m
                ),
            );
            geometry_ok = false;
        }
        if !(door.thickness_m > 0.0 && door.thickness_m <= MAX_DOOR_THICKNESS_M) {
            d.at(
                l.thickness,
                format!(
                    "door '{}' has thickness_m = {}, outside (0, {MAX_DOOR_THICKNESS_M}] m; leave it out for the default 0.04",
                    door.id, door.thickness_m
                ),
            );
            geometry_ok = false;
        }
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
                        "door '{}' has {key} = {h}, outside -360..360; give the heading in degrees",
                        door.id
                    ),
                );
                geometry_ok = false;
            }
        }
        let swing = wrap_angle((door.open_heading_deg - door.closed_heading_deg).to_radians())
            .to_degrees()
            .abs();
        if swing < MIN_DOOR_SWING_DEG {
            d.at(
                l.open_heading,
                format!(
                    "door '{}' swings only {swing:.1} degrees between closed and open; make open_heading_deg differ from closed_heading_deg, usually by 90",
                    door.id
                ),
            );
            geometry_ok = false;
        }
    }
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        let n = r.waypoints_m.len();
        if n < 3 {
            d.at(
                l.waypoints_key,
                format!(
                    "route '{}' has {n} waypoint(s) but a route is a closed loop of at least 3; add waypoints",
                    r.id
                ),
            );
            continue;
        }
        for j in 0..n {
            if r.waypoints_m[j] == r.waypoints_m[(j + 1) % n] {
                let k = (j + 1) % n;
                d.at(
                    l.waypoints.get(k).copied().unwrap_or(l.waypoints_key),
                    format!(
                        "route '{}' waypoint {} repeats waypoint {} (a zero-length leg); remove it{}",
                        r.id,
                        k + 1,
                        j + 1,
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
    if loc.home.valid && spec.robot_home.heading_deg.abs() > 360.0 {
        d.at(
            loc.home.heading,
            "robot home heading_deg is outside -360..360; give the heading in degrees".into(),
        );
    }

    if geometry_ok && !d.is_full() {
        geometry(spec, loc, check.robot_radius_m, d);
    }
}

/// Rejects worlds more than [`MAX_EXTENT_M`] across, pointing at the farthest coordinate.
fn extent_ok(spec: &WorldSpec, loc: &WorldLoc, d: &mut Diags) -> bool {
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
                fmt_coord(p[0]),
                fmt_coord(p[1]),
                MAX_ABS_COORD_M / 1000.0
            ),
        );
        return false;
    }
    for axis in 0..2 {
        let mut vals: Vec<f64> = pts.iter().map(|(p, _)| p[axis]).collect();
        let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if hi - lo > MAX_EXTENT_M {
            let mid = vals.len() / 2;
            vals.select_nth_unstable_by(mid, f64::total_cmp);
            let median = vals[mid];
            let (p, at) = pts
                .iter()
                .max_by(|a, b| {
                    (a.0[axis] - median)
                        .abs()
                        .total_cmp(&(b.0[axis] - median).abs())
                })
                .copied()
                .unwrap_or(([0.0, 0.0], 0));
            d.at(
                at,
                format!(
                    "the world is {:.0} m across in {} (limit {MAX_EXTENT_M:.0} m), because of the point [{}, {}]; coordinates are metres: check this value",
                    hi - lo,
                    if axis == 0 { "x" } else { "y" },
                    fmt_coord(p[0]),
                    fmt_coord(p[1])
                ),
            );
            return false;
        }
    }
    true
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

fn door_panel(door: &crate::spec::world::DoorSpec, open: bool) -> Segment {
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

fn geometry(spec: &WorldSpec, loc: &WorldLoc, robot_radius_m: f64, d: &mut Diags) {
    let mut items = Vec::new();
    let mut owner = Vec::new();
    for (wi, w) in spec.walls.iter().enumerate() {
        let n = w.points_m.len();
        let m = if w.closed { n } else { n - 1 };
        for j in 0..m {
            let s = Segment::new(v(&w.points_m[j]), v(&w.points_m[(j + 1) % n]));
            if s.length() > 0.0 {
                items.push(ThickSegment {
                    seg: s,
                    half_thickness_m: w.thickness_m / 2.0,
                });
                owner.push(Owner::Wall(wi));
            }
        }
    }
    let walls = Obstacles {
        index: SegmentIndex::new(items),
        owner,
    };
    let doors_in = |open: bool| -> Obstacles {
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
    };
    let closed = doors_in(false);
    let open = doors_in(true);

    // Doors: closed they fill a wall gap; open they do not cut through a wall.
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        let panel = door_panel(door, false);
        let point = |p: Vec2| Segment::new(p, p);
        let probe = 1.0;
        for (end, at, which, fix) in [
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
        ] {
            let c = walls.nearest(point(end), probe).map(|(_, c)| c);
            if c.is_none_or(|c| c > DOOR_GAP_TOLERANCE_M) {
                let dist = c
                    .map(|c| format!("{c:.2} m"))
                    .unwrap_or_else(|| format!("more than {probe} m"));
                d.at(
                    at,
                    format!(
                        "closed door '{}' does not span a wall gap: its {which} at [{:.2}, {:.2}] is {dist} from the nearest wall (at most {DOOR_GAP_TOLERANCE_M} m); {fix}",
                        door.id, end.x, end.y
                    ),
                );
            }
        }
        let mid = (panel.a + panel.b) / 2.0;
        if let Some((Owner::Wall(wi), c)) = walls.nearest(point(mid), 0.0)
            && c < -0.001
        {
            d.at(
                l.hinge,
                format!(
                    "closed door '{}' lies along wall '{}' instead of filling a gap in it; leave a gap in the wall where the door is",
                    door.id, spec.walls[wi].id
                ),
            );
        }
        let op = door_panel(door, true);
        let dir = (op.b - op.a) / door.width_m;
        let part = Segment::new(op.a + dir * (0.1f64).min(door.width_m / 2.0), op.b);
        let half = door.thickness_m / 2.0;
        if let Some((Owner::Wall(wi), c)) = walls.nearest(part, half - 0.005) {
            let _ = c;
            d.at(
                l.open_heading,
                format!(
                    "open door '{}' cuts through wall '{}'; turn open_heading_deg so the door swings into free space in its room",
                    door.id, spec.walls[wi].id
                ),
            );
        }
    }

    // Home pose: in free space.
    if loc.home.valid {
        let p = Vec2::new(spec.robot_home.x_m, spec.robot_home.y_m);
        let s = Segment::new(p, p);
        let worst = [
            walls.nearest(s, robot_radius_m).map(|(o, c)| (o, c, "")),
            closed
                .nearest(s, robot_radius_m)
                .map(|(o, c)| (o, c, "closed")),
            open.nearest(s, robot_radius_m).map(|(o, c)| (o, c, "open")),
        ]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.1.total_cmp(&b.1));
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

    // Routes: waypoints keep radius + margin; legs let the disc through in both door states.
    let need_wp = robot_radius_m + WAYPOINT_MARGIN_M;
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        let n = r.waypoints_m.len();
        if n < 3 {
            continue;
        }
        let mut bad = vec![false; n];
        for (k, p) in r.waypoints_m.iter().enumerate() {
            let p = v(p);
            let s = Segment::new(p, p);
            let worst = [
                walls.nearest(s, need_wp).map(|(o, c)| (o, c, "")),
                closed.nearest(s, need_wp).map(|(o, c)| (o, c, "closed")),
                open.nearest(s, need_wp).map(|(o, c)| (o, c, "open")),
            ]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((o, c, state)) = worst {
                bad[k] = true;
                d.at(
                    l.waypoints.get(k).copied().unwrap_or(l.waypoints_key),
                    format!(
                        "route '{}' waypoint {} is {} {}; keep waypoints at least {need_wp:.2} m (robot radius {robot_radius_m} m + {WAYPOINT_MARGIN_M} m) from walls and doors",
                        r.id,
                        k + 1,
                        fmt_m(c),
                        owner_name(spec, o, state)
                    ),
                );
            }
        }
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
            for (hit, state, when) in checks {
                if let Some((o, c)) = hit {
                    d.at(
                        at,
                        format!(
                            "route '{}' leg from waypoint {} to {} is blocked{when}: it passes {} {} and the robot's disc (radius {robot_radius_m} m) cannot drive through; move the waypoints so the leg keeps {robot_radius_m} m from walls and doors",
                            r.id,
                            k + 1,
                            k2 + 1,
                            fmt_m(c),
                            owner_name(spec, o, state)
                        ),
                    );
                }
            }
        }
    }

    // Walking areas: people walk along the centre line of the longer side.
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
