//! People walking back and forth: each pedestrian walks a polyline (along the longer side of a
//! world area, at a random offset across it, or an explicit path), turning round at its ends, at
//! a constant speed drawn from the speed range. Their positions are a pure function of time, so
//! the simulation stays deterministic and cheap.

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
    /// Where along the out-and-back cycle the walk starts, metres.
    phase_m: f64,
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
            phase_m,
            radius_m,
        }
    }

    fn length_m(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// Centre `t` seconds after the lap started.
    pub fn position(&self, t: f64) -> Vec2 {
        let len = self.length_m();
        if self.path.is_empty() {
            return Vec2::zeros();
        }
        if len <= 0.0 {
            return self.path[0];
        }
        let c = (self.phase_m + self.speed_m_s * t).rem_euclid(2.0 * len);
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

    pub fn disc(&self, t: f64) -> Disc {
        Disc {
            centre: self.position(t),
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
            let phase = if cycle > 0.0 {
                rng.random_range(0.0..cycle)
            } else {
                0.0
            };
            Pedestrian {
                phase_m: phase,
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
        let p = Pedestrian::new(
            vec![Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0)],
            1.0,
            0.0,
            0.2,
        );
        assert!((p.position(1.0).x - 1.0).abs() < 1e-12);
        assert!((p.position(5.0).x - 3.0).abs() < 1e-12);
        assert!((p.position(9.0).x - 1.0).abs() < 1e-12);
    }
}
