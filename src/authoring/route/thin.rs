//! Zhang–Suen thinning: a free-space component down to a one-cell skeleton that keeps its holes.

/// Zhang–Suen thinning of a binary image (row-major, `nx` wide).
///
/// Each sub-iteration decides every pixel from the image as it stood at the sub-iteration's
/// start, and a pixel's decision depends only on its 3×3 neighbourhood. So after the first
/// full pass only pixels next to one deleted since their last look under the same rule (north-
/// east or south-west) are looked at again: the same deletions, in work proportional to the
/// image plus the pixels removed, not to the image times the passes (a 350 m open map thinned
/// in thousands of full passes took a minute).
pub(super) fn zhang_suen(img: Vec<bool>, nx: usize, ny: usize) -> Vec<bool> {
    if nx < 3 || ny < 3 {
        return img;
    }
    let mut t = Thinning::new(img, nx, ny);
    loop {
        let mut changed = false;
        for step in 0..2 {
            changed |= t.sub_iteration(step);
        }
        if !changed {
            return t.img;
        }
    }
}

/// The 8 neighbours of interior pixel `k`, P2..P9 clockwise from north (north = +y row,
/// direction does not matter).
fn ring(k: usize, nx: usize) -> [usize; 8] {
    [
        k + nx,
        k + nx + 1,
        k + 1,
        k - nx + 1,
        k - nx,
        k - nx - 1,
        k - 1,
        k + nx - 1,
    ]
}

/// Whether a foreground pixel with neighbours `p` (P2..P9) goes in sub-iteration `step`.
fn deletable(p: [bool; 8], step: usize) -> bool {
    let b = p.iter().filter(|&&x| x).count();
    if !(2..=6).contains(&b) {
        return false;
    }
    let a = (0..8).filter(|&t| !p[t] && p[(t + 1) % 8]).count();
    if a != 1 {
        return false;
    }
    let (p2, p4, p6, p8) = (p[0], p[2], p[4], p[6]);
    if step == 0 {
        !(p4 && p6 && (p2 || p8))
    } else {
        !(p2 && p8 && (p4 || p6))
    }
}

/// The image being thinned and, per rule, the pixels to look at and whether they are queued.
struct Thinning {
    img: Vec<bool>,
    nx: usize,
    todo: [Vec<usize>; 2],
    queued: [Vec<bool>; 2],
    del: Vec<usize>,
}

impl Thinning {
    /// At first the foreground pixels on its border are queued: one whose 8 neighbours are all
    /// foreground is kept by both rules until a neighbour goes (and then it is queued). The
    /// image's edge is never looked at: marked queued for good, it is never queued.
    fn new(img: Vec<bool>, nx: usize, ny: usize) -> Thinning {
        let interior = |k: usize| {
            let (i, j) = (k % nx, k / nx);
            i >= 1 && i + 1 < nx && j >= 1 && j + 1 < ny
        };
        let mut todo: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let edge: Vec<bool> = (0..nx * ny).map(|k| !interior(k)).collect();
        let mut queued = [edge.clone(), edge];
        for k in 0..nx * ny {
            if img[k] && interior(k) && ring(k, nx).iter().any(|&q| !img[q]) {
                for step in 0..2 {
                    todo[step].push(k);
                    queued[step][k] = true;
                }
            }
        }
        Thinning {
            img,
            nx,
            todo,
            queued,
            del: Vec::new(),
        }
    }

    /// One sub-iteration under rule `step`: deletes what the rule deletes among the queued
    /// pixels and queues their foreground neighbours under both rules. Whether any went.
    fn sub_iteration(&mut self, step: usize) -> bool {
        self.del.clear();
        let mut look = std::mem::take(&mut self.todo[step]);
        for &k in &look {
            self.queued[step][k] = false;
            if self.img[k] && deletable(ring(k, self.nx).map(|q| self.img[q]), step) {
                self.del.push(k);
            }
        }
        look.clear();
        self.todo[step] = look;
        if self.del.is_empty() {
            return false;
        }
        for &k in &self.del {
            self.img[k] = false;
        }
        self.queue_neighbours_of_deleted();
        true
    }

    /// Queues for both rules every set pixel next to one just deleted, once.
    fn queue_neighbours_of_deleted(&mut self) {
        for &k in &self.del {
            for q in ring(k, self.nx) {
                if self.img[q] {
                    for rule in 0..2 {
                        if !self.queued[rule][q] {
                            self.queued[rule][q] = true;
                            self.todo[rule].push(q);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zhang–Suen as first written: every pixel every sub-iteration.
    fn zhang_suen_full_passes(mut img: Vec<bool>, nx: usize, ny: usize) -> Vec<bool> {
        let mut changed = true;
        while changed {
            changed = false;
            for step in 0..2 {
                let mut del = Vec::new();
                for j in 1..ny - 1 {
                    for i in 1..nx - 1 {
                        let k = j * nx + i;
                        if !img[k] {
                            continue;
                        }
                        let p = [
                            img[k + nx],
                            img[k + nx + 1],
                            img[k + 1],
                            img[k - nx + 1],
                            img[k - nx],
                            img[k - nx - 1],
                            img[k - 1],
                            img[k + nx - 1],
                        ];
                        let b = p.iter().filter(|&&x| x).count();
                        let a = (0..8).filter(|&t| !p[t] && p[(t + 1) % 8]).count();
                        let (p2, p4, p6, p8) = (p[0], p[2], p[4], p[6]);
                        let cond = if step == 0 {
                            !(p4 && p6 && (p2 || p8))
                        } else {
                            !(p2 && p8 && (p4 || p6))
                        };
                        if (2..=6).contains(&b) && a == 1 && cond {
                            del.push(k);
                        }
                    }
                }
                changed |= !del.is_empty();
                del.iter().for_each(|&k| img[k] = false);
            }
        }
        img
    }

    /// Looking again only where a neighbour went gives the skeleton of full passes, on blobs,
    /// noise and a large open square (the shape that took a minute).
    #[test]
    fn thinning_revisits_only_changed_neighbourhoods_with_the_same_skeleton() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for (nx, ny, fill) in [
            (40, 30, 0.9),
            (64, 64, 0.6),
            (17, 90, 0.97),
            (120, 120, 1.0),
        ] {
            let img: Vec<bool> = (0..nx * ny)
                .map(|k| {
                    let (i, j) = (k % nx, k / nx);
                    let edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
                    rng.random_bool(fill) && !edge
                })
                .collect();
            let want = zhang_suen_full_passes(img.clone(), nx, ny);
            assert_eq!(zhang_suen(img, nx, ny), want, "{nx}x{ny} at {fill}");
        }
    }
}
