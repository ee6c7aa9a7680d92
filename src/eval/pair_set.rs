//! Sets of index pairs `(a, b)` kept as sorted packed `u64`s: 8 bytes a pair instead of the 16
//! (plus hashing slack, about 34 in all) of a `HashSet<(usize, usize)>`, which is what lets a
//! thousand-lap run with millions of distinct observation pairs be scored in bounded memory.
//! Both indices must be below 2³² (observation and lap indices are; a run would need hundreds of
//! millions of laps to pass it).

use std::hash::{BuildHasherDefault, Hasher};

/// `a` in the high half, `b` in the low half.
pub fn pack(a: usize, b: usize) -> u64 {
    debug_assert!(a <= u32::MAX as usize && b <= u32::MAX as usize);
    ((a as u64) << 32) | (b as u64 & 0xffff_ffff)
}

/// A hash map keyed by packed pairs ([`pack`]) whose hash keeps a run of pairs together.
pub type PairMap<V> = std::collections::HashMap<u64, V, BuildHasherDefault<PairHasher>>;

/// Hashes a packed pair `(a, b)` so that the pairs of one block of 16 consecutive `a` and 16
/// consecutive `b` fall in 16 consecutive buckets, by `a`'s low 4 bits, at a place mixed from the
/// block (SplitMix64's finaliser). Consecutive pairs of a match (`(q + i, p ± i)`) then share a
/// few cache lines of the table instead of one line each, which is what scoring as matches
/// arrive spent its time on (BENCHMARKS.md, issue 30). At most 16 pairs of any input share a
/// bucket's place (those of one `a` and one block of `b`), so no input makes the probing long.
/// The low 4 bits are the bucket's; hashbrown tells keys apart by the top 7, which are mixed.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairHasher(u64);

impl Hasher for PairHasher {
    fn finish(&self) -> u64 {
        let (a, b) = (self.0 >> 32, self.0 & 0xffff_ffff);
        let mut m = (a >> 4) << 32 | (b >> 4);
        m = (m ^ (m >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        m = (m ^ (m >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        m ^= m >> 31;
        (m & !15) | (a & 15)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = v;
    }
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

    /// The pairs of a run share 16 consecutive buckets per block, and distinct blocks differ in
    /// the bits hashbrown tells keys apart by.
    #[test]
    fn pair_hash_keeps_a_run_together() {
        use std::hash::BuildHasher;
        let h =
            |a: usize, b: usize| BuildHasherDefault::<PairHasher>::default().hash_one(pack(a, b));
        for i in 0..16 {
            assert_eq!(h(32 + i, 48 + i) & !15, h(32, 48) & !15);
            assert_eq!(h(32 + i, 48 + i) & 15, i as u64);
        }
        let tops: std::collections::HashSet<u64> =
            (0..64).map(|k| h(16 * k, 7 * 16 * k) >> 57).collect();
        assert!(tops.len() > 32, "{}", tops.len());
        let mut m: PairMap<u8> = PairMap::default();
        for q in 0..2000 {
            *m.entry(pack(q, q / 3)).or_insert(0) += 1;
            *m.entry(pack(q, q / 3)).or_insert(0) += 1;
        }
        assert!(m.len() == 2000 && m.values().all(|&v| v == 2));
    }

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
