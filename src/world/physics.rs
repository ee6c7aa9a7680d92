//! The rapier2d physics world of a simulation: walls fixed, doors placed open or closed per lap,
//! pedestrians and the robot as kinematic discs.
//!
//! Bodies are kinematic and position-based: the simulator computes where the robot's wheels and
//! the pedestrians' walks take them, hands rapier the next poses, and steps; rapier keeps the
//! bodies and reports overlaps (the robot touching a wall, a door or a person). Rapier is f32;
//! the simulator keeps the f64 poses it handed over as the ground truth.
//!
//! Door states change only between laps ([`Physics::set_doors`]); each door has one collider per
//! state, and exactly one of them is enabled.

use crate::geom::{Pose2, Segment, Vec2};
use crate::world::{DoorStates, World};
use rapier2d::prelude::{
    ActiveCollisionTypes, ColliderBuilder, ColliderHandle, PhysicsWorld, Pose, RigidBodyBuilder,
    RigidBodyHandle, Vector,
};

/// A world's physics for one robot and a fixed number of pedestrians.
pub struct Physics {
    world: PhysicsWorld,
    robot: RigidBodyHandle,
    robot_collider: ColliderHandle,
    pedestrians: Vec<RigidBodyHandle>,
    /// (closed collider, open collider) per door.
    doors: Vec<(ColliderHandle, ColliderHandle)>,
}

fn pose32(p: Pose2) -> Pose {
    Pose::new(Vector::new(p.x as f32, p.y as f32), p.theta as f32)
}

fn slab(s: Segment, thickness_m: f64) -> Option<ColliderBuilder> {
    let d = s.b - s.a;
    let len = d.norm();
    if len == 0.0 {
        return None;
    }
    let mid = (s.a + s.b) / 2.0;
    let angle = d.y.atan2(d.x);
    Some(
        ColliderBuilder::cuboid((len / 2.0) as f32, (thickness_m.max(1e-3) / 2.0) as f32)
            .position(pose32(Pose2::new(mid.x, mid.y, angle))),
    )
}

impl Physics {
    /// Builds the world with every door closed, the robot (a disc of `robot_radius_m`) at
    /// `robot_pose`, and `pedestrian_count` discs of `pedestrian_radius_m` parked at the origin.
    pub fn new(
        world: &World,
        robot_radius_m: f64,
        robot_pose: Pose2,
        pedestrian_count: usize,
        pedestrian_radius_m: f64,
        step_s: f64,
    ) -> Self {
        let mut pw = PhysicsWorld::new();
        pw.gravity = Vector::new(0.0, 0.0);
        pw.integration_parameters.dt = step_s as f32;
        for w in &world.walls {
            for s in w.segments() {
                if let Some(c) = slab(s, w.thickness_m) {
                    pw.insert_collider(c, None);
                }
            }
        }
        let mut doors = Vec::with_capacity(world.doors.len());
        for d in &world.doors {
            let mut pair = [None, None];
            for (k, open) in [false, true].into_iter().enumerate() {
                let c = slab(d.panel(open), d.thickness_m)
                    .unwrap_or_else(|| ColliderBuilder::ball(1e-3))
                    .enabled(!open);
                pair[k] = Some(pw.insert_collider(c, None));
            }
            doors.push((pair[0].unwrap(), pair[1].unwrap()));
        }
        let robot =
            pw.insert_body(RigidBodyBuilder::kinematic_position_based().pose(pose32(robot_pose)));
        let robot_collider = pw.insert_collider(
            ColliderBuilder::ball(robot_radius_m as f32)
                .sensor(true)
                .active_collision_types(ActiveCollisionTypes::all()),
            Some(robot),
        );
        let pedestrians = (0..pedestrian_count)
            .map(|_| {
                let h = pw.insert_body(RigidBodyBuilder::kinematic_position_based());
                pw.insert_collider(ColliderBuilder::ball(pedestrian_radius_m as f32), Some(h));
                h
            })
            .collect();
        Physics {
            world: pw,
            robot,
            robot_collider,
            pedestrians,
            doors,
        }
    }

    /// Places the doors; takes effect at the next [`Physics::step`].
    pub fn set_doors(&mut self, states: &DoorStates) {
        for (i, &(closed, open)) in self.doors.iter().enumerate() {
            let is_open = states.is_open(i);
            if let Some(c) = self.world.colliders.get_mut(closed) {
                c.set_enabled(!is_open);
            }
            if let Some(c) = self.world.colliders.get_mut(open) {
                c.set_enabled(is_open);
            }
        }
    }

    /// Where the robot must be after the next step.
    pub fn set_robot_next(&mut self, pose: Pose2) {
        if let Some(b) = self.world.bodies.get_mut(self.robot) {
            b.set_next_kinematic_position(pose32(pose));
        }
    }

    /// Where pedestrian `i` must be after the next step.
    pub fn set_pedestrian_next(&mut self, i: usize, centre: Vec2) {
        if let Some(b) = self
            .pedestrians
            .get(i)
            .and_then(|h| self.world.bodies.get_mut(*h))
        {
            b.set_next_kinematic_position(pose32(Pose2::new(centre.x, centre.y, 0.0)));
        }
    }

    /// Advances one step.
    pub fn step(&mut self) {
        self.world.step();
    }

    /// The robot body's pose (f32 precision).
    #[cfg(test)]
    pub fn robot_pose(&self) -> Pose2 {
        let p = self.world.bodies[self.robot].position();
        Pose2::new(
            p.translation.x as f64,
            p.translation.y as f64,
            p.rotation.angle() as f64,
        )
    }

    /// Pedestrian `i`'s centre (f32 precision).
    #[cfg(test)]
    pub fn pedestrian_centre(&self, i: usize) -> Vec2 {
        let t = self.world.bodies[self.pedestrians[i]].translation();
        Vec2::new(t.x as f64, t.y as f64)
    }

    /// Whether the robot's disc overlapped a wall, a door in its current state or a pedestrian
    /// at the start of the last step (rapier finds overlaps before it moves bodies).
    pub fn robot_touches_something(&self) -> bool {
        self.world
            .intersection_pairs_with(self.robot_collider)
            .any(|(_, _, _, _, hit)| hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Door, Wall};

    fn world() -> World {
        World {
            name: "t".into(),
            description: None,
            home: Pose2::IDENTITY,
            walls: vec![Wall {
                id: "w".into(),
                points: vec![Vec2::new(0.0, 1.0), Vec2::new(4.0, 1.0)],
                closed: false,
                thickness_m: 0.1,
            }],
            doors: vec![Door {
                id: "d".into(),
                hinge: Vec2::new(0.0, -1.0),
                width_m: 0.9,
                closed_heading_rad: 0.0,
                open_heading_rad: -std::f64::consts::FRAC_PI_2,
                thickness_m: 0.04,
            }],
            routes: vec![],
            areas: vec![],
        }
    }

    #[test]
    fn robot_follows_kinematic_targets_and_touches_walls_and_doors() {
        let w = world();
        let mut p = Physics::new(&w, 0.25, Pose2::new(2.0, 0.0, 0.0), 1, 0.2, 0.05);
        p.set_pedestrian_next(0, Vec2::new(10.0, 10.0));
        p.step();
        p.step(); // overlaps are found at the start of a step
        assert!(!p.robot_touches_something());
        p.set_robot_next(Pose2::new(2.0, 0.8, 0.5));
        p.step();
        p.step(); // overlaps are found at the start of a step
        let r = p.robot_pose();
        assert!((r.y - 0.8).abs() < 1e-5 && (r.theta - 0.5).abs() < 1e-5);
        assert!(p.robot_touches_something(), "wall at y = 0.95");
        // The closed door spans x 0..0.9 at y = -1.
        p.set_robot_next(Pose2::new(0.45, -0.8, 0.0));
        p.step();
        p.step(); // overlaps are found at the start of a step
        assert!(p.robot_touches_something(), "closed door");
        p.set_doors(&DoorStates { open: vec![true] });
        p.step();
        p.step(); // overlaps are found at the start of a step
        assert!(!p.robot_touches_something(), "open door swung away");
        p.set_pedestrian_next(0, Vec2::new(0.45, -0.5));
        p.step();
        p.step(); // overlaps are found at the start of a step
        assert!(p.robot_touches_something(), "pedestrian");
        assert!((p.pedestrian_centre(0) - Vec2::new(0.45, -0.5)).norm() < 1e-5);
    }
}
