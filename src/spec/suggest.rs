//! "Did you mean" hints: the closest known name to a misspelt one.

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
}
