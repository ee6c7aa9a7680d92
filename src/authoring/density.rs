//! The density map (paper Fig. 2a): the world's free space coloured by the density class the
//! recognizer would give a robot standing in each cell.
//!
//! The world is drawn into cells of the recognizer's grid size (walls and door panels in their
//! given state occupied, the free space the route and home reach free, everything else unknown),
//! and Ψ of a sample of cells is computed by the recognizer's own kernel
//! ([`crate::recognizer::DensityKernel::free_cells_at`]) and quantized by its own rule ([`WordLevels::class_of`]).
//! The robot's local grid holds what its laser saw within a few metres, which for a robot in
//! open view of its surroundings is this map's free space; so the classes here are those the
//! recognizer sees, up to the small differences of a grid turned with the odometry frame.

use crate::geom::Vec2;
use crate::recognizer::density::{CellState, Visited, cell_value};
use crate::recognizer::{RecognizerConfig, WordLevels};
use crate::world::geometry::ThickSegment;
use crate::world::raster::Raster;
use crate::world::{DoorStates, World};
use rayon::prelude::*;

/// Default distance between two sampled cells of the map, metres.
pub const DEFAULT_SAMPLE_M: f64 = 0.1;

/// Density classes of the world's free space on a grid of samples.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityMap {
    /// Bottom-left corner of sample cell (0, 0), metres.
    pub origin: Vec2,
    /// Side of a sample cell, metres.
    pub sample_m: f64,
    pub width: usize,
    pub height: usize,
    /// Ψ of each sample cell in reachable free space (`None` elsewhere), row-major from the
    /// bottom row.
    pub psi: Vec<Option<f64>>,
    /// Density class of each sample cell, as the recognizer quantizes Ψ.
    pub class: Vec<Option<u8>>,
    /// Number of classes.
    pub classes: usize,
}

impl DensityMap {
    /// Sample cells per class (index = class).
    pub fn class_counts(&self) -> Vec<usize> {
        let mut out = vec![0; self.classes];
        for c in self.class.iter().flatten() {
            out[*c as usize] += 1;
        }
        out
    }

    /// Class at a world position, if that cell is reachable free space.
    pub fn class_at(&self, p: Vec2) -> Option<u8> {
        let q = (p - self.origin) / self.sample_m;
        if q.x < 0.0 || q.y < 0.0 {
            return None;
        }
        let (x, y) = (q.x as usize, q.y as usize);
        if x >= self.width || y >= self.height {
            return None;
        }
        self.class[y * self.width + x]
    }
}

/// Thick segments of the walls and of the door panels in `doors`.
pub fn obstacles(world: &World, doors: &DoorStates) -> Vec<ThickSegment> {
    let walls = world.walls.iter().flat_map(|w| {
        w.segments().into_iter().map(|seg| ThickSegment {
            seg,
            half_thickness_m: w.thickness_m / 2.0,
        })
    });
    let panels = world.doors.iter().enumerate().map(|(i, d)| ThickSegment {
        seg: d.panel(doors.is_open(i)),
        half_thickness_m: d.thickness_m / 2.0,
    });
    walls.chain(panels).collect()
}

/// Cell values for the kernel: free where reachable from the routes and home, occupied where a
/// wall or door is, unknown elsewhere; padded by `pad` unknown cells on every side.
fn kernel_cells(world: &World, raster: &Raster, pad: usize) -> Vec<u8> {
    let mut seeds: Vec<Vec2> = world
        .routes
        .iter()
        .flat_map(|r| r.waypoints.clone())
        .collect();
    seeds.push(world.home.position());
    let free = raster.reachable(&seeds);
    let stride = raster.width + 2 * pad;
    let mut cells = vec![cell_value(CellState::Unknown); stride * (raster.height + 2 * pad)];
    for y in 0..raster.height {
        for x in 0..raster.width {
            let i = y * raster.width + x;
            let state = if raster.occupied[i] {
                CellState::Occupied
            } else if free[i] {
                CellState::Free
            } else {
                CellState::Unknown
            };
            cells[(y + pad) * stride + x + pad] = cell_value(state);
        }
    }
    cells
}

/// The density map of `world` with the doors in `doors`, sampled every `sample_m` metres
/// (rounded to whole recognizer cells), with the recognizer settings `cfg`.
pub fn density_map(
    world: &World,
    doors: &DoorStates,
    cfg: &RecognizerConfig,
    sample_m: f64,
) -> DensityMap {
    let cell_m = cfg.grid.grid_cell_m;
    let kernel = cfg.density_kernel();
    // Half a cell of dilation keeps thin diagonal walls closed for the kernel's rays.
    let raster = Raster::new(&obstacles(world, doors), &[], cell_m, 1.0, cell_m * 0.5);
    let pad = kernel.radius_cells() + 1;
    let cells = kernel_cells(world, &raster, pad);
    let stride = raster.width + 2 * pad;
    let deltas = kernel.deltas(stride);
    let step = ((sample_m / raster.cell_m).round() as usize).max(1);
    let (width, height) = (raster.width / step, raster.height / step);
    let quantizer = WordLevels::new(cfg.words.classes, 1, 1);
    let psi: Vec<Option<f64>> = (0..height)
        .into_par_iter()
        .flat_map_iter(|sy| {
            let mut visited = Visited::default();
            let row: Vec<Option<f64>> = (0..width)
                .map(|sx| {
                    let (x, y) = (sx * step + step / 2, sy * step + step / 2);
                    let base = (y + pad) * stride + x + pad;
                    (cells[base] == cell_value(CellState::Free)).then(|| {
                        let free =
                            kernel.free_cells_at(&deltas, &cells, base, usize::MAX, &mut visited);
                        kernel.psi_of_count(free.count)
                    })
                })
                .collect();
            row
        })
        .collect();
    let class = psi
        .iter()
        .map(|p| p.map(|p| quantizer.class_of(p)))
        .collect();
    DensityMap {
        origin: raster.origin,
        sample_m: raster.cell_m * step as f64,
        width,
        height,
        psi,
        class,
        classes: cfg.words.classes,
    }
}

/// Colours of the density classes, from the narrowest free space to the widest (viridis).
pub const CLASS_COLORS: [&str; 8] = [
    "#440154", "#46327e", "#365c8d", "#277f8e", "#1fa187", "#4ac16d", "#a0da39", "#fde725",
];

/// Colour of class `c` of `classes` (spread over the palette when there are fewer than 8).
fn class_color(c: usize, classes: usize) -> String {
    let k = if classes <= 1 {
        0
    } else {
        c * (CLASS_COLORS.len() - 1) / (classes - 1)
    };
    CLASS_COLORS[k.min(CLASS_COLORS.len() - 1)].to_string()
}

/// The world with its free space coloured by density class, a legend of the classes (Ψ range
/// and share of the free space) and the doors in `doors`.
pub fn density_svg(world: &World, doors: &DoorStates, map: &DensityMap, title: &str) -> String {
    use crate::report::world_render::{RenderOptions, TileLayer, render_world_svg};
    let n = map.classes;
    let swatches = class_swatches(map);
    let opts = RenderOptions {
        doors: doors.clone(),
        title: Some(title.to_string()),
        show_areas: false,
        show_door_labels: false,
        tiles: Some(TileLayer {
            origin: map.origin,
            cell_m: map.sample_m,
            width: map.width,
            height: map.height,
            cells: map.class.clone(),
            palette: (0..n).map(|c| class_color(c, n)).collect(),
        }),
        swatches,
        ..RenderOptions::default()
    };
    render_world_svg(world, &opts)
}

/// A legend entry per density class: its range of Ψ and its share of the cells.
fn class_swatches(map: &DensityMap) -> Vec<crate::report::world_render::Swatch> {
    let counts = map.class_counts();
    let total = counts.iter().sum::<usize>().max(1);
    let n = map.classes;
    (0..n)
        .map(|c| crate::report::world_render::Swatch {
            label: format!(
                "class {c}: \u{3a8} {:.3}-{:.3} ({:.0} %)",
                c as f64 / n as f64,
                (c + 1) as f64 / n as f64,
                100.0 * counts[c] as f64 / total as f64
            ),
            color: class_color(c, n),
        })
        .collect()
}

/// The density picture of `world` with the default recognizer settings (what `placewords world
/// density` writes).
pub fn density_picture(world: &World, doors: &DoorStates) -> String {
    let cfg = RecognizerConfig::default();
    let map = density_map(world, doors, &cfg, DEFAULT_SAMPLE_M);
    let title = format!(
        "{}: density classes of the free space (kernel {} m, {} classes)",
        world.name, cfg.density.kernel_radius_m, cfg.words.classes
    );
    density_svg(world, doors, &map, &title)
}
