//! The SICK LMS200 model (docs/design.md, Simulation defaults): 181 beams over 180° at 1°,
//! 10 Hz, uniform ±5 mm range noise, a fixed angle error per beam (uniform ±0.0007 rad, drawn
//! once per robot), no return = maximum range; mounted 0.021 m ahead of the robot centre.

use crate::geom::{Pose2, Vec2};
use crate::scan::{BeamLayout, Scan};
use crate::sim::rng::SimRng;
use crate::world::raycast::{Beams, Disc, SweepCaster};
use rand::RngExt;

/// Named laser settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaserPreset {
    /// 32.767 m maximum range (centimetre mode).
    Lms200,
    /// 8.191 m maximum range (millimetre mode).
    Lms200Mm,
}

impl LaserPreset {
    pub const NAMES: [&'static str; 2] = ["lms200", "lms200-mm"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "lms200" => Some(LaserPreset::Lms200),
            "lms200-mm" => Some(LaserPreset::Lms200Mm),
            _ => None,
        }
    }
}

/// Laser parameters. Defaults: the `lms200` preset.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserConfig {
    /// Number of beams. Default 181.
    pub beams: usize,
    /// Field of view from the first to the last beam, radians. Default π (180°).
    pub fov_rad: f64,
    /// No-return range, metres. Default 32.767 (`lms200`); 8.191 for `lms200-mm`.
    pub max_range_m: f64,
    /// Half-width of the uniform range noise, metres. Default 0.005.
    pub range_noise_m: f64,
    /// Half-width of the uniform fixed per-beam angle error, radians. Default 0.0007.
    pub angle_error_rad: f64,
    /// Scans per second. Default 10.
    pub rate_hz: f64,
    /// Sensor position ahead of the robot centre, metres. Default 0.021.
    pub mount_x_m: f64,
}

impl LaserConfig {
    pub fn preset(p: LaserPreset) -> Self {
        LaserConfig {
            beams: 181,
            fov_rad: std::f64::consts::PI,
            max_range_m: match p {
                LaserPreset::Lms200 => 32.767,
                LaserPreset::Lms200Mm => 8.191,
            },
            range_noise_m: 0.005,
            angle_error_rad: 0.0007,
            rate_hz: 10.0,
            mount_x_m: 0.021,
        }
    }

    /// The nominal beam layout (what a log records).
    pub fn layout(&self) -> BeamLayout {
        BeamLayout::centered(
            self.beams,
            self.fov_rad,
            self.max_range_m,
            Pose2::new(self.mount_x_m, 0.0, 0.0),
        )
    }
}

impl Default for LaserConfig {
    fn default() -> Self {
        Self::preset(LaserPreset::Lms200)
    }
}

/// One robot's laser: its configuration and its fixed per-beam angle errors.
#[derive(Clone, Debug)]
pub struct Laser {
    pub config: LaserConfig,
    layout: BeamLayout,
    beams: Beams,
    angle_errors_rad: Vec<f64>,
    /// cos and sin of each beam's nominal angle.
    nominal_dirs: Vec<(f64, f64)>,
}

impl Laser {
    /// A laser whose per-beam angle errors are drawn from `rng` (once per robot).
    pub fn new(config: LaserConfig, rng: &mut SimRng) -> Self {
        let e = config.angle_error_rad;
        let angle_errors_rad: Vec<f64> = (0..config.beams)
            .map(|_| {
                if e > 0.0 {
                    rng.random_range(-e..=e)
                } else {
                    0.0
                }
            })
            .collect();
        Self::with_angle_errors(config, angle_errors_rad)
    }

    /// A laser with given per-beam angle errors (empty for none).
    pub fn with_angle_errors(config: LaserConfig, angle_errors_rad: Vec<f64>) -> Self {
        let layout = config.layout();
        let beams = Beams::new(
            layout.start_angle_rad,
            layout.step_rad,
            layout.count,
            &angle_errors_rad,
        );
        let nominal_dirs = (0..layout.count)
            .map(|i| {
                let (s, c) = layout.beam_angle_rad(i).sin_cos();
                (c, s)
            })
            .collect();
        Laser {
            config,
            layout,
            beams,
            angle_errors_rad,
            nominal_dirs,
        }
    }

    pub fn layout(&self) -> &BeamLayout {
        &self.layout
    }

    pub fn angle_errors_rad(&self) -> &[f64] {
        &self.angle_errors_rad
    }

    /// Hit points of `ranges` in the robot frame, along the nominal beam directions (beams at
    /// maximum range are left out).
    pub fn hits_in_robot<'r>(&'r self, ranges: &'r [f64]) -> impl Iterator<Item = Vec2> + 'r {
        let max = self.config.max_range_m;
        let mount = self.layout.mount;
        ranges
            .iter()
            .zip(&self.nominal_dirs)
            .filter(move |(r, _)| **r < max)
            .map(move |(r, (c, s))| Vec2::new(mount.x + r * c, mount.y + r * s))
    }

    /// Where the sensor is for a robot at `robot_pose`.
    pub fn sensor_pose(&self, robot_pose: Pose2) -> Pose2 {
        let p = robot_pose.transform_point(Vec2::new(self.config.mount_x_m, 0.0));
        Pose2::new(p.x, p.y, robot_pose.theta)
    }

    /// Noise-free ranges (exact intersections along the true beam directions).
    pub fn exact_ranges(
        &self,
        caster: &SweepCaster,
        robot_pose: Pose2,
        discs: &[Disc],
        out: &mut Vec<f64>,
    ) {
        let s = self.sensor_pose(robot_pose);
        caster.cast(
            s.position(),
            s.theta,
            &self.beams,
            self.config.max_range_m,
            discs,
            out,
        );
    }

    /// Adds the range noise to exact ranges: hits get uniform ±`range_noise_m`, are rounded to
    /// whole millimetres (the LMS200 reports integer millimetres in both presets) and stay
    /// within [0, max]; no-returns stay at the maximum range.
    pub fn add_noise(&self, ranges: &mut [f64], rng: &mut SimRng) {
        let max = self.config.max_range_m;
        let n = self.config.range_noise_m;
        // The scenario's size limit keeps ±n (and so the uniform draw's width) finite.
        debug_assert!((0.0..=1e300).contains(&n), "range_noise_m = {n}");
        for r in ranges.iter_mut() {
            if *r >= max || !r.is_finite() {
                *r = max;
            } else {
                let noisy = if n > 0.0 {
                    *r + rng.random_range(-n..=n)
                } else {
                    *r
                };
                *r = (round_half_away(noisy * 1000.0) / 1000.0).clamp(0.0, max);
            }
        }
    }

    /// One noisy scan from a robot at `robot_pose` at `time_s`.
    pub fn scan(
        &self,
        caster: &SweepCaster,
        robot_pose: Pose2,
        discs: &[Disc],
        rng: &mut SimRng,
        time_s: f64,
    ) -> Scan {
        let mut ranges = Vec::with_capacity(self.config.beams);
        self.exact_ranges(caster, robot_pose, discs, &mut ranges);
        self.add_noise(&mut ranges, rng);
        Scan {
            layout: self.layout.clone(),
            ranges_m: ranges,
            time_s,
        }
    }
}

/// `x.round()` (halves away from zero, the sign of zero kept) without the software `round`
/// the baseline x86-64 target calls for it. Below 2⁵², adding and taking away 2⁵² rounds the
/// magnitude to the nearest whole number with ties to even, exactly; the remainder, also exact,
/// is ½ only for the ties that went down, which `round` takes up. From 2⁵² on every f64 is whole.
#[inline]
fn round_half_away(x: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    let a = x.abs();
    if a >= TWO_52 || a.is_nan() {
        return x; // already whole, or not finite
    }
    let mut y = (a + TWO_52) - TWO_52;
    if a - y == 0.5 {
        y += 1.0;
    }
    y.copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_half_away_is_round() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            2.5,
            -2.5,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4_503_599_627_370_495.5,
            4_503_599_627_370_497.0,
            -4_503_599_627_370_495.5,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        // Every millimetre half-way point and its neighbours over the laser's ranges.
        for k in -40_000i64..=40_000 {
            let h = k as f64 + 0.5;
            xs.extend([
                h,
                f64::from_bits(h.to_bits() + 1),
                f64::from_bits(h.to_bits() - 1),
            ]);
            xs.push(k as f64 * 0.001_3 * 1000.0);
        }
        for x in xs {
            assert_eq!(round_half_away(x).to_bits(), x.round().to_bits(), "{x}");
        }
        assert!(round_half_away(f64::NAN).is_nan());
    }
}
