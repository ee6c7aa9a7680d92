//! Sets of index pairs `(a, b)` kept as sorted packed `u64`s: 8 bytes a pair instead of the 16
//! (plus hashing slack, about 34 in all) of a `HashSet<(usize, usize)>`, which is what lets a
//! thousand-lap run with millions of distinct observation pairs be scored in bounded memory.
//! Both indices must be below 2³² (observation and lap indices are; a run would need hundreds of
//! millions of laps to pass it).

/// `a` in the high half, `b` in the low half.
pub fn pack(a: usize, b: usize) -> u64 {
    debug_assert!(a <= u32::MAX as usize && b <= u32::MAX as usize);
    ((a as u64) << 32) | (b as u64 & 0xffff_ffff)
}

/// A set of pairs, built once from any sequence (duplicates collapse).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PairSet(Vec<u64>);

impl PairSet {
    /// The distinct pairs of `pairs`. Duplicates are dropped whenever the buffer doubles since
    /// the last clean-up, so it holds at most about twice the distinct pairs (matches of several
    /// levels repeat most pairs), at O(n log n) in all.
    pub fn from_pairs(pairs: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut v: Vec<u64> = Vec::new();
        let mut clean = 0usize;
        for (a, b) in pairs {
            v.push(pack(a, b));
            if v.len() >= 2 * clean.max(1 << 16) {
                v.sort_unstable();
                v.dedup();
                clean = v.len();
            }
        }
        v.sort_unstable();
        v.dedup();
        v.shrink_to_fit();
        PairSet(v)
    }

    /// Distinct pairs held.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn contains(&self, a: usize, b: usize) -> bool {
        self.0.binary_search(&pack(a, b)).is_ok()
    }

    /// The pairs in increasing order of `(a, b)`.
    pub fn iter(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.0
            .iter()
            .map(|&v| ((v >> 32) as usize, (v & 0xffff_ffff) as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_collapse_and_lookups_find_exactly_the_pairs_given() {
        let s = PairSet::from_pairs([(3, 1), (0, 7), (3, 1), (1 << 31, 5)]);
        assert_eq!(s.len(), 3);
        assert!(s.contains(3, 1) && s.contains(0, 7) && s.contains(1 << 31, 5));
        assert!(!s.contains(1, 3) && !s.contains(0, 0) && !s.contains(5, 1 << 31));
        let back: Vec<_> = s.iter().collect();
        assert_eq!(back, vec![(0, 7), (3, 1), (1 << 31, 5)]);
        assert!(PairSet::from_pairs([]).is_empty());
    }
}
