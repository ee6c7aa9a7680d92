//! Pictures of what is wrong: an invalid world drawn as far as it could be read, each problem
//! marked in red with its number (from 0, the order the messages are printed in) where the
//! file's offending value lies in the world: a wall point, a door's hinge or tip, a waypoint, the
//! home. A wall or door that did not read is drawn dashed as far as it read and its problems
//! marked on it (or listed as off the map when nothing of its place read); a door whose open
//! heading is at fault is drawn open; every message is written in full under the picture.

use crate::geom::Vec2;
use crate::report::world_render::{
    LegendEntry, MarkOverlay, PathOverlay, RenderOptions, render_world_svg,
};
use crate::spec::Diagnostic;
use crate::spec::world::{WorldLoc, WorldSpec};
use crate::world::load::read_world_lenient;
use crate::world::{DoorStates, World};

const PROBLEM_COLOR: &str = "#d62728";
/// Most problem messages written under the picture.
const MAX_NOTES: usize = 15;

/// Byte offset of a 1-based line and character column in `src`.
fn offset_of(src: &str, line: usize, col: usize) -> usize {
    let start: usize = src
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let rest = &src[start.min(src.len())..];
    start
        + rest
            .char_indices()
            .nth(col.saturating_sub(1))
            .map(|(i, _)| i)
            .unwrap_or(rest.len())
}

/// Where each value of the file lies in the world: (byte offset, position).
fn anchors(spec: &WorldSpec, loc: &WorldLoc) -> Vec<(usize, Vec2)> {
    let v = |p: &[f64; 2]| Vec2::new(p[0], p[1]);
    let mut out = Vec::new();
    for (w, l) in spec.walls.iter().zip(&loc.walls) {
        if let Some(first) = w.points_m.first() {
            out.extend([l.table, l.id, l.points_key, l.thickness].map(|o| (o, v(first))));
        }
        out.extend(l.points.iter().zip(&w.points_m).map(|(o, p)| (*o, v(p))));
    }
    for (door, l) in spec.doors.iter().zip(&loc.doors) {
        let hinge = v(&door.hinge_m);
        let tip = |deg: f64| {
            let h = deg.to_radians();
            hinge + Vec2::new(h.cos(), h.sin()) * door.width_m
        };
        let (closed, open) = (tip(door.closed_heading_deg), tip(door.open_heading_deg));
        out.extend([l.table, l.id, l.hinge, l.thickness].map(|o| (o, hinge)));
        out.extend([
            (l.width, closed),
            (l.closed_heading, closed),
            (l.open_heading, open),
        ]);
    }
    for (r, l) in spec.routes.iter().zip(&loc.routes) {
        if let Some(first) = r.waypoints_m.first() {
            out.extend([l.table, l.id, l.waypoints_key].map(|o| (o, v(first))));
        }
        out.extend(
            l.waypoints
                .iter()
                .zip(&r.waypoints_m)
                .map(|(o, p)| (*o, v(p))),
        );
    }
    for (a, l) in spec.areas.iter().zip(&loc.areas) {
        let c = (v(&a.min_m) + v(&a.max_m)) / 2.0;
        out.extend([
            (l.table, c),
            (l.id, c),
            (l.min, v(&a.min_m)),
            (l.max, v(&a.max_m)),
        ]);
    }
    if loc.home.valid {
        let h = Vec2::new(spec.robot_home.x_m, spec.robot_home.y_m);
        out.extend([loc.home.table, loc.home.x, loc.home.y, loc.home.heading].map(|o| (o, h)));
    }
    out.retain(|(o, p)| *o > 0 && p.x.is_finite() && p.y.is_finite());
    out.sort_by_key(|(o, _)| *o);
    out
}

/// Where the entities that did not read lie, as far as their points read: (their table's
/// offset, their first point or `None`, how messages name them).
fn unread_anchors(loc: &WorldLoc) -> Vec<(usize, Option<Vec2>, String)> {
    loc.unread
        .iter()
        .map(|u| {
            let at = u.points_m.first().map(|p| Vec2::new(p[0], p[1]));
            (
                u.at,
                at.filter(|p| p.x.is_finite() && p.y.is_finite()),
                u.name.clone(),
            )
        })
        .collect()
}

/// Where a problem is drawn: on the map (with, when its entity did not read, how messages
/// name that entity), or off it because nothing of its entity's place read.
#[derive(Clone, Debug, PartialEq)]
pub enum ProblemPlace {
    /// On the value the problem points at, or on the first point of its entity.
    At(Vec2, Option<String>),
    /// Its entity (named) did not read far enough to have a place.
    Unplaced(String),
    /// Before every value of the file (e.g. a missing top-level key).
    File,
}

/// The world position of each problem: that of the nearest value at or before it in the file,
/// read or not (a problem in a door that did not read sits on its hinge, not on the entity
/// before it).
pub fn problem_positions(
    src: &str,
    spec: &WorldSpec,
    loc: &WorldLoc,
    diags: &[Diagnostic],
) -> Vec<ProblemPlace> {
    let mut list: Vec<(usize, Option<Vec2>, Option<String>)> = anchors(spec, loc)
        .into_iter()
        .map(|(o, p)| (o, Some(p), None))
        .collect();
    list.extend(
        unread_anchors(loc)
            .into_iter()
            .map(|(o, p, n)| (o, p, Some(n))),
    );
    list.sort_by_key(|(o, ..)| *o);
    diags
        .iter()
        .map(|d| {
            let at = offset_of(src, d.line, d.col);
            let k = list.partition_point(|(o, ..)| *o <= at);
            match k.checked_sub(1).map(|k| &list[k]) {
                None => ProblemPlace::File,
                Some((_, Some(p), name)) => ProblemPlace::At(*p, name.clone()),
                Some((_, None, name)) => ProblemPlace::Unplaced(name.clone().unwrap_or_default()),
            }
        })
        .collect()
}

/// What read of the walls and doors that did not read cleanly, as dashed red lines (a door
/// from its hinge to its closed tip), so the picture does not lose them.
fn unread_paths(loc: &WorldLoc) -> Vec<PathOverlay> {
    loc.unread
        .iter()
        .filter(|u| matches!(u.kind, "wall" | "door") && u.points_m.len() >= 2)
        .map(|u| PathOverlay {
            label: String::new(),
            color: PROBLEM_COLOR.into(),
            points: u.points_m.iter().map(|p| Vec2::new(p[0], p[1])).collect(),
            dashed: true,
            width_px: 2.5,
        })
        .collect()
}

/// The doors a problem is about when open (it points at their `open_heading_deg`): drawn open,
/// so the offending panel shows.
fn doors_to_open(loc: &WorldLoc, src: &str, diags: &[Diagnostic], n: usize) -> DoorStates {
    let at: Vec<usize> = diags
        .iter()
        .map(|d| offset_of(src, d.line, d.col))
        .collect();
    DoorStates {
        open: (0..n)
            .map(|i| {
                loc.doors
                    .get(i)
                    .is_some_and(|l| at.contains(&l.open_heading))
            })
            .collect(),
    }
}

/// An invalid world's picture: what could be read of it with each problem marked, counted from
/// 0 in the order the messages are printed; `None` when nothing could be read (not TOML).
/// `opts` gives the grid, waypoint numbers and doors.
pub fn problems_svg(
    src: &str,
    path: &str,
    opts: &RenderOptions,
) -> (Option<String>, Vec<Diagnostic>) {
    let (read, diags) = read_world_lenient(src, path);
    let Some((spec, loc)) = read else {
        return (None, diags);
    };
    let world = World::from_spec(&spec);
    let open = doors_to_open(&loc, src, &diags, world.doors.len());
    let mut opts = RenderOptions {
        title: Some(format!("{path}: {} problem(s), marked in red", diags.len())),
        doors: DoorStates {
            open: (0..world.doors.len())
                .map(|i| opts.doors.is_open(i) || open.is_open(i))
                .collect(),
        },
        ..opts.clone()
    };
    opts.paths.extend(unread_paths(&loc));
    if opts.paths.iter().any(|p| p.color == PROBLEM_COLOR) {
        opts.legend.push(LegendEntry {
            label: "did not read (as far as it read)".into(),
            color: PROBLEM_COLOR.into(),
            dashed: true,
        });
    }
    let places = problem_positions(src, &spec, &loc, &diags);
    for (k, place) in places.iter().enumerate() {
        if let ProblemPlace::At(at, _) = place {
            opts.marks.push(MarkOverlay {
                at: *at,
                text: k.to_string(),
                color: PROBLEM_COLOR.into(),
                class: "problem".into(),
            });
        }
    }
    opts.notes = diags
        .iter()
        .zip(&places)
        .take(MAX_NOTES)
        .enumerate()
        .map(|(k, (d, place))| note(k, d, place))
        .collect();
    if diags.len() > MAX_NOTES {
        opts.notes.push(format!(
            "... and {} more (see the messages)",
            diags.len() - MAX_NOTES
        ));
    }
    (Some(render_world_svg(&world, &opts)), diags)
}

/// The line under the picture for problem `k`: its number, line, where it is drawn when that
/// is not plain, and its whole message.
fn note(k: usize, d: &Diagnostic, place: &ProblemPlace) -> String {
    let where_ = match place {
        ProblemPlace::At(_, None) => String::new(),
        ProblemPlace::At(_, Some(name)) => {
            format!(", drawn at what read of {name}, which did not read")
        }
        ProblemPlace::Unplaced(name) => format!(", not on the map: {name} did not read"),
        ProblemPlace::File => ", not on the map".into(),
    };
    format!("{k}. line {}{where_}: {}", d.line, d.message)
}
