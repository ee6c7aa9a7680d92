//! Which seeds to run and which part of the work a CI job takes: a [`SeedRange`] (`"1..20"`,
//! both ends included, or one seed `"7"`) and a [`Shard`] (`"2/4"`, the second of four parts).
//!
//! The scenario's seed is the root of every random stream of the simulator (`sim::rng`), so a
//! seed re-draws everything random: noise, doors drawn at random, people, lap variation.

use std::fmt;
use std::str::FromStr;

/// Most seeds one range may hold: a stress test of more seeds than this is a typo, not a plan.
pub const MAX_SEEDS: u64 = 10_000;

/// Most parts the work may be cut into.
pub const MAX_SHARDS: usize = 10_000;

/// Seeds `first..=last` (written `"first..last"`, both ends included, or `"seed"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SeedRange {
    pub first: u64,
    pub last: u64,
}

impl SeedRange {
    /// The range holding only `seed`.
    pub fn one(seed: u64) -> Self {
        SeedRange {
            first: seed,
            last: seed,
        }
    }

    /// The seeds, in increasing order.
    pub fn seeds(&self) -> impl Iterator<Item = u64> + use<> {
        self.first..=self.last
    }

    /// How many seeds the range holds.
    pub fn len(&self) -> u64 {
        self.last - self.first + 1
    }

    /// Never true (a range holds at least one seed); for clippy's `len` rule.
    pub fn is_empty(&self) -> bool {
        false
    }
}

impl fmt::Display for SeedRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.first == self.last {
            write!(f, "{}", self.first)
        } else {
            write!(f, "{}..{}", self.first, self.last)
        }
    }
}

impl FromStr for SeedRange {
    type Err = String;

    /// `"A..B"` (A ≤ B, both included) or `"N"`; at most [`MAX_SEEDS`] seeds.
    fn from_str(s: &str) -> Result<Self, String> {
        let num = |t: &str| {
            t.trim().parse::<u64>().map_err(|_| {
                format!("`{t}` is not a seed; seeds are integers 0 or more, e.g. \"1..20\"")
            })
        };
        let (first, last) = match s.split_once("..") {
            Some((a, b)) => (num(a)?, num(b.strip_prefix('=').unwrap_or(b))?),
            None => {
                let n = num(s)?;
                (n, n)
            }
        };
        if first > last {
            return Err(format!(
                "seed range `{s}` is empty; write the smaller seed first, e.g. \"{last}..{first}\""
            ));
        }
        if last - first >= MAX_SEEDS {
            return Err(format!(
                "seed range `{s}` holds more than {MAX_SEEDS} seeds; use a shorter range"
            ));
        }
        Ok(SeedRange { first, last })
    }
}

/// Part `index` (1-based) of `count` disjoint parts of a run's (scenario × seed) work.
///
/// Read back from a part file through [`Shard::new`], so a part with index 0, an index above
/// its count, or a count of 0 or above [`MAX_SHARDS`] is refused where it is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "RawShard")]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

/// A shard as a file writes it, before [`Shard::new`] checks it.
#[derive(serde::Deserialize)]
struct RawShard {
    index: u64,
    count: u64,
}

impl TryFrom<RawShard> for Shard {
    type Error = String;

    fn try_from(raw: RawShard) -> Result<Self, String> {
        // u64 first: on a 32-bit target a huge count must be refused, not wrapped.
        let fit = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
        Shard::new(fit(raw.index), fit(raw.count))
            .map_err(|e| format!("shard {}/{}: {e}", raw.index, raw.count))
    }
}

/// Environment variable `name`, when set and not blank.
fn env_var(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|v| !v.trim().is_empty())
}

/// The number of parts from `PLACEWORDS_SHARD_COUNT`.
fn shard_count_from_env() -> Result<usize, String> {
    let n = env_var("PLACEWORDS_SHARD_COUNT").ok_or(
        "--shard auto needs the number of parts: --shard-count N or \
         PLACEWORDS_SHARD_COUNT=N (the Job's completions)",
    )?;
    n.trim()
        .parse()
        .map_err(|_| format!("PLACEWORDS_SHARD_COUNT = `{n}` is not a positive integer"))
}

impl Shard {
    /// Whether the work item at position `item` (0-based, in plan order) is this shard's. Items
    /// are dealt round-robin, so every shard gets a share of every scenario's seeds.
    pub fn owns(&self, item: usize) -> bool {
        item % self.count == self.index - 1
    }

    /// The shard of a Kubernetes Indexed Job: `JOB_COMPLETION_INDEX` (0-based) is the part,
    /// `count` (a flag) or else `PLACEWORDS_SHARD_COUNT` the number of parts.
    pub fn from_env(count: Option<usize>) -> Result<Self, String> {
        let index = env_var("JOB_COMPLETION_INDEX").ok_or(
            "--shard auto needs JOB_COMPLETION_INDEX (set by a Kubernetes Indexed Job); \
             or give --shard K/N",
        )?;
        let index: usize = index.trim().parse().map_err(|_| {
            format!("JOB_COMPLETION_INDEX = `{index}` is not a non-negative integer")
        })?;
        let count = match count {
            Some(n) => n,
            None => shard_count_from_env()?,
        };
        // JOB_COMPLETION_INDEX counts from 0: part index + 1 (checked: u64::MAX must not wrap
        // to part 0).
        if count == 0 || count > MAX_SHARDS {
            return Shard::new(1, count);
        }
        if index >= count {
            return Err(format!(
                "JOB_COMPLETION_INDEX = {index} is not a part of {count}: it counts from 0 to {}",
                count - 1
            ));
        }
        Shard::new(index + 1, count)
    }

    /// Part `index` of `count`, checked: 1 ≤ index ≤ count ≤ [`MAX_SHARDS`].
    pub fn new(index: usize, count: usize) -> Result<Self, String> {
        if count == 0 || count > MAX_SHARDS {
            return Err(format!(
                "{count} parts: use 1 to {MAX_SHARDS} parts (`--shard K/N`)"
            ));
        }
        if index == 0 || index > count {
            return Err(format!(
                "part {index} of {count} does not exist; K runs from 1 to {count} in `--shard K/{count}`"
            ));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;

    /// `"K/N"`: part K (1-based) of N.
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}` is not a shard; write K/N, e.g. 2/4 (the second of 4 parts)");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        Shard::new(k, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_include_both_ends() {
        let r: SeedRange = "1..20".parse().unwrap();
        assert_eq!(r.len(), 20);
        assert_eq!(r.seeds().next(), Some(1));
        assert_eq!(r.seeds().last(), Some(20));
        assert_eq!(r.to_string(), "1..20");
        assert_eq!("7".parse::<SeedRange>().unwrap(), SeedRange::one(7));
        assert_eq!("3..=4".parse::<SeedRange>().unwrap().len(), 2);
    }

    #[test]
    fn bad_ranges_say_what_to_write() {
        assert!(
            "20..1"
                .parse::<SeedRange>()
                .unwrap_err()
                .contains("\"1..20\"")
        );
        assert!("a..3".parse::<SeedRange>().unwrap_err().contains("`a`"));
        assert!(
            "0..99999"
                .parse::<SeedRange>()
                .unwrap_err()
                .contains("10000")
        );
    }

    #[test]
    fn shards_split_the_work_into_disjoint_parts_covering_it() {
        let shards: Vec<Shard> = (1..=3).map(|k| format!("{k}/3").parse().unwrap()).collect();
        for item in 0..10 {
            assert_eq!(shards.iter().filter(|s| s.owns(item)).count(), 1);
        }
        assert!("0/3".parse::<Shard>().is_err());
        assert!("4/3".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().unwrap_err().contains("K/N"));
    }

    #[test]
    fn a_shard_read_from_a_file_is_checked() {
        let read = |s: &str| serde_json::from_str::<Shard>(s);
        assert_eq!(
            read(r#"{"index":2,"count":4}"#).unwrap(),
            Shard::new(2, 4).unwrap()
        );
        for bad in [
            r#"{"index":0,"count":1}"#,
            r#"{"index":1,"count":0}"#,
            r#"{"index":3,"count":2}"#,
            r#"{"index":1,"count":1000000000000}"#,
            r#"{"index":1,"count":18446744073709551615}"#,
        ] {
            let e = read(bad).unwrap_err().to_string();
            assert!(e.contains("shard ") && e.contains("part"), "{bad}: {e}");
        }
    }
}
