//! Slips along a corridor: where the density Ψ is flat enough along the route that the fine
//! alignment (paper §IV-D: raw densities of two chains slid against each other) can slide one
//! chain along the other by more than the true-positive radius without its residual growing
//! past what the lap-to-lap variation of Ψ already gives. Such a match joins the right corridor
//! at the wrong place: a false pair 1–3 m off, the commonest error of the recognizer on long
//! uniform corridors.
//!
//! From the noise-free drive of the ambiguity map (two laps per door set): Ψ along the route in
//! 0.1 m bins, per door set, from the second lap (the first starts with an empty grid); the
//! noise level ε from the two laps' difference at the same bins (with a floor); for every bin,
//! how far a window of Ψ around it can be shifted each way before the mean absolute difference
//! of the window and its shifted copy exceeds ε. The larger of the two is the bin's expected
//! along-track uncertainty; bins where it exceeds twice the radius form the slip stretches.

use super::ambiguity::{AmbiguityError, BIN_M, Drive};
use crate::recognizer::{DensityFrontEnd, RecognizerConfig};
use serde::Serialize;

/// Length of route over which the alignment compares Ψ, metres: about the shortest chain the
/// matcher accepts (a few words of 2–4 m). Tuned on scenario B (6, 12 and 20 m tried; 12 m
/// flagged the least route for the false pairs it held), confirmed on A and C (RESULTS.md).
pub const WINDOW_M: f64 = 12.0;
/// A bin slips when its uncertainty exceeds this many true-positive radii (1, 2, 3 and 5 tried
/// on B; 2 kept: 1 flags most of every corridor, 3 and more almost nothing).
pub const SLIP_FACTOR: f64 = 2.0;
/// Largest slip searched, metres (a slip this long is reported as this long).
pub const MAX_SLIP_M: f64 = 10.0;
/// Floor of the noise level ε of Ψ (a noise-free drive under-states the lap-to-lap variation
/// that laser noise, lanes and people add; 0.02 and 0.04 tried on B, 0.04 flags twice the route).
pub const MIN_NOISE: f64 = 0.02;

/// A stretch of the route where the alignment can slide along it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlipStretch {
    /// From 0, in route order.
    pub number: usize,
    /// Start, metres along the route from waypoint 0.
    pub from_m: f64,
    /// End, metres along the route (less than `from_m` when it passes waypoint 0).
    pub to_m: f64,
    pub length_m: f64,
    /// The largest expected along-track uncertainty inside, metres (the half-width of the
    /// band the picture draws).
    pub uncertainty_m: f64,
    /// The door set under which it slips the most.
    pub door_set: String,
    /// Mean expected along-track uncertainty over the stretch, metres.
    pub score: f64,
}

/// Ψ of each 0.1 m bin of the loop in each lap of each door set: `[door set][lap][bin]`.
fn profiles(drive: &Drive, cfg: &RecognizerConfig) -> Result<Vec<[Vec<f64>; 2]>, AmbiguityError> {
    let n = ((drive.loop_m / BIN_M).ceil() as usize).max(1);
    let sets = drive.door_sets.len().max(1);
    let mut sum = vec![[vec![0.0; n], vec![0.0; n]]; sets];
    let mut count = vec![[vec![0usize; n], vec![0usize; n]]; sets];
    let mut front = DensityFrontEnd::new(cfg)?;
    for (i, f) in drive.frames.iter().enumerate() {
        if i == 0 || drive.door_set_of_frame[i] != drive.door_set_of_frame[i - 1] {
            front.start_run();
        }
        for o in front.push_frame(i, f.odom, &f.scan) {
            let at = o.frame_id.min(drive.frames.len() - 1);
            let (k, lap) = (drive.door_set_of_frame[at], drive.lap_of_frame[at].min(1));
            let b = ((drive.route_m[at] / BIN_M) as usize).min(n - 1);
            sum[k][lap][b] += o.psi;
            count[k][lap][b] += 1;
        }
    }
    Ok((0..sets)
        .map(|k| [0, 1].map(|lap| filled(&sum[k][lap], &count[k][lap])))
        .collect())
}

/// Means per bin, empty bins given their nearest filled neighbour's (circularly).
fn filled(sum: &[f64], count: &[usize]) -> Vec<f64> {
    let n = sum.len();
    let known: Vec<usize> = (0..n).filter(|&b| count[b] > 0).collect();
    if known.is_empty() {
        return vec![0.0; n];
    }
    (0..n)
        .map(|b| {
            if count[b] > 0 {
                return sum[b] / count[b] as f64;
            }
            let dist = |k: usize| {
                let d = k.abs_diff(b);
                d.min(n - d)
            };
            let k = *known.iter().min_by_key(|&&k| dist(k)).unwrap_or(&known[0]);
            sum[k] / count[k] as f64
        })
        .collect()
}

/// The noise level of Ψ: the 90th percentile of the two laps' difference bin by bin (the
/// first `WINDOW_M` of the first lap left out: its grid is still filling), at least
/// [`MIN_NOISE`].
fn noise(laps: &[Vec<f64>; 2]) -> f64 {
    let skip = (WINDOW_M / BIN_M) as usize;
    let mut d: Vec<f64> = laps[0]
        .iter()
        .zip(&laps[1])
        .skip(skip)
        .map(|(a, b)| (a - b).abs())
        .collect();
    if d.is_empty() {
        return MIN_NOISE;
    }
    d.sort_by(f64::total_cmp);
    d[(d.len() * 9 / 10).min(d.len() - 1)].max(MIN_NOISE)
}

/// Per bin: how far (metres) a `WINDOW_M` window of `psi` around it slides each way before its
/// mean absolute difference from the shifted copy exceeds `eps`; the larger of the two.
pub fn along_track_uncertainty(psi: &[f64], eps: f64) -> Vec<f64> {
    let n = psi.len();
    let half = ((WINDOW_M / BIN_M) as usize / 2).min(n / 2);
    let max_shift = ((MAX_SLIP_M / BIN_M) as usize).min(n.saturating_sub(1));
    let width = (2 * half + 1) as f64;
    // How far each bin's window still fits, per direction; stops at the first shift that fails.
    let mut reach = [vec![0usize; n], vec![0usize; n]];
    let mut open = [vec![true; n], vec![true; n]];
    let mut prefix = vec![0.0; n + 1];
    for d in 1..=max_shift {
        for (dir, sign) in [(0, 1isize), (1, -1)] {
            // prefix sums of |Ψ(j) − Ψ(j ± d)| over the loop.
            for j in 0..n {
                let k = (j as isize + sign * d as isize).rem_euclid(n as isize) as usize;
                prefix[j + 1] = prefix[j] + (psi[j] - psi[k]).abs();
            }
            for b in 0..n {
                if !open[dir][b] {
                    continue;
                }
                let window_sum = circular_sum(&prefix, b as isize - half as isize, 2 * half + 1);
                if window_sum / width <= eps {
                    reach[dir][b] = d;
                } else {
                    open[dir][b] = false;
                }
            }
        }
        if !open[0].iter().chain(&open[1]).any(|o| *o) {
            break;
        }
    }
    (0..n)
        .map(|b| reach[0][b].max(reach[1][b]) as f64 * BIN_M)
        .collect()
}

/// Sum of `len` consecutive values from index `start` (wrapping) of the series whose prefix
/// sums are `prefix` (`prefix[0] = 0`, `prefix.len()` = series length + 1).
fn circular_sum(prefix: &[f64], start: isize, len: usize) -> f64 {
    let n = prefix.len() - 1;
    let s = start.rem_euclid(n as isize) as usize;
    let end = s + len.min(n);
    if end <= n {
        prefix[end] - prefix[s]
    } else {
        (prefix[n] - prefix[s]) + prefix[end - n]
    }
}

/// The slip stretches of a noise-free drive at the recognizer settings `cfg`: runs of bins
/// whose along-track uncertainty under some door set exceeds [`SLIP_FACTOR`] × `radius_m`, at
/// least half a [`WINDOW_M`] long.
pub fn slips(
    drive: &Drive,
    cfg: &RecognizerConfig,
    radius_m: f64,
) -> Result<Vec<SlipStretch>, AmbiguityError> {
    let profiles = profiles(drive, cfg)?;
    let n = ((drive.loop_m / BIN_M).ceil() as usize).max(1);
    // Per bin: the largest uncertainty over the door sets, and which set gives it.
    let mut worst = vec![(0.0f64, 0usize); n];
    for (k, laps) in profiles.iter().enumerate() {
        let eps = noise(laps);
        for (b, u) in along_track_uncertainty(&laps[1], eps)
            .into_iter()
            .enumerate()
        {
            if u > worst[b].0 {
                worst[b] = (u, k);
            }
        }
    }
    let name = |k: usize| {
        drive
            .door_sets
            .get(k)
            .map(|d| d.name.clone())
            .unwrap_or_default()
    };
    let runs = runs_over(
        &worst
            .iter()
            .map(|w| w.0 > SLIP_FACTOR * radius_m)
            .collect::<Vec<_>>(),
    );
    // Shorter than half a window: a flat spot the alignment's window reaches past.
    let min_bins = (WINDOW_M / 2.0 / BIN_M) as usize;
    Ok(runs
        .into_iter()
        .filter(|&(_, len)| len >= min_bins)
        .enumerate()
        .map(|(number, (start, len))| {
            let inside = (0..len).map(|i| worst[(start + i) % n]);
            let (peak, set) = inside
                .clone()
                .fold((0.0f64, 0usize), |a, w| if w.0 > a.0 { w } else { a });
            let mean = inside.map(|w| w.0).sum::<f64>() / len as f64;
            let round = |x: f64| (x * 10.0).round() / 10.0;
            SlipStretch {
                number,
                from_m: round(start as f64 * BIN_M),
                to_m: round(((start + len) as f64 * BIN_M).rem_euclid(drive.loop_m)),
                length_m: round(len as f64 * BIN_M),
                uncertainty_m: round(peak),
                door_set: name(set),
                score: (mean * 100.0).round() / 100.0,
            }
        })
        .collect())
}

/// Runs of `true` in a circular series: (start, length), in order of start; a run through the
/// end continues at the start.
fn runs_over(marked: &[bool]) -> Vec<(usize, usize)> {
    let n = marked.len();
    if marked.iter().all(|m| *m) {
        return vec![(0, n)];
    }
    // Start scanning just after a false bin, so no run is cut at the seam.
    let Some(origin) = marked.iter().position(|m| !m) else {
        return Vec::new();
    };
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut current: Option<(usize, usize)> = None;
    for i in 1..=n {
        let b = (origin + i) % n;
        match (marked[b], current.as_mut()) {
            (true, Some(run)) => run.1 += 1,
            (true, None) => current = Some((b, 1)),
            (false, _) => out.extend(current.take()),
        }
    }
    out.extend(current);
    out.sort_by_key(|r| r.0);
    out
}

/// Share of the loop inside at least one slip.
pub fn share(slips: &[SlipStretch], loop_m: f64) -> f64 {
    let marked = super::ambiguity::flagged(&[], slips, loop_m);
    marked.iter().filter(|m| **m).count() as f64 / marked.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_profile_slips_and_a_textured_one_does_not() {
        let flat = vec![0.5; 400];
        let u = along_track_uncertainty(&flat, 0.02);
        assert!(
            u.iter().all(|&x| (x - MAX_SLIP_M).abs() < 1e-9),
            "{:?}",
            &u[..5]
        );
        // A saw tooth of 1 m period: any shift of 0.1 m or more changes the window.
        let saw: Vec<f64> = (0..400).map(|i| (i % 10) as f64 / 10.0).collect();
        let u = along_track_uncertainty(&saw, 0.02);
        assert!(u.iter().all(|&x| x == 0.0), "{:?}", &u[..20]);
    }

    #[test]
    fn runs_wrap_around_the_seam() {
        let m = [true, true, false, false, true, false, true];
        assert_eq!(runs_over(&m), vec![(4, 1), (6, 3)]);
        assert_eq!(runs_over(&[false; 3]), Vec::<(usize, usize)>::new());
        assert_eq!(runs_over(&[true; 3]), vec![(0, 3)]);
    }
}
