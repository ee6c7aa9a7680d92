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
    candidates
        .into_iter()
        .map(|c| {
            let jw = strsim::jaro_winkler(&lower, &c.to_lowercase());
            let lev = strsim::normalized_damerau_levenshtein(&lower, &c.to_lowercase());
            (c, jw.max(lev))
        })
        .filter(|(_, score)| *score >= 0.75)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(c, _)| c)
}

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
}
