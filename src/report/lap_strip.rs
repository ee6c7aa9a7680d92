//! A strip of recall and precision per lap, laps in driving order, each lap's column shaded by
//! its door configuration and each run's first lap marked: where along the experiment the
//! recognizer found or lost places, and under which doors.

use super::svg::{Svg, num, text_width_px};

/// One lap's figures.
#[derive(Clone, Debug, PartialEq)]
pub struct LapPoint {
    pub run: usize,
    pub door_config: String,
    /// Share of its observations with a revisit that were recognized; `None` without revisits.
    pub recall: Option<f64>,
    /// Share of the pairs whose query lies in the lap that are correct; `None` without pairs.
    pub precision: Option<f64>,
}

const LEFT: f64 = 60.0;
const RIGHT: f64 = 230.0;
const TOP: f64 = 40.0;
const PLOT_H: f64 = 220.0;
const BOTTOM: f64 = 50.0;
const RECALL_COLOR: &str = "#0072b2";
const PRECISION_COLOR: &str = "#d55e00";
/// Pale shades for door configurations (cycled).
const SHADES: [&str; 8] = [
    "#f2f2f2", "#fde0c5", "#d6ecfa", "#dff3d8", "#f6d8ea", "#fff2b3", "#e4dcf5", "#d9f2ef",
];

/// The strip as an SVG document.
pub fn lap_strip(laps: &[LapPoint], title: &str) -> String {
    let col = (900.0 / laps.len().max(1) as f64).clamp(6.0, 30.0);
    let pw = col * laps.len().max(1) as f64;
    // A log of one lap makes a narrow strip; the title still fits.
    let w = (LEFT + pw + RIGHT).max(text_width_px(title, 15.0) + 20.0);
    let h = TOP + PLOT_H + BOTTOM;
    let x = |i: f64| LEFT + i * col;
    let y = |v: f64| TOP + (1.0 - v) * PLOT_H;
    let mut configs: Vec<&str> = Vec::new();
    for l in laps {
        if !configs.contains(&l.door_config.as_str()) {
            configs.push(&l.door_config);
        }
    }
    let shade = |c: &str| SHADES[configs.iter().position(|k| *k == c).unwrap_or(0) % SHADES.len()];
    let mut svg = Svg::new(w, h);
    svg.text(
        (w / 2.0, 22.0),
        title,
        r#"text-anchor="middle" font-size="15""#,
    );
    for (i, l) in laps.iter().enumerate() {
        let fill = format!(r#"fill="{}""#, shade(&l.door_config));
        svg.rect(x(i as f64), TOP, col, PLOT_H, &fill);
        if i == 0 || laps[i - 1].run != l.run {
            svg.line(
                (x(i as f64), TOP - 6.0),
                (x(i as f64), TOP + PLOT_H),
                r##"stroke="#555" stroke-width="1.5""##,
            );
            svg.text(
                (x(i as f64) + 2.0, TOP - 8.0),
                &format!("run {}", l.run),
                r#"font-size="10""#,
            );
        }
    }
    for v in [0.0, 0.25, 0.5, 0.75, 1.0] {
        svg.line(
            (LEFT, y(v)),
            (LEFT + pw, y(v)),
            r##"stroke="#bbb" stroke-width="0.5""##,
        );
        svg.text(
            (LEFT - 6.0, y(v) + 4.0),
            &num(v),
            r#"text-anchor="end" font-size="11""#,
        );
    }
    let step = ((laps.len() as f64 / 10.0).ceil() as usize).max(1);
    for i in (0..laps.len()).step_by(step) {
        svg.text(
            (x(i as f64 + 0.5), TOP + PLOT_H + 16.0),
            &i.to_string(),
            r#"text-anchor="middle" font-size="11""#,
        );
    }
    svg.text(
        (LEFT + pw / 2.0, h - 12.0),
        "lap (driving order)",
        r#"text-anchor="middle" font-size="12""#,
    );
    series(&mut svg, laps, |l| l.recall, RECALL_COLOR, &x, &y);
    series(&mut svg, laps, |l| l.precision, PRECISION_COLOR, &x, &y);
    svg.rect(LEFT, TOP, pw, PLOT_H, r##"fill="none" stroke="#333""##);
    legend(&mut svg, LEFT + pw + 14.0, &configs, &shade);
    svg.finish()
}

/// A series as dots joined by lines (gaps where a lap has no value).
fn series(
    svg: &mut Svg,
    laps: &[LapPoint],
    value: impl Fn(&LapPoint) -> Option<f64>,
    color: &str,
    x: &dyn Fn(f64) -> f64,
    y: &dyn Fn(f64) -> f64,
) {
    let mut run: Vec<(f64, f64)> = Vec::new();
    let line = format!(r#"fill="none" stroke="{color}" stroke-width="1.5""#);
    for (i, l) in laps.iter().enumerate() {
        match value(l) {
            Some(v) => {
                let p = (x(i as f64 + 0.5), y(v.clamp(0.0, 1.0)));
                svg.circle(p, 2.5, &format!(r#"fill="{color}""#));
                run.push(p);
            }
            None => {
                if run.len() > 1 {
                    svg.polyline(&run, false, &line);
                }
                run.clear();
            }
        }
    }
    if run.len() > 1 {
        svg.polyline(&run, false, &line);
    }
}

fn legend(svg: &mut Svg, x0: f64, configs: &[&str], shade: &dyn Fn(&str) -> &'static str) {
    let mut y0 = TOP + 8.0;
    for (label, color) in [("recall", RECALL_COLOR), ("precision", PRECISION_COLOR)] {
        svg.line(
            (x0, y0),
            (x0 + 20.0, y0),
            &format!(r#"stroke="{color}" stroke-width="2""#),
        );
        svg.text((x0 + 26.0, y0 + 4.0), label, r#"font-size="12""#);
        y0 += 18.0;
    }
    svg.text((x0, y0 + 6.0), "doors:", r#"font-size="12""#);
    y0 += 18.0;
    for c in configs {
        svg.rect(
            x0,
            y0 - 9.0,
            20.0,
            12.0,
            &format!(r##"fill="{}" stroke="#999""##, shade(c)),
        );
        svg.text((x0 + 26.0, y0 + 2.0), c, r#"font-size="12""#);
        y0 += 18.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strip_has_a_column_per_lap_and_both_series() {
        let laps: Vec<LapPoint> = (0..6)
            .map(|i| LapPoint {
                run: i / 3,
                door_config: if i % 2 == 0 { "closed" } else { "a<b" }.into(),
                recall: (i > 0).then_some(0.1 * i as f64),
                precision: Some(0.9),
            })
            .collect();
        let svg = lap_strip(&laps, "B: per lap");
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG");
        let dots = doc
            .descendants()
            .filter(|n| n.has_tag_name("circle"))
            .count();
        assert_eq!(dots, 5 + 6);
        assert!(svg.contains("a&lt;b") && svg.contains("run 1"));
    }

    /// A real log is one lap: its strip is narrow, and the document is widened to its title.
    #[test]
    fn a_strip_of_one_lap_is_as_wide_as_its_title() {
        let lap = LapPoint {
            run: 0,
            door_config: "unknown".into(),
            recall: Some(0.5),
            precision: Some(0.97),
        };
        let title = "intel-corrected: recall and precision per lap, 3 level(s)";
        let svg = lap_strip(&[lap], title);
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG");
        let width: f64 = doc
            .root_element()
            .attribute("width")
            .unwrap()
            .parse()
            .unwrap();
        assert!(width >= text_width_px(title, 15.0), "{width}");
    }
}
