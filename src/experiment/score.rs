//! Scoring any recognizer: the logs `placewords simulate` wrote (CARMEN logs with `TRUEPOS`, and
//! `manifest.json`) plus a matches file ([`crate::io::matches_csv`]) from any tool give the same
//! metrics, table and JSON report as `placewords run`.
//!
//! The harness holds the truth: the `TRUEPOS` of every laser line and the laps (door
//! configurations) from the manifest. Placewords' recognizer scores *observations*, one per
//! 0.10 m of odometric travel; a tool's matches name *scans*. To score both on the same footing,
//! the scans are thinned by the recognizer's own rule ([`ObservationClock`]: an observation
//! each time the odometric travel passes a multiple of 0.10 m, counted from the run's start), so
//! the observations fall on the scans the recognizer's fall on, and a matched scan counts as the
//! observation at or before it in its run. `score` on `run`'s exported matches therefore gives
//! `run`'s figures (the test beside `score_rows`).

use crate::eval::scores::Report;
use crate::eval::{GroundTruth, LapInfo, Recognition};
use crate::geom::{OdomPose, Pose2, TruePose};
use crate::io::carmen::{CarmenError, LogRecord, ReadOptions, read_log};
use crate::io::matches_csv::{MatchRow, MatchesCsvError, MatchesFile};
use crate::place::{Match, Observation};
use crate::recognizer::ObservationClock;
use crate::sim::RunLog;
use crate::sim::logs::Manifest;
use crate::spec::evaluation::EvaluationSpec;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Why a log folder or matches file could not be scored.
#[derive(Debug, thiserror::Error)]
pub enum ScoreError {
    #[error("{path}: {message}")]
    Manifest { path: String, message: String },
    #[error(transparent)]
    Log(#[from] CarmenError),
    /// A run's bag (`simulate --format mcap`).
    #[error(transparent)]
    Bag(#[from] crate::io::real_log::RealLogError),
    #[error(transparent)]
    Matches(#[from] MatchesCsvError),
    /// A located problem of the manifest or the matches file (invalid UTF-8, bad JSON, a row
    /// naming a scan the logs do not hold).
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"))]
    Located(Vec<crate::spec::diag::Diagnostic>),
    #[error(
        "{path}: match {row} names run {run} scan {scan}, which the logs do not hold ({what}); \
         check the run and 0-based scan numbers against manifest.json"
    )]
    UnknownScan {
        path: String,
        row: usize,
        run: usize,
        scan: usize,
        what: String,
    },
}

/// What the harness knows about a simulated log folder.
#[derive(Clone, Debug)]
pub struct LoggedRuns {
    pub scenario: String,
    pub seed: u64,
    pub laps: usize,
    /// Truth of every laser line, runs in manifest order.
    pub truth: GroundTruth,
    /// Observations (scans thinned as the recognizer thins them, see the module docs).
    pub observations: Vec<Observation>,
    /// Per run (manifest order): run number, index of its first scan in `truth.frames`, scans.
    pub runs: Vec<(usize, usize, usize)>,
    /// Global scan index → observation index (the observation at or before it; `None` in a run
    /// too short for one).
    obs_of_scan: Vec<Option<usize>>,
}

/// `(run number, frames)` of simulated runs, to map observations back to scans.
pub fn run_frames(runs: &[RunLog]) -> Vec<(usize, usize)> {
    runs.iter().map(|r| (r.run, r.frames().count())).collect()
}

/// The distinct pairs of `rec`'s matches as matches-file rows (query run/scan, matched
/// run/scan, the match's n-gram length as score, its direction), with runs laid out as
/// `run_frames` says.
pub fn export_rows(rec: &Recognition, run_frames: &[(usize, usize)]) -> Vec<MatchRow> {
    let mut starts = Vec::with_capacity(run_frames.len());
    let mut acc = 0;
    for &(_, n) in run_frames {
        starts.push(acc);
        acc += n;
    }
    let locate = |input: usize| {
        let k = starts.partition_point(|&s| s <= input).saturating_sub(1);
        (run_frames[k].0, input - starts[k])
    };
    let input_of: HashMap<usize, usize> = rec
        .observations
        .iter()
        .map(|o| (o.id, o.frame_id))
        .collect();
    let mut seen = HashSet::new();
    let mut rows = Vec::new();
    for m in &rec.matches {
        for (query, past) in m.pairs() {
            let (Some(&q), Some(&pa)) = (input_of.get(&query), input_of.get(&past)) else {
                continue;
            };
            if !seen.insert((query, past)) {
                continue;
            }
            let ((qr, qs), (pr, ps)) = (locate(q), locate(pa));
            rows.push(MatchRow {
                query_run: qr,
                query_scan: qs,
                matched_run: pr,
                matched_scan: ps,
                score: Some(m.score),
                direction: m.direction,
            });
        }
    }
    rows
}

/// Reads `dir/manifest.json` and every run's log (CARMEN or ROS 2 bag) in it.
pub fn load_logged_runs(dir: &Path) -> Result<LoggedRuns, ScoreError> {
    let mpath = dir.join("manifest.json");
    let bad = |message: String| ScoreError::Manifest {
        path: mpath.display().to_string(),
        message,
    };
    let text = crate::spec::diag::read_text(&mpath).map_err(|e| match e {
        crate::spec::SpecError::Io { source, .. } => bad(format!(
            "cannot read: {source}; give the folder `placewords simulate -o` wrote"
        )),
        crate::spec::SpecError::Invalid(d) => ScoreError::Located(d),
    })?;
    let manifest: Manifest = serde_json::from_str(&text).map_err(|e| {
        let file = mpath.display().to_string();
        ScoreError::Located(vec![crate::spec::diag::json_diagnostic(
            &file,
            &e,
            "not the manifest `placewords simulate -o` writes",
        )])
    })?;
    let mut truth = GroundTruth::default();
    let mut odom = Vec::new();
    let mut runs = Vec::new();
    for r in &manifest.runs {
        let path = dir.join(&r.file);
        let (poses, truths) = read_run(&path)?;
        let lap_frames: usize = r.laps.iter().map(|l| l.frames).sum();
        if poses.len() != lap_frames {
            return Err(bad(format!(
                "run {} lists {lap_frames} frames in its laps but {} has {} laser lines with TRUEPOS",
                r.run,
                path.display(),
                poses.len()
            )));
        }
        runs.push((r.run, truth.frames.len(), poses.len()));
        let mut k = 0;
        for l in &r.laps {
            let info = LapInfo {
                run: r.run,
                lap: l.lap,
                door_config: l.door_config.clone(),
                open_doors: l.open_doors.clone(),
            };
            let frames = truths[k..k + l.frames].iter().zip(&poses[k..k + l.frames]);
            truth.push_lap(
                info,
                frames.map(|(t, o)| (TruePose(*t), crate::geom::OdomPose(*o))),
            );
            k += l.frames;
        }
        odom.extend(poses);
    }
    let (observations, obs_of_scan) = thin(&odom, &runs);
    Ok(LoggedRuns {
        scenario: manifest.scenario_name,
        seed: manifest.seed,
        laps: truth.laps.len(),
        truth,
        observations,
        runs,
        obs_of_scan,
    })
}

/// The odometry and truth of every laser line of one log (a laser line's truth is the
/// `TRUEPOS` line that follows it, as `simulate` writes them); of a bag, every scan's odometry
/// and the truth at its stamp.
fn read_run(path: &Path) -> Result<(Vec<Pose2>, Vec<Pose2>), ScoreError> {
    use crate::io::real_log::{TruthSource, load_bag_run, noise_free};
    if crate::io::ros2::bag::is_mcap(path) {
        let run = load_bag_run(path, &Default::default(), TruthSource::TruePos, noise_free)?;
        return Ok(run.frames().map(|f| (f.odom.0, f.truth.0)).unzip());
    }
    let readout = read_log(path, ReadOptions::default())?;
    let (mut odom, mut truth) = (Vec::new(), Vec::new());
    let mut pending: Option<Pose2> = None;
    for rec in &readout.records {
        match rec {
            LogRecord::Laser(l) => pending = Some(l.odom),
            LogRecord::TruePos(t) => {
                if let Some(o) = pending.take() {
                    odom.push(o);
                    truth.push(t.truth);
                }
            }
            _ => {}
        }
    }
    Ok((odom, truth))
}

/// Observations from scans, placed by the recognizer's own rule ([`ObservationClock`], with
/// its default spacing and interpolation limit): a scan makes as many observations as the
/// recognizer would make there. For every scan, the observation at or before it in its run
/// (before a run's first observation, that one); `None` in a run without observations.
fn thin(odom: &[Pose2], runs: &[(usize, usize, usize)]) -> (Vec<Observation>, Vec<Option<usize>>) {
    let defaults = crate::recognizer::RecognizerConfig::default();
    let mut clock = ObservationClock::new(
        defaults.front_end.observation_spacing_m,
        defaults.front_end.max_interpolation_m,
    );
    let mut obs: Vec<Observation> = Vec::new();
    let mut of_scan = vec![None; odom.len()];
    for (run_pos, &(_, start, n)) in runs.iter().enumerate() {
        clock.start_run();
        let first = obs.len();
        for i in start..start + n {
            let due = clock.step(OdomPose(odom[i]));
            for _ in 0..due.observations() {
                obs.push(Observation::new(
                    obs.len(),
                    run_pos,
                    i,
                    OdomPose(odom[i]),
                    clock.travel_m(),
                ));
            }
            if obs.len() > first {
                of_scan[i] = Some(obs.len() - 1);
            }
        }
        // Scans before the run's first observation count as that one.
        if obs.len() > first {
            for slot in &mut of_scan[start..start + n] {
                if slot.is_some() {
                    break;
                }
                *slot = Some(first);
            }
        }
    }
    (obs, of_scan)
}

impl LoggedRuns {
    /// Global scan index of `run`'s scan `scan`, if the logs hold it.
    fn scan(&self, run: usize, scan: usize) -> Result<usize, String> {
        let Some(&(_, start, n)) = self.runs.iter().find(|r| r.0 == run) else {
            let have: Vec<String> = self.runs.iter().map(|r| r.0.to_string()).collect();
            return Err(format!("runs are {}", have.join(", ")));
        };
        if scan < n {
            Ok(start + scan)
        } else {
            Err(format!("run {run} has {n} scans"))
        }
    }

    /// `rows` as a recognition: every row one match of one observation pair, claiming the
    /// row's direction (so the evaluation's heading rule, `eval::pair_recall::Facing`, judges
    /// it as it judges placewords' own matches).
    pub fn recognition(&self, rows: &[MatchRow], path: &str) -> Result<Recognition, ScoreError> {
        let mut matches = Vec::with_capacity(rows.len());
        for (k, r) in rows.iter().enumerate() {
            let at = |run: usize, scan: usize| {
                self.scan(run, scan)
                    .map_err(|what| ScoreError::UnknownScan {
                        path: path.to_string(),
                        row: k + 1,
                        run,
                        scan,
                        what,
                    })
            };
            let observed = |run: usize, scan: usize| {
                let i = at(run, scan)?;
                self.obs_of_scan[i].ok_or_else(|| ScoreError::UnknownScan {
                    path: path.to_string(),
                    row: k + 1,
                    run,
                    scan,
                    what: format!("run {run} is too short to make an observation"),
                })
            };
            let q = observed(r.query_run, r.query_scan)?;
            let p = observed(r.matched_run, r.matched_scan)?;
            let (qo, po) = (&self.observations[q], &self.observations[p]);
            let mut m = Match::from_pairs([(qo.id, po.id)], r.score.unwrap_or(1.0));
            m.direction = r.direction;
            matches.push(m);
        }
        Ok(Recognition::new(
            "external",
            self.observations.clone(),
            matches,
            self.laps,
            std::sync::Arc::new(self.truth.clone()),
        ))
    }
}

/// [`score_rows`] on a matches file read with [`crate::io::matches_csv::read_matches`]: a row
/// naming a scan the logs do not hold is reported at its line of `path`.
pub fn score_file(
    logs: &LoggedRuns,
    file: &MatchesFile,
    path: &str,
    spec: &EvaluationSpec,
    levels: Option<usize>,
) -> Result<Report, ScoreError> {
    score_rows(logs, &file.rows, path, spec, levels).map_err(|e| match e {
        ScoreError::UnknownScan {
            path,
            row,
            run,
            scan,
            what,
        } => match file.lines.get(row.wrapping_sub(1)) {
            Some(&line) => ScoreError::Located(vec![crate::spec::diag::Diagnostic::error(
                &path,
                (line, 1),
                format!(
                    "run {run} scan {scan} is not in the logs ({what}); check the run and \
                     0-based scan numbers against manifest.json"
                ),
            )]),
            None => ScoreError::UnknownScan {
                path,
                row,
                run,
                scan,
                what,
            },
        },
        e => e,
    })
}

/// Scores `rows` against the logs as a report with one subject: `external` (kind `external`),
/// or `words-N` with `levels` `Some(N)` (matches `run --export-matches` wrote, compared with
/// `run`'s own row).
pub fn score_rows(
    logs: &LoggedRuns,
    rows: &[MatchRow],
    path: &str,
    spec: &EvaluationSpec,
    levels: Option<usize>,
) -> Result<Report, ScoreError> {
    let rec = logs.recognition(rows, path)?;
    let mut report = Report::new(&logs.scenario, logs.seed, logs.laps, spec.clone());
    match levels {
        Some(levels) => {
            report.add_level(levels, &[], &rec);
        }
        None => {
            report.add_subject(&rec.name, crate::eval::scores::SubjectKind::External, &rec);
        }
    }
    report.finish();
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::load_scenario;
    use crate::experiment::{ExperimentOptions, evaluate_runs, recognizer_config};
    use crate::io::matches_csv::{parse_matches, write_matches};
    use crate::place::Direction;

    /// The smoke scenario simulated and written as `simulate` writes it.
    fn smoke_logs() -> (tempfile::TempDir, Vec<RunLog>, crate::experiment::Scenario) {
        let scn = load_scenario(Path::new("scenarios/smoke.toml")).expect("smoke loads");
        logs_of(scn)
    }

    fn logs_of(
        scn: crate::experiment::Scenario,
    ) -> (tempfile::TempDir, Vec<RunLog>, crate::experiment::Scenario) {
        let runs = crate::sim::simulate(&scn.sim, None, &|| {}).expect("simulates");
        let dir = tempfile::tempdir().expect("temp dir");
        crate::sim::logs::write_logs(&scn.sim, &runs, None, dir.path()).expect("logs written");
        (dir, runs, scn)
    }

    /// The smoke scenario with its second run driven in reverse: its laps revisit the first
    /// run's places facing the other way.
    fn reverse_smoke_logs() -> (tempfile::TempDir, Vec<RunLog>, crate::experiment::Scenario) {
        let src = std::fs::read_to_string("scenarios/smoke.toml").expect("smoke reads");
        let world = std::fs::canonicalize("worlds/loop-small.toml").expect("world exists");
        let src = src
            .replace(
                "\"../worlds/loop-small.toml\"",
                &format!("{:?}", world.display().to_string()),
            )
            .replace(
                "start_waypoint = 2\n",
                "start_waypoint = 2\ndirection = \"reverse\"\n",
            );
        assert!(
            src.contains("direction = \"reverse\""),
            "smoke's second run moved"
        );
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("reverse-smoke.toml");
        std::fs::write(&path, src).expect("written");
        logs_of(load_scenario(&path).expect("reverse smoke loads"))
    }

    /// For every observation with a revisit facing as `claim` says, its nearest earlier such
    /// partner, as rows claiming `claim`; with `shift` scans added to the matched scan (clamped
    /// to the run).
    fn oracle_rows(
        logs: &LoggedRuns,
        spec: &EvaluationSpec,
        shift: usize,
        claim: Direction,
    ) -> Vec<MatchRow> {
        let facing = crate::eval::pair_recall::Facing::of(claim);
        let tolerance = spec.heading_tolerance_deg.to_radians();
        let travel = crate::eval::pair_recall::true_travel_m(&logs.truth);
        let pose = |o: &Observation| logs.truth.frames[o.frame_id].pose.0;
        let locate = |i: usize| {
            let &(run, start, n) = logs.runs.iter().rfind(|r| r.1 <= i).expect("a run");
            (run, i - start, n)
        };
        let mut rows = Vec::new();
        for (k, q) in logs.observations.iter().enumerate() {
            let best = logs.observations[..k]
                .iter()
                .filter(|p| travel[q.frame_id] - travel[p.frame_id] >= spec.min_gap_m)
                .filter(|p| facing.agrees(pose(q).theta, pose(p).theta, tolerance))
                .map(|p| (pose(q).distance(&pose(p)), p))
                .filter(|(d, _)| *d <= spec.tp_radius_m)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, p)) = best {
                let (qr, qs, _) = locate(q.frame_id);
                let (pr, ps, n) = locate(p.frame_id);
                if ps + shift < n {
                    rows.push(MatchRow {
                        query_run: qr,
                        query_scan: qs,
                        matched_run: pr,
                        matched_scan: ps + shift,
                        score: None,
                        direction: claim,
                    });
                }
            }
        }
        rows
    }

    /// A matches file written from the truth scores 1; the same file with every matched scan
    /// moved 5 m along the path (125 scans at 0.4 m/s and 10 Hz) scores 0. And `score` on
    /// `run`'s own exported matches gives `run`'s figures: scans are thinned to observations by the recognizer's own rule, so
    /// they fall on the same scans and count the same revisits.
    #[test]
    fn score_reads_logs_and_matches_files_like_run() {
        let (dir, runs, scn) = smoke_logs();
        let logs = load_logged_runs(dir.path()).expect("logs load");
        let spec = EvaluationSpec::default();
        let text = write_matches(&oracle_rows(&logs, &spec, 0, Direction::Same));
        let perfect = parse_matches(&text, "perfect.csv").expect("parses");
        let r = score_rows(&logs, &perfect, "perfect.csv", &spec, None).unwrap();
        // Another tool's matches are not labelled as the paper's recognizer (they read `1 []`,
        // then `words-1`, beside `run`'s own words-1 row).
        assert_eq!(
            (r.subjects[0].name.as_str(), r.subjects[0].kind),
            ("external", crate::eval::scores::SubjectKind::External)
        );
        let s = &r.subjects[0].scores;
        assert_eq!((s.precision, s.recall), (1.0, 1.0), "{s:?}");
        let shifted = oracle_rows(&logs, &spec, 125, Direction::Same);
        assert!(shifted.len() > perfect.len() / 2);
        let r = score_rows(&logs, &shifted, "shifted.csv", &spec, None).unwrap();
        let s = &r.subjects[0].scores;
        assert_eq!((s.precision, s.recall), (0.0, 0.0), "{s:?}");

        let opts = ExperimentOptions {
            levels: vec![3],
            ..ExperimentOptions::default()
        };
        let base = recognizer_config(&scn).unwrap();
        let exp = evaluate_runs("smoke", scn.sim.seed, runs, &base, &spec, &opts).unwrap();
        let (_, rec) = &exp.recognitions[0];
        let rows = export_rows(rec, &run_frames(&exp.runs));
        let scored = score_rows(&logs, &rows, "run.csv", &spec, Some(3)).unwrap();
        assert_eq!(
            scored.subjects[0].name, exp.report.subjects[0].name,
            "words-3 as run says"
        );
        let (a, b) = (&exp.report.subjects[0].scores, &scored.subjects[0].scores);
        assert!(a.pairs > 100, "smoke should match: {a:?}");
        assert_eq!(exp.report.revisits, scored.revisits);
        assert_eq!(a.revisits, b.revisits, "{a:?} vs {b:?}");
        assert_eq!((a.pairs, a.correct_pairs), (b.pairs, b.correct_pairs));
        assert_eq!((a.precision, a.recall), (b.precision, b.recall));
    }

    /// A matches file's `direction` column is scored by the evaluation's heading rule: the
    /// truth's opposite-direction partners claimed `opposite` are all correct and recall every
    /// opposite revisit; the same rows claimed `same` (the default of a file without the column)
    /// are all wrong.
    #[test]
    fn opposite_rows_are_scored_per_direction() {
        let (dir, _, _) = reverse_smoke_logs();
        let logs = load_logged_runs(dir.path()).expect("logs load");
        let spec = EvaluationSpec::default();
        let rows = oracle_rows(&logs, &spec, 0, Direction::Opposite);
        assert!(rows.len() > 100, "a reverse run revisits: {}", rows.len());
        let text = write_matches(&rows);
        let parsed = parse_matches(&text, "opposite.csv").expect("parses");
        let r = score_rows(&logs, &parsed, "opposite.csv", &spec, None).unwrap();
        let s = &r.subjects[0].scores;
        let opp = s.of_direction(Direction::Opposite);
        assert_eq!((opp.precision, opp.recall), (1.0, 1.0), "{opp:?}");
        assert_eq!(s.precision, 1.0);
        assert_eq!(s.of_direction(Direction::Same).pairs, 0);

        let as_same: Vec<MatchRow> = rows
            .iter()
            .map(|r| MatchRow {
                direction: Direction::Same,
                ..*r
            })
            .collect();
        let r = score_rows(&logs, &as_same, "same.csv", &spec, None).unwrap();
        let s = &r.subjects[0].scores;
        assert_eq!((s.precision, s.correct_pairs), (0.0, 0), "{s:?}");
    }

    #[test]
    fn unknown_scans_are_named() {
        let (dir, _, _) = smoke_logs();
        let logs = load_logged_runs(dir.path()).unwrap();
        let row = MatchRow {
            query_run: 7,
            query_scan: 0,
            matched_run: 0,
            matched_scan: 0,
            score: None,
            direction: Direction::Same,
        };
        let e = score_rows(&logs, &[row], "m.csv", &EvaluationSpec::default(), None).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("m.csv: match 1 names run 7 scan 0"),
            "{e}"
        );
        assert!(load_logged_runs(Path::new("/nonexistent")).is_err());
    }
}
