//! A summary of a world for people and scripts (`placewords world info`).

use crate::geom::wrap_angle;
use crate::world::{Route, World};
use serde::Serialize;

/// A turn sharper than this at a waypoint counts as a corner, degrees.
pub const CORNER_MIN_TURN_DEG: f64 = 20.0;

/// One route's summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RouteInfo {
    pub id: String,
    /// Length of one lap, metres.
    pub length_m: f64,
    /// Waypoints where the route turns by more than [`CORNER_MIN_TURN_DEG`].
    pub corners: usize,
    pub waypoints: usize,
}

/// A world's summary; the JSON of `placewords world info --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorldInfo {
    pub name: String,
    pub doors: usize,
    pub walls: usize,
    pub wall_segments: usize,
    /// Total centre-line length of the walls, metres.
    pub wall_length_m: f64,
    /// Width and height of the walls' and doors' bounding box, metres.
    pub bounds_m: [f64; 2],
    /// Lower-left corner of that box, metres.
    pub origin_m: [f64; 2],
    pub routes: Vec<RouteInfo>,
    pub areas: usize,
}

/// Number of corners of a closed route.
pub fn route_corners(route: &Route) -> usize {
    let n = route.waypoints.len();
    if n < 3 {
        return 0;
    }
    (0..n)
        .filter(|&i| {
            let prev = route.waypoints[(i + n - 1) % n];
            let here = route.waypoints[i];
            let next = route.waypoints[(i + 1) % n];
            let (a, b) = (here - prev, next - here);
            if a.norm() == 0.0 || b.norm() == 0.0 {
                return false;
            }
            let turn = wrap_angle(b.y.atan2(b.x) - a.y.atan2(a.x));
            turn.abs().to_degrees() > CORNER_MIN_TURN_DEG
        })
        .count()
}

/// `x` to the millimetre: sums of segment lengths print as `984.1`, not `984.1000000000001`.
fn mm(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// Summarises `world` (lengths to the millimetre).
pub fn world_info(world: &World) -> WorldInfo {
    let (lo, hi) = world.bounds();
    let segs = world.wall_segments();
    WorldInfo {
        name: world.name.clone(),
        doors: world.doors.len(),
        walls: world.walls.len(),
        wall_segments: segs.len(),
        wall_length_m: mm(segs.iter().map(|s| s.length()).sum()),
        bounds_m: [mm(hi.x - lo.x), mm(hi.y - lo.y)],
        origin_m: [mm(lo.x), mm(lo.y)],
        routes: world
            .routes
            .iter()
            .map(|r| RouteInfo {
                id: r.id.clone(),
                length_m: mm(r.length_m()),
                corners: route_corners(r),
                waypoints: r.waypoints.len(),
            })
            .collect(),
        areas: world.areas.len(),
    }
}

impl std::fmt::Display for WorldInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "world      {}", self.name)?;
        writeln!(
            f,
            "size       {:.1} m x {:.1} m (from [{:.1}, {:.1}])",
            self.bounds_m[0], self.bounds_m[1], self.origin_m[0], self.origin_m[1]
        )?;
        writeln!(
            f,
            "walls      {} ({} segments, {:.1} m in all)",
            self.walls, self.wall_segments, self.wall_length_m
        )?;
        writeln!(f, "doors      {}", self.doors)?;
        writeln!(f, "areas      {}", self.areas)?;
        for r in &self.routes {
            writeln!(
                f,
                "route      {}: {:.1} m, {} corners, {} waypoints",
                r.id, r.length_m, r.corners, r.waypoints
            )?;
        }
        Ok(())
    }
}
