//! The world file format (TOML, `format_version = 1`): walls, doors, routes, home pose, areas.
//!
//! The reference, with every key, unit, default and limit, is `docs/world-format.md`.
//!
//! These structs describe the file only; `world::World` is the validated model built
//! from them. Units are in every physical key; angles are degrees here and radians in the model.
//!
//! Parsing walks toml's spanned document ([`toml::de::DeTable`]) by hand rather than through
//! serde, so that every problem of a file (unknown keys, missing keys, wrong types, bad
//! numbers) is reported at once with the line and column of the offending value; the geometric
//! checks then run in `crate::world::validate`.
//!
//! ```toml
//! format_version = 1
//! name = "tiny"
//!
//! [robot_home]
//! x_m = 1.0
//! y_m = 1.0
//! heading_deg = 0.0            # degrees in files, radians in code
//!
//! [[walls]]                    # a polyline with a thickness (default 0.1 m)
//! id = "outer"
//! points_m = [[0.0, 0.0], [12.0, 0.0], [12.0, 6.0], [0.0, 6.0]]
//! closed = true
//!
//! [[walls]]                    # a room with a 0.9 m gap from x = 5.0 to 5.9
//! id = "room"
//! points_m = [[5.0, 2.0], [2.0, 2.0], [2.0, 4.0], [10.0, 4.0], [10.0, 2.0], [5.9, 2.0]]
//!
//! [[doors]]
//! id = "d-1"
//! hinge_m = [5.0, 2.0]         # one end of the gap
//! width_m = 0.9                # panel length, hinge to tip
//! closed_heading_deg = 0.0     # hinge -> tip when closed: across the gap
//! open_heading_deg = 90.0      # hinge -> tip when open: into the room
//!
//! [[routes]]                   # a closed loop; the last leg returns to the first waypoint
//! id = "lap"
//! waypoints_m = [[1.0, 1.0], [11.0, 1.0], [11.0, 5.0], [1.0, 5.0]]
//!
//! [[areas]]                    # optional: where people may walk
//! id = "south"
//! min_m = [2.0, 0.5]
//! max_m = [10.0, 1.5]
//! ```

use crate::spec::diag::Diags;
use crate::spec::read::{
    boolean, ctx_of, get, id, missing, number, opt_number, parse_int, point, points,
    read_entries_with, req_number, req_point, req_points, string, table_array, type_name,
    unknown_keys,
};
use serde::{Deserialize, Serialize};
use toml::de::{DeTable, DeValue};

/// A whole world file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Must be 1.
    pub format_version: i64,
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    pub robot_home: HomeSpec,
    #[serde(default)]
    pub walls: Vec<WallSpec>,
    #[serde(default)]
    pub doors: Vec<DoorSpec>,
    #[serde(default)]
    pub routes: Vec<RouteSpec>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub areas: Vec<AreaSpec>,
}

/// The robot's home pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HomeSpec {
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub heading_deg: f64,
}

/// A wall: a polyline of at least two points with a thickness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    pub id: String,
    /// Vertices, metres.
    pub points_m: Vec<[f64; 2]>,
    /// Whether the polyline closes back to its first point. Default false.
    #[serde(default, skip_serializing_if = "is_false")]
    pub closed: bool,
    /// Full thickness, metres, centred on the polyline. Default 0.1.
    #[serde(default = "default_wall_thickness_m")]
    pub thickness_m: f64,
}

/// A hinged door panel. Closed, it spans a gap in a wall; open, it swings into its room.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DoorSpec {
    pub id: String,
    /// Hinge point, metres.
    pub hinge_m: [f64; 2],
    /// Panel length from hinge to tip, metres.
    pub width_m: f64,
    /// Direction hinge→tip when closed, degrees counter-clockwise from +x.
    pub closed_heading_deg: f64,
    /// Direction hinge→tip when open, degrees.
    pub open_heading_deg: f64,
    /// Panel thickness, metres. Default 0.04.
    #[serde(default = "default_door_thickness_m")]
    pub thickness_m: f64,
}

/// A closed loop of waypoints the robot drives, in order; the last leg returns to the first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RouteSpec {
    pub id: String,
    pub waypoints_m: Vec<[f64; 2]>,
}

/// An axis-aligned rectangle where people may walk (back and forth along its longer side).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AreaSpec {
    pub id: String,
    pub min_m: [f64; 2],
    pub max_m: [f64; 2],
}

pub fn default_wall_thickness_m() -> f64 {
    0.1
}

pub fn default_door_thickness_m() -> f64 {
    0.04
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// Known keys per table, for unknown-key checks and "did you mean" hints.
pub const TOP_KEYS: &[&str] = &[
    "format_version",
    "name",
    "description",
    "robot_home",
    "walls",
    "doors",
    "routes",
    "areas",
];
pub const HOME_KEYS: &[&str] = &["x_m", "y_m", "heading_deg"];
pub const WALL_KEYS: &[&str] = &["id", "points_m", "closed", "thickness_m"];
pub const DOOR_KEYS: &[&str] = &[
    "id",
    "hinge_m",
    "width_m",
    "closed_heading_deg",
    "open_heading_deg",
    "thickness_m",
];
pub const ROUTE_KEYS: &[&str] = &["id", "waypoints_m"];
pub const AREA_KEYS: &[&str] = &["id", "min_m", "max_m"];

/// Byte offsets of the values of a world file, so later checks can point at them.
#[derive(Clone, Debug, Default)]
pub struct WorldLoc {
    pub home: HomeLoc,
    pub walls: Vec<WallLoc>,
    pub doors: Vec<DoorLoc>,
    pub routes: Vec<RouteLoc>,
    pub areas: Vec<AreaLoc>,
    /// Where `walls` starts (for whole-file limits).
    pub walls_key: usize,
    /// Whether every entity read cleanly (no missing or mistyped value). The geometric checks
    /// run on the entities that did read; those that did not are in `unread`.
    pub all_read: bool,
    /// The walls, doors, routes and areas that did not read cleanly, in file order, with what
    /// could be read of their geometry: a check that depends on one of them is skipped with a
    /// note rather than reported wrongly or hidden.
    pub unread: Vec<Unread>,
}

/// An entity of the file that did not read cleanly (a missing key, a wrong type, a bad number)
/// or whose values are out of range, with what could be read of its geometry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Unread {
    /// `wall`, `door`, `route` or `area`.
    pub kind: &'static str,
    /// How messages name it: `wall 'room'`, or `wall #1` (its place among the walls, from 0)
    /// when its id did not read.
    pub name: String,
    /// Byte offset of its table.
    pub at: usize,
    /// Its points, metres, as far as they read: a wall's points, a door's hinge (and tip when
    /// its width and closed heading read), a route's waypoints, an area's corners.
    pub points_m: Vec<[f64; 2]>,
}

#[derive(Clone, Debug, Default)]
pub struct HomeLoc {
    /// Whether the home pose read cleanly.
    pub valid: bool,
    pub table: usize,
    pub x: usize,
    pub y: usize,
    pub heading: usize,
}

#[derive(Clone, Debug, Default)]
pub struct WallLoc {
    pub table: usize,
    pub id: usize,
    pub points_key: usize,
    pub points: Vec<usize>,
    pub thickness: usize,
}

#[derive(Clone, Debug, Default)]
pub struct DoorLoc {
    pub table: usize,
    pub id: usize,
    pub hinge: usize,
    pub width: usize,
    pub closed_heading: usize,
    pub open_heading: usize,
    pub thickness: usize,
}

#[derive(Clone, Debug, Default)]
pub struct RouteLoc {
    pub table: usize,
    pub id: usize,
    pub waypoints_key: usize,
    pub waypoints: Vec<usize>,
}

#[derive(Clone, Debug, Default)]
pub struct AreaLoc {
    pub table: usize,
    pub id: usize,
    pub min: usize,
    pub max: usize,
}

/// Most wall segments, door panels and route legs a world may hold. The simulator's time per
/// lap grows faster than linearly with the segment count (20,000 segments take about 10 s a lap
/// on one core), so the limit keeps a lap within seconds.
pub const MAX_SEGMENTS: usize = 10_000;
/// Largest absolute coordinate, metres, of a world or a scenario's walking path: keeps every
/// number the geometry squares or converts far from overflow.
pub const MAX_ABS_COORD_M: f64 = 1_000_000.0;

/// Reads a world file's text into its file structures and the offsets of its values, reporting
/// every syntax, key and type problem to `d`. `None` when the text is not TOML (or the problem
/// list is full); the geometric checks are the world model's (`crate::world::validate`).
pub fn read_world(src: &str, d: &mut Diags) -> Option<(WorldSpec, WorldLoc)> {
    let doc = crate::spec::read::parse_document(src, d)?;
    if is_scenario(doc.get_ref()) {
        d.at(
            0,
            "this is a scenario file, not a world; check it with `placewords scenario check`"
                .into(),
        );
        return None;
    }
    let mut loc = WorldLoc::default();
    let spec = read_top(doc.get_ref(), d, &mut loc)?;
    Some((spec, loc))
}

/// Whether a document is a scenario (it names a world and has runs) rather than a world.
fn is_scenario(top: &DeTable<'_>) -> bool {
    get(top, "runs").is_some() && get(top, "world").is_some()
}

fn read_top(top: &DeTable<'_>, d: &mut Diags, loc: &mut WorldLoc) -> Option<WorldSpec> {
    unknown_keys(top, TOP_KEYS, "the world file", d);
    let format_version = read_format_version(top, d);
    let name = read_name(top, d);
    let description =
        get(top, "description").map(|(_, v)| string(v, "description", "the world file", d));
    let robot_home = read_home(top, d, &mut loc.home);
    let mut ok = format_version.is_some()
        && name.is_some()
        && description.as_ref().is_none_or(Option::is_some)
        && robot_home.is_some();
    let (walls, doors, routes, areas) = read_sections(top, d, loc, &mut ok)?;
    loc.home.valid = robot_home.is_some();
    loc.all_read = ok;
    Some(WorldSpec {
        format_version: format_version.unwrap_or(0),
        name: name.unwrap_or_default(),
        description: description.flatten(),
        robot_home: robot_home.unwrap_or(HomeSpec {
            x_m: 0.0,
            y_m: 0.0,
            heading_deg: 0.0,
        }),
        walls,
        doors,
        routes,
        areas,
    })
}

/// `format_version`: `Some(1)`, or `None` with the problem reported.
fn read_format_version(top: &DeTable<'_>, d: &mut Diags) -> Option<i64> {
    let Some((_, v)) = get(top, "format_version") else {
        missing(
            top,
            "format_version",
            TOP_KEYS,
            0,
            "missing key `format_version`; add `format_version = 1` as the first line".into(),
            d,
        );
        return None;
    };
    let message = match v.get_ref() {
        DeValue::Integer(i) if parse_int(i.as_str(), i.radix()) == Some(1) => return Some(1),
        DeValue::Integer(i) => format!(
            "unsupported format_version {}; this placewords reads `format_version = 1`",
            i.as_str()
        ),
        other => format!(
            "`format_version` must be the integer 1, found {}; write `format_version = 1`",
            type_name(other)
        ),
    };
    d.at(v.span().start, message);
    None
}

/// `name`: a non-empty string, or `None` with the problem reported.
fn read_name(top: &DeTable<'_>, d: &mut Diags) -> Option<String> {
    let Some((_, v)) = get(top, "name") else {
        missing(
            top,
            "name",
            TOP_KEYS,
            0,
            "missing key `name`; add `name = \"my-floor\"` near the top".into(),
            d,
        );
        return None;
    };
    match string(v, "name", "the world file", d) {
        Some(s) if s.trim().is_empty() => {
            d.at(
                v.span().start,
                "`name` is empty; give the world a short name".into(),
            );
            None
        }
        other => other,
    }
}

/// The entity sections as read: walls, doors, routes, areas.
type Sections = (Vec<WallSpec>, Vec<DoorSpec>, Vec<RouteSpec>, Vec<AreaSpec>);

/// The `[[walls]]`, `[[doors]]`, `[[routes]]` and `[[areas]]` sections and their locations;
/// `ok` is cleared on any problem (walls and routes are required).
fn read_sections(
    top: &DeTable<'_>,
    d: &mut Diags,
    loc: &mut WorldLoc,
    ok: &mut bool,
) -> Option<Sections> {
    if let Some((kat, _)) = get(top, "walls") {
        loc.walls_key = kat;
    }
    let wall_tables = table_array(top, "walls", d);
    let door_tables = table_array(top, "doors", d);
    let route_tables = table_array(top, "routes", d);
    let area_tables = table_array(top, "areas", d);
    *ok &= required_section(
        top,
        "walls",
        "at least one `[[walls]]` section with `id` and `points_m`",
        d,
    );
    *ok &= required_section(
        top,
        "routes",
        "a `[[routes]]` section with `id` and `waypoints_m` (a closed loop)",
        d,
    );
    let mut unread = Vec::new();
    let on_fail =
        |kind: &'static str| move |i: usize, at: usize, t: &DeTable<'_>| unread_of(kind, i, at, t);
    let (walls, wall_locs) = read_entries_with(
        wall_tables,
        d,
        ok,
        read_wall,
        |table| WallLoc {
            table,
            ..Default::default()
        },
        &mut unread,
        on_fail("wall"),
    )?;
    let (doors, door_locs) = read_entries_with(
        door_tables,
        d,
        ok,
        read_door,
        |table| DoorLoc {
            table,
            ..Default::default()
        },
        &mut unread,
        on_fail("door"),
    )?;
    let (routes, route_locs) = read_entries_with(
        route_tables,
        d,
        ok,
        read_route,
        |table| RouteLoc {
            table,
            ..Default::default()
        },
        &mut unread,
        on_fail("route"),
    )?;
    let (areas, area_locs) = read_entries_with(
        area_tables,
        d,
        ok,
        read_area,
        |table| AreaLoc {
            table,
            ..Default::default()
        },
        &mut unread,
        on_fail("area"),
    )?;
    loc.unread = unread;
    loc.walls.extend(wall_locs);
    loc.doors.extend(door_locs);
    loc.routes.extend(route_locs);
    loc.areas.extend(area_locs);
    Some((walls, doors, routes, areas))
}

/// What could be read of an entity that did not read cleanly, read again without reporting
/// (its problems are reported already).
fn unread_of(kind: &'static str, i: usize, at: usize, t: &DeTable<'_>) -> Unread {
    let mut quiet = Diags::new("", "");
    let d = &mut quiet;
    let id = get(t, "id").and_then(|(_, v)| string(v, "id", "", d));
    let point_of = |key: &str, d: &mut Diags| get(t, key).and_then(|(_, v)| point(v, key, "", d));
    let number_of = |key: &str, d: &mut Diags| get(t, key).and_then(|(_, v)| number(v, key, "", d));
    let points_m = match kind {
        "wall" | "route" => {
            let key = if kind == "wall" {
                "points_m"
            } else {
                "waypoints_m"
            };
            let mut spans = Vec::new();
            get(t, key)
                .and_then(|(_, v)| points(v, key, "", d, &mut spans))
                .unwrap_or_default()
        }
        "door" => {
            let hinge = point_of("hinge_m", d);
            let tip = match (
                hinge,
                number_of("width_m", d),
                number_of("closed_heading_deg", d),
            ) {
                (Some(h), Some(w), Some(c)) => {
                    let c = c.to_radians();
                    Some([h[0] + w * c.cos(), h[1] + w * c.sin()])
                }
                _ => None,
            };
            hinge.into_iter().chain(tip).collect()
        }
        _ => ["min_m", "max_m"]
            .into_iter()
            .filter_map(|k| point_of(k, d))
            .collect(),
    };
    Unread {
        kind,
        name: ctx_of(kind, &id, i),
        at,
        points_m,
    }
}

/// Whether section `key` is present and not empty; reports it with `add` (what to add) if not.
fn required_section(top: &DeTable<'_>, key: &str, add: &str, d: &mut Diags) -> bool {
    match get(top, key) {
        Some((kat, v)) if matches!(v.get_ref(), DeValue::Array(a) if a.is_empty()) => {
            d.at(kat, format!("`{key}` is empty; add {add}"));
            false
        }
        Some(_) => true,
        None => {
            let message = format!("the world has no {key}; add {add}");
            missing(top, key, TOP_KEYS, 0, message, d);
            false
        }
    }
}

fn read_home(top: &DeTable<'_>, d: &mut Diags, l: &mut HomeLoc) -> Option<HomeSpec> {
    let ctx = "[robot_home]";
    let Some((kat, v)) = get(top, "robot_home") else {
        missing(
            top,
            "robot_home",
            TOP_KEYS,
            0,
            "missing table [robot_home]; add `[robot_home]` with `x_m`, `y_m` and `heading_deg`"
                .into(),
            d,
        );
        return None;
    };
    let DeValue::Table(t) = v.get_ref() else {
        d.at(
            kat,
            format!(
                "`robot_home` must be a table, found {}; write a `[robot_home]` section with `x_m`, `y_m`, `heading_deg`",
                type_name(v.get_ref())
            ),
        );
        return None;
    };
    l.table = v.span().start;
    unknown_keys(t, HOME_KEYS, ctx, d);
    let mut req = |key: &str, slot: &mut usize| -> Option<f64> {
        match get(t, key) {
            None => {
                missing(
                    t,
                    key,
                    HOME_KEYS,
                    l.table,
                    format!("missing key `{key}` in {ctx}; add `{key} = <metres>`"),
                    d,
                );
                None
            }
            Some((_, v)) => {
                *slot = v.span().start;
                number(v, key, ctx, d)
            }
        }
    };
    let (mut xs, mut ys) = (l.table, l.table);
    let x = req("x_m", &mut xs);
    let y = req("y_m", &mut ys);
    l.x = xs;
    l.y = ys;
    l.heading = l.table;
    let heading = match get(t, "heading_deg") {
        None => Some(0.0),
        Some((_, v)) => {
            l.heading = v.span().start;
            number(v, "heading_deg", ctx, d)
        }
    };
    Some(HomeSpec {
        x_m: x?,
        y_m: y?,
        heading_deg: heading?,
    })
}

fn read_wall(
    t: &DeTable<'_>,
    at: usize,
    i: usize,
    d: &mut Diags,
    l: &mut WallLoc,
) -> Option<WallSpec> {
    let (id, id_at) = id(t, WALL_KEYS, at, &format!("wall #{i}"), d);
    l.id = id_at;
    let ctx = ctx_of("wall", &id, i);
    unknown_keys(t, WALL_KEYS, &ctx, d);
    let pts = req_points(
        t,
        WALL_KEYS,
        "points_m",
        &ctx,
        at,
        d,
        &mut l.points_key,
        &mut l.points,
    );
    let closed = match get(t, "closed") {
        None => Some(false),
        Some((_, v)) => boolean(v, "closed", &ctx, d),
    };
    let thickness = opt_number(
        t,
        "thickness_m",
        &ctx,
        default_wall_thickness_m(),
        at,
        d,
        &mut l.thickness,
    );
    Some(WallSpec {
        id: id?,
        points_m: pts?,
        closed: closed?,
        thickness_m: thickness?,
    })
}

fn read_door(
    t: &DeTable<'_>,
    at: usize,
    i: usize,
    d: &mut Diags,
    l: &mut DoorLoc,
) -> Option<DoorSpec> {
    let (id, id_at) = id(t, DOOR_KEYS, at, &format!("door #{i}"), d);
    l.id = id_at;
    let ctx = ctx_of("door", &id, i);
    unknown_keys(t, DOOR_KEYS, &ctx, d);
    let hinge = req_point(t, DOOR_KEYS, "hinge_m", &ctx, at, d, &mut l.hinge);
    let width = req_number(
        t,
        DOOR_KEYS,
        "width_m",
        &ctx,
        at,
        "panel length, metres",
        d,
        &mut l.width,
    );
    let closed = req_number(
        t,
        DOOR_KEYS,
        "closed_heading_deg",
        &ctx,
        at,
        "direction hinge to tip when closed, degrees",
        d,
        &mut l.closed_heading,
    );
    let open = req_number(
        t,
        DOOR_KEYS,
        "open_heading_deg",
        &ctx,
        at,
        "direction hinge to tip when open, degrees",
        d,
        &mut l.open_heading,
    );
    let thickness = opt_number(
        t,
        "thickness_m",
        &ctx,
        default_door_thickness_m(),
        at,
        d,
        &mut l.thickness,
    );
    Some(DoorSpec {
        id: id?,
        hinge_m: hinge?,
        width_m: width?,
        closed_heading_deg: closed?,
        open_heading_deg: open?,
        thickness_m: thickness?,
    })
}

fn read_route(
    t: &DeTable<'_>,
    at: usize,
    i: usize,
    d: &mut Diags,
    l: &mut RouteLoc,
) -> Option<RouteSpec> {
    let (id, id_at) = id(t, ROUTE_KEYS, at, &format!("route #{i}"), d);
    l.id = id_at;
    let ctx = ctx_of("route", &id, i);
    unknown_keys(t, ROUTE_KEYS, &ctx, d);
    let wps = req_points(
        t,
        ROUTE_KEYS,
        "waypoints_m",
        &ctx,
        at,
        d,
        &mut l.waypoints_key,
        &mut l.waypoints,
    );
    Some(RouteSpec {
        id: id?,
        waypoints_m: wps?,
    })
}

fn read_area(
    t: &DeTable<'_>,
    at: usize,
    i: usize,
    d: &mut Diags,
    l: &mut AreaLoc,
) -> Option<AreaSpec> {
    let (id, id_at) = id(t, AREA_KEYS, at, &format!("area #{i}"), d);
    l.id = id_at;
    let ctx = ctx_of("area", &id, i);
    unknown_keys(t, AREA_KEYS, &ctx, d);
    let min = req_point(t, AREA_KEYS, "min_m", &ctx, at, d, &mut l.min);
    let max = req_point(t, AREA_KEYS, "max_m", &ctx, at, d, &mut l.max);
    Some(AreaSpec {
        id: id?,
        min_m: min?,
        max_m: max?,
    })
}
