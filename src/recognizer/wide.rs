//! The wide window: how much of a wide disc around the robot the laser has seen free, for open
//! space, where the density Ψ saturates (issue 28, "words in open space").
//!
//! Ψ reads the free space within the kernel radius (2.5 m): in a hall or outdoors every cell there
//! is free, Ψ sits in the top class for tens of metres, and one word covers the whole crossing (a
//! 44 × 34 m hall: a 42 m word, where a corridor's words are 2–4 m). The structure that tells one
//! part of a hall from another (its walls, 5–20 m away) lies beyond the kernel and the local grid.
//! This window keeps, on a coarse grid (`CELL_M`), which cells within `wide_radius_m` the laser
//! has seen free in the last `2 × wide_radius_m` of travel, and reads the fraction of the disc
//! they fill: the wide density Φ ∈ [0, 1]. Where Ψ is in its top class, the word builder splits
//! that class by Φ (`WordOptions::wide_classes`), so a hall is read as the walls recede and
//! approach. A corridor never reaches the top class, and a room of a few metres fills little of
//! a 20 m disc, so neither changes.
//!
//! A scan is taken in once per `INTEGRATE_M` of travel (the disc is hundreds of square metres,
//! which a metre of travel barely changes), and once per `INTEGRATE_OPEN_M` where Φ is read: in
//! open space the word boundaries follow Φ, and a metre's steps of it moved them by up to a
//! metre between visits (the hall world's precision, seeds 1–3: 0.945 at 1 m, 0.952 at 0.25 m,
//! 0.951 without the window). Φ is measured at an observation's own position, and only where
//! the word builder reads it (Ψ in its top class), so corridors pay for the marking alone. The grid is a torus whose slots remember which cell they hold and when it was seen,
//! so moving the window clears nothing.

use crate::geom::Pose2;
use crate::scan::Scan;

/// Side of a cell of the wide window, metres: coarse, since Φ averages over the whole disc.
pub const CELL_M: f64 = 0.5;

/// Travel between two scans taken into the window, metres: a wall 5–20 m away moves little
/// against the disc in a metre.
pub const INTEGRATE_M: f64 = 1.0;

/// Travel between two scans taken into the window in open space (where Φ is read), metres.
pub const INTEGRATE_OPEN_M: f64 = 0.25;

/// Every how many beams a scan's beams are traced: 2° apart, their marks leave no gap within
/// 14 m, and beyond, the next scans' marks (a metre on) fill most of what they skip.
pub const BEAM_STRIDE: usize = 2;

/// Cells are counted from this far below zero, so truncation is the floor (odometric
/// coordinates stay well within ±2²⁰ cells, ±524 km).
const ORIGIN_CELLS: f64 = (1u32 << 20) as f64;

/// One slot of the torus: the cell it holds (its two unsigned cell coordinates) and the travel
/// at which it was last seen free.
#[derive(Clone, Copy, Debug)]
struct Slot {
    cell: u64,
    seen_at_m: f64,
}

const EMPTY: Slot = Slot {
    cell: u64::MAX,
    seen_at_m: f64::NEG_INFINITY,
};

/// Free space seen within a wide radius of the robot (the `recognizer::wide` module docs).
#[derive(Clone, Debug)]
pub struct WideWindow {
    radius_m: f64,
    /// Cells seen longer ago than this (in travel) are forgotten, metres.
    memory_m: f64,
    /// Side of the torus, cells (a power of two).
    side: usize,
    slots: Vec<Slot>,
    next_integrate_m: f64,
    /// Travel of the newest scan taken in, metres.
    travel_m: f64,
}

impl WideWindow {
    /// A window of `radius_m` (positive).
    pub fn new(radius_m: f64) -> Self {
        let r = (radius_m / CELL_M).ceil() as usize;
        let side = (2 * r + 4).next_power_of_two();
        WideWindow {
            radius_m,
            memory_m: 2.0 * radius_m,
            side,
            slots: vec![EMPTY; side * side],
            next_integrate_m: f64::NEG_INFINITY,
            travel_m: 0.0,
        }
    }

    /// Forgets everything (a new run).
    pub fn clear(&mut self) {
        self.slots.fill(EMPTY);
        self.next_integrate_m = f64::NEG_INFINITY;
    }

    /// Takes in the scan made at `robot` (odometric pose) after `travel_m` of travel, when one is
    /// due (a run's first, then every `INTEGRATE_M` of travel, or `INTEGRATE_OPEN_M` when
    /// `open`: the robot is where Φ is read): the cells its beams cross are marked seen free,
    /// up to half a cell before a hit or to the radius.
    pub fn integrate(&mut self, robot: Pose2, scan: &Scan, travel_m: f64, open: bool) {
        self.travel_m = travel_m;
        let due_m = if open {
            self.next_integrate_m - (INTEGRATE_M - INTEGRATE_OPEN_M)
        } else {
            self.next_integrate_m
        };
        if travel_m < due_m {
            return;
        }
        self.next_integrate_m = travel_m + INTEGRATE_M;
        let sensor = robot.compose(&scan.layout.mount);
        let (x0, y0) = (
            sensor.x / CELL_M + ORIGIN_CELLS,
            sensor.y / CELL_M + ORIGIN_CELLS,
        );
        let n = scan.layout.count.min(scan.ranges_m.len());
        for i in (0..n).step_by(BEAM_STRIDE) {
            let r = scan.ranges_m[i];
            if r.is_nan() || r <= 0.0 {
                continue;
            }
            let len = if scan.is_hit(i) {
                (r - 0.5 * CELL_M).min(self.radius_m)
            } else {
                self.radius_m
            };
            let (s, c) = (sensor.theta + scan.layout.beam_angle_rad(i)).sin_cos();
            let steps = (len / CELL_M).floor().max(0.0) as usize;
            // One cell's length per step, in cells.
            let (mut x, mut y) = (x0, y0);
            for _ in 0..=steps {
                self.mark(x as u32, y as u32, travel_m);
                x += c;
                y += s;
            }
        }
    }

    fn slot_of(&self, ix: u32, iy: u32) -> usize {
        let m = self.side - 1;
        (iy as usize & m) * self.side + (ix as usize & m)
    }

    fn mark(&mut self, ix: u32, iy: u32, travel_m: f64) {
        let k = self.slot_of(ix, iy);
        self.slots[k] = Slot {
            cell: u64::from(iy) << 32 | u64::from(ix),
            seen_at_m: travel_m,
        };
    }

    /// Φ at (x, y) (odometric frame): of the cells whose centres lie within the radius, the
    /// share seen free within the memory.
    pub fn density_at(&self, x: f64, y: f64) -> f64 {
        let oldest_m = self.travel_m - self.memory_m;
        let r = self.radius_m;
        // In cells, from the origin: cell i's centre is at i + ½.
        let (cx, cy, rc) = (
            x / CELL_M + ORIGIN_CELLS,
            y / CELL_M + ORIGIN_CELLS,
            r / CELL_M,
        );
        let (mut inside, mut seen) = (0usize, 0usize);
        for iy in (cy - rc - 0.5).ceil() as u32..=(cy + rc - 0.5).floor() as u32 {
            let dy = iy as f64 + 0.5 - cy;
            let half = (rc * rc - dy * dy).max(0.0).sqrt();
            // The cells of this row whose centres are within the radius.
            for ix in (cx - half - 0.5).ceil() as u32..=(cx + half - 0.5).floor() as u32 {
                inside += 1;
                let s = self.slots[self.slot_of(ix, iy)];
                let cell = u64::from(iy) << 32 | u64::from(ix);
                seen += usize::from(s.cell == cell && s.seen_at_m >= oldest_m);
            }
        }
        seen as f64 / inside.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scan::BeamLayout;
    use std::f64::consts::PI;

    /// A 181-beam, 180° scan from `robot` inside the box [0, w] × [0, h], beams beyond
    /// `max_range_m` reported at it.
    fn scan_in_box(robot: Pose2, w: f64, h: f64, max_range_m: f64) -> Scan {
        let layout = BeamLayout::centered(181, PI, max_range_m, Pose2::IDENTITY);
        let ranges_m = (0..181)
            .map(|i| {
                let (s, c) = (robot.theta + layout.beam_angle_rad(i)).sin_cos();
                let to = |p: f64, d: f64, hi: f64| match d {
                    d if d > 1e-12 => (hi - p) / d,
                    d if d < -1e-12 => -p / d,
                    _ => f64::INFINITY,
                };
                to(robot.x, c, w).min(to(robot.y, s, h)).min(max_range_m)
            })
            .collect();
        Scan {
            layout,
            ranges_m,
            time_s: 0.0,
        }
    }

    /// Drives along y = h/2 of a w × h box from x = 1 to `to_x` and returns Φ there.
    fn phi_after_driving(w: f64, h: f64, to_x: f64) -> f64 {
        let mut win = WideWindow::new(20.0);
        let mut x = 1.0;
        while x <= to_x {
            let robot = Pose2::new(x, h / 2.0, 0.0);
            win.integrate(robot, &scan_in_box(robot, w, h, 32.0), x - 1.0, true);
            x += 0.25;
        }
        win.density_at(to_x, h / 2.0)
    }

    /// In the middle of a 44 × 34 m hall most of a 20 m disc is seen free; in a 2 m corridor,
    /// and in a 6 × 6 m room, little is (so neither leaves Ψ's top class whole or not).
    #[test]
    fn a_hall_is_open_and_a_corridor_or_a_room_is_not() {
        let hall = phi_after_driving(44.0, 34.0, 22.0);
        assert!(hall > 0.7, "Φ in the middle of the hall: {hall}");
        let entry = phi_after_driving(44.0, 34.0, 2.0);
        assert!(
            entry < hall - 0.2,
            "Φ at the hall's entry {entry}, middle {hall}"
        );
        let corridor = phi_after_driving(80.0, 2.0, 40.0);
        assert!(corridor < 0.1, "Φ in a corridor: {corridor}");
        let room = phi_after_driving(6.0, 6.0, 3.0);
        assert!(room < 0.15, "Φ in a room: {room}");
    }

    /// What was seen more than the memory (twice the radius) of travel ago is forgotten, and a
    /// new run starts with nothing seen.
    #[test]
    fn old_and_cleared_marks_are_forgotten() {
        let mut win = WideWindow::new(20.0);
        let robot = Pose2::new(22.0, 17.0, 0.0);
        win.integrate(robot, &scan_in_box(robot, 44.0, 34.0, 32.0), 0.0, false);
        let seen = win.density_at(22.0, 17.0);
        assert!(seen > 0.3, "Φ after one scan: {seen}");
        let mut blind = scan_in_box(robot, 44.0, 34.0, 32.0);
        blind.ranges_m.fill(f64::NAN);
        win.integrate(robot, &blind, 39.0, false);
        assert_eq!(win.density_at(22.0, 17.0), seen, "within the memory");
        win.integrate(robot, &blind, 41.0, false);
        assert_eq!(win.density_at(22.0, 17.0), 0.0, "past the memory");
        win.integrate(robot, &scan_in_box(robot, 44.0, 34.0, 32.0), 42.0, false);
        win.clear();
        win.integrate(robot, &blind, 0.0, false);
        assert_eq!(win.density_at(22.0, 17.0), 0.0, "after clear");
    }
}
