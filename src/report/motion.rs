//! `placewords motion` for people: one row of figures per input (quantiles of speed, heading
//! deviation and weave, turns on the spot per 100 m, the spectrum's bands), then each input's
//! Kolmogorov–Smirnov distance to the first.

use crate::eval::motion::{BANDS_M, Motion, ks_statistic};
use std::fmt::Write;

/// The q-quantile of `v` (nearest rank), or `None` when empty.
fn quantile(v: &[f64], q: f64) -> Option<f64> {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let i = ((v.len() as f64 - 1.0) * q).round() as usize;
    v.get(i).copied()
}

/// `p10 / p50 / p90` of `v` scaled by `k`, `–` when empty.
fn spread(v: &[f64], k: f64, decimals: usize) -> String {
    let q: Vec<String> = [0.1, 0.5, 0.9]
        .iter()
        .map(|&q| quantile(v, q).map_or("–".into(), |x| format!("{:.decimals$}", x * k)))
        .collect();
    q.join(" / ")
}

fn abs(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| x.abs()).collect()
}

/// The table of `inputs` (name, figures) and the KS distances to the first input.
pub fn text(inputs: &[(String, Motion)]) -> String {
    let mut out = String::from(
        "input: travel m | speed m/s p10 / p50 / p90 | |heading - corridor| deg p10 / p50 / p90 | \
         weave per metre cm p10 / p50 / p90 | turns on the spot per 100 m | heading variance by \
         wavelength",
    );
    let bands: Vec<String> = BANDS_M.iter().map(|(a, b)| format!("{a}-{b} m")).collect();
    let _ = writeln!(
        out,
        " ({}) | turn on the spot deg p10 / p50 / p90",
        bands.join(", ")
    );
    for (name, m) in inputs {
        let spectrum: Vec<String> = m
            .spectrum
            .iter()
            .map(|x| format!("{:.0} %", x * 100.0))
            .collect();
        let _ = writeln!(
            out,
            "{name}: {:.0} | {} | {} | {} | {:.1} | {} | {}",
            m.travel_m,
            if m.speed_unknown && m.speed_m_s.is_empty() {
                "– (stamps unusable)".to_string()
            } else {
                spread(&m.speed_m_s, 1.0, 2)
            },
            spread(&abs(&m.heading_deviation_rad), 1f64.to_degrees(), 1),
            spread(&m.weave_m, 100.0, 1),
            m.spins_per_100_m(),
            spectrum.join(", "),
            spread(&m.spin_rad, 1f64.to_degrees(), 0)
        );
    }
    if let [(first, a), rest @ ..] = inputs
        && !rest.is_empty()
    {
        let _ = writeln!(
            out,
            "\nKolmogorov–Smirnov distance to {first} (0: the same distribution, 1: no overlap):"
        );
        let ks =
            |x: &[f64], y: &[f64]| ks_statistic(x, y).map_or("–".into(), |d| format!("{d:.2}"));
        for (name, b) in rest {
            let _ = writeln!(
                out,
                "{name}: speed {}, |heading deviation| {}, weave {}, turn angle {}",
                ks(&a.speed_m_s, &b.speed_m_s),
                ks(
                    &abs(&a.heading_deviation_rad),
                    &abs(&b.heading_deviation_rad)
                ),
                ks(&a.weave_m, &b.weave_m),
                ks(&a.spin_rad, &b.spin_rad),
            );
        }
    }
    out
}
