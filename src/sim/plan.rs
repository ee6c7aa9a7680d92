//! What the simulator is asked to do: the world and route, the seed, the runs with their door
//! plans, and the models of the robot, its laser, its odometry and the people around it. Built
//! (and checked) from a scenario file one layer up, in `experiment::scenario`.

use crate::sim::laser::LaserConfig;
use crate::sim::odometry::OdometryConfig;
use crate::sim::pedestrians::PedestrianConfig;
use crate::sim::robot::RobotConfig;
use crate::world::{DoorStates, Route, World};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A named set of door states.
#[derive(Clone, Debug, PartialEq)]
pub struct DoorChoice {
    /// "all-closed", "all-open" or a `[door_configs]` name.
    pub name: String,
    pub states: DoorStates,
}

/// How a run's doors are set each lap.
#[derive(Clone, Debug, PartialEq)]
pub enum DoorPlan {
    Fixed(DoorChoice),
    /// Lap `k` uses entry `k mod len`.
    Cycle(Vec<DoorChoice>),
    /// Each door open with this probability, drawn per lap.
    Random {
        open_probability: f64,
    },
}

/// One run: where it starts, how many laps, how its doors are set.
#[derive(Clone, Debug, PartialEq)]
pub struct RunPlan {
    /// Index into the route's waypoints (0 is the first).
    pub start_waypoint: usize,
    /// Drive the route's waypoints in reverse order.
    pub reverse: bool,
    pub laps: usize,
    pub doors: DoorPlan,
}

impl SimPlan {
    /// One run of `laps` laps of `route` from waypoint 0, forward, with the doors of `doors`,
    /// seed 0, nobody about and the default robot, laser and odometry: the drive the world
    /// checks and the authoring maps make (they change the models they need noise-free).
    pub fn one_run(
        name: String,
        world: &World,
        route: &Route,
        laps: usize,
        doors: DoorChoice,
    ) -> Self {
        SimPlan {
            name,
            path: PathBuf::new(),
            world_path: PathBuf::new(),
            world: world.clone(),
            route: route.clone(),
            seed: 0,
            runs: vec![RunPlan {
                start_waypoint: 0,
                reverse: false,
                laps,
                doors: DoorPlan::Fixed(doors),
            }],
            door_configs: BTreeMap::new(),
            pedestrians: PedestrianConfig::default(),
            laser: LaserConfig::default(),
            odometry: OdometryConfig::default(),
            robot: RobotConfig::default(),
        }
    }
}

impl RunPlan {
    /// The route as this run drives it (reversed for a reverse run) and the index of its start
    /// waypoint in it (the same place as `start_waypoint` in the route's own order).
    pub fn driven_route(&self, route: &Route) -> (Route, usize) {
        if self.reverse {
            let n = route.waypoints.len();
            (route.reversed(), n.saturating_sub(1 + self.start_waypoint))
        } else {
            (route.clone(), self.start_waypoint)
        }
    }
}

/// Everything a simulation needs.
#[derive(Clone, Debug)]
pub struct SimPlan {
    /// The scenario's name (for log headers and manifests).
    pub name: String,
    /// The scenario file (as given).
    pub path: PathBuf,
    /// The world file, resolved against the scenario's folder.
    pub world_path: PathBuf,
    pub world: World,
    pub route: Route,
    pub seed: u64,
    pub runs: Vec<RunPlan>,
    pub door_configs: BTreeMap<String, DoorStates>,
    pub pedestrians: PedestrianConfig,
    pub laser: LaserConfig,
    pub odometry: OdometryConfig,
    pub robot: RobotConfig,
}
