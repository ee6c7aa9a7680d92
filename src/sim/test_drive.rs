//! A test drive of a route before any long run: the simulator's own robot, controller and
//! route tracker ([`RunSim`], so the turning path is the one laps are driven on: smooth arcs
//! inside ordinary corners, turns on the spot where `sim::robot::spin_waypoints` says) drive the route
//! once round, noise-free, with nobody about, no wander and no lap variation, once with every
//! door closed and once with every door open. A route is refused where the robot's disc would
//! touch a wall or door (by more than [`TOUCH_TOLERANCE_M`]) or where the robot would be
//! blocked, naming the waypoint nearest the place (from 0, as the file lists them), the place
//! and the cause.
//!
//! `world check` test-drives every route for the default robot ([`check_world`]); `scenario
//! check` the scenario's route as its runs drive it, for its `[robot]` and `[laser]`
//! ([`plan_problems`]).

use crate::geom::{Segment, Vec2};
use crate::sim::pedestrians::PedestrianConfig;
use crate::sim::plan::{DoorChoice, DoorPlan, RunPlan, SimPlan};
use crate::sim::robot::{RobotConfig, spin_waypoints, waypoint_room};
use crate::sim::runner::{RunSim, SimError};
use crate::sim::variation::LapVariationConfig;
use crate::spec::diag::{Diagnostic, SpecError};
use crate::world::geometry::{SegmentIndex, ThickSegment};
use crate::world::{DoorStates, RouteProblem, World};
use std::collections::BTreeMap;
use std::path::Path;

/// How far the disc may overlap a wall or door before the drive counts it as touching, metres
/// (legs are checked exactly elsewhere; this keeps the controller's millimetre tracking error
/// on a leg that clears a wall by exactly the radius from refusing it).
pub const TOUCH_TOLERANCE_M: f64 = 0.01;

/// Where one drive of a route went wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct Undrivable {
    /// The waypoint nearest the place, indexed as the file lists the route's waypoints.
    pub waypoint: usize,
    /// The robot's centre when it went wrong, world frame, metres.
    pub x_m: f64,
    pub y_m: f64,
    /// What went wrong and what to try.
    pub cause: String,
}

/// The walls and doors of one door state, with a name for each.
struct Obstacles {
    index: SegmentIndex,
    names: Vec<String>,
}

impl Obstacles {
    fn new(world: &World, doors: &DoorStates) -> Self {
        let mut items = Vec::new();
        let mut names = Vec::new();
        for w in &world.walls {
            for seg in w.segments() {
                items.push(ThickSegment {
                    seg,
                    half_thickness_m: w.thickness_m / 2.0,
                });
                names.push(format!("wall '{}'", w.id));
            }
        }
        for (i, d) in world.doors.iter().enumerate() {
            let open = doors.is_open(i);
            items.push(ThickSegment {
                seg: d.panel(open),
                half_thickness_m: d.thickness_m / 2.0,
            });
            let state = if open { "open" } else { "closed" };
            names.push(format!("{state} door '{}'", d.id));
        }
        Obstacles {
            index: SegmentIndex::new(items),
            names,
        }
    }

    /// The nearest obstacle closer than `margin` to `s`, named.
    fn nearest(&self, s: Segment, margin: f64) -> Option<&str> {
        self.index
            .nearest_within(s, margin)
            .map(|(i, _)| self.names[i].as_str())
    }
}

/// Drives `plan`'s run `run` (only its start, direction and the door states given matter) one
/// lap and a little beyond its start, and reports the first place it goes wrong.
/// `file_index` maps a waypoint of the route as driven back to the file's numbering.
fn drive(plan: &SimPlan, doors: &DoorStates) -> Option<Undrivable> {
    let cfg = &plan.robot;
    let obstacles = Obstacles::new(&plan.world, doors);
    let mut sim = RunSim::new(plan, 0);
    sim.begin_lap(0);
    let length_m = plan.route.length_m();
    // Past the start waypoint, so its corner (never turned on lap 0) is driven too.
    let goal_m = length_m + cfg.lookahead_m + 2.0;
    let min_speed = (cfg.cruise_speed_m_s * 0.05).max(1e-3);
    let max_steps = ((goal_m / min_speed + cfg.blocked_timeout_s) / cfg.step_s).ceil() as usize;
    let nearest_waypoint = |p: Vec2| {
        let w = &plan.route.waypoints;
        (0..w.len())
            .min_by(|&a, &b| (w[a] - p).norm().total_cmp(&(w[b] - p).norm()))
            .unwrap_or(0)
    };
    let mut last = sim.truth().position();
    for _ in 0..max_steps {
        if sim.progress_m() >= goal_m {
            return None;
        }
        if let Err(SimError::Blocked { x_m, y_m, .. }) = sim.step() {
            let pose = sim.truth();
            let ahead = Segment::new(
                pose.position(),
                pose.position()
                    + Vec2::new(pose.theta.cos(), pose.theta.sin())
                        * (cfg.radius_m + cfg.stop_distance_m + 0.1),
            );
            let what = obstacles
                .nearest(ahead, cfg.radius_m + 0.05)
                .map_or("something".to_string(), str::to_string);
            let p = Vec2::new(x_m, y_m);
            return Some(Undrivable {
                waypoint: nearest_waypoint(p),
                x_m,
                y_m,
                cause: format!(
                    "the robot stops for {what} ahead (closer than stop_distance_m = {} m to its front, within its width plus 0.05 m each side) and makes no progress for {} s; keep the route at least {:.2} m (radius + 0.05 m) from it",
                    cfg.stop_distance_m,
                    cfg.blocked_timeout_s,
                    cfg.radius_m + 0.05
                ),
            });
        }
        let now = sim.truth().position();
        let margin = cfg.radius_m - TOUCH_TOLERANCE_M;
        if let Some(what) = obstacles.nearest(Segment::new(last, now), margin) {
            let room_m = waypoint_room(&plan.route, &crate::sim::variation::obstacles(&plan.world));
            let turns = spin_waypoints(&plan.route, cfg, &room_m);
            let k = nearest_waypoint(now);
            let how = if turns[k] {
                "where it turns on the spot"
            } else {
                "on its turn (the robot rounds a corner of less than the spin angle on an arc inside it)"
            };
            return Some(Undrivable {
                waypoint: k,
                x_m: now.x,
                y_m: now.y,
                cause: format!(
                    "the robot's disc (radius {} m) touches {what} {how}; give the corner more room or move the waypoint away from it",
                    cfg.radius_m
                ),
            });
        }
        last = now;
    }
    None
}

/// The plan of a test drive: `plan`'s world, route and robot (without wander or lap
/// variation), nobody about, one run from `start_waypoint`.
fn drive_plan(base: &SimPlan, start_waypoint: usize, reverse: bool, doors: &DoorStates) -> SimPlan {
    let robot = RobotConfig {
        path_wander_m: 0.0,
        variation: LapVariationConfig::default(),
        ..base.robot.clone()
    };
    SimPlan {
        runs: vec![RunPlan {
            start_waypoint,
            reverse,
            laps: 1,
            doors: DoorPlan::Fixed(DoorChoice {
                name: "test drive".into(),
                states: doors.clone(),
            }),
        }],
        door_configs: BTreeMap::new(),
        pedestrians: PedestrianConfig {
            count: 0,
            ..base.pedestrians.clone()
        },
        robot,
        ..base.clone()
    }
}

/// Test-drives the route of `plan` as each of its runs drives it (each distinct start and
/// direction), with all doors closed and all open; one problem per place, worded for the
/// world file's route number `route_index`.
pub fn plan_problems(plan: &SimPlan, route_index: usize) -> Vec<RouteProblem> {
    let mut starts: Vec<(usize, bool)> = plan
        .runs
        .iter()
        .map(|r| (r.start_waypoint, r.reverse))
        .collect();
    starts.sort_unstable();
    starts.dedup();
    let mut out: Vec<RouteProblem> = Vec::new();
    for (start, reverse) in starts {
        for (doors, when) in [
            (DoorStates::all_closed(&plan.world), "all doors closed"),
            (DoorStates::all_open(&plan.world), "all doors open"),
        ] {
            let drive_plan = drive_plan(plan, start, reverse, &doors);
            let Some(u) = drive(&drive_plan, &doors) else {
                continue;
            };
            if out.iter().any(|p| p.waypoint == u.waypoint) {
                continue;
            }
            let way = if reverse { " (driven in reverse)" } else { "" };
            out.push(RouteProblem {
                route: route_index,
                waypoint: u.waypoint,
                message: format!(
                    "route '{}'{way} cannot be driven with {when}: at ({:.2}, {:.2}), nearest waypoint {}, {}",
                    plan.route.id, u.x_m, u.y_m, u.waypoint, u.cause
                ),
            });
        }
    }
    out
}

/// Test-drives every route of `world` for the default robot and laser, from waypoint 0 in the
/// file's order.
pub fn world_problems(world: &World) -> Vec<RouteProblem> {
    world
        .routes
        .iter()
        .enumerate()
        .flat_map(|(i, route)| {
            let doors = DoorChoice {
                name: "all-closed".into(),
                states: DoorStates::all_closed(world),
            };
            let plan = SimPlan::one_run("test drive".into(), world, route, 1, doors);
            plan_problems(&plan, i)
        })
        .collect()
}

/// `world check` of a file: every check of [`crate::world::check_world`], then a test drive of
/// each route (when the rest is valid); returns the world and its warnings.
pub fn check_world(path: &Path) -> Result<(World, Vec<Diagnostic>), SpecError> {
    crate::world::check_world_with(path, &world_problems)
}

/// [`check_world`] of a file's text; `path` only names the file in messages.
pub fn check_world_text(src: &str, path: &str) -> Result<World, SpecError> {
    crate::world::parse_world_spec_checked(
        src,
        path,
        &crate::world::WorldCheck::default(),
        Some(&world_problems),
    )
    .map(|(spec, _)| World::from_spec(&spec))
}
