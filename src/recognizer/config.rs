//! The recognizer's settings: the composition of its components' options (`options`), read
//! from a scenario's `[recognizer]` table and its subtables; the problems that cross two
//! components; the old flat keys' new places (the reader's migration messages).

use super::options::{
    AlignmentOptions, DensityOptions, FrontEndOptions, GridOptions, MAX_GRID_HALF_CELLS,
    MatcherOptions, VerifyOptions, WordOptions,
};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Settings of the whole recognizer: one options struct per component (front end, grid,
/// density, words, matcher, alignment, verification), read from a file as the subtables
/// `[recognizer.<component>]`, plus the number of level configurations, which the harness
/// sets. Missing keys take their default; [`RecognizerConfig::default`] is the paper's
/// recognizer as the harness runs it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct RecognizerConfig {
    /// Number of level configurations searched: 1 = level 0 only, 2 = levels 0-1, 3 = levels 0-2,
    /// 4 = levels 0-3. Words are built up to level `levels − 1`. Default 3. The harness sets it
    /// per level configuration (`--levels`); a scenario or `--config` file may not.
    pub levels: usize,
    /// `[recognizer.front_end]`: observation spacing and interpolation; a key left out keeps its default.
    pub front_end: FrontEndOptions,
    /// `[recognizer.grid]`: the local grid; a key left out keeps its default.
    pub grid: GridOptions,
    /// `[recognizer.density]`: the density kernel; a key left out keeps its default.
    pub density: DensityOptions,
    /// `[recognizer.words]`: density classes and words of every level; a key left out keeps its default.
    pub words: WordOptions,
    /// `[recognizer.matcher]`: word pairs and n-gram chains; a key left out keeps its default.
    pub matcher: MatcherOptions,
    /// `[recognizer.alignment]`: the fine alignment; a key left out keeps its default.
    pub alignment: AlignmentOptions,
    /// `[recognizer.verify]`: verification of each candidate n-gram; a key left out keeps its default.
    pub verify: VerifyOptions,
}

impl Default for RecognizerConfig {
    fn default() -> Self {
        RecognizerConfig {
            levels: 3,
            front_end: FrontEndOptions::default(),
            grid: GridOptions::default(),
            density: DensityOptions::default(),
            words: WordOptions::default(),
            matcher: MatcherOptions::default(),
            alignment: AlignmentOptions::default(),
            verify: VerifyOptions::default(),
        }
    }
}

/// The subtables of `[recognizer]`, one per component, in the order of [`RecognizerConfig`]'s
/// fields.
pub const SECTIONS: &[&str] = &[
    "front_end",
    "grid",
    "density",
    "words",
    "matcher",
    "alignment",
    "verify",
];

/// Keys of `[recognizer]` before the subtables whose name changed when they moved: (old key,
/// subtable, new key). Every other old key kept its name in its subtable.
pub const RENAMED_KEYS: &[(&str, &str, &str)] = &[
    ("alignment", "alignment", "mode"),
    ("verify", "verify", "enabled"),
];

/// One invalid setting: where it is (`section`, the subtable of `[recognizer]`, empty for a
/// key of `[recognizer]` itself, and the key) and what is wrong with it.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ConfigProblem {
    /// The subtable of `[recognizer]` (`grid`, `verify`, ...), or empty.
    pub section: &'static str,
    pub field: &'static str,
    /// `what is wrong; what to try`, lowercase.
    pub problem: String,
}

impl ConfigProblem {
    pub fn new(section: &'static str, field: &'static str, problem: String) -> Self {
        ConfigProblem {
            section,
            field,
            problem,
        }
    }

    /// The table the key is in: `[recognizer.grid]`, or `[recognizer]`.
    pub fn table(&self) -> String {
        table_name(self.section)
    }
}

/// `[recognizer.section]`, or `[recognizer]` for the empty section.
pub fn table_name(section: &str) -> String {
    if section.is_empty() {
        "[recognizer]".to_string()
    } else {
        format!("[recognizer.{section}]")
    }
}

impl fmt::Display for ConfigProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}: {}", self.table(), self.field, self.problem)
    }
}

impl RecognizerConfig {
    /// Every problem of the settings, component by component, then those that cross two
    /// components; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut out = Vec::new();
        if !(1..=4).contains(&self.levels) {
            out.push(ConfigProblem::new(
                "",
                "levels",
                format!(
                    "must be 1, 2, 3 or 4, got {}; the default is 3",
                    self.levels
                ),
            ));
        }
        out.extend(self.front_end.problems());
        out.extend(self.grid.problems());
        out.extend(self.density.problems());
        out.extend(self.words.problems());
        out.extend(self.matcher.problems(self.levels));
        out.extend(self.alignment.problems());
        out.extend(self.verify.problems());
        out.extend(self.cross_problems());
        out
    }

    /// The problems between components: the kernel must fit in the local grid, and the grid's
    /// torus must reach a kernel centred `max_interpolation_m` back along a step.
    fn cross_problems(&self) -> Vec<ConfigProblem> {
        [self.kernel_in_grid(), self.interpolation_in_grid()]
            .into_iter()
            .flatten()
            .collect()
    }

    /// A problem when the density kernel is wider than the local grid.
    fn kernel_in_grid(&self) -> Option<ConfigProblem> {
        let (grid, kernel_m) = (&self.grid, self.density.kernel_radius_m);
        let positive = |v: f64| v.is_finite() && v > 0.0;
        (positive(kernel_m) && positive(grid.grid_radius_m) && kernel_m > grid.grid_radius_m).then(|| {
            ConfigProblem::new(
                "density",
                "kernel_radius_m",
                format!(
                    "{kernel_m} m is larger than grid_radius_m ({} m); the kernel must fit in the local grid",
                    grid.grid_radius_m
                ),
            )
        })
    }

    /// A problem when interpolating plus the kernel reaches past [`MAX_GRID_HALF_CELLS`] cells.
    fn interpolation_in_grid(&self) -> Option<ConfigProblem> {
        let (grid, kernel_m) = (&self.grid, self.density.kernel_radius_m);
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let interpolation_m = self.front_end.max_interpolation_m;
        if (0.0..=20.0).contains(&interpolation_m)
            && positive(grid.grid_cell_m)
            && positive(kernel_m)
            && (interpolation_m + kernel_m) / grid.grid_cell_m > MAX_GRID_HALF_CELLS
        {
            return Some(ConfigProblem::new(
                "front_end",
                "max_interpolation_m",
                format!(
                    "{interpolation_m} m plus the kernel radius ({kernel_m} m) is more than {} \
                     cells of {} m; use a shorter limit or larger cells",
                    MAX_GRID_HALF_CELLS, grid.grid_cell_m
                ),
            ));
        }
        None
    }

    /// `Ok` when the settings are usable, else every problem.
    pub fn validate(&self) -> Result<(), RecognizerError> {
        let problems = self.problems();
        if problems.is_empty() {
            Ok(())
        } else {
            Err(RecognizerError::InvalidConfig(problems))
        }
    }

    /// These settings with `levels` level configurations (the thresholds unchanged).
    pub fn with_levels(mut self, levels: usize) -> Self {
        self.levels = levels;
        self
    }

    /// The open-space classes above the top density class that these settings use:
    /// `[recognizer.words] wide_classes` when the wide window is on (`[recognizer.density]
    /// wide_radius_m` > 0), else none.
    pub fn wide_classes_in_use(&self) -> usize {
        if self.density.wide_radius_m > 0.0 {
            self.words.wide_classes
        } else {
            0
        }
    }

    /// These settings with the fast front end of docs/design.md, "The front end's
    /// approximation" (the defaults): every 4th beam of a scan traced (`beam_stride = 4`), every
    /// 2nd density ray walked, cells weighted (`ray_stride = 2`); Ψ within the bound
    /// `tests/it/frontend_bound.rs` checks. About 14 ms a lap of the loop floor against 23
    /// exact (BENCHMARKS.md, session 9).
    pub fn with_fast_front_end(mut self) -> Self {
        self.grid.beam_stride = 4;
        self.density.ray_stride = 2;
        self
    }

    /// These settings with the exact front end (the authors' grid update and kernel): every beam
    /// traced and every ray walked (`beam_stride = 1`, `ray_stride = 1`).
    pub fn with_exact_front_end(mut self) -> Self {
        self.grid.beam_stride = 1;
        self.density.ray_stride = 1;
        self
    }

    /// The density kernel of these settings: `kernel_radius_m` in cells, a ray every
    /// `ray_step_deg`, every `ray_stride`-th of them walked.
    pub fn density_kernel(&self) -> super::density::DensityKernel {
        super::density::DensityKernel::with_ray_stride(
            self.kernel_radius_cells(),
            self.density.ray_step_deg,
            self.density.ray_stride,
        )
    }

    /// Kernel radius in grid cells (rounded).
    pub fn kernel_radius_cells(&self) -> usize {
        (self.density.kernel_radius_m / self.grid.grid_cell_m).round() as usize
    }
}

/// Why a recognizer could not be built.
#[derive(Debug, thiserror::Error)]
pub enum RecognizerError {
    #[error("invalid recognizer settings: {}", join(.0))]
    InvalidConfig(Vec<ConfigProblem>),
}

fn join(problems: &[ConfigProblem]) -> String {
    problems
        .iter()
        .map(|p| p.to_string())
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_the_tables_of_the_settings() {
        let t = toml::Table::try_from(RecognizerConfig::default()).unwrap();
        let tables: Vec<&str> = t
            .iter()
            .filter(|(_, v)| v.is_table())
            .map(|(k, _)| k.as_str())
            .collect();
        let mut want = SECTIONS.to_vec();
        want.sort();
        let mut got = tables.clone();
        got.sort();
        assert_eq!(got, want);
    }
}
