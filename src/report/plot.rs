//! Precision-recall curves as a standalone SVG, hand-written: no system library, no plotting
//! crate. Recall on x, precision on y. Two pictures: the τ sweep (paper Fig. 8; multi-level
//! curves solid, the single-level curve dotted; a legend with each curve's max-F1 and best
//! recall at precision ≥ 0.9) and each subject's curve over its match score (`eval::ranking`;
//! the legend gives AP, max F1 and recall at 99 % and 100 % precision).

use crate::eval::ranking::RankingScores;
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

/// One curve to draw: its points `(recall, precision, threshold as written)` in order, its
/// label, whether it is dotted, and two lines of figures for the legend.
struct Series {
    label: String,
    dotted: bool,
    points: Vec<(f64, f64, String)>,
    notes: [String; 2],
}

/// The SVG document of the τ sweep's `curves` titled `title` (paper Fig. 8): one curve per
/// level configuration, its max F1 and best recall at precision ≥ [`PRECISION_FLOOR`].
pub fn pr_curves_svg(curves: &[PrCurve], title: &str) -> String {
    let series: Vec<Series> = curves
        .iter()
        .map(|c| {
            let f1 = c
                .max_f1
                .as_ref()
                .map(|p| format!("max F1 {:.3} at t = {}", p.f1, p.threshold))
                .unwrap_or_else(|| "max F1 –".into());
            let best = c
                .best_recall_at_precision
                .as_ref()
                .map(|p| {
                    let (r, t) = (p.recall, p.threshold);
                    format!("recall {r:.3} at P ≥ {PRECISION_FLOOR}, t = {t}")
                })
                .unwrap_or_else(|| format!("no point at P ≥ {PRECISION_FLOOR}"));
            Series {
                label: c.label.clone(),
                dotted: c.levels == 1,
                points: (c.points.iter().filter(|p| p.pairs > 0))
                    .map(|p| (p.recall, p.precision, p.threshold.to_string()))
                    .collect(),
                notes: [f1, best],
            }
        })
        .collect();
    svg(&series, title, PRECISION_FLOOR)
}

/// The SVG document of each subject's precision–recall curve over its match score
/// (`eval::ranking`), titled `title`, with the 0.99 precision line; each curve's AP, max F1
/// and recall at 99 % and 100 % precision in the legend.
pub fn score_curves_svg(subjects: &[(String, &RankingScores)], title: &str) -> String {
    let series: Vec<Series> = subjects
        .iter()
        .map(|(name, r)| Series {
            label: name.clone(),
            dotted: false,
            points: (r.curve.iter())
                .map(|p| (p.recall, p.precision, format!("{:.2}", p.threshold)))
                .collect(),
            notes: [
                format!(
                    "AP {:.3}, max F1 {:.3}{}",
                    r.average_precision,
                    r.max_f1,
                    r.max_f1_threshold
                        .map_or(String::new(), |t| format!(" at t = {t:.2}"))
                ),
                format!(
                    "R {:.3} at P ≥ 0.99, {:.3} at P = 1",
                    r.recall_at_99_precision, r.recall_at_100_precision
                ),
            ],
        })
        .collect();
    svg(&series, title, 0.99)
}

/// Axes fitted to the points drawn (and the precision `floor`), so curves near P = 1 spread.
struct Frame {
    x: (f64, f64, f64),
    y: (f64, f64, f64),
}

impl Frame {
    fn of(series: &[Series], floor: f64) -> Self {
        let drawn = || series.iter().flat_map(|c| c.points.iter());
        let (r_lo, r_hi) = drawn().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
        let p_lo = drawn().map(|p| p.1).fold(floor, f64::min);
        Frame {
            x: fitted_axis(r_lo, r_hi),
            y: fitted_axis(p_lo, 1.0),
        }
    }

    fn sx(&self, x: f64) -> f64 {
        LEFT + (x - self.x.0) / (self.x.1 - self.x.0) * (W - LEFT - RIGHT)
    }

    fn sy(&self, y: f64) -> f64 {
        TOP + (self.y.1 - y) / (self.y.1 - self.y.0) * (H - TOP - BOTTOM)
    }
}

/// The whole document: frame, grid, the precision `floor` as a dashed line, the curves and the
/// legend.
fn svg(series: &[Series], title: &str, floor: f64) -> String {
    let f = Frame::of(series, floor);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        LEFT + (W - LEFT - RIGHT) / 2.0,
        escape(title)
    );
    grid(&mut s, &f);
    axes(&mut s, &f, floor);
    let mut labels: Vec<(f64, f64)> = Vec::new();
    for (i, c) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        curve(&mut s, &f, c, colour);
        end_labels(&mut s, &f, c, colour, &mut labels);
        legend(&mut s, i, c, colour);
    }
    s.push_str("</svg>\n");
    s
}

/// Grid lines and tick labels on both axes.
fn grid(s: &mut String, f: &Frame) {
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let ticks = |(a, b, st): (f64, f64, f64)| {
        let n = ((b - a) / st).round() as usize;
        (0..=n).map(move |i| a + st * i as f64)
    };
    for fx in ticks(f.x) {
        let x = f.sx(fx);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#e5e5e5"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP + ph,
            TOP + ph + 16.0,
            trim(fx, f.x.2)
        );
    }
    for fy in ticks(f.y) {
        let y = f.sy(fy);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT + pw,
            LEFT - 6.0,
            y + 4.0,
            trim(fy, f.y.2)
        );
    }
}

/// The precision floor, the plot's border and the axis names.
fn axes(s: &mut String, f: &Frame, floor: f64) {
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let yf = f.sy(floor);
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
}

/// The stroke-dasharray attribute of a dotted curve (empty for a solid one).
fn dash(c: &Series) -> &'static str {
    if c.dotted {
        r#" stroke-dasharray="2 3""#
    } else {
        ""
    }
}

/// A curve's polyline and a marker with a tooltip at each point.
fn curve(s: &mut String, f: &Frame, c: &Series, colour: &str) {
    let pts: Vec<String> = (c.points.iter())
        .map(|p| format!("{:.1},{:.1}", f.sx(p.0), f.sy(p.1)))
        .collect();
    let _ = writeln!(
        s,
        r#"<polyline fill="none" stroke="{colour}" stroke-width="2"{} points="{}"><title>{}</title></polyline>"#,
        dash(c),
        pts.join(" "),
        escape(&c.label)
    );
    for (r, p, t) in &c.points {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="{colour}"><title>{}, t = {}: P {p:.3} R {r:.3}</title></circle>"#,
            f.sx(*r),
            f.sy(*p),
            escape(&c.label),
            escape(t),
        );
    }
}

/// Each end of a curve says its threshold, so a reader sees which way t grows; a label where
/// another already stands (`labels`) is left out, as it would hide both (the tooltip says it).
fn end_labels(s: &mut String, f: &Frame, c: &Series, colour: &str, labels: &mut Vec<(f64, f64)>) {
    let ends = match (c.points.first(), c.points.last()) {
        (Some(a), Some(b)) if c.points.len() > 1 => vec![a, b],
        (Some(a), _) => vec![a],
        _ => Vec::new(),
    };
    for (r, p, t) in ends {
        let (x, y) = (f.sx(*r), f.sy(*p));
        if (labels.iter()).any(|&(lx, ly)| (lx - x).abs() < 34.0 && (ly - y).abs() < 12.0) {
            continue;
        }
        labels.push((x, y));
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="10" fill="{colour}">t={}</text>"#,
            x + 4.0,
            y - 4.0,
            escape(t)
        );
    }
}

/// Legend entry `i`: the curve's stroke and label, and its two lines of figures.
fn legend(s: &mut String, i: usize, c: &Series, colour: &str) {
    let ly = TOP + 10.0 + 46.0 * i as f64;
    let lx = W - RIGHT + 16.0;
    let _ = writeln!(
        s,
        r#"<line x1="{lx}" y1="{ly}" x2="{:.1}" y2="{ly}" stroke="{colour}" stroke-width="2"{}/><text x="{:.1}" y="{:.1}">{}</text>"#,
        lx + 24.0,
        dash(c),
        lx + 30.0,
        ly + 4.0,
        escape(&c.label)
    );
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="10" fill="#444">{}</text><text x="{:.1}" y="{:.1}" font-size="10" fill="#444">{}</text>"##,
        lx + 30.0,
        ly + 17.0,
        escape(&c.notes[0]),
        lx + 30.0,
        ly + 30.0,
        escape(&c.notes[1])
    );
}

/// A tick label at the precision of the tick step `step`, without trailing zeros (so ticks
/// 0.002 apart near P = 1 read 0.996, 0.998, 1).
fn trim(v: f64, step: f64) -> String {
    let decimals = (-step.log10() - 1e-9).ceil().max(2.0) as usize;
    let s = format!("{v:.decimals$}");
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
        // Ticks 0.002 apart keep their third decimal.
        assert_eq!(trim(0.998, 0.002), "0.998");
        assert_eq!(trim(1.0, 0.002), "1");
        assert_eq!(trim(0.5, 0.1), "0.5");
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

    /// The score curves: a polyline per subject, the 0.99 precision line, and each subject's
    /// AP and recall at 99 % precision in the legend.
    #[test]
    fn score_curves_have_a_polyline_per_subject() {
        let a = crate::eval::ranking::curve(&[(9.0, true), (8.0, true), (2.0, false)], 3);
        let b = crate::eval::ranking::curve(&[(1.0, true), (0.5, false)], 3);
        let svg = score_curves_svg(&[("words-3".into(), &a), ("icp".into(), &b)], "B");
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG/XML");
        let lines = doc.descendants().filter(|n| n.has_tag_name("polyline"));
        assert_eq!(lines.count(), 2);
        assert!(svg.contains("AP 0.667, max F1 0.800 at t = 8.00"), "{svg}");
        assert!(svg.contains("R 0.667 at P ≥ 0.99, 0.667 at P = 1"), "{svg}");
        if let Ok(path) = std::env::var("PLACEWORDS_SCORE_PLOT_SAMPLE") {
            std::fs::write(path, &svg).unwrap();
        }
    }
}
