//! Pictures of an experiment: the world with the true and odometry paths (odometry placed at the
//! run's true start); the true path coloured where revisits were recognized, recognized wrongly
//! and missed, with the worst clusters of wrong pairs as lines and marks where verification
//! turned down true revisits; and a strip of recall and precision per lap with the door
//! configurations marked.

use crate::eval::Recognition;
use crate::eval::metrics::Scorer;
use crate::eval::pair_recall::Facing;
use crate::log::RunLog;
use crate::report::lap_strip::{LapPoint, lap_strip};
use crate::report::world_render::{
    LegendEntry, MarkOverlay, PathOverlay, RenderOptions, SegmentOverlay, render_world_svg,
};
use crate::spec::evaluation::EvaluationSpec;
use crate::world::World;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

const TRUE_COLOR: &str = "#1f77b4";
const ODOM_COLOR: &str = "#ff7f0e";
const CORRECT_COLOR: &str = "#2ca02c";
const WRONG_COLOR: &str = "#d62728";
const MISSED_COLOR: &str = "#222222";
const PLAIN_COLOR: &str = "#c7c7c7";
const TURNED_DOWN_COLOR: &str = "#9467bd";

fn true_paths(runs: &[RunLog], label: &str) -> Vec<PathOverlay> {
    runs.iter()
        .enumerate()
        .map(|(i, r)| PathOverlay {
            label: if i == 0 {
                label.to_string()
            } else {
                String::new()
            },
            color: TRUE_COLOR.into(),
            points: r.frames().map(|f| f.truth.0.position()).collect(),
            dashed: false,
        })
        .collect()
}

fn plain(world: &World, title: String) -> RenderOptions {
    RenderOptions {
        title: Some(title),
        show_routes: false,
        show_areas: false,
        show_door_labels: false,
        doors: crate::world::DoorStates::all_closed(world),
        ..RenderOptions::default()
    }
}

/// A run's odometry path in the world frame: the odometry frame placed so that the first
/// odometry pose lies on the first true pose (the robot's odometry starts at (0, 0, 0) wherever
/// it is switched on).
pub fn odometry_in_world(run: &RunLog) -> Vec<crate::geom::Vec2> {
    let mut frames = run.frames();
    let Some(first) = frames.next() else {
        return Vec::new();
    };
    let world_from_odom = first.truth.0.compose(&first.odom.0.inverse());
    std::iter::once(first)
        .chain(frames)
        .map(|f| world_from_odom.transform_point(f.odom.0.position()))
        .collect()
}

/// The world with each run's true path and odometry path (drawn from the run's true start).
pub fn trajectory_svg(world: &World, runs: &[RunLog], title: &str) -> String {
    let mut opts = plain(world, title.to_string());
    opts.paths = true_paths(runs, "true path");
    opts.paths
        .extend(runs.iter().enumerate().map(|(i, r)| PathOverlay {
            label: if i == 0 {
                "odometry (from the true start)".into()
            } else {
                String::new()
            },
            color: ODOM_COLOR.into(),
            points: odometry_in_world(r),
            dashed: true,
        }));
    render_world_svg(world, &opts)
}

/// The world with the true path coloured where revisits were recognized, recognized wrongly
/// and missed (see [`ObsStatus`]), and the worst clusters of wrong pairs as lines.
pub fn matches_svg(
    world: &World,
    runs: &[RunLog],
    rec: &Recognition,
    radius_m: f64,
    title: &str,
) -> String {
    let spec = EvaluationSpec {
        tp_radius_m: radius_m,
        ..EvaluationSpec::default()
    };
    let status = observation_status(rec, &spec);
    let mut opts = plain(world, title.to_string());
    opts.paths = true_paths(runs, "true path, no revisit");
    for p in &mut opts.paths {
        p.color = PLAIN_COLOR.into();
    }
    let counts = |k: Kind| status.kinds.iter().filter(|x| **x == k).count();
    for kind in [Kind::Recognized, Kind::Missed, Kind::Wrong] {
        opts.paths
            .extend(status.runs_of(kind).into_iter().map(|points| PathOverlay {
                label: String::new(),
                color: kind.color().into(),
                points,
                dashed: false,
            }));
    }
    let right_rejected = rec.rejected.iter().filter(|r| r.is_right(&spec)).count();
    let checks = rec
        .diagnostics
        .as_ref()
        .map(|d| d.checks())
        .unwrap_or_default();
    opts.marks = turned_down_marks(&rec.rejected, &checks, &spec, 2 * WORST_CLUSTERS);
    let clusters = worst_wrong_clusters(&status.wrong_pairs, WORST_CLUSTERS);
    let shown: usize = clusters.iter().map(|c| c.2).sum();
    opts.segments = clusters
        .iter()
        .map(|&(a, b, _)| SegmentOverlay {
            color: WRONG_COLOR.into(),
            a,
            b,
        })
        .collect();
    let legend = |label: String, color: &str| LegendEntry {
        label,
        color: color.into(),
        dashed: false,
    };
    opts.legend = vec![
        legend(
            format!(
                "recognized, most pairs correct ({} obs.)",
                counts(Kind::Recognized)
            ),
            CORRECT_COLOR,
        ),
        legend(
            format!(
                "recognized, most pairs wrong ({} obs.)",
                counts(Kind::Wrong)
            ),
            WRONG_COLOR,
        ),
        legend(
            format!("revisit missed ({} obs.)", counts(Kind::Missed)),
            MISSED_COLOR,
        ),
        legend(
            format!(
                "pairs: {} correct, {} wrong; lines: worst {} wrong clusters ({shown} pairs)",
                status.correct_pairs,
                status.wrong_pairs.len(),
                clusters.len()
            ),
            WRONG_COLOR,
        ),
    ];
    if !rec.rejected.is_empty() {
        opts.legend.push(legend(
            format!(
                "verification turned down {right_rejected} true revisits, {} look-alikes \
                 (candidates sampled)",
                rec.rejected.len() - right_rejected
            ),
            TURNED_DOWN_COLOR,
        ));
        if right_rejected > 0 {
            opts.notes.push(
                "purple marks: true revisits turned down per 5 m, and the check that did most \
                 (Tr travel, Tu turn, D density, S sides, St straight)"
                    .into(),
            );
        }
    }
    render_world_svg(world, &opts)
}

/// A check's short label on the picture: its name's first two letters, the first capitalised
/// ("turn" → "Tu").
fn check_label(check: Option<&String>) -> String {
    let mut c = check.map_or("?", |c| c.as_str()).chars().take(2);
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

/// Marks where verification turned down true revisits: the rejected candidates the truth
/// calls right, grouped by the 5 m cell of their query, the `k` largest groups, each at its
/// mean query position with its size and its most frequent check.
fn turned_down_marks(
    rejected: &[crate::eval::RejectedTruth],
    checks: &[String],
    spec: &EvaluationSpec,
    k: usize,
) -> Vec<MarkOverlay> {
    type Group = (crate::geom::Vec2, usize, Vec<usize>);
    let mut groups: HashMap<(i64, i64), Group> = HashMap::new();
    for r in rejected.iter().filter(|r| r.is_right(spec)) {
        let at = crate::geom::Vec2::new(r.query.0.x, r.query.0.y);
        let cell = (
            (at.x / CLUSTER_CELL_M).floor() as i64,
            (at.y / CLUSTER_CELL_M).floor() as i64,
        );
        let g = groups
            .entry(cell)
            .or_insert_with(|| (crate::geom::Vec2::zeros(), 0, vec![0; checks.len().max(1)]));
        g.0 += at;
        g.1 += 1;
        if let Some(n) = g.2.get_mut(r.check) {
            *n += 1;
        }
    }
    let mut list: Vec<((i64, i64), Group)> = groups.into_iter().collect();
    // Largest first; ties by cell so the picture does not depend on hash order.
    list.sort_by(|x, y| y.1.1.cmp(&x.1.1).then(x.0.cmp(&y.0)));

    list.into_iter()
        .take(k)
        .map(|(_, (sum, n, by_check))| {
            let n_checks = by_check.len();
            let check = (0..n_checks)
                .max_by_key(|&c| (by_check[c], n_checks - c))
                .unwrap_or(0);
            MarkOverlay {
                at: sum / n as f64,
                text: format!("{n} {}", check_label(checks.get(check))),
                color: TURNED_DOWN_COLOR.into(),
                class: "turned-down".into(),
            }
        })
        .collect()
}

/// Wrong-pair clusters drawn as lines in the matches picture.
pub const WORST_CLUSTERS: usize = 8;
/// Cell size of wrong-pair clustering, metres.
const CLUSTER_CELL_M: f64 = 5.0;

/// What happened at one observation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// No revisit and no pair.
    Plain,
    /// The query of pairs, at least half of them correct.
    Recognized,
    /// The query of pairs, most of them wrong.
    Wrong,
    /// A revisit with no pair at all.
    Missed,
}

impl Kind {
    fn color(self) -> &'static str {
        match self {
            Kind::Plain => PLAIN_COLOR,
            Kind::Recognized => CORRECT_COLOR,
            Kind::Wrong => WRONG_COLOR,
            Kind::Missed => MISSED_COLOR,
        }
    }
}

/// Per observation (creation order): its kind, true position, lap slot and revisit; and the
/// wrong pairs' true positions.
pub struct ObsStatus {
    pub kinds: Vec<Kind>,
    pub positions: Vec<Option<crate::geom::Vec2>>,
    pub lap_slots: Vec<Option<usize>>,
    pub revisits: Vec<bool>,
    /// Per observation: (correct pairs, pairs) it is the query of.
    pub pair_counts: Vec<(usize, usize)>,
    pub correct_pairs: usize,
    pub wrong_pairs: Vec<(crate::geom::Vec2, crate::geom::Vec2)>,
}

/// Classifies every observation of `rec` (a pair is correct within `tp_radius_m` with agreeing
/// headings, as the evaluation says).
pub fn observation_status(rec: &Recognition, spec: &EvaluationSpec) -> ObsStatus {
    let revisits = Scorer::new(&rec.observations, &rec.truth, spec).revisits(spec.tp_radius_m);
    let index_of: HashMap<usize, usize> = rec
        .observations
        .iter()
        .enumerate()
        .map(|(i, o)| (o.id, i))
        .collect();
    let pose = |i: usize| {
        rec.truth
            .frame(rec.observations[i].frame_id)
            .map(|f| f.pose.0)
    };
    let n = rec.observations.len();
    let mut pair_counts = vec![(0usize, 0usize); n];
    let (mut correct_pairs, mut wrong_pairs) = (0, Vec::new());
    let mut seen = HashSet::new();
    let tol = spec.heading_tolerance_deg.to_radians();
    let claimed = rec.matches.iter().flat_map(|m| {
        let claim = Facing::of(m.direction);
        m.pairs().map(move |p| (p, claim))
    });
    for ((query, past), claim) in claimed {
        let (Some(&q), Some(&pa)) = (index_of.get(&query), index_of.get(&past)) else {
            continue;
        };
        let (Some(a), Some(b)) = (pose(q), pose(pa)) else {
            continue;
        };
        if !seen.insert((q, pa)) {
            continue;
        }
        let ok = a.distance(&b) <= spec.tp_radius_m && claim.agrees(a.theta, b.theta, tol);
        pair_counts[q].1 += 1;
        if ok {
            pair_counts[q].0 += 1;
            correct_pairs += 1;
        } else {
            wrong_pairs.push((a.position(), b.position()));
        }
    }
    let kinds = (0..n)
        .map(|i| match pair_counts[i] {
            (c, t) if c > 0 && 2 * c >= t => Kind::Recognized,
            (_, t) if t > 0 => Kind::Wrong,
            _ if revisits[i] => Kind::Missed,
            _ => Kind::Plain,
        })
        .collect();
    ObsStatus {
        kinds,
        positions: (0..n).map(|i| pose(i).map(|p| p.position())).collect(),
        lap_slots: rec
            .observations
            .iter()
            .map(|o| rec.truth.frame(o.frame_id).map(|f| f.lap_slot))
            .collect(),
        revisits,
        pair_counts,
        correct_pairs,
        wrong_pairs,
    }
}

impl ObsStatus {
    /// Polylines of consecutive observations of `kind` (in the same lap, at most 1 m apart).
    fn runs_of(&self, kind: Kind) -> Vec<Vec<crate::geom::Vec2>> {
        let mut out: Vec<Vec<crate::geom::Vec2>> = Vec::new();
        let mut cur: Vec<crate::geom::Vec2> = Vec::new();
        let mut last_slot = None;
        for i in 0..self.kinds.len() {
            let (Some(p), true) = (self.positions[i], self.kinds[i] == kind) else {
                if cur.len() > 1 {
                    out.push(std::mem::take(&mut cur));
                }
                cur.clear();
                continue;
            };
            let broken = last_slot != self.lap_slots[i]
                || cur
                    .last()
                    .is_some_and(|q: &crate::geom::Vec2| (p - q).norm() > 1.0);
            if broken && !cur.is_empty() {
                let done = std::mem::take(&mut cur);
                if done.len() > 1 {
                    out.push(done);
                }
            }
            last_slot = self.lap_slots[i];
            cur.push(p);
        }
        if cur.len() > 1 {
            out.push(cur);
        }
        out
    }
}

/// The `k` largest clusters of wrong pairs (query cell, past cell on a 5 m grid), each as the
/// mean query position, the mean past position and its size, largest first.
pub fn worst_wrong_clusters(
    wrong: &[(crate::geom::Vec2, crate::geom::Vec2)],
    k: usize,
) -> Vec<(crate::geom::Vec2, crate::geom::Vec2, usize)> {
    let cell = |p: crate::geom::Vec2| {
        (
            (p.x / CLUSTER_CELL_M).floor() as i64,
            (p.y / CLUSTER_CELL_M).floor() as i64,
        )
    };
    type Acc = (crate::geom::Vec2, crate::geom::Vec2, usize);
    type Cells = ((i64, i64), (i64, i64));
    let mut groups: HashMap<Cells, Acc> = HashMap::new();
    for &(a, b) in wrong {
        let g = groups.entry((cell(a), cell(b))).or_insert((
            crate::geom::Vec2::zeros(),
            crate::geom::Vec2::zeros(),
            0,
        ));
        g.0 += a;
        g.1 += b;
        g.2 += 1;
    }
    let mut list: Vec<(Cells, Acc)> = groups.into_iter().collect();
    // Largest first; ties by cell so the picture does not depend on hash order.
    list.sort_by(|x, y| y.1.2.cmp(&x.1.2).then(x.0.cmp(&y.0)));
    list.into_iter()
        .take(k)
        .map(|(_, (a, b, n))| (a / n as f64, b / n as f64, n))
        .collect()
}

/// Per lap (in driving order): recall of its observations with a revisit and precision of the
/// pairs whose query lies in it, with its door configuration; as an SVG strip.
pub fn lap_strip_svg(rec: &Recognition, spec: &EvaluationSpec, title: &str) -> String {
    let status = observation_status(rec, spec);
    let n = rec.truth.laps.len();
    let mut acc = vec![(0usize, 0usize, 0usize, 0usize); n];
    for i in 0..status.kinds.len() {
        let Some(slot) = status.lap_slots[i] else {
            continue;
        };
        let a = &mut acc[slot];
        if status.revisits[i] {
            a.0 += 1;
            a.1 += (status.pair_counts[i].0 > 0) as usize;
        }
        a.2 += status.pair_counts[i].1;
        a.3 += status.pair_counts[i].0;
    }
    let laps: Vec<LapPoint> = rec
        .truth
        .laps
        .iter()
        .zip(&acc)
        .map(|(l, &(rv, rc, pairs, ok))| LapPoint {
            run: l.run,
            door_config: l.door_config.clone(),
            recall: (rv > 0).then(|| rc as f64 / rv as f64),
            precision: (pairs > 0).then(|| ok as f64 / pairs as f64),
        })
        .collect();
    lap_strip(&laps, title)
}

/// An empty world for real logs, which come without a world file; the picture's extent follows
/// the overlays, and the home marker sits at the first true pose.
pub fn empty_world(runs: &[RunLog], name: &str) -> World {
    let home = runs
        .iter()
        .flat_map(|r| r.frames())
        .next()
        .map(|f| f.truth.0)
        .unwrap_or(crate::geom::Pose2::IDENTITY);
    World {
        name: name.to_string(),
        description: None,
        home,
        walls: Vec::new(),
        doors: Vec::new(),
        routes: Vec::new(),
        areas: Vec::new(),
    }
}

/// Writes an experiment's pictures into `dir`: `trajectory.svg` (true and odometry paths) and,
/// per level configuration (and ICP), `matches-X.svg` (the true path coloured by what was
/// recognized) and `laps-X.svg` (recall and precision per lap). Returns the files written.
pub fn write_pictures(
    exp: &super::Experiment,
    world: &World,
    radius_m: f64,
    dir: &Path,
) -> std::io::Result<Vec<PathBuf>> {
    let name = &exp.report.scenario;
    let mut pictures = vec![(
        "trajectory.svg".to_string(),
        trajectory_svg(world, &exp.runs, &format!("{name}: paths")),
    )];
    let recognitions = exp
        .recognitions
        .iter()
        .map(|(levels, rec)| (format!("{levels} level(s)"), format!("levels{levels}"), rec))
        .chain(exp.icp.iter().map(|rec| ("ICP".into(), "icp".into(), rec)))
        .chain(
            exp.scan_context
                .iter()
                .map(|rec| ("Scan Context".into(), "scan-context".into(), rec)),
        );
    for (what, file, rec) in recognitions {
        let title = format!("{name}: matched pairs, {what}");
        let svg = matches_svg(world, &exp.runs, rec, radius_m, &title);
        pictures.push((format!("matches-{file}.svg"), svg));
        let title = format!("{name}: recall and precision per lap, {what}");
        let svg = lap_strip_svg(rec, &exp.report.evaluation, &title);
        pictures.push((format!("laps-{file}.svg"), svg));
    }
    let mut written = Vec::new();
    for (file, svg) in pictures {
        let path = dir.join(file);
        crate::io::atomic::write_atomic(&path, svg.as_bytes()).map_err(|e| {
            std::io::Error::new(e.kind(), format!("{}: cannot write: {e}", path.display()))
        })?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{OdomPose, Pose2, TruePose};
    use crate::scan::{BeamLayout, Scan};
    use crate::sim::{Frame, LapLog};

    /// A run starting at (5, 3) facing +y, driving 2 m straight; odometry starts at (0, 0, 0)
    /// and drifts 2° to the left.
    fn run() -> RunLog {
        let layout = BeamLayout::centered(3, 1.0, 8.0, Pose2::IDENTITY);
        let frames = (0..=20)
            .map(|k| {
                let d = 0.1 * k as f64;
                Frame {
                    time_s: d,
                    odom: OdomPose(Pose2::new(d, 0.035 * d, 0.0)),
                    truth: TruePose(Pose2::new(5.0, 3.0 + d, std::f64::consts::FRAC_PI_2)),
                    scan: Scan {
                        layout: layout.clone(),
                        ranges_m: vec![8.0; 3],
                        time_s: d,
                    },
                }
            })
            .collect();
        RunLog {
            run: 0,
            laps: vec![LapLog {
                lap: 0,
                door_config: "all-closed".into(),
                open_doors: vec![],
                frames,
            }],
        }
    }

    /// Regression: odometry was drawn from (0, 0, 0), so in scenario A its loops lay rotated,
    /// outside the building. The picture's first odometry point is the first true pose.
    #[test]
    fn odometry_is_drawn_from_the_true_start() {
        let r = run();
        let pts = odometry_in_world(&r);
        assert!((pts[0] - crate::geom::Vec2::new(5.0, 3.0)).norm() < 1e-12);
        // 2 m of odometry along its own x axis is 2 m up the true heading.
        assert!(
            (pts[20] - crate::geom::Vec2::new(5.0 - 0.07, 5.0)).norm() < 1e-9,
            "{:?}",
            pts[20]
        );
        let world = empty_world(std::slice::from_ref(&r), "t");
        let svg = trajectory_svg(&world, std::slice::from_ref(&r), "t");
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG");
        let firsts: Vec<String> = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some("path"))
            .map(|n| {
                n.attribute("points")
                    .unwrap()
                    .split(' ')
                    .next()
                    .unwrap()
                    .to_string()
            })
            .collect();
        assert_eq!(firsts.len(), 2, "true path and odometry");
        assert_eq!(firsts[0], firsts[1]);
    }

    #[test]
    fn worst_clusters_are_largest_first() {
        let v = crate::geom::Vec2::new;
        let mut wrong = vec![(v(1.0, 1.0), v(30.0, 1.0)); 5];
        wrong.extend(vec![(v(12.0, 1.0), v(40.0, 1.0)); 2]);
        wrong.push((v(50.0, 50.0), v(0.0, 0.0)));
        let c = worst_wrong_clusters(&wrong, 2);
        assert_eq!(c.iter().map(|c| c.2).collect::<Vec<_>>(), [5, 2]);
        assert_eq!(c[0].0, v(1.0, 1.0));
    }

    /// True revisits that verification turned down are marked per 5 m cell with their count
    /// and the check that did most; look-alikes it turned down are not marked.
    #[test]
    fn turned_down_true_revisits_are_marked() {
        use crate::eval::RejectedTruth;
        use crate::recognizer::Direction;
        use crate::recognizer::Rejection;
        let at = |x: f64| TruePose(Pose2::new(x, 1.0, 0.0));
        let r = |q: f64, p: f64, reason: Rejection| RejectedTruth {
            query: at(q),
            past: at(p),
            direction: Direction::Same,
            check: reason.index(),
        };
        let checks: Vec<String> = Rejection::ALL.iter().map(|r| r.name().into()).collect();
        let rejected = [
            r(1.0, 1.2, Rejection::Turn),
            r(2.0, 2.3, Rejection::Turn),
            r(3.0, 3.1, Rejection::Sides),
            r(12.0, 12.5, Rejection::Travel),
            // A look-alike 20 m away.
            r(30.0, 10.0, Rejection::Turn),
        ];
        let marks = turned_down_marks(&rejected, &checks, &EvaluationSpec::default(), 8);
        let texts: Vec<&str> = marks.iter().map(|m| m.text.as_str()).collect();
        assert_eq!(texts, ["3 Tu", "1 Tr"]);
        assert_eq!(marks[0].at, crate::geom::Vec2::new(2.0, 1.0));
        assert_eq!(
            turned_down_marks(&rejected, &checks, &EvaluationSpec::default(), 1).len(),
            1
        );
    }
}
