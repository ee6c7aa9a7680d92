//! "Did you mean" hints: the closest known name to a misspelt one, and the unit a number seems
//! to be written in (radians for a heading in degrees, millimetres or centimetres for metres).

use crate::spec::diag::fmt_number;

/// The candidate closest to `word`, if it is close enough to be a plausible typo.
pub fn closest<'a, I>(word: &str, candidates: I) -> Option<&'a str>
where
    I: IntoIterator<Item = &'a str>,
{
    // No typo is this long, and comparing a huge word costs time and memory.
    if word.chars().count() > 64 {
        return None;
    }
    let lower = word.to_lowercase();
    // By meaning first: a word that names what a known key means (a wall's `width_m` is its
    // `thickness_m`), when that key is a candidate here.
    let all: Vec<&'a str> = candidates.into_iter().collect();
    if let Some(&(_, meant)) = MEANINGS
        .iter()
        .find(|(w, m)| *w == lower && all.contains(m))
    {
        return all.into_iter().find(|c| *c == meant);
    }
    all.into_iter()
        .map(|c| {
            let jw = strsim::jaro_winkler(&lower, &c.to_lowercase());
            let lev = strsim::normalized_damerau_levenshtein(&lower, &c.to_lowercase());
            (c, jw.max(lev))
        })
        .filter(|(_, score)| *score >= 0.75)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(c, _)| c)
}

/// Words people write for a known key that spelling alone does not lead to: (word, key).
/// Each applies only where the key is allowed (a wall's `width_m` is its `thickness_m`; a
/// door has a `width_m` of its own).
const MEANINGS: &[(&str, &str)] = &[
    ("width_m", "thickness_m"),
    ("width", "thickness_m"),
    ("thick_m", "thickness_m"),
    ("length_m", "width_m"),
    ("size_m", "width_m"),
    ("points", "points_m"),
    ("vertices_m", "points_m"),
    ("waypoints", "waypoints_m"),
    ("points_m", "waypoints_m"),
    ("hinge", "hinge_m"),
    ("position_m", "hinge_m"),
    ("theta_deg", "heading_deg"),
    ("yaw_deg", "heading_deg"),
    ("angle_deg", "heading_deg"),
];

/// `; did you mean `x`?` or, with no close candidate, a list of what is allowed.
pub fn hint<'a, I>(word: &str, candidates: I, what: &str) -> String
where
    I: IntoIterator<Item = &'a str> + Clone,
{
    match closest(word, candidates.clone()) {
        Some(c) => format!("did you mean `{c}`?"),
        None => {
            let all: Vec<&str> = candidates.into_iter().take(12).collect();
            if all.is_empty() {
                format!("there are no {what}")
            } else {
                format!("known {what}: {}", all.join(", "))
            }
        }
    }
}

/// Units a length in metres is often written in by mistake: (name, how many make a metre).
const LENGTH_UNITS: [(&str, f64); 2] = [("millimetres", 1000.0), ("centimetres", 100.0)];

/// `VALUE looks like millimetres (M m); write KEY = M` when a length `x` that should be metres
/// lies outside `typical_m` while `x` read as millimetres (or else centimetres) lies inside it.
pub fn length_unit_hint(key: &str, x: f64, typical_m: (f64, f64)) -> Option<String> {
    let fits = |m: f64| m >= typical_m.0 && m <= typical_m.1;
    if fits(x) {
        return None;
    }
    LENGTH_UNITS.iter().find_map(|&(unit, per_m)| {
        let m = x / per_m;
        fits(m).then(|| {
            format!(
                "{} looks like {unit} ({} m); lengths are metres: write {key} = {}",
                fmt_number(x),
                fmt_number(m),
                fmt_number(m)
            )
        })
    })
}

/// The heading in whole degrees that `deg` means if it was written in radians: a value within
/// one turn of radians (|x| <= 2 pi), not a whole number, that in degrees lies within half a
/// degree of a multiple of 15 (1.57 is 89.95 degrees: 90). Headings people mean in degrees are
/// whole numbers almost always; quarter and eighth turns in radians almost never are.
pub fn radians_as_degrees(deg: f64) -> Option<f64> {
    let as_deg = deg.to_degrees();
    let nearest = (as_deg / 15.0).round() * 15.0;
    (deg.is_finite()
        && deg.fract() != 0.0
        && deg.abs() <= std::f64::consts::TAU + 0.01
        && (as_deg - nearest).abs() <= 0.5
        && nearest != 0.0)
        .then_some(nearest)
}

/// `KEY = VALUE looks like radians (D degrees); headings are degrees: write KEY = D`.
pub fn radians_hint(key: &str, deg: f64) -> Option<String> {
    radians_as_degrees(deg).map(|d| {
        format!(
            "{key} = {} looks like radians ({} degrees); headings are degrees: write {key} = {}",
            fmt_number(deg),
            fmt_number(d),
            fmt_number(d)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_unit_suffix_and_typos() {
        let keys = ["id", "hinge_m", "width_m", "closed_heading_deg"];
        assert_eq!(closest("width", keys), Some("width_m"));
        assert_eq!(closest("widht_m", keys), Some("width_m"));
        assert_eq!(closest("hinge", keys), Some("hinge_m"));
        assert_eq!(closest("colour", keys), None);
    }

    #[test]
    fn suggests_by_meaning_where_the_key_is_allowed() {
        let wall = ["id", "points_m", "closed", "thickness_m"];
        assert_eq!(closest("width_m", wall), Some("thickness_m"));
        let door = ["id", "hinge_m", "width_m", "thickness_m"];
        assert_eq!(closest("length_m", door), Some("width_m"));
        assert_eq!(closest("widht_m", door), Some("width_m"));
    }

    #[test]
    #[allow(clippy::approx_constant)] // 3.1416 is what a user types for 180 degrees
    fn radians_and_small_units_are_recognised() {
        assert_eq!(radians_as_degrees(1.57), Some(90.0));
        assert_eq!(radians_as_degrees(3.1416), Some(180.0));
        assert_eq!(radians_as_degrees(-0.785), Some(-45.0));
        // Whole degrees, odd fractions and values past one turn are degrees.
        assert_eq!(radians_as_degrees(90.0), None);
        assert_eq!(radians_as_degrees(1.3), None);
        assert_eq!(radians_as_degrees(12.5), None);
        let door = (0.6, 1.5);
        assert!(
            length_unit_hint("width_m", 900.0, door)
                .unwrap()
                .contains("millimetres (0.9 m)")
        );
        assert!(
            length_unit_hint("width_m", 90.0, door)
                .unwrap()
                .contains("centimetres (0.9 m)")
        );
        assert_eq!(length_unit_hint("width_m", 0.9, door), None);
        assert_eq!(length_unit_hint("width_m", 30.0, door), None);
    }
}
