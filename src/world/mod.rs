//! The validated world model: walls, doors and their states, routes, home, walking areas, and the
//! obstacle geometry the laser and the physics see. The only module that touches parry/rapier.

pub(crate) mod cell_grid;
pub(crate) mod geometry;
pub mod info;
pub(crate) mod load;
pub(crate) mod physics;
pub(crate) mod raster;
pub mod raycast;
pub(crate) mod validate;

pub use load::{
    RouteCheck, RouteProblem, check_world, check_world_with, load_world, load_world_for,
    parse_world, parse_world_for, parse_world_spec, parse_world_spec_checked,
};
pub use validate::WorldCheck;

use crate::geom::{Pose2, Segment, Vec2};
use crate::spec::world::WorldSpec;

/// A wall polyline with a thickness.
#[derive(Clone, Debug, PartialEq)]
pub struct Wall {
    pub id: String,
    pub points: Vec<Vec2>,
    pub closed: bool,
    pub thickness_m: f64,
}

impl Wall {
    /// The centre-line segments of the polyline.
    pub fn segments(&self) -> Vec<Segment> {
        let n = self.points.len();
        let mut out: Vec<Segment> = self
            .points
            .windows(2)
            .map(|w| Segment::new(w[0], w[1]))
            .collect();
        if self.closed && n > 2 {
            out.push(Segment::new(self.points[n - 1], self.points[0]));
        }
        out
    }
}

/// A hinged door panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Door {
    pub id: String,
    pub hinge: Vec2,
    pub width_m: f64,
    pub closed_heading_rad: f64,
    pub open_heading_rad: f64,
    pub thickness_m: f64,
}

impl Door {
    /// The panel's centre line, hinge to tip, in the given state.
    pub fn panel(&self, open: bool) -> Segment {
        let h = if open {
            self.open_heading_rad
        } else {
            self.closed_heading_rad
        };
        Segment::new(
            self.hinge,
            self.hinge + Vec2::new(h.cos(), h.sin()) * self.width_m,
        )
    }
}

/// A closed loop of waypoints.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    pub id: String,
    pub waypoints: Vec<Vec2>,
}

impl Route {
    /// Legs of the loop, the last one returning to the first waypoint.
    pub fn legs(&self) -> Vec<Segment> {
        let n = self.waypoints.len();
        (0..n)
            .map(|i| Segment::new(self.waypoints[i], self.waypoints[(i + 1) % n]))
            .collect()
    }

    /// Length of one lap, metres.
    pub fn length_m(&self) -> f64 {
        self.legs().iter().map(Segment::length).sum()
    }

    /// The same loop driven the other way: waypoint i becomes waypoint n − 1 − i.
    pub fn reversed(&self) -> Route {
        Route {
            id: self.id.clone(),
            waypoints: self.waypoints.iter().rev().copied().collect(),
        }
    }
}

/// An axis-aligned rectangle where people may walk.
#[derive(Clone, Debug, PartialEq)]
pub struct Area {
    pub id: String,
    pub min: Vec2,
    pub max: Vec2,
}

/// Which doors are open, indexed like [`World::doors`].
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct DoorStates {
    pub open: Vec<bool>,
}

impl DoorStates {
    pub fn all_closed(world: &World) -> Self {
        DoorStates {
            open: vec![false; world.doors.len()],
        }
    }

    pub fn all_open(world: &World) -> Self {
        DoorStates {
            open: vec![true; world.doors.len()],
        }
    }

    pub fn is_open(&self, door_index: usize) -> bool {
        self.open.get(door_index).copied().unwrap_or(false)
    }
}

/// A validated world.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    pub name: String,
    pub description: Option<String>,
    pub home: Pose2,
    pub walls: Vec<Wall>,
    pub doors: Vec<Door>,
    pub routes: Vec<Route>,
    pub areas: Vec<Area>,
}

impl World {
    /// Builds the model from a file's structures, converting degrees to radians. Checks nothing:
    /// validation lives in `validate` and reports located errors before this is called.
    pub fn from_spec(spec: &WorldSpec) -> World {
        let v = |p: &[f64; 2]| Vec2::new(p[0], p[1]);
        World {
            name: spec.name.clone(),
            description: spec.description.clone(),
            home: Pose2::new(
                spec.robot_home.x_m,
                spec.robot_home.y_m,
                spec.robot_home.heading_deg.to_radians(),
            ),
            walls: spec
                .walls
                .iter()
                .map(|w| Wall {
                    id: w.id.clone(),
                    points: w.points_m.iter().map(v).collect(),
                    closed: w.closed,
                    thickness_m: w.thickness_m,
                })
                .collect(),
            doors: spec
                .doors
                .iter()
                .map(|d| Door {
                    id: d.id.clone(),
                    hinge: v(&d.hinge_m),
                    width_m: d.width_m,
                    closed_heading_rad: d.closed_heading_deg.to_radians(),
                    open_heading_rad: d.open_heading_deg.to_radians(),
                    thickness_m: d.thickness_m,
                })
                .collect(),
            routes: spec
                .routes
                .iter()
                .map(|r| Route {
                    id: r.id.clone(),
                    waypoints: r.waypoints_m.iter().map(v).collect(),
                })
                .collect(),
            areas: spec
                .areas
                .iter()
                .map(|a| Area {
                    id: a.id.clone(),
                    min: v(&a.min_m),
                    max: v(&a.max_m),
                })
                .collect(),
        }
    }

    pub fn door_index(&self, id: &str) -> Option<usize> {
        self.doors.iter().position(|d| d.id == id)
    }

    pub fn route(&self, id: &str) -> Option<&Route> {
        self.routes.iter().find(|r| r.id == id)
    }

    /// All wall centre-line segments.
    pub fn wall_segments(&self) -> Vec<Segment> {
        self.walls.iter().flat_map(Wall::segments).collect()
    }

    /// The surfaces a laser sees with the doors in `doors`: each thick wall segment and door
    /// panel as the outline of its rectangle.
    pub fn obstacle_outline(&self, doors: &DoorStates) -> Vec<Segment> {
        let mut out = Vec::new();
        for w in &self.walls {
            for s in w.segments() {
                push_rectangle(&mut out, s, w.thickness_m);
            }
        }
        for (i, d) in self.doors.iter().enumerate() {
            push_rectangle(&mut out, d.panel(doors.is_open(i)), d.thickness_m);
        }
        out
    }

    /// Axis-aligned bounds of all walls and doors (both states): (min, max), metres.
    pub fn bounds(&self) -> (Vec2, Vec2) {
        let mut lo = Vec2::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut add = |p: Vec2| {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        };
        for w in &self.walls {
            for p in &w.points {
                add(*p);
            }
        }
        for d in &self.doors {
            add(d.panel(false).b);
            add(d.panel(true).b);
            add(d.hinge);
        }
        if !lo.x.is_finite() {
            return (Vec2::zeros(), Vec2::zeros());
        }
        (lo, hi)
    }
}

/// Pushes the four edges of the rectangle of width `thickness_m` centred on `s`.
fn push_rectangle(out: &mut Vec<Segment>, s: Segment, thickness_m: f64) {
    let d = s.b - s.a;
    let len = d.norm();
    if len == 0.0 {
        return;
    }
    let n = Vec2::new(-d.y, d.x) / len * (thickness_m / 2.0);
    let (p0, p1, p2, p3) = (s.a + n, s.b + n, s.b - n, s.a - n);
    out.push(Segment::new(p0, p1));
    out.push(Segment::new(p1, p2));
    out.push(Segment::new(p2, p3));
    out.push(Segment::new(p3, p0));
}
