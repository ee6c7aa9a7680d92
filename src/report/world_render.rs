//! Pictures of a world as SVG: walls, doors (closed solid; open swung, with the swing arc), door
//! ids, routes with direction arrows, the home pose, walking areas, a scale bar, a title and a
//! legend; plus overlays other commands add (trajectories, matched pairs).
//!
//! Every wall segment is one `<line class="wall">` and every door one element with
//! `class="door ..."` and `id="door-<id>"`, so tests and scripts can find them.

use crate::geom::{Segment, Vec2};
use crate::report::svg::{Svg, escape, num};
use crate::world::{DoorStates, World};

/// A polyline drawn over the world, e.g. a trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct PathOverlay {
    /// Legend text; empty for no legend entry.
    pub label: String,
    /// Any SVG colour, e.g. `#d62728`.
    pub color: String,
    pub points: Vec<Vec2>,
    pub dashed: bool,
    /// Stroke width, pixels (1.5 for a plain trajectory; wider to show a status above it).
    pub width_px: f64,
}

/// A single segment drawn over the world, e.g. a matched pair of positions.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentOverlay {
    pub color: String,
    pub a: Vec2,
    pub b: Vec2,
    /// Drawn dashed (so a pair line is not read as a path of the same colour).
    pub dashed: bool,
}

/// An extra legend line (for overlays that carry no label themselves).
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    pub label: String,
    pub color: String,
    pub dashed: bool,
}

/// A raster drawn under the world, e.g. density classes. Cell (x, y) covers the square of side
/// `cell_m` whose bottom-left corner is `origin + (x, y)·cell_m`; cells are row-major from the
/// bottom row.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TileLayer {
    pub origin: Vec2,
    pub cell_m: f64,
    pub width: usize,
    pub height: usize,
    /// Index into `palette` per cell; `None` leaves the cell blank.
    pub cells: Vec<Option<u8>>,
    /// SVG colours.
    pub palette: Vec<String>,
}

/// A thick translucent band along a polyline, e.g. a stretch of a route.
#[derive(Clone, Debug, PartialEq)]
pub struct BandOverlay {
    pub points: Vec<Vec2>,
    pub color: String,
    /// Stroke width, pixels.
    pub width_px: f64,
}

/// A labelled marker: a ring around the spot (translucent, so the path under it stays visible)
/// with its short text beside it, e.g. a problem number or a waypoint. `class` becomes the
/// element's SVG class.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkOverlay {
    pub at: Vec2,
    pub text: String,
    pub color: String,
    pub class: String,
}

/// A legend entry drawn as a filled square (a colour of a [`TileLayer`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Swatch {
    pub label: String,
    pub color: String,
}

/// What to draw and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Door states; doors missing from it are closed. Default: all closed.
    pub doors: DoorStates,
    /// Title; default: the world's name.
    pub title: Option<String>,
    /// Draw the world's routes with direction arrows. Default true.
    pub show_routes: bool,
    /// Draw walking areas. Default true.
    pub show_areas: bool,
    /// Write door ids beside the doors. Default true.
    pub show_door_labels: bool,
    /// Trajectories and other polylines, drawn above the world.
    pub paths: Vec<PathOverlay>,
    /// Single segments (matched pairs), drawn above the paths.
    pub segments: Vec<SegmentOverlay>,
    /// Extra legend entries.
    pub legend: Vec<LegendEntry>,
    /// Pixels per metre; default: fit the world into about 1500 pixels.
    pub px_per_m: Option<f64>,
    /// A raster under the world (density classes). Default none.
    pub tiles: Option<TileLayer>,
    /// Bands along polylines, drawn above the routes. Default none.
    pub bands: Vec<BandOverlay>,
    /// Numbered markers, drawn on top of everything. Default none.
    pub marks: Vec<MarkOverlay>,
    /// Legend entries drawn as filled squares. Default none.
    pub swatches: Vec<Swatch>,
    /// A coordinate grid with labelled metres under the world. Default false.
    pub show_grid: bool,
    /// Number each route waypoint (from 0, as `waypoints_m` and `start_waypoint` index them and messages count them). Default false.
    pub show_waypoints: bool,
    /// Lines of text under the legend (e.g. the numbered problems). Default none.
    pub notes: Vec<String>,
    /// Replaces the subtitle's "N doors (k open)" when the picture spans laps whose doors
    /// differ (e.g. "18 doors, 4 open in some lap"). Default none.
    pub door_summary: Option<String>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            doors: DoorStates::default(),
            title: None,
            show_routes: true,
            show_areas: true,
            show_door_labels: true,
            paths: Vec::new(),
            segments: Vec::new(),
            legend: Vec::new(),
            px_per_m: None,
            tiles: None,
            bands: Vec::new(),
            marks: Vec::new(),
            swatches: Vec::new(),
            show_grid: false,
            show_waypoints: false,
            notes: Vec::new(),
            door_summary: None,
        }
    }
}

const WALL_COLOR: &str = "#222222";
const DOOR_CLOSED_COLOR: &str = "#a0522d";
const DOOR_OPEN_COLOR: &str = "#e67e22";
const ROUTE_COLORS: [&str; 4] = ["#1f77b4", "#2ca02c", "#9467bd", "#17becf"];
const HOME_COLOR: &str = "#d62728";
const AREA_FILL: &str = "#f6e7a6";
const LABEL_COLOR: &str = "#7a3b12";

struct Frame {
    min: Vec2,
    max: Vec2,
    s: f64,
    left: f64,
    top: f64,
}

impl Frame {
    fn p(&self, v: Vec2) -> (f64, f64) {
        (
            self.left + (v.x - self.min.x) * self.s,
            self.top + (self.max.y - v.y) * self.s,
        )
    }
}

fn nice_length(target_m: f64) -> f64 {
    let mut best = 1.0;
    for c in [
        0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0,
    ] {
        if c <= target_m {
            best = c;
        }
    }
    best
}

/// Renders `world` as an SVG document.
pub fn render_world_svg(world: &World, opts: &RenderOptions) -> String {
    // Extent of everything drawn.
    let (mut lo, mut hi) = world.bounds();
    let mut add = |p: Vec2| {
        if p.x.is_finite() && p.y.is_finite() {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    };
    if world.walls.is_empty() && world.doors.is_empty() {
        add(world.home.position());
    }
    for r in &world.routes {
        r.waypoints.iter().for_each(|p| add(*p));
    }
    for a in &world.areas {
        add(a.min);
        add(a.max);
    }
    add(world.home.position());
    for p in &opts.paths {
        p.points.iter().for_each(|q| add(*q));
    }
    for s in &opts.segments {
        add(s.a);
        add(s.b);
    }
    opts.bands
        .iter()
        .flat_map(|b| &b.points)
        .for_each(|p| add(*p));
    opts.marks.iter().for_each(|m| add(m.at));
    let margin_m = 1.0;
    lo -= Vec2::new(margin_m, margin_m);
    hi += Vec2::new(margin_m, margin_m);
    let (w_m, h_m) = ((hi.x - lo.x).max(1.0), (hi.y - lo.y).max(1.0));
    let s = opts
        .px_per_m
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| (1500.0 / w_m.max(h_m * 1.2)).clamp(2.0, 120.0));
    let pad = 20.0;
    let title_h = 56.0;
    let legend_h = 70.0 + 18.0 * opts.notes.len() as f64;
    let map_w = w_m * s;
    let map_h = h_m * s;
    let width = (map_w + 2.0 * pad).max(760.0);
    let legend_x = pad + nice_length(180.0 / s) * s + 40.0;
    let height =
        title_h + map_h + legend_h + legend_extra_h(world, opts, legend_x, width - pad) + pad;
    let f = Frame {
        min: lo,
        max: hi,
        s,
        left: pad + (width - 2.0 * pad - map_w) / 2.0,
        top: title_h,
    };

    let mut svg = Svg::new(width, height);
    let font = (0.55 * s).clamp(9.0, 16.0);

    // Title and subtitle.
    let title = opts.title.clone().unwrap_or_else(|| world.name.clone());
    svg.text(
        (pad, 28.0),
        &title,
        r##"font-size="22" font-weight="bold" fill="#111""##,
    );
    let n_open = (0..world.doors.len())
        .filter(|i| opts.doors.is_open(*i))
        .count();
    let doors = opts
        .door_summary
        .clone()
        .unwrap_or_else(|| format!("{} doors ({n_open} open)", world.doors.len()));
    let sub = format!(
        "{} - {:.0} m x {:.0} m, {doors}, {} route(s)",
        world.name,
        w_m - 2.0 * margin_m,
        h_m - 2.0 * margin_m,
        world.routes.len()
    );
    svg.text((pad, 47.0), &sub, r##"font-size="13" fill="#555""##);

    if opts.show_grid {
        grid(&mut svg, &f, map_w, map_h);
    }
    if let Some(t) = &opts.tiles {
        tiles(&mut svg, &f, t);
    }

    // Walking areas.
    if opts.show_areas && !world.areas.is_empty() {
        svg.open_group(r#"id="areas""#);
        for a in &world.areas {
            let p0 = f.p(Vec2::new(a.min.x, a.max.y));
            svg.rect(
                p0.0,
                p0.1,
                (a.max.x - a.min.x) * s,
                (a.max.y - a.min.y) * s,
                &format!(
                    r#"class="area" id="area-{}" fill="{AREA_FILL}" fill-opacity="0.7""#,
                    escape(&a.id)
                ),
            );
        }
        svg.close_group();
    }

    // Walls: one line per segment.
    svg.open_group(&format!(
        r#"id="walls" stroke="{WALL_COLOR}" stroke-linecap="square""#
    ));
    for w in &world.walls {
        let sw = (w.thickness_m * s).max(2.0);
        for (k, seg) in w.segments().iter().enumerate() {
            svg.line(
                f.p(seg.a),
                f.p(seg.b),
                &format!(
                    r#"class="wall" id="wall-{}-{}" stroke-width="{}""#,
                    escape(&w.id),
                    k,
                    num(sw)
                ),
            );
        }
    }
    svg.close_group();

    // Doors: one element each.
    svg.open_group(r#"id="doors" stroke-linecap="butt""#);
    for (i, d) in world.doors.iter().enumerate() {
        let sw = (d.thickness_m * s * 1.5).max(3.0);
        let closed = d.panel(false);
        if opts.doors.is_open(i) {
            let open = d.panel(true);
            let sweep = crate::geom::wrap_angle(d.open_heading_rad - d.closed_heading_rad);
            // SVG's y axis points down, so a counter-clockwise turn in the world is clockwise on
            // screen: sweep-flag 0 for positive world angles.
            let flag = if sweep > 0.0 { 0 } else { 1 };
            let r = d.width_m * s;
            let (a, b) = (f.p(closed.b), f.p(open.b));
            svg.raw(&format!(
                r#"<g class="door open" id="door-{id}"><path d="M {ax} {ay} A {r} {r} 0 0 {flag} {bx} {by}" fill="none" stroke="{DOOR_OPEN_COLOR}" stroke-width="1.2" stroke-dasharray="4 3"/><line x1="{hx}" y1="{hy}" x2="{bx}" y2="{by}" stroke="{DOOR_OPEN_COLOR}" stroke-width="{sw}"/></g>"#,
                id = escape(&d.id),
                ax = num(a.0),
                ay = num(a.1),
                bx = num(b.0),
                by = num(b.1),
                r = num(r),
                hx = num(f.p(d.hinge).0),
                hy = num(f.p(d.hinge).1),
                sw = num(sw),
            ));
        } else {
            svg.line(
                f.p(closed.a),
                f.p(closed.b),
                &format!(
                    r#"class="door closed" id="door-{}" stroke="{DOOR_CLOSED_COLOR}" stroke-width="{}""#,
                    escape(&d.id),
                    num(sw)
                ),
            );
        }
    }
    svg.close_group();

    // Door ids, inside the room the door opens into.
    if opts.show_door_labels && !world.doors.is_empty() {
        svg.open_group(&format!(
            r#"id="door-labels" font-size="{}" fill="{LABEL_COLOR}" text-anchor="middle""#,
            num(font)
        ));
        for d in &world.doors {
            let c = d.panel(false);
            let mid = (c.a + c.b) / 2.0;
            let into = Vec2::new(d.open_heading_rad.cos(), d.open_heading_rad.sin());
            // Clear of the open panel and its arc: past the panel's length, plus half the
            // label's extent in the direction it is pushed.
            let half_w_m = 0.3 * font * d.id.chars().count() as f64 / s;
            let half_h_m = 0.5 * font / s;
            let at =
                mid + into * (d.width_m + 0.25 + into.x.abs() * half_w_m + into.y.abs() * half_h_m);
            let p = f.p(at);
            svg.text((p.0, p.1 + font * 0.35), &d.id, r#"class="door-label""#);
        }
        svg.close_group();
    }

    // Routes with direction arrows.
    if opts.show_routes {
        svg.open_group(r#"id="routes""#);
        for (ri, r) in world.routes.iter().enumerate() {
            if r.waypoints.len() < 2 {
                continue;
            }
            let color = ROUTE_COLORS[ri % ROUTE_COLORS.len()];
            // Later routes are shifted a few pixels to the left of travel so that routes
            // sharing a corridor stay visible side by side.
            let shifted = offset_loop(&r.waypoints, ri as f64 * 6.0 / s);
            let pts: Vec<(f64, f64)> = shifted.iter().map(|p| f.p(*p)).collect();
            let dash = if ri == 0 {
                ""
            } else {
                r#" stroke-dasharray="10 5""#
            };
            svg.polyline(
                &pts,
                true,
                &format!(
                    r#"class="route" id="route-{}" fill="none" stroke="{color}" stroke-width="2" stroke-opacity="0.8"{dash}"#,
                    escape(&r.id)
                ),
            );
            let n = shifted.len();
            for k in 0..n {
                arrows(
                    &mut svg,
                    &f,
                    Segment::new(shifted[k], shifted[(k + 1) % n]),
                    color,
                );
            }
        }
        svg.close_group();
    }

    if !opts.bands.is_empty() {
        svg.open_group(r#"id="bands" fill="none" stroke-linecap="round" stroke-linejoin="round""#);
        for b in &opts.bands {
            let pts: Vec<(f64, f64)> = b.points.iter().map(|q| f.p(*q)).collect();
            svg.polyline(
                &pts,
                false,
                &format!(
                    r#"class="band" stroke="{}" stroke-width="{}" stroke-opacity="0.75""#,
                    escape(&b.color),
                    num(b.width_px)
                ),
            );
        }
        svg.close_group();
    }

    // Overlays.
    if !opts.paths.is_empty() {
        svg.open_group(r#"id="paths" fill="none""#);
        for p in &opts.paths {
            let pts: Vec<(f64, f64)> = p.points.iter().map(|q| f.p(*q)).collect();
            let dash = if p.dashed {
                r#" stroke-dasharray="6 4""#
            } else {
                ""
            };
            svg.polyline(
                &pts,
                false,
                &format!(
                    r#"class="path" stroke="{}" stroke-width="{}"{dash}"#,
                    escape(&p.color),
                    num(p.width_px)
                ),
            );
        }
        svg.close_group();
    }
    if !opts.segments.is_empty() {
        svg.open_group(r#"id="segments" stroke-width="1" stroke-opacity="0.7""#);
        for sg in &opts.segments {
            let dash = if sg.dashed {
                r#" stroke-dasharray="5 3""#
            } else {
                ""
            };
            svg.line(
                f.p(sg.a),
                f.p(sg.b),
                &format!(r#"class="pair" stroke="{}"{dash}"#, escape(&sg.color)),
            );
        }
        svg.close_group();
    }

    // Home pose.
    {
        let h = world.home;
        let c = f.p(h.position());
        let r = (0.25 * s).max(5.0);
        let tip = f.p(h.position() + Vec2::new(h.theta.cos(), h.theta.sin()) * (0.25 + 0.6));
        svg.open_group(r#"id="home" class="home""#);
        svg.circle(
            c,
            r,
            &format!(
                r#"fill="{HOME_COLOR}" fill-opacity="0.25" stroke="{HOME_COLOR}" stroke-width="2""#
            ),
        );
        svg.line(
            c,
            tip,
            &format!(r#"stroke="{HOME_COLOR}" stroke-width="2.5""#),
        );
        svg.close_group();
    }

    if opts.show_waypoints {
        waypoint_marks(&mut svg, &f, world);
    }
    marks(&mut svg, &f, &opts.marks);

    // Scale bar, bottom left.
    let y0 = title_h + map_h + 22.0;
    let bar_m = nice_length(180.0 / s);
    let x0 = pad;
    svg.open_group(r#"id="scale-bar""#);
    svg.line(
        (x0, y0),
        (x0 + bar_m * s, y0),
        r##"stroke="#111" stroke-width="3""##,
    );
    svg.line(
        (x0, y0 - 5.0),
        (x0, y0 + 5.0),
        r##"stroke="#111" stroke-width="2""##,
    );
    svg.line(
        (x0 + bar_m * s, y0 - 5.0),
        (x0 + bar_m * s, y0 + 5.0),
        r##"stroke="#111" stroke-width="2""##,
    );
    let label = if bar_m >= 1.0 {
        format!("{bar_m:.0} m")
    } else {
        format!("{bar_m} m")
    };
    svg.text(
        (x0 + bar_m * s / 2.0, y0 + 20.0),
        &label,
        r##"font-size="13" text-anchor="middle" fill="#111""##,
    );
    svg.close_group();

    // Legend, after the scale bar.
    let legend_end = legend(
        &mut svg,
        world,
        opts,
        x0 + bar_m * s + 40.0,
        y0,
        width - pad,
    );
    notes(&mut svg, &opts.notes, pad, legend_end.max(y0 + 24.0) + 22.0);
    svg.finish()
}

/// A closed loop moved `d` metres to the left of travel (mitred at the corners).
fn offset_loop(pts: &[Vec2], d: f64) -> Vec<Vec2> {
    let n = pts.len();
    if d == 0.0 || n < 2 {
        return pts.to_vec();
    }
    let left = |a: Vec2, b: Vec2| -> Vec2 {
        let t = b - a;
        let l = t.norm();
        if l == 0.0 {
            Vec2::zeros()
        } else {
            Vec2::new(-t.y, t.x) / l
        }
    };
    (0..n)
        .map(|i| {
            let n_in = left(pts[(i + n - 1) % n], pts[i]);
            let n_out = left(pts[i], pts[(i + 1) % n]);
            let m = n_in + n_out;
            let c = m.norm_squared();
            if c < 1e-9 {
                pts[i] + n_out * d
            } else {
                // Mitre: the offset along the bisector that keeps distance d from both legs.
                pts[i] + m * (2.0 * d / c)
            }
        })
        .collect()
}

/// Arrowheads along a leg: one every 8 m, at least one at the middle.
fn arrows(svg: &mut Svg, f: &Frame, leg: Segment, color: &str) {
    let len = leg.length();
    if len <= 0.0 {
        return;
    }
    let dir = (leg.b - leg.a) / len;
    let n = ((len / 8.0).floor() as usize).clamp(1, 1000);
    let size_px = 9.0;
    for k in 0..n {
        let t = (k as f64 + 0.5) / n as f64 * len;
        let c = f.p(leg.a + dir * t);
        // Screen direction (y flipped).
        let (dx, dy) = (dir.x, -dir.y);
        let (nx, ny) = (-dy, dx);
        let tip = (c.0 + dx * size_px, c.1 + dy * size_px);
        let l = (
            c.0 - dx * size_px * 0.6 + nx * size_px * 0.6,
            c.1 - dy * size_px * 0.6 + ny * size_px * 0.6,
        );
        let r = (
            c.0 - dx * size_px * 0.6 - nx * size_px * 0.6,
            c.1 - dy * size_px * 0.6 - ny * size_px * 0.6,
        );
        svg.polyline(
            &[tip, l, r],
            true,
            &format!(r#"class="arrow" fill="{color}" stroke="none""#),
        );
    }
}

enum Sym {
    Line(String, f64, bool),
    Arc,
    Home,
    Area,
    Swatch(String),
}

fn legend_entries(world: &World, opts: &RenderOptions) -> Vec<(Sym, String)> {
    let mut entries: Vec<(Sym, String)> = vec![
        (Sym::Line(WALL_COLOR.into(), 4.0, false), "wall".into()),
        (
            Sym::Line(DOOR_CLOSED_COLOR.into(), 4.0, false),
            "door, closed".into(),
        ),
        (Sym::Arc, "door, open (swing arc)".into()),
    ];
    if opts.show_routes {
        for (ri, r) in world.routes.iter().enumerate() {
            entries.push((
                Sym::Line(ROUTE_COLORS[ri % ROUTE_COLORS.len()].into(), 2.0, ri > 0),
                format!("route '{}' ({:.0} m)", r.id, r.length_m()),
            ));
        }
    }
    entries.push((Sym::Home, "robot home".into()));
    if opts.show_areas && !world.areas.is_empty() {
        entries.push((Sym::Area, "walking area".into()));
    }
    for p in &opts.paths {
        if !p.label.is_empty() {
            entries.push((Sym::Line(p.color.clone(), 2.0, p.dashed), p.label.clone()));
        }
    }
    for l in &opts.legend {
        entries.push((Sym::Line(l.color.clone(), 2.0, l.dashed), l.label.clone()));
    }
    for sw in &opts.swatches {
        entries.push((Sym::Swatch(sw.color.clone()), sw.label.clone()));
    }
    entries
}

/// Where each legend entry goes: (x, y) per entry, wrapping at `x_end`.
fn legend_layout(entries: &[(Sym, String)], x_start: f64, y: f64, x_end: f64) -> Vec<(f64, f64)> {
    let (mut x, mut y) = (x_start, y);
    entries
        .iter()
        .map(|(_, label)| {
            let w = 34.0 + 7.2 * label.chars().count() as f64 + 18.0;
            if x + w > x_end && x > x_start {
                x = x_start;
                y += 22.0;
            }
            let at = (x, y);
            x += w;
            at
        })
        .collect()
}

/// Extra height the legend needs beyond its first two rows, pixels.
fn legend_extra_h(world: &World, opts: &RenderOptions, x_start: f64, x_end: f64) -> f64 {
    let layout = legend_layout(&legend_entries(world, opts), x_start, 0.0, x_end);
    let last = layout.last().map(|p| p.1).unwrap_or(0.0);
    (last - 22.0).max(0.0)
}

/// Draws the legend; returns the y of its last row.
fn legend(
    svg: &mut Svg,
    world: &World,
    opts: &RenderOptions,
    x_start: f64,
    y: f64,
    x_end: f64,
) -> f64 {
    let entries = legend_entries(world, opts);
    let layout = legend_layout(&entries, x_start, y, x_end);
    svg.open_group(r##"id="legend" font-size="13" fill="#111""##);
    for ((sym, label), &(x, y)) in entries.iter().zip(&layout) {
        legend_symbol(svg, sym, x, y);
        svg.text((x + 34.0, y + 4.5), label, "");
    }
    svg.close_group();
    layout.last().map(|p| p.1).unwrap_or(y)
}

fn legend_symbol(svg: &mut Svg, sym: &Sym, x: f64, y: f64) {
    match sym {
        Sym::Line(c, sw, dashed) => {
            let dash = if *dashed {
                r#" stroke-dasharray="6 4""#
            } else {
                ""
            };
            svg.line(
                (x, y),
                (x + 26.0, y),
                &format!(r#"stroke="{}" stroke-width="{sw}"{dash}"#, escape(c)),
            );
        }
        Sym::Arc => {
            svg.path(
                &format!(
                    "M {} {} A 20 20 0 0 0 {} {}",
                    num(x + 20.0),
                    num(y + 6.0),
                    num(x),
                    num(y - 14.0)
                ),
                &format!(
                    r#"fill="none" stroke="{DOOR_OPEN_COLOR}" stroke-width="1.2" stroke-dasharray="4 3""#
                ),
            );
            svg.line(
                (x, y + 6.0),
                (x, y - 14.0),
                &format!(r#"stroke="{DOOR_OPEN_COLOR}" stroke-width="4""#),
            );
        }
        Sym::Home => {
            svg.circle(
                (x + 8.0, y),
                6.0,
                &format!(r#"fill="{HOME_COLOR}" fill-opacity="0.25" stroke="{HOME_COLOR}" stroke-width="2""#),
            );
            svg.line(
                (x + 8.0, y),
                (x + 22.0, y),
                &format!(r#"stroke="{HOME_COLOR}" stroke-width="2.5""#),
            );
        }
        Sym::Area => {
            svg.rect(
                x,
                y - 6.0,
                26.0,
                12.0,
                &format!(r#"fill="{AREA_FILL}" fill-opacity="0.7""#),
            );
        }
        Sym::Swatch(c) => {
            svg.rect(
                x + 4.0,
                y - 8.0,
                18.0,
                16.0,
                &format!(r##"fill="{}" stroke="#555" stroke-width="0.5""##, escape(c)),
            );
        }
    }
}

/// A light coordinate grid every `nice` metres, labelled along the bottom and left edges.
fn grid(svg: &mut Svg, f: &Frame, map_w: f64, map_h: f64) {
    let step = nice_length(60.0 / f.s).max(0.5);
    svg.open_group(r##"id="grid" stroke="#d8d8d8" stroke-width="0.6" font-size="10" fill="#888""##);
    let first = |lo: f64| (lo / step).ceil() * step;
    // "0", never "-0", and no float residue ("0.30000000000000004") in the labels.
    let label = |v: f64| format!("{}", (v / step).round() * step + 0.0);
    let mut x = first(f.min.x);
    while x <= f.max.x {
        let (px, _) = f.p(Vec2::new(x, f.min.y));
        svg.line((px, f.top), (px, f.top + map_h), "");
        svg.text(
            (px + 2.0, f.top + map_h - 3.0),
            &label(x),
            r#"stroke="none""#,
        );
        x += step;
    }
    let mut y = first(f.min.y);
    while y <= f.max.y {
        let (_, py) = f.p(Vec2::new(f.min.x, y));
        svg.line((f.left, py), (f.left + map_w, py), "");
        svg.text((f.left + 2.0, py - 2.0), &label(y), r#"stroke="none""#);
        y += step;
    }
    svg.close_group();
}

/// The tiles, one rectangle per run of equal cells along a row.
fn tiles(svg: &mut Svg, f: &Frame, t: &TileLayer) {
    svg.open_group(r#"id="tiles" shape-rendering="crispEdges""#);
    let side = t.cell_m * f.s;
    for y in 0..t.height {
        let row = &t.cells[y * t.width..(y + 1) * t.width];
        let mut x = 0;
        while x < t.width {
            let Some(c) = row[x] else {
                x += 1;
                continue;
            };
            let run = row[x..].iter().take_while(|v| **v == Some(c)).count();
            let top_left = t.origin + Vec2::new(x as f64, (y + 1) as f64) * t.cell_m;
            let (px, py) = f.p(top_left);
            let color = t
                .palette
                .get(c as usize)
                .map(String::as_str)
                .unwrap_or("#ccc");
            svg.rect(
                px,
                py,
                side * run as f64 + 0.3,
                side + 0.3,
                &format!(r#"fill="{}""#, escape(color)),
            );
            x += run;
        }
    }
    svg.close_group();
}

/// A numbered marker per waypoint of every route, offset a little off the route.
fn waypoint_marks(svg: &mut Svg, f: &Frame, world: &World) {
    let list: Vec<MarkOverlay> = world
        .routes
        .iter()
        .enumerate()
        .flat_map(|(ri, r)| {
            let color = ROUTE_COLORS[ri % ROUTE_COLORS.len()];
            r.waypoints
                .iter()
                .enumerate()
                .map(move |(k, p)| MarkOverlay {
                    at: *p,
                    text: format!("{k}"),
                    color: color.to_string(),
                    class: "waypoint".into(),
                })
        })
        .collect();
    marks(svg, f, &list);
}

fn marks(svg: &mut Svg, f: &Frame, list: &[MarkOverlay]) {
    if list.is_empty() {
        return;
    }
    // A ring with a faint fill keeps the path under the spot visible; the text sits beside the
    // ring on a white halo, so it reads over walls and paths alike.
    svg.open_group(r#"id="marks" font-size="12" font-weight="bold""#);
    for m in list {
        let c = f.p(m.at);
        let r = 7.0;
        svg.raw(&format!(
            r##"<g class="{class}"><circle cx="{x}" cy="{y}" r="{r}" fill="{color}" fill-opacity="0.18" stroke="{color}" stroke-width="2"/><text x="{tx}" y="{ty}" fill="{color}" stroke="white" stroke-width="3" paint-order="stroke">{text}</text></g>"##,
            class = escape(&m.class),
            x = num(c.0),
            y = num(c.1),
            tx = num(c.0 + r + 3.0),
            ty = num(c.1 - r + 2.0),
            r = num(r),
            color = escape(&m.color),
            text = escape(&m.text),
        ));
    }
    svg.close_group();
}

fn notes(svg: &mut Svg, lines: &[String], x: f64, y: f64) {
    if lines.is_empty() {
        return;
    }
    svg.open_group(r##"id="notes" font-size="13" fill="#111""##);
    for (k, line) in lines.iter().enumerate() {
        svg.text((x, y + 18.0 * k as f64), line, "");
    }
    svg.close_group();
}
