//! A drivable closed route through a map's free space, for `world import` (a line map has
//! walls but no route):
//!
//! 1. rasterise at [`RouteOptions::resolution_m`]: a cell is free when its centre is at least
//!    robot radius + margin (0.25 + 0.10 m) from every wall surface (exact point–segment
//!    distances; `raster`);
//! 2. keep the 4-connected free component holding the home (or the free cell nearest to it);
//! 3. thin it to a one-cell skeleton (Zhang–Suen, `thin`; it keeps the component's holes,
//!    i.e. the obstacles one can drive around);
//! 4. in the skeleton's 8-connected graph, rooted at the pixel nearest the home, take the
//!    fundamental cycles of a breadth-first tree, drop those enclosing less than 2 m² (pixel
//!    noise), and keep the one maximising `length − 2 × distance to home` (`skeleton`);
//! 5. rotate it to start nearest the home and simplify it (Douglas–Peucker, 0.35 m;
//!    `simplify`) without ever accepting a leg closer than [`RouteOptions::leg_clearance_m`]
//!    to a wall surface.
//!
//! With no loop, an out-and-back route along the longest skeleton branch from the home is used;
//! failing that, the error explains how to add a `[[routes]]` block by hand.

mod raster;
mod simplify;
mod skeleton;
mod thin;

use crate::geom::{Segment, Vec2, segment_distance};
use raster::Raster;
pub use raster::{
    COARSEST_M, MARGIN_M, MAX_AREA_M2, MAX_CELLS, bounding_box, cell_size_m, raster_area_m2,
};
use skeleton::Tree;

/// Settings of the route generator.
#[derive(Clone, Debug, PartialEq)]
pub struct RouteOptions {
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

impl Default for RouteOptions {
    fn default() -> Self {
        RouteOptions {
            resolution_m: 0.05,
            robot_radius_m: 0.25,
            margin_m: 0.10,
            leg_clearance_m: 0.30,
            simplify_tolerance_m: 0.35,
        }
    }
}

/// What every failure tells the user to do instead.
const BY_HAND: &str = "add a route by hand: a [[routes]] block with `id = \"loop\"` and \
                `waypoints_m = [[x1, y1], [x2, y2], [x3, y3], …]` (at least 3 waypoints, each >= 0.30 m from \
                every wall, legs clear of walls by the robot radius 0.25 m), then run `placewords world check`";

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

/// Generates a drivable closed route; the error explains how to add one by hand.
pub fn generate_route(
    walls: &[Segment],
    thickness_m: f64,
    home: Vec2,
    opts: &RouteOptions,
) -> Result<Vec<Vec2>, String> {
    let need = opts.robot_radius_m + opts.margin_m;
    let raster = Raster::around(walls, home, opts.resolution_m).map_err(|(w, h)| {
        format!("the map spans {w:.0} × {h:.0} m, too large to rasterise for route generation; {BY_HAND}")
    })?;
    let free = raster.free_cells(walls, thickness_m, need);
    let Some(start) = raster.start_cell(&free, walls, home) else {
        return Err(format!(
            "no free space within 2 m of the home ({:.2}, {:.2}) where the robot fits with {need:.2} m clearance; {BY_HAND}",
            home.x, home.y
        ));
    };
    let skel = thin::zhang_suen(raster.component(&free, start), raster.nx, raster.ny);
    let Some(tree) = Tree::grow(&skel, raster.nx, raster.ny, start) else {
        return Err(format!(
            "the free space around the home is too small to drive in; {BY_HAND}"
        ));
    };
    route_along(&tree, &raster, walls, thickness_m, home, opts)
}

/// The route along the skeleton `tree` of the free space: a loop through its best cycle, else
/// out along a branch and back; checked against `walls`.
fn route_along(
    tree: &Tree,
    raster: &Raster,
    walls: &[Segment],
    thickness_m: f64,
    home: Vec2,
    opts: &RouteOptions,
) -> Result<Vec<Vec2>, String> {
    let leg_ok = |a: Vec2, b: Vec2| {
        leg_clear(
            walls,
            thickness_m,
            &Segment::new(a, b),
            opts.leg_clearance_m,
        )
    };
    let pt = |k: usize| raster.center(k % raster.nx, k / raster.nx);
    let route = match tree.best_cycle(&pt, home) {
        Some(cycle) => loop_from(&cycle, &pt, home, opts, &leg_ok),
        None => out_and_back(tree, &pt, home, opts, &leg_ok)?,
    };
    checked(route, walls, thickness_m, opts)
}

/// The cycle as a route starting at its pixel nearest the home, simplified.
fn loop_from(
    cycle: &[usize],
    pt: &dyn Fn(usize) -> Vec2,
    home: Vec2,
    opts: &RouteOptions,
    leg_ok: &dyn Fn(Vec2, Vec2) -> bool,
) -> Vec<Vec2> {
    let mut pts: Vec<Vec2> = cycle.iter().map(|&k| pt(k)).collect();
    let s = (0..pts.len())
        .min_by(|&a, &b| (pts[a] - home).norm().total_cmp(&(pts[b] - home).norm()))
        .unwrap();
    pts.rotate_left(s);
    pts.push(pts[0]);
    let mut simp = simplify::simplify(&pts, opts.simplify_tolerance_m, leg_ok);
    simp.pop();
    simp
}

/// Out and back along the tree's longest branch from its root; an error when it is shorter
/// than 1 m.
fn out_and_back(
    tree: &Tree,
    pt: &dyn Fn(usize) -> Vec2,
    home: Vec2,
    opts: &RouteOptions,
    leg_ok: &dyn Fn(Vec2, Vec2) -> bool,
) -> Result<Vec<Vec2>, String> {
    let pts: Vec<Vec2> = tree.longest_branch().iter().map(|&k| pt(k)).collect();
    let simp = simplify::simplify(&pts, opts.simplify_tolerance_m, leg_ok);
    let length: f64 = simp.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    if length < 1.0 {
        return Err(format!(
            "the free space around the home ({:.2}, {:.2}) holds neither a loop nor a branch of 1 m to drive out and back; {BY_HAND}",
            home.x, home.y
        ));
    }
    let mut route = simp.clone();
    if simp.len() == 2 {
        route.push((simp[0] + simp[1]) / 2.0);
    } else {
        route.extend(simp[1..simp.len() - 1].iter().rev());
    }
    Ok(route)
}

/// The route rounded to millimetres as the file writes it, if it still keeps its clearances
/// (waypoints 0.30 m from walls, legs the robot radius).
fn checked(
    route: Vec<Vec2>,
    walls: &[Segment],
    thickness_m: f64,
    opts: &RouteOptions,
) -> Result<Vec<Vec2>, String> {
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
            "the generated route failed its clearance check; {BY_HAND}"
        ));
    }
    Ok(route)
}
