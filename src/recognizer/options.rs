//! The recognizer's options, one struct per component, each with its defaults (docs/design.md,
//! Recognizer choices), its units and its own checks. A file sets them as subtables of
//! `[recognizer]` named after the component: `[recognizer.front_end]`, `[recognizer.grid]`,
//! `[recognizer.density]`, `[recognizer.words]`, `[recognizer.matcher]`,
//! `[recognizer.alignment]`, `[recognizer.verify]` (docs/scenario-format.md). What crosses two
//! components (the kernel inside the grid, say) is checked by `RecognizerConfig::problems`.

use super::config::ConfigProblem;
use super::types::Direction;
use crate::spec::diag::fmt_number;
use serde::{Deserialize, Serialize};

/// Smallest `observation_spacing_m`, metres: the observations (and their memory) grow as
/// travel / spacing, and a real log at 1e-4 m runs for minutes.
pub const MIN_OBSERVATION_SPACING_M: f64 = 0.01;
/// Largest `max_alignment_offset` and `chain_alignment_offset`, observations: each shift is
/// tried for every matched pair (1e9 never finishes).
pub const MAX_ALIGNMENT_OFFSET: usize = 1000;
/// Largest `ray_stride`: weights of bins that wider strides leave with a cell or none say
/// little.
pub const MAX_RAY_STRIDE: usize = 8;
/// Largest `beam_stride`: a wider stride leaves free space unseen for as many integrations.
pub use super::grid::MAX_BEAM_STRIDE;
/// Largest local grid the recognizer accepts, cells from the centre to the edge.
pub const MAX_GRID_HALF_CELLS: f64 = 1000.0;

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Problems of one options table, each located by its key.
struct Problems {
    section: &'static str,
    out: Vec<ConfigProblem>,
}

impl Problems {
    fn new(section: &'static str) -> Self {
        Problems {
            section,
            out: Vec::new(),
        }
    }

    fn bad(&mut self, field: &'static str, problem: String) {
        self.out
            .push(ConfigProblem::new(self.section, field, problem));
    }

    /// `field` must be a finite number of at least 0.
    fn non_negative(&mut self, field: &'static str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.bad(
                field,
                format!("must be a number of at least 0, got {}", fmt_number(v)),
            );
        }
    }

    /// `field` must lie in `range` (`shown` as written in the message).
    fn within(&mut self, field: &'static str, v: f64, ok: bool, shown: &str, default: &str) {
        if !(v.is_finite() && ok) {
            self.bad(
                field,
                format!(
                    "must be in {shown}, got {}; the default is {default}",
                    fmt_number(v)
                ),
            );
        }
    }
}

/// Front end (paper §II): when observations are made along the odometry, and how scans reach
/// the local grid. `[recognizer.front_end]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct FrontEndOptions {
    /// Odometric travel between two observations, metres. Default 0.10.
    pub observation_spacing_m: f64,
    /// Longest step between two scans along which observations are interpolated, metres: a scan
    /// after a step of up to this length makes one observation per spacing passed, at poses along
    /// the step; a longer jump makes one observation at the new pose. The local grid's torus
    /// reaches far enough that those observations' kernels never read its far side (cells
    /// farther than `grid_memory_m` from the robot read as unknown). Default 5.0: Intel thinned
    /// to every 3rd scan has steps up to 3.1 m (3.3 m with odometry noise); at 3.0 each longer
    /// step left a gap of one observation where 30 were due, words broke there, and no noise
    /// seed 1–5 gave a pair (with 4.0 or 5.0 all five do, precision 0.995; every 4th scan, steps
    /// up to 4.2 m, needs 5.0).
    pub max_interpolation_m: f64,
    /// Integrate every scan into the local grid, instead of one scan per observation step as the
    /// authors' code does. Default false.
    pub integrate_every_scan: bool,
}

impl Default for FrontEndOptions {
    fn default() -> Self {
        FrontEndOptions {
            observation_spacing_m: 0.10,
            max_interpolation_m: 5.0,
            integrate_every_scan: false,
        }
    }
}

impl FrontEndOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("front_end");
        if !(self.observation_spacing_m.is_finite()
            && self.observation_spacing_m >= MIN_OBSERVATION_SPACING_M)
        {
            p.bad(
                "observation_spacing_m",
                format!(
                    "must be a distance of at least {MIN_OBSERVATION_SPACING_M} m (finer spacing \
                     multiplies the observations and the memory they take), got {}; the default \
                     is 0.10",
                    fmt_number(self.observation_spacing_m)
                ),
            );
        }
        let m = self.max_interpolation_m;
        p.within(
            "max_interpolation_m",
            m,
            (0.0..=20.0).contains(&m),
            "[0, 20]",
            "5",
        );
        p.out
    }
}

/// The local occupancy grid the scans are traced into (paper §II-A). `[recognizer.grid]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct GridOptions {
    /// Side of a local grid cell, metres. Default 0.05.
    pub grid_cell_m: f64,
    /// How far from the robot each scan is traced into the local grid, metres (cells are
    /// forgotten beyond `grid_memory_m`). Default 3.0.
    pub grid_radius_m: f64,
    /// How far from the robot, along either axis, the local grid remembers cells, metres (at
    /// least `grid_radius_m`); farther cells are forgotten, and read as unknown by a kernel
    /// centred back along a long step. Default 6.4 (a window of 256 cells of 5 cm, as before
    /// it was a setting; 12.8 m, which remembers a corridor the robot turned out of, cost fhw
    /// every pair).
    pub grid_memory_m: f64,
    /// Beams of a scan traced into the grid: every `beam_stride`-th, the next scan the next
    /// ones, so that `beam_stride` consecutive integrations trace each beam once, and each
    /// traced beam lowers the counters it passes as `beam_stride` beams would; every return
    /// within `grid_radius_m` still marks its cell occupied, and the beams traced from the
    /// sensor (every 16th) are traced on every scan. A scan more than 0.15 m or 2° from the
    /// last one integrated (a sparse log, a turn) traces every beam, so on the real logs, whose
    /// scans are farther apart, a stride changes nothing. 1 traces every beam on every scan (the
    /// exact front end, `RecognizerConfig::with_exact_front_end`). Default 4: with
    /// `ray_stride = 2` the fast front end, about 14 ms a lap of the loop floor against 23
    /// exact, with Ψ within the bound `tests/it/frontend_bound.rs` checks and precision as
    /// high as exact's over scenario seeds 1–30 (docs/design.md, "The front end's
    /// approximation").
    pub beam_stride: usize,
}

impl Default for GridOptions {
    fn default() -> Self {
        GridOptions {
            grid_cell_m: 0.05,
            grid_radius_m: 3.0,
            grid_memory_m: 6.4,
            beam_stride: 4,
        }
    }
}

impl GridOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("grid");
        if !positive(self.grid_cell_m) {
            p.bad(
                "grid_cell_m",
                format!(
                    "must be a positive size, got {}; the default is 0.05",
                    self.grid_cell_m
                ),
            );
        }
        self.radius_problems(&mut p);
        self.memory_problems(&mut p);
        let b = self.beam_stride;
        p.within(
            "beam_stride",
            b as f64,
            (1..=MAX_BEAM_STRIDE).contains(&b),
            &format!("[1, {MAX_BEAM_STRIDE}]"),
            "1",
        );
        p.out
    }

    /// Whether `m` metres is more cells of `grid_cell_m` than the grid accepts.
    fn too_many_cells(&self, m: f64) -> bool {
        positive(self.grid_cell_m) && m / self.grid_cell_m > MAX_GRID_HALF_CELLS
    }

    fn radius_problems(&self, p: &mut Problems) {
        if !positive(self.grid_radius_m) {
            p.bad(
                "grid_radius_m",
                format!(
                    "must be a positive radius, got {}; the default is 3.0",
                    self.grid_radius_m
                ),
            );
        } else if self.too_many_cells(self.grid_radius_m) {
            p.bad(
                "grid_radius_m",
                format!(
                    "{} m is more than {} cells of {} m; use a smaller radius or larger cells",
                    self.grid_radius_m, MAX_GRID_HALF_CELLS, self.grid_cell_m
                ),
            );
        }
    }

    fn memory_problems(&self, p: &mut Problems) {
        if !positive(self.grid_memory_m) {
            p.bad(
                "grid_memory_m",
                format!(
                    "must be a positive distance, got {}; the default is 6.4",
                    self.grid_memory_m
                ),
            );
        } else if positive(self.grid_radius_m) && self.grid_memory_m < self.grid_radius_m {
            p.bad(
                "grid_memory_m",
                format!(
                    "{} m is less than grid_radius_m ({} m); the grid must remember what a scan traces",
                    self.grid_memory_m, self.grid_radius_m
                ),
            );
        } else if self.too_many_cells(self.grid_memory_m) {
            p.bad(
                "grid_memory_m",
                format!(
                    "{} m is more than {} cells of {} m; use a shorter memory or larger cells",
                    self.grid_memory_m, MAX_GRID_HALF_CELLS, self.grid_cell_m
                ),
            );
        }
    }
}

/// The density Ψ of the free space around the robot (paper §II-B, Eq. 1): its kernel.
/// `[recognizer.density]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct DensityOptions {
    /// Radius of the density kernel, metres (at most `grid_radius_m`). Default 2.5.
    pub kernel_radius_m: f64,
    /// Angle between two density rays, degrees. Default 1.0.
    pub ray_step_deg: f64,
    /// Radius of the wide window, metres: the share of a disc this wide that the laser has seen
    /// free lately, the wide density Φ, splits Ψ's top class in open space, where Ψ saturates
    /// (`wide_classes` in `[recognizer.words]`; `recognizer::wide`). 0 turns it off. Default 20.
    pub wide_radius_m: f64,
    /// Rays walked: every `ray_stride`-th of those `ray_step_deg` apart, each cell counted with
    /// a weight (the cells every ray reaches in its bin, a ring and a sector, over those the
    /// walked rays reach; `DensityKernel::with_ray_stride`), so that an all-free window still
    /// gives Ψ = 1 and Ψ stays that of every ray within the bound `tests/it/frontend_bound.rs`
    /// checks. 1 walks every ray (the exact kernel, the authors'). Default 2: a density costs
    /// about 40 % less, and with `beam_stride = 4` it is the fast front end (see `beam_stride`
    /// in `[recognizer.grid]`); 3 or 4 cost seattle its pairs on 3 noise seeds of its 4.
    pub ray_stride: usize,
}

impl Default for DensityOptions {
    fn default() -> Self {
        DensityOptions {
            kernel_radius_m: 2.5,
            ray_step_deg: 1.0,
            wide_radius_m: 20.0,
            ray_stride: 2,
        }
    }
}

impl DensityOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("density");
        if !positive(self.kernel_radius_m) {
            p.bad(
                "kernel_radius_m",
                format!(
                    "must be a positive radius, got {}; the default is 2.5",
                    self.kernel_radius_m
                ),
            );
        }
        let r = self.ray_step_deg;
        p.within(
            "ray_step_deg",
            r,
            positive(r) && r <= 360.0,
            "(0, 360]",
            "1.0",
        );
        let w = self.wide_radius_m;
        p.within(
            "wide_radius_m",
            w,
            w.is_finite() && (w == 0.0 || (1.0..=100.0).contains(&w)),
            "0 (off) or [1, 100]",
            "20",
        );
        let k = self.ray_stride;
        p.within(
            "ray_stride",
            k as f64,
            (1..=MAX_RAY_STRIDE).contains(&k),
            &format!("[1, {MAX_RAY_STRIDE}]"),
            "1",
        );
        p.out
    }
}

/// Density classes, words and multi-level words (paper §III, Algorithms 1 and 2).
/// `[recognizer.words]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct WordOptions {
    /// Number of uniform density classes over [0, 1]: class = min(floor(classes·Ψ), classes − 1)
    /// (boundaries shifted by `class_offset`). Default 8.
    pub classes: usize,
    /// Minimum word size t_o, observations: a shorter run of another class is absorbed by the word
    /// it interrupts. Default 5.
    pub min_word_size: usize,
    /// How upper-level ("corrected") words are built: `paper` (Algorithm 2 as written: a level-l
    /// word fuses l + 2 level-0 words whose first and last share a class) or `boundaries` (a
    /// level-l word fuses a bump that leaves a class and comes back to it, crossing l class
    /// boundaries at its deepest: `A B A` is level 1, `A B C B A` level 2). Default `boundaries`
    /// (see the `words` module doc for why).
    pub multi_level: MultiLevelRule,
    /// Classes for open space above Ψ's top class, read from the wide density Φ (the share of a
    /// disc of `wide_radius_m` in `[recognizer.density]` seen free; Ψ saturates in open space):
    /// an observation of the top class with Φ ≥ ½ has class
    /// `classes + min(floor(wide_classes·(2Φ − 1)), wide_classes − 1)`. 0 (or a wide window
    /// turned off) keeps the top class whole. Default 4.
    pub wide_classes: usize,
    /// Observations of a centred window over which Ψ is summarized before it is quantized (an
    /// experiment, issue 28): an odd count; each observation's class is that of the window's
    /// `psi_window_statistic`, the window cut at the ends of a run. Centred, so a place driven
    /// either way gets the same classes; words then close `psi_window / 2` observations later.
    /// 1 (off) classifies each observation by its own Ψ. Default 1; at most 101
    /// (`MAX_PSI_WINDOW`).
    pub psi_window: usize,
    /// How the `psi_window` is summarized: `median` or `mean`. Default `median`.
    pub psi_window_statistic: PsiWindowStatistic,
    /// Shifts every density class boundary down by this fraction of a class (not in the
    /// paper): class = min(floor(classes·Ψ + class_offset), classes − 1), so with 8 classes and
    /// 0.5 the boundaries lie at 0.0625, 0.1875, … instead of 0.125, 0.25, …. In [0, 1);
    /// default 0 (the paper's classes). Why it exists: where a building's Ψ has its mode on a
    /// boundary, words flicker between the two classes there, and where it lies decides much
    /// of the figures. The simulated floors' corridors put Ψ's mode at 0.5, a boundary: 0.5
    /// raises scenario A's 3-level recall 0.637 → 0.713 and `reverse`'s 0.693 → 0.843 (seeds
    /// 1–10), but the real logs move by chance with any shift, a sixteenth of a class
    /// included (seattle: pairs on 0 or 5 seeds of 5, fhw 5 or 0; RESULTS.md, session 10), so
    /// it is left at 0 and kept to measure that.
    pub class_offset: f64,
}

/// The widest `psi_window`, observations (10 m at the default spacing): each observation sorts
/// its window, so a window as long as a run would make the word builder quadratic.
pub const MAX_PSI_WINDOW: usize = 101;

/// How a window of Ψ is summarized before quantization (`psi_window_statistic`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum PsiWindowStatistic {
    /// The median (the mean of the two middle values of an even count).
    Median,
    /// The arithmetic mean.
    Mean,
}

impl Default for WordOptions {
    fn default() -> Self {
        WordOptions {
            classes: 8,
            min_word_size: 5,
            multi_level: MultiLevelRule::Boundaries,
            wide_classes: 4,
            psi_window: 1,
            psi_window_statistic: PsiWindowStatistic::Median,
            class_offset: 0.0,
        }
    }
}

impl WordOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("words");
        if self.classes == 0 || self.classes > 255 {
            p.bad(
                "classes",
                format!(
                    "must be between 1 and 255, got {}; the default is 8",
                    self.classes
                ),
            );
        }
        if self.min_word_size == 0 {
            p.bad(
                "min_word_size",
                "must be at least 1 observation; the default is 5".to_string(),
            );
        }
        if self.classes + self.wide_classes > 256 {
            p.bad(
                "wide_classes",
                format!(
                    "classes + wide_classes must be at most 256, got {} + {}; the default is 4 \
                     (0: no open-space classes)",
                    self.classes, self.wide_classes
                ),
            );
        }
        p.within(
            "class_offset",
            self.class_offset,
            (0.0..1.0).contains(&self.class_offset),
            "[0, 1)",
            "0",
        );
        if self.psi_window.is_multiple_of(2) || self.psi_window > MAX_PSI_WINDOW {
            p.bad(
                "psi_window",
                format!(
                    "must be an odd count of observations (centred) of at most {MAX_PSI_WINDOW}, \
                     got {}; the default is 1 (off)",
                    self.psi_window
                ),
            );
        }
        p.out
    }
}

/// How upper-level words are built (`multi_level` setting); see the `words` module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum MultiLevelRule {
    /// Algorithm 2 as written: level l fuses the l + 2 level-0 words w_{j−l−1} … w_j when
    /// w_{j−l−1} and w_j have the same class.
    Paper,
    /// Level l fuses a bump of depth l: level-0 words w_i … w_j with w_i and w_j of class D, every
    /// word between of another class, the farthest of them l classes from D, and at most 2l + 1
    /// of them.
    Boundaries,
}

/// Largest `reverse_size_tolerance_observations`: 10 m of observations at the default spacing;
/// more would let every word of a class match every other.
pub const MAX_SIZE_TOLERANCE_OBSERVATIONS: usize = 100;

/// Word matching and n-gram chains (paper §III-C): which word pairs match, which chains of them
/// are reported, in which directions. `[recognizer.matcher]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct MatcherOptions {
    /// Minimum n-gram size (words) per level configuration: index k applies to configuration
    /// k + 1. Needs at least `levels` entries; 0 and 1 both accept every matching word pair (the
    /// paper's Fig. 8 sweeps from 0). Default [6, 9, 12, 15].
    pub min_ngram: Vec<usize>,
    /// Size syllables match when |S₁ − S₂| ≤ ratio · max(S₁, S₂) (read backwards, plus
    /// `reverse_size_tolerance_observations`). Default 0.25.
    pub size_tolerance_ratio: f64,
    /// Read backwards, size syllables also match within this many observations more: |S₁ − S₂| ≤
    /// `size_tolerance_ratio` · max(S₁, S₂) + this (not in the paper; 0 = the ratio alone). The
    /// idea: a level-0 word closes only once the new class has lasted `min_word_size`
    /// observations, and a shorter flicker before that is absorbed by the word driven first, so
    /// driven the other way a boundary could move by a few observations whatever the words'
    /// lengths, while the ratio alone asks a 10-observation word to agree within 2.5. (A
    /// boundary placed the same either way changed nothing on Intel, fhw or seattle, so that is
    /// not what splits the words read backwards.) Default 0 (off): on Intel (noise seeds 1–5)
    /// 2 raised 3-level recall 0.435 → 0.460 (worst seed 0.387 → 0.411) at precision ≥ 0.979,
    /// but 1 lowered it to 0.428 (worst 0.370) and 3 gave 0.475: chains read backwards won
    /// and lost by seed, not a trend; and
    /// with 1 or 2 `scenarios/reverse.toml` misses its 1-level opposite precision bound (0.944
    /// against 0.95 at seed 7; session 9's default had 0.951 there). Applied driven the same way
    /// too, 2 lowered scenario A's 1-level precision to 0.633 at seed 3. RESULTS.md, session 10.
    /// At most 100.
    pub reverse_size_tolerance_observations: usize,
    /// Read backwards, size syllables also match within this share of the two words' sampling slack
    /// more ([`Word::sampling_slack_obs`](super::words::Word::sampling_slack_obs): how many more
    /// observations the scan steps at their ends made), and verification's travel check widens by
    /// the same share in metres (not in the paper; 0 = off). On a sparse log a class boundary that
    /// a long scan step crossed is placed somewhere along the step, so a word's size is known to a
    /// step at each end (Intel: a scan every 0.7 m, 7 observations), while the ratio alone asks a
    /// 15-observation word to agree within 4. A word's size and the travel to the next word's start
    /// are one measure, hence one share for both: with the sizes alone widened, the travel check
    /// turned the chains down. With a scan per observation or denser (every simulated run) the
    /// slack is 0 and nothing changes. Default 0.2, tuned on Intel (noise seeds 1–5; 0.1 → 3-level
    /// recall 0.446, 0.15 → 0.471, 0.2 → 0.492, 0.25 → 0.487, 0.3 → 0.481, 0.5 → 0.473, mean
    /// precision 0.975–0.985) and confirmed on Intel seeds 6–10, Intel every 3rd scan, fhw and
    /// seattle. Applied driven the same way too, it cost Intel every 3rd scan its precision (0.990
    /// → 0.904) and fhw 1.000 → 0.976. In [0, 2].
    pub reverse_sampling_slack: f64,
    /// Angle syllables match when the wrapped difference is at most this, degrees. Default 30.
    pub angle_tolerance_deg: f64,
    /// Widen the angle tolerance of two words by how far their angle syllables may be off
    /// because the positions they are measured from were interpolated along long steps between
    /// sparse scans (each word's `angle_slack_deg`: the step's turn could lie anywhere in it),
    /// by at most half of `angle_tolerance_deg` more. Where no observation is interpolated
    /// across a turn (every simulated run: scans 4–10 cm apart) nothing changes. Default true:
    /// Intel every 3rd scan (1.6 m between scans) gets same-direction pairs where it had none;
    /// the cap of half the tolerance keeps Intel every 4th scan's precision (the whole
    /// tolerance lowered it 0.892 → 0.832; RESULTS.md, 2026-12-05).
    pub angle_slack: bool,
    /// Candidate gap: a past word must end at least this much odometric travel before the
    /// current n-gram begins, metres (not the evaluation's revisit gap, `[evaluation] min_gap_m`,
    /// though both default to 20). Default 20.0.
    pub candidate_gap_m: f64,
    /// Most recent candidates a closing word is matched against: the last k earlier words of its
    /// class that match it and end beyond the candidate gap; 0 = every one (the paper). A bound
    /// keeps the work and the output per lap flat as the history grows (a long-term run), at the
    /// cost of pairing each place with its k most recent look-alikes only. Default 0.
    pub max_candidates: usize,
    /// Also recognize revisits driven the other way (paper §VI, future work). The past words are
    /// read backwards: their order reversed, each angle syllable negated (class and size are
    /// unchanged), and a chain grows through successors, so current word i+1 pairs with past
    /// word j−1 when current i pairs with past j. The fine alignment reads the past word's Ψ
    /// backwards. Verification is the same, with the past side's travel and turn measured
    /// backwards (the turn between two matched past words is negated). Such matches carry
    /// `direction = "opposite"`. Default true.
    pub reverse: bool,
    /// Extra words an opposite-direction n-gram needs beyond the configuration's minimum size:
    /// a corridor whose words alternate between two classes reads the same both ways, so short
    /// opposite chains are often a place matched to its own mirror image. Default 2 (tuned on
    /// scenario A seeds 1..10, which has no opposite revisit: 2 removed every opposite match
    /// there; confirmed on `reverse` seeds 1..10: opposite precision 0.939 → 0.977 mean).
    pub reverse_extra_ngram: usize,
    /// Extra words a chain needs, driven the same way, when its n-gram's current words take
    /// only two density classes. Neighbouring words differ in class, so such an n-gram's
    /// classes alternate and, after its first word, say nothing; its evidence is the words'
    /// sizes and turns alone, which a corridor of regularly spaced doors repeats and two
    /// corners that turn alike share. The n-gram is verified and reported once its chain is
    /// this many words longer (it stays the last τ words); 0 = off. Read backwards this does
    /// not apply (those chains must turn, and need `reverse_extra_ngram` more words already).
    /// Default 1: tuned on scenario A with weaving laps (`lap_variation = "real-weave"`),
    /// seeds 1–5, where 7 of the 8 false chains were two-class n-grams of exactly τ words
    /// (3-level precision worst 0.916 → 0.960, recall mean 0.397 → 0.382; 2 gave 0.966 and
    /// 0.373, refusing every two-class n-gram 0.962 and 0.319), and Intel (unchanged);
    /// confirmed on A, B, C and `reverse`, smooth and weaving, seeds 1–10, and the five logs
    /// (RESULTS.md, 2026-12-05).
    pub two_class_extra_ngram: usize,
    /// Chains may bridge one substituted word: (c, p) may extend a chain ending one level-0 word
    /// further back on both sides, when the two skipped words have the same class and sizes
    /// within `substitution_size_ratio` (their angle syllable, or their size by a little, did
    /// not match). The bridged pair does not count towards the n-gram's size. Sparse real logs
    /// and turns between scans move a word's turn angle between visits, which breaks chains
    /// before τ. Default true: fhw gets pairs on every noise seed 1..5 (none without, precision
    /// 1.0); scenarios A, B, C and `reverse` keep 3-level precision ≥ 0.95 on every seed 1..10
    /// and A's recall rises 0.562 → 0.592 (RESULTS.md).
    pub substitutions: bool,
    /// How far the sizes of the two words a substitution bridges may differ, as a fraction of
    /// the larger (`substitutions`). Default 0.3: the bridged words keep (nearly) the size
    /// syllable and differ in their turn angle, which in logs with turns between scans is what
    /// moves; bridging any same-class word lowered scenario A's worst precision to 0.937.
    pub substitution_size_ratio: f64,
    /// Also accept an n-gram shorter than the configuration's minimum size when it has at least
    /// `ngram_travel_min_words` word pairs and its current side spans at least this much
    /// odometric travel, metres; 0 = off. Long words (a corridor loop where a word is 3–8 m)
    /// make τ words a long stretch that one path difference breaks. Default 0 (off): with 12 m
    /// Intel's opposite-direction recall goes 0 → 0.38 (noise seeds 1..5, precision 0.977) and
    /// seattle gets pairs on 1 of 5 seeds, but fhw's precision falls to 0.55 and scenario
    /// A's 3-level precision to 0.693 (RESULTS.md).
    pub ngram_travel_m: f64,
    /// The same for n-grams read backwards (opposite direction), metres; 0 = off. Default 30.
    /// Read backwards, a word's boundaries do not fall where they fell driving the other way (the
    /// laser looks ahead, so Ψ rises and falls at different places), so opposite chains break
    /// into runs of a few long words that rarely reach τ + `reverse_extra_ngram` words: without
    /// this rule Intel's opposite-direction recall is 0.03. Shorter spans let through corridors
    /// that read the same backwards (scenario A, which has no opposite revisit: 3-level precision
    /// 0.839 at 12 m); with `reverse_verify_max_lateral_rms`, 30 m keeps A's precision
    /// (RESULTS.md; tuned on A seeds 1–10 and Intel noise seeds 1–3).
    pub reverse_ngram_travel_m: f64,
    /// Fewest word pairs an n-gram accepted by `ngram_travel_m` needs (plus
    /// `reverse_extra_ngram` read backwards). Default 4.
    pub ngram_travel_min_words: usize,
    /// A shorter n-gram read backwards (not in the paper): when a chain read backwards has no
    /// n-gram by τ or by `reverse_ngram_travel_m`, its last word pairs, as few as span
    /// `reverse_short_ngram_travel_m` but at least `reverse_short_ngram_words` and fewer than τ,
    /// are a candidate; verification holds such an n-gram to `reverse_short_max_lateral_rms` in
    /// `[recognizer.verify]`. 0 = off.
    /// Read backwards a place's words disagree more than driven the same way (on fhw, words of
    /// one class at an opposite revisit differ in size by 0.27–0.36 of the larger, median over
    /// noise seeds 1–5, against 0.17–0.23 driven the same way; `examples/opposite_revisits.rs`),
    /// so opposite chains stop at 4–5 words where same-direction ones go on; seattle's one
    /// opposite stretch long enough makes a chain of 4 words over 22–25 m. Default 4: seattle
    /// gets pairs on noise seeds 1–4 instead of 4 only (5 words: seed 4 only); tuned on seattle
    /// and `reverse` seeds 1–10, confirmed on A, B, C and `reverse`, smooth and weaving, Intel
    /// (every scan and every 3rd) and fhw (RESULTS.md, session 7).
    pub reverse_short_ngram_words: usize,
    /// Travel the current side of such a short n-gram read backwards must span, metres. Default
    /// 22: seattle's short chains span 22–25 m (25 keeps seed 4 only); 20 gives `reverse` about
    /// the same precision (3 levels 0.984 mean, 0.969 worst seed).
    pub reverse_short_ngram_travel_m: f64,
}

impl Default for MatcherOptions {
    fn default() -> Self {
        MatcherOptions {
            min_ngram: vec![6, 9, 12, 15],
            size_tolerance_ratio: 0.25,
            reverse_size_tolerance_observations: 0,
            reverse_sampling_slack: 0.2,
            angle_tolerance_deg: 30.0,
            angle_slack: true,
            candidate_gap_m: 20.0,
            max_candidates: 0,
            reverse: true,
            reverse_extra_ngram: 2,
            two_class_extra_ngram: 1,
            substitutions: true,
            substitution_size_ratio: 0.3,
            ngram_travel_m: 0.0,
            reverse_ngram_travel_m: 30.0,
            ngram_travel_min_words: 4,
            reverse_short_ngram_words: 4,
            reverse_short_ngram_travel_m: 22.0,
        }
    }
}

impl MatcherOptions {
    /// Whether the size syllables of two words, `a` and `b` observations long with sampling
    /// slack `sampling_obs` between them (the sum of their
    /// [`Word::sampling_slack_obs`](super::words::Word::sampling_slack_obs)), match read in
    /// direction `dir`: they differ by at most `size_tolerance_ratio` of the larger, read
    /// backwards `reverse_size_tolerance_observations` and `reverse_sampling_slack` ·
    /// `sampling_obs` more. The one size rule (the matcher and the study tools read it).
    pub fn sizes_match(&self, a: usize, b: usize, sampling_obs: f64, dir: Direction) -> bool {
        self.size_excess_matches(self.size_excess(a, b), sampling_obs, dir)
    }

    /// How much more verification's travel check allows between two word starts read in
    /// direction `dir`, metres, when the words spanning the travel have sampling slack
    /// `sampling_obs` between them ([`sizes_match`](Self::sizes_match)) and observations are
    /// `spacing_m` apart: the same share as the size syllables get, read backwards; 0 driven
    /// the same way.
    pub fn travel_sampling_slack_m(
        &self,
        sampling_obs: f64,
        spacing_m: f64,
        dir: Direction,
    ) -> f64 {
        self.sampling_slack(sampling_obs, dir) * spacing_m
    }

    /// The share of `sampling_obs` (observations) that sizes, and the travel between word
    /// starts, may differ by beyond their own tolerances, read in direction `dir`: the one
    /// `reverse_sampling_slack` rule of [`size_slack`](Self::size_slack) and
    /// [`travel_sampling_slack_m`](Self::travel_sampling_slack_m).
    fn sampling_slack(&self, sampling_obs: f64, dir: Direction) -> f64 {
        match dir {
            Direction::Same => 0.0,
            Direction::Opposite => self.reverse_sampling_slack * sampling_obs,
        }
    }

    /// How far sizes `a` and `b` (observations) differ beyond `size_tolerance_ratio` of the
    /// larger (≤ 0 when they match driven the same way).
    pub(crate) fn size_excess(&self, a: usize, b: usize) -> f64 {
        let (sa, sb) = (a as f64, b as f64);
        (sa - sb).abs() - self.size_tolerance_ratio * sa.max(sb)
    }

    /// Whether sizes differing by `excess` ([`size_excess`](Self::size_excess)) match read in
    /// direction `dir`: the second half of [`sizes_match`](Self::sizes_match), for a caller
    /// that tests one excess both ways.
    pub(crate) fn size_excess_matches(
        &self,
        excess: f64,
        sampling_obs: f64,
        dir: Direction,
    ) -> bool {
        excess <= self.size_slack(sampling_obs, dir) + 1e-9
    }

    /// The observations sizes may differ by beyond the ratio, read in direction `dir`, for
    /// words with sampling slack `sampling_obs` between them.
    fn size_slack(&self, sampling_obs: f64, dir: Direction) -> f64 {
        let observations = match dir {
            Direction::Same => 0.0,
            Direction::Opposite => self.reverse_size_tolerance_observations as f64,
        };
        observations + self.sampling_slack(sampling_obs, dir)
    }

    /// Every problem of these options for a run of `levels` level configurations, located by
    /// key; empty when they are usable.
    pub fn problems(&self, levels: usize) -> Vec<ConfigProblem> {
        let mut p = Problems::new("matcher");
        self.tolerance_problems(&mut p);
        self.min_ngram_problems(levels, &mut p);
        if !(self.candidate_gap_m.is_finite() && self.candidate_gap_m >= 0.0) {
            p.bad(
                "candidate_gap_m",
                format!(
                    "must be a distance of at least 0, got {}; the default is 20",
                    self.candidate_gap_m
                ),
            );
        }
        let r = self.substitution_size_ratio;
        p.within(
            "substitution_size_ratio",
            r,
            (0.0..=1.0).contains(&r),
            "[0, 1]",
            "0.3",
        );
        p.non_negative("ngram_travel_m", self.ngram_travel_m);
        p.non_negative("reverse_ngram_travel_m", self.reverse_ngram_travel_m);
        p.non_negative(
            "reverse_short_ngram_travel_m",
            self.reverse_short_ngram_travel_m,
        );
        p.out
    }

    /// The word size and angle tolerances' ranges.
    fn tolerance_problems(&self, p: &mut Problems) {
        let s = self.size_tolerance_ratio;
        p.within(
            "size_tolerance_ratio",
            s,
            (0.0..1.0).contains(&s),
            "[0, 1)",
            "0.25",
        );
        if self.reverse_size_tolerance_observations > MAX_SIZE_TOLERANCE_OBSERVATIONS {
            p.bad(
                "reverse_size_tolerance_observations",
                format!(
                    "must be at most {MAX_SIZE_TOLERANCE_OBSERVATIONS} observations, got {}; the default is 0",
                    self.reverse_size_tolerance_observations
                ),
            );
        }
        let r = self.reverse_sampling_slack;
        p.within(
            "reverse_sampling_slack",
            r,
            (0.0..=2.0).contains(&r),
            "[0, 2]",
            "0.2",
        );
        let a = self.angle_tolerance_deg;
        p.within(
            "angle_tolerance_deg",
            a,
            (0.0..=180.0).contains(&a),
            "[0, 180]",
            "30",
        );
    }

    /// The words an n-gram read backwards needs beyond τ (none when `reverse` is off).
    pub(crate) fn opposite_extra_ngram(&self) -> usize {
        if self.reverse {
            self.reverse_extra_ngram
        } else {
            0
        }
    }

    /// The short rule for n-grams read backwards (`reverse_short_ngram_words`): its words (at
    /// least 1) and travel, metres, when it is on.
    pub(crate) fn short_opposite_rule(&self) -> Option<(usize, f64)> {
        (self.reverse && self.reverse_short_ngram_words > 0).then_some((
            self.reverse_short_ngram_words,
            self.reverse_short_ngram_travel_m,
        ))
    }

    /// The travel rule's span in direction `dir`: `ngram_travel_m` or `reverse_ngram_travel_m`.
    pub(crate) fn travel_rule_m(&self, dir: super::types::Direction) -> f64 {
        match dir {
            super::types::Direction::Same => self.ngram_travel_m,
            super::types::Direction::Opposite => self.reverse_ngram_travel_m,
        }
    }

    fn min_ngram_problems(&self, levels: usize, p: &mut Problems) {
        if self.min_ngram.len() < levels.min(4) {
            p.bad(
                "min_ngram",
                format!(
                    "has {} entries but levels = {} needs one per level configuration; e.g. [6, 9, 12, 15]",
                    self.min_ngram.len(),
                    levels
                ),
            );
        } else if self.min_ngram.iter().take(levels).any(|&n| n > 10_000) {
            p.bad(
                "min_ngram",
                "every size must be between 0 and 10000 words (0 and 1 both accept any chain)"
                    .to_string(),
            );
        }
    }
}

/// Fine alignment (paper §IV, Eq. 2): where the smaller word's window is placed against the
/// larger one's. `[recognizer.alignment]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct AlignmentOptions {
    /// Placements the fine alignment tries: `paper` (Eq. 2 as written: the n = min(S₁, S₂)
    /// observations from both words' starts, shifted by d ∈ (−Δmax, Δmax)) or `whole-word`
    /// (the smaller word's n observations at every placement inside the larger word, never past
    /// its ends) or `chain` (within ±`chain_alignment_offset` of the shift the whole matched
    /// n-gram agrees on, even past the words' ends, or of the nearest placement inside the
    /// larger word; ties within `chain_alignment_tie` go to the n-gram's shift). Default `chain`.
    /// (Before subtables, `[recognizer] alignment`.)
    pub mode: AlignmentMode,
    /// Largest shift Δmax tried by the fine alignment (Eq. 2), observations. Default 10.
    pub max_alignment_offset: usize,
    /// Largest shift from the n-gram's offset tried by `mode = "chain"`, observations.
    /// Default 5 (tuned on scenario A seeds 1..10: 10 left near-misses of about 1 m, 2 gave
    /// the same as 5).
    pub chain_alignment_offset: usize,
    /// `mode = "chain"`: placements whose mean squared Ψ difference is within this of the
    /// best count as equally good, and the one nearest the n-gram's shift wins (a long word of
    /// flat Ψ otherwise slid to whatever placement noise favoured). Ψ², default 1e-4 (an RMS
    /// difference of 0.01, a twelfth of a class of 8).
    pub chain_alignment_tie: f64,
    /// Pairs the rest of a matched current word too (not in the paper): Eq. 2 pairs n =
    /// min(S₁, S₂) observations, so a current word longer than its past match (a class boundary
    /// that moved between the visits) kept observations unpaired although the match places
    /// them. Outwards from the window, each further observation of the current word pairs with
    /// the past observation the window's shift gives while their Ψ differ by at most this.
    /// Ψ, default 0.03, in [0, 1]; 0 = the n pairs of Eq. 2 only. Tuned on Intel (noise seeds
    /// 1–5: 3-level recall 0.492 → 0.502 at precision 0.978; 0.04: 0.507 but `reverse`'s
    /// 1-level precision bound missed on one seed, 0.08: 0.510 at worst-seed precision 0.966),
    /// confirmed on Intel seeds 6–10, Intel every 3rd scan, seattle, fhw and the scenarios
    /// (RESULTS.md, session 13).
    pub fill_max_psi_diff: f64,
}

impl Default for AlignmentOptions {
    fn default() -> Self {
        AlignmentOptions {
            mode: AlignmentMode::Chain,
            max_alignment_offset: 10,
            chain_alignment_offset: 5,
            chain_alignment_tie: 1e-4,
            fill_max_psi_diff: 0.03,
        }
    }
}

impl AlignmentOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("alignment");
        for (field, v) in [
            ("max_alignment_offset", self.max_alignment_offset),
            ("chain_alignment_offset", self.chain_alignment_offset),
        ] {
            if v > MAX_ALIGNMENT_OFFSET {
                p.bad(
                    field,
                    format!(
                        "must be at most {MAX_ALIGNMENT_OFFSET} observations (every shift is \
                         tried for every matched pair), got {v}; the default is 10 or 5"
                    ),
                );
            }
        }
        p.non_negative("chain_alignment_tie", self.chain_alignment_tie);
        let f = self.fill_max_psi_diff;
        p.within(
            "fill_max_psi_diff",
            f,
            (0.0..=1.0).contains(&f),
            "[0, 1]",
            "0.03",
        );
        p.out
    }
}

/// Where the fine alignment may place the smaller word's window (`[recognizer.alignment] mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum AlignmentMode {
    /// Eq. 2 as written: shifts d ∈ (−Δmax, Δmax) from both words' starts.
    Paper,
    /// Every placement of the smaller word inside the larger one.
    WholeWord,
    /// Placements inside the larger word within ±Δmax of where the n-gram puts the pair: the
    /// travel offset between the current and past sides, taken as the median over the n-gram's
    /// word pairs of the offset between their centres. A long word of flat Ψ no longer slides
    /// to an arbitrary place inside its partner.
    Chain,
}

/// Verification of each candidate n-gram before it is reported (not in the paper; see the
/// `verify` module). `[recognizer.verify]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct VerifyOptions {
    /// Verify each match before reporting it (the other keys of this table). Default true.
    /// (Before subtables, `[recognizer] verify`.)
    pub enabled: bool,
    /// Travel: between two consecutive words of a matched n-gram, and from its first word to each
    /// later one, the odometric travel of the current and past sides may differ by at most this
    /// fraction of the longer, plus `verify_travel_slack_m`. Default 0.15 (tuned on scenario A
    /// seed 3 and Intel; 0.25, the word size tolerance, let through false n-grams whose words
    /// each fit but whose spacing drifts).
    pub verify_travel_ratio: f64,
    /// Travel: absolute slack added to the allowed difference, metres. Default 0.5.
    pub verify_travel_slack_m: f64,
    /// Turn: between two consecutive words of a matched n-gram, and from its first word to each
    /// later one, the odometric heading change of the two sides may differ by at most this,
    /// degrees. Default 30.
    pub verify_turn_deg: f64,
    /// Densities: the root mean square Ψ difference over the n-gram's aligned observation pairs
    /// must be at most this (Ψ ∈ [0, 1]; a class is 1/`classes` wide). Default 0.04 (a third of
    /// a class of 8; tuned on scenario A seed 3 and Intel).
    pub verify_max_psi_rms: f64,
    /// Sides: the root mean square difference of the observations' `lateral_moment` (where the
    /// space around the robot lies across the path, in kernel radii; a side corridor 3 m wide
    /// off a 2 m corridor gives about 0.12) over the n-gram's aligned pairs must be at most
    /// this. Ψ is the same on both sides of a mirror; this is not. Default 0.08 (tuned on
    /// scenario A and Intel; 0.05 cost Intel a third of its same-direction recall).
    pub verify_max_lateral_rms: f64,
    /// The same bound for n-grams read backwards, where the past side's moment is negated (driven
    /// the other way, left is right). Default 0.06: chains read backwards are runs of a few long
    /// words accepted by travel, and a corridor that reads the same backwards needs a tighter
    /// bound (scenario A at 30 m without the turn rule: 3-level precision 0.951, worst seed
    /// 0.901, with 0.08; 0.977 / 0.956 with 0.05). With the turn rule 0.06 keeps A's precision and
    /// gives every Intel noise seed 1–5 opposite pairs (0.05 left seed 4 with none).
    pub reverse_verify_max_lateral_rms: f64,
    /// Read backwards: the current side of an n-gram matched in the opposite direction must
    /// turn, its odometric heading changing by at least this from its first word, degrees;
    /// 0 = off. Default 45. A straight corridor read backwards matches itself mirrored about its
    /// middle wherever its two halves look alike (scenarios B and C: ~100,000 false opposite
    /// pairs per seed, 3-level precision 0.940 and 0.918 without it); Intel's opposite-direction
    /// recall hardly changes (noise seeds 1–3: 0.331–0.465 with 45 or 80).
    pub reverse_min_turn_deg: f64,
    /// Turn, judged over the n-gram as a whole: the heading offset between the two sides at
    /// each word start (current minus past, from the first word) must lie within
    /// `verify_turn_deg` of the offsets' median, except at up to this many word starts, never
    /// the newest, nor the first unless the n-gram extends a reported chain (then its first word
    /// start lies inside the chain: session 13, Intel noise seed 4 recall 0.485 → 0.505). 0 =
    /// the per-word limit of `verify_turn_deg` (every step, and every offset from the first
    /// word, within it). Default 1 (not in the paper). Why: a real robot
    /// cuts corners and turns on the spot, so a word boundary can fall inside a corner on one
    /// visit and after it on the other; that one word start is then off by the corner (60–80°)
    /// and the next agrees again. On Intel (noise seeds 1–5) the per-word limit turned down 54
    /// candidates, 42 of them true revisits, nearly all of this kind. The ends stay strict: an
    /// n-gram whose first word starts mid-corner on one side only is where two paths meet
    /// (allowing it cost Intel 0.02 precision), and one whose newest word turns on one side only
    /// waits until a later word agrees again. Tuned on Intel and scenario A with smooth and
    /// weaving laps (with 1: weaving A recall 0.414 → 0.515, worst precision 0.960 → 0.963).
    /// A short n-gram read backwards (`reverse_short_ngram_words`) keeps the per-word limit.
    pub verify_turn_outliers: usize,
    /// Travel, judged over the n-gram as a whole: up to this many of its word starts, never
    /// the first or the newest, may disagree and are passed over; the travel to the next word
    /// start is then measured from the last one that agreed (and from the first word, as
    /// always). 0 = every word start must agree (`verify_travel_ratio`). Default 0 (not in the
    /// paper; off by default). Why it exists: where a word boundary falls at another place on
    /// one pass (Ψ near a class boundary, a door that changed, a weaving robot's lane), that one
    /// word start moves, and the steps before and after it disagree by the shift with opposite
    /// signs while the travel of the n-gram agrees; of the travel check's rejections on scenario
    /// A (seeds 1–10) 478 of 1,644 were true revisits, on Intel 14 of 20. With 1, recall rises
    /// everywhere (A 0.585 → 0.627, weaving A 0.515 → 0.550, `reverse` 0.668 → 0.701, Intel
    /// 0.442 → 0.448) and every seed keeps 3-level precision ≥ 0.95, but `scenarios/reverse.toml`
    /// misses its per-direction bounds (3 levels same-direction worst 0.932 → 0.910, opposite
    /// 0.980 → 0.953), so it is not the default (RESULTS.md, session 7, exact front end).
    pub verify_travel_outliers: usize,
    /// The sides bound for a short n-gram read backwards (`reverse_short_ngram_words` in
    /// `[recognizer.matcher]`). Default 0.035: four words say little, and the side of the free
    /// space is what tells a place from its mirror image (`reverse`, 3 levels, worst seed: 0.957
    /// at 0.04, 0.969 at 0.035, 0.967 without the rule; 0.03 costs seattle seed 2 its pairs).
    pub reverse_short_max_lateral_rms: f64,
    /// Read backwards, an n-gram that fails the travel or turn check is verified again without
    /// its oldest word pair, and again, while what is left is still a short n-gram
    /// (`reverse_short_ngram_words` words or more spanning `reverse_short_ngram_travel_m` in
    /// `[recognizer.matcher]`), held to the short rule's checks; the first that passes is the
    /// match. Default true (not in the paper). Why: a chain read backwards reaches back to where
    /// the robot came into the revisit from another corridor, and its oldest word starts then
    /// turn (or travel) on one side only, so the whole n-gram failed although its newer words
    /// are the place; chains read backwards are a few long words, so the next word does not
    /// come soon enough to leave the junction behind. On seattle it gives noise seed 3 its
    /// opposite pairs (every seed 1–5 has pairs at precision 1.0; also with `class_offset`
    /// 1/16, where none had any); Intel, fhw, A, B, C and weaving `reverse` are unchanged, and
    /// `reverse` keeps its worst precision (RESULTS.md, session 11). An n-gram that extends a
    /// reported chain is trimmed likewise, its densities then checked in full.
    pub reverse_trim_to_short: bool,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            enabled: true,
            verify_travel_ratio: 0.15,
            verify_travel_slack_m: 0.5,
            verify_turn_deg: 30.0,
            verify_max_psi_rms: 0.04,
            verify_max_lateral_rms: 0.08,
            reverse_verify_max_lateral_rms: 0.06,
            reverse_min_turn_deg: 45.0,
            verify_turn_outliers: 1,
            verify_travel_outliers: 0,
            reverse_short_max_lateral_rms: 0.035,
            reverse_trim_to_short: true,
        }
    }
}

impl VerifyOptions {
    /// Every problem of these options, located by key; empty when they are usable.
    pub fn problems(&self) -> Vec<ConfigProblem> {
        let mut p = Problems::new("verify");
        for (field, v) in [
            ("verify_travel_ratio", self.verify_travel_ratio),
            ("verify_travel_slack_m", self.verify_travel_slack_m),
            ("verify_turn_deg", self.verify_turn_deg),
            ("verify_max_psi_rms", self.verify_max_psi_rms),
            ("verify_max_lateral_rms", self.verify_max_lateral_rms),
            (
                "reverse_verify_max_lateral_rms",
                self.reverse_verify_max_lateral_rms,
            ),
            ("reverse_min_turn_deg", self.reverse_min_turn_deg),
            (
                "reverse_short_max_lateral_rms",
                self.reverse_short_max_lateral_rms,
            ),
        ] {
            p.non_negative(field, v);
        }
        p.out
    }

    /// The largest RMS lateral-moment difference in direction `dir`.
    pub(crate) fn max_lateral_rms(&self, dir: super::types::Direction) -> f64 {
        match dir {
            super::types::Direction::Same => self.verify_max_lateral_rms,
            super::types::Direction::Opposite => self.reverse_verify_max_lateral_rms,
        }
    }
}
