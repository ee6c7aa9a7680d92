//! Synthetic inputs for the recognizer's tests and benchmarks (no simulator needed):
//! observation sequences laid out word by word, analytic scans of a few wall segments, and a
//! 200 m loop floor with side rooms whose doors open and close. A test fixture, outside the
//! library: `tests/it` and `benches/recognizer.rs` include it by path (not every user uses every
//! item, hence the `dead_code` allowance).
#![allow(dead_code)]

use placewords::geom::{OdomPose, Pose2, Segment, Vec2, wrap_angle};
use placewords::recognizer::{DensityObservation, Observation};
use placewords::scan::{BeamLayout, Scan};

/// A small deterministic generator (SplitMix64), so tests and benches need no RNG crate.
#[derive(Clone, Debug)]
pub struct SplitMix(u64);

impl SplitMix {
    pub fn new(seed: u64) -> Self {
        SplitMix(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in lo..=hi.
    pub fn int(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as usize
    }
}

/// One stretch of a synthetic path: `size` observations of density `psi`, turning by
/// `turn_deg` right after its median observation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stretch {
    pub psi: f64,
    pub size: usize,
    pub turn_deg: f64,
}

impl Stretch {
    pub fn new(psi: f64, size: usize, turn_deg: f64) -> Self {
        Stretch {
            psi,
            size,
            turn_deg,
        }
    }
}

/// Lays observations along a path, one per `spacing_m`, continuing `ids`, travel and pose from
/// `after` (or from the origin heading east).
pub fn observations(
    stretches: &[Stretch],
    spacing_m: f64,
    run: usize,
    after: Option<&DensityObservation>,
) -> Vec<DensityObservation> {
    let (mut pose, mut travel, mut id, mut input) = match after {
        Some(o) => {
            let o = &o.observation;
            (o.odom_pose.0, o.travel_m, o.id + 1, o.frame_id + 1)
        }
        None => (Pose2::IDENTITY, 0.0, 0, 0),
    };
    let mut out = Vec::new();
    for s in stretches {
        // The whole turn happens right after the median observation, so A = turn_deg exactly.
        let turn_at = (s.size.max(1) - 1) / 2 + 1;
        for i in 0..s.size {
            if i == turn_at {
                pose.theta = wrap_angle(pose.theta + s.turn_deg.to_radians());
            }
            if !(after.is_none() && out.is_empty()) {
                pose.x += spacing_m * pose.theta.cos();
                pose.y += spacing_m * pose.theta.sin();
                travel += spacing_m;
            }
            out.push(DensityObservation {
                observation: Observation::new(id, run, input, OdomPose(pose), travel),
                psi: s.psi,
                lateral_moment: 0.0,
                position_slack_m: 0.0,
                wide_density: 0.0,
                scan_step_observations: 1,
            });
            id += 1;
            input += 1;
        }
    }
    out
}

/// Ψ at the middle of class `class` of `classes` uniform classes.
pub fn class_psi(class: usize, classes: usize) -> f64 {
    (class as f64 + 0.5) / classes as f64
}

/// Range of the beam from `origin` along `dir` (unit) to the nearest wall, if any.
fn cast(walls: &[Segment], origin: Vec2, dir: Vec2) -> Option<f64> {
    let mut best: Option<f64> = None;
    for w in walls {
        let e = w.b - w.a;
        let denom = dir.x * e.y - dir.y * e.x;
        if denom.abs() < 1e-12 {
            continue;
        }
        let ao = w.a - origin;
        let t = (ao.x * e.y - ao.y * e.x) / denom;
        let u = (ao.x * dir.y - ao.y * dir.x) / denom;
        if t > 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&u) && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    }
    best
}

/// An exact scan of `walls` from the robot at `robot` (the sensor at the layout's mount).
/// Beams that hit nothing within range report the maximum range.
pub fn scan_of(walls: &[Segment], robot: Pose2, layout: &BeamLayout, time_s: f64) -> Scan {
    let sensor = robot.compose(&layout.mount);
    let origin = sensor.position();
    let ranges_m = (0..layout.count)
        .map(|i| {
            let a = sensor.theta + layout.beam_angle_rad(i);
            match cast(walls, origin, Vec2::new(a.cos(), a.sin())) {
                Some(r) if r < layout.max_range_m => r,
                _ => layout.max_range_m,
            }
        })
        .collect();
    Scan {
        layout: layout.clone(),
        ranges_m,
        time_s,
    }
}

/// The LMS200 layout: 181 beams over 180°, 32.767 m, 0.021 m ahead of the centre.
pub fn lms200() -> BeamLayout {
    BeamLayout::centered(
        181,
        std::f64::consts::PI,
        32.767,
        Pose2::new(0.021, 0.0, 0.0),
    )
}

fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
    Segment::new(Vec2::new(ax, ay), Vec2::new(bx, by))
}

/// A straight corridor along +x from x = 0 to `length_m`, `width_m` wide, centred on y = 0, with
/// a side branch (a bifurcation) `branch_width_m` wide opening upward at `branch_at_m`.
pub fn corridor_with_branch(
    length_m: f64,
    width_m: f64,
    branch_at_m: f64,
    branch_width_m: f64,
) -> Vec<Segment> {
    let h = width_m / 2.0;
    let b0 = branch_at_m - branch_width_m / 2.0;
    let b1 = branch_at_m + branch_width_m / 2.0;
    vec![
        seg(-1.0, -h, length_m, -h),
        seg(-1.0, h, b0, h),
        seg(b1, h, length_m, h),
        seg(b0, h, b0, h + 10.0),
        seg(b1, h, b1, h + 10.0),
        seg(-1.0, -h, -1.0, h),
        seg(length_m, -h, length_m, h),
    ]
}

/// What interrupts the outer wall of a [`LoopFloor`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feature {
    /// A 0.9 m door into a 4 m × 4 m room; open or closed per lap.
    Door,
    /// A 2 m wide dead-end side corridor, 6 m deep (a bifurcation).
    Branch,
    /// The wall juts 0.6 m into the corridor for 6 m (a cabinet row, a pillar block).
    Narrowing,
}

/// A rectangular loop floor: a corridor `corridor_m` wide around a block, centreline
/// `length_m` × `width_m`, with features along the outer wall at given travel positions
/// (measured along the centreline from the start corner, counter-clockwise).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopFloor {
    pub length_m: f64,
    pub width_m: f64,
    pub corridor_m: f64,
    pub features: Vec<(f64, Feature)>,
}

impl LoopFloor {
    /// The 200 m lap used by the benchmarks: 58 m × 42 m centreline, 2 m corridor, 8 doors,
    /// 3 branches, 4 narrowings.
    pub fn institute() -> Self {
        use Feature::*;
        LoopFloor {
            length_m: 58.0,
            width_m: 42.0,
            corridor_m: 2.0,
            features: vec![
                (10.0, Door),
                (20.0, Narrowing),
                (33.0, Branch),
                (45.0, Door),
                (66.0, Door),
                (78.0, Narrowing),
                (90.0, Door),
                (110.0, Branch),
                (122.0, Door),
                (134.0, Door),
                (146.0, Narrowing),
                (168.0, Door),
                (180.0, Branch),
                (191.0, Door),
                (196.0, Narrowing),
            ],
        }
    }

    /// Number of doors (the length of the `open` slices).
    pub fn door_count(&self) -> usize {
        self.features
            .iter()
            .filter(|f| f.1 == Feature::Door)
            .count()
    }

    pub fn lap_length_m(&self) -> f64 {
        2.0 * (self.length_m + self.width_m)
    }

    /// A point of the centreline at travel `s` and the corridor direction there.
    fn centreline(&self, s: f64) -> (Vec2, f64) {
        let s = s.rem_euclid(self.lap_length_m());
        let (l, w) = (self.length_m, self.width_m);
        if s < l {
            (Vec2::new(s, 0.0), 0.0)
        } else if s < l + w {
            (Vec2::new(l, s - l), std::f64::consts::FRAC_PI_2)
        } else if s < 2.0 * l + w {
            (Vec2::new(l - (s - l - w), w), std::f64::consts::PI)
        } else {
            (
                Vec2::new(0.0, w - (s - 2.0 * l - w)),
                -std::f64::consts::FRAC_PI_2,
            )
        }
    }

    /// Wall segments with the given doors open (`open[i]` for the i-th door along the lap).
    pub fn walls(&self, open: &[bool]) -> Vec<Segment> {
        let h = self.corridor_m / 2.0;
        let (l, w) = (self.length_m, self.width_m);
        // Inner block.
        let mut walls = vec![
            seg(h, h, l - h, h),
            seg(l - h, h, l - h, w - h),
            seg(l - h, w - h, h, w - h),
            seg(h, w - h, h, h),
        ];
        let mut door = 0usize;
        let mut features: Vec<(f64, Feature, bool)> = Vec::new();
        for &(at, f) in &self.features {
            let is_open = f == Feature::Door && open.get(door).copied().unwrap_or(false);
            if f == Feature::Door {
                door += 1;
            }
            features.push((at, f, is_open));
        }
        // Outer wall, side by side, interrupted by the features.
        let sides = [
            (Vec2::new(-h, -h), Vec2::new(l + h, -h), 0.0, l),
            (Vec2::new(l + h, -h), Vec2::new(l + h, w + h), l, w),
            (Vec2::new(l + h, w + h), Vec2::new(-h, w + h), l + w, l),
            (Vec2::new(-h, w + h), Vec2::new(-h, -h), 2.0 * l + w, w),
        ];
        for (a, b, s0, len) in sides {
            let dir = (b - a) / (b - a).norm();
            let out = Vec2::new(dir.y, -dir.x); // away from the corridor
            let at = |t: f64, o: f64| a + dir * t + out * o;
            let mut from = 0.0;
            for &(pos, f, is_open) in features.iter().filter(|f| f.0 > s0 && f.0 < s0 + len) {
                let c = pos - s0 + h;
                let mut push = |p: Vec2, q: Vec2| {
                    if (q - p).norm() > 1e-9 {
                        walls.push(Segment::new(p, q));
                    }
                };
                match f {
                    Feature::Door | Feature::Branch => {
                        let (gap, half, depth) = if f == Feature::Door {
                            (0.45, 2.0, 4.0)
                        } else {
                            (1.0, 1.0, 6.0)
                        };
                        push(at(from, 0.0), at(c - gap, 0.0));
                        if f == Feature::Door && !is_open {
                            push(at(c - gap, 0.0), at(c + gap, 0.0));
                        }
                        push(at(c - half, 0.0), at(c - gap, 0.0));
                        push(at(c + gap, 0.0), at(c + half, 0.0));
                        push(at(c - half, 0.0), at(c - half, depth));
                        push(at(c + half, 0.0), at(c + half, depth));
                        push(at(c - half, depth), at(c + half, depth));
                        from = c + gap;
                    }
                    Feature::Narrowing => {
                        push(at(from, 0.0), at(c - 3.0, 0.0));
                        push(at(c - 3.0, 0.0), at(c - 3.0, -0.6));
                        push(at(c - 3.0, -0.6), at(c + 3.0, -0.6));
                        push(at(c + 3.0, -0.6), at(c + 3.0, 0.0));
                        from = c + 3.0;
                    }
                }
            }
            walls.push(Segment::new(at(from, 0.0), b));
        }
        walls
    }

    /// Robot poses of one lap every `step_m` along the centreline, with a small lateral weave,
    /// corners cut by a 1 m arc-free diagonal blend (heading interpolated over ±0.5 m).
    pub fn lap_poses(&self, step_m: f64) -> Vec<Pose2> {
        let n = (self.lap_length_m() / step_m).round() as usize;
        (0..n)
            .map(|i| {
                let s = i as f64 * step_m;
                let (p, th) = self.centreline(s);
                let (_, th_next) = self.centreline(s + 0.5);
                let (_, th_prev) = self.centreline(s - 0.5);
                let theta = if th_next != th {
                    wrap_angle(th + wrap_angle(th_next - th) * 0.5)
                } else if th_prev != th {
                    wrap_angle(th - wrap_angle(th - th_prev) * 0.5)
                } else {
                    th
                };
                let weave = 0.1 * (s * 0.37).sin();
                Pose2::new(p.x - weave * th.sin(), p.y + weave * th.cos(), theta)
            })
            .collect()
    }

    /// One lap of (odometry pose, scan) at 0.04 m per scan (0.4 m/s at 10 Hz), odometry exact.
    pub fn lap_inputs(&self, open: &[bool], layout: &BeamLayout) -> Vec<(OdomPose, Scan)> {
        let walls = self.walls(open);
        self.lap_poses(0.04)
            .into_iter()
            .enumerate()
            .map(|(i, p)| (OdomPose(p), scan_of(&walls, p, layout, i as f64 * 0.1)))
            .collect()
    }
}

/// One lap of synthetic observations with a realistic class structure (corridors of classes
/// 1–3, corners and crossings of 4–6, door bumps when `doors_open`), for back-end benches. The
/// floor layout comes from `floor_seed`; `lap_seed` varies noise, door states and sizes.
pub fn procedural_lap(
    floor_seed: u64,
    lap_seed: u64,
    after: Option<&DensityObservation>,
) -> Vec<DensityObservation> {
    let mut floor = SplitMix::new(floor_seed);
    let mut lap = SplitMix::new(lap_seed ^ 0xA5A5_5A5A);
    let mut stretches = Vec::new();
    let mut total = 0usize;
    while total < 2000 {
        let corridor_class = floor.int(1, 3);
        let len = floor.int(30, 150);
        let door_at = floor.int(8, len.saturating_sub(8).max(9));
        let door_open = lap.unit() < 0.3;
        let jitter = |r: &mut SplitMix, n: usize| {
            ((n as f64) * r.range(0.95, 1.05)).round().max(1.0) as usize
        };
        let psi = class_psi(corridor_class, 8);
        if door_open && len > 20 {
            stretches.push(Stretch::new(psi, jitter(&mut lap, door_at), 0.0));
            stretches.push(Stretch::new(
                class_psi(corridor_class + 2, 8),
                jitter(&mut lap, 7),
                0.0,
            ));
            stretches.push(Stretch::new(psi, jitter(&mut lap, len - door_at), 0.0));
        } else {
            stretches.push(Stretch::new(psi, jitter(&mut lap, len), 0.0));
        }
        let corner_class = floor.int(4, 6);
        let turn = [90.0, -90.0, 0.0][floor.int(0, 2)];
        stretches.push(Stretch::new(
            class_psi(corner_class, 8),
            jitter(&mut lap, floor.int(6, 20)),
            turn,
        ));
        total += len + 15;
    }
    let mut obs = observations(
        &stretches,
        0.10,
        after.map_or(0, |o| o.observation.run),
        after,
    );
    for o in &mut obs {
        o.psi = (o.psi + lap.range(-0.03, 0.03)).clamp(0.0, 1.0);
    }
    obs
}
