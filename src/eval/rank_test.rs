//! One-sided rank tests over seeds, for the comparison with a baseline (`eval::compare`).
//!
//! - [`signed_rank_greater`]: the Wilcoxon signed-rank test of paired differences, exact
//!   (every one of the 2ⁿ sign patterns counted) up to [`EXACT_MAX`] differences, the normal
//!   approximation with the tie correction beyond. Zeros are left out; tied magnitudes get
//!   their average rank, and the exact distribution is counted over those ranks.
//! - [`rank_sum_greater`]: the Mann–Whitney (Wilcoxon rank-sum) test of two samples, by the
//!   normal approximation with the tie and continuity corrections.
//!
//! Both answer "is the first sample centred above the second (or above 0)?" with a p-value:
//! the chance, if it were not, of a statistic at least as large as the one seen.

/// Up to this many non-zero differences the signed-rank test is exact.
pub const EXACT_MAX: usize = 100;

/// One-sided p-value of the Wilcoxon signed-rank test that `d` is centred above 0: the chance
/// under "symmetric about 0" of a sum of positive ranks W⁺ at least the one observed. `None`
/// when no difference is non-zero (nothing to test).
pub fn signed_rank_greater(d: &[f64]) -> Option<f64> {
    let mut nz: Vec<f64> = d
        .iter()
        .copied()
        .filter(|x| *x != 0.0 && x.is_finite())
        .collect();
    if nz.is_empty() {
        return None;
    }
    nz.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    let ranks2 = doubled_ranks(&nz.iter().map(|x| x.abs()).collect::<Vec<_>>());
    let n = nz.len();
    let w2: usize = nz
        .iter()
        .zip(&ranks2)
        .filter(|(x, _)| **x > 0.0)
        .map(|(_, r)| *r)
        .sum();
    if n <= EXACT_MAX {
        // P(W⁺ = s) over every sign pattern, in doubled ranks (integers even with ties).
        let total: usize = ranks2.iter().sum();
        let mut p = vec![0.0f64; total + 1];
        p[0] = 1.0;
        let mut reach = 0;
        for &r in &ranks2 {
            for s in (0..=reach).rev() {
                let half = p[s] * 0.5;
                p[s] = half;
                p[s + r] += half;
            }
            reach += r;
        }
        return Some(p[w2..].iter().sum::<f64>().min(1.0));
    }
    let n = n as f64;
    let mean = n * (n + 1.0) / 4.0;
    let var = n * (n + 1.0) * (2.0 * n + 1.0) / 24.0 - tie_term(&ranks2) / 48.0;
    let w = w2 as f64 / 2.0;
    Some(upper_normal(
        (w - mean - 0.5) / var.max(f64::MIN_POSITIVE).sqrt(),
    ))
}

/// One-sided p-value of the Mann–Whitney test that `x` is centred above `y` (normal
/// approximation, tie and continuity corrections). `None` when a sample is empty or every
/// value is one number.
pub fn rank_sum_greater(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.is_empty() || y.is_empty() {
        return None;
    }
    let mut all: Vec<(f64, bool)> = x.iter().map(|v| (*v, true)).collect();
    all.extend(y.iter().map(|v| (*v, false)));
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ranks2 = doubled_ranks(&all.iter().map(|a| a.0).collect::<Vec<_>>());
    let (m, n) = (x.len() as f64, y.len() as f64);
    let r2: usize = all
        .iter()
        .zip(&ranks2)
        .filter(|(a, _)| a.1)
        .map(|(_, r)| *r)
        .sum();
    let u = r2 as f64 / 2.0 - m * (m + 1.0) / 2.0;
    let big_n = m + n;
    let var = m * n / 12.0 * ((big_n + 1.0) - tie_term(&ranks2) / (big_n * (big_n - 1.0)));
    if var <= 0.0 {
        return None;
    }
    Some(upper_normal((u - m * n / 2.0 - 0.5) / var.sqrt()))
}

/// Twice the average rank (from 1) of each value of the sorted `v`: ties share theirs.
fn doubled_ranks(v: &[f64]) -> Vec<usize> {
    let mut out = vec![0; v.len()];
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[i] {
            j += 1;
        }
        // ranks i+1..=j+1, average (i + j + 2) / 2, doubled.
        for o in &mut out[i..=j] {
            *o = i + j + 2;
        }
        i = j + 1;
    }
    out
}

/// Σ (t³ − t) over the groups of t tied values.
fn tie_term(ranks2: &[usize]) -> f64 {
    let mut sum = 0.0;
    let mut i = 0;
    while i < ranks2.len() {
        let mut j = i;
        while j + 1 < ranks2.len() && ranks2[j + 1] == ranks2[i] {
            j += 1;
        }
        let t = (j - i + 1) as f64;
        sum += t * t * t - t;
        i = j + 1;
    }
    sum
}

/// P(Z ≥ z) for a standard normal Z.
fn upper_normal(z: f64) -> f64 {
    0.5 * libm::erfc(z / std::f64::consts::SQRT_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_rank_is_exact_on_small_samples() {
        // Every difference positive: only one pattern of 2^n has W+ this large.
        assert_eq!(
            signed_rank_greater(&[1.0, 2.0, 3.0, 4.0, 5.0]),
            Some(1.0 / 32.0)
        );
        let p = signed_rank_greater(&[-1.0, -2.0, -3.0]).unwrap();
        assert_eq!(p, 1.0);
        assert_eq!(signed_rank_greater(&[0.0, 0.0]), None);
        // n = 10, W+ = 45 (ranks 2..10 positive, rank 1 negative): the table's P = 2/1024.
        let d: Vec<f64> = (1..=10)
            .map(|i| if i == 1 { -1.0 } else { i as f64 })
            .collect();
        let p = signed_rank_greater(&d).unwrap();
        assert!((p - 2.0 / 1024.0).abs() < 1e-12, "{p}");
        // Ties: two equal magnitudes share rank 1.5.
        let p = signed_rank_greater(&[1.0, -1.0]).unwrap();
        assert!((p - 0.75).abs() < 1e-12, "{p}");
    }

    #[test]
    fn signed_rank_normal_tail_agrees_with_the_exact_one() {
        let d: Vec<f64> = (1..=120).map(|i| i as f64 - 40.0).collect();
        let approx = signed_rank_greater(&d).unwrap();
        let exact = signed_rank_greater(&d[..100]).unwrap();
        assert!(approx < 1e-6 && exact < 1e-3, "{approx} {exact}");
        assert!((upper_normal(1.644_853_6) - 0.05).abs() < 1e-6);
    }

    #[test]
    fn rank_sum_sees_a_shift() {
        let x: Vec<f64> = (0..10).map(|i| 10.0 + i as f64).collect();
        let y: Vec<f64> = (0..10).map(|i| i as f64).collect();
        assert!(rank_sum_greater(&x, &y).unwrap() < 0.001);
        assert!(rank_sum_greater(&y, &x).unwrap() > 0.999);
        let p = rank_sum_greater(&y, &y).unwrap();
        assert!((0.4..0.6).contains(&p), "{p}");
        assert_eq!(rank_sum_greater(&[1.0], &[1.0]), None);
    }
}
