//! Lap variation: a real robot does not re-drive its route to the centimetre at one speed. Each
//! lap gets its own plan ([`LapPlan`]), drawn from the lap's seeded stream:
//!
//! - **lane**: every waypoint is shifted across the corridor, within the room measured at that
//!   waypoint ([`LaneRoom`]: the largest shift, each side, that keeps the robot's disc
//!   `lane_margin_m` clear of every wall and every door panel, open or closed). A lap leans to
//!   one side as a whole (one draw per lap) plus a draw per waypoint; a shifted leg that would
//!   come closer than the margin to an obstacle is pulled back towards the route until it is
//!   clear (the unshifted route is what the world validator proves clear);
//! - **speed**: the lap's cruise speed is scaled by `1 + U(±lap_speed_spread_ratio)`, and along
//!   the lap by `1 + speed_wave_ratio · w(s)`, a smooth random wave of arc length (|w| ≤ 1,
//!   wavelengths 6–25 m);
//! - **stops**: short stops (a person, a door) at places drawn with exponential gaps of mean
//!   `stop_spacing_m`, each lasting `U(0.3, 1) · stop_duration_s`;
//! - **turns on the spot**: at places drawn with exponential gaps of mean `spin_spacing_m`, the
//!   robot stops and turns on the spot by `U(90°, spin_angle_deg)` either way, then the
//!   controller turns it back onto its path;
//! - **corners on the spot**: each lap turns on the spot at a share `corner_spin_ratio` of the
//!   route's corners of 60° or more ([`corner_spins`]), where it would otherwise drive an arc;
//! - **weave**: real robots sway about their lane (issue 28: median heading 2–10° off the
//!   corridor on five real logs, 2–7 cm of weave per metre, most of the heading's variance at
//!   wavelengths of 0.5–5 m). The lane is offset sideways by a sum of [`WEAVE_WAVES`] sinusoids
//!   of arc length with wavelengths drawn log-uniformly in `weave_wavelength_min_m` to
//!   `weave_wavelength_max_m`, whose slopes add up to at most `weave_heading_deg`, under a slow
//!   envelope (wavelengths 10–40 m) that calms `weave_envelope_ratio` of it in stretches, as real
//!   robots weave in some places and drive straight in others. The offset never exceeds the room
//!   a shifted leg leaves beyond the lane margin (measured along the whole leg), so the weave
//!   keeps the same clearance from walls and doors as the lanes; the controller follows its
//!   curvature as well as its offset (see [`PathShape::curvature`]).
//!
//! Everything is off by default ([`LapVariationConfig::default`]); scenarios A, B and C turn it
//! on in their `[robot]` tables, or name a preset (`lap_variation = "smooth"` or
//! `"real-weave"`, [`LapVariationConfig::preset`]).

use crate::geom::{Segment, Vec2};
use crate::sim::rng::SimRng;
use crate::sim::robot::{RouteTracker, Wander};
use crate::world::geometry::{SegmentIndex, ThickSegment};
use crate::world::{Route, World};
use rand::RngExt;

/// Knobs of lap variation (the `[robot]` keys of the same names). All off by default.
#[derive(Clone, Debug, PartialEq)]
pub struct LapVariationConfig {
    /// Share (0–1) of the room measured at each waypoint that a lap's lane may use. Default 0
    /// (the robot follows the route's waypoints).
    pub lane_offset_ratio: f64,
    /// Clearance beyond the robot's radius a shifted lane keeps from walls and doors, metres.
    /// Default 0.25.
    pub lane_margin_m: f64,
    /// A lap's cruise speed is scaled by 1 + U(±this). Default 0.
    pub lap_speed_spread_ratio: f64,
    /// Along a lap, speed is scaled by 1 + this · (a smooth wave in [-1, 1]). Default 0.
    pub speed_wave_ratio: f64,
    /// Mean distance between short stops, metres; 0 means no stops. Default 0.
    pub stop_spacing_m: f64,
    /// Longest short stop, seconds (each lasts U(0.3, 1) × this). Default 4.
    pub stop_duration_s: f64,
    /// Mean distance between turns on the spot, metres; 0 means none. Default 0.
    pub spin_spacing_m: f64,
    /// Largest turn on the spot, radians (file: `spin_angle_deg`). Default 360°.
    pub spin_angle_rad: f64,
    /// Smallest turn on the spot, radians (file: `spin_angle_min_deg`). Default 90°.
    pub spin_angle_min_rad: f64,
    /// Share (0–1) of the route's corners (a heading change of at least the robot's
    /// `short_leg_spin_turn_rad`, 60°) a lap turns on the spot at, as real robots often do,
    /// rather than on an arc; drawn per lap and corner. Default 0.
    pub corner_spin_ratio: f64,
    /// Largest heading the weave asks of the robot against its lane (the sum of its waves'
    /// slopes), radians (file: `weave_heading_deg`); 0 means no weave. Default 0.
    pub weave_heading_rad: f64,
    /// Shortest wavelength of the weave, metres. Default 0.5.
    pub weave_wavelength_min_m: f64,
    /// Longest wavelength of the weave, metres. Default 5.
    pub weave_wavelength_max_m: f64,
    /// Share (0–1) of the weave a slow envelope takes away in calm stretches (0: the weave is
    /// as strong everywhere). Default 0.
    pub weave_envelope_ratio: f64,
}

impl Default for LapVariationConfig {
    fn default() -> Self {
        LapVariationConfig {
            lane_offset_ratio: 0.0,
            lane_margin_m: 0.25,
            lap_speed_spread_ratio: 0.0,
            speed_wave_ratio: 0.0,
            stop_spacing_m: 0.0,
            stop_duration_s: 4.0,
            spin_spacing_m: 0.0,
            spin_angle_rad: std::f64::consts::TAU,
            spin_angle_min_rad: std::f64::consts::FRAC_PI_2,
            corner_spin_ratio: 0.0,
            weave_heading_rad: 0.0,
            weave_wavelength_min_m: 0.5,
            weave_wavelength_max_m: 5.0,
            weave_envelope_ratio: 0.0,
        }
    }
}

/// Number of sinusoids in a lap's weave.
pub const WEAVE_WAVES: usize = 6;

impl LapVariationConfig {
    /// The names [`LapVariationConfig::preset`] knows (`lap_variation = "…"` in `[robot]`).
    pub const PRESETS: [&'static str; 3] = ["none", "smooth", "real-weave"];

    /// A named set of lap variation keys, which the `[robot]` table's own keys then override:
    /// `none` (all off), `smooth` (the lanes, speeds, stops and rare turns on the spot of
    /// scenarios A, B and C: laps that do not weave), `real-weave` (`smooth` plus a weave and
    /// turns on the spot tuned on the Intel log's corrected path; RESULTS.md gives the figures
    /// and the Kolmogorov–Smirnov distances to the five real logs).
    pub fn preset(name: &str) -> Option<Self> {
        let smooth = LapVariationConfig {
            lane_offset_ratio: 0.8,
            lap_speed_spread_ratio: 0.2,
            speed_wave_ratio: 0.25,
            stop_spacing_m: 60.0,
            stop_duration_s: 4.0,
            spin_spacing_m: 200.0,
            ..LapVariationConfig::default()
        };
        match name {
            "none" => Some(LapVariationConfig::default()),
            "smooth" => Some(smooth),
            "real-weave" => Some(LapVariationConfig {
                spin_spacing_m: 20.0,
                spin_angle_min_rad: 45f64.to_radians(),
                spin_angle_rad: 180f64.to_radians(),
                corner_spin_ratio: 1.0,
                weave_heading_rad: 50f64.to_radians(),
                weave_envelope_ratio: 0.8,
                ..smooth
            }),
            _ => None,
        }
    }
}

/// Every wall and door panel (both states) as thick segments: what a lane must keep clear of.
pub fn obstacles(world: &World) -> SegmentIndex {
    let mut items = Vec::new();
    for w in &world.walls {
        items.extend(w.segments().into_iter().map(|seg| ThickSegment {
            seg,
            half_thickness_m: w.thickness_m / 2.0,
        }));
    }
    for d in &world.doors {
        for open in [false, true] {
            items.push(ThickSegment {
                seg: d.panel(open),
                half_thickness_m: d.thickness_m / 2.0,
            });
        }
    }
    SegmentIndex::new(items)
}

/// How far each waypoint of a route may move across its corridor, each side.
#[derive(Clone, Debug, PartialEq)]
pub struct LaneRoom {
    /// Unit direction of a positive shift at each waypoint (left of the route, on the bisector).
    pub normals: Vec<Vec2>,
    /// Room to the left (along `normals`) and to the right, metres.
    pub room_m: Vec<(f64, f64)>,
}

/// Step of the room search, metres.
const ROOM_STEP_M: f64 = 0.05;
/// Largest shift looked for, metres.
const ROOM_MAX_M: f64 = 3.0;

impl LaneRoom {
    /// Measures the room at every waypoint: walking out along the normal in 5 cm steps while
    /// the robot's disc stays `clearance_m` clear of `obstacles`.
    pub fn measure(route: &Route, obstacles: &SegmentIndex, clearance_m: f64) -> Self {
        let n = route.waypoints.len();
        let mut normals = Vec::with_capacity(n);
        let mut room_m = Vec::with_capacity(n);
        for i in 0..n {
            let p = route.waypoints[i];
            let prev = route.waypoints[(i + n - 1) % n];
            let next = route.waypoints[(i + 1) % n];
            let unit = |v: Vec2| v / v.norm().max(1e-12);
            let along = unit(unit(p - prev) + unit(next - p));
            let normal = Vec2::new(-along.y, along.x);
            let free = |t: f64| {
                let q = p + normal * t;
                obstacles
                    .nearest_within(Segment::new(q, q), clearance_m)
                    .is_none()
            };
            let walk = |sign: f64| {
                let mut t = 0.0;
                while t + ROOM_STEP_M <= ROOM_MAX_M && free(sign * (t + ROOM_STEP_M)) {
                    t += ROOM_STEP_M;
                }
                t
            };
            normals.push(normal);
            room_m.push((walk(1.0), walk(-1.0)));
        }
        LaneRoom { normals, room_m }
    }
}

/// What the robot does differently in one lap.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LapPlan {
    /// Displacement of each waypoint.
    shifts: Vec<Vec2>,
    /// The older sinusoidal wander, on top of the lane (0 unless `path_wander_m` is set).
    wander: Wander,
    /// Cruise speed factor of the whole lap.
    lap_speed: f64,
    speed_wave_ratio: f64,
    speed_wave: Wander,
    /// (absolute arc length, seconds), in arc order.
    stops: Vec<(f64, f64)>,
    /// (absolute arc length, signed radians), in arc order.
    spins: Vec<(f64, f64)>,
    /// The sway about the lane (none unless `weave_heading_deg` is set).
    weave: Weave,
    /// Largest weave offset at each waypoint, metres: the room the shifted legs on either side
    /// leave beyond the clearance.
    weave_room_m: Vec<f64>,
}

/// Where a lap plan says the robot should be and how fast.
pub trait PathShape {
    /// The target point at absolute arc length `s` of the tracker's route.
    fn target(&self, tracker: &RouteTracker, s: f64) -> Vec2;
    /// Factor on the cruise speed at absolute arc length `s`.
    fn speed_factor(&self, s: f64) -> f64;
    /// Curvature the path adds to the route's at absolute arc length `s`, 1/m (positive to
    /// the left): the controller steers it ahead of its pursuit, so a short sway is driven
    /// rather than cut.
    fn curvature(&self, _tracker: &RouteTracker, _s: f64) -> f64 {
        0.0
    }
}

impl LapPlan {
    /// A plan that only wanders (`path_wander_m`), as before lap variation existed.
    pub fn wander_only(wander: Wander) -> Self {
        LapPlan {
            wander,
            lap_speed: 1.0,
            ..LapPlan::default()
        }
    }

    /// Draws the plan of a lap covering absolute arc lengths `[start_m, start_m + length_m)`.
    pub fn draw(
        cfg: &LapVariationConfig,
        lane: (&LaneRoom, &Route, &SegmentIndex, f64),
        (start_m, length_m): (f64, f64),
        wander: Wander,
        rng: &mut SimRng,
    ) -> Self {
        let (room, route, obstacles, clearance_m) = lane;
        let shifts = draw_shifts(cfg.lane_offset_ratio, room, rng);
        let shifts = pull_back(route, obstacles, clearance_m, shifts);
        let spread = cfg.lap_speed_spread_ratio.clamp(0.0, 0.9);
        let lap_speed = 1.0
            + if spread > 0.0 {
                rng.random_range(-spread..spread)
            } else {
                0.0
            };
        let speed_wave = Wander::draw_with_wavelengths(1.0, (6.0, 25.0), rng);
        let stops = events(cfg.stop_spacing_m, (start_m, length_m), rng)
            .into_iter()
            .map(|s| (s, cfg.stop_duration_s * rng.random_range(0.3..1.0)))
            .collect();
        let lo = cfg.spin_angle_min_rad.min(cfg.spin_angle_rad);
        let spins = events(cfg.spin_spacing_m, (start_m, length_m), rng)
            .into_iter()
            .map(|s| {
                let a = if cfg.spin_angle_rad > lo {
                    rng.random_range(lo..cfg.spin_angle_rad)
                } else {
                    lo
                };
                (s, if rng.random_bool(0.5) { a } else { -a })
            })
            .collect();
        // Drawn last, and only when on, so laps without a weave keep their draws.
        let weave = Weave::draw(cfg, rng);
        let weave_room_m = weave_room(route, obstacles, clearance_m, &shifts, weave.reach_m);
        LapPlan {
            shifts,
            wander,
            lap_speed,
            speed_wave_ratio: cfg.speed_wave_ratio.clamp(0.0, 0.9),
            speed_wave,
            stops,
            spins,
            weave,
            weave_room_m,
        }
    }

    /// The weave's sideways offset at absolute arc `s`, metres: within the room of the leg.
    fn weave_offset_m(&self, tracker: &RouteTracker, s: f64) -> f64 {
        if self.weave.reach_m <= 0.0 || self.weave_room_m.is_empty() {
            return 0.0;
        }
        let (i, t) = tracker.locate(s);
        let j = (i + 1) % self.weave_room_m.len();
        let room = self.weave_room_m[i] * (1.0 - t) + self.weave_room_m[j] * t;
        self.weave.offset_m(s) * (room / self.weave.reach_m).min(1.0)
    }

    /// The first stop at or before arc `s` not taken yet (removes it): its duration.
    pub fn take_stop(&mut self, s: f64) -> Option<f64> {
        take_due(&mut self.stops, s)
    }

    /// The first turn on the spot at or before arc `s` not taken yet (removes it): its angle.
    pub fn take_spin(&mut self, s: f64) -> Option<f64> {
        take_due(&mut self.spins, s)
    }

    /// Displacement of the route point at absolute arc `s`: the waypoint shifts interpolated
    /// along the leg.
    fn shift_at(&self, tracker: &RouteTracker, s: f64) -> Vec2 {
        if self.shifts.is_empty() {
            return Vec2::zeros();
        }
        let (i, t) = tracker.locate(s);
        let j = (i + 1) % self.shifts.len();
        self.shifts[i] * (1.0 - t) + self.shifts[j] * t
    }
}

impl PathShape for LapPlan {
    fn target(&self, tracker: &RouteTracker, s: f64) -> Vec2 {
        let (on_route, dir) = tracker.point_at(s);
        let side = self.wander.offset_m(s) + self.weave_offset_m(tracker, s);
        on_route + self.shift_at(tracker, s) + Vec2::new(-dir.y, dir.x) * side
    }

    fn curvature(&self, tracker: &RouteTracker, s: f64) -> f64 {
        if self.weave.reach_m <= 0.0 {
            return 0.0;
        }
        // The offset's second derivative (the curvature of a gentle sway), by differences.
        let h = 0.05;
        let y = |s| self.weave_offset_m(tracker, s);
        (y(s + h) - 2.0 * y(s) + y(s - h)) / (h * h)
    }

    fn speed_factor(&self, s: f64) -> f64 {
        self.lap_speed * (1.0 + self.speed_wave_ratio * self.speed_wave.offset_m(s))
    }
}

fn take_due(list: &mut Vec<(f64, f64)>, s: f64) -> Option<f64> {
    match list.first() {
        Some(&(at, v)) if at <= s => {
            list.remove(0);
            Some(v)
        }
        _ => None,
    }
}

/// Arc positions in `[start, start + length)` with exponential gaps of mean `spacing_m` (none
/// when the spacing is 0).
fn events(spacing_m: f64, (start_m, length_m): (f64, f64), rng: &mut SimRng) -> Vec<f64> {
    let mut out = Vec::new();
    if spacing_m <= 0.0 || !spacing_m.is_finite() {
        return out;
    }
    // The scenario's limits (0 or at least 1 m) bound the events per lap to its length.
    debug_assert!(spacing_m >= 1e-3, "event spacing {spacing_m} m");
    let mut s = start_m;
    loop {
        let u: f64 = rng.random_range(f64::EPSILON..1.0);
        s += -spacing_m * u.ln();
        if s >= start_m + length_m {
            return out;
        }
        out.push(s);
    }
}

/// The waypoints a lap turns on the spot at: those `base` marks (the route's own rule), and
/// each other corner of at least `robot.short_leg_spin_turn_rad` with probability
/// `corner_spin_ratio` (nothing is drawn when it is 0).
pub fn corner_spins(
    route: &Route,
    robot: &crate::sim::robot::RobotConfig,
    (base, room_m): (&[bool], &[f64]),
    rng: &mut SimRng,
) -> Vec<bool> {
    let ratio = robot.variation.corner_spin_ratio.clamp(0.0, 1.0);
    if ratio == 0.0 {
        return base.to_vec();
    }
    let sharp = crate::sim::robot::RobotConfig {
        spin_turn_rad: robot.short_leg_spin_turn_rad,
        ..robot.clone()
    };
    let corners = crate::sim::robot::spin_waypoints(route, &sharp, room_m);
    base.iter()
        .zip(corners)
        .map(|(&b, c)| b || (c && rng.random_bool(ratio)))
        .collect()
}

/// A lap's sway about its lane: `offset(s) = e(s) · Σₖ (θₖ λₖ / 2π) sin(2π s / λₖ + φₖ)`, so
/// its slope is at most Σ θₖ = `weave_heading_rad`; `e(s)` in [1 − r, 1] is the slow envelope.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Weave {
    /// (heading amplitude rad, wavelength m, phase rad) of each wave.
    waves: Vec<(f64, f64, f64)>,
    envelope: Wander,
    envelope_ratio: f64,
    /// The largest offset the waves can reach, metres.
    reach_m: f64,
}

impl Weave {
    /// The weave of one lap (none when `weave_heading_rad` is 0; then nothing is drawn).
    fn draw(cfg: &LapVariationConfig, rng: &mut SimRng) -> Self {
        let heading = cfg.weave_heading_rad;
        if heading <= 0.0 {
            return Weave::default();
        }
        let lo = cfg.weave_wavelength_min_m.max(0.1);
        let hi = cfg.weave_wavelength_max_m.max(lo * 1.001);
        let mut waves: Vec<(f64, f64, f64)> = (0..WEAVE_WAVES)
            .map(|_| {
                let a: f64 = rng.random_range(0.2..1.0);
                let lambda = lo * (hi / lo).powf(rng.random_range(0.0..1.0));
                (a, lambda, rng.random_range(0.0..std::f64::consts::TAU))
            })
            .collect();
        let total: f64 = waves.iter().map(|w| w.0).sum();
        for w in &mut waves {
            w.0 *= heading / total;
        }
        let reach_m = waves.iter().map(|w| amplitude_m(*w)).sum();
        Weave {
            waves,
            envelope: Wander::draw_with_wavelengths(1.0, (10.0, 40.0), rng),
            envelope_ratio: cfg.weave_envelope_ratio.clamp(0.0, 1.0),
            reach_m,
        }
    }

    /// Sideways offset at arc `s`, metres (positive to the left), |offset| ≤ `reach_m`.
    fn offset_m(&self, s: f64) -> f64 {
        let e = 1.0 - self.envelope_ratio * 0.5 * (1.0 + self.envelope.offset_m(s));
        e * self
            .waves
            .iter()
            .map(|&w| amplitude_m(w) * (std::f64::consts::TAU * s / w.1 + w.2).sin())
            .sum::<f64>()
    }
}

/// The sideways amplitude of a wave whose slope peaks at `heading` radians.
fn amplitude_m((heading, lambda, _): (f64, f64, f64)) -> f64 {
    heading * lambda / std::f64::consts::TAU
}

/// The largest weave offset at each waypoint: on each shifted leg, the clearance beyond
/// `clearance_m` from every obstacle (at most `reach_m`), the smaller of the two legs meeting
/// at the waypoint. Empty when there is no weave.
fn weave_room(
    route: &Route,
    obstacles: &SegmentIndex,
    clearance_m: f64,
    shifts: &[Vec2],
    reach_m: f64,
) -> Vec<f64> {
    let n = route.waypoints.len();
    if reach_m <= 0.0 || n == 0 {
        return Vec::new();
    }
    let at = |i: usize| route.waypoints[i] + shifts.get(i).copied().unwrap_or_else(Vec2::zeros);
    let legs: Vec<f64> = (0..n)
        .map(|i| {
            let leg = Segment::new(at(i), at((i + 1) % n));
            obstacles
                .nearest_within(leg, clearance_m + reach_m)
                .map_or(reach_m, |(_, c)| (c - clearance_m).clamp(0.0, reach_m))
        })
        .collect();
    (0..n).map(|i| legs[i].min(legs[(i + n - 1) % n])).collect()
}

/// Per-waypoint shifts: a lean of the whole lap plus a draw per waypoint, in [-1, 1] of the
/// room on that side, times `ratio`.
fn draw_shifts(ratio: f64, room: &LaneRoom, rng: &mut SimRng) -> Vec<Vec2> {
    let ratio = ratio.clamp(0.0, 1.0);
    if ratio == 0.0 {
        return Vec::new();
    }
    let lean: f64 = rng.random_range(-1.0..1.0);
    room.normals
        .iter()
        .zip(&room.room_m)
        .map(|(n, &(left, right))| {
            let u = (0.6 * lean + 0.6 * rng.random_range(-1.0..1.0)).clamp(-1.0, 1.0);
            let side = if u >= 0.0 { left } else { right };
            n * (u * side * ratio)
        })
        .collect()
}

/// Halves the shifts of both ends of any shifted leg that comes within `clearance_m` of an
/// obstacle, until every leg is clear (at worst the unshifted route, which the world validator
/// proves clear).
fn pull_back(
    route: &Route,
    obstacles: &SegmentIndex,
    clearance_m: f64,
    mut shifts: Vec<Vec2>,
) -> Vec<Vec2> {
    let n = shifts.len();
    if n == 0 {
        return shifts;
    }
    for pass in 0..12 {
        let mut clean = true;
        for i in 0..n {
            let j = (i + 1) % n;
            let leg = Segment::new(
                route.waypoints[i] + shifts[i],
                route.waypoints[j] + shifts[j],
            );
            if obstacles.nearest_within(leg, clearance_m).is_some() {
                clean = false;
                let k = if pass == 11 { 0.0 } else { 0.5 };
                shifts[i] *= k;
                shifts[j] *= k;
            }
        }
        if clean {
            break;
        }
    }
    shifts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::rng::{Purpose, stream};
    use crate::world::Wall;

    /// A 20 × 10 m loop in a corridor 3 m wide (walls at ±1.5 m from the route).
    fn corridor() -> (Route, SegmentIndex) {
        let route = Route {
            id: "r".into(),
            waypoints: vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(20.0, 0.0),
                Vec2::new(20.0, 10.0),
                Vec2::new(0.0, 10.0),
            ],
        };
        let rect = |lo: f64, hi_x: f64, hi_y: f64| Wall {
            id: "w".into(),
            points: vec![
                Vec2::new(lo, lo),
                Vec2::new(hi_x, lo),
                Vec2::new(hi_x, hi_y),
                Vec2::new(lo, hi_y),
            ],
            closed: true,
            thickness_m: 0.1,
        };
        let walls = [rect(-1.5, 21.5, 11.5), rect(1.5, 18.5, 8.5)];
        let items = walls
            .iter()
            .flat_map(|w| w.segments())
            .map(|seg| ThickSegment {
                seg,
                half_thickness_m: 0.05,
            })
            .collect();
        (route, SegmentIndex::new(items))
    }

    #[test]
    fn room_is_the_corridor_width_less_the_clearance() {
        let (route, obs) = corridor();
        let room = LaneRoom::measure(&route, &obs, 0.5);
        // Corner waypoints move along the diagonal: inwards until the inner wall's corner
        // (1.5, 1.5) is 0.55 m from the centre (t = 1.5·√2 − 0.55), outwards until the outer
        // walls at −1.5 are (t = (1.5 − 0.05 − 0.5)·√2); at most one 5 cm step short.
        let inward = 1.5 * std::f64::consts::SQRT_2 - 0.55;
        let outward = 0.95 * std::f64::consts::SQRT_2;
        for &(l, r) in &room.room_m {
            assert!(l <= inward && inward - l < 0.05, "{l} vs {inward}");
            assert!(r <= outward && outward - r < 0.05, "{r} vs {outward}");
        }
    }

    #[test]
    fn lanes_vary_between_laps_and_stay_clear() {
        let (route, obs) = corridor();
        let room = LaneRoom::measure(&route, &obs, 0.5);
        let cfg = LapVariationConfig {
            lane_offset_ratio: 1.0,
            ..LapVariationConfig::default()
        };
        let mut firsts = Vec::new();
        for lap in 0..20 {
            let mut rng = stream(1, 0, lap, Purpose::LapVariation);
            let plan = LapPlan::draw(
                &cfg,
                (&room, &route, &obs, 0.5),
                (0.0, 60.0),
                Wander::default(),
                &mut rng,
            );
            for i in 0..4 {
                let leg = Segment::new(
                    route.waypoints[i] + plan.shifts[i],
                    route.waypoints[(i + 1) % 4] + plan.shifts[(i + 1) % 4],
                );
                assert!(obs.nearest_within(leg, 0.5).is_none(), "lap {lap} leg {i}");
            }
            firsts.push(plan.shifts[0].norm());
        }
        let spread = firsts.iter().cloned().fold(0.0, f64::max);
        assert!(spread > 0.6, "lanes should use the corridor: {firsts:?}");
    }

    #[test]
    fn stops_and_spins_fall_inside_the_lap_at_the_mean_spacing() {
        let cfg = LapVariationConfig {
            stop_spacing_m: 10.0,
            spin_spacing_m: 50.0,
            ..LapVariationConfig::default()
        };
        let (route, obs) = corridor();
        let room = LaneRoom::measure(&route, &obs, 0.5);
        let (mut stops, mut spins) = (0, 0);
        for lap in 0..50 {
            let mut rng = stream(2, 0, lap, Purpose::LapVariation);
            let mut plan = LapPlan::draw(
                &cfg,
                (&room, &route, &obs, 0.5),
                (100.0, 60.0),
                Wander::default(),
                &mut rng,
            );
            assert!(
                plan.stops
                    .iter()
                    .all(|&(s, d)| (100.0..160.0).contains(&s) && d > 0.0)
            );
            assert!(plan.take_stop(99.0).is_none());
            stops += plan.stops.len();
            spins += plan.spins.len();
        }
        // 50 laps × 60 m: about 300 stops and 60 spins.
        assert!((200..400).contains(&stops), "{stops}");
        assert!((30..95).contains(&spins), "{spins}");
    }

    #[test]
    fn every_preset_resolves_and_real_weave_targets_keep_clear_of_the_walls() {
        for name in LapVariationConfig::PRESETS {
            assert!(LapVariationConfig::preset(name).is_some(), "{name}");
        }
        assert_eq!(
            LapVariationConfig::preset("smooth")
                .unwrap()
                .weave_heading_rad,
            0.0
        );
        let cfg = LapVariationConfig::preset("real-weave").unwrap();
        let (route, obs) = corridor();
        let room = LaneRoom::measure(&route, &obs, 0.5);
        let tracker = RouteTracker::new(&route, 0);
        let mut widest = 0.0f64;
        for lap in 0..20 {
            let mut rng = stream(3, 0, lap, Purpose::LapVariation);
            let plan = LapPlan::draw(
                &cfg,
                (&room, &route, &obs, 0.5),
                (0.0, 60.0),
                Wander::default(),
                &mut rng,
            );
            for k in 0..600 {
                let s = k as f64 * 0.1;
                let p = plan.target(&tracker, s);
                let near = obs.nearest_within(Segment::new(p, p), 0.5 - 1e-9);
                assert!(
                    near.is_none(),
                    "lap {lap}, arc {s} m: target {p:?} too close"
                );
                widest = widest.max(plan.weave_offset_m(&tracker, s).abs());
            }
        }
        assert!(widest > 0.1, "the weave sways: at most {widest} m");
    }
}
