//! The Pioneer 3-DX: differential-drive kinematics, route tracking on the true trajectory, and a
//! pure-pursuit controller that keeps to cruise speed within the acceleration limits, slows for
//! obstacles ahead and waits for them to clear.
//!
//! **Turning on the spot.** Ordinary corners are driven smoothly: the pure-pursuit target runs
//! `lookahead_m` ahead along the route, so the robot rounds a corner on an arc just inside it.
//! Where the route reverses or turns sharply ([`spin_waypoints`]: a heading change of at least
//! `spin_turn_rad`, 120° by default, or of at least `short_leg_spin_turn_rad`, 60°, when a leg
//! next to the waypoint is shorter than twice the look-ahead or a wall or door is closer to the
//! waypoint than `radius_m + stop_distance_m`, 0.85 m), the robot does what a P3-DX does
//! in a dead end or a narrow corridor: it drives to the waypoint itself, braking to arrive,
//! stops, turns on the spot to the next leg's heading, and drives on. The route tracker treats
//! such a waypoint as a gate: progress never runs past it before the turn nor falls back behind
//! it after, so a route into a dead end and back out along the same line is tracked leg by leg.
//! A wall or person further ahead than the turning point does not stop the robot short of it.

use crate::geom::{Pose2, Segment, Vec2, wrap_angle};
use crate::sim::variation::{LapVariationConfig, PathShape};
use crate::world::Route;
use crate::world::geometry::SegmentIndex;

/// Robot and controller parameters (P3-DX defaults from ARIA/MobileSim).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotConfig {
    /// Body radius, metres. Default 0.25.
    pub radius_m: f64,
    /// Distance between the wheels, metres. Default 0.357.
    pub axle_track_m: f64,
    /// Speed along the route, m/s. Default 0.4.
    pub cruise_speed_m_s: f64,
    /// Speed limit, m/s. Default 1.0.
    pub max_speed_m_s: f64,
    /// Turn rate limit, rad/s. Default 100°/s.
    pub max_turn_rate_rad_s: f64,
    /// Linear acceleration and deceleration limit, m/s². Default 0.3.
    pub accel_m_s2: f64,
    /// Angular acceleration limit, rad/s². Default 100°/s².
    pub turn_accel_rad_s2: f64,
    /// Pure-pursuit look-ahead along the route, metres. Default 0.8.
    pub lookahead_m: f64,
    /// The robot stops when an obstacle is this close ahead of its front, metres. Default 0.6.
    pub stop_distance_m: f64,
    /// It starts slowing when an obstacle is this close ahead of its front, metres. Default 1.2.
    pub slow_distance_m: f64,
    /// A run fails when the robot makes no progress for this long, seconds. Default 30.
    pub blocked_timeout_s: f64,
    /// Simulation time step, seconds. Default 0.05.
    pub step_s: f64,
    /// Largest sideways offset from the route the robot wanders by, metres: each lap it follows
    /// the route shifted sideways by a smooth random function of arc length (a real robot does
    /// not retrace its path to the millimetre). Default 0 (it follows the route exactly).
    pub path_wander_m: f64,
    /// Lanes across the corridor, speed changes, short stops and turns on the spot per lap
    /// (see [`crate::sim::variation`]). Default: all off.
    pub variation: LapVariationConfig,
    /// The robot turns on the spot at a waypoint where the route's heading changes by at least
    /// this much, radians. Default 120° (a reversal is 180°; office corners are 90°).
    pub spin_turn_rad: f64,
    /// ... or by at least this much where a leg next to the waypoint is shorter than twice
    /// `lookahead_m` (a smooth turn would cut across the whole short leg), or where a wall or
    /// door is closer to the waypoint than `radius_m + stop_distance_m` (so narrow that the wall
    /// ahead would stop the robot before it had turned), radians. Default 60°.
    pub short_leg_spin_turn_rad: f64,
}

impl Default for RobotConfig {
    fn default() -> Self {
        RobotConfig {
            radius_m: crate::world::validate::ROBOT_RADIUS_M,
            axle_track_m: 0.357,
            cruise_speed_m_s: 0.4,
            max_speed_m_s: 1.0,
            max_turn_rate_rad_s: 100f64.to_radians(),
            accel_m_s2: 0.3,
            turn_accel_rad_s2: 100f64.to_radians(),
            lookahead_m: 0.8,
            stop_distance_m: 0.6,
            slow_distance_m: 1.2,
            blocked_timeout_s: 30.0,
            step_s: 0.05,
            path_wander_m: 0.0,
            variation: LapVariationConfig::default(),
            spin_turn_rad: 120f64.to_radians(),
            short_leg_spin_turn_rad: 60f64.to_radians(),
        }
    }
}

/// Which waypoints of `route` (driven in its own order) the robot turns on the spot at; see
/// the module docs for the rule. `room_m[k]` is the clearance from waypoint `k` to the nearest
/// wall or door (in either state; [`waypoint_room`]). The one rule both the controller and the
/// route checks use.
pub fn spin_waypoints(route: &Route, cfg: &RobotConfig, room_m: &[f64]) -> Vec<bool> {
    let n = route.waypoints.len();
    let legs = route.legs();
    (0..n)
        .map(|k| {
            let (into, out) = (legs[(k + n - 1) % n], legs[k]);
            let (din, dout) = (into.b - into.a, out.b - out.a);
            if n < 3 || din.norm() < 1e-9 || dout.norm() < 1e-9 {
                return false;
            }
            let turn = wrap_angle(dout.y.atan2(dout.x) - din.y.atan2(din.x)).abs();
            let short = into.length().min(out.length()) < 2.0 * cfg.lookahead_m;
            let narrow = room_m
                .get(k)
                .is_some_and(|&r| r < cfg.radius_m + cfg.stop_distance_m);
            turn >= cfg.spin_turn_rad - 1e-9
                || ((short || narrow) && turn >= cfg.short_leg_spin_turn_rad - 1e-9)
        })
        .collect()
}

/// Clearance from each waypoint of `route` to the nearest of `obstacles` (walls and door
/// panels), metres; infinite where nothing is within 10 m.
pub fn waypoint_room(route: &Route, obstacles: &SegmentIndex) -> Vec<f64> {
    route
        .waypoints
        .iter()
        .map(|&p| {
            obstacles
                .nearest_within(Segment::new(p, p), 10.0)
                .map_or(f64::INFINITY, |(_, c)| c)
        })
        .collect()
}

/// Exact motion of a differential drive at constant (v, ω) for `dt` seconds.
pub fn integrate(pose: Pose2, v: f64, w: f64, dt: f64) -> Pose2 {
    let th = pose.theta;
    let (dx, dy) = if w.abs() < 1e-9 {
        (v * dt * th.cos(), v * dt * th.sin())
    } else {
        let r = v / w;
        let th1 = th + w * dt;
        (r * (th1.sin() - th.sin()), -r * (th1.cos() - th.cos()))
    };
    Pose2::new(pose.x + dx, pose.y + dy, wrap_angle(th + w * dt))
}

/// Wheel speeds (left, right) for body speeds (v, ω), m/s.
pub fn wheel_speeds(v: f64, w: f64, axle_track_m: f64) -> (f64, f64) {
    (v - w * axle_track_m / 2.0, v + w * axle_track_m / 2.0)
}

/// Progress along a closed route, measured by projecting the true position onto the route
/// polyline near the previous projection, unwrapped so that it grows by the route length every
/// lap.
#[derive(Clone, Debug)]
pub struct RouteTracker {
    legs: Vec<Segment>,
    /// Arc length at the start of each leg, from waypoint 0.
    starts: Vec<f64>,
    length_m: f64,
    /// Arc length (from waypoint 0) where the run started.
    origin_m: f64,
    /// Unwrapped progress since the start, metres.
    progress_m: f64,
    /// Arc lengths (from waypoint 0, within one lap, ascending) of the waypoints the robot turns
    /// on the spot at: gates progress does not pass until the turn is done.
    gates_m: Vec<f64>,
    /// Absolute arc length of the last gate passed (the start at first).
    passed_gate_m: f64,
}

impl RouteTracker {
    /// A tracker with a gate at each waypoint `spins` marks (see [`spin_waypoints`]).
    /// Every marked gate is kept, the one at the start waypoint too (a narrow corner there is
    /// turned on the spot when the lap comes back to it).
    pub fn with_gates(route: &Route, start_waypoint: usize, spins: &[bool]) -> Self {
        let mut t = RouteTracker::new(route, start_waypoint);
        t.gates_m = t.gates_at(spins);
        t
    }

    /// Arc lengths of the waypoints `spins` marks.
    fn gates_at(&self, spins: &[bool]) -> Vec<f64> {
        (0..self.starts.len())
            .filter(|&k| spins.get(k).copied().unwrap_or(false))
            .map(|k| self.starts[k])
            .collect()
    }

    /// Replaces the gates with the waypoints `spins` marks, from here on (a lap that turns on
    /// the spot at other corners). A gate within 1 m of the robot is left out unless it was
    /// one already: the robot is past it or about to be.
    pub fn set_gates(&mut self, spins: &[bool]) {
        let here = self.wrap(self.arc_m());
        let near = |g: f64| {
            let d = (g - here).abs();
            d.min(self.length_m - d) < 1.0
        };
        let old = std::mem::take(&mut self.gates_m);
        self.gates_m = self
            .gates_at(spins)
            .into_iter()
            .filter(|&g| !near(g) || old.contains(&g))
            .collect();
        // Every gate behind the robot counts as passed (progress never passes an unturned one).
        self.passed_gate_m = self.passed_gate_m.max(self.arc_m() - 1e-6);
    }

    /// Absolute arc length of the next gate ahead, if the route has any.
    pub fn next_gate_m(&self) -> Option<f64> {
        let first = *self.gates_m.first()?;
        let passed = self.passed_gate_m;
        let base = passed - self.wrap(passed);
        Some(
            self.gates_m
                .iter()
                .map(|g| base + g)
                .find(|&g| g > passed + 1e-9)
                .unwrap_or(base + self.length_m + first),
        )
    }

    /// The turn at the next gate is done: progress moves up to it and the gate is passed.
    pub fn pass_gate(&mut self) {
        if let Some(g) = self.next_gate_m() {
            self.progress_m = self.progress_m.max(g - self.origin_m);
            self.passed_gate_m = g;
        }
    }

    pub fn new(route: &Route, start_waypoint: usize) -> Self {
        let legs = route.legs();
        let mut starts = Vec::with_capacity(legs.len());
        let mut acc = 0.0;
        for l in &legs {
            starts.push(acc);
            acc += l.length();
        }
        let origin_m = starts.get(start_waypoint).copied().unwrap_or(0.0);
        RouteTracker {
            legs,
            starts,
            length_m: acc,
            origin_m,
            progress_m: 0.0,
            gates_m: Vec::new(),
            passed_gate_m: origin_m,
        }
    }

    pub fn length_m(&self) -> f64 {
        self.length_m
    }

    /// Unwrapped progress since the start, metres.
    pub fn progress_m(&self) -> f64 {
        self.progress_m
    }

    fn wrap(&self, s: f64) -> f64 {
        s.rem_euclid(self.length_m)
    }

    /// The leg at arc length `s` (any real, taken modulo the loop) and the fraction of it done.
    pub fn locate(&self, s: f64) -> (usize, f64) {
        let s = self.wrap(s);
        let i = match self.starts.partition_point(|&x| x <= s) {
            0 => 0,
            k => k - 1,
        };
        let len = self.legs[i].length().max(1e-12);
        (i, ((s - self.starts[i]) / len).clamp(0.0, 1.0))
    }

    /// The point at arc length `s` (any real, taken modulo the loop) and the leg's direction.
    pub fn point_at(&self, s: f64) -> (Vec2, Vec2) {
        let s = self.wrap(s);
        let i = self.locate(s).0;
        let leg = self.legs[i];
        let len = leg.length().max(1e-12);
        let dir = (leg.b - leg.a) / len;
        (leg.a + dir * (s - self.starts[i]).min(len), dir)
    }

    /// The pose at the start (the start waypoint, facing along its leg).
    pub fn start_pose(&self) -> Pose2 {
        let (p, d) = self.point_at(self.origin_m);
        Pose2::new(p.x, p.y, d.y.atan2(d.x))
    }

    /// Arc length (absolute, unwrapped) of the current progress.
    pub fn arc_m(&self) -> f64 {
        self.origin_m + self.progress_m
    }

    /// Updates progress from a new true position; only projections within a few metres of the
    /// previous one are considered, so parallel corridors never make it jump.
    pub fn update(&mut self, p: Vec2) -> f64 {
        let window = 3.0;
        let prev = self.wrap(self.arc_m());
        // Between gates: not past the next one, not behind the last one passed.
        let bounds = self
            .next_gate_m()
            .map(|g| (self.passed_gate_m - self.arc_m(), g - self.arc_m()));
        let mut best: Option<(f64, f64)> = None; // (distance, delta)
        for (i, leg) in self.legs.iter().enumerate() {
            let t = leg.project(p);
            let s = self.starts[i] + t * leg.length();
            let mut delta = s - prev;
            let half = self.length_m / 2.0;
            if delta > half {
                delta -= self.length_m;
            } else if delta < -half {
                delta += self.length_m;
            }
            if delta.abs() > window
                || bounds.is_some_and(|(lo, hi)| delta < lo - 1e-9 || delta > hi + 1e-9)
            {
                continue;
            }
            let dist = (p - leg.point_at(t)).norm();
            if best.is_none_or(|(bd, _)| dist < bd) {
                best = Some((dist, delta));
            }
        }
        if let Some((_, delta)) = best {
            self.progress_m += delta;
        }
        self.progress_m
    }
}

/// A lap's sideways wander: offset(s) = amplitude · Σₖ aₖ sin(2π s / λₖ + φₖ) with Σ aₖ = 1,
/// three components of wavelength 8-30 m, so |offset| ≤ amplitude and it varies smoothly.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Wander {
    amplitude_m: f64,
    waves: [(f64, f64, f64); 3],
}

impl Wander {
    /// A wander of at most `amplitude_m`, drawn from `rng`.
    pub fn draw(amplitude_m: f64, rng: &mut crate::sim::rng::SimRng) -> Self {
        Self::draw_with_wavelengths(amplitude_m, (8.0, 30.0), rng)
    }

    /// A wave of at most `amplitude_m` with wavelengths in `[lo, hi)` metres.
    pub fn draw_with_wavelengths(
        amplitude_m: f64,
        (lo, hi): (f64, f64),
        rng: &mut crate::sim::rng::SimRng,
    ) -> Self {
        use rand::RngExt;
        let mut waves = [(0.0, 1.0, 0.0); 3];
        let mut total = 0.0;
        for w in &mut waves {
            let a: f64 = rng.random_range(0.2..1.0);
            let lambda: f64 = rng.random_range(lo..hi);
            let phase: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            *w = (a, lambda, phase);
            total += a;
        }
        for w in &mut waves {
            w.0 /= total;
        }
        Wander { amplitude_m, waves }
    }

    /// Sideways offset at arc length `s`, metres (positive to the left of the route).
    pub fn offset_m(&self, s: f64) -> f64 {
        if self.amplitude_m == 0.0 {
            return 0.0;
        }
        self.amplitude_m
            * self
                .waves
                .iter()
                .map(|(a, l, ph)| a * (std::f64::consts::TAU * s / l + ph).sin())
                .sum::<f64>()
    }
}

/// Turn rate when the target is more than 60° off the heading, rad/s (about 46°/s).
pub const TURN_BACK_RAD_S: f64 = 0.8;

/// The controller's state: current commanded speeds.
#[derive(Clone, Debug, Default)]
pub struct Controller {
    pub v_m_s: f64,
    pub w_rad_s: f64,
}

impl Controller {
    /// New speeds for the next step. `free_ahead_m` is the clear distance in front of the
    /// robot's body along its heading (from its last scan). Before a gate (a waypoint the robot
    /// turns on the spot at, [`RouteTracker::next_gate_m`]) the target stops at the gate, the
    /// robot brakes to arrive there, and what lies beyond the gate does not stop it.
    pub fn command(
        &mut self,
        cfg: &RobotConfig,
        pose: Pose2,
        tracker: &RouteTracker,
        path: &dyn PathShape,
        free_ahead_m: f64,
    ) -> (f64, f64) {
        let dt = cfg.step_s;
        let gate_left_m = tracker
            .next_gate_m()
            .map(|g| g - tracker.arc_m())
            .filter(|&left| left < cfg.lookahead_m + cfg.slow_distance_m + 2.0);
        let mut s = tracker.arc_m() + cfg.lookahead_m;
        if let Some(left) = gate_left_m {
            s = s.min(tracker.arc_m() + left.max(0.0));
        }
        let target = path.target(tracker, s);
        let to = target - pose.position();
        let alpha = wrap_angle(to.y.atan2(to.x) - pose.theta);
        // Speed: cruise (as the lap plan varies it), less when the route bends away, and less
        // near obstacles.
        let cruise = (cfg.cruise_speed_m_s * path.speed_factor(tracker.arc_m()))
            .clamp(0.0, cfg.max_speed_m_s);
        let heading_factor = if alpha.abs() > 60f64.to_radians() {
            0.0
        } else {
            alpha.cos().max(0.0)
        };
        let span = (cfg.slow_distance_m - cfg.stop_distance_m).max(1e-6);
        let mut obstacle_factor = ((free_ahead_m - cfg.stop_distance_m) / span).clamp(0.0, 1.0);
        let mut v_goal_cap = f64::INFINITY;
        if let Some(left) = gate_left_m {
            if free_ahead_m > left {
                obstacle_factor = 1.0;
            }
            v_goal_cap = (2.0 * cfg.accel_m_s2 * left.max(0.0)).sqrt();
        }
        let v_goal = (cruise * heading_factor * obstacle_factor).min(v_goal_cap);
        let dv = cfg.accel_m_s2 * dt;
        let v = v_goal.clamp(self.v_m_s - dv, self.v_m_s + dv);
        // Turn: pure pursuit curvature at (at least) a nominal speed so the robot can line up
        // when it is slow or stopped.
        let ld = to.norm().max(1e-3);
        // Facing away (after a turn on the spot): turn back at a steady rate, since the
        // pursuit curvature vanishes as the target falls behind.
        let w_goal = if heading_factor == 0.0 {
            alpha.signum() * TURN_BACK_RAD_S
        } else {
            // The path's own curvature is steered ahead (feed-forward): pursuit alone cuts a
            // sway shorter than a few look-aheads (measured: median weave 0.7 cm/m, 2.4 with).
            2.0 * v.max(0.15) * alpha.sin() / ld + v * path.curvature(tracker, tracker.arc_m())
        }
        .clamp(-cfg.max_turn_rate_rad_s, cfg.max_turn_rate_rad_s);
        let dw = cfg.turn_accel_rad_s2 * dt;
        let w = w_goal.clamp(self.w_rad_s - dw, self.w_rad_s + dw);
        self.v_m_s = v;
        self.w_rad_s = w;
        (v, w)
    }
}

impl Controller {
    /// Speeds while the robot holds its place: slowing to a stop, turning at `turn_rad_s`
    /// (0 for a plain stop), within the acceleration limits.
    pub fn hold(&mut self, cfg: &RobotConfig, turn_rad_s: f64) -> (f64, f64) {
        let dt = cfg.step_s;
        let dv = cfg.accel_m_s2 * dt;
        let v = 0f64.clamp(self.v_m_s - dv, self.v_m_s + dv);
        let dw = cfg.turn_accel_rad_s2 * dt;
        let w_goal = turn_rad_s.clamp(-cfg.max_turn_rate_rad_s, cfg.max_turn_rate_rad_s);
        let w = w_goal.clamp(self.w_rad_s - dw, self.w_rad_s + dw);
        self.v_m_s = v;
        self.w_rad_s = w;
        (v, w)
    }
}

/// Clear distance ahead of the robot's front from a scan's hit points, given in the robot frame:
/// the nearest hit within a band as wide as the body (plus 5 cm each side) ahead of it.
pub fn free_ahead(cfg: &RobotConfig, hits_in_robot: impl Iterator<Item = Vec2>) -> f64 {
    let half = cfg.radius_m + 0.05;
    hits_in_robot
        .filter(|h| h.x > 0.0 && h.y.abs() < half)
        .map(|h| h.x - cfg.radius_m)
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Route {
        Route {
            id: "r".into(),
            waypoints: vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(10.0, 0.0),
                Vec2::new(10.0, 4.0),
                Vec2::new(0.0, 4.0),
            ],
        }
    }

    #[test]
    fn integrate_goes_straight_and_turns_in_a_circle() {
        let p = integrate(Pose2::IDENTITY, 1.0, 0.0, 2.0);
        assert!((p.x - 2.0).abs() < 1e-12 && p.y.abs() < 1e-12);
        let mut q = Pose2::IDENTITY;
        for _ in 0..50 {
            q = integrate(q, 1.0, std::f64::consts::PI, 0.02);
        }
        // Half a circle of radius 1/π.
        assert!(q.x.abs() < 1e-9 && (q.y - 2.0 / std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn tracker_unwraps_laps_and_starts_at_the_start_waypoint() {
        let r = square();
        let mut t = RouteTracker::new(&r, 1);
        assert_eq!(t.length_m(), 28.0);
        let s = t.start_pose();
        assert!(
            (s.x - 10.0).abs() < 1e-12 && (s.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
        let mut s = 0.0;
        while s < 2.0 * 28.0 {
            s += 0.5;
            let (p, _) = t.point_at(t.arc_m() + 0.5);
            t.update(p);
        }
        assert!((t.progress_m() - 56.0).abs() < 1e-9);
    }
}
