//! Sets of index pairs `(a, b)` kept as sorted packed `u64`s: 8 bytes a pair instead of the 16
//! (plus hashing slack, about 34 in all) of a `HashSet<(usize, usize)>`, which is what lets a
//! thousand-lap run with millions of distinct observation pairs be scored in bounded memory.
//! Both indices must be below 2³² (observation and lap indices are; a run would need hundreds of
//! millions of laps to pass it).

use foldhash::HashMap;
use std::cell::Cell;
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

/// A line `(step, key)`, an interval of `q` along it, and whether the interval is held.
type Lookup = (i8, i64, [usize; 2], bool);

/// A set of index pairs `(q, p)` kept as intervals of `q` along the lines `p = key + step·q`
/// of the runs that made them (a match's aligned run of step `step` lies on one such line), so
/// a run of pairs costs one interval, not an entry per pair, and a pair is looked up in a small
/// map of lines that stays in cache. Scoring as matches arrive keeps the distinct pairs it has
/// counted this way (`eval::tally`): later matches of a chain repeat most of the earlier ones'
/// pairs, along the same lines. A pair inserted along several lines is held once per line, and
/// [`RunSet::remove_below`] lists it once per line (its caller removes the repeats).
#[derive(Clone, Debug, Default)]
pub struct RunSet {
    /// `(step, key)` → sorted, disjoint, non-touching half-open intervals of `q`.
    lines: HashMap<(i8, i64), Vec<[usize; 2]>>,
    /// The steps of the lines held (usually one).
    steps: Vec<i8>,
    /// The interval being extended by consecutive inserts, not yet in `lines`.
    open: Option<(i8, i64, [usize; 2])>,
    /// The last lookup in `lines`: a line, an interval of it held or a gap between two, and
    /// which (the pairs of a run are looked up one after the other along one line).
    last: Cell<Option<Lookup>>,
}

impl RunSet {
    /// Whether `(q, p)` is held.
    pub fn contains(&self, q: usize, p: usize) -> bool {
        self.steps.iter().any(|&t| {
            let key = line_key(t, q, p);
            if let Some((s, k, [a, b])) = self.open
                && (s, k) == (t, key)
                && (a..b).contains(&q)
            {
                return true;
            }
            if let Some((s, k, [a, b], held)) = self.last.get()
                && (s, k) == (t, key)
                && (a..b).contains(&q)
            {
                return held;
            }
            let (range, held) = match self.lines.get(&(t, key)) {
                None => ([0, usize::MAX], false),
                Some(iv) => {
                    let i = iv.partition_point(|v| v[1] <= q);
                    match iv.get(i) {
                        Some(&v) if v[0] <= q => (v, true),
                        next => {
                            let from = i.checked_sub(1).map_or(0, |j| iv[j][1]);
                            ([from, next.map_or(usize::MAX, |v| v[0])], false)
                        }
                    }
                }
            };
            self.last.set(Some((t, key, range, held)));
            held
        })
    }

    /// Adds `(q, p)`, on the line of step `step` through it. Consecutive inserts along one line
    /// (`q` one more each time) extend one interval.
    pub fn insert(&mut self, q: usize, p: usize, step: i8) {
        let key = line_key(step, q, p);
        if let Some((s, k, iv)) = &mut self.open
            && (*s, *k) == (step, key)
            && iv[1] == q
        {
            iv[1] += 1;
            return;
        }
        self.settle();
        if !self.steps.contains(&step) {
            self.steps.push(step);
        }
        self.open = Some((step, key, [q, q + 1]));
    }

    /// Merges the open interval into its line.
    fn settle(&mut self) {
        let Some((s, k, [a, b])) = self.open.take() else {
            return;
        };
        self.last.set(None);
        let iv = self.lines.entry((s, k)).or_default();
        // The intervals that overlap or touch [a, b) are iv[i..j].
        let i = iv.partition_point(|v| v[1] < a);
        let j = iv.partition_point(|v| v[0] <= b);
        if i < j {
            let joined = [a.min(iv[i][0]), b.max(iv[j - 1][1])];
            iv.splice(i..j, [joined]);
        } else {
            iv.insert(i, [a, b]);
        }
    }

    /// Pairs held (a pair held along two lines counts twice).
    pub fn len(&self) -> usize {
        let open = self.open.map_or(0, |(.., [a, b])| b - a);
        let lines: usize = self.lines.values().flatten().map(|v| v[1] - v[0]).sum();
        open + lines
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Drops the pairs whose `q` is below `h`, appending them packed ([`pack`]) to `gone`
    /// when given (unsorted; a pair held along two lines is appended once per line).
    pub fn remove_below(&mut self, h: usize, mut gone: Option<&mut Vec<u64>>) {
        self.settle();
        self.last.set(None);
        self.lines.retain(|&(t, key), iv| {
            let cut = iv.partition_point(|v| v[1] <= h);
            if let Some(gone) = gone.as_deref_mut() {
                for v in &iv[..cut.min(iv.len())] {
                    gone.extend((v[0]..v[1]).map(|q| pack(q, line_point(t, key, q))));
                }
                if let Some(v) = iv.get(cut).filter(|v| v[0] < h) {
                    gone.extend((v[0]..h).map(|q| pack(q, line_point(t, key, q))));
                }
            }
            iv.drain(..cut);
            if let Some(v) = iv.first_mut() {
                v[0] = v[0].max(h);
            }
            !iv.is_empty()
        });
        let lines = &self.lines;
        self.steps.retain(|t| lines.keys().any(|k| k.0 == *t));
    }
}

/// The key of the line of step `step` through `(q, p)`: `p − step·q`.
fn line_key(step: i8, q: usize, p: usize) -> i64 {
    p as i64 - i64::from(step) * q as i64
}

/// The `p` of the line `(step, key)` at `q`.
fn line_point(step: i8, key: i64, q: usize) -> usize {
    (key + i64::from(step) * q as i64) as usize
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

    /// A run set holds exactly the pairs inserted (along any lines, in any order) and not
    /// removed, and lists each removed pair once.
    #[test]
    fn run_set_holds_what_was_inserted_and_lists_what_it_drops() {
        use std::collections::BTreeSet;
        let mut set = RunSet::default();
        let mut want = BTreeSet::new();
        // Runs of step 1, −1 and 0, overlapping and touching, some pairs on two lines.
        let runs = [
            (10, 3, 5, 1),
            (12, 5, 6, 1),
            (8, 1, 2, 1),
            (20, 30, 4, -1),
            (11, 4, 3, 0),
        ];
        for (q0, p0, len, step) in runs {
            for i in 0..len {
                let (q, p) = (q0 + i, (p0 as i64 + i64::from(step) * i as i64) as usize);
                set.insert(q, p, step);
                want.insert((q, p));
            }
        }
        set.insert(40, 2, 1);
        set.insert(15, 8, 1);
        want.extend([(40, 2), (15, 8)]);
        let check = |set: &RunSet, want: &BTreeSet<(usize, usize)>| {
            for q in 0..45 {
                for p in 0..40 {
                    assert_eq!(set.contains(q, p), want.contains(&(q, p)), "({q}, {p})");
                }
            }
            // Along lines, as a run is looked up.
            for key in -12..12i64 {
                for q in 0..45usize {
                    let Ok(p) = usize::try_from(q as i64 + key) else {
                        continue;
                    };
                    assert_eq!(set.contains(q, p), want.contains(&(q, p)), "({q}, {p})");
                }
            }
        };
        check(&set, &want);
        for h in [11, 14, 22, 41] {
            let mut gone = Vec::new();
            set.remove_below(h, Some(&mut gone));
            gone.sort_unstable();
            gone.dedup();
            let dropped: Vec<u64> = want
                .iter()
                .filter(|&&(q, _)| q < h)
                .map(|&(q, p)| pack(q, p))
                .collect();
            assert_eq!(gone, dropped, "below {h}");
            want.retain(|&(q, _)| q >= h);
            check(&set, &want);
        }
        assert!(set.is_empty());
    }
}
