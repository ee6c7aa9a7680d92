//! Free-space density Ψ of a cell (paper Eq. 1, as the authors' code computes it).
//!
//! From the cell, a ray is cast every `ray_step`; each ray starts at the cell's integer
//! coordinates and advances one cell per step along its dominant axis (the other coordinate moves
//! by tan of the angle and is floored), for floor(max(|cos|, |sin|)·W) + 1 steps, W being the
//! kernel radius in cells. A free cell counts once (the first time any ray reaches it), an
//! unknown cell is skipped but does not stop the ray, an occupied cell stops it. The count is
//! divided by the same count on an all-free window, so Ψ ∈ [0, 1].
//!
//! The ray cell offsets are computed once per kernel and merged into a prefix tree. A query
//! copies the kernel's square of cells out of the grid it reads (a few row copies), walks the
//! tree over that copy, marking each reached cell with a bit no cell value has, and counts the
//! marked free cells in one pass: counting "once" costs a store per step, not a test. The walk
//! reads a few nodes at a time and marks them all when none is occupied.

/// What a grid knows about a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellState {
    Unknown,
    Free,
    Occupied,
}

/// Cell values shared by every grid the kernel reads: 0 unknown, 1..=7 free, 8..=15 occupied
/// (the local grid keeps a small evidence counter in that range).
pub const CELL_UNKNOWN: u8 = 0;
/// Smallest value of an occupied cell.
pub const CELL_OCCUPIED_FROM: u8 = 8;

/// The state a cell value encodes.
#[inline(always)]
pub fn cell_state(v: u8) -> CellState {
    if v == CELL_UNKNOWN {
        CellState::Unknown
    } else if v >= CELL_OCCUPIED_FROM {
        CellState::Occupied
    } else {
        CellState::Free
    }
}

/// A value encoding `state`.
pub fn cell_value(state: CellState) -> u8 {
    match state {
        CellState::Unknown => CELL_UNKNOWN,
        CellState::Free => 1,
        CellState::Occupied => 15,
    }
}

/// Marks a cell of the square that the rays reached: a bit no cell value (0..=15) has, so a
/// reached cell keeps its occupied bit clear and its free or unknown value.
const REACHED: u8 = 0x40;

/// Sizes (powers of two) of the scratch array a query walks in: the smallest that holds the
/// kernel's square is used, and the walk masks each index with the size − 1, a constant the
/// compiler sees, so the step needs no bounds check. 2¹⁶ holds a 127-cell kernel (the default is
/// 50), 2²² a 1023-cell one; a larger kernel is walked with bounds checks.
const SQUARE_SIZES: [usize; 4] = [1 << 16, 1 << 18, 1 << 20, 1 << 22];

/// Scratch of one query: the kernel's square of cells copied out of the grid it reads (side²
/// cells at the start of the array), where the walk marks the cells the rays reach. Only the
/// square is touched (10,201 bytes for a 50-cell kernel), so the walk stays in the L1 cache
/// whatever the grid's size.
#[derive(Clone, Debug, Default)]
pub struct Visited {
    cells: Vec<u8>,
}

impl Visited {
    /// Copies the `side` × `side` square centred on index `base` of a row-major array of
    /// `stride` cells per row (indices `& mask`, see [`DensityKernel::free_cells_at`]).
    fn copy_square(&mut self, cells: &[u8], base: usize, stride: usize, mask: usize, side: usize) {
        let len = side * side;
        let size = SQUARE_SIZES.into_iter().find(|&n| n >= len).unwrap_or(len);
        if self.cells.len() != size {
            self.cells = vec![0; size];
        }
        let half = (side / 2) as isize;
        for (row, out) in self.cells[..len].chunks_exact_mut(side).enumerate() {
            let dy = row as isize - half;
            let start = (base as isize)
                .wrapping_add(dy.wrapping_mul(stride as isize))
                .wrapping_sub(half) as usize
                & mask;
            match cells.get(start..start + side) {
                Some(src) => out.copy_from_slice(src),
                // A torus row crossing the array's end continues at its start.
                None => {
                    let first = cells.len() - start;
                    out[..first].copy_from_slice(&cells[start..]);
                    out[first..].copy_from_slice(&cells[..side - first]);
                }
            }
        }
    }

    /// Walks the prefix tree over the copied square, marking the cells reached; returns the
    /// summed moments of the subtrees occupied cells cut off.
    fn walk(&mut self, deltas: &RayDeltas) -> (i32, i32) {
        fn sized<const N: usize, I: NodeIndex>(
            cells: &mut [u8],
            at: &[I],
            deltas: &RayDeltas,
        ) -> (i32, i32) {
            let square: &mut [u8; N] = cells.try_into().expect("a scratch of N cells");
            walk_tree(square, N - 1, at, deltas)
        }
        let cells = &mut self.cells[..];
        match (&deltas.at, cells.len()) {
            (NodeIndices::Narrow(at), n) if n == SQUARE_SIZES[0] => {
                sized::<{ SQUARE_SIZES[0] }, u16>(cells, at, deltas)
            }
            (NodeIndices::Wide(at), n) if n == SQUARE_SIZES[1] => {
                sized::<{ SQUARE_SIZES[1] }, u32>(cells, at, deltas)
            }
            (NodeIndices::Wide(at), n) if n == SQUARE_SIZES[2] => {
                sized::<{ SQUARE_SIZES[2] }, u32>(cells, at, deltas)
            }
            (NodeIndices::Wide(at), n) if n == SQUARE_SIZES[3] => {
                sized::<{ SQUARE_SIZES[3] }, u32>(cells, at, deltas)
            }
            (NodeIndices::Narrow(at), _) => walk_tree(cells, usize::MAX, at, deltas),
            (NodeIndices::Wide(at), _) => walk_tree(cells, usize::MAX, at, deltas),
        }
    }

    /// The weights (one per cell of the square) of the free cells the walk reached, summed.
    fn weigh_reached(&self, weights: &[u8]) -> u32 {
        let reached = |v: u8, w: u8| {
            if v.wrapping_sub(REACHED + 1) < CELL_OCCUPIED_FROM - 1 {
                u16::from(w)
            } else {
                0
            }
        };
        // Sums of 64 weights fit 16 bits; they vectorise.
        let cells = &self.cells[..weights.len()];
        let chunks = cells.chunks_exact(64).zip(weights.chunks_exact(64));
        let tail = weights.len() - weights.len() % 64;
        let tail: u32 = cells[tail..]
            .iter()
            .zip(&weights[tail..])
            .map(|(&v, &w)| u32::from(reached(v, w)))
            .sum();
        chunks
            .map(|(c, w)| u32::from(c.iter().zip(w).map(|(&v, &w)| reached(v, w)).sum::<u16>()))
            .sum::<u32>()
            + tail
    }

    /// Free cells among the `len` first that the walk reached.
    fn count_reached(&self, len: usize) -> u32 {
        // Reached free cells hold REACHED | 1..=7 (reached unknown ones REACHED alone).
        let reached = |v: &u8| u8::from(v.wrapping_sub(REACHED + 1) < CELL_OCCUPIED_FROM - 1);
        // Byte sums over 64 cells at a time: they vectorise 16 cells to an instruction.
        let chunks = self.cells[..len].chunks_exact(64);
        let tail: u32 = chunks
            .remainder()
            .iter()
            .map(|v| u32::from(reached(v)))
            .sum();
        chunks
            .map(|c| u32::from(c.iter().map(reached).sum::<u8>()))
            .sum::<u32>()
            + tail
    }
}

/// Nodes looked at together: their cells are read, and when none is occupied (the common case:
/// a ray stops once) they are all marked reached with no branch per node. 4 rather than 8: a
/// chunk holding an occupied node is walked again node by node, and rays in a corridor stop
/// often (loop floor, least of 7 laps: 14.1 against 14.8 ms a lap, exact kernel 23.8 against
/// 24.6; 16 took 20.8, 2 or 3 the same as 4).
const CHUNK: usize = 4;

/// The prefix-tree walk over `square` (indices `& mask`, which must keep every node's index):
/// marks each reached cell with [`REACHED`] and returns the summed moments of the subtrees that
/// occupied cells cut off. Exactly the walk node by node: a node is reached when no ancestor is
/// occupied, and a run of nodes none of which is occupied is reached in depth-first order.
#[inline(always)]
fn walk_tree<I: NodeIndex>(
    square: &mut [u8],
    mask: usize,
    at: &[I],
    deltas: &RayDeltas,
) -> (i32, i32) {
    let skip = &deltas.skip[..];
    let mut blocked = (0i32, 0i32);
    let mut k = 0;
    while let Some(chunk) = at.get(k..k + CHUNK) {
        let chunk: &[I; CHUNK] = chunk.try_into().expect("CHUNK nodes");
        // All reads before any mark: a mark keeps the occupied bit, so the tests hold.
        let v: [u8; CHUNK] = std::array::from_fn(|j| square[chunk[j].index() & mask]);
        let run = if v.iter().fold(0, |a, &b| a | b) & CELL_OCCUPIED_FROM == 0 {
            CHUNK
        } else {
            v.iter()
                .position(|&b| b & CELL_OCCUPIED_FROM != 0)
                .unwrap_or(CHUNK)
        };
        if run == CHUNK {
            // A constant count: unrolled, no branch per node.
            for j in 0..CHUNK {
                square[chunk[j].index() & mask] = v[j] | REACHED;
            }
        } else {
            for j in 0..run {
                square[chunk[j].index() & mask] = v[j] | REACHED;
            }
        }
        k += run;
        if run < CHUNK {
            // Every node of the occupied node's subtree is unreached: its moment goes at once.
            let m = deltas.moments[k];
            blocked = (blocked.0 + m.0, blocked.1 + m.1);
            k = skip[k] as usize;
        }
    }
    while let Some(&node) = at.get(k) {
        let i = node.index() & mask;
        let v = square[i];
        if v & CELL_OCCUPIED_FROM != 0 {
            let m = deltas.moments[k];
            blocked = (blocked.0 + m.0, blocked.1 + m.1);
            k = skip[k] as usize;
        } else {
            square[i] = v | REACHED;
            k += 1;
        }
    }
    blocked
}

/// The prefix-tree nodes' indices in the kernel's square, in depth-first order: 16 bits when
/// the square fits the smallest scratch (2¹⁶ cells; the default's 101 × 101 does), half the
/// bytes the walk reads a node; else 32.
#[derive(Clone, Debug)]
enum NodeIndices {
    Narrow(Vec<u16>),
    Wide(Vec<u32>),
}

impl Default for NodeIndices {
    fn default() -> Self {
        NodeIndices::Wide(Vec::new())
    }
}

/// A prefix-tree node's index in the kernel's square, as stored ([`NodeIndices`]).
trait NodeIndex: Copy {
    fn index(self) -> usize;
}

impl NodeIndex for u16 {
    #[inline(always)]
    fn index(self) -> usize {
        usize::from(self)
    }
}

impl NodeIndex for u32 {
    #[inline(always)]
    fn index(self) -> usize {
        self as usize
    }
}

/// Precomputed rays of a density kernel.
#[derive(Clone, Debug)]
pub struct DensityKernel {
    radius_cells: usize,
    /// Cell offsets of every ray, one ray after the other.
    offsets: Vec<(i16, i16)>,
    /// Ray `r` is `offsets[ray_starts[r]..ray_starts[r + 1]]`.
    ray_starts: Vec<usize>,
    /// The rays merged into a prefix tree, in depth-first order: node offsets, and for each node
    /// the index just past its subtree (where a walk goes when the node's cell is occupied, since
    /// every ray through the node stops there).
    tree_offsets: Vec<(i16, i16)>,
    tree_skip: Vec<u32>,
    /// Per node, the sum of the offsets of its subtree (itself included).
    tree_moments: Vec<(i32, i32)>,
    /// Free cells an all-free window yields (the normaliser); weighted when `weights` is not
    /// empty.
    full_count: u32,
    /// For a kernel that walks only some of its rays: per cell offset its rays reach, the weight of
    /// the cell in the count (see [`DensityKernel::with_ray_stride`]); empty: every cell 1.
    weights: Vec<((i16, i16), u8)>,
}

/// A kernel's rays ready for a row-major cell array of some row stride: the prefix tree's nodes
/// as indices into the kernel's square (which a query copies out of the array).
#[derive(Clone, Debug, Default)]
pub struct RayDeltas {
    stride: usize,
    /// Side of the kernel's square, cells (odd: the centre cell in the middle).
    side: usize,
    /// Per prefix-tree node, in depth-first order: its index in the square.
    at: NodeIndices,
    /// Per node, the index just past its subtree (read only where an occupied cell stops it).
    skip: Vec<u32>,
    /// Per node, the sum of the offsets of its subtree (read only when moments are wanted).
    moments: Vec<(i32, i32)>,
    /// Sum of the offsets of every node.
    reach_all: (i32, i32),
    /// Per cell of the square, its weight in the count (empty: every cell 1).
    weights: Vec<u8>,
}

/// What the kernel counts from a cell: the free cells (the numerator of Ψ) and where the space
/// its rays reach lies: the sum of the offsets from the centre, in cells, of every node of the
/// rays' prefix tree the walk reaches (unknown cells included: they do not stop a ray), its
/// first moment. Summed over tree nodes rather than distinct cells, it costs nothing per cell:
/// the walk subtracts a precomputed subtree sum each time an occupied cell stops it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FreeCells {
    pub count: u32,
    pub reach_moment: (i32, i32),
}

impl DensityKernel {
    /// A kernel of `radius_cells` with a ray every `ray_step_deg` degrees, starting at 0°.
    pub fn new(radius_cells: usize, ray_step_deg: f64) -> Self {
        Self::with_ray_stride(radius_cells, ray_step_deg, 1)
    }

    /// A kernel of `radius_cells` with a ray every `ray_step_deg` degrees, starting at 0°, of
    /// which only every `ray_stride`-th is walked (1: every ray, [`Self::new`]'s kernel).
    ///
    /// The sparser rays reach fewer of the cells, more so far from the centre, so a plain count
    /// would weigh the inner part more (Ψ rose by about 0.05 with every 2nd ray). Each cell is
    /// counted instead with the weight of its bin (see `ring_weights`): the cells all the rays
    /// reach in the bin over those the walked rays reach, so that an all-free bin counts as it
    /// did. Ψ is the weighted count over the weighted count of an all-free window.
    pub fn with_ray_stride(radius_cells: usize, ray_step_deg: f64, ray_stride: usize) -> Self {
        let ray_stride = ray_stride.max(1);
        let step = ray_step_deg.clamp(1e-3, 360.0);
        let n_rays = ((360.0 / step) - 1e-9).ceil().max(1.0) as usize;
        let w = radius_cells as f64;
        let mut offsets = Vec::new();
        let mut ray_starts = Vec::with_capacity(n_rays + 1);
        for i in (0..n_rays).step_by(ray_stride) {
            ray_starts.push(offsets.len());
            let a = (i as f64 * step).to_radians();
            let (s, c) = a.sin_cos();
            let dmax = c.abs().max(s.abs());
            let (dx, dy) = (c / dmax, s / dmax);
            let steps = (dmax * w + 1e-9).floor() as i64;
            for k in 0..=steps {
                let kf = k as f64;
                // The authors accumulate in f32 from an integer start: a drift of a few 1e-7
                // cells never crosses a cell border there, so absorb it here too.
                let ox = (kf * dx + 1e-6).floor() as i16;
                let oy = (kf * dy + 1e-6).floor() as i16;
                offsets.push((ox, oy));
            }
        }
        ray_starts.push(offsets.len());
        let weights = if ray_stride > 1 {
            ring_weights(&Self::new(radius_cells, ray_step_deg).offsets, &offsets)
        } else {
            Vec::new()
        };
        let (tree_offsets, tree_skip) = prefix_tree(&offsets, &ray_starts);
        let tree_moments = subtree_moments(&tree_offsets, &tree_skip);
        let mut kernel = DensityKernel {
            radius_cells,
            offsets,
            ray_starts,
            tree_offsets,
            tree_skip,
            tree_moments,
            full_count: 1,
            weights,
        };
        let mut free = DenseGrid::new(1, 1, CellState::Free);
        free.set_pad(radius_cells + 1, CellState::Free);
        let deltas = kernel.deltas(free.stride());
        let base = free.base(0, 0);
        kernel.full_count = kernel
            .free_cells_at(
                &deltas,
                &free.cells,
                base,
                usize::MAX,
                &mut Visited::default(),
            )
            .count
            .max(1);
        kernel
    }

    pub fn radius_cells(&self) -> usize {
        self.radius_cells
    }

    /// Number of rays.
    pub fn ray_count(&self) -> usize {
        self.ray_starts.len() - 1
    }

    /// Free cells counted on an all-free window.
    pub fn full_count(&self) -> u32 {
        self.full_count
    }

    /// Nodes of the rays' prefix tree (what an all-free window reaches, shared prefixes once).
    pub fn node_count(&self) -> usize {
        self.tree_offsets.len()
    }

    /// Cell offsets (x, y) of ray `r`, from the centre outward.
    pub fn ray(&self, r: usize) -> &[(i16, i16)] {
        &self.offsets[self.ray_starts[r]..self.ray_starts[r + 1]]
    }

    /// The rays for a row-major array whose rows are `stride` cells apart.
    pub fn deltas(&self, stride: usize) -> RayDeltas {
        let half = self
            .tree_offsets
            .iter()
            .map(|&(ox, oy)| ox.unsigned_abs().max(oy.unsigned_abs()) as usize)
            .max()
            .unwrap_or(0);
        let side = 2 * half + 1;
        let at = self.tree_offsets.iter().map(|&(ox, oy)| {
            let (x, y) = (ox as isize + half as isize, oy as isize + half as isize);
            y as usize * side + x as usize
        });
        // The smallest scratch holds the square: every index fits 16 bits.
        let at = if side * side <= SQUARE_SIZES[0] {
            NodeIndices::Narrow(at.map(|i| i as u16).collect())
        } else {
            NodeIndices::Wide(at.map(|i| i as u32).collect())
        };
        RayDeltas {
            stride,
            side,
            at,
            skip: self.tree_skip.clone(),
            moments: self.tree_moments.clone(),
            reach_all: self.reach_all(),
            weights: self.square_weights(half),
        }
    }

    /// The cell weights as a square of side 2·`half` + 1 (empty when every cell weighs 1).
    fn square_weights(&self, half: usize) -> Vec<u8> {
        if self.weights.is_empty() {
            return Vec::new();
        }
        let side = 2 * half + 1;
        let mut out = vec![0u8; side * side];
        for &((ox, oy), w) in &self.weights {
            let (x, y) = (ox as isize + half as isize, oy as isize + half as isize);
            out[y as usize * side + x as usize] = w;
        }
        out
    }

    /// Sum of the offsets of every node of the prefix tree.
    fn reach_all(&self) -> (i32, i32) {
        self.tree_offsets
            .iter()
            .fold((0, 0), |a, &(ox, oy)| (a.0 + ox as i32, a.1 + oy as i32))
    }

    /// Free cells reached from the cell at index `base` of a row-major array of cell values
    /// in 0..=15 (see `CELL_UNKNOWN`, `CELL_OCCUPIED_FROM`), and the first moment of the space the rays
    /// reach; indices are `(base + offset) & mask` (`usize::MAX` for a plain array, side² − 1
    /// for a power-of-two torus). The numerator of Ψ; every grid the recognizer, the authoring
    /// maps or the oracle test uses goes through here.
    pub fn free_cells_at(
        &self,
        deltas: &RayDeltas,
        cells: &[u8],
        base: usize,
        mask: usize,
        visited: &mut Visited,
    ) -> FreeCells {
        visited.copy_square(cells, base, deltas.stride, mask, deltas.side);
        // Walking the prefix tree visits each shared ray prefix once (about 22 % fewer steps
        // than ray by ray for a 50-cell kernel) and reaches the same cells; a cell reached
        // twice is marked twice and counted once.
        let blocked = visited.walk(deltas);
        let all = deltas.reach_all;
        let len = deltas.side * deltas.side;
        FreeCells {
            count: if deltas.weights.is_empty() {
                visited.count_reached(len)
            } else {
                visited.weigh_reached(&deltas.weights)
            },
            reach_moment: (all.0 - blocked.0, all.1 - blocked.1),
        }
    }

    /// Ψ from a free-cell count, in [0, 1].
    pub fn psi_of_count(&self, count: u32) -> f64 {
        (count as f64 / self.full_count as f64).min(1.0)
    }
}

impl RayDeltas {
    /// Row stride the deltas were made for.
    pub fn stride(&self) -> usize {
        self.stride
    }
}

/// Per distinct cell offset of `thinned` (a subset of `full`'s rays), the weight of its bin:
/// the distinct cells of `full` in the bin over those of `thinned`, as a byte scaled so that
/// the largest weight is at most 255 (the scale cancels in Ψ, a ratio of weighted counts). A
/// bin is a ring [`RING_CELLS`] wide and a sector of [`SECTOR_DEG`] of the angle from the
/// nearest axis: the sparser rays reach a smaller share of the cells near a diagonal than near
/// an axis (a ray crosses a column per step, and columns are farther apart across a diagonal
/// ray), and weights by ring alone raised Ψ along axis-aligned corridors (by 0.007 on average).
fn ring_weights(full: &[(i16, i16)], thinned: &[(i16, i16)]) -> Vec<((i16, i16), u8)> {
    use std::collections::{BTreeMap, BTreeSet};
    let bin = |&(x, y): &(i16, i16)| {
        let (x, y) = (f64::from(x).abs(), f64::from(y).abs());
        let ring = (x.hypot(y) / RING_CELLS).round() as i32;
        let from_axis = x.min(y).atan2(x.max(y)).to_degrees();
        (ring, (from_axis / SECTOR_DEG) as i32)
    };
    let full: BTreeSet<(i16, i16)> = full.iter().copied().collect();
    let thinned: BTreeSet<(i16, i16)> = thinned.iter().copied().collect();
    let mut counts: BTreeMap<(i32, i32), (usize, usize)> = BTreeMap::new();
    full.iter()
        .for_each(|c| counts.entry(bin(c)).or_default().0 += 1);
    thinned
        .iter()
        .for_each(|c| counts.entry(bin(c)).or_default().1 += 1);
    let ratio = |c: &(i16, i16)| {
        let (f, t) = counts[&bin(c)];
        f as f64 / t.max(1) as f64
    };
    let max = thinned.iter().map(ratio).fold(1.0, f64::max);
    let scale = 255.0 / max;
    thinned
        .iter()
        .map(|c| (*c, (ratio(c) * scale).round().clamp(1.0, 255.0) as u8))
        .collect()
}

/// Width of a ring of [`ring_weights`]' bins, cells.
const RING_CELLS: f64 = 2.0;
/// Width of a sector of [`ring_weights`]' bins, degrees from the nearest axis.
const SECTOR_DEG: f64 = 5.0;

/// Per node of a prefix tree in depth-first order (`skip[k]`: index just past k's subtree), the
/// sum of the offsets of its subtree, itself included.
fn subtree_moments(offsets: &[(i16, i16)], skip: &[u32]) -> Vec<(i32, i32)> {
    // Prefix sums over depth-first order: a subtree is the contiguous range k..skip[k].
    let mut prefix = vec![(0i32, 0i32); offsets.len() + 1];
    for (k, &(ox, oy)) in offsets.iter().enumerate() {
        prefix[k + 1] = (prefix[k].0 + ox as i32, prefix[k].1 + oy as i32);
    }
    (0..offsets.len())
        .map(|k| {
            let end = skip[k] as usize;
            (prefix[end].0 - prefix[k].0, prefix[end].1 - prefix[k].1)
        })
        .collect()
}

/// The rays (`offsets[starts[r]..starts[r + 1]]`) merged into a prefix tree: node offsets in
/// depth-first order and, per node, the index just past its subtree.
fn prefix_tree(offsets: &[(i16, i16)], starts: &[usize]) -> (Vec<(i16, i16)>, Vec<u32>) {
    use std::collections::HashMap;
    // Node 0 is a virtual root; children in order of first appearance.
    let mut children: Vec<Vec<u32>> = vec![Vec::new()];
    let mut cell: Vec<(i16, i16)> = vec![(0, 0)];
    let mut index: HashMap<(u32, (i16, i16)), u32> = HashMap::new();
    for r in 0..starts.len() - 1 {
        let mut node = 0u32;
        for &o in &offsets[starts[r]..starts[r + 1]] {
            node = *index.entry((node, o)).or_insert_with(|| {
                let id = cell.len() as u32;
                cell.push(o);
                children.push(Vec::new());
                children[node as usize].push(id);
                id
            });
        }
    }
    let mut out_offsets = Vec::with_capacity(cell.len() - 1);
    let mut out_skip = Vec::with_capacity(cell.len() - 1);
    // Iterative depth-first walk; a node's skip is filled when its subtree is done.
    let mut stack: Vec<u32> = children[0].iter().rev().copied().collect();
    let mut open: Vec<(usize, usize)> = Vec::new(); // (position in output, depth)
    let mut depth_of: Vec<usize> = vec![0; cell.len()];
    while let Some(node) = stack.pop() {
        let depth = depth_of[node as usize];
        while let Some(&(pos, d)) = open.last() {
            if d >= depth {
                out_skip[pos] = out_offsets.len() as u32;
                open.pop();
            } else {
                break;
            }
        }
        let pos = out_offsets.len();
        out_offsets.push(cell[node as usize]);
        out_skip.push(0);
        open.push((pos, depth));
        for &c in children[node as usize].iter().rev() {
            depth_of[c as usize] = depth + 1;
            stack.push(c);
        }
    }
    for (pos, _) in open {
        out_skip[pos] = out_offsets.len() as u32;
    }
    (out_offsets, out_skip)
}

/// A fixed rectangular grid of cell states, x to the right and y up, cell (0, 0) at the bottom
/// left. Cells outside it are unknown (queries copy it with a margin of unknown cells as wide as
/// the kernel, so rays never leave the array).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseGrid {
    pub width: usize,
    pub height: usize,
    pad: usize,
    /// Row-major from y = −pad upward, `width + 2·pad` per row.
    cells: Vec<u8>,
}

impl DenseGrid {
    pub fn new(width: usize, height: usize, fill: CellState) -> Self {
        DenseGrid {
            width,
            height,
            pad: 0,
            cells: vec![cell_value(fill); width * height],
        }
    }

    fn stride(&self) -> usize {
        self.width + 2 * self.pad
    }

    /// Grows the margin to `pad` cells (filled with `fill`).
    fn set_pad(&mut self, pad: usize, fill: CellState) {
        if pad == self.pad {
            return;
        }
        let stride = self.width + 2 * pad;
        let mut cells = vec![cell_value(fill); stride * (self.height + 2 * pad)];
        for y in 0..self.height {
            for x in 0..self.width {
                cells[(y + pad) * stride + x + pad] = self.cells[self.index(x, y)];
            }
        }
        self.cells = cells;
        self.pad = pad;
    }

    fn index(&self, x: usize, y: usize) -> usize {
        (y + self.pad) * self.stride() + x + self.pad
    }

    fn base(&self, x: usize, y: usize) -> usize {
        self.index(x, y)
    }

    pub fn get(&self, x: i32, y: i32) -> CellState {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 {
            return CellState::Unknown;
        }
        cell_state(self.cells[self.index(x as usize, y as usize)])
    }

    pub fn set(&mut self, x: usize, y: usize, state: CellState) {
        let i = self.index(x, y);
        self.cells[i] = cell_value(state);
    }

    /// Ψ of every free cell (`None` elsewhere), row-major from y = 0.
    pub fn density_map(&self, kernel: &DensityKernel) -> Vec<Option<f64>> {
        let mut padded = self.clone();
        padded.set_pad(kernel.radius_cells() + 1, CellState::Unknown);
        let deltas = kernel.deltas(padded.stride());
        let mut visited = Visited::default();
        let mut out = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            for x in 0..self.width {
                let base = padded.base(x, y);
                out.push(match cell_state(padded.cells[base]) {
                    CellState::Free => {
                        let free = kernel.free_cells_at(
                            &deltas,
                            &padded.cells,
                            base,
                            usize::MAX,
                            &mut visited,
                        );
                        Some(kernel.psi_of_count(free.count))
                    }
                    _ => None,
                });
            }
        }
        out
    }

    /// Ψ of cell (x, y).
    pub fn psi(&self, kernel: &DensityKernel, x: usize, y: usize) -> f64 {
        kernel.psi_of_count(self.free_cells(kernel, x, y).count)
    }

    /// The free cells the kernel counts from cell (x, y), with their first moment.
    pub fn free_cells(&self, kernel: &DensityKernel, x: usize, y: usize) -> FreeCells {
        let mut padded = self.clone();
        padded.set_pad(kernel.radius_cells() + 1, CellState::Unknown);
        let deltas = kernel.deltas(padded.stride());
        let base = padded.base(x, y);
        kernel.free_cells_at(
            &deltas,
            &padded.cells,
            base,
            usize::MAX,
            &mut Visited::default(),
        )
    }
}

/// Ψ of cell (x, y) of `grid` with a kernel of `radius_cells` and a ray every `ray_step_deg`
/// degrees (builds the kernel; reuse a [`DensityKernel`] and [`DenseGrid::density_map`] for
/// many queries).
pub fn density(
    grid: &DenseGrid,
    x: usize,
    y: usize,
    radius_cells: usize,
    ray_step_deg: f64,
) -> f64 {
    grid.psi(&DensityKernel::new(radius_cells, ray_step_deg), x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_free_gives_one_and_walls_lower_it() {
        let k = DensityKernel::new(10, 1.0);
        let mut g = DenseGrid::new(41, 41, CellState::Free);
        assert!((g.psi(&k, 20, 20) - 1.0).abs() < 1e-12);
        for x in 0..41 {
            g.set(x, 23, CellState::Occupied);
            g.set(x, 17, CellState::Occupied);
        }
        let psi = g.psi(&k, 20, 20);
        assert!(psi > 0.05 && psi < 0.5, "corridor psi {psi}");
    }

    /// The prefix-tree walk counts exactly what walking every ray does, and sums exactly the
    /// offsets of the cells it counts.
    #[test]
    fn prefix_tree_walk_equals_ray_by_ray() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as u32
        };
        for &(radius, step) in &[(10usize, 1.0f64), (50, 1.0), (30, 0.5), (7, 13.0)] {
            let k = DensityKernel::new(radius, step);
            let side = 2 * radius + 5;
            let mut g = DenseGrid::new(side, side, CellState::Free);
            for y in 0..side {
                for x in 0..side {
                    let r = next() % 100;
                    let st = if r < 8 {
                        CellState::Occupied
                    } else if r < 20 {
                        CellState::Unknown
                    } else {
                        CellState::Free
                    };
                    g.set(x, y, st);
                }
            }
            let c = (side / 2) as i32;
            let mut seen = std::collections::HashSet::new();
            for r in 0..k.ray_count() {
                for &(ox, oy) in k.ray(r) {
                    let (x, y) = (c + ox as i32, c + oy as i32);
                    match g.get(x, y) {
                        CellState::Occupied => break,
                        CellState::Free => {
                            seen.insert((x, y));
                        }
                        CellState::Unknown => {}
                    }
                }
            }
            let expected = seen.len() as f64 / k.full_count() as f64;
            assert_eq!(
                g.psi(&k, side / 2, side / 2),
                expected.min(1.0),
                "radius {radius}"
            );
            // Reached prefix-tree nodes: every distinct ray prefix up to (not including) the
            // first occupied cell.
            let mut reached = std::collections::HashSet::new();
            for r in 0..k.ray_count() {
                let ray = k.ray(r);
                for (j, &(ox, oy)) in ray.iter().enumerate() {
                    if g.get(c + ox as i32, c + oy as i32) == CellState::Occupied {
                        break;
                    }
                    reached.insert(ray[..=j].to_vec());
                }
            }
            let moment = reached.iter().fold((0, 0), |(mx, my), p| {
                let (ox, oy) = p[p.len() - 1];
                (mx + ox as i32, my + oy as i32)
            });
            let free = g.free_cells(&k, side / 2, side / 2);
            assert_eq!(
                (free.count as usize, free.reach_moment),
                (seen.len(), moment),
                "radius {radius}"
            );
        }
    }

    /// A kernel walking every 4th ray reads an all-free window as Ψ = 1 and a half-plane
    /// (free on one side of a wall through the centre) as about half, as every ray does.
    #[test]
    fn a_ray_stride_keeps_psi_of_free_and_half_free_windows() {
        let (full, sparse) = (
            DensityKernel::new(50, 1.0),
            DensityKernel::with_ray_stride(50, 1.0, 4),
        );
        assert!(sparse.node_count() * 3 < full.node_count());
        let free = DenseGrid::new(121, 121, CellState::Free);
        assert_eq!(free.psi(&sparse, 60, 60), 1.0);
        let mut half = free.clone();
        for y in 0..121 {
            half.set(60 + 1, y, CellState::Occupied);
        }
        let (a, b) = (half.psi(&full, 60, 60), half.psi(&sparse, 60, 60));
        assert!((a - b).abs() < 0.02, "{a} {b}");
        assert!((0.4..0.65).contains(&a), "{a}");
    }

    #[test]
    fn unknown_cells_do_not_count_nor_stop() {
        let k = DensityKernel::new(10, 1.0);
        let g = DenseGrid::new(41, 41, CellState::Unknown);
        assert_eq!(g.psi(&k, 20, 20), 0.0);
    }
}
