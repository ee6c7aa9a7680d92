//! One density front end for the level configurations that share it. The configurations of a
//! run differ past the front end (levels, thresholds), and the front end (local grid and Ψ,
//! most of a lap's recognition time) depends only on the `[recognizer.front_end]`, `grid` and
//! `density` settings ([`DensityFrontEnd::same_settings`]). So the streamed harness runs one
//! [`DensityFrontEnd`] per distinct front-end setting ([`FrontEnds`]) on the frames it feeds,
//! and hands its observations to each sharing configuration's [`WordMatcher`]
//! ([`SharedWords`], a [`PlaceRecognizer`] fed by the harness as any other), instead of a whole
//! [`crate::recognizer::Recognizer`] per configuration. Each back end sees the observations the
//! whole recognizer would have made, in the same order, so the matches and every figure but the
//! timings are the same.
//!
//! Time: each sharing configuration is charged the whole of its front end's CPU (and wall)
//! time ([`crate::eval::Recording::charge`]), as if it ran alone. A subject's seconds per lap
//! thus stay what that recognizer costs a user, whatever other configurations ran beside it,
//! and comparable with a baseline's (`max_slowdown`); the CPU the process used is less than the
//! sum of the subjects' (the front end is counted once per sharing subject).

use super::ExperimentError;
use super::stream::Job;
use crate::clock::Stopwatch;
use crate::eval::{GroundTruth, PlaceRecognizer};
use crate::geom::OdomPose;
use crate::log::Frame;
use crate::place::{self, FrameId, Observation};
use crate::recognizer::{
    DensityFrontEnd, DensityObservation, MatchDiagnostics, RecognizerConfig, WordMatcher,
    harness_name, to_place,
};
use crate::scan::Scan;
use rayon::prelude::*;
use std::sync::{Arc, PoisonError, RwLock};

/// The observations a front end made of the frames fed last.
#[derive(Debug, Default)]
struct Observed {
    /// Input index of the first of those frames.
    first: usize,
    /// The observations each frame made, in order.
    per_frame: Vec<Vec<DensityObservation>>,
    /// The front end's long steps so far ([`DensityFrontEnd::long_steps`]).
    long_steps: usize,
}

/// One front end and what it observed last, read by its sharing back ends.
struct Front {
    config: RecognizerConfig,
    front: DensityFrontEnd,
    observed: Arc<RwLock<Observed>>,
}

/// The front ends the word jobs share, and which front end each job reads (none for a
/// recognizer of its own: ICP, Scan Context, an external program).
#[derive(Default)]
pub(super) struct FrontEnds {
    fronts: Vec<Front>,
    of_job: Vec<Option<usize>>,
}

impl FrontEnds {
    /// A word job with the settings `config`, reading the front end of the first job before it
    /// with the same front-end settings (made here when there is none); its back end is the
    /// job's recognizer.
    pub(super) fn words_job(
        &mut self,
        config: &RecognizerConfig,
    ) -> Result<SharedWords, ExperimentError> {
        let fail =
            |e: crate::recognizer::RecognizerError| ExperimentError::Recognizer(e.to_string());
        let back = WordMatcher::new(config).map_err(fail)?;
        let i = match self
            .fronts
            .iter()
            .position(|f| DensityFrontEnd::same_settings(&f.config, config))
        {
            Some(i) => i,
            None => {
                self.fronts.push(Front {
                    config: config.clone(),
                    front: DensityFrontEnd::new(config).map_err(fail)?,
                    observed: Arc::default(),
                });
                self.fronts.len() - 1
            }
        };
        self.of_job.push(Some(i));
        Ok(SharedWords {
            config: config.clone(),
            back,
            observed: self.fronts[i].observed.clone(),
        })
    }

    /// Notes a job with a recognizer of its own (call in job order, after the word jobs).
    pub(super) fn own_job(&mut self) {
        self.of_job.push(None);
    }

    /// The number of distinct front ends.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.fronts.len()
    }

    /// Starts a run on every front end, then on every job (in parallel), each sharing job
    /// charged its front end's time.
    pub(super) fn start_run(&mut self, jobs: &mut [Job], truth: &GroundTruth) {
        let spent: Vec<(f64, f64)> = self
            .fronts
            .iter_mut()
            .map(|f| {
                let w = Stopwatch::start();
                f.front.start_run();
                (w.cpu_s(), w.wall_s())
            })
            .collect();
        self.for_jobs(jobs, &spent, |rec, recording| {
            recording.start_run(rec, truth)
        });
    }

    /// Feeds `frames` (their truth in `truth` from input index `first`) to every job: each
    /// front end observes them first (the front ends in parallel), then every job takes them
    /// (in parallel), each sharing job charged its front end's time.
    pub(super) fn frames(
        &mut self,
        jobs: &mut [Job],
        frames: &[Frame],
        first: usize,
        truth: &GroundTruth,
    ) {
        let spent: Vec<(f64, f64)> = self
            .fronts
            .par_iter_mut()
            .map(|f| {
                let w = Stopwatch::start();
                let per_frame = frames
                    .iter()
                    .enumerate()
                    .map(|(i, frame)| f.front.push_frame(first + i, frame.odom, &frame.scan))
                    .collect();
                let spent = (w.cpu_s(), w.wall_s());
                *f.observed.write().unwrap_or_else(PoisonError::into_inner) = Observed {
                    first,
                    per_frame,
                    long_steps: f.front.long_steps(),
                };
                spent
            })
            .collect();
        self.for_jobs(jobs, &spent, |rec, recording| {
            recording.frames(rec, frames, first, truth)
        });
    }

    /// Runs `work` on every job in parallel, after charging each sharing job its front end's
    /// `spent` (CPU, wall) seconds.
    fn for_jobs(
        &self,
        jobs: &mut [Job],
        spent: &[(f64, f64)],
        work: impl Fn(&mut dyn PlaceRecognizer, &mut crate::eval::Recording) + Sync,
    ) {
        debug_assert_eq!(jobs.len(), self.of_job.len(), "a front end entry per job");
        jobs.par_iter_mut()
            .zip(self.of_job.par_iter())
            .for_each(|((_, rec, recording), front)| {
                if let Some(&(cpu_s, wall_s)) = front.and_then(|f| spent.get(f)) {
                    recording.charge(cpu_s, wall_s);
                }
                work(rec.as_mut(), recording);
            });
    }
}

/// The back end of a level configuration, fed the observations of a front end it shares
/// ([`FrontEnds`]): as a [`PlaceRecognizer`], `push` takes the observations the front end made
/// of that frame (it must have observed it last), and the matches are those of a whole
/// recognizer with the same settings.
pub(super) struct SharedWords {
    config: RecognizerConfig,
    back: WordMatcher,
    observed: Arc<RwLock<Observed>>,
}

impl PlaceRecognizer for SharedWords {
    fn start_run(&mut self) -> Vec<place::Match> {
        to_place(self.back.start_run())
    }
    fn push(&mut self, frame_id: FrameId, _odom: OdomPose, _scan: &Scan) -> Vec<place::Match> {
        let observed = self.observed.read().unwrap_or_else(PoisonError::into_inner);
        let made = frame_id
            .checked_sub(observed.first)
            .and_then(|i| observed.per_frame.get(i));
        debug_assert!(made.is_some(), "frame {frame_id} was not observed last");
        let mut out = Vec::new();
        for obs in made.into_iter().flatten() {
            out.extend(self.back.push_observation(obs));
        }
        to_place(out)
    }
    fn finish(&mut self) -> Vec<place::Match> {
        to_place(self.back.finish_run())
    }
    fn observations(&self) -> &[Observation] {
        self.back.observations()
    }
    fn query_horizon(&self) -> usize {
        self.back.query_horizon()
    }
    fn name(&self) -> String {
        harness_name(&self.config)
    }
    fn diagnostics(&self) -> Option<Box<dyn place::Diagnostics>> {
        let long_steps = self
            .observed
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .long_steps;
        Some(Box::new(MatchDiagnostics {
            long_steps,
            ..self.back.diagnostics()
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::{LapInfo, Recording, recognize_runs};
    use crate::experiment::{
        ExperimentOptions, SubjectId, level_configs, load_scenario, recognizer_config,
    };
    use crate::recognizer::Recognizer;
    use std::path::Path;

    /// Level configurations 1, 2 and 3 of the smoke scenario fed through one shared front end
    /// find the matches (and report the observations, names and diagnostics) of whole
    /// recognizers with the same settings, and each is charged the front end's time; a
    /// configuration with other grid settings gets a front end of its own.
    #[test]
    fn shared_front_end_gives_the_matches_of_whole_recognizers() {
        let scn = load_scenario(Path::new("scenarios/smoke.toml")).expect("smoke loads");
        let opts = ExperimentOptions {
            laps: Some(3),
            ..ExperimentOptions::default()
        };
        let runs = crate::experiment::simulate(&scn, &opts).unwrap().0;
        let base = recognizer_config(&scn).unwrap();
        let configs = level_configs(&base, &[1, 2, 3]).unwrap();
        let mut fronts = FrontEnds::default();
        let mut jobs: Vec<Job> = configs
            .iter()
            .map(|c| {
                let rec = fronts.words_job(c).unwrap();
                (
                    SubjectId::Words(c.levels),
                    Box::new(rec) as _,
                    Recording::default(),
                )
            })
            .collect();
        assert_eq!(fronts.len(), 1);
        let mut truth = GroundTruth::default();
        for run in &runs {
            fronts.start_run(&mut jobs, &truth);
            for lap in &run.laps {
                truth.start_lap(LapInfo::of(run.run, lap));
                let first = truth.push_frames(&lap.frames);
                jobs.iter_mut().for_each(|j| j.2.start_lap());
                fronts.frames(&mut jobs, &lap.frames, first, &truth);
                jobs.iter_mut().for_each(|j| j.2.end_lap());
            }
        }
        let truth = Arc::new(truth);
        let mut found_some = false;
        for ((_, mut rec, mut recording), cfg) in jobs.into_iter().zip(&configs) {
            recording.close(rec.as_mut(), &truth);
            let shared = recording.finish(rec.as_mut(), truth.clone());
            let whole = recognize_runs(&mut Recognizer::new(cfg.clone()).unwrap(), &runs);
            assert_eq!(shared.matches, whole.matches, "levels {}", cfg.levels);
            assert_eq!(shared.observations, whole.observations);
            assert_eq!(shared.name, whole.name);
            let text = |r: &crate::eval::Recognition| r.diagnostics.as_ref().map(|d| d.to_json());
            assert_eq!(text(&shared), text(&whole));
            assert!(shared.seconds > 0.0 && shared.lap_seconds.iter().all(|&s| s > 0.0));
            found_some |= !shared.matches.is_empty();
        }
        assert!(found_some, "the smoke laps match");
        let mut other = configs[0].clone();
        other.grid.grid_cell_m *= 2.0;
        fronts.words_job(&other).unwrap();
        fronts.words_job(&configs[2]).unwrap();
        assert_eq!(fronts.len(), 2);
    }
}
