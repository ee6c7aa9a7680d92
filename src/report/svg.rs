//! A tiny SVG writer: hand-written SVG text, pure Rust, no fonts needed (the viewer picks a
//! sans-serif). Coordinates are pixels; callers map metres to pixels.

use std::fmt::Write;

pub use super::xml::escape;

/// Formats a pixel coordinate compactly (two decimals, no trailing zeros).
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let s = format!("{x:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.to_string()
    }
}

/// About how wide `text` is drawn at `font_px` in the sans-serif the documents name (DejaVu Sans
/// averages 0.6 em a character; a little more than most text needs), pixels: for sizing a
/// document so that its title is not cut off.
pub fn text_width_px(text: &str, font_px: f64) -> f64 {
    0.6 * font_px * text.chars().count() as f64
}

/// Accumulates an SVG document.
pub struct Svg {
    buf: String,
    depth: usize,
}

impl Svg {
    /// Starts a document `width` × `height` pixels with a white background.
    pub fn new(width: f64, height: f64) -> Self {
        let mut buf = String::new();
        let _ = writeln!(
            buf,
            r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">
<rect x="0" y="0" width="{w}" height="{h}" fill="white"/>"#,
            w = num(width),
            h = num(height)
        );
        Svg { buf, depth: 0 }
    }

    /// Appends a raw element line (already well-formed SVG).
    pub fn raw(&mut self, s: &str) {
        self.buf.push_str(s);
        self.buf.push('\n');
    }

    /// Opens a group with the given attributes (e.g. `id="walls" class="walls"`).
    pub fn open_group(&mut self, attrs: &str) {
        let _ = writeln!(self.buf, "<g {attrs}>");
        self.depth += 1;
    }

    pub fn close_group(&mut self) {
        if self.depth > 0 {
            self.buf.push_str("</g>\n");
            self.depth -= 1;
        }
    }

    /// A line; `attrs` holds stroke and class attributes.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), attrs: &str) {
        let _ = writeln!(
            self.buf,
            r#"<line x1="{}" y1="{}" x2="{}" y2="{}" {attrs}/>"#,
            num(a.0),
            num(a.1),
            num(b.0),
            num(b.1)
        );
    }

    /// A polyline (or a polygon when `closed`).
    pub fn polyline(&mut self, pts: &[(f64, f64)], closed: bool, attrs: &str) {
        let p: Vec<String> = pts
            .iter()
            .map(|(x, y)| format!("{},{}", num(*x), num(*y)))
            .collect();
        let tag = if closed { "polygon" } else { "polyline" };
        let _ = writeln!(self.buf, r#"<{tag} points="{}" {attrs}/>"#, p.join(" "));
    }

    pub fn circle(&mut self, c: (f64, f64), r: f64, attrs: &str) {
        let _ = writeln!(
            self.buf,
            r#"<circle cx="{}" cy="{}" r="{}" {attrs}/>"#,
            num(c.0),
            num(c.1),
            num(r)
        );
    }

    pub fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, attrs: &str) {
        let _ = writeln!(
            self.buf,
            r#"<rect x="{}" y="{}" width="{}" height="{}" {attrs}/>"#,
            num(x),
            num(y),
            num(w),
            num(h)
        );
    }

    /// A path with data `d`.
    pub fn path(&mut self, d: &str, attrs: &str) {
        let _ = writeln!(self.buf, r#"<path d="{d}" {attrs}/>"#);
    }

    /// Text at a point; the content is escaped here.
    pub fn text(&mut self, at: (f64, f64), content: &str, attrs: &str) {
        let _ = writeln!(
            self.buf,
            r#"<text x="{}" y="{}" {attrs}>{}</text>"#,
            num(at.0),
            num(at.1),
            escape(content)
        );
    }

    /// Closes open groups and the document.
    pub fn finish(mut self) -> String {
        while self.depth > 0 {
            self.close_group();
        }
        self.buf.push_str("</svg>\n");
        self.buf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }

    #[test]
    fn numbers_are_compact() {
        assert_eq!(num(1.50), "1.5");
        assert_eq!(num(2.0), "2");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(f64::NAN), "0");
    }
}
