//! Pictures of a world as SVG: walls, doors (closed solid; open swung, with the swing arc), door
//! ids, routes with direction arrows, the home pose, walking areas, a scale bar, a title and a
//! legend; plus overlays other commands add (trajectories, matched pairs).
//!
//! Every wall segment is one `<line class="wall">` and every door one element with
//! `class="door ..."` and `id="door-<id>"`, so tests and scripts can find them.

use crate::geom::{Segment, Vec2};
use crate::report::svg::{Svg, escape, num};
use crate::world::{Door, DoorStates, World};

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

/// Where everything goes: the world frame and the picture's size.
struct Layout {
    f: Frame,
    width: f64,
    map_h: f64,
    /// The world's extent without the margin, metres.
    size_m: (f64, f64),
    /// The notes, wrapped to the picture's width.
    notes: Vec<String>,
}

const PAD_PX: f64 = 20.0;
const TITLE_H_PX: f64 = 56.0;
const MARGIN_M: f64 = 1.0;
/// Width of a character of the 13-pixel notes, pixels (for wrapping).
const NOTE_CHAR_PX: f64 = 7.0;

/// Renders `world` as an SVG document.
pub fn render_world_svg(world: &World, opts: &RenderOptions) -> String {
    let l = layout(world, opts);
    let f = &l.f;
    let mut svg = Svg::new(
        l.width,
        f.top + l.map_h + legend_height(world, opts, &l) + PAD_PX,
    );
    header(&mut svg, world, opts, &l);
    if opts.show_grid {
        grid(&mut svg, f, l.f.s * (f.max.x - f.min.x), l.map_h);
    }
    if let Some(t) = &opts.tiles {
        tiles(&mut svg, f, t);
    }
    if opts.show_areas {
        areas(&mut svg, f, world);
    }
    walls(&mut svg, f, world);
    doors(&mut svg, f, world, &opts.doors);
    if opts.show_door_labels {
        door_labels(&mut svg, f, world);
    }
    if opts.show_routes {
        // Over a raster the routes get a white casing, so no colour of it hides them.
        routes(&mut svg, f, world, opts.tiles.is_some());
    }
    bands(&mut svg, f, &opts.bands);
    paths(&mut svg, f, &opts.paths);
    segments(&mut svg, f, &opts.segments);
    home(&mut svg, f, world);
    // Waypoint numbers and the other marks together, so marks on one spot fan out.
    let mut all = if opts.show_waypoints {
        waypoint_marks(world)
    } else {
        Vec::new()
    };
    all.extend(opts.marks.iter().cloned());
    marks(&mut svg, f, &all);
    let y0 = f.top + l.map_h + 22.0;
    let bar_end = scale_bar(&mut svg, f.s, PAD_PX, y0);
    let legend_end = legend(&mut svg, world, opts, bar_end + 40.0, y0, l.width - PAD_PX);
    notes(&mut svg, &l.notes, PAD_PX, legend_end.max(y0 + 24.0) + 22.0);
    svg.finish()
}

/// The extent of everything drawn, metres.
fn extent(world: &World, opts: &RenderOptions) -> (Vec2, Vec2) {
    let (mut lo, mut hi) = world.bounds();
    let mut add = |p: Vec2| {
        if p.x.is_finite() && p.y.is_finite() {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    };
    let routes = world
        .routes
        .iter()
        .flat_map(|r| r.waypoints.iter().copied());
    let areas = world.areas.iter().flat_map(|a| [a.min, a.max]);
    let paths = opts.paths.iter().flat_map(|p| p.points.iter().copied());
    let segments = opts.segments.iter().flat_map(|s| [s.a, s.b]);
    let bands = opts.bands.iter().flat_map(|b| b.points.iter().copied());
    let marks = opts.marks.iter().map(|m| m.at);
    routes
        .chain(areas)
        .chain(paths)
        .chain(segments)
        .chain(bands)
        .chain(marks)
        .chain([world.home.position()])
        .for_each(&mut add);
    (lo, hi)
}

/// The frame and picture size for `world` with `opts`.
fn layout(world: &World, opts: &RenderOptions) -> Layout {
    let (lo, hi) = extent(world, opts);
    let (lo, hi) = (lo - Vec2::repeat(MARGIN_M), hi + Vec2::repeat(MARGIN_M));
    let (w_m, h_m) = ((hi.x - lo.x).max(1.0), (hi.y - lo.y).max(1.0));
    let s = opts
        .px_per_m
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| (1500.0 / w_m.max(h_m * 1.2)).clamp(2.0, 120.0));
    let (map_w, map_h) = (w_m * s, h_m * s);
    let width = (map_w + 2.0 * PAD_PX).max(760.0);
    let chars = ((width - 2.0 * PAD_PX) / NOTE_CHAR_PX).max(40.0) as usize;
    Layout {
        f: Frame {
            min: lo,
            max: hi,
            s,
            left: PAD_PX + (width - 2.0 * PAD_PX - map_w) / 2.0,
            top: TITLE_H_PX,
        },
        width,
        map_h,
        size_m: (w_m - 2.0 * MARGIN_M, h_m - 2.0 * MARGIN_M),
        notes: wrap_notes(&opts.notes, chars),
    }
}

/// Each note wrapped to `chars` characters, its continuation lines indented, so no text is cut.
fn wrap_notes(notes: &[String], chars: usize) -> Vec<String> {
    let wrap = textwrap::Options::new(chars).subsequent_indent("      ");
    notes
        .iter()
        .flat_map(|n| textwrap::wrap(n, &wrap).into_iter().map(|l| l.into_owned()))
        .collect()
}

/// Height below the map: scale bar, legend rows and notes, pixels.
fn legend_height(world: &World, opts: &RenderOptions, l: &Layout) -> f64 {
    let legend_x = PAD_PX + nice_length(180.0 / l.f.s) * l.f.s + 40.0;
    70.0 + 18.0 * l.notes.len() as f64 + legend_extra_h(world, opts, legend_x, l.width - PAD_PX)
}

/// Title and subtitle (name, size, doors, routes).
fn header(svg: &mut Svg, world: &World, opts: &RenderOptions, l: &Layout) {
    let title = opts.title.clone().unwrap_or_else(|| world.name.clone());
    svg.text(
        (PAD_PX, 28.0),
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
        l.size_m.0,
        l.size_m.1,
        world.routes.len()
    );
    svg.text((PAD_PX, 47.0), &sub, r##"font-size="13" fill="#555""##);
}

/// Walking areas, filled.
fn areas(svg: &mut Svg, f: &Frame, world: &World) {
    if world.areas.is_empty() {
        return;
    }
    svg.open_group(r#"id="areas""#);
    for a in &world.areas {
        let p0 = f.p(Vec2::new(a.min.x, a.max.y));
        svg.rect(
            p0.0,
            p0.1,
            (a.max.x - a.min.x) * f.s,
            (a.max.y - a.min.y) * f.s,
            &format!(
                r#"class="area" id="area-{}" fill="{AREA_FILL}" fill-opacity="0.7""#,
                escape(&a.id)
            ),
        );
    }
    svg.close_group();
}

/// Walls: one line per segment.
fn walls(svg: &mut Svg, f: &Frame, world: &World) {
    svg.open_group(&format!(
        r#"id="walls" stroke="{WALL_COLOR}" stroke-linecap="square""#
    ));
    for w in &world.walls {
        let sw = (w.thickness_m * f.s).max(2.0);
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
}

/// Doors: one element each, closed as a line, open as the swung panel with its arc.
fn doors(svg: &mut Svg, f: &Frame, world: &World, states: &DoorStates) {
    svg.open_group(r#"id="doors" stroke-linecap="butt""#);
    for (i, d) in world.doors.iter().enumerate() {
        let sw = (d.thickness_m * f.s * 1.5).max(3.0);
        if states.is_open(i) {
            open_door(svg, f, d, sw);
        } else {
            let closed = d.panel(false);
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
}

/// An open door: its panel and the arc its tip swept from closed.
fn open_door(svg: &mut Svg, f: &Frame, d: &Door, sw: f64) {
    let (closed, open) = (d.panel(false), d.panel(true));
    let sweep = crate::geom::wrap_angle(d.open_heading_rad - d.closed_heading_rad);
    // SVG's y axis points down, so a counter-clockwise turn in the world is clockwise on
    // screen: sweep-flag 0 for positive world angles.
    let flag = if sweep > 0.0 { 0 } else { 1 };
    let r = d.width_m * f.s;
    let (a, b, h) = (f.p(closed.b), f.p(open.b), f.p(d.hinge));
    svg.raw(&format!(
        r#"<g class="door open" id="door-{id}"><path d="M {ax} {ay} A {r} {r} 0 0 {flag} {bx} {by}" fill="none" stroke="{DOOR_OPEN_COLOR}" stroke-width="1.2" stroke-dasharray="4 3"/><line x1="{hx}" y1="{hy}" x2="{bx}" y2="{by}" stroke="{DOOR_OPEN_COLOR}" stroke-width="{sw}"/></g>"#,
        id = escape(&d.id),
        ax = num(a.0),
        ay = num(a.1),
        bx = num(b.0),
        by = num(b.1),
        r = num(r),
        hx = num(h.0),
        hy = num(h.1),
        sw = num(sw),
    ));
}

/// Door ids, inside the room the door opens into.
fn door_labels(svg: &mut Svg, f: &Frame, world: &World) {
    if world.doors.is_empty() {
        return;
    }
    let font = (0.55 * f.s).clamp(9.0, 16.0);
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
        let half_w_m = 0.3 * font * d.id.chars().count() as f64 / f.s;
        let half_h_m = 0.5 * font / f.s;
        let at =
            mid + into * (d.width_m + 0.25 + into.x.abs() * half_w_m + into.y.abs() * half_h_m);
        let p = f.p(at);
        svg.text((p.0, p.1 + font * 0.35), &d.id, r#"class="door-label""#);
    }
    svg.close_group();
}

/// Routes with direction arrows; `cased`: each on a white casing (over a raster).
fn routes(svg: &mut Svg, f: &Frame, world: &World, cased: bool) {
    svg.open_group(r#"id="routes""#);
    for (ri, r) in world.routes.iter().enumerate() {
        if r.waypoints.len() < 2 {
            continue;
        }
        let color = ROUTE_COLORS[ri % ROUTE_COLORS.len()];
        // Later routes are shifted a few pixels to the left of travel so that routes
        // sharing a corridor stay visible side by side.
        let shifted = offset_loop(&r.waypoints, ri as f64 * 6.0 / f.s);
        let pts: Vec<(f64, f64)> = shifted.iter().map(|p| f.p(*p)).collect();
        if cased {
            svg.polyline(
                &pts,
                true,
                r#"class="route-casing" fill="none" stroke="white" stroke-width="6" stroke-linejoin="round""#,
            );
        }
        let dash = if ri == 0 {
            ""
        } else {
            r#" stroke-dasharray="10 5""#
        };
        let (width, opacity) = if cased { ("2.5", "1") } else { ("2", "0.8") };
        svg.polyline(
            &pts,
            true,
            &format!(
                r#"class="route" id="route-{}" fill="none" stroke="{color}" stroke-width="{width}" stroke-opacity="{opacity}"{dash}"#,
                escape(&r.id)
            ),
        );
        let n = shifted.len();
        for k in 0..n {
            arrows(
                svg,
                f,
                Segment::new(shifted[k], shifted[(k + 1) % n]),
                color,
            );
        }
    }
    svg.close_group();
}

/// Thick translucent bands along polylines.
fn bands(svg: &mut Svg, f: &Frame, list: &[BandOverlay]) {
    if list.is_empty() {
        return;
    }
    svg.open_group(r#"id="bands" fill="none" stroke-linecap="round" stroke-linejoin="round""#);
    for b in list {
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

/// Trajectories and other polylines.
fn paths(svg: &mut Svg, f: &Frame, list: &[PathOverlay]) {
    if list.is_empty() {
        return;
    }
    svg.open_group(r#"id="paths" fill="none""#);
    for p in list {
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

/// Single segments (matched pairs).
fn segments(svg: &mut Svg, f: &Frame, list: &[SegmentOverlay]) {
    if list.is_empty() {
        return;
    }
    svg.open_group(r#"id="segments" stroke-width="1" stroke-opacity="0.7""#);
    for sg in list {
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

/// The home pose: the robot's disc and its heading.
fn home(svg: &mut Svg, f: &Frame, world: &World) {
    let h = world.home;
    let c = f.p(h.position());
    let r = (0.25 * f.s).max(5.0);
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

/// A scale bar at (x0, y0) for `s` pixels per metre; returns its right end.
fn scale_bar(svg: &mut Svg, s: f64, x0: f64, y0: f64) -> f64 {
    let bar_m = nice_length(180.0 / s);
    let x1 = x0 + bar_m * s;
    svg.open_group(r#"id="scale-bar""#);
    svg.line((x0, y0), (x1, y0), r##"stroke="#111" stroke-width="3""##);
    for x in [x0, x1] {
        svg.line(
            (x, y0 - 5.0),
            (x, y0 + 5.0),
            r##"stroke="#111" stroke-width="2""##,
        );
    }
    let label = if bar_m >= 1.0 {
        format!("{bar_m:.0} m")
    } else {
        format!("{bar_m} m")
    };
    svg.text(
        ((x0 + x1) / 2.0, y0 + 20.0),
        &label,
        r##"font-size="13" text-anchor="middle" fill="#111""##,
    );
    svg.close_group();
    x1
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
    overlay_entries(opts, &mut entries);
    entries
}

/// The legend entries the caller drew over the world: labelled paths, extra lines, swatches.
fn overlay_entries(opts: &RenderOptions, entries: &mut Vec<(Sym, String)>) {
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
    for y in 0..t.height {
        tile_row(svg, f, t, y);
    }
    svg.close_group();
}

/// Row `y` of the tiles, a rectangle per run of equal cells.
fn tile_row(svg: &mut Svg, f: &Frame, t: &TileLayer, y: usize) {
    let side = t.cell_m * f.s;
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

/// A numbered marker per waypoint of every route.
fn waypoint_marks(world: &World) -> Vec<MarkOverlay> {
    world
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
        .collect()
}

/// Marks closer than this on screen share a spot, pixels: their labels fan out around it.
const SAME_SPOT_PX: f64 = 10.0;

/// For each mark, where its label goes relative to its spot (pixels) and whether it was fanned
/// out (then a leader line joins it to the spot). A lone mark's label sits up and right of its
/// ring; marks that share a spot spread theirs evenly around it, in list order.
fn label_offsets(spots: &[(f64, f64)]) -> Vec<((f64, f64), bool)> {
    let near = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1) < SAME_SPOT_PX;
    (0..spots.len())
        .map(|i| {
            let group: Vec<usize> = (0..spots.len())
                .filter(|&j| near(spots[i], spots[j]))
                .collect();
            if group.len() == 1 {
                return ((10.0, -9.0), false);
            }
            let k = group.iter().position(|&j| j == i).unwrap_or(0) as f64;
            let n = group.len() as f64;
            let angle = std::f64::consts::FRAC_PI_4 + k * std::f64::consts::TAU / n;
            let r = 16.0 + 2.0 * n;
            ((r * angle.cos(), -r * angle.sin()), true)
        })
        .collect()
}

/// The line from the ring (radius `r`) around spot `c` towards its label fanned out by `d`.
fn leader_line(color: &str, c: (f64, f64), d: (f64, f64), r: f64) -> String {
    let (dx, dy) = d;
    let len = dx.hypot(dy);
    format!(
        r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{color}" stroke-width="1"/>"#,
        num(c.0 + dx * r / len),
        num(c.1 + dy * r / len),
        num(c.0 + dx * 0.8),
        num(c.1 + dy * 0.8),
        color = escape(color),
    )
}

fn marks(svg: &mut Svg, f: &Frame, list: &[MarkOverlay]) {
    if list.is_empty() {
        return;
    }
    // A ring with a faint fill keeps the path under the spot visible; the text sits beside the
    // ring on a white halo, so it reads over walls and paths alike.
    let spots: Vec<(f64, f64)> = list.iter().map(|m| f.p(m.at)).collect();
    svg.open_group(r#"id="marks" font-size="12" font-weight="bold""#);
    for ((m, c), ((dx, dy), fanned)) in list.iter().zip(&spots).zip(label_offsets(&spots)) {
        let r = 7.0;
        let leader = if fanned {
            leader_line(&m.color, *c, (dx, dy), r)
        } else {
            String::new()
        };
        let anchor = if dx < 0.0 { "end" } else { "start" };
        svg.raw(&format!(
            r##"<g class="{class}"><circle cx="{x}" cy="{y}" r="{r}" fill="{color}" fill-opacity="0.18" stroke="{color}" stroke-width="2"/>{leader}<text x="{tx}" y="{ty}" text-anchor="{anchor}" fill="{color}" stroke="white" stroke-width="3" paint-order="stroke">{text}</text></g>"##,
            class = escape(&m.class),
            x = num(c.0),
            y = num(c.1),
            tx = num(c.0 + dx),
            ty = num(c.1 + dy + 4.0),
            r = num(r),
            color = escape(&m.color),
            text = escape(&m.text),
        ));
    }
    svg.close_group();
}

/// Lines of text under the legend (already wrapped to the picture's width).
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
