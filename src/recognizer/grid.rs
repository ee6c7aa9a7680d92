//! The local occupancy grid around the robot, in the odometry frame.
//!
//! A square window of L × L cells (the memory) stored in a torus of 2ⁿ × 2ⁿ ≥ L × L cells:
//! global cell (x, y) lives at index (y·2ⁿ + x) mod 4ⁿ, which is one-to-one inside any
//! 2ⁿ × 2ⁿ window and lets the density kernel read it with constant index steps. When the robot
//! moves to another cell the window scrolls with it: the cells that leave it are cleared, so
//! everything farther than L/2 cells from the robot along either axis is forgotten. The torus is
//! larger than the window when a kernel may be centred far from the robot (observations
//! interpolated back along a long step): it then reads forgotten cells as unknown, never cells
//! of the window's far side.
//!
//! Each cell holds a small counter: 0 unknown, 1..=7 free, 8..=15 occupied. A beam passing a cell
//! lowers it by one (a first pass makes it 4, free); a beam ending in it raises it by three (a
//! first hit makes it 11, occupied). A wall cell grazed by a few beams stays a wall, a person who
//! walked away fades after a few scans.
//!
//! Beams are traced with an integer DDA (one cell per step along the beam's dominant axis, the
//! other coordinate in 16.16 fixed point), only up to the grid radius. Near the sensor, where
//! neighbouring beams cross the same cells, beams are thinned (see [`LocalGrid::integrate`]):
//! the cells there are still crossed by the sparser beams, and about a quarter of the cell
//! visits are saved. With a beam stride (`[recognizer.grid] beam_stride`, default 4; a grid
//! made here traces every beam until [`LocalGrid::set_beam_stride`]) a scan traces only every
//! n-th beam, the next scan the next ones, each traced beam lowering the counters it passes n
//! times; returns are marked for every beam. An approximation: Ψ stays within the bound
//! `tests/it/frontend_bound.rs` checks against the exact update (stride 1).

use super::density::{CellState, DensityKernel, FreeCells, RayDeltas, Visited, cell_state};
use crate::geom::{OdomPose, Pose2};
use crate::scan::Scan;

/// 256 entries, so that a cell's byte indexes it unmasked (cells hold 0..=15; a larger byte
/// reads its low four bits' entry).
const fn free_next() -> [u8; 256] {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        let v = i & 15;
        t[i] = if v == 0 {
            4
        } else if v > 1 {
            v as u8 - 1
        } else {
            1
        };
        i += 1;
    }
    t
}

const fn hit_next() -> [u8; 256] {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        let v = i & 15;
        t[i] = if v == 0 {
            11
        } else if v + 3 > 15 {
            15
        } else {
            v as u8 + 3
        };
        i += 1;
    }
    t
}

/// Counter after a beam passes the cell.
const FREE_NEXT: [u8; 256] = free_next();

/// Largest beam stride (`LocalGrid::set_beam_stride`).
pub const MAX_BEAM_STRIDE: usize = 8;

/// Per stride n ≤ [`MAX_BEAM_STRIDE`], the counter after n beams pass the cell (`FREE_NEXT`
/// applied n times; entry 0 is unused).
const FREE_NEXT_TIMES: [[u8; 256]; MAX_BEAM_STRIDE + 1] = {
    let mut t = [[0u8; 256]; MAX_BEAM_STRIDE + 1];
    let mut n = 1;
    while n <= MAX_BEAM_STRIDE {
        let mut i = 0;
        while i < 256 {
            let mut v = i as u8;
            let mut k = 0;
            while k < n {
                v = FREE_NEXT[v as usize];
                k += 1;
            }
            t[n][i] = v;
            i += 1;
        }
        n += 1;
    }
    t
};
/// Counter after a beam ends in the cell.
const HIT_NEXT: [u8; 256] = hit_next();

/// floor(v) as i32 without a libm call (v well inside the i32 range).
#[inline(always)]
fn floor_i32(v: f64) -> i32 {
    let t = v as i32;
    if (t as f64) > v { t - 1 } else { t }
}

/// 1.5 · 2⁵²: a double of magnitude below 2⁵¹ added to it is rounded to an integer, which the
/// low 32 bits of the sum hold in two's complement (no saturating cast).
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Quotients a beam's cells may have for `floor_div` (checked once per scan).
const SMALL_QUOTIENT: f64 = (1u32 << 29) as f64;

/// floor(v / cell_m) exactly as `floor_i32(v / cell_m)`, for |v / cell_m| < 2²⁹, with a product
/// instead of the division: v · inv_cell (inv_cell = 1 / cell_m rounded) is within
/// |v / cell_m| · 2⁻⁵² < 2⁻²³ of the exact quotient, and the rounded division within 2⁻²⁴ of
/// it, so when the product is more than 10⁻⁶ from an integer both have the same floor. Nearer
/// an integer (about 2 quotients in a million) it divides.
#[inline(always)]
fn floor_div(v: f64, cell_m: f64, inv_cell: f64) -> i32 {
    let q = v * inv_cell;
    let r = q + ROUNDER;
    let nearest = r - ROUNDER;
    if (q - nearest).abs() > 1e-6 {
        (r.to_bits() as i32) - i32::from(nearest > q)
    } else {
        floor_i32(v / cell_m)
    }
}

/// Longest step from the last scan integrated after which a scan may skip beams, metres: the
/// scans of an observation step (0.10 m) may, those of a sparse log (0.7 m apart) may not.
pub const STRIDE_MAX_STEP_M: f64 = 0.15;
/// Largest turn since the last scan integrated after which a scan may skip beams, radians
/// (2°): turning, the view changes and every beam is traced.
pub const STRIDE_MAX_TURN_RAD: f64 = 0.035;

/// The rolling local grid.
#[derive(Clone, Debug)]
pub struct LocalGrid {
    cell_m: f64,
    radius_m: f64,
    /// log2 of the torus's side.
    shift: u32,
    /// Side L of the window of remembered cells (at most the torus's side).
    window: i32,
    /// side² − 1.
    mask: usize,
    cells: Vec<u8>,
    /// Global cell coordinates of the window's lowest corner.
    origin: (i32, i32),
    half: i32,
    has_origin: bool,
    visited: Visited,
    /// `65536 / n` for trace lengths n of up to a window's side (a division per beam saved).
    inv_steps: Vec<f64>,
    /// Beams traced per scan: every `beam_stride`-th (1: all), see [`LocalGrid::set_beam_stride`].
    beam_stride: usize,
    /// Scans integrated so far: which beams of the stride the next scan traces.
    phase: usize,
    /// The sensor pose of the last scan integrated (`None` after `clear`).
    last_sensor: Option<Pose2>,
    /// What a beam passing a cell does to its counter in the scan being integrated: one pass,
    /// or as many as the scan's stride (each traced beam stands for that many).
    free_next: &'static [u8; 256],
}

impl LocalGrid {
    /// A grid of `cell_m` cells keeping everything within `radius_m` of the robot.
    pub fn new(cell_m: f64, radius_m: f64) -> Self {
        Self::with_margin(cell_m, radius_m, 0.0)
    }

    /// A grid whose window reaches `margin_m` beyond `radius_m` on every side, so that a kernel
    /// of radius up to `radius_m` centred up to `margin_m` from the robot reads only cells of its
    /// own neighbourhood: the window is a torus, and a kernel crossing its edge would read cells
    /// from the far side (ahead of the robot) instead. Scans are still traced only up to
    /// `radius_m`; the margin only remembers a little longer what the robot left behind.
    pub fn with_margin(cell_m: f64, radius_m: f64, margin_m: f64) -> Self {
        let half = ((radius_m + margin_m.max(0.0)) / cell_m).ceil() as i32 + 2;
        let side = ((2 * half + 1) as u32).next_power_of_two() as usize;
        Self::with_window(cell_m, radius_m, side, side)
    }

    /// A grid that remembers the cells within `memory_m` of the robot along either axis (at
    /// least `radius_m`), in a torus large enough that a kernel of `reach_m` (its radius plus
    /// how far from the robot it may be centred) reads no cell of the window's far side.
    pub fn with_memory(cell_m: f64, radius_m: f64, memory_m: f64, reach_m: f64) -> Self {
        let half = ((memory_m.max(radius_m) / cell_m).round() as usize).max(1);
        let reach = (reach_m.max(0.0) / cell_m).ceil() as usize;
        // A kernel cell u cells from the window's centre must satisfy half + u < side (and
        // −half − u ≥ window − side) so that no alias of it lies inside the window.
        let side = (2 * half).max(half + reach + 2).next_power_of_two();
        Self::with_window(cell_m, radius_m, 2 * half, side)
    }

    fn with_window(cell_m: f64, radius_m: f64, window: usize, side: usize) -> Self {
        LocalGrid {
            cell_m,
            radius_m,
            window: window as i32,
            shift: side.trailing_zeros(),
            mask: side * side - 1,
            cells: vec![0; side * side],
            origin: (0, 0),
            half: window as i32 / 2,
            has_origin: false,
            visited: Visited::default(),
            inv_steps: (0..=side).map(|n| 65536.0 / n as f64).collect(),
            beam_stride: 1,
            phase: 0,
            last_sensor: None,
            free_next: &FREE_NEXT_TIMES[1],
        }
    }

    /// Traces only every `stride`-th beam of each scan (1, the default: every beam), the next
    /// scan the next beams of the stride, so that `stride` consecutive scans trace each beam
    /// once; every return within the radius still marks its cell occupied. Free space is
    /// then seen once per `stride` integrations (a cell's counter lowers more slowly), walls
    /// as before.
    pub fn set_beam_stride(&mut self, stride: usize) {
        self.beam_stride = stride.clamp(1, MAX_BEAM_STRIDE);
    }

    /// Side of the window, cells.
    pub fn side(&self) -> usize {
        1 << self.shift
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        self.cells.fill(0);
        self.has_origin = false;
        self.last_sensor = None;
    }

    /// Global cell of a point of the odometry frame.
    #[inline]
    pub fn cell_of(&self, x: f64, y: f64) -> (i32, i32) {
        (floor_i32(x / self.cell_m), floor_i32(y / self.cell_m))
    }

    #[inline(always)]
    fn index(&self, x: i32, y: i32) -> usize {
        (((y as i64) << self.shift) + x as i64) as usize & self.mask
    }

    fn inside(&self, x: i32, y: i32) -> bool {
        let side = self.window;
        self.has_origin
            && x >= self.origin.0
            && y >= self.origin.1
            && x < self.origin.0 + side
            && y < self.origin.1 + side
    }

    /// State of global cell (x, y) (unknown outside the window).
    pub fn state(&self, x: i32, y: i32) -> CellState {
        if !self.inside(x, y) {
            return CellState::Unknown;
        }
        cell_state(self.cells[self.index(x, y)])
    }

    /// Scrolls the window so that it is centred on global cell (cx, cy), clearing what leaves it.
    pub fn recenter(&mut self, cx: i32, cy: i32) {
        let side = self.window;
        let new_origin = (cx - self.half, cy - self.half);
        if !self.has_origin {
            self.origin = new_origin;
            self.has_origin = true;
            return;
        }
        let (ox, oy) = self.origin;
        let (nx, ny) = new_origin;
        if (nx, ny) == (ox, oy) {
            return;
        }
        if (nx - ox).abs() >= side || (ny - oy).abs() >= side {
            self.cells.fill(0);
            self.origin = new_origin;
            return;
        }
        let leaving_cols = if nx > ox {
            ox..nx
        } else {
            nx + side..ox + side
        };
        for x in leaving_cols {
            for y in oy..oy + side {
                let i = self.index(x, y);
                self.cells[i] = 0;
            }
        }
        let leaving_rows = if ny > oy {
            oy..ny
        } else {
            ny + side..oy + side
        };
        for y in leaving_rows {
            self.clear_run(ox, y, side as usize);
        }
        self.origin = new_origin;
    }

    /// Clears the `len` cells of row `y` from global column `x` on: consecutive indices of the
    /// torus (global cell (x, y) is at (y·2ⁿ + x) mod 4ⁿ), which may wrap to the array's start.
    /// Row by row rather than column by column, the cells cleared lie next to each other.
    fn clear_run(&mut self, x: i32, y: i32, len: usize) {
        let first = self.index(x, y);
        let head = len.min(self.cells.len() - first);
        self.cells[first..first + head].fill(0);
        self.cells[..len - head].fill(0);
    }

    /// Integrates one scan taken at `odom` (the robot pose; the sensor sits at the layout's
    /// mount). A return within the grid radius marks its cell occupied and the cells before it
    /// free; a no-return beam, or a return beyond the radius, marks free space up to the radius.
    /// Beam i is traced from the distance where beams 2^(t+1) steps apart (t = trailing zeros of
    /// i) are half a cell apart: every 16th beam from the sensor, the odd ones from 0.72 m for
    /// 1° beams and 5 cm cells.
    pub fn integrate(&mut self, odom: &OdomPose, scan: &Scan) {
        let robot = odom.0;
        let (rcx, rcy) = self.cell_of(robot.x, robot.y);
        self.recenter(rcx, rcy);
        let mount = &scan.layout.mount;
        let sensor: Pose2 = robot.compose(mount);
        // Keep every traced cell within the radius of the robot, hence inside the window.
        let reach = (self.radius_m - mount.x.hypot(mount.y)).max(0.0);
        let (sx, sy) = self.cell_of(sensor.x, sensor.y);
        if !self.inside(sx, sy) {
            return;
        }
        let n = scan.layout.count.min(scan.ranges_m.len());
        let ranges = &scan.ranges_m[..n];
        let max_range_m = scan.layout.max_range_m;
        let step = scan.layout.step_rad.abs();
        // Beam directions by rotation, not a sin_cos per beam (drift over 1000 beams ~1e-13).
        let (mut s, mut c) = (sensor.theta + scan.layout.start_angle_rad).sin_cos();
        let (ds, dc) = scan.layout.step_rad.sin_cos();
        // Where beam i starts, by i mod 16 (beams with t trailing zeros, t < 4, start where
        // beams 2^(t+1) steps apart are half a cell apart; the others, i mod 16 = 0, at the
        // sensor): once per scan rather than a division per beam.
        let starts: [f64; 16] = std::array::from_fn(|j| {
            let t = j.trailing_zeros();
            if j == 0 || step <= 0.0 {
                0.0
            } else {
                0.5 * self.cell_m / (step * (1u32 << (t + 1)) as f64)
            }
        });
        let (cell_m, inv_cell) = (self.cell_m, 1.0 / self.cell_m);
        // Every traced point lies within `reach` of the sensor: when their quotients are small
        // (always, short of 2.6e7 m from the origin at 5 cm cells), cells come from a product.
        let far = (sensor.x.abs().max(sensor.y.abs()) + reach) / cell_m + 2.0;
        let small = far < SMALL_QUOTIENT;
        let stride = self.stride_from(&sensor);
        let phase = self.phase % stride;
        // A traced beam stands for the `stride` beams around it: the counters it passes fall
        // as fast per scan as with every beam (a passer-by's returns fade as quickly).
        self.free_next = &FREE_NEXT_TIMES[stride];
        self.phase = self.phase.wrapping_add(1);
        let cell = |x: f64, y: f64| {
            if small {
                (
                    floor_div(x, cell_m, inv_cell),
                    floor_div(y, cell_m, inv_cell),
                )
            } else {
                (floor_i32(x / cell_m), floor_i32(y / cell_m))
            }
        };
        // i mod stride, counted rather than divided (a division per beam cost more than the
        // beam's skip saved).
        let mut beam_in_stride = 0;
        for (i, &r) in ranges.iter().enumerate() {
            let (bs, bc) = (s, c);
            (s, c) = (s * dc + c * ds, c * dc - s * ds);
            let in_phase = beam_in_stride == phase;
            beam_in_stride = if beam_in_stride + 1 == stride {
                0
            } else {
                beam_in_stride + 1
            };
            if r.is_nan() || r <= 0.0 {
                continue;
            }
            // A return (`Scan::is_hit`: finite, below the maximum range) within the radius.
            let hit = r <= reach && r < max_range_m;
            let len = r.min(reach);
            // Near the sensor neighbouring beams pass through the same cells: beam i starts
            // where beams 2^(t+1) steps apart (t: trailing zeros of i) get more than half a
            // cell apart, so the cells there are still crossed by the sparser beams.
            let start = starts[i & 15];
            let end = || cell(sensor.x + bc * len, sensor.y + bs * len);
            // Beams traced from the sensor (every 16th) are traced on every scan: they lower the
            // counters of the cells around the robot, which a passer-by's returns raised.
            if start >= len || (!in_phase && i & 15 != 0) {
                if hit {
                    let (ex, ey) = end();
                    self.mark(ex, ey, true);
                }
                continue;
            }
            let (ex, ey) = end();
            let (bx, by) = if start > 0.0 {
                cell(sensor.x + bc * start, sensor.y + bs * start)
            } else {
                (sx, sy)
            };
            self.trace(bx, by, ex, ey, hit);
        }
    }

    /// The stride of the scan taken at `sensor`: `beam_stride` when the last scan integrated
    /// was taken near it (so that the beams skipped now were traced from about here), else 1.
    fn stride_from(&mut self, sensor: &Pose2) -> usize {
        let near = self.last_sensor.is_some_and(|last| {
            last.distance(sensor) <= STRIDE_MAX_STEP_M
                && crate::geom::wrap_angle(sensor.theta - last.theta).abs() <= STRIDE_MAX_TURN_RAD
        });
        self.last_sensor = Some(*sensor);
        if near { self.beam_stride } else { 1 }
    }

    /// Updates one cell: a beam ended in it (`hit`) or passed it.
    #[inline]
    fn mark(&mut self, x: i32, y: i32, hit: bool) {
        let i = self.index(x, y);
        let v = self.cells[i] as usize;
        self.cells[i] = if hit { HIT_NEXT[v] } else { self.free_next[v] };
    }

    /// Marks the cells from (x0, y0) to (x1, y1) free, the last one occupied when `hit`: n steps
    /// (n the longer axis's cell count) of a 16.16 fixed-point DDA from the cell's centre.
    #[inline]
    fn trace(&mut self, x0: i32, y0: i32, x1: i32, y1: i32, hit: bool) {
        let (dx, dy) = ((x1 - x0) as i64, (y1 - y0) as i64);
        let n = dx.abs().max(dy.abs());
        if n > 0 {
            let inv = match self.inv_steps.get(n as usize) {
                Some(&inv) => inv,
                None => 65536.0 / n as f64,
            };
            let start = self.index(x0, y0);
            if n < 0x8000 {
                // The longer axis's increment, n · inv truncated, is 65536 or 65535 (inv is
                // 65536 / n rounded, so n · inv ≥ 65536 − 2⁻³⁷): either way its coordinate
                // moves exactly one cell per step for fewer than 2¹⁵ steps, and only the other
                // axis's carry varies.
                let (major, minor, d_minor) = if dx.abs() >= dy.abs() {
                    (dx.signum(), 1i64 << self.shift, dy)
                } else {
                    (dy.signum() << self.shift, 1, dx)
                };
                let minor_inc = (d_minor as f64 * inv) as i64;
                if minor == 1 {
                    let inc = (major << 16).wrapping_add(minor_inc) as u64;
                    trace_steps_fixed(&mut self.cells, self.free_next, self.mask, start, n, inc);
                } else {
                    let step = major.wrapping_add((minor_inc >> 16).wrapping_mul(minor)) as usize;
                    let fraction = (minor_inc & 0xFFFF) as u32;
                    trace_steps(
                        (&mut self.cells, self.free_next),
                        self.mask,
                        start,
                        n,
                        step,
                        minor.trailing_zeros(),
                        fraction,
                    );
                }
            } else {
                let (ix, iy) = ((dx as f64 * inv) as i64, (dy as f64 * inv) as i64);
                self.trace_dda(x0, y0, n, ix, iy);
            }
        }
        self.mark(x1, y1, hit);
    }

    /// The plain DDA: `n` cells from (x0, y0), both coordinates in 16.16 fixed point.
    fn trace_dda(&mut self, x0: i32, y0: i32, n: i64, ix: i64, iy: i64) {
        let mut xf = ((x0 as i64) << 16) + 0x8000;
        let mut yf = ((y0 as i64) << 16) + 0x8000;
        let (shift, mask, free_next) = (self.shift, self.mask, self.free_next);
        // Exactly side² cells: indices masked by side² − 1 need no bounds check.
        let cells = &mut self.cells[..=mask];
        for _ in 0..n {
            let i = (((yf >> 16) << shift) + (xf >> 16)) as usize & mask;
            cells[i] = free_next[cells[i] as usize];
            xf += ix;
            yf += iy;
        }
    }

    /// Free cells the kernel reaches from global cell (cx, cy), with the first moment of the
    /// space its rays reach;
    /// `deltas` must be `kernel.deltas(self.side())`.
    pub fn free_cells(
        &mut self,
        kernel: &DensityKernel,
        deltas: &RayDeltas,
        cx: i32,
        cy: i32,
    ) -> FreeCells {
        debug_assert_eq!(deltas.stride(), self.side());
        let base = self.index(cx, cy);
        kernel.free_cells_at(deltas, &self.cells, base, self.mask, &mut self.visited)
    }

    /// Whether a kernel of `radius_cells` centred on the odometry position (x, y) reads no cell
    /// twice and none from the far side of the torus: each of its cells lies in the window or
    /// where no alias of it does.
    pub fn kernel_fits(&self, radius_cells: usize, x: f64, y: f64) -> bool {
        let (cx, cy) = self.cell_of(x, y);
        let r = radius_cells as i32;
        let side = self.side() as i32;
        let fits = |c: i32, o: i32| c - r - o >= self.window - side && c + r - o < side;
        self.has_origin && fits(cx, self.origin.0) && fits(cy, self.origin.1)
    }

    /// Ψ at the cell holding the odometry position (x, y).
    pub fn psi_at(&mut self, kernel: &DensityKernel, deltas: &RayDeltas, x: f64, y: f64) -> f64 {
        self.density_at(kernel, deltas, x, y).psi
    }

    /// Ψ at the cell holding the odometry position (x, y) and where its free cells lie.
    pub fn density_at(
        &mut self,
        kernel: &DensityKernel,
        deltas: &RayDeltas,
        x: f64,
        y: f64,
    ) -> Density {
        let (cx, cy) = self.cell_of(x, y);
        let free = self.free_cells(kernel, deltas, cx, cy);
        // In kernel radii per node of the tree.
        let scale = 1.0 / (kernel.node_count().max(1) as f64 * kernel.radius_cells().max(1) as f64);
        Density {
            psi: kernel.psi_of_count(free.count),
            moment: (
                free.reach_moment.0 as f64 * scale,
                free.reach_moment.1 as f64 * scale,
            ),
        }
    }
}

/// `n` free passes along a DDA from torus index `start`: each step moves `step` (the longer
/// axis's cell, plus the shorter axis's whole cells per step), and the shorter axis's cell
/// (`1 << minor_shift` in the index) once more each time its 16-bit fraction, from the cell's
/// centre and growing by `fraction`, carries over. The same cells as the 16.16 DDA with one
/// index per cell instead of two coordinates. Step k's index is computed from k alone (the
/// carries so far are the high half of 0x8000 + k·fraction, which fits 32 bits for k < 2¹⁵), not
/// from step k − 1's index: the steps do not wait on each other's carry. `free_next` is what
/// a pass does to a counter.
#[inline(always)]
fn trace_steps(
    (cells, free_next): (&mut [u8], &[u8; 256]),
    mask: usize,
    start: usize,
    n: i64,
    step: usize,
    minor_shift: u32,
    fraction: u32,
) {
    // Exactly side² cells: indices masked by side² − 1 need no bounds check.
    let cells = &mut cells[..=mask];
    let (mut whole, mut frac) = (start, 0x8000u32);
    for _ in 0..n {
        let i = whole.wrapping_add(((frac >> 16) as usize) << minor_shift) & mask;
        cells[i] = free_next[cells[i] as usize];
        whole = whole.wrapping_add(step);
        frac += fraction;
    }
}

/// `n` free passes along a DDA from torus index `start` whose shorter axis is x (one index per
/// cell): the index in fixed point, 16 bits of fraction from the cell's centre, grows by `inc`
/// (the longer axis's index step · 2¹⁶ plus the shorter axis's 16.16 increment), and its whole
/// part is the cell. The same cells as `trace_steps` with one add per step (wrapping: the
/// whole part is taken modulo the torus).
#[inline(always)]
fn trace_steps_fixed(
    cells: &mut [u8],
    free_next: &[u8; 256],
    mask: usize,
    start: usize,
    n: i64,
    inc: u64,
) {
    // Exactly side² cells: indices masked by side² − 1 need no bounds check.
    let cells = &mut cells[..=mask];
    let mut at = ((start as u64) << 16) | 0x8000;
    for _ in 0..n {
        let i = (at >> 16) as usize & mask;
        cells[i] = free_next[cells[i] as usize];
        at = at.wrapping_add(inc);
    }
}

/// Ψ at a cell and the first moment of the space the kernel's rays reach from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Density {
    /// Free-space density Ψ in [0, 1].
    pub psi: f64,
    /// Sum of the offsets from the cell (odometry frame axes) of the prefix-tree nodes the
    /// kernel's rays reach (see `FreeCells`), in kernel radii, divided by the tree's node count.
    pub moment: (f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognizer::density::CELL_OCCUPIED_FROM;

    /// `integrate` as it was written before its per-beam shortcuts (cells by division, the hit
    /// test of `Scan::is_hit`, the start by trailing zeros): the reference for exactness.
    fn integrate_plain(grid: &mut LocalGrid, odom: &OdomPose, scan: &Scan) {
        let robot = odom.0;
        let (rcx, rcy) = grid.cell_of(robot.x, robot.y);
        grid.recenter(rcx, rcy);
        let mount = &scan.layout.mount;
        let sensor: Pose2 = robot.compose(mount);
        let reach = (grid.radius_m - mount.x.hypot(mount.y)).max(0.0);
        let (sx, sy) = grid.cell_of(sensor.x, sensor.y);
        if !grid.inside(sx, sy) {
            return;
        }
        let step = scan.layout.step_rad.abs();
        let (mut s, mut c) = (sensor.theta + scan.layout.start_angle_rad).sin_cos();
        let (ds, dc) = scan.layout.step_rad.sin_cos();
        for i in 0..scan.layout.count.min(scan.ranges_m.len()) {
            let r = scan.ranges_m[i];
            let (bs, bc) = (s, c);
            (s, c) = (s * dc + c * ds, c * dc - s * ds);
            if r.is_nan() || r <= 0.0 {
                continue;
            }
            let (len, hit) = if scan.is_hit(i) && r <= reach {
                (r, true)
            } else {
                (r.min(reach), false)
            };
            let t = if i == 0 { 31 } else { i.trailing_zeros() };
            let start = if t >= 4 || step <= 0.0 {
                0.0
            } else {
                0.5 * grid.cell_m / (step * (1u32 << (t + 1)) as f64)
            };
            let (ex, ey) = grid.cell_of(sensor.x + bc * len, sensor.y + bs * len);
            if start >= len {
                if hit {
                    grid.mark(ex, ey, true);
                }
                continue;
            }
            let (bx, by) = if start > 0.0 {
                grid.cell_of(sensor.x + bc * start, sensor.y + bs * start)
            } else {
                (sx, sy)
            };
            grid.trace(bx, by, ex, ey, hit);
        }
    }

    /// `integrate` leaves every cell as the plain per-beam code does: random poses (far from
    /// the origin too, where the product floor is not used), ranges with misses, no-returns,
    /// NaN and non-positive readings.
    #[test]
    fn integrate_equals_the_plain_per_beam_code() {
        use crate::scan::BeamLayout;
        let mut seed = 3u64;
        let mut unit = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let layout =
            BeamLayout::centered(181, std::f64::consts::PI, 8.0, Pose2::new(0.021, 0.0, 0.0));
        let mut fast = LocalGrid::with_memory(0.05, 3.0, 6.4, 7.5);
        let mut plain = fast.clone();
        let (mut x, mut y) = (0.0, 0.0);
        for k in 0..3000 {
            if k % 1000 == 0 {
                // Jump: near the origin, far away, beyond the product floor's range.
                (x, y) = [(0.3, -0.7), (1.0e5, -2.5e4), (3.0e7, 1.0)][k / 1000];
            }
            x += unit() * 0.2 - 0.05;
            y += unit() * 0.2 - 0.1;
            let odom = OdomPose(Pose2::new(x, y, unit() * 7.0 - 3.5));
            let ranges_m = (0..181)
                .map(|_| match (unit() * 20.0) as u32 {
                    0 => f64::NAN,
                    1 => 0.0,
                    2 => 8.0,
                    3 => f64::INFINITY,
                    _ => unit() * 5.0,
                })
                .collect();
            let scan = Scan {
                layout: layout.clone(),
                ranges_m,
                time_s: 0.0,
            };
            fast.integrate(&odom, &scan);
            integrate_plain(&mut plain, &odom, &scan);
            assert_eq!(fast.cells, plain.cells, "scan {k}");
        }
        assert!(fast.cells.iter().any(|&v| v >= CELL_OCCUPIED_FROM));
    }

    /// The product floor is the division's floor, also for quotients within an ulp of an
    /// integer (where the product alone may round to the other side), at several cell sizes.
    #[test]
    fn floor_div_equals_the_division() {
        let mut seed = 11u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed >> 11
        };
        for cell_m in [0.05, 0.1, 0.03, 0.07, 0.2, 1.0 / 3.0] {
            let inv = 1.0 / cell_m;
            for _ in 0..200_000 {
                let k = (next() % 2_000_000) as f64 - 1_000_000.0;
                // On a cell border, a few ulps either side, or anywhere in the cell.
                let v = match next() % 4 {
                    0 => k * cell_m,
                    1 => f64::from_bits((k * cell_m).to_bits() + next() % 5),
                    2 => f64::from_bits((k * cell_m).to_bits().saturating_sub(next() % 5)),
                    _ => (k + (next() % 1000) as f64 / 1000.0) * cell_m,
                };
                assert_eq!(
                    floor_div(v, cell_m, inv),
                    floor_i32(v / cell_m),
                    "{v} / {cell_m}"
                );
            }
        }
    }

    /// The one-index trace updates exactly the cells of the plain 16.16 DDA, in the same order
    /// (a counter passed twice by one beam moves twice), across the torus's edges too.
    #[test]
    fn trace_steps_equal_the_plain_dda() {
        let mut seed = 7u64;
        let mut next = |m: i32| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % m as u64) as i32
        };
        let mut fast = LocalGrid::with_memory(0.05, 3.0, 6.4, 7.5);
        let mut plain = fast.clone();
        for _ in 0..20_000 {
            let (x0, y0) = (next(1200) - 600, next(1200) - 600);
            let (x1, y1) = (x0 + next(161) - 80, y0 + next(161) - 80);
            let hit = next(2) == 0;
            fast.trace(x0, y0, x1, y1, hit);
            let (dx, dy) = ((x1 - x0) as i64, (y1 - y0) as i64);
            let n = dx.abs().max(dy.abs());
            if n > 0 {
                let inv = 65536.0 / n as f64;
                plain.trace_dda(
                    x0,
                    y0,
                    n,
                    (dx as f64 * inv) as i64,
                    (dy as f64 * inv) as i64,
                );
            }
            plain.mark(x1, y1, hit);
        }
        assert!(fast.cells.iter().any(|&v| v >= CELL_OCCUPIED_FROM));
        assert_eq!(fast.cells, plain.cells);
    }
}
