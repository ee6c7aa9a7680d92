//! How a robot moves along its route, measured from its true path (issue 28 point 1): the
//! figures that tell a real robot's weaving from the simulator's smooth laps, and the
//! Kolmogorov–Smirnov distance between two robots' distributions.
//!
//! The path (true poses in time order) is walked by arc length; frames closer than 1 cm to the
//! last kept one are standing still. Per metre of travel, and per frame step:
//!
//! - **speed** (m/s): each step's length over its time, for steps of 1 cm to 2 m taking 0.01 to
//!   2 s (a log whose time is derived from travel, such as csail's, has no speed of its own);
//! - **heading deviation** (rad): the robot's heading against the *corridor direction*, taken as
//!   the chord of the path from [`CORRIDOR_HALF_WINDOW_M`] behind to as far ahead, every
//!   [`STEP_M`] of travel;
//! - **weave** (m): per metre of travel, the largest distance of the path from the chord of that
//!   metre (a straight drive gives 0; a sway across the corridor gives its amplitude);
//! - **turns on the spot**: heading changes of at least [`SPIN_MIN_RAD`] over less than
//!   [`SPIN_MAX_TRAVEL_M`] of travel, per 100 m, and their angles;
//! - **spectrum** of the heading deviation over arc length: the share of its variance in
//!   wavelength bands ([`BANDS_M`]), from a periodogram of the deviation sampled every
//!   [`STEP_M`].

use crate::geom::{Pose2, wrap_angle};

/// Arc-length step of the heading-deviation series, metres.
pub const STEP_M: f64 = 0.1;
/// Half the window whose chord gives the corridor direction, metres.
pub const CORRIDOR_HALF_WINDOW_M: f64 = 2.0;
/// The smallest heading change that counts as a turn on the spot, radians (45°).
pub const SPIN_MIN_RAD: f64 = std::f64::consts::FRAC_PI_4;
/// The most travel a turn on the spot may take, metres.
pub const SPIN_MAX_TRAVEL_M: f64 = 0.3;
/// Wavelength bands of the spectrum, metres: `[from, to)`.
pub const BANDS_M: [(f64, f64); 4] = [(0.5, 2.0), (2.0, 5.0), (5.0, 10.0), (10.0, 25.0)];

/// What [`measure`] finds on one path.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Motion {
    /// Metres travelled (moving steps only).
    pub travel_m: f64,
    /// Speed of each moving step with a usable time, m/s.
    pub speed_m_s: Vec<f64>,
    /// Heading against the corridor direction every [`STEP_M`], radians in (−π, π].
    pub heading_deviation_rad: Vec<f64>,
    /// Largest distance from the chord of each metre of travel, metres.
    pub weave_m: Vec<f64>,
    /// The angle of each turn on the spot, radians (absolute).
    pub spin_rad: Vec<f64>,
    /// Share of the heading deviation's variance in each band of [`BANDS_M`].
    pub spectrum: [f64; 4],
    /// True when some path had no usable time (a log whose stamps are unusable): its speeds
    /// are left out of `speed_m_s` rather than derived from a nominal speed.
    pub speed_unknown: bool,
}

impl Motion {
    /// Turns on the spot per 100 m of travel.
    pub fn spins_per_100_m(&self) -> f64 {
        if self.travel_m > 0.0 {
            self.spin_rad.len() as f64 * 100.0 / self.travel_m
        } else {
            0.0
        }
    }

    /// Adds another path's figures (the laps of a run, the runs of a scenario).
    pub fn add(&mut self, other: &Motion) {
        let w = |m: &Motion| m.heading_deviation_rad.len() as f64;
        let (a, b) = (w(self), w(other));
        if a + b > 0.0 {
            for (x, y) in self.spectrum.iter_mut().zip(other.spectrum) {
                *x = (*x * a + y * b) / (a + b);
            }
        }
        self.travel_m += other.travel_m;
        self.speed_m_s.extend(&other.speed_m_s);
        self.speed_unknown |= other.speed_unknown;
        self.heading_deviation_rad
            .extend(&other.heading_deviation_rad);
        self.weave_m.extend(&other.weave_m);
        self.spin_rad.extend(&other.spin_rad);
    }
}

/// A point of the path with its arc length.
#[derive(Clone, Copy)]
struct PathPoint {
    s_m: f64,
    pose: Pose2,
}

/// The figures of one path: `(time_s, true pose)` in time order.
pub fn measure(path: &[(f64, Pose2)]) -> Motion {
    let mut m = Motion {
        speed_m_s: speeds(path),
        ..Motion::default()
    };
    let (points, spins) = walk(path);
    m.spin_rad = spins;
    m.travel_m = points.last().map_or(0.0, |p| p.s_m);
    m.heading_deviation_rad = heading_deviation(&points);
    m.weave_m = weave(&points);
    m.spectrum = spectrum(&m.heading_deviation_rad);
    m
}

fn speeds(path: &[(f64, Pose2)]) -> Vec<f64> {
    path.windows(2)
        .filter_map(|w| {
            let (d, dt) = (w[0].1.distance(&w[1].1), w[1].0 - w[0].0);
            ((0.01..=2.0).contains(&d) && (0.01..=2.0).contains(&dt)).then(|| d / dt)
        })
        .collect()
}

/// The moving points with their arc length, and the turns on the spot: heading changes of at
/// least [`SPIN_MIN_RAD`] accumulated while travelling less than [`SPIN_MAX_TRAVEL_M`].
fn walk(path: &[(f64, Pose2)]) -> (Vec<PathPoint>, Vec<f64>) {
    let mut points: Vec<PathPoint> = Vec::new();
    let mut spins = Vec::new();
    // The turn accumulated since the robot last moved by SPIN_MAX_TRAVEL_M.
    let (mut turn, mut turn_from_s, mut last_theta) = (0.0f64, 0.0f64, None::<f64>);
    for &(_, pose) in path {
        if let Some(t) = last_theta {
            turn += wrap_angle(pose.theta - t);
        }
        last_theta = Some(pose.theta);
        let s = match points.last() {
            None => 0.0,
            Some(p) if p.pose.distance(&pose) < 0.01 => continue,
            Some(p) => p.s_m + p.pose.distance(&pose),
        };
        points.push(PathPoint { s_m: s, pose });
        if s - turn_from_s >= SPIN_MAX_TRAVEL_M {
            if turn.abs() >= SPIN_MIN_RAD {
                spins.push(turn.abs());
            }
            (turn, turn_from_s) = (0.0, s);
        }
    }
    if turn.abs() >= SPIN_MIN_RAD {
        spins.push(turn.abs());
    }
    (points, spins)
}

/// The point at arc length `s` (linear between points; `i` a hint that only grows).
fn at(points: &[PathPoint], s: f64, i: &mut usize) -> Pose2 {
    while *i + 1 < points.len() && points[*i + 1].s_m < s {
        *i += 1;
    }
    let a = points[*i];
    let Some(b) = points.get(*i + 1) else {
        return a.pose;
    };
    let f = ((s - a.s_m) / (b.s_m - a.s_m)).clamp(0.0, 1.0);
    Pose2 {
        x: a.pose.x + f * (b.pose.x - a.pose.x),
        y: a.pose.y + f * (b.pose.y - a.pose.y),
        theta: a.pose.theta + f * wrap_angle(b.pose.theta - a.pose.theta),
    }
}

fn heading_deviation(points: &[PathPoint]) -> Vec<f64> {
    let Some(end) = points.last().map(|p| p.s_m) else {
        return Vec::new();
    };
    let h = CORRIDOR_HALF_WINDOW_M;
    let (mut i0, mut i1, mut i2) = (0, 0, 0);
    let mut out = Vec::new();
    let mut s = h;
    while s + h <= end {
        let (a, p, b) = (
            at(points, s - h, &mut i0),
            at(points, s, &mut i1),
            at(points, s + h, &mut i2),
        );
        out.push(wrap_angle(p.theta - (b.y - a.y).atan2(b.x - a.x)));
        s += STEP_M;
    }
    out
}

fn weave(points: &[PathPoint]) -> Vec<f64> {
    let Some(end) = points.last().map(|p| p.s_m) else {
        return Vec::new();
    };
    let (mut i, mut out, mut from) = (0usize, Vec::new(), 0.0);
    while from + 1.0 <= end {
        let a = at(points, from, &mut i);
        let b = at(points, from + 1.0, &mut i.clone());
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let len = dx.hypot(dy).max(1e-9);
        let mut worst = 0.0f64;
        let mut k = i;
        while k < points.len() && points[k].s_m <= from + 1.0 {
            let p = points[k].pose;
            worst = worst.max(((p.x - a.x) * dy - (p.y - a.y) * dx).abs() / len);
            k += 1;
        }
        out.push(worst);
        from += 1.0;
    }
    out
}

/// The share of the series' variance in each band of [`BANDS_M`] (a periodogram at every
/// frequency k / (n · STEP_M) of the mean-removed series; all zeros for a flat series).
fn spectrum(x: &[f64]) -> [f64; 4] {
    let n = x.len();
    let mut out = [0.0; 4];
    if n < 8 {
        return out;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let total: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    if total <= 0.0 {
        return out;
    }
    let length_m = n as f64 * STEP_M;
    for (band, &(lo, hi)) in BANDS_M.iter().enumerate() {
        // Wavelength λ = length / k, so k from length / hi to length / lo.
        let k_lo = (length_m / hi).ceil().max(1.0) as usize;
        let k_hi = ((length_m / lo).floor() as usize).min(n / 2);
        for k in k_lo..=k_hi {
            let w = std::f64::consts::TAU * k as f64 / n as f64;
            let (mut re, mut im) = (0.0, 0.0);
            for (j, v) in x.iter().enumerate() {
                let (s, c) = (w * j as f64).sin_cos();
                re += (v - mean) * c;
                im += (v - mean) * s;
            }
            // Parseval: Σ|x|² = (1/n)·Σ_k |X_k|², each k in 1..n/2 counted twice.
            out[band] += 2.0 * (re * re + im * im) / n as f64 / total;
        }
    }
    out
}

/// The two-sample Kolmogorov–Smirnov statistic: the largest gap between the empirical
/// distribution functions of `a` and `b` (0 when they are the same, 1 when they do not
/// overlap; `None` when either is empty).
pub fn ks_statistic(a: &[f64], b: &[f64]) -> Option<f64> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let sorted = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v
    };
    let (a, b) = (sorted(a), sorted(b));
    let (mut i, mut j, mut d) = (0usize, 0usize, 0.0f64);
    while i < a.len() && j < b.len() {
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / a.len() as f64 - j as f64 / b.len() as f64).abs());
    }
    Some(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drive along x at 0.5 m/s, 10 frames a second, `y(x)` sideways, heading along the path.
    fn drive(len_m: f64, y: impl Fn(f64) -> f64) -> Vec<(f64, Pose2)> {
        let n = (len_m / 0.05) as usize;
        (0..=n)
            .map(|i| {
                let x = i as f64 * 0.05;
                let theta = (y(x + 0.01) - y(x)).atan2(0.01);
                (i as f64 * 0.1, Pose2 { x, y: y(x), theta })
            })
            .collect()
    }

    #[test]
    fn a_straight_drive_has_its_speed_and_no_weave_deviation_or_spin() {
        let m = measure(&drive(30.0, |_| 0.0));
        assert!((m.travel_m - 30.0).abs() < 1e-6);
        assert!(m.speed_m_s.iter().all(|v| (v - 0.5).abs() < 1e-9));
        assert!(m.heading_deviation_rad.iter().all(|d| d.abs() < 1e-9));
        assert!(m.weave_m.iter().all(|w| *w < 1e-9));
        assert_eq!(m.spins_per_100_m(), 0.0);
        assert_eq!(m.spectrum, [0.0; 4]);
    }

    #[test]
    fn a_sway_shows_as_weave_deviation_and_its_wavelength() {
        // 0.3 m amplitude, 4 m wavelength.
        let sway = |x: f64| 0.3 * (x * std::f64::consts::TAU / 4.0).sin();
        let m = measure(&drive(80.0, sway));
        let max_dev = m
            .heading_deviation_rad
            .iter()
            .fold(0.0f64, |a, d| a.max(d.abs()));
        assert!(max_dev > 0.3, "{max_dev}");
        assert!(m.weave_m.iter().any(|w| *w > 0.05), "{:?}", &m.weave_m[..5]);
        assert!(
            m.spectrum[1] > 0.8,
            "the 2-5 m band holds the sway: {:?}",
            m.spectrum
        );
    }

    #[test]
    fn a_turn_on_the_spot_is_counted_with_its_angle() {
        let mut path = drive(10.0, |_| 0.0);
        let (t, end) = *path.last().unwrap();
        for k in 1..=20 {
            let theta = k as f64 * std::f64::consts::PI / 20.0;
            path.push((t + k as f64 * 0.1, Pose2 { theta, ..end }));
        }
        let m = measure(&path);
        assert_eq!(m.spin_rad.len(), 1);
        assert!((m.spin_rad[0] - std::f64::consts::PI).abs() < 1e-9);
        assert!((m.spins_per_100_m() - 10.0).abs() < 1e-6);
    }

    #[test]
    fn ks_is_zero_for_equal_samples_and_one_for_disjoint_ones() {
        assert_eq!(ks_statistic(&[1.0, 2.0, 3.0], &[3.0, 1.0, 2.0]), Some(0.0));
        assert_eq!(ks_statistic(&[1.0, 2.0], &[5.0, 6.0, 7.0]), Some(1.0));
        let d = ks_statistic(&[1.0, 2.0, 3.0, 4.0], &[3.0, 4.0, 5.0, 6.0]).unwrap();
        assert!((d - 0.5).abs() < 1e-12, "{d}");
        assert_eq!(ks_statistic(&[], &[1.0]), None);
    }
}
