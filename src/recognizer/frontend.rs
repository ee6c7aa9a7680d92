//! Front end: odometry poses and scans → the stream of density observations.
//!
//! A scan is integrated into the local grid each time an observation is due (and at the start
//! of a run; every scan with `integrate_every_scan`); each time the odometric travel passes the next
//! multiple of `observation_spacing_m` (counted from the start of the run), Ψ is computed at the
//! robot's cell and an [`Observation`] is made. When a scan comes after a step longer than the
//! spacing (sparse logs: Intel has a scan every ~0.7 m, fhw every ~1 m), the multiples it passed
//! are observed at poses interpolated along the step, in the grid that already holds the new scan.
//!
//! The grid's window is centred on the newest scan, so an observation interpolated far back along
//! a long step has its kernel near the window's edge. The window is a torus: a kernel crossing
//! the edge reads cells from the far side, ahead of the robot, and Ψ there was garbage (this,
//! with steps over 2 m observed only once, is why Intel thinned to every 2nd scan gave no pair).
//! The torus therefore reaches `max_interpolation_m` plus the kernel radius beyond the robot
//! (a kernel reads cells farther than `grid_memory_m` as unknown, never the far side), and steps
//! up to `max_interpolation_m` are interpolated (longer jumps make one observation at the new
//! pose). A step just over that limit leaves a gap of one observation where dozens were due,
//! and the words there break. Steps longer than the grid radius leave a band that no scan
//! traced (the laser looks ahead, and beams are traced to the grid radius only): Ψ is lower
//! there (mean |ΔΨ| against dense scans 0.17 for 4.4 m steps in a synthetic corridor, 0.02 for
//! 2.9 m). Tracing farther for long steps halved that, but cost Intel every 3rd scan
//! precision (worst noise seed 0.991 → 0.882), so it was not kept.

use super::config::{RecognizerConfig, RecognizerError};
use super::density::{DensityKernel, RayDeltas};
use super::grid::LocalGrid;
use super::types::{DensityObservation, FrameId, Observation};
use super::wide::WideWindow;
use super::words::{WordLevels, density_class};
use crate::geom::OdomPose;
use crate::scan::Scan;

/// When observations are due: each time the odometric travel passes the next multiple of the
/// spacing, counted from the start of each run (a run's first scan is not one). The one rule
/// for where observations fall: the front end follows it, and so does `score`, which thins a
/// tool's scans to observations (`experiment::score`).
#[derive(Clone, Debug)]
pub struct ObservationClock {
    spacing_m: f64,
    max_interpolation_m: f64,
    last_odom: Option<OdomPose>,
    travel_m: f64,
    next_obs_travel_m: f64,
}

/// What one scan's step made due ([`ObservationClock::step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Due {
    /// The previous scan's pose and travel (`None` at a run's first scan).
    pub previous: Option<(OdomPose, f64)>,
    /// Spacing multiples the step passed (0: no observation is due).
    pub passed: usize,
    /// Travel of the first multiple passed, metres.
    pub first_travel_m: f64,
    /// Whether the `passed` observations are made along the step (it is at most
    /// `max_interpolation_m` long); otherwise one is made at the new pose.
    pub along_step: bool,
}

impl Due {
    /// The number of observations this step makes.
    pub fn observations(&self) -> usize {
        if self.along_step {
            self.passed
        } else {
            self.passed.min(1)
        }
    }
}

impl ObservationClock {
    /// A clock with observations every `spacing_m` of odometric travel, interpolated along steps
    /// up to `max_interpolation_m`.
    pub fn new(spacing_m: f64, max_interpolation_m: f64) -> Self {
        ObservationClock {
            spacing_m,
            max_interpolation_m,
            last_odom: None,
            travel_m: 0.0,
            next_obs_travel_m: spacing_m,
        }
    }

    /// Moves to the next scan, taken at `odom`.
    pub fn step(&mut self, odom: OdomPose) -> Due {
        let previous = self.last_odom.map(|last| (last, self.travel_m));
        self.travel_to(odom);
        let first_travel_m = self.next_obs_travel_m;
        if self.travel_m + 1e-9 < self.next_obs_travel_m {
            return Due {
                previous,
                passed: 0,
                first_travel_m,
                along_step: false,
            };
        }
        let passed =
            ((self.travel_m + 1e-9 - self.next_obs_travel_m) / self.spacing_m).floor() as usize + 1;
        self.next_obs_travel_m += passed as f64 * self.spacing_m;
        let along_step = previous.is_some_and(|(_, last_travel)| {
            passed > 1 && self.travel_m - last_travel <= self.max_interpolation_m + 1e-9
        });
        Due {
            previous,
            passed,
            first_travel_m,
            along_step,
        }
    }

    /// Adds the distance from the last scan's odometry to `odom` to the travel (a non-finite
    /// step adds nothing), and makes `odom` the last.
    fn travel_to(&mut self, odom: OdomPose) {
        if let Some(last) = self.last_odom {
            let step = last.0.distance(&odom.0);
            if step.is_finite() {
                self.travel_m += step;
            }
        }
        self.last_odom = Some(odom);
    }

    /// Starts a new run: the jump to the new start is not travel. Returns false (and does
    /// nothing) while the current run has had no scan.
    pub fn start_run(&mut self) -> bool {
        if self.last_odom.is_none() {
            return false;
        }
        self.last_odom = None;
        self.next_obs_travel_m = self.travel_m + self.spacing_m;
        true
    }

    /// Odometric travel so far, metres.
    pub fn travel_m(&self) -> f64 {
        self.travel_m
    }

    /// Spacing between observations, metres.
    pub fn spacing_m(&self) -> f64 {
        self.spacing_m
    }
}

/// The word settings the wide window depends on (Φ is read where Ψ is in the top class), when
/// the settings use it.
fn wide_window_settings(config: &RecognizerConfig) -> Option<(usize, usize, f64)> {
    let wide_classes = config.wide_classes_in_use();
    (wide_classes > 0).then_some((
        config.words.classes,
        wide_classes,
        config.words.class_offset,
    ))
}

/// The wide window of `config` and the density classes (count, offset) whose top one reads Φ,
/// when the settings use it.
fn wide_window(config: &RecognizerConfig) -> Option<(WideWindow, (usize, f64))> {
    let (classes, _, offset) = wide_window_settings(config)?;
    Some((
        WideWindow::new(config.density.wide_radius_m),
        (classes, offset),
    ))
}

/// Local grid + density: makes observations from odometry and scans.
#[derive(Clone, Debug)]
pub struct DensityFrontEnd {
    clock: ObservationClock,
    kernel_cells: usize,
    integrate_every_scan: bool,
    grid: LocalGrid,
    kernel: DensityKernel,
    deltas: RayDeltas,
    /// The wide window (`wide_radius_m` > 0 and `wide_classes` > 0), and the density classes
    /// (count, `class_offset`): the word builder reads Φ in the top one, so Φ is measured there
    /// only.
    wide: Option<(WideWindow, (usize, f64))>,
    /// Whether the newest observation's Ψ was in the top class (Φ read there).
    open: bool,
    run: usize,
    inputs: usize,
    next_id: usize,
    /// Steps longer than `max_interpolation_m` that passed more than one spacing.
    long_steps: usize,
}

impl DensityFrontEnd {
    /// A front end with the `[recognizer.front_end]`, `grid` and `density` settings of
    /// `config` (checked whole), and with a wide window, `[recognizer.words]` `classes` and
    /// `wide_classes` (where the wide density Φ is read): it reads no other (see
    /// [`Self::same_settings`]).
    pub fn new(config: &RecognizerConfig) -> Result<Self, RecognizerError> {
        config.validate()?;
        let mut grid = LocalGrid::with_memory(
            config.grid.grid_cell_m,
            config.grid.grid_radius_m,
            config.grid.grid_memory_m,
            config.front_end.max_interpolation_m + config.density.kernel_radius_m,
        );
        grid.set_beam_stride(config.grid.beam_stride);
        let kernel = config.density_kernel();
        Ok(DensityFrontEnd {
            clock: ObservationClock::new(
                config.front_end.observation_spacing_m,
                config.front_end.max_interpolation_m,
            ),
            kernel_cells: config.kernel_radius_cells(),
            integrate_every_scan: config.front_end.integrate_every_scan,
            deltas: kernel.deltas(grid.side()),
            wide: wide_window(config),
            open: false,
            grid,
            kernel,
            run: 0,
            inputs: 0,
            next_id: 0,
            long_steps: 0,
        })
    }

    /// Whether the front ends of `a` and `b` make the same observations of the same input: their
    /// `[recognizer.front_end]`, `grid` and `density` settings and the word settings of the
    /// wide window, all that [`Self::new`] reads, are equal (level configurations differ only past the front end, so a harness may run
    /// one front end for them all).
    pub fn same_settings(a: &RecognizerConfig, b: &RecognizerConfig) -> bool {
        a.front_end == b.front_end
            && a.grid == b.grid
            && a.density == b.density
            && wide_window_settings(a) == wide_window_settings(b)
    }

    /// Integrates one scan taken at `odom`; returns the observations it made: usually none or
    /// one; after a step longer than the spacing (sparse logs), one per spacing passed, at poses
    /// interpolated along the step (steps longer than `max_interpolation_m` give one).
    pub fn push(&mut self, odom: OdomPose, scan: &Scan) -> Vec<DensityObservation> {
        self.push_frame(self.inputs, odom, scan)
    }

    /// Like [`push`](Self::push), with the frame's id given by the caller: the observations it
    /// makes carry `frame_id`.
    pub fn push_frame(
        &mut self,
        frame_id: FrameId,
        odom: OdomPose,
        scan: &Scan,
    ) -> Vec<DensityObservation> {
        self.inputs += 1;
        let due = self.clock.step(odom);
        // The authors' code updates the grid once per observation step (0.10 m), not on every
        // scan: the same map at a fraction of the cost (a scan every 2.5 cm adds little).
        if self.integrate_every_scan || due.passed > 0 || due.previous.is_none() {
            self.grid.integrate(&odom, scan);
        }
        let travel_now = self.clock.travel_m();
        if let Some((w, _)) = &mut self.wide {
            w.integrate(odom.0, scan, travel_now, self.open);
        }
        if due.passed == 0 {
            return Vec::new();
        }
        let mut at: Vec<(OdomPose, f64, f64)> = Vec::new();
        match due.previous {
            Some((last, last_travel)) if due.along_step => {
                let span = (travel_now - last_travel).max(1e-12);
                for k in 0..due.passed {
                    let travel = due.first_travel_m + k as f64 * self.clock.spacing_m();
                    let f = ((travel - last_travel) / span).clamp(0.0, 1.0);
                    let (a, b) = (last.0, odom.0);
                    let pose = crate::geom::Pose2::new(
                        a.x + (b.x - a.x) * f,
                        a.y + (b.y - a.y) * f,
                        crate::geom::wrap_angle(
                            a.theta + crate::geom::wrap_angle(b.theta - a.theta) * f,
                        ),
                    );
                    // Where the step's turn took the path off its chord, for a path of constant
                    // curvature (an arc: span · |Δθ| · f(1 − f) / 2, the sagitta at f = ½).
                    let turn = crate::geom::wrap_angle(b.theta - a.theta).abs();
                    let slack_m = span * turn * f * (1.0 - f) / 2.0;
                    at.push((OdomPose(pose), travel.min(travel_now), slack_m));
                }
            }
            _ => {
                self.long_steps += usize::from(due.passed > 1 && due.previous.is_some());
                at.push((odom, travel_now, 0.0))
            }
        }
        let scan_step_observations = u32::try_from(at.len()).unwrap_or(u32::MAX);
        at.into_iter()
            .map(|(pose, travel_m, position_slack_m)| {
                debug_assert!(self.grid.kernel_fits(self.kernel_cells, pose.0.x, pose.0.y));
                let density = self
                    .grid
                    .density_at(&self.kernel, &self.deltas, pose.0.x, pose.0.y);
                let wide_density = match &self.wide {
                    Some((w, (classes, offset)))
                        if usize::from(density_class(density.psi, *classes, *offset)) + 1
                            == *classes =>
                    {
                        self.open = true;
                        w.density_at(pose.0.x, pose.0.y)
                    }
                    _ => {
                        self.open = false;
                        0.0
                    }
                };
                let (sin, cos) = pose.0.theta.sin_cos();
                let obs = DensityObservation {
                    observation: Observation::new(self.next_id, self.run, frame_id, pose, travel_m),
                    psi: density.psi,
                    // On the robot's left axis (−sin θ, cos θ) of the odometry heading.
                    lateral_moment: cos * density.moment.1 - sin * density.moment.0,
                    position_slack_m,
                    wide_density,
                    scan_step_observations,
                };
                self.next_id += 1;
                obs
            })
            .collect()
    }

    /// Starts a new run: the grid is cleared and the jump to the new start is not travel. Does
    /// nothing while the current run has had no input (so calling it before every run, the first
    /// included, is fine).
    pub fn start_run(&mut self) {
        if self.clock.start_run() {
            self.run += 1;
            self.grid.clear();
            self.open = false;
            if let Some((w, _)) = &mut self.wide {
                w.clear();
            }
        }
    }

    /// The local grid (for plots and tests).
    pub fn grid(&self) -> &LocalGrid {
        &self.grid
    }

    /// The density kernel in use.
    pub fn kernel(&self) -> &DensityKernel {
        &self.kernel
    }

    /// Steps between scans so far that were longer than `max_interpolation_m` and passed more
    /// than one observation spacing: each was observed once, and the words there break.
    pub fn long_steps(&self) -> usize {
        self.long_steps
    }

    /// Odometric travel so far, metres.
    pub fn travel_m(&self) -> f64 {
        self.clock.travel_m()
    }

    /// Index of the current run (0 for the first).
    pub fn run(&self) -> usize {
        self.run
    }
}

/// How far one front end's Ψ is from another's over the same observations (the fast front end
/// against the exact one, `[recognizer.grid] beam_stride`, `[recognizer.density] ray_stride`):
/// the one measure `tests/it/frontend_bound.rs` bounds and `examples/psi_bound.rs` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct PsiGap {
    /// Observations compared.
    pub observations: usize,
    /// Largest |ΔΨ|.
    pub max: f64,
    /// |ΔΨ| at the 99th percentile.
    pub p99: f64,
    /// Mean |ΔΨ|.
    pub mean: f64,
    /// Share of the observations with |ΔΨ| above [`PsiGap::FAR`].
    pub far_share: f64,
    /// Share of the observations whose density class (the word builder's, the wide density Φ
    /// included) differs.
    pub class_share: f64,
}

impl PsiGap {
    /// |ΔΨ| beyond which an observation counts in `far_share`.
    pub const FAR: f64 = 0.1;

    /// The gap between `a` and `b`, observations of the same inputs in the same order, classed
    /// by `cfg`'s words; `None` when their counts differ (the front ends did not observe at the
    /// same travel) or there is none.
    pub fn between(
        cfg: &RecognizerConfig,
        a: &[DensityObservation],
        b: &[DensityObservation],
    ) -> Option<PsiGap> {
        if a.len() != b.len() || a.is_empty() {
            return None;
        }
        let levels = WordLevels::new(cfg.words.classes, cfg.words.min_word_size, 1)
            .with_wide_classes(cfg.wide_classes_in_use())
            .with_class_offset(cfg.words.class_offset);
        let class = |o: &DensityObservation| levels.class_of_observation(o.psi, o.wide_density);
        let mut d: Vec<f64> = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x.psi - y.psi).abs())
            .collect();
        d.sort_by(f64::total_cmp);
        let n = d.len() as f64;
        let changed = a
            .iter()
            .zip(b)
            .filter(|(x, y)| class(x) != class(y))
            .count();
        Some(PsiGap {
            observations: d.len(),
            max: d[d.len() - 1],
            p99: d[((d.len() - 1) as f64 * 0.99) as usize],
            mean: d.iter().sum::<f64>() / n,
            far_share: d.iter().filter(|&&v| v > Self::FAR).count() as f64 / n,
            class_share: changed as f64 / n,
        })
    }
}
