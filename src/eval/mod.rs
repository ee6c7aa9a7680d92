//! Evaluation: ground truth pairs, precision and recall, sweeps and the paper's Table I.
//!
//! The flow is: [`recognize_runs`] feeds the frames of simulated (or logged) runs to a
//! [`PlaceRecognizer`] in order, keeping the ground truth of every frame to itself
//! ([`GroundTruth`]); [`metrics::evaluate`] turns the recognizer's matches into observation pairs
//! and scores them (docs/design.md, Evaluation) through a [`tally::Tally`], which counts each match as it
//! arrives: a [`Recording::streaming`] feeds it while the recognizer runs and keeps no match,
//! forgetting the pairs behind the recognizer's query horizon, so a thousand-lap run is scored
//! in memory that grows with its observations, not its pairs; [`sweep`] repeats this over a
//! grid of thresholds;
//! [`scores`] holds the computed results ([`scores::Report`]) that `report` formats;
//! [`gate`] compares a report with a scenario's `[expect]` block; [`compare`] compares a
//! stress run with a baseline run, paired by seed.

pub mod compare;
pub(crate) mod distribution;
pub mod gate;
mod lap_grid;
pub mod metrics;
pub mod motion;
pub mod observation_status;
pub mod pair_recall;
pub mod pair_set;
pub mod provenance;
pub mod rank_test;
pub mod ranking;
pub mod scores;
pub mod site_tree;
pub mod suite;
pub mod sweep;
pub mod tally;

use crate::clock::Stopwatch;
use crate::geom::{OdomPose, TruePose};
use crate::log::{Frame, LapLog, RunLog};
use crate::place::{Diagnostics, Direction, Match, ObsId, Observation, RejectedCandidate};
use crate::spec::evaluation::EvaluationSpec;
use std::sync::Arc;
pub use tally::SharedTruth;
use tally::{Scope, Tally};

pub use metrics::{Evaluation, Metrics, evaluate, evaluate_by_site_tree};

/// The interface a recognizer implements to be scored lives below `eval` and `baseline` in
/// [`crate::place`]; re-exported here for the evaluation's users.
pub use crate::place::PlaceRecognizer;

/// What the evaluation knows about one lap.
#[derive(Clone, Debug, PartialEq)]
pub struct LapInfo {
    /// 0-based run index within the scenario.
    pub run: usize,
    /// 0-based lap within the run.
    pub lap: usize,
    /// Name of the door configuration during the lap.
    pub door_config: String,
    /// Ids of the doors open during the lap.
    pub open_doors: Vec<String>,
}

impl LapInfo {
    /// What the evaluation keeps of `lap`, of run `run`.
    pub fn of(run: usize, lap: &LapLog) -> Self {
        LapInfo {
            run,
            lap: lap.lap,
            door_config: lap.door_config.clone(),
            open_doors: lap.open_doors.clone(),
        }
    }
}

/// Ground truth of one input frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTruth {
    pub pose: TruePose,
    /// The frame's odometry pose (to carry the truth to observations made away from the frame).
    pub odom: crate::geom::OdomPose,
    /// Index into [`GroundTruth::laps`].
    pub lap_slot: usize,
    /// Distance along the true path from the first frame, metres (a run boundary adds none;
    /// `eval::pair_recall::true_travel_m`).
    pub travel_m: f64,
}

/// Ground truth of every frame fed to a recognizer, indexed by the global input index
/// (`Observation::frame_id`). Built beside the recognizer; never handed to it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroundTruth {
    pub frames: Vec<FrameTruth>,
    pub laps: Vec<LapInfo>,
}

impl GroundTruth {
    /// The truth of the frames of `runs`, in the order [`recognize_runs`] feeds them.
    pub fn from_runs(runs: &[RunLog]) -> Self {
        let mut gt = GroundTruth::default();
        for run in runs {
            for lap in &run.laps {
                gt.add_lap(run.run, lap);
            }
        }
        gt
    }

    /// Appends one lap: its description and the true and odometry pose of each of its frames.
    pub fn push_lap(
        &mut self,
        info: LapInfo,
        frames: impl IntoIterator<Item = (TruePose, OdomPose)>,
    ) {
        self.start_lap(info);
        for (pose, odom) in frames {
            self.push_frame(pose, odom);
        }
    }

    /// Starts a lap whose frames follow ([`Self::push_frame`]).
    pub fn start_lap(&mut self, info: LapInfo) {
        self.laps.push(info);
    }

    /// Appends the truth of `frames`, the next frames of the last lap started; returns the
    /// input index of the first (the index the recognizer is handed back).
    pub fn push_frames(&mut self, frames: &[Frame]) -> usize {
        let first = self.frames.len();
        for f in frames {
            self.push_frame(f.truth, f.odom);
        }
        first
    }

    /// Appends one frame of the last lap started.
    pub fn push_frame(&mut self, pose: TruePose, odom: OdomPose) {
        let lap_slot = self.laps.len().saturating_sub(1);
        let run_of = |slot: usize| self.laps.get(slot).map(|l| l.run);
        let travel_m = match self.frames.last() {
            Some(prev) if run_of(prev.lap_slot) == run_of(lap_slot) => {
                prev.travel_m + prev.pose.0.distance(&pose.0)
            }
            Some(prev) => prev.travel_m,
            None => 0.0,
        };
        self.frames.push(FrameTruth {
            pose,
            odom,
            lap_slot,
            travel_m,
        });
    }

    /// Appends the truth of one lap of run `run` (laps in the order they are fed).
    pub fn add_lap(&mut self, run: usize, lap: &LapLog) {
        let info = LapInfo::of(run, lap);
        self.push_lap(info, lap.frames.iter().map(|f| (f.truth, f.odom)));
    }

    /// Truth of input frame `frame_id`, if it exists.
    pub fn frame(&self, frame_id: usize) -> Option<&FrameTruth> {
        self.frames.get(frame_id)
    }

    /// True pose of an observation: its frame's truth moved by the observation's odometric offset
    /// from the frame (observations interpolated back along a long step between scans lie up to
    /// a few metres before the frame that made them).
    pub fn observation_pose(&self, obs: &crate::place::Observation) -> Option<TruePose> {
        let f = self.frame(obs.frame_id)?;
        let offset = f.odom.0.between(&obs.odom_pose.0);
        Some(TruePose(f.pose.0.compose(&offset)))
    }

    /// The lap of input frame `frame_id`.
    pub fn lap_of(&self, frame_id: usize) -> Option<&LapInfo> {
        self.frame(frame_id).map(|f| &self.laps[f.lap_slot])
    }

    /// Names of the door configurations in order of first appearance.
    pub fn door_configs(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for l in &self.laps {
            if !names.contains(&l.door_config) {
                names.push(l.door_config.clone());
            }
        }
        names
    }
}

/// The outcome of feeding runs to a recognizer.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Recognition {
    /// The recognizer's name.
    pub name: String,
    /// Every observation, as the recognizer reported them at the end; empty when the matches
    /// were scored as they arrived (`evaluation` is set; nothing needs them after).
    pub observations: Vec<Observation>,
    /// Every match, in the order found.
    pub matches: Vec<Match>,
    /// CPU seconds of the thread that fed the recognizer, spent inside `start_run`, `push` and
    /// `finish` (truth bookkeeping and scoring excluded; [`crate::clock`]).
    pub seconds: f64,
    /// Wall-clock seconds of the same calls (longer than `seconds` when other work shares the
    /// cores: seeds or level configurations run in parallel).
    pub wall_seconds: f64,
    /// CPU seconds spent scoring the matches: as they arrived, the end of the scoring, or the
    /// whole of it when scored after the recognition ([`scores::Scores::measure`] adds its own).
    pub score_seconds: f64,
    /// Number of laps fed.
    pub laps: usize,
    /// Truth of every frame fed, by input index (shared by the recognitions of one input).
    pub truth: Arc<GroundTruth>,
    /// What the recognizer saw (to say why nothing matched), when it tells.
    pub diagnostics: Option<Arc<dyn Diagnostics>>,
    /// Seconds the recognizer spent on each lap's frames, in the order fed: CPU time of the
    /// thread that fed them (so a loaded machine does not blur how the work grows with history);
    /// empty when not recorded.
    pub lap_seconds: Vec<f64>,
    /// The evaluation, with the rules it was made with, when the matches were scored as they
    /// arrived ([`Recording::streaming`]; `matches` is then empty).
    pub evaluation: Option<(EvaluationSpec, Evaluation)>,
    /// `(pairs, correct pairs)` this recognition found that the level configuration with one
    /// level fewer did not, when counted as the matches arrived (`Report::set_level_gains`).
    pub level_gain: Option<(usize, usize)>,
    /// The candidates the recognizer's verification turned down (the first 10,000, as its
    /// diagnostics sample them), with the truth of each one's observation pair: whether
    /// verification turned down true revisits or look-alikes.
    pub rejected: Vec<RejectedTruth>,
    /// Each query observation's best-scoring answer, when the matches were scored as they
    /// arrived ([`Recording::streaming`]; otherwise [`scores::Scores::measure`] ranks `matches`),
    /// and the observations made.
    pub ranking: Option<(ranking::Ranking, usize)>,
}

/// A candidate the recognizer's verification turned down, with the true poses of the
/// observation pair it was sampled at (`recognizer::RejectedCandidate`) and of the pair at its
/// oldest end when it spans a stretch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RejectedTruth {
    /// The query observation's position among the recognition's observations (scoring order).
    pub query_index: usize,
    pub query: TruePose,
    pub past: TruePose,
    pub direction: Direction,
    /// The check that turned it down ([`Diagnostics::checks`]).
    pub check: usize,
    /// The true poses of the pair at the candidate's oldest end, when the recognizer gave one.
    pub oldest: Option<(TruePose, TruePose)>,
}

impl RejectedTruth {
    /// Whether the candidate is a true revisit with `spec`'s rules: its pair (and the pair at
    /// its oldest end, when it has one) within `tp_radius_m`, facing as the candidate's
    /// direction claims. A chain whose newest pair is the same place but whose oldest is not
    /// (the robot reached one place from two corridors) is a look-alike: accepted, it would
    /// claim false pairs.
    pub fn is_right(&self, spec: &EvaluationSpec) -> bool {
        let right = |(q, p): (TruePose, TruePose)| {
            let (q, p) = (q.0, p.0);
            q.distance(&p) <= spec.tp_radius_m
                && pair_recall::Facing::of(self.direction).agrees(
                    q.theta,
                    p.theta,
                    spec.heading_tolerance_deg.to_radians(),
                )
        };
        right((self.query, self.past)) && self.oldest.is_none_or(right)
    }
}

/// The truth of the rejected candidates `rejected`, whose observations are among
/// `observations` (those without truth are left out).
fn rejected_truth(
    rejected: &[RejectedCandidate],
    observations: &[Observation],
    truth: &GroundTruth,
) -> Vec<RejectedTruth> {
    // The recognizer's own ids are the observations' indices; anything else is looked up.
    let by_index = observations.iter().enumerate().all(|(i, o)| o.id == i);
    let map: std::collections::HashMap<ObsId, usize> = if by_index {
        Default::default()
    } else {
        observations
            .iter()
            .enumerate()
            .map(|(i, o)| (o.id, i))
            .collect()
    };
    let index = |id: ObsId| {
        if by_index {
            (id < observations.len()).then_some(id)
        } else {
            map.get(&id).copied()
        }
    };
    rejected
        .iter()
        .filter_map(|r| {
            let pose = |id: ObsId| truth.observation_pose(&observations[index(id)?]);
            let oldest = match r.oldest {
                Some((q, p)) => Some((pose(q)?, pose(p)?)),
                None => None,
            };
            Some(RejectedTruth {
                query_index: index(r.query)?,
                query: pose(r.query)?,
                past: pose(r.past)?,
                direction: r.direction,
                check: r.check,
                oldest,
            })
        })
        .collect()
}

impl Recognition {
    /// The recognition `name` made: its `observations` and `matches` over `laps` laps of the
    /// input whose truth is `truth`; untimed, scored after (no streamed evaluation), without
    /// diagnostics or rejected candidates. Set the other fields after, as the recognition had
    /// them (the one way to build one: the type is `#[non_exhaustive]`).
    pub fn new(
        name: impl Into<String>,
        observations: Vec<Observation>,
        matches: Vec<Match>,
        laps: usize,
        truth: Arc<GroundTruth>,
    ) -> Self {
        Recognition {
            name: name.into(),
            observations,
            matches,
            seconds: 0.0,
            wall_seconds: 0.0,
            score_seconds: 0.0,
            laps,
            truth,
            diagnostics: None,
            lap_seconds: Vec::new(),
            evaluation: None,
            level_gain: None,
            rejected: Vec::new(),
            ranking: None,
        }
    }

    /// Recognition CPU seconds per lap (0 when no lap was fed).
    pub fn seconds_per_lap(&self) -> f64 {
        self.seconds / self.laps.max(1) as f64
    }

    /// Recognition wall-clock seconds per lap (0 when no lap was fed).
    pub fn wall_seconds_per_lap(&self) -> f64 {
        self.wall_seconds / self.laps.max(1) as f64
    }
}

/// Feeds every frame of `runs` to `rec` in order (calling `start_run` before each run), with
/// input indices counted across runs, and times the recognizer.
///
/// Scoring a recognizer of one's own through the public API: runs (here two laps round a
/// circle, made by hand; `experiment::simulate` or `io::real_log` make real ones), the
/// recognition, and [`scores::Scores::of`] with the rules of an `[evaluation]` table. The
/// recognizer sees only odometry and scans; the truth in the runs is the scorer's.
///
/// ```
/// use placewords::eval::{recognize_runs, scores::Scores};
/// use placewords::geom::{OdomPose, Pose2, TruePose};
/// use placewords::log::{Frame, LapLog, RunLog};
/// use placewords::place::{FrameId, Match, Observation, PlaceRecognizer};
/// use placewords::scan::{BeamLayout, Scan};
/// use placewords::spec::evaluation::EvaluationSpec;
///
/// /// Pairs an observation with the first one at least 20 m of odometric travel back whose
/// /// odometry lies within 0.3 m (a toy: it trusts odometry, which a real run's drifts).
/// #[derive(Default)]
/// struct Returns {
///     observations: Vec<Observation>,
///     travel_m: f64,
///     last: Option<Pose2>,
///     runs: usize,
/// }
///
/// impl PlaceRecognizer for Returns {
///     fn start_run(&mut self) -> Vec<Match> {
///         self.runs += 1;
///         self.last = None;
///         Vec::new()
///     }
///     fn push(&mut self, frame_id: FrameId, odom: OdomPose, _scan: &Scan) -> Vec<Match> {
///         self.travel_m += self.last.map_or(0.0, |p| p.distance(&odom.0));
///         self.last = Some(odom.0);
///         let id = self.observations.len();
///         let past = self.observations.iter().find(|o| {
///             self.travel_m - o.travel_m >= 20.0 && o.odom_pose.0.distance(&odom.0) < 0.3
///         });
///         let found = past.map(|o| Match::from_pairs([(id, o.id)], 1.0));
///         let run = self.runs - 1;
///         self.observations.push(Observation::new(id, run, frame_id, odom, self.travel_m));
///         found.into_iter().collect()
///     }
///     fn observations(&self) -> &[Observation] {
///         &self.observations
///     }
///     fn name(&self) -> String {
///         "returns".into()
///     }
/// }
///
/// // One run of two laps round a circle of 5 m radius, a frame every 0.25 m.
/// let layout = BeamLayout::centered(181, std::f64::consts::PI, 30.0, Pose2::IDENTITY);
/// let lap = |lap: usize| LapLog {
///     lap,
///     door_config: "all-closed".into(),
///     open_doors: Vec::new(),
///     frames: (0..126)
///         .map(|i| {
///             let a = i as f64 * 0.05;
///             let pose = Pose2::new(5.0 * a.cos(), 5.0 * a.sin(), a + std::f64::consts::FRAC_PI_2);
///             let time_s = (lap * 126 + i) as f64 * 0.5;
///             let scan = Scan { layout: layout.clone(), ranges_m: vec![30.0; 181], time_s };
///             Frame { time_s, odom: OdomPose(pose), truth: TruePose(pose), scan }
///         })
///         .collect(),
/// };
/// let runs = vec![RunLog { run: 0, laps: vec![lap(0), lap(1)] }];
///
/// let recognition = recognize_runs(&mut Returns::default(), &runs);
/// let scores = Scores::of(&recognition, &EvaluationSpec::default());
/// // Every pair is at the right place, and nearly every observation with a revisit is found.
/// assert_eq!(scores.precision, 1.0);
/// assert!(scores.recall > 0.9, "recall {}", scores.recall);
/// assert!(scores.recognize_seconds_per_lap >= 0.0);
/// ```
pub fn recognize_runs(rec: &mut dyn PlaceRecognizer, runs: &[RunLog]) -> Recognition {
    recognize_runs_with_progress(rec, runs, &mut |_| {})
}

/// [`recognize_runs`] with a callback after every lap (argument: laps done so far), for
/// progress bars.
pub fn recognize_runs_with_progress(
    rec: &mut dyn PlaceRecognizer,
    runs: &[RunLog],
    on_lap: &mut dyn FnMut(usize),
) -> Recognition {
    let mut truth = GroundTruth::default();
    let mut recording = Recording::default();
    for run in runs {
        recording.start_run(rec, &truth);
        for lap in &run.laps {
            truth.start_lap(LapInfo::of(run.run, lap));
            let first = truth.push_frames(&lap.frames);
            recording.lap(rec, &lap.frames, first, &truth);
            on_lap(recording.laps);
        }
    }
    recording.close(rec, &truth);
    recording.finish(rec, Arc::new(truth))
}

/// A recognition in progress, fed lap by lap or frames at a time (so a caller need not hold
/// every lap's scans): the matches so far and the recognizer's time, in total and per lap. The
/// truth of the frames is the caller's ([`GroundTruth::push_frames`] before each feed), so the
/// recognizers of one input share one copy. [`Recording::streaming`] scores the matches as they
/// arrive instead of keeping them ([`tally`]).
#[derive(Default)]
pub struct Recording {
    matches: Vec<Match>,
    seconds: f64,
    wall_seconds: f64,
    score_seconds: f64,
    laps: usize,
    lap_seconds: Vec<f64>,
    /// CPU seconds of the lap being fed so far.
    lap_so_far: f64,
    /// Scores the matches as they arrive, when streaming.
    tally: Option<(EvaluationSpec, Tally)>,
    /// Ranks each query's answers as they arrive, when streaming.
    ranking: ranking::Ranking,
    level_gain: Option<(usize, usize)>,
    closed: bool,
}

impl Recording {
    /// A recording that scores each match with `spec` as it arrives and keeps none: memory
    /// grows with the observations, not with the pairs (`Recognition::matches` stays empty).
    pub fn streaming(spec: &EvaluationSpec) -> Self {
        Recording {
            tally: Some((spec.clone(), Tally::new(spec, Scope::Full))),
            ..Recording::default()
        }
    }

    /// Keeps (or scores) matches `found`, after the frames and observations they name.
    fn take(&mut self, rec: &dyn PlaceRecognizer, truth: &GroundTruth, found: Vec<Match>) {
        match &mut self.tally {
            Some((_, tally)) => {
                if !found.is_empty() {
                    let w = Stopwatch::start();
                    tally.sync(rec.observations(), truth);
                    for m in &found {
                        tally.add_ranked(m, Some(&mut self.ranking));
                    }
                    self.score_seconds += w.cpu_s();
                }
            }
            None => self.matches.extend(found),
        }
    }

    /// Starts a run (call before each run's first lap, the first run included).
    pub fn start_run(&mut self, rec: &mut dyn PlaceRecognizer, truth: &GroundTruth) {
        let w = Stopwatch::start();
        let found = rec.start_run();
        self.clocked(&w, rec.runs_out_of_process());
        self.take(rec, truth, found);
    }

    /// Feeds every frame of a lap (`truth` holds them from input index `first_id`) and times
    /// it as one lap.
    pub fn lap(
        &mut self,
        rec: &mut dyn PlaceRecognizer,
        frames: &[Frame],
        first_id: usize,
        truth: &GroundTruth,
    ) {
        self.start_lap();
        self.frames(rec, frames, first_id, truth);
        self.end_lap();
    }

    /// Starts a lap whose frames come in pieces ([`Self::frames`]) until [`Self::end_lap`].
    pub fn start_lap(&mut self) {
        self.lap_so_far = 0.0;
    }

    /// Feeds `frames`, the next frames of the lap started, whose truth `truth` already holds
    /// from input index `first_id` on.
    pub fn frames(
        &mut self,
        rec: &mut dyn PlaceRecognizer,
        frames: &[Frame],
        first_id: usize,
        truth: &GroundTruth,
    ) {
        let mut found = Vec::new();
        let w = Stopwatch::start();
        for (i, frame) in frames.iter().enumerate() {
            found.extend(rec.push(first_id + i, frame.odom, &frame.scan));
        }
        // A recognizer in another process works while this thread waits: its time is the
        // wall clock's.
        self.lap_so_far += self.clocked(&w, rec.runs_out_of_process());
        // Scored outside the timing: the recognizer's time is its own.
        self.take(rec, truth, found);
    }

    /// Adds the time since `w` started to the recognizer's; returns its seconds: CPU, or wall
    /// for a recognizer that works in another process (`out_of_process`).
    fn clocked(&mut self, w: &Stopwatch, out_of_process: bool) -> f64 {
        let t = if out_of_process {
            w.wall_s()
        } else {
            w.cpu_s()
        };
        self.seconds += t;
        self.wall_seconds += w.wall_s();
        t
    }

    /// Adds work done for the recognizer outside its own calls to its time (and to the lap's,
    /// inside a lap): CPU seconds `cpu_s`, wall-clock seconds `wall_s`. The harness charges
    /// each level configuration the whole of a density front end it shares with others, as if
    /// it ran alone (`experiment::shared_front`).
    pub fn charge(&mut self, cpu_s: f64, wall_s: f64) {
        self.seconds += cpu_s;
        self.wall_seconds += wall_s;
        self.lap_so_far += cpu_s;
    }

    /// Ends the lap started.
    pub fn end_lap(&mut self) {
        self.lap_seconds.push(self.lap_so_far);
        self.laps += 1;
    }

    /// Laps fed so far.
    pub fn laps(&self) -> usize {
        self.laps
    }

    /// When streaming: forgets the pairs whose query lies before observation `horizon` (no
    /// later match of the recognizer names one, `PlaceRecognizer::query_horizon`).
    pub fn forget_behind(&mut self, horizon: usize) {
        if let Some((_, tally)) = &mut self.tally {
            // Forgetting counts the visit recall of what it forgets: scoring, timed as such.
            let w = Stopwatch::start();
            tally.evict_below(horizon);
            self.score_seconds += w.cpu_s();
        }
    }

    /// When streaming: the distinct pairs held to deduplicate, and those that arrived behind
    /// the horizon (0 for a recognizer that keeps its promise).
    pub fn pairs_held(&self) -> Option<(usize, usize)> {
        self.tally
            .as_ref()
            .map(|(_, t)| (t.pairs_held(), t.late_pairs()))
    }

    /// When streaming: keep the distinct pairs forgotten, to compare level configurations
    /// ([`Self::take_forgotten`]).
    pub fn keep_forgotten(&mut self) {
        if let Some((_, tally)) = &mut self.tally {
            tally.keep_forgotten();
        }
    }

    /// The distinct pairs forgotten since the last call (see [`tally::Tally::take_forgotten`]).
    pub fn take_forgotten(&mut self) -> Vec<u64> {
        self.tally
            .as_mut()
            .map(|(_, t)| t.take_forgotten())
            .unwrap_or_default()
    }

    /// Adds to the level gain: of `here` (this recording's forgotten pairs), those `fewer` (the
    /// configuration with a level fewer) does not hold ([`tally::gain`]).
    pub fn add_level_gain(&mut self, here: &[u64], fewer: &[u64]) {
        let Some((_, tally)) = &self.tally else {
            return;
        };
        let (p, c) = tally::gain(here, fewer, |q, p| tally.within_radius(q, p));
        let g = self.level_gain.get_or_insert((0, 0));
        g.0 += p;
        g.1 += c;
    }

    /// Ends the input: adds the matches closing the last run produced (once).
    pub fn close(&mut self, rec: &mut dyn PlaceRecognizer, truth: &GroundTruth) {
        if self.closed {
            return;
        }
        self.closed = true;
        let w = Stopwatch::start();
        let found = rec.finish();
        self.clocked(&w, rec.runs_out_of_process());
        self.take(rec, truth, found);
    }

    /// Hands over the recognition (scored, when streaming), after [`Self::close`]; `truth` is
    /// the truth of every frame fed.
    pub fn finish(self, rec: &mut dyn PlaceRecognizer, truth: Arc<GroundTruth>) -> Recognition {
        self.end(rec, &truth).finish(truth)
    }

    /// Takes from the recognizer all that [`Ended::finish`] needs (after [`Self::close`]), so
    /// the recognizer can be dropped before the scoring's last count.
    pub fn end(mut self, rec: &mut dyn PlaceRecognizer, truth: &GroundTruth) -> Ended {
        self.close(rec, truth);
        // Scored as they arrived, the observations are not needed again (a long log has
        // millions): the tally keeps what it needs of them.
        let observations = match &mut self.tally {
            Some((_, tally)) => {
                tally.sync(rec.observations(), truth);
                Vec::new()
            }
            None => rec.observations().to_vec(),
        };
        let diagnostics: Option<Arc<dyn Diagnostics>> = rec.diagnostics().map(Arc::from);
        let rejected = diagnostics.as_ref().map_or_else(Vec::new, |d| {
            rejected_truth(d.rejected(), rec.observations(), truth)
        });
        Ended {
            name: rec.name(),
            diagnostics,
            observations,
            rejected,
            recording: self,
        }
    }
}

/// A recording whose recognizer is done ([`Recording::end`]).
pub struct Ended {
    name: String,
    diagnostics: Option<Arc<dyn Diagnostics>>,
    observations: Vec<Observation>,
    rejected: Vec<RejectedTruth>,
    recording: Recording,
}

impl Ended {
    /// The recognition, scored when the recording was streaming.
    pub fn finish(self, truth: Arc<GroundTruth>) -> Recognition {
        self.finish_sharing(truth, &mut SharedTruth::default())
    }

    /// [`Self::finish`], the truth side of the scores shared with the other recognitions of
    /// the same observations ([`SharedTruth`]: level configurations of one experiment).
    pub fn finish_sharing(self, truth: Arc<GroundTruth>, shared: &mut SharedTruth) -> Recognition {
        let r = self.recording;
        let w = Stopwatch::start();
        let observations_made = r.tally.as_ref().map_or(0, |(_, t)| t.observations());
        let evaluation = r.tally.map(|(spec, tally)| {
            let e = tally.finish_sharing(&truth, shared);
            (spec, e)
        });
        let ranking = evaluation
            .is_some()
            .then_some((r.ranking, observations_made));
        let score_seconds = r.score_seconds + w.cpu_s();
        Recognition {
            seconds: r.seconds,
            wall_seconds: r.wall_seconds,
            score_seconds,
            diagnostics: self.diagnostics,
            lap_seconds: r.lap_seconds,
            evaluation,
            level_gain: r.level_gain,
            rejected: self.rejected,
            ranking,
            ..Recognition::new(self.name, self.observations, r.matches, r.laps, truth)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Pose2;

    /// A turned-down chain is a true revisit only when both its ends are the same place: one
    /// whose newest pair coincides but whose oldest pair lies 5 m apart (the robot came from
    /// another corridor) is a look-alike.
    #[test]
    fn a_rejected_chain_is_a_true_revisit_only_at_both_ends() {
        let spec = EvaluationSpec::default();
        let at = |x: f64, y: f64| TruePose(Pose2::new(x, y, 0.0));
        let newest_right = RejectedTruth {
            query_index: 0,
            query: at(0.0, 0.0),
            past: at(0.2, 0.0),
            direction: Direction::Same,
            check: 0,
            oldest: None,
        };
        assert!(newest_right.is_right(&spec));
        let both_right = RejectedTruth {
            oldest: Some((at(-10.0, 0.0), at(-9.8, 0.1))),
            ..newest_right
        };
        assert!(both_right.is_right(&spec));
        let oldest_apart = RejectedTruth {
            oldest: Some((at(-10.0, 0.0), at(-6.0, 3.0))),
            ..newest_right
        };
        assert!(!oldest_apart.is_right(&spec));
        let newest_apart = RejectedTruth {
            past: at(3.0, 0.0),
            ..both_right
        };
        assert!(!newest_apart.is_right(&spec));
    }
}
