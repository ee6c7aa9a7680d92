//! People walking back and forth: each pedestrian walks a polyline (along the longer side of a
//! world area, at a random offset across it, or an explicit path), turning round at its ends, at
//! a constant speed drawn from the speed range. A person about to walk into the robot turns
//! round instead (people step aside for robots; the robot, in turn, waits for people ahead).

use crate::geom::Vec2;
use crate::sim::rng::SimRng;
use crate::world::Area;
use crate::world::raycast::Disc;
use rand::RngExt;

/// Where pedestrians may walk.
#[derive(Clone, Debug, PartialEq)]
pub enum WalkSource {
    /// A world area: walk along its longer side.
    Area(Area),
    /// An explicit polyline, metres.
    Path(Vec<Vec2>),
}

/// An encounter with the robot ends when the person is this much farther than the keep-away
/// distance from it, metres.
pub const ENCOUNTER_END_M: f64 = 2.0;

/// Pedestrian parameters. Default: none.
#[derive(Clone, Debug, PartialEq)]
pub struct PedestrianConfig {
    /// How many people walk during each lap. Default 0.
    pub count: usize,
    /// Where they walk; pedestrian `i` uses source `i mod len`.
    pub sources: Vec<WalkSource>,
    /// Walking speed range, m/s. Default 0.5..1.2.
    pub speed_min_m_s: f64,
    pub speed_max_m_s: f64,
    /// Disc radius, metres. Default 0.2.
    pub radius_m: f64,
}

impl Default for PedestrianConfig {
    fn default() -> Self {
        PedestrianConfig {
            count: 0,
            sources: Vec::new(),
            speed_min_m_s: 0.5,
            speed_max_m_s: 1.2,
            radius_m: 0.2,
        }
    }
}

/// One walking person.
#[derive(Clone, Debug, PartialEq)]
pub struct Pedestrian {
    path: Vec<Vec2>,
    /// Arc length at each vertex.
    cum: Vec<f64>,
    pub speed_m_s: f64,
    /// Where along the out-and-back cycle (length 2 × path length) the person is, metres.
    cycle_m: f64,
    /// +1 walking forward along the cycle, -1 after turning round for the robot.
    sense: f64,
    /// Already turned round for the robot during this encounter (the robot has not been more
    /// than [`ENCOUNTER_END_M`] beyond the keep-away distance since); blocked again, the person
    /// squeezes past instead of turning again (at a path's end both ways lead towards the robot).
    turned: bool,
    /// Squeezing past the robot: keeps walking until the robot is behind.
    squeezing: bool,
    pub radius_m: f64,
}

impl Pedestrian {
    pub fn new(path: Vec<Vec2>, speed_m_s: f64, phase_m: f64, radius_m: f64) -> Self {
        let mut cum = Vec::with_capacity(path.len());
        let mut acc = 0.0;
        for (i, p) in path.iter().enumerate() {
            if i > 0 {
                acc += (p - path[i - 1]).norm();
            }
            cum.push(acc);
        }
        Pedestrian {
            path,
            cum,
            speed_m_s,
            cycle_m: phase_m,
            sense: 1.0,
            turned: false,
            squeezing: false,
            radius_m,
        }
    }

    fn length_m(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    fn at_cycle(&self, c: f64) -> Vec2 {
        let len = self.length_m();
        if self.path.is_empty() {
            return Vec2::zeros();
        }
        if len <= 0.0 {
            return self.path[0];
        }
        let c = c.rem_euclid(2.0 * len);
        let s = if c > len { 2.0 * len - c } else { c };
        let i = match self.cum.partition_point(|&x| x <= s) {
            0 => 0,
            k => (k - 1).min(self.path.len() - 2),
        };
        let seg = self.cum[i + 1] - self.cum[i];
        let f = if seg > 0.0 {
            (s - self.cum[i]) / seg
        } else {
            0.0
        };
        self.path[i] + (self.path[i + 1] - self.path[i]) * f.clamp(0.0, 1.0)
    }

    /// Current centre.
    pub fn position(&self) -> Vec2 {
        self.at_cycle(self.cycle_m)
    }

    /// Walks for `dt` seconds. A step that would bring the person closer than `keep_away_m`
    /// (centre to centre) to `robot`, and closer than now, is not taken: the person turns round
    /// instead. If they are still heading for the robot right after turning (at the end of a
    /// path), they squeeze past it.
    pub fn advance(&mut self, dt: f64, robot: Vec2, keep_away_m: f64) {
        let next = self.cycle_m + self.sense * self.speed_m_s * dt;
        let (now_d, next_d) = (
            (self.position() - robot).norm(),
            (self.at_cycle(next) - robot).norm(),
        );
        let blocked = next_d < keep_away_m && next_d < now_d;
        if now_d > keep_away_m + ENCOUNTER_END_M {
            self.turned = false;
        }
        if blocked && !self.squeezing && !self.turned {
            self.sense = -self.sense;
            self.turned = true;
        } else {
            self.squeezing = blocked;
            let len2 = 2.0 * self.length_m();
            self.cycle_m = if len2 > 0.0 {
                next.rem_euclid(len2)
            } else {
                0.0
            };
        }
    }

    pub fn disc(&self) -> Disc {
        Disc {
            centre: self.position(),
            radius_m: self.radius_m,
        }
    }
}

/// Draws the pedestrians of one lap.
pub fn draw(cfg: &PedestrianConfig, rng: &mut SimRng) -> Vec<Pedestrian> {
    if cfg.sources.is_empty() {
        return Vec::new();
    }
    (0..cfg.count)
        .map(|i| {
            let r = cfg.radius_m;
            let path = match &cfg.sources[i % cfg.sources.len()] {
                WalkSource::Path(p) => p.clone(),
                WalkSource::Area(a) => {
                    let (w, h) = (a.max.x - a.min.x, a.max.y - a.min.y);
                    let across = |lo: f64, hi: f64, rng: &mut SimRng| {
                        if hi - lo > 2.0 * r {
                            rng.random_range(lo + r..=hi - r)
                        } else {
                            (lo + hi) / 2.0
                        }
                    };
                    let along = |lo: f64, hi: f64| {
                        if hi - lo > 2.0 * r {
                            (lo + r, hi - r)
                        } else {
                            ((lo + hi) / 2.0, (lo + hi) / 2.0)
                        }
                    };
                    if w >= h {
                        let y = across(a.min.y, a.max.y, rng);
                        let (x0, x1) = along(a.min.x, a.max.x);
                        vec![Vec2::new(x0, y), Vec2::new(x1, y)]
                    } else {
                        let x = across(a.min.x, a.max.x, rng);
                        let (y0, y1) = along(a.min.y, a.max.y);
                        vec![Vec2::new(x, y0), Vec2::new(x, y1)]
                    }
                }
            };
            let (lo, hi) = (cfg.speed_min_m_s, cfg.speed_max_m_s.max(cfg.speed_min_m_s));
            let speed = if hi > lo {
                rng.random_range(lo..=hi)
            } else {
                lo
            };
            let p = Pedestrian::new(path, speed, 0.0, r);
            let cycle = 2.0 * p.length_m();
            // The scenario's coordinate limit keeps the path's length finite.
            debug_assert!(cycle.is_finite(), "walking path of length {cycle}");
            let phase = if cycle > 0.0 {
                rng.random_range(0.0..cycle)
            } else {
                0.0
            };
            Pedestrian {
                cycle_m: phase,
                ..p
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walks_back_and_forth() {
        let mut p = Pedestrian::new(
            vec![Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0)],
            1.0,
            0.0,
            0.2,
        );
        let far = Vec2::new(100.0, 100.0);
        let at = |p: &mut Pedestrian, secs: usize| {
            for _ in 0..secs * 4 {
                p.advance(0.25, far, 0.6);
            }
            p.position().x
        };
        assert!((at(&mut p, 1) - 1.0).abs() < 1e-12);
        assert!((at(&mut p, 4) - 3.0).abs() < 1e-12);
        assert!((at(&mut p, 4) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn turns_round_before_walking_into_the_robot() {
        let mut p = Pedestrian::new(
            vec![Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0)],
            1.0,
            0.0,
            0.2,
        );
        let robot = Vec2::new(5.0, 0.0);
        for _ in 0..200 {
            p.advance(0.05, robot, 0.6);
            assert!((p.position() - robot).norm() >= 0.6 - 1e-9);
        }
        assert!(p.position().x < 4.5);
    }

    /// At the end of its path both ways lead to the robot: the person squeezes past rather
    /// than standing in front of the robot for ever.
    #[test]
    fn squeezes_past_the_robot_at_the_end_of_its_path() {
        let mut p = Pedestrian::new(
            vec![Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0)],
            1.0,
            0.0,
            0.2,
        );
        let robot = Vec2::new(0.9, 0.0);
        for _ in 0..100 {
            p.advance(0.05, robot, 0.6);
        }
        assert!(p.position().x > 2.0, "stuck at {:?}", p.position());
    }
}
