//! Pictures of what is wrong: an invalid world drawn as far as it could be read, each problem
//! marked in red with its number (the order the messages are printed in) where the file's
//! offending value lies in the world: a wall point, a door's hinge or tip, a waypoint, the home.

use crate::geom::Vec2;
use crate::report::world_render::{MarkOverlay, RenderOptions, render_world_svg};
use crate::spec::Diagnostic;
use crate::spec::world::{WorldLoc, WorldSpec};
use crate::world::World;
use crate::world::load::read_world_lenient;

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

/// The world position of each problem: that of the nearest value at or before it in the file
/// (`None` before every value, e.g. a missing top-level key).
pub fn problem_positions(
    src: &str,
    spec: &WorldSpec,
    loc: &WorldLoc,
    diags: &[Diagnostic],
) -> Vec<Option<Vec2>> {
    let list = anchors(spec, loc);
    diags
        .iter()
        .map(|d| {
            let at = offset_of(src, d.line, d.col);
            let k = list.partition_point(|(o, _)| *o <= at);
            (k > 0).then(|| list[k - 1].1)
        })
        .collect()
}

/// An invalid world's picture: what could be read of it with each problem marked; `None` when
/// nothing could be read (not TOML). `opts` gives the grid, waypoint numbers and doors.
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
    let mut opts = RenderOptions {
        title: Some(format!("{path}: {} problem(s), marked in red", diags.len())),
        ..opts.clone()
    };
    for (k, at) in problem_positions(src, &spec, &loc, &diags)
        .into_iter()
        .enumerate()
    {
        if let Some(at) = at {
            opts.marks.push(MarkOverlay {
                at,
                text: (k + 1).to_string(),
                color: PROBLEM_COLOR.into(),
                class: "problem".into(),
            });
        }
    }
    opts.notes = diags
        .iter()
        .take(MAX_NOTES)
        .enumerate()
        .map(|(k, d)| {
            let text: String = d.message.chars().take(150).collect();
            format!("{}. line {}: {text}", k + 1, d.line)
        })
        .collect();
    (Some(render_world_svg(&world, &opts)), diags)
}
