//! Precision-recall curves as a standalone SVG (paper Fig. 8), hand-written: no system library,
//! no plotting crate. Recall on x, precision on y; multi-level curves solid, the single-level
//! curve dotted; a legend with each curve's max-F1 and best recall at precision ≥ 0.9.

use crate::eval::sweep::{PRECISION_FLOOR, PrCurve};
use crate::report::junit::escape;
use std::fmt::Write;

const W: f64 = 760.0;
const H: f64 = 520.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 250.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

/// A colour per curve index (colour-blind friendly cycle).
const COLOURS: [&str; 10] = [
    "#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#7f7f7f", "#8c564b",
    "#bcbd22", "#000000",
];

/// An axis over `[lo, hi]` (ratios in [0, 1]) fitted to the data: a round tick step of 1, 2 or
/// 5 × 10^k giving about 5 to 10 ticks, the ends on ticks, at least one step wide.
pub fn fitted_axis(lo: f64, hi: f64) -> (f64, f64, f64) {
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo <= hi {
        (lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0))
    } else {
        (0.0, 1.0)
    };
    let span = (hi - lo).max(0.01);
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|st| span / st <= 8.0)
        .unwrap_or(10.0 * mag);
    let mut a = ((lo / step) + 1e-9).floor() * step;
    let mut b = ((hi / step) - 1e-9).ceil() * step;
    if b - a < step * 0.5 {
        b = a + step;
    }
    if b > 1.0 + 1e-9 {
        (a, b) = ((1.0 - (b - a)).max(0.0), 1.0);
    }
    (a.max(0.0), b.min(1.0), step)
}

/// The SVG document of `curves` titled `title`.
pub fn pr_curves_svg(curves: &[PrCurve], title: &str) -> String {
    // Axes fitted to the points drawn (and the precision floor), so curves near P = 1 spread.
    let drawn = || {
        curves
            .iter()
            .flat_map(|c| c.points.iter().filter(|p| p.pairs > 0))
    };
    let (r_lo, r_hi) = drawn().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p.recall), b.max(p.recall))
    });
    let p_lo = drawn().map(|p| p.precision).fold(PRECISION_FLOOR, f64::min);
    let (x_min, x_max, x_step) = fitted_axis(r_lo, r_hi);
    let (y_min, y_max, y_step) = fitted_axis(p_lo, 1.0);
    let pw = W - LEFT - RIGHT;
    let ph = H - TOP - BOTTOM;
    let sx = |x: f64| LEFT + (x - x_min) / (x_max - x_min) * pw;
    let sy = |y: f64| TOP + (y_max - y) / (y_max - y_min) * ph;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        LEFT + pw / 2.0,
        escape(title)
    );
    // Grid, ticks and labels.
    let ticks = |a: f64, b: f64, st: f64| {
        let n = ((b - a) / st).round() as usize;
        (0..=n).map(move |i| a + st * i as f64)
    };
    for fx in ticks(x_min, x_max, x_step) {
        let x = sx(fx);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#e5e5e5"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP + ph,
            TOP + ph + 16.0,
            trim(fx)
        );
    }
    for fy in ticks(y_min, y_max, y_step) {
        let y = sy(fy);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT + pw,
            LEFT - 6.0,
            y + 4.0,
            trim(fy)
        );
    }
    // The precision floor.
    let yf = sy(PRECISION_FLOOR);
    let _ = writeln!(
        s,
        r##"<line x1="{LEFT}" y1="{yf:.1}" x2="{:.1}" y2="{yf:.1}" stroke="#999" stroke-dasharray="6 3"/>"##,
        LEFT + pw
    );
    let _ = writeln!(
        s,
        r##"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>"##
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="13">recall</text>"#,
        LEFT + pw / 2.0,
        H - 18.0
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{:.1}" text-anchor="middle" font-size="13" transform="rotate(-90 18 {:.1})">precision</text>"#,
        TOP + ph / 2.0,
        TOP + ph / 2.0
    );
    // Curves.
    let mut labels: Vec<(f64, f64)> = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let dash = if c.levels == 1 {
            r#" stroke-dasharray="2 3""#
        } else {
            ""
        };
        let pts: Vec<String> = c
            .points
            .iter()
            .filter(|p| p.pairs > 0)
            .map(|p| format!("{:.1},{:.1}", sx(p.recall), sy(p.precision)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline fill="none" stroke="{colour}" stroke-width="2"{dash} points="{}"><title>{}</title></polyline>"#,
            pts.join(" "),
            escape(&c.label)
        );
        for p in c.points.iter().filter(|p| p.pairs > 0) {
            let _ = writeln!(
                s,
                r#"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="{colour}"><title>{}, t = {}: P {:.3} R {:.3}</title></circle>"#,
                sx(p.recall),
                sy(p.precision),
                escape(&c.label),
                p.threshold,
                p.precision,
                p.recall
            );
        }
        // Each end of the curve says its t, so a reader sees which way t grows.
        let drawn: Vec<_> = c.points.iter().filter(|p| p.pairs > 0).collect();
        let ends = match (drawn.first(), drawn.last()) {
            (Some(a), Some(b)) if drawn.len() > 1 => vec![*a, *b],
            (Some(a), _) => vec![*a],
            _ => Vec::new(),
        };
        for p in ends {
            // A label where another already stands would hide both: the point's tooltip says it.
            let (x, y) = (sx(p.recall), sy(p.precision));
            if labels
                .iter()
                .any(|&(lx, ly): &(f64, f64)| (lx - x).abs() < 34.0 && (ly - y).abs() < 12.0)
            {
                continue;
            }
            labels.push((x, y));
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{:.1}" font-size="10" fill="{colour}">t={}</text>"#,
                x + 4.0,
                y - 4.0,
                p.threshold
            );
        }
        // Legend entry.
        let ly = TOP + 10.0 + 46.0 * i as f64;
        let lx = W - RIGHT + 16.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{:.1}" y2="{ly}" stroke="{colour}" stroke-width="2"{dash}/><text x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 24.0,
            lx + 30.0,
            ly + 4.0,
            escape(&c.label)
        );
        let f1 = c
            .max_f1
            .as_ref()
            .map(|p| format!("max F1 {:.3} at t = {}", p.f1, p.threshold))
            .unwrap_or_else(|| "max F1 –".into());
        let br = c
            .best_recall_at_precision
            .as_ref()
            .map(|p| {
                format!(
                    "recall {:.3} at P ≥ {PRECISION_FLOOR}, t = {}",
                    p.recall, p.threshold
                )
            })
            .unwrap_or_else(|| format!("no point at P ≥ {PRECISION_FLOOR}"));
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}" font-size="10" fill="#444">{}</text><text x="{:.1}" y="{:.1}" font-size="10" fill="#444">{}</text>"##,
            lx + 30.0,
            ly + 17.0,
            escape(&f1),
            lx + 30.0,
            ly + 30.0,
            escape(&br)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// A tick label without trailing zeros.
fn trim(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::metrics::Metrics;
    use crate::eval::sweep::{GridPoint, SweepResult, pr_curves};

    #[test]
    fn fitted_axes_end_on_round_ticks() {
        let (a, b, st) = fitted_axis(0.93, 1.0);
        assert!((st - 0.01).abs() < 1e-12 && (a - 0.93).abs() < 1e-9 && b == 1.0);
        let (a, b, st) = fitted_axis(0.08, 0.87);
        assert_eq!((a, st), (0.0, 0.1));
        assert!((b - 0.9).abs() < 1e-9);
        let (a, b, _) = fitted_axis(0.5, 0.5);
        assert!(a <= 0.5 && b > a);
        assert_eq!(fitted_axis(f64::INFINITY, f64::NEG_INFINITY).0, 0.0);
    }

    #[test]
    fn svg_has_one_polyline_per_curve_and_parses() {
        let mut results = Vec::new();
        for t in 0..=9 {
            results.push(SweepResult {
                point: GridPoint::new(1, &[t]),
                metrics: Metrics {
                    precision: 0.5 + 0.05 * t as f64,
                    recall: 0.3 - 0.03 * t as f64,
                    pairs: 5,
                    ..Metrics::default()
                },
                recognize_seconds_per_lap: 0.0,
            });
            results.push(SweepResult {
                point: GridPoint::new(2, &[6, t]),
                metrics: Metrics {
                    precision: 0.6 + 0.04 * t as f64,
                    recall: 0.5 - 0.03 * t as f64,
                    pairs: 5,
                    ..Metrics::default()
                },
                recognize_seconds_per_lap: 0.0,
            });
        }
        let curves = pr_curves(&results);
        let svg = pr_curves_svg(&curves, "B <sweep>");
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG/XML");
        let lines: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("polyline"))
            .collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].attribute("stroke-dasharray"), Some("2 3"));
        assert_eq!(lines[1].attribute("stroke-dasharray"), None);
        assert!(svg.contains("max F1"));
        if let Ok(path) = std::env::var("PLACEWORDS_PLOT_SAMPLE") {
            std::fs::write(path, &svg).unwrap();
        }
        assert!(svg.contains("B &lt;sweep&gt;"));
    }
}
