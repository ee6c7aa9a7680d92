//! Real robot logs as experiments. "Corrected" CARMEN logs carry no raw odometry, so odometry is
//! derived from the corrected increments, each perturbed by the simulator's odometry model
//! ([`perturb_increment`]) from a seeded stream; the corrected pose stays the truth.

use crate::geom::{Pose2, wrap_angle};
use crate::io::carmen::ReadOptions;
use crate::io::real_log::{RealLogError, TruthSource, load_run};
use crate::log::RunLog;
use crate::sim::odometry::{OdometryConfig, OdometryModel};
use crate::sim::rng::{Purpose, SimRng, stream};
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;

/// Perturbs one odometry increment (robot frame) with `cfg`'s model:
/// - proportional: translation `Δs` and rotation `Δθ` get independent Gaussian errors of
///   variance `σ_t²·|Δs|` and `σ_r²·|Δθ|` (as the simulator, per update);
/// - Thrun: the increment is split into rot1, trans, rot2, each perturbed with α1..α4;
///
/// then the systematic wheel-radius bias scales the translation.
pub fn perturb_increment(cfg: &OdometryConfig, inc: Pose2, rng: &mut SimRng) -> Pose2 {
    let mut g = || -> f64 { StandardNormal.sample(rng) };
    let trans = inc.x.hypot(inc.y);
    let scale = 1.0 + cfg.wheel_radius_bias_ratio;
    match &cfg.model {
        OdometryModel::Proportional {
            translation_ratio,
            rotation_ratio,
        } => {
            let s = trans + g() * translation_ratio * trans.sqrt();
            let dtheta = inc.theta + g() * rotation_ratio * inc.theta.abs().sqrt();
            let dir = if trans > 1e-12 {
                inc.y.atan2(inc.x)
            } else {
                0.0
            };
            let s = s * scale;
            Pose2::new(s * dir.cos(), s * dir.sin(), wrap_angle(dtheta))
        }
        OdometryModel::Thrun { alpha } => {
            let rot1 = if trans > 1e-6 {
                inc.y.atan2(inc.x)
            } else {
                0.0
            };
            let rot2 = wrap_angle(inc.theta - rot1);
            let sd = |v: f64| v.max(0.0).sqrt();
            let r1 = rot1 + g() * sd(alpha[0] * rot1 * rot1 + alpha[1] * trans * trans);
            let t =
                trans + g() * sd(alpha[2] * trans * trans + alpha[3] * (rot1 * rot1 + rot2 * rot2));
            let r2 = rot2 + g() * sd(alpha[0] * rot2 * rot2 + alpha[1] * trans * trans);
            let t = t * scale;
            Pose2::new(t * r1.cos(), t * r1.sin(), wrap_angle(r1 + r2))
        }
    }
}

/// Reads a log and turns it into one run, with odometry derived by `noise` (or exactly the
/// corrected increments when `noise` is `None`) from the stream of `seed`.
pub fn load_real_run(
    path: &Path,
    lenient: bool,
    truth: TruthSource,
    noise: Option<&OdometryConfig>,
    seed: u64,
) -> Result<(RunLog, usize), RealLogError> {
    let mut rng = stream(seed, 0, 0, Purpose::Odometry);
    let (run, readout) = load_run(path, ReadOptions { lenient }, truth, |inc| match noise {
        Some(cfg) => perturb_increment(cfg, inc, &mut rng),
        None => inc,
    })?;
    Ok((run, readout.skipped_lines))
}

/// Keeps every `k`-th frame of `run` (the first included; `k` ≤ 1 keeps all), so a dense log can
/// be made as sparse as many real logs are. The odometry is untouched: each kept frame still has
/// its pose, so the recognizer sees the same path sampled less often.
pub fn keep_every_nth_scan(run: &mut RunLog, k: usize) {
    if k <= 1 {
        return;
    }
    let mut i = 0usize;
    for lap in &mut run.laps {
        lap.frames.retain(|_| {
            i += 1;
            (i - 1).is_multiple_of(k)
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proportional_noise_has_the_configured_spread() {
        let cfg = OdometryConfig::default();
        let mut rng = stream(1, 0, 0, Purpose::Odometry);
        let n = 20_000;
        let inc = Pose2::new(1.0, 0.0, 1.0);
        let (mut sx, mut sxx) = (0.0, 0.0);
        for _ in 0..n {
            let p = perturb_increment(&cfg, inc, &mut rng);
            sx += p.x - 1.0;
            sxx += (p.x - 1.0).powi(2);
        }
        let mean = sx / n as f64;
        let sd = (sxx / n as f64 - mean * mean).sqrt();
        assert!(mean.abs() < 0.0005, "mean error {mean}");
        assert!((sd - 0.0075).abs() < 0.00075, "spread {sd}");
    }
}
