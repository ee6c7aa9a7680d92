//! Words (paper Algorithm 1) and multi-level words (Algorithm 2), built online.
//!
//! Observations are quantized into density classes. A level-0 word is a run of observations of
//! one class; a run of another class shorter than `min_word_size` (t_o) is absorbed by the word
//! it interrupts, so a word closes only once the new class has lasted t_o observations (the first
//! word of a run, if shorter than t_o, is absorbed by the second). A word's syllables: D its
//! class, S its observation count, A = angle(median→last) − angle(first→median) in degrees,
//! wrapped to (−180, 180].
//!
//! **Upper levels** ("corrected" words for a bump such as an open door, paper §III). When level-0
//! word w_j closes, upper-level words ending at it are built from the observations of w_i … w_j
//! (same run only); such a word has the class of w_i, the predecessors of w_i, and becomes a
//! predecessor of w_{j+1}, whose predecessors are w_j and every upper-level word ending at w_j
//! (at most one per level). Words are built as soon as their last word closes, not when the next
//! one does: the words and predecessor lists are Algorithm 2's, only known one word earlier.
//! Which w_i is the `multi_level` setting:
//! - `paper` (Algorithm 2 as written): for each level l ≥ 1, i = j − l − 1 when w_i.D = w_j.D.
//! - `boundaries` (default): i is the last earlier word of w_j's class, provided every word
//!   between differs from it; the word's level is the depth of the bump, the largest class
//!   distance between D and a word in between (at most 2·depth + 1 words in between).
//!
//! Why `boundaries`: the paper's intent is an alternative word for a bump that crosses one, two
//! or three class boundaries. Densities change smoothly, so a door that lifts Ψ across two class
//! boundaries makes the symmetric `A B C B A`: Algorithm 2 as written files it under level 3
//! (three replaced words) and level 2 (`A x y A`, an even number of words in between) is almost
//! never built, so the 3-level configuration found exactly the pairs of the 2-level one. Counting
//! the boundaries crossed puts `A B A` at level 1, `A B C B A` at level 2 and `A B C D C B A` at
//! level 3, so each level adds the words of deeper bumps that lower levels cannot correct.

use super::options::{MultiLevelRule, PsiWindowStatistic};
use super::types::{DensityObservation, Observation, WordRef};
use crate::geom::wrap_angle;

/// Density class of Ψ among `classes` uniform classes whose boundaries are shifted down by
/// `offset` of a class (`WordOptions::class_offset`, 0 by default): min(floor(classes·Ψ +
/// offset), classes − 1) (NaN gives class 0). The one rule, for the word builder and for the
/// front end (which reads the wide density only in the top class).
pub fn density_class(psi: f64, classes: usize, offset: f64) -> u8 {
    let c = (psi * classes as f64 + offset).floor();
    (c.max(0.0) as usize).min(classes.max(1) - 1) as u8
}

/// Arena index of a word (across levels).
pub type WordId = u32;

/// Highest number of word levels (L = 0..3).
pub const MAX_LEVELS: usize = 4;

/// One word of some level.
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    pub level: usize,
    /// Position in its level's list.
    pub index: usize,
    /// D: density class.
    pub class: u8,
    /// S: observation count.
    pub size: usize,
    /// A: heading change, degrees in (−180, 180].
    pub angle_deg: f64,
    /// How far A may be off because the positions it is measured from were interpolated
    /// between sparse scans, degrees (`word_angle_slack_deg`; 0 with dense scans).
    pub angle_slack_deg: f64,
    /// How far S may be off because its ends fall inside long steps between sparse scans, in
    /// observations: the mean, over its first and last observation, of the other observations
    /// their scan step made ([`DensityObservation::scan_step_observations`] − 1); 0 with a scan
    /// per observation or denser (`MatcherOptions::reverse_sampling_slack`).
    pub sampling_slack_obs: f64,
    /// Index (in the back end's observation list) of the first observation; a word's observations
    /// are consecutive.
    pub first_obs: usize,
    pub run: usize,
    /// Level-0 indices of the first and last level-0 word it spans.
    pub l0_first: usize,
    pub l0_last: usize,
    /// Odometric travel at its first and last observation, metres.
    pub start_travel_m: f64,
    pub end_travel_m: f64,
    preds: [WordId; MAX_LEVELS],
    n_preds: u8,
}

impl Word {
    /// Observation indices of the word.
    pub fn obs_range(&self) -> std::ops::Range<usize> {
        self.first_obs..self.first_obs + self.size
    }

    /// Arena ids of its predecessors (at most one per level).
    pub fn pred_ids(&self) -> &[WordId] {
        &self.preds[..self.n_preds as usize]
    }

    pub fn word_ref(&self) -> WordRef {
        WordRef {
            level: self.level,
            index: self.index,
        }
    }
}

/// A = angle(median→last) − angle(first→median), degrees, wrapped to (−180, 180].
pub fn word_angle_deg(obs: &[Observation]) -> f64 {
    if obs.is_empty() {
        return 0.0;
    }
    let first = obs[0].odom_pose.0;
    let med = obs[(obs.len() - 1) / 2].odom_pose.0;
    let last = obs[obs.len() - 1].odom_pose.0;
    let a2 = (last.y - med.y).atan2(last.x - med.x);
    let a1 = (med.y - first.y).atan2(med.x - first.x);
    wrap_angle(a2 - a1).to_degrees()
}

/// How far [`word_angle_deg`] may move when each of the first, median and last observation's
/// positions may lie up to its slack (`slack_m`, [`DensityObservation::position_slack_m`]) off
/// the path: each chord's direction by atan((slack at its ends) / its length), degrees; 0 when
/// every slack is 0.
pub fn word_angle_slack_deg(obs: &[Observation], slack_m: &[f64]) -> f64 {
    if obs.is_empty() {
        return 0.0;
    }
    let (i0, im, i1) = (0, (obs.len() - 1) / 2, obs.len() - 1);
    let chord = |a: usize, b: usize| {
        let s = slack_m[a] + slack_m[b];
        if s <= 0.0 {
            return 0.0;
        }
        let (pa, pb) = (obs[a].odom_pose.0, obs[b].odom_pose.0);
        s.atan2((pb.x - pa.x).hypot(pb.y - pa.y))
    };
    (chord(i0, im) + chord(im, i1)).to_degrees()
}

/// [`Word::sampling_slack_obs`] of a word whose first and last observations were made by scan
/// steps of `first` and `last` observations.
pub fn word_sampling_slack_obs(first: u32, last: u32) -> f64 {
    f64::from(first.saturating_sub(1) + last.saturating_sub(1)) / 2.0
}

#[derive(Clone, Copy, Debug)]
struct Run {
    class: u8,
    start: usize,
    len: usize,
}

/// The online word builder: observations in, words of every level out.
#[derive(Clone, Debug)]
pub struct WordLevels {
    classes: usize,
    /// Classes added above the top class for open space, by the wide density Φ (0: none).
    wide_classes: usize,
    /// How far the class boundaries are shifted down, in classes (`WordOptions::class_offset`).
    class_offset: f64,
    min_word_size: usize,
    levels: usize,
    rule: MultiLevelRule,
    /// Half the centred Ψ window (`WordOptions::psi_window`): 0 classifies each observation as
    /// it comes.
    psi_half_window: usize,
    psi_statistic: PsiWindowStatistic,
    /// Wide density Φ of the observations not classified yet (at most a half window of them),
    /// oldest first: only the class needs it.
    pending_wide: std::collections::VecDeque<f64>,
    observations: Vec<Observation>,
    /// Ψ of each observation, contiguous for the alignment.
    psi: Vec<f64>,
    /// Lateral moment of each observation ([`DensityObservation::lateral_moment`]).
    lateral_moments: Vec<f64>,
    /// [`DensityObservation::position_slack_m`] of each observation.
    position_slack_m: Vec<f64>,
    /// [`DensityObservation::scan_step_observations`] of each observation.
    scan_step_observations: Vec<u32>,
    /// Index of the first observation of each run.
    run_starts: Vec<usize>,
    obs_class: Vec<u8>,
    words: Vec<Word>,
    by_level: [Vec<WordId>; MAX_LEVELS],
    open: Option<Run>,
    pending: Option<Run>,
    run: usize,
    /// Level-0 index of the first word of the current run.
    run_first_l0: usize,
    /// Predecessors of the next level-0 word: the last level-0 word and upper words ending at it.
    next_preds: Vec<WordId>,
}

impl WordLevels {
    /// A builder with `classes` uniform classes, minimum word size t_o and words up to level
    /// `levels − 1` (1..=4), upper levels built by the paper's Algorithm 2 as written.
    pub fn new(classes: usize, min_word_size: usize, levels: usize) -> Self {
        Self::with_rule(classes, min_word_size, levels, MultiLevelRule::Paper)
    }

    /// Like [`WordLevels::new`], with upper levels built by `rule`.
    pub fn with_rule(
        classes: usize,
        min_word_size: usize,
        levels: usize,
        rule: MultiLevelRule,
    ) -> Self {
        WordLevels {
            classes: classes.clamp(1, 255),
            wide_classes: 0,
            class_offset: 0.0,
            min_word_size: min_word_size.max(1),
            levels: levels.clamp(1, MAX_LEVELS),
            rule,
            psi_half_window: 0,
            psi_statistic: PsiWindowStatistic::Median,
            pending_wide: std::collections::VecDeque::new(),
            observations: Vec::new(),
            psi: Vec::new(),
            lateral_moments: Vec::new(),
            position_slack_m: Vec::new(),
            scan_step_observations: Vec::new(),
            run_starts: vec![0],
            obs_class: Vec::new(),
            words: Vec::new(),
            by_level: Default::default(),
            open: None,
            pending: None,
            run: 0,
            run_first_l0: 0,
            next_preds: Vec::new(),
        }
    }

    /// This builder with `wide_classes` classes above Ψ's top class for open space, read from
    /// the wide density Φ (`WordOptions::wide_classes`; 0: none).
    pub fn with_wide_classes(mut self, wide_classes: usize) -> Self {
        self.wide_classes = wide_classes.min(256 - self.classes);
        self
    }

    /// This builder classifying each observation by the `statistic` of Ψ over a centred window
    /// of `window` observations (`WordOptions::psi_window`, odd; 1: off), cut at the ends of a
    /// run; an observation's class is known, and words close, `window / 2` observations later.
    pub fn with_psi_window(mut self, window: usize, statistic: PsiWindowStatistic) -> Self {
        self.psi_half_window = window / 2;
        self.psi_statistic = statistic;
        self
    }

    /// Class of observation `j` (of wide density `wide_density`) from the Ψ window around it,
    /// cut at the run's start and at the last observation so far (the same rule at both ends,
    /// so reversing a run reverses its classes).
    fn windowed_class(&self, j: usize, wide_density: f64) -> u8 {
        let k = self.psi_half_window;
        let run_start = self.run_starts[self.run];
        let lo = j.saturating_sub(k).max(run_start);
        let hi = (j + k + 1).min(self.psi.len());
        let psi = match self.psi_statistic {
            PsiWindowStatistic::Mean => self.psi[lo..hi].iter().sum::<f64>() / (hi - lo) as f64,
            PsiWindowStatistic::Median => {
                let mut w = self.psi[lo..hi].to_vec();
                w.sort_by(f64::total_cmp);
                let n = w.len();
                (w[(n - 1) / 2] + w[n / 2]) / 2.0
            }
        };
        self.class_of_observation(psi, wide_density)
    }

    /// Classifies every observation whose window is complete (all of them when `flush`, at the
    /// end of a run) and feeds them to the word builder; returns the words they closed.
    fn classify_due(&mut self, flush: bool) -> Vec<WordId> {
        let mut closed = Vec::new();
        let lag = if flush { 0 } else { self.psi_half_window };
        while self.obs_class.len() + lag < self.observations.len() {
            let j = self.obs_class.len();
            // One Φ is queued per observation pushed and not yet classified (this loop's bound).
            let wide = self.pending_wide.pop_front().unwrap_or(f64::NAN);
            let q = if self.psi_half_window == 0 {
                self.class_of_observation(self.psi[j], wide)
            } else {
                self.windowed_class(j, wide)
            };
            self.obs_class.push(q);
            closed.extend(self.step(j, q));
        }
        closed
    }

    /// How many classes an observation may have: the density classes and the wide ones.
    pub fn class_count(&self) -> usize {
        self.classes + self.wide_classes
    }

    /// Density class of Ψ: min(floor(classes·Ψ + class_offset), classes − 1) (NaN gives 0).
    pub fn class_of(&self, psi: f64) -> u8 {
        density_class(psi, self.classes, self.class_offset)
    }

    /// Shifts the class boundaries down by `offset` of a class (`WordOptions::class_offset`).
    pub fn with_class_offset(mut self, offset: f64) -> Self {
        self.class_offset = offset;
        self
    }

    /// Class of an observation: [`Self::class_of`] its Ψ; in the top class, open space (at
    /// least half the wide disc seen free, Φ ≥ ½) takes one of the `wide_classes` classes above
    /// it, by uniform steps of Φ over [½, 1].
    pub fn class_of_observation(&self, psi: f64, wide_density: f64) -> u8 {
        let q = self.class_of(psi);
        if self.wide_classes == 0
            || usize::from(q) + 1 < self.classes
            || wide_density.is_nan()
            || wide_density < 0.5
        {
            return q;
        }
        let w = ((2.0 * wide_density - 1.0) * self.wide_classes as f64).floor();
        let extra = (w.max(0.0) as usize).min(self.wide_classes - 1);
        (usize::from(q) + 1 + extra) as u8
    }

    /// Adds one observation; returns the ids of the words it closed (level 0 first).
    pub fn push(&mut self, obs: &DensityObservation) -> Vec<WordId> {
        self.observations.push(obs.observation);
        self.psi.push(obs.psi);
        self.pending_wide.push_back(obs.wide_density);
        self.lateral_moments.push(obs.lateral_moment);
        self.position_slack_m.push(obs.position_slack_m);
        self.scan_step_observations.push(obs.scan_step_observations);
        self.classify_due(false)
    }

    /// Algorithm 1's step for observation `i` of class `q`; returns the words it closed.
    fn step(&mut self, i: usize, q: u8) -> Vec<WordId> {
        let Some(mut open) = self.open else {
            self.open = Some(Run {
                class: q,
                start: i,
                len: 1,
            });
            return Vec::new();
        };
        let mut closed = Vec::new();
        if q == open.class {
            if let Some(p) = self.pending.take() {
                open.len += p.len;
            }
            open.len += 1;
        } else {
            let mut pending = match self.pending.take() {
                Some(mut p) if p.class == q => {
                    p.len += 1;
                    p
                }
                Some(p) => {
                    open.len += p.len;
                    Run {
                        class: q,
                        start: i,
                        len: 1,
                    }
                }
                None => Run {
                    class: q,
                    start: i,
                    len: 1,
                },
            };
            if pending.len >= self.min_word_size {
                if open.len < self.min_word_size {
                    // The short first word of a run joins the word that follows it.
                    pending.start = open.start;
                    pending.len += open.len;
                } else {
                    closed = self.close_word(open);
                }
                open = pending;
            } else {
                self.pending = Some(pending);
            }
        }
        self.open = Some(open);
        closed
    }

    /// Closes the open word of the run (however short); returns the words it closed.
    pub fn finish_run(&mut self) -> Vec<WordId> {
        let mut closed = self.classify_due(true);
        let Some(mut open) = self.open.take() else {
            return closed;
        };
        if let Some(p) = self.pending.take() {
            open.len += p.len;
        }
        closed.extend(self.close_word(open));
        closed
    }

    /// Closes the current run and starts the next one: no word will have a predecessor across.
    /// Does nothing while the current run has no observation (so calling it before every run,
    /// the first included, is fine).
    pub fn start_run(&mut self) -> Vec<WordId> {
        if self.run_range(self.run).is_empty() {
            return Vec::new();
        }
        let next = self.run + 1;
        self.begin_run(next)
    }

    /// Closes the current run and makes `run` (later than the current one) the current run.
    pub fn begin_run(&mut self, run: usize) -> Vec<WordId> {
        let closed = self.finish_run();
        if run <= self.run {
            return closed;
        }
        while self.run_starts.len() <= run {
            self.run_starts.push(self.observations.len());
        }
        self.run = run;
        self.run_first_l0 = self.by_level[0].len();
        self.next_preds.clear();
        closed
    }

    fn make_word(
        &self,
        level: usize,
        class: u8,
        start: usize,
        len: usize,
        l0: (usize, usize),
    ) -> Word {
        let obs = &self.observations[start..start + len];
        Word {
            level,
            index: self.by_level[level].len(),
            class,
            size: len,
            angle_deg: word_angle_deg(obs),
            angle_slack_deg: word_angle_slack_deg(obs, &self.position_slack_m[start..start + len]),
            sampling_slack_obs: word_sampling_slack_obs(
                self.scan_step_observations[start],
                self.scan_step_observations[start + len - 1],
            ),
            first_obs: start,
            run: self.run,
            l0_first: l0.0,
            l0_last: l0.1,
            start_travel_m: obs[0].travel_m,
            end_travel_m: obs[len - 1].travel_m,
            preds: [0; MAX_LEVELS],
            n_preds: 0,
        }
    }

    fn add(&mut self, mut word: Word, preds: &[WordId]) -> WordId {
        for &p in preds.iter().take(MAX_LEVELS) {
            word.preds[word.n_preds as usize] = p;
            word.n_preds += 1;
        }
        let id = self.words.len() as WordId;
        self.by_level[word.level].push(id);
        self.words.push(word);
        id
    }

    fn close_word(&mut self, run: Run) -> Vec<WordId> {
        let j = self.by_level[0].len();
        let w = self.make_word(0, run.class, run.start, run.len, (j, j));
        let preds = std::mem::take(&mut self.next_preds);
        let id = self.add(w, &preds);
        let mut closed = vec![id];
        let mut next_preds = vec![id];
        let fusions = match self.rule {
            MultiLevelRule::Paper => self.paper_fusions(j, run.class),
            MultiLevelRule::Boundaries => self.bump_fusion(j, run.class).into_iter().collect(),
        };
        for (l, i) in fusions {
            let first = &self.words[self.by_level[0][i] as usize];
            let start = first.first_obs;
            let len = run.start + run.len - start;
            let first_preds: Vec<WordId> = first.pred_ids().to_vec();
            let w = self.make_word(l, first.class, start, len, (i, j));
            let uid = self.add(w, &first_preds);
            closed.push(uid);
            next_preds.push(uid);
        }
        self.next_preds = next_preds;
        closed
    }

    /// Algorithm 2 as written: (level l, first level-0 word j − l − 1) for each level whose first
    /// word has the class of the closing word j.
    fn paper_fusions(&self, j: usize, class: u8) -> Vec<(usize, usize)> {
        (1..self.levels)
            .take_while(|&l| j > self.run_first_l0 + l)
            .map(|l| (l, j - l - 1))
            .filter(|&(_, i)| self.words[self.by_level[0][i] as usize].class == class)
            .collect()
    }

    /// The bump closed by level-0 word j: (its depth as the level, its first level-0 word), when
    /// the last earlier word of j's class in the run is separated from j only by words of other
    /// classes, at most 2·depth + 1 of them, and the depth is a level being built.
    fn bump_fusion(&self, j: usize, class: u8) -> Option<(usize, usize)> {
        let max_between = 2 * (self.levels - 1) + 1;
        let mut depth = 0usize;
        for i in (self.run_first_l0..j).rev() {
            let c = self.words[self.by_level[0][i] as usize].class;
            if c == class {
                let between = j - i - 1;
                let ok = depth >= 1 && depth < self.levels && between <= 2 * depth + 1;
                return ok.then_some((depth, i));
            }
            if j - i > max_between {
                return None;
            }
            depth = depth.max(c.abs_diff(class) as usize);
        }
        None
    }

    pub fn observations(&self) -> &[Observation] {
        &self.observations
    }

    /// Ψ of each observation.
    pub fn psi(&self) -> &[f64] {
        &self.psi
    }

    /// Lateral moment of every observation, in order ([`DensityObservation::lateral_moment`]).
    pub fn lateral_moments(&self) -> &[f64] {
        &self.lateral_moments
    }

    /// Observation indices of run `run` (so far).
    pub fn run_range(&self, run: usize) -> std::ops::Range<usize> {
        let lo = self
            .run_starts
            .get(run)
            .copied()
            .unwrap_or(self.observations.len());
        let hi = self
            .run_starts
            .get(run + 1)
            .copied()
            .unwrap_or(self.observations.len());
        lo..hi
    }

    /// Density class of each observation.
    pub fn observation_classes(&self) -> &[u8] {
        &self.obs_class
    }

    /// Every word, in creation order (arena ids).
    pub fn all_words(&self) -> &[Word] {
        &self.words
    }

    pub fn word(&self, id: WordId) -> &Word {
        &self.words[id as usize]
    }

    /// Words of `level`, in order (empty for levels not built).
    pub fn level(&self, level: usize) -> impl Iterator<Item = &Word> + '_ {
        self.by_level
            .get(level)
            .into_iter()
            .flatten()
            .map(move |&id| &self.words[id as usize])
    }

    /// The word a [`WordRef`] names.
    pub fn get(&self, r: WordRef) -> Option<&Word> {
        let id = *self.by_level.get(r.level)?.get(r.index)?;
        Some(&self.words[id as usize])
    }

    /// Predecessors of a word, as references.
    pub fn predecessors(&self, r: WordRef) -> Vec<WordRef> {
        self.get(r)
            .map(|w| {
                w.pred_ids()
                    .iter()
                    .map(|&p| self.words[p as usize].word_ref())
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Index of the current run (0 for the first).
    pub fn run(&self) -> usize {
        self.run
    }

    /// Number of word levels built (1..=4).
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// The most level-0 words one word of any level can span (the bound each rule enforces:
    /// `paper` fuses j − l − 1 … j, l ≤ levels − 1; `boundaries` at most 2·(levels − 1) + 1
    /// words between the two ends of a bump).
    pub fn max_span_l0(&self) -> usize {
        match self.rule {
            MultiLevelRule::Paper => self.levels + 1,
            MultiLevelRule::Boundaries => 2 * self.levels + 1,
        }
    }

    /// Level-0 words closed so far.
    pub fn closed_l0(&self) -> usize {
        self.by_level[0].len()
    }

    /// Level-0 word `i` (its index in level 0), if closed.
    pub fn level0(&self, i: usize) -> Option<&Word> {
        let id = *self.by_level[0].get(i)?;
        Some(&self.words[id as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{OdomPose, Pose2};

    /// Open space (the top class, Φ ≥ ½) takes the classes above the top one, by Φ; no other
    /// class moves, and without wide classes nothing does.
    #[test]
    fn only_the_top_class_in_open_space_is_split_by_the_wide_density() {
        let w = WordLevels::new(8, 5, 1).with_wide_classes(4);
        assert_eq!(w.class_count(), 12);
        assert_eq!(w.class_of_observation(0.5, 1.0), 4, "below the top class");
        assert_eq!(w.class_of_observation(0.9, 0.2), 7, "a room: Φ under ½");
        assert_eq!(w.class_of_observation(0.9, f64::NAN), 7);
        assert_eq!(w.class_of_observation(1.0, 0.5), 8);
        assert_eq!(w.class_of_observation(1.0, 0.6), 8);
        assert_eq!(w.class_of_observation(1.0, 0.7), 9);
        assert_eq!(w.class_of_observation(0.9, 0.8), 10);
        assert_eq!(w.class_of_observation(1.0, 1.0), 11);
        let plain = WordLevels::new(8, 5, 1);
        assert_eq!(plain.class_of_observation(1.0, 1.0), 7);
    }

    /// Classes of `psi` read through a builder with a centred Ψ window, and its level-0 word
    /// sizes.
    fn windowed(psi: &[f64], window: usize, stat: PsiWindowStatistic) -> (Vec<u8>, Vec<usize>) {
        let mut w = WordLevels::new(8, 3, 1).with_psi_window(window, stat);
        let mut closed = 0;
        for (i, &p) in psi.iter().enumerate() {
            let observation =
                Observation::new(i, 0, i, OdomPose(Pose2::new(i as f64, 0.0, 0.0)), i as f64);
            closed += w
                .push(&DensityObservation {
                    observation,
                    psi: p,
                    lateral_moment: 0.0,
                    position_slack_m: 0.0,
                    scan_step_observations: 1,
                    wide_density: f64::NAN,
                })
                .len();
        }
        closed += w.finish_run().len();
        let sizes: Vec<usize> = w.level(0).map(|x| x.size).collect();
        assert_eq!(closed, sizes.len());
        assert_eq!(
            sizes.iter().sum::<usize>(),
            psi.len(),
            "words cover every observation"
        );
        (w.observation_classes().to_vec(), sizes)
    }

    /// `class_offset` moves every boundary down by that share of a class, the top class
    /// included, and nothing past the top class; `WordLevels` reads the same rule.
    #[test]
    fn a_class_offset_shifts_every_boundary_down_by_that_share_of_a_class() {
        // 8 classes: boundaries at 0.125·k, with 0.5 at 0.125·k − 0.0625.
        assert_eq!(density_class(0.49, 8, 0.0), 3);
        assert_eq!(density_class(0.49, 8, 0.5), 4);
        assert_eq!(density_class(0.43, 8, 0.5), 3);
        assert_eq!(density_class(0.05, 8, 0.5), 0);
        assert_eq!(density_class(0.06, 8, 0.5), 0);
        assert_eq!(density_class(0.07, 8, 0.5), 1);
        // The top class reaches down to 0.8125; nothing goes past it.
        assert_eq!(density_class(0.82, 8, 0.5), 7);
        assert_eq!(density_class(1.0, 8, 0.5), 7);
        let w = WordLevels::new(8, 5, 1).with_class_offset(0.5);
        assert_eq!(w.class_of(0.49), 4);
    }

    /// A centred Ψ window is the same driven either way: the reversed Ψ sequence gives the
    /// reversed classes (window cut at both ends of the run alike); it removes a flicker across
    /// a class threshold, and a window of one observation is today's per-observation rule.
    #[test]
    fn a_centred_psi_window_gives_reversed_classes_for_reversed_psi() {
        let psi: Vec<f64> = (0..60)
            .map(|i| 0.3 + 0.15 * (i as f64 / 9.0).sin() + if i % 3 == 0 { 0.06 } else { -0.02 })
            .collect();
        let reversed: Vec<f64> = psi.iter().rev().copied().collect();
        for stat in [PsiWindowStatistic::Median, PsiWindowStatistic::Mean] {
            for window in [3, 5, 7] {
                let (fwd, _) = windowed(&psi, window, stat);
                let (mut back, _) = windowed(&reversed, window, stat);
                back.reverse();
                assert_eq!(fwd, back, "{stat:?} over {window}");
            }
        }
        let own: Vec<u8> = psi.iter().map(|&p| density_class(p, 8, 0.0)).collect();
        assert_eq!(windowed(&psi, 1, PsiWindowStatistic::Median).0, own);
        let flicker = [
            0.49, 0.49, 0.51, 0.49, 0.49, 0.51, 0.49, 0.49, 0.51, 0.49, 0.49,
        ];
        let (classes, sizes) = windowed(&flicker, 3, PsiWindowStatistic::Median);
        assert!(classes.iter().all(|&c| c == 3), "{classes:?}");
        assert_eq!(sizes, vec![flicker.len()]);
    }

    fn along(points: &[(f64, f64)]) -> Vec<Observation> {
        (points.iter().enumerate())
            .map(|(i, &(x, y))| {
                Observation::new(i, 0, i, OdomPose(Pose2::new(x, y, 0.0)), i as f64)
            })
            .collect()
    }

    /// A word's sampling slack is the mean, over its first and last observation, of the other
    /// observations their scan step made; 0 where each scan made one (or the count is unknown).
    #[test]
    fn sampling_slack_reads_the_scan_steps_at_a_words_ends() {
        assert_eq!(word_sampling_slack_obs(1, 1), 0.0);
        assert_eq!(word_sampling_slack_obs(0, 1), 0.0);
        assert_eq!(word_sampling_slack_obs(7, 3), 4.0);
        let mut w = WordLevels::new(8, 3, 1);
        // A word of 10 observations of class 1, its first made by a 7-observation step, its
        // middle ones by single scans, its last by a 3-observation step; then class 6.
        let steps = |i: usize| match i {
            0 => 7,
            9 => 3,
            _ => 1,
        };
        for i in 0..20 {
            let pose = OdomPose(Pose2::new(i as f64 * 0.1, 0.0, 0.0));
            let observation = Observation::new(i, 0, i, pose, i as f64 * 0.1);
            w.push(&DensityObservation {
                observation,
                psi: if i < 10 { 0.2 } else { 0.8 },
                lateral_moment: 0.0,
                position_slack_m: 0.0,
                scan_step_observations: steps(i),
                wide_density: f64::NAN,
            });
        }
        let first = w.level(0).next().expect("the first word closed");
        assert_eq!((first.size, first.sampling_slack_obs), (10, 4.0));
    }

    /// A word's angle slack is 0 when no position was interpolated, and grows with the slack
    /// of its first, median and last positions against its chords' lengths.
    #[test]
    fn angle_slack_is_zero_at_scan_poses_and_grows_with_interpolation() {
        let obs = along(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (2.0, 2.0)]);
        assert_eq!(word_angle_slack_deg(&obs, &[0.0; 5]), 0.0);
        let small = word_angle_slack_deg(&obs, &[0.0, 0.0, 0.1, 0.0, 0.0]);
        let large = word_angle_slack_deg(&obs, &[0.0, 0.0, 0.4, 0.0, 0.0]);
        // The median (2, 0) is 2 m from the first and from the last position: its 0.1 m moves
        // each chord by atan(0.1 / 2).
        let chord = 2.0;
        assert!(
            (small - 2.0 * (0.1f64).atan2(chord).to_degrees()).abs() < 1e-9,
            "{small}"
        );
        assert!(large > small);
        // Slack at a position the angle is not measured from does not count.
        assert_eq!(word_angle_slack_deg(&obs, &[0.0, 0.3, 0.0, 0.3, 0.0]), 0.0);
    }
}
