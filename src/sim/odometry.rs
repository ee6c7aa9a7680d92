//! Odometry error models: the robot integrates what its wheel encoders report, which differs from
//! the true wheel motion.
//!
//! Each update takes the true travel of the left and right wheels over one simulation step.
//! First a systematic error: the odometry assumes nominal wheel radii, while the real wheels are
//! off by `wheel_radius_bias_ratio` (both wheels: a scale error on distance) and by
//! ±`wheel_radius_mismatch_ratio`/2 (right/left: a heading drift on straight lines). Then a random
//! error, by model:
//!
//! - **Proportional** (default), in one of two forms ([`ProportionalError`]):
//!   - **each update** (default; MobileSim's `random_each_update`, the default odometry error
//!     mode of the MobileSim the paper's simulated runs came from): at every update a new error
//!     fraction is drawn uniformly in `±σ_t` (translation) and `±σ_r` (rotation), and the update's
//!     `Δs` and `Δθ` are scaled by `(1 + e)`, as MobileSim's position model does
//!     (`vx·dt·(1 + integration_error.x)`, a new `integration_error` each iteration). The error of
//!     one update is proportional to its motion; over `n` updates of length `δ` the spread is
//!     `σ_t·δ·√(n/3)` = `σ_t·√(δ·d/3)`: with 0.02 m updates, about 0.002 m after 10 m.
//!   - **random walk** (the earlier default, kept as an option): every update's `Δs` and `Δθ`
//!     get independent zero-mean Gaussian errors with variances `σ_t²·|Δs|` and `σ_r²·|Δθ|`, so
//!     after `d` metres the translation error has standard deviation `σ_t·√d` (0.024 m after
//!     10 m with `σ_t = 0.0075`), independent of the update rate.
//! - **Thrun** (Probabilistic Robotics, table 5.6, `sample_motion_model_odometry`): the motion
//!   is split into rot1, trans, rot2 and each part gets a Gaussian error with variance
//!   `α1·rot1² + α2·trans²` (rotations) and `α3·trans² + α4·(rot1² + rot2²)` (translation).
//!   These variances are per update, so they depend on the update rate (0.05 s by default).
//!
//! The noisy motion is integrated at the midpoint heading into the odometry pose.

use crate::geom::{Pose2, wrap_angle};
use crate::sim::rng::SimRng;
use rand::RngExt;
use rand_distr::StandardNormal;

/// Random error model.
#[derive(Clone, Debug, PartialEq)]
pub enum OdometryModel {
    /// Standard deviations per metre travelled and per radian turned (see module docs).
    Proportional {
        translation_ratio: f64,
        rotation_ratio: f64,
    },
    /// Thrun's α1..α4.
    Thrun { alpha: [f64; 4] },
}

/// How the proportional model turns its ratios into errors (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProportionalError {
    /// MobileSim `random_each_update`: each update scaled by `1 + U(-ratio, ratio)`.
    #[default]
    EachUpdate,
    /// Gaussian random walk: variance `ratio²·|Δ|` per update.
    RandomWalk,
}

/// Odometry parameters. Default: proportional 0.0075 m/m and rad/rad drawn at each update
/// (MobileSim), no systematic error.
/// Thrun's α1..α4 when a file names `model = "thrun"` without giving them.
pub const DEFAULT_THRUN_ALPHA: [f64; 4] = [0.01; 4];

#[derive(Clone, Debug, PartialEq)]
pub struct OdometryConfig {
    pub model: OdometryModel,
    /// Form of the proportional model's error. Default [`ProportionalError::EachUpdate`].
    pub proportional: ProportionalError,
    /// Relative error of both wheel radii (odometric distance = true × (1 + this)). Default 0.
    pub wheel_radius_bias_ratio: f64,
    /// Right wheel radius minus left, relative to nominal. Default 0.
    pub wheel_radius_mismatch_ratio: f64,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        OdometryConfig {
            model: OdometryModel::Proportional {
                translation_ratio: 0.0075,
                rotation_ratio: 0.0075,
            },
            proportional: ProportionalError::EachUpdate,
            wheel_radius_bias_ratio: 0.0,
            wheel_radius_mismatch_ratio: 0.0,
        }
    }
}

/// Dead reckoning: the pose in the odometry frame.
#[derive(Clone, Debug)]
pub struct Odometry {
    pub config: OdometryConfig,
    axle_track_m: f64,
    pose: Pose2,
}

fn gauss(rng: &mut SimRng) -> f64 {
    rng.sample::<f64, _>(StandardNormal)
}

/// The proportional model's noisy `(Δs, Δθ)` for one update's `(Δs, Δθ)`.
fn proportional_error(
    form: ProportionalError,
    (ds, dth): (f64, f64),
    (t_ratio, r_ratio): (f64, f64),
    rng: &mut SimRng,
) -> (f64, f64) {
    match form {
        ProportionalError::EachUpdate => {
            // The scenario's size limit keeps each draw's width -r..r finite.
            debug_assert!(t_ratio.abs() <= 1e300 && r_ratio.abs() <= 1e300);
            let mut fraction = |r: f64| {
                if r > 0.0 {
                    rng.random_range(-r..r)
                } else {
                    0.0
                }
            };
            let (et, er) = (fraction(t_ratio), fraction(r_ratio));
            (ds * (1.0 + et), dth * (1.0 + er))
        }
        ProportionalError::RandomWalk => (
            ds + t_ratio * ds.abs().sqrt() * gauss(rng),
            dth + r_ratio * dth.abs().sqrt() * gauss(rng),
        ),
    }
}

impl Odometry {
    /// Starts at `start` in the odometry frame.
    pub fn new(config: OdometryConfig, axle_track_m: f64, start: Pose2) -> Self {
        Odometry {
            config,
            axle_track_m,
            pose: start,
        }
    }

    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// The (Δs, Δθ) the encoders report for true wheel travels, with systematic errors only.
    pub fn measured_motion(&self, left_m: f64, right_m: f64) -> (f64, f64) {
        let b = self.config.wheel_radius_bias_ratio;
        let m = self.config.wheel_radius_mismatch_ratio;
        let l = left_m * (1.0 + b - m / 2.0);
        let r = right_m * (1.0 + b + m / 2.0);
        ((l + r) / 2.0, (r - l) / self.axle_track_m)
    }

    /// One update from the true wheel travels over a step; returns the noisy (Δs, Δθ) used.
    pub fn update(&mut self, left_m: f64, right_m: f64, rng: &mut SimRng) -> (f64, f64) {
        let motion = self.measured_motion(left_m, right_m);
        let (ds, dth, heading) = noisy_motion(&self.config, motion, rng);
        let th = self.pose.theta;
        self.pose.x += ds * (th + heading).cos();
        self.pose.y += ds * (th + heading).sin();
        self.pose.theta = wrap_angle(th + dth);
        (ds, dth)
    }
}

/// The random error of one update: the encoders' `(Δs, Δθ)` (systematic errors applied) become
/// the noisy `(Δs, Δθ, heading)`, `heading` the direction `Δs` is travelled in, relative to the
/// heading at the start of the update (`Δθ/2` at the midpoint, or Thrun's noisy rot1). The
/// simulator integrates it ([`Odometry::update`]); real logs add it to their increments.
pub fn noisy_motion(
    config: &OdometryConfig,
    (ds, dth): (f64, f64),
    rng: &mut SimRng,
) -> (f64, f64, f64) {
    match config.model {
        OdometryModel::Proportional {
            translation_ratio,
            rotation_ratio,
        } => {
            let (ds, dth) = proportional_error(
                config.proportional,
                (ds, dth),
                (translation_ratio, rotation_ratio),
                rng,
            );
            (ds, dth, dth / 2.0)
        }
        OdometryModel::Thrun {
            alpha: [a1, a2, a3, a4],
        } => {
            let (rot1, trans, rot2) = (dth / 2.0, ds, dth / 2.0);
            let n1 = (a1 * rot1 * rot1 + a2 * trans * trans).sqrt() * gauss(rng);
            let nt = (a3 * trans * trans + a4 * (rot1 * rot1 + rot2 * rot2)).sqrt() * gauss(rng);
            let n2 = (a1 * rot2 * rot2 + a2 * trans * trans).sqrt() * gauss(rng);
            let (rot1, trans, rot2) = (rot1 - n1, trans - nt, rot2 - n2);
            (trans, rot1 + rot2, rot1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::rng::{Purpose, stream};

    fn stats(v: &[f64]) -> (f64, f64) {
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, var.sqrt())
    }

    /// 2000 straight 10 m drives of 500 updates: translation error sd 0.0075·√10, biased by
    /// the wheel-radius bias.
    #[test]
    fn proportional_translation_error_matches_the_configured_spread_and_bias() {
        let mut rng = stream(7, 0, 0, Purpose::Odometry);
        let cfg = OdometryConfig {
            wheel_radius_bias_ratio: 0.01,
            proportional: ProportionalError::RandomWalk,
            ..OdometryConfig::default()
        };
        let errs: Vec<f64> = (0..2000)
            .map(|_| {
                let mut o = Odometry::new(cfg.clone(), 0.357, Pose2::IDENTITY);
                for _ in 0..500 {
                    o.update(0.02, 0.02, &mut rng);
                }
                o.pose().x - 10.0
            })
            .collect();
        let (m, sd) = stats(&errs);
        let want_sd = 0.0075 * 10f64.sqrt();
        assert!((m - 0.1).abs() < 0.1 * 0.1, "mean {m}");
        assert!((sd / want_sd - 1.0).abs() < 0.1, "sd {sd} vs {want_sd}");
    }

    #[test]
    fn proportional_rotation_error_matches_the_configured_spread() {
        let mut rng = stream(8, 0, 0, Purpose::Odometry);
        let axle = 0.357;
        // Turning on the spot: one full turn in 400 updates.
        let w = 2.0 * std::f64::consts::PI / 400.0 * axle / 2.0;
        let errs: Vec<f64> = (0..2000)
            .map(|_| {
                let walk = OdometryConfig {
                    proportional: ProportionalError::RandomWalk,
                    ..OdometryConfig::default()
                };
                let mut o = Odometry::new(walk, axle, Pose2::IDENTITY);
                let mut total = 0.0;
                for _ in 0..400 {
                    total += o.update(-w, w, &mut rng).1;
                }
                total - 2.0 * std::f64::consts::PI
            })
            .collect();
        let (m, sd) = stats(&errs);
        let want = 0.0075 * (2.0 * std::f64::consts::PI).sqrt();
        assert!(m.abs() < 0.1 * want, "mean {m}");
        assert!((sd / want - 1.0).abs() < 0.1, "sd {sd} vs {want}");
    }

    /// MobileSim's `random_each_update`: 500 updates of 0.02 m, each scaled by 1 + U(±0.0075):
    /// spread 0.0075 · 0.02 · √(500/3), far below the random walk's 0.0075 · √10.
    #[test]
    fn each_update_error_is_proportional_to_each_update() {
        let mut rng = stream(10, 0, 0, Purpose::Odometry);
        let errs: Vec<f64> = (0..2000)
            .map(|_| {
                let mut o = Odometry::new(OdometryConfig::default(), 0.357, Pose2::IDENTITY);
                for _ in 0..500 {
                    o.update(0.02, 0.02, &mut rng);
                }
                o.pose().x - 10.0
            })
            .collect();
        let (m, sd) = stats(&errs);
        let want = 0.0075 * 0.02 * (500.0f64 / 3.0).sqrt();
        assert!(m.abs() < 0.1 * want, "mean {m}");
        assert!((sd / want - 1.0).abs() < 0.1, "sd {sd} vs {want}");
        // One update never errs by more than the ratio of its own motion.
        let mut o = Odometry::new(OdometryConfig::default(), 0.357, Pose2::IDENTITY);
        let (ds, _) = o.update(1.0, 1.0, &mut rng);
        assert!((ds - 1.0).abs() <= 0.0075);
    }

    #[test]
    fn thrun_translation_error_matches_alpha3() {
        let mut rng = stream(9, 0, 0, Purpose::Odometry);
        let cfg = OdometryConfig {
            model: OdometryModel::Thrun {
                alpha: [0.0, 0.0, 0.01, 0.0],
            },
            ..OdometryConfig::default()
        };
        let errs: Vec<f64> = (0..2000)
            .map(|_| {
                let mut o = Odometry::new(cfg.clone(), 0.357, Pose2::IDENTITY);
                for _ in 0..100 {
                    o.update(0.02, 0.02, &mut rng);
                }
                o.pose().x - 2.0
            })
            .collect();
        let (m, sd) = stats(&errs);
        // Per update sd = 0.1 · 0.02; 100 updates.
        let want = 0.1 * 0.02 * 10.0;
        assert!(m.abs() < 0.1 * want, "mean {m}");
        assert!((sd / want - 1.0).abs() < 0.1, "sd {sd} vs {want}");
    }
}
