//! Lap generation: drives the robot around the scenario's route, run by run (in parallel) and
//! lap by lap, and records a [`Frame`] per laser scan.
//!
//! Per step (`robot.step_s`, 0.05 s by default): the controller picks speeds from the true pose
//! and the last scan; the wheels move the robot exactly along the arc those speeds give; the
//! odometry integrates the noisy wheel motion; pedestrians walk; the physics world takes the
//! new poses and steps; the route tracker measures progress on the true trajectory. Every
//! `1 / laser.rate_hz` seconds a scan is taken and a frame recorded. A lap ends when progress
//! reaches a whole route length. Door states change only between laps.
//!
//! Each run starts at its start waypoint facing along the route, at rest, with the odometry at
//! (0, 0, 0) as on a robot just switched on; odometry is continuous across the run's laps.

use crate::geom::{OdomPose, Pose2, TruePose, wrap_angle};
use crate::log::{Frame, LapLog, RunLog};
use crate::sim::laser::Laser;
use crate::sim::odometry::Odometry;
use crate::sim::pedestrians::{self, Pedestrian};
use crate::sim::plan::{DoorPlan, SimPlan};
use crate::sim::rng::{Purpose, RUN_WIDE, SimRng, stream};
use crate::sim::robot::{
    Controller, RouteTracker, Wander, free_ahead, integrate, spin_waypoints, waypoint_room,
    wheel_speeds,
};
use crate::sim::variation::{LaneRoom, LapPlan, PathShape, corner_spins, obstacles};
use crate::world::geometry::SegmentIndex;
use crate::world::physics::Physics;
use crate::world::raycast::{Disc, SweepCaster};
use crate::world::{DoorStates, Route};
use rand::RngExt;
use rayon::prelude::*;

/// Why a simulation stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error(
        "run {run}, lap {lap}: the robot was blocked for {waited_s:.0} s at ({x_m:.2}, {y_m:.2}); \
         check the route for walls, closed doors or people in the way there"
    )]
    Blocked {
        run: usize,
        lap: usize,
        x_m: f64,
        y_m: f64,
        waited_s: f64,
    },
}

/// The door states of `run`'s lap `lap`, and the configuration's name.
pub fn door_states(scn: &SimPlan, run: usize, lap: usize) -> (String, DoorStates) {
    match &scn.runs[run].doors {
        DoorPlan::Fixed(c) => (c.name.clone(), c.states.clone()),
        DoorPlan::Cycle(list) => {
            let c = &list[lap % list.len()];
            (c.name.clone(), c.states.clone())
        }
        DoorPlan::Random { open_probability } => {
            let mut rng = stream(scn.seed, run as u64, lap as u64, Purpose::Doors);
            let open = scn
                .world
                .doors
                .iter()
                .map(|_| rng.random_bool(open_probability.clamp(0.0, 1.0)))
                .collect();
            ("random".into(), DoorStates { open })
        }
    }
}

/// Simulates every run (in parallel; results are identical whatever the thread count).
/// `laps_override` replaces each run's lap count; `progress` is called once per finished lap.
pub fn simulate(
    scn: &SimPlan,
    laps_override: Option<usize>,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<RunLog>, SimError> {
    Ok(simulate_timed(scn, laps_override, progress)?.0)
}

/// [`simulate`], with the CPU seconds the laps cost (summed over the threads that made them).
pub fn simulate_timed(
    scn: &SimPlan,
    laps_override: Option<usize>,
    progress: &(dyn Fn() + Sync),
) -> Result<(Vec<RunLog>, f64), SimError> {
    let cpu_s = std::sync::Mutex::new(0.0f64);
    let runs = (0..scn.runs.len())
        .into_par_iter()
        .map(|run| {
            let laps = laps_override.unwrap_or(scn.runs[run].laps);
            let mut sim = RunSim::new(scn, run);
            let mut out = RunLog {
                run,
                laps: Vec::with_capacity(laps),
            };
            for lap in 0..laps {
                let w = crate::clock::Stopwatch::start();
                out.laps.push(sim.run_lap(lap)?);
                *cpu_s.lock().unwrap_or_else(|e| e.into_inner()) += w.cpu_s();
                progress();
            }
            Ok(out)
        })
        .collect::<Result<Vec<RunLog>, SimError>>()?;
    let cpu_s = cpu_s.into_inner().unwrap_or_else(|e| e.into_inner());
    Ok((runs, cpu_s))
}

/// The state of one run: robot, odometry, laser, physics, pedestrians, time.
pub struct RunSim<'a> {
    scn: &'a SimPlan,
    run: usize,
    laser: Laser,
    odometry: Odometry,
    controller: Controller,
    tracker: RouteTracker,
    /// The route as this run drives it (reversed for a reverse run).
    route: Route,
    physics: Physics,
    caster: SweepCaster,
    pedestrians: Vec<Pedestrian>,
    truth: Pose2,
    time_s: f64,
    lap_start_s: f64,
    next_scan_s: f64,
    free_ahead_m: f64,
    laser_rng: SimRng,
    odom_rng: SimRng,
    /// Progress and time when progress last grew by 0.1 m.
    stall_mark: (f64, f64),
    discs: Vec<Disc>,
    ranges: Vec<f64>,
    lap: usize,
    door_config: String,
    open_doors: Vec<String>,
    contact_steps: usize,
    plan: LapPlan,
    /// Walls and doors a lane keeps clear of, and the room at each waypoint.
    lanes: (SegmentIndex, LaneRoom),
    /// What the robot is doing instead of driving: stopped until a time, or turning on the
    /// spot with an angle left to turn.
    hold: Hold,
}

/// A pause in driving, from the lap plan.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Hold {
    Drive,
    StopUntil(f64),
    /// Signed angle left to turn, radians.
    Spin(f64),
    /// Turning on the spot at a route waypoint ([`spin_waypoints`]): signed angle left to turn,
    /// radians; the tracker passes the gate when it is done.
    TurnAtWaypoint(f64),
}

/// Turn rate of a turn on the spot, rad/s (45°/s).
const SPIN_RATE_RAD_S: f64 = std::f64::consts::FRAC_PI_4;

/// The robot starts its turn on the spot at a waypoint when its progress is this close to it,
/// metres.
pub const TURN_CAPTURE_M: f64 = 0.05;

impl<'a> RunSim<'a> {
    /// A run at its start waypoint, with all doors closed until the first lap sets them.
    pub fn new(scn: &'a SimPlan, run: usize) -> Self {
        let plan = &scn.runs[run];
        let (route, start) = plan.driven_route(&scn.route);
        let obstacles = obstacles(&scn.world);
        let room_m = waypoint_room(&route, &obstacles);
        let spins = spin_waypoints(&route, &scn.robot, &room_m);
        let tracker = RouteTracker::with_gates(&route, start, &spins);
        let truth = tracker.start_pose();
        let clearance_m = scn.robot.radius_m + scn.robot.variation.lane_margin_m;
        let room = LaneRoom::measure(&route, &obstacles, clearance_m);
        let mut angle_rng = stream(scn.seed, run as u64, RUN_WIDE, Purpose::LaserAngles);
        let laser = Laser::new(scn.laser.clone(), &mut angle_rng);
        let physics = Physics::new(
            &scn.world,
            scn.robot.radius_m,
            truth,
            scn.pedestrians.count,
            scn.pedestrians.radius_m,
            scn.robot.step_s,
        );
        RunSim {
            scn,
            run,
            laser,
            odometry: Odometry::new(
                scn.odometry.clone(),
                scn.robot.axle_track_m,
                Pose2::IDENTITY,
            ),
            controller: Controller::default(),
            tracker,
            route,
            physics,
            caster: SweepCaster::for_world(&scn.world, &DoorStates::all_closed(&scn.world)),
            pedestrians: Vec::new(),
            truth,
            time_s: 0.0,
            lap_start_s: 0.0,
            next_scan_s: 0.0,
            free_ahead_m: f64::INFINITY,
            laser_rng: stream(scn.seed, run as u64, 0, Purpose::LaserNoise),
            odom_rng: stream(scn.seed, run as u64, 0, Purpose::Odometry),
            stall_mark: (0.0, 0.0),
            discs: Vec::new(),
            ranges: Vec::new(),
            lap: 0,
            door_config: "all-closed".into(),
            open_doors: Vec::new(),
            contact_steps: 0,
            plan: LapPlan::wander_only(Wander::default()),
            lanes: (obstacles, room),
            hold: Hold::Drive,
        }
    }

    /// Sets the doors, people and random streams of lap `lap`.
    pub fn begin_lap(&mut self, lap: usize) {
        let (scn, run) = (self.scn, self.run as u64);
        let (name, doors) = door_states(scn, self.run, lap);
        self.caster = SweepCaster::for_world(&scn.world, &doors);
        self.physics.set_doors(&doors);
        self.open_doors = scn
            .world
            .doors
            .iter()
            .enumerate()
            .filter(|(i, _)| doors.is_open(*i))
            .map(|(_, d)| d.id.clone())
            .collect();
        self.door_config = name;
        let mut prng = stream(scn.seed, run, lap as u64, Purpose::Pedestrians);
        self.pedestrians = pedestrians::draw(&scn.pedestrians, &mut prng);
        self.laser_rng = stream(scn.seed, run, lap as u64, Purpose::LaserNoise);
        self.odom_rng = stream(scn.seed, run, lap as u64, Purpose::Odometry);
        let mut wrng = stream(scn.seed, run, lap as u64, Purpose::PathWander);
        let wander = Wander::draw(scn.robot.path_wander_m, &mut wrng);
        let mut vrng = stream(scn.seed, run, lap as u64, Purpose::LapVariation);
        let clearance_m = scn.robot.radius_m + scn.robot.variation.lane_margin_m;
        let lap_start_m = self.tracker.arc_m();
        self.plan = LapPlan::draw(
            &scn.robot.variation,
            (&self.lanes.1, &self.route, &self.lanes.0, clearance_m),
            (lap_start_m, self.tracker.length_m()),
            wander,
            &mut vrng,
        );
        if scn.robot.variation.corner_spin_ratio > 0.0 {
            let room_m = waypoint_room(&self.route, &self.lanes.0);
            let base = spin_waypoints(&self.route, &scn.robot, &room_m);
            let gates = corner_spins(&self.route, &scn.robot, (&base, &room_m), &mut vrng);
            self.tracker.set_gates(&gates);
        }
        self.lap = lap;
        self.lap_start_s = self.time_s;
        self.stall_mark = (self.tracker.progress_m(), self.time_s);
        self.update_discs();
    }

    fn update_discs(&mut self) {
        self.discs.clear();
        self.discs
            .extend(self.pedestrians.iter().map(Pedestrian::disc));
    }

    pub fn truth(&self) -> Pose2 {
        self.truth
    }

    pub fn odometry(&self) -> Pose2 {
        self.odometry.pose()
    }

    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Progress along the route since the run started, metres.
    pub fn progress_m(&self) -> f64 {
        self.tracker.progress_m()
    }

    /// Steps in which the robot's disc overlapped something (walls, doors, people).
    pub fn contact_steps(&self) -> usize {
        self.contact_steps
    }

    /// One simulation step; returns a frame when a scan was due.
    pub fn step(&mut self) -> Result<Option<Frame>, SimError> {
        let cfg = &self.scn.robot;
        let dt = cfg.step_s;
        let (v, w) = self.drive_command();
        let (vl, vr) = wheel_speeds(v, w, cfg.axle_track_m);
        let next = integrate(self.truth, v, w, dt);
        self.odometry.update(vl * dt, vr * dt, &mut self.odom_rng);
        self.time_s += dt;
        // People keep a hand's width off the robot's body.
        let keep_away = cfg.radius_m + self.scn.pedestrians.radius_m + 0.1;
        for (i, p) in self.pedestrians.iter_mut().enumerate() {
            p.advance(dt, next.position(), keep_away);
            self.physics.set_pedestrian_next(i, p.position());
        }
        self.physics.set_robot_next(next);
        self.physics.step();
        if self.physics.robot_touches_something() {
            self.contact_steps += 1;
        }
        self.truth = next;
        match self.hold {
            Hold::Spin(left) => {
                let turned = w * dt;
                self.hold = if left.abs() <= turned.abs() {
                    Hold::Drive
                } else {
                    Hold::Spin(left - turned)
                };
            }
            Hold::TurnAtWaypoint(left) => {
                let turned = w * dt;
                self.hold = if left.abs() <= turned.abs() {
                    self.tracker.pass_gate();
                    Hold::Drive
                } else {
                    Hold::TurnAtWaypoint(left - turned)
                };
            }
            _ => {}
        }
        let progress = self.tracker.update(next.position());
        if self.hold != Hold::Drive {
            // A planned pause is not being blocked.
            self.stall_mark.1 = self.time_s;
        }
        if progress >= self.stall_mark.0 + 0.1 {
            self.stall_mark = (progress, self.time_s);
        } else if self.time_s - self.stall_mark.1 > cfg.blocked_timeout_s {
            return Err(SimError::Blocked {
                run: self.run,
                lap: self.lap,
                x_m: next.x,
                y_m: next.y,
                waited_s: self.time_s - self.stall_mark.1,
            });
        }
        if self.time_s + 1e-9 >= self.next_scan_s {
            self.next_scan_s += 1.0 / self.scn.laser.rate_hz;
            return Ok(Some(self.take_scan()));
        }
        Ok(None)
    }

    /// Speeds for the next step: the lap plan's stops and turns on the spot when one is due,
    /// otherwise the route-following controller.
    fn drive_command(&mut self) -> (f64, f64) {
        let cfg = &self.scn.robot;
        let arc = self.tracker.arc_m();
        if self.hold == Hold::Drive {
            if let Some(gate) = self.tracker.next_gate_m().filter(|&g| {
                // A lane shifted off a corner projects short of it: its own point counts
                // (only with corners on the spot, so other laps keep their turns).
                let off = self.plan.target(&self.tracker, g) - self.truth.position();
                g - arc <= TURN_CAPTURE_M
                    || (cfg.variation.corner_spin_ratio > 0.0 && g - arc < 1.0 && off.norm() < 0.15)
            }) {
                let (_, out) = self.tracker.point_at(gate + 1e-6);
                let turn = wrap_angle(out.y.atan2(out.x) - self.truth.theta);
                self.hold = Hold::TurnAtWaypoint(turn);
            } else if let Some(d) = self.plan.take_stop(arc) {
                self.hold = Hold::StopUntil(self.time_s + d);
            } else if let Some(a) = self.plan.take_spin(arc) {
                self.hold = Hold::Spin(a);
            }
        }
        match self.hold {
            Hold::StopUntil(t) if self.time_s < t => self.controller.hold(cfg, 0.0),
            Hold::Spin(left) | Hold::TurnAtWaypoint(left) => {
                self.controller.hold(cfg, left.signum() * SPIN_RATE_RAD_S)
            }
            _ => {
                self.hold = Hold::Drive;
                self.controller.command(
                    cfg,
                    self.truth,
                    &self.tracker,
                    &self.plan,
                    self.free_ahead_m,
                )
            }
        }
    }

    fn take_scan(&mut self) -> Frame {
        self.update_discs();
        self.laser
            .exact_ranges(&self.caster, self.truth, &self.discs, &mut self.ranges);
        // The controller sees obstacles through the (noise-free) scan.
        self.free_ahead_m = free_ahead(&self.scn.robot, self.laser.hits_in_robot(&self.ranges));
        let layout = self.laser.layout();
        let mut ranges = self.ranges.clone();
        self.laser.add_noise(&mut ranges, &mut self.laser_rng);
        Frame {
            time_s: self.time_s,
            odom: OdomPose(self.odometry.pose()),
            truth: TruePose(self.truth),
            scan: crate::scan::Scan {
                layout: layout.clone(),
                ranges_m: ranges,
                time_s: self.time_s,
            },
        }
    }

    /// Drives lap `lap` to its end.
    pub fn run_lap(&mut self, lap: usize) -> Result<LapLog, SimError> {
        self.begin_lap(lap);
        let goal = (lap + 1) as f64 * self.tracker.length_m();
        let mut frames = Vec::new();
        while self.tracker.progress_m() < goal {
            if let Some(f) = self.step()? {
                frames.push(f);
            }
        }
        Ok(LapLog {
            lap,
            door_config: self.door_config.clone(),
            open_doors: self.open_doors.clone(),
            frames,
        })
    }
}
