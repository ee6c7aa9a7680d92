//! The skeleton as a graph: a breadth-first tree over its 8-connected pixels, its fundamental
//! cycles (the loops one can drive) and its longest branch.

use crate::geom::Vec2;
use std::collections::{HashMap, VecDeque};

/// A breadth-first tree of the skeleton's pixels (row-major indices), rooted at the pixel
/// nearest the start cell.
pub(super) struct Tree<'a> {
    skel: &'a [bool],
    nx: usize,
    ny: usize,
    root: usize,
    parent: HashMap<usize, usize>,
    depth: HashMap<usize, usize>,
    /// Pixels in the order the search reached them.
    order: Vec<usize>,
}

impl<'a> Tree<'a> {
    /// The tree from the skeleton pixel nearest `start`; `None` for an empty skeleton.
    pub fn grow(skel: &'a [bool], nx: usize, ny: usize, start: (usize, usize)) -> Option<Tree<'a>> {
        let root = (0..nx * ny).filter(|&k| skel[k]).min_by_key(|&k| {
            let (i, j) = (k % nx, k / nx);
            (i as i64 - start.0 as i64).pow(2) + (j as i64 - start.1 as i64).pow(2)
        })?;
        let mut tree = Tree {
            skel,
            nx,
            ny,
            root,
            parent: HashMap::from([(root, root)]),
            depth: HashMap::from([(root, 0)]),
            order: vec![root],
        };
        let mut q = VecDeque::from([root]);
        while let Some(u) = q.pop_front() {
            for v in tree.neighbours(u) {
                if let std::collections::hash_map::Entry::Vacant(e) = tree.parent.entry(v) {
                    e.insert(u);
                    let d = tree.depth[&u] + 1;
                    tree.depth.insert(v, d);
                    tree.order.push(v);
                    q.push_back(v);
                }
            }
        }
        Some(tree)
    }

    /// The skeleton pixels among the 8 around `k`, row by row from below.
    fn neighbours(&self, k: usize) -> Vec<usize> {
        let (i, j) = ((k % self.nx) as i64, (k / self.nx) as i64);
        let mut v = Vec::with_capacity(8);
        for dj in -1..=1i64 {
            for di in -1..=1i64 {
                if di == 0 && dj == 0 {
                    continue;
                }
                let (a, b) = (i + di, j + dj);
                if a >= 0 && b >= 0 && (a as usize) < self.nx && (b as usize) < self.ny {
                    let q = b as usize * self.nx + a as usize;
                    if self.skel[q] {
                        v.push(q);
                    }
                }
            }
        }
        v
    }

    /// The fundamental cycle a non-tree edge (u, v) closes: u up to the common ancestor, then
    /// down to v.
    fn cycle_through(&self, u: usize, v: usize) -> Vec<usize> {
        let (mut a, mut b) = (u, v);
        let mut left = vec![a];
        let mut right = vec![b];
        while a != b {
            if self.depth[&a] >= self.depth[&b] {
                a = self.parent[&a];
                left.push(a);
            } else {
                b = self.parent[&b];
                right.push(b);
            }
        }
        right.pop(); // the common ancestor is already in `left`
        left.extend(right.into_iter().rev());
        left
    }

    /// The fundamental cycle maximising `length − 2 × distance to home`, among those of 8
    /// pixels or more enclosing at least 2 m² (smaller ones are pixel noise); `pt` places a
    /// pixel.
    pub fn best_cycle(&self, pt: &dyn Fn(usize) -> Vec2, home: Vec2) -> Option<Vec<usize>> {
        let mut best: Option<(f64, Vec<usize>)> = None;
        for &u in &self.order {
            for v in self.neighbours(u) {
                if v <= u || self.parent[&v] == u || self.parent[&u] == v {
                    continue;
                }
                let cycle = self.cycle_through(u, v);
                if cycle.len() < 8 {
                    continue;
                }
                let pts: Vec<Vec2> = cycle.iter().map(|&k| pt(k)).collect();
                let Some(score) = score(&pts, home) else {
                    continue;
                };
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((score, cycle));
                }
            }
        }
        best.map(|(_, cycle)| cycle)
    }

    /// The path from the root to the pixel reached last (the farthest from the root).
    pub fn longest_branch(&self) -> Vec<usize> {
        let far = *self.order.last().unwrap();
        let mut path = vec![far];
        let mut k = far;
        while k != self.root {
            k = self.parent[&k];
            path.push(k);
        }
        path.reverse();
        path
    }
}

/// A closed polygon's `length − 2 × distance to home`; `None` when it encloses less than 2 m².
fn score(pts: &[Vec2], home: Vec2) -> Option<f64> {
    let n = pts.len();
    let mut area2 = 0.0;
    let mut len = 0.0;
    for t in 0..n {
        let (p, r) = (pts[t], pts[(t + 1) % n]);
        area2 += p.x * r.y - r.x * p.y;
        len += (r - p).norm();
    }
    if area2.abs() / 2.0 < 2.0 {
        return None;
    }
    let dhome = pts
        .iter()
        .map(|p| (p - home).norm())
        .fold(f64::INFINITY, f64::min);
    Some(len - 2.0 * dhome)
}
