//! Pictures of an experiment: the world with the true and odometry paths (odometry placed at the
//! run's true start, one colour per run, each run's start marked); the true path coloured where
//! revisits were recognized, recognized wrongly and missed, with the worst clusters of wrong
//! pairs as dashed lines and rings where verification turned down true revisits; and a strip of
//! recall and precision per lap with the door configurations marked. Every picture draws the
//! doors as the laps it shows had them, and says so when they differ between laps.

use crate::eval::Recognition;
use crate::eval::observation_status::{
    CLUSTER_CELL_M, ObservationKind, ObservationStatus, observation_status, worst_wrong_clusters,
};
use crate::eval::scores::RejectedScores;
use crate::log::RunLog;
use crate::report::lap_strip::{LapPoint, lap_strip};
use crate::report::world_render::{
    LegendEntry, MarkOverlay, PathOverlay, RenderOptions, SegmentOverlay, render_world_svg,
};
use crate::spec::evaluation::EvaluationSpec;
use crate::world::World;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const TRUE_COLOR: &str = "#1f77b4";
const ODOM_COLOR: &str = "#ff7f0e";
const CORRECT_COLOR: &str = "#2ca02c";
const WRONG_COLOR: &str = "#d62728";
/// Wrong-pair cluster lines: darker than the "most pairs wrong" path and dashed, so the two
/// legend rows are told apart.
const WRONG_LINE_COLOR: &str = "#7f0000";
/// Missed revisits: a blue far from the walls' near-black and from every other status colour.
const MISSED_COLOR: &str = "#1a9bd7";
const PLAIN_COLOR: &str = "#c7c7c7";
const TURNED_DOWN_COLOR: &str = "#9467bd";
/// One colour per run in pictures of several runs (cycled past eight runs).
const RUN_COLORS: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f",
];
/// Runs named one by one in a legend; later runs reuse the colours unnamed.
const RUNS_IN_LEGEND: usize = 8;
/// Laps listed one by one in a picture's door notes.
const LAPS_IN_NOTES: usize = 12;
/// Door ids listed per lap in the notes.
const DOORS_PER_NOTE: usize = 12;
/// Width of a status path drawn over the plain true path, pixels.
const STATUS_WIDTH_PX: f64 = 2.5;
const PLAIN_WIDTH_PX: f64 = 1.5;

fn path(label: String, color: &str, points: Vec<crate::geom::Vec2>, dashed: bool) -> PathOverlay {
    PathOverlay {
        label,
        color: color.into(),
        points,
        dashed,
        width_px: PLAIN_WIDTH_PX,
    }
}

fn true_paths(runs: &[RunLog], label: &str) -> Vec<PathOverlay> {
    runs.iter()
        .enumerate()
        .map(|(i, r)| {
            let label = if i == 0 { label } else { "" };
            let points = r.frames().map(|f| f.truth.0.position()).collect();
            path(label.to_string(), TRUE_COLOR, points, false)
        })
        .collect()
}

/// The doors a picture spanning `runs` draws: a door is drawn open when it was open in some lap
/// shown. When the laps' doors differ, the subtitle says so and the notes list each lap's open
/// doors (the first [`LAPS_IN_NOTES`] laps), so the picture never shows a state no lap had
/// without saying it.
struct DoorsSeen {
    states: crate::world::DoorStates,
    summary: Option<String>,
    notes: Vec<String>,
}

fn doors_seen(world: &World, runs: &[RunLog]) -> DoorsSeen {
    let mut states = crate::world::DoorStates::all_closed(world);
    let laps: Vec<&crate::log::LapLog> = runs.iter().flat_map(|r| &r.laps).collect();
    for lap in &laps {
        for id in &lap.open_doors {
            if let Some(i) = world.doors.iter().position(|d| &d.id == id) {
                states.open[i] = true;
            }
        }
    }
    let differ = laps.windows(2).any(|w| {
        let key = |l: &crate::log::LapLog| {
            let mut v = l.open_doors.clone();
            v.sort();
            v
        };
        key(w[0]) != key(w[1])
    });
    if !differ {
        return DoorsSeen {
            states,
            summary: None,
            notes: Vec::new(),
        };
    }
    let n_open = states.open.iter().filter(|o| **o).count();
    let summary = Some(format!(
        "{} doors, {n_open} open in some lap (drawn open; each lap's open doors listed below)",
        world.doors.len()
    ));
    let mut notes: Vec<String> = Vec::new();
    for r in runs {
        for lap in &r.laps {
            if notes.len() == LAPS_IN_NOTES {
                break;
            }
            let open = match lap.open_doors.len() {
                0 => "every door closed".to_string(),
                n if n <= DOORS_PER_NOTE => format!("open {}", lap.open_doors.join(", ")),
                n => format!(
                    "open {} and {} more",
                    lap.open_doors[..DOORS_PER_NOTE].join(", "),
                    n - DOORS_PER_NOTE
                ),
            };
            notes.push(format!(
                "run {} lap {} ({}): {open}",
                r.run, lap.lap, lap.door_config
            ));
        }
    }
    if laps.len() > notes.len() {
        notes.push(format!("... and {} more laps", laps.len() - notes.len()));
    }
    DoorsSeen {
        states,
        summary,
        notes,
    }
}

/// A picture of `runs` on the world: the doors as the laps had them (see [`DoorsSeen`]) and a
/// mark at each run's start.
fn plain(world: &World, runs: &[RunLog], title: String) -> RenderOptions {
    let seen = doors_seen(world, runs);
    let multi = runs.len() > 1;
    let marks = runs
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let first = r.frames().next()?;
            Some(MarkOverlay {
                at: first.truth.0.position(),
                text: format!("run {} start", r.run),
                color: if multi {
                    RUN_COLORS[i % RUN_COLORS.len()]
                } else {
                    TRUE_COLOR
                }
                .into(),
                class: "run-start".into(),
            })
        })
        .collect();
    RenderOptions {
        title: Some(title),
        show_routes: false,
        show_areas: false,
        show_door_labels: false,
        doors: seen.states,
        door_summary: seen.summary,
        notes: seen.notes,
        marks,
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

/// The world with each run's true path and odometry path (drawn from the run's true start),
/// each run's start marked. With several runs each run has its own colour (odometry dashed in
/// it), so the laps of one run are told from another's.
pub fn trajectory_svg(world: &World, runs: &[RunLog], title: &str) -> String {
    let mut opts = plain(world, runs, title.to_string());
    if runs.len() <= 1 {
        opts.paths = true_paths(runs, "true path");
        opts.paths.extend(runs.iter().map(|r| {
            let label = "odometry (from the true start)".to_string();
            path(label, ODOM_COLOR, odometry_in_world(r), true)
        }));
        return render_world_svg(world, &opts);
    }
    for (i, r) in runs.iter().enumerate() {
        let color = RUN_COLORS[i % RUN_COLORS.len()];
        let laps = r.laps.len();
        let label = if i < RUNS_IN_LEGEND {
            format!("run {}: true path ({laps} lap{})", r.run, plural(laps))
        } else {
            String::new()
        };
        let truth = r.frames().map(|f| f.truth.0.position()).collect();
        opts.paths.push(path(label, color, truth, false));
        opts.paths
            .push(path(String::new(), color, odometry_in_world(r), true));
    }
    opts.legend.push(LegendEntry {
        label: "dashed: the run's odometry (from its true start)".into(),
        color: "#555555".into(),
        dashed: true,
    });
    if runs.len() > RUNS_IN_LEGEND {
        opts.notes.push(format!(
            "runs {}-{} reuse the colours above",
            runs[RUNS_IN_LEGEND].run,
            runs[runs.len() - 1].run
        ));
    }
    render_world_svg(world, &opts)
}

/// "s" unless `n` is 1.
fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// The world with the true path coloured where revisits were recognized, recognized wrongly
/// and missed (see [`ObservationStatus`]), and the worst clusters of wrong pairs as lines,
/// judged by `spec`: the rule the run's report was scored with (radius, gap, headings).
pub fn matches_svg(
    world: &World,
    runs: &[RunLog],
    rec: &Recognition,
    spec: &EvaluationSpec,
    title: &str,
) -> String {
    let status = observation_status(rec, spec);
    let mut opts = plain(world, runs, title.to_string());
    opts.paths = true_paths(runs, "true path, no revisit");
    for p in &mut opts.paths {
        p.color = PLAIN_COLOR.into();
    }
    // Missed first, so the recognized and the wrong stretches are drawn over it.
    for kind in [
        ObservationKind::Missed,
        ObservationKind::Recognized,
        ObservationKind::Wrong,
    ] {
        opts.paths.extend(
            runs_of(&status, kind)
                .into_iter()
                .map(|points| PathOverlay {
                    width_px: STATUS_WIDTH_PX,
                    ..path(String::new(), kind_color(kind), points, false)
                }),
        );
    }
    let checks = rec
        .diagnostics
        .as_ref()
        .map(|d| d.checks())
        .unwrap_or_default();
    // The true revisits turned down, and those recognized later all the same (the query
    // observation the newer side of a correct pair), counted as the report counts them.
    let recognized: Vec<bool> = status.pair_counts.iter().map(|c| c.0 > 0).collect();
    let turned_down = RejectedScores::of(&rec.rejected, &checks, spec, &recognized);
    opts.marks.extend(turned_down_marks(
        &rec.rejected,
        &checks,
        spec,
        2 * WORST_CLUSTERS,
    ));
    let clusters = worst_wrong_clusters(&status.wrong_pairs, WORST_CLUSTERS);
    let shown: usize = clusters.iter().map(|c| c.2).sum();
    opts.segments = clusters
        .iter()
        .map(|&(a, b, _)| SegmentOverlay {
            color: WRONG_LINE_COLOR.into(),
            a,
            b,
            dashed: true,
        })
        .collect();
    opts.legend
        .extend(status_legend(&status, clusters.len(), shown));
    let mut notes = pair_notes(&status, turned_down.as_ref());
    notes.append(&mut opts.notes);
    opts.notes = notes;
    render_world_svg(world, &opts)
}

/// The matches picture's legend: a row only for what it shows (each kind of observation
/// drawn, and the `clusters` dashed lines of `shown` wrong pairs).
fn status_legend(status: &ObservationStatus, clusters: usize, shown: usize) -> Vec<LegendEntry> {
    let legend = |label: String, color: &str, dashed: bool| LegendEntry {
        label,
        color: color.into(),
        dashed,
    };
    let counts = |k: ObservationKind| status.kinds.iter().filter(|x| **x == k).count();
    let rows = [
        (
            ObservationKind::Recognized,
            "recognized, most pairs correct",
        ),
        (ObservationKind::Wrong, "recognized, most pairs wrong"),
        (ObservationKind::Missed, "revisit missed"),
    ];
    let mut out = Vec::new();
    for (kind, what) in rows {
        let n = counts(kind);
        if n > 0 {
            let label = format!("{what} ({n} observation{})", plural(n));
            out.push(legend(label, kind_color(kind), false));
        }
    }
    if clusters > 0 {
        let label = format!(
            "dashed lines: the worst {} wrong-pair cluster{} ({shown} pair{})",
            clusters,
            plural(clusters),
            plural(shown)
        );
        out.push(legend(label, WRONG_LINE_COLOR, true));
    }
    out
}

/// The matches picture's notes: the pairs, and what verification turned down (`turned_down`:
/// the candidates sampled, scored as the report scores them), in the text table's words.
fn pair_notes(status: &ObservationStatus, turned_down: Option<&RejectedScores>) -> Vec<String> {
    let mut notes = vec![format!(
        "pairs: {} correct, {} wrong",
        status.correct_pairs,
        status.wrong_pairs.len()
    )];
    if let Some(r) = turned_down {
        notes.push(crate::report::explain::turned_down_sentence(r));
        if r.correct > 0 {
            notes.push(
                "purple rings: true revisits turned down per 5 m, and the check that did most \
                 (Tr travel, Tu turn, D density, S sides, St straight)"
                    .into(),
            );
        }
    }
    notes
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
/// The colour the matches picture gives an observation's kind.
fn kind_color(kind: ObservationKind) -> &'static str {
    match kind {
        ObservationKind::Plain => PLAIN_COLOR,
        ObservationKind::Recognized => CORRECT_COLOR,
        ObservationKind::Wrong => WRONG_COLOR,
        ObservationKind::Missed => MISSED_COLOR,
    }
}

/// Polylines of consecutive observations of `kind` (in the same lap, at most 1 m apart).
fn runs_of(status: &ObservationStatus, kind: ObservationKind) -> Vec<Vec<crate::geom::Vec2>> {
    let mut out: Vec<Vec<crate::geom::Vec2>> = Vec::new();
    let mut cur: Vec<crate::geom::Vec2> = Vec::new();
    let mut last_slot = None;
    for i in 0..status.kinds.len() {
        let (Some(p), true) = (status.positions[i], status.kinds[i] == kind) else {
            if cur.len() > 1 {
                out.push(std::mem::take(&mut cur));
            }
            cur.clear();
            continue;
        };
        let broken = last_slot != status.lap_slots[i]
            || cur
                .last()
                .is_some_and(|q: &crate::geom::Vec2| (p - q).norm() > 1.0);
        if broken && !cur.is_empty() {
            let done = std::mem::take(&mut cur);
            if done.len() > 1 {
                out.push(done);
            }
        }
        last_slot = status.lap_slots[i];
        cur.push(p);
    }
    if cur.len() > 1 {
        out.push(cur);
    }
    out
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

/// Writes an experiment's pictures into `dir`: `trajectory.svg` (true and odometry paths; with
/// several runs also `trajectory-run-NNN.svg` per run) and,
/// per level configuration (and ICP), `matches-X.svg` (the true path coloured by what was
/// recognized) and `laps-X.svg` (recall and precision per lap). Returns the files written.
pub fn write_pictures(
    exp: &super::Experiment,
    world: &World,
    dir: &Path,
) -> std::io::Result<Vec<PathBuf>> {
    let name = &exp.report.scenario;
    let mut pictures = vec![(
        "trajectory.svg".to_string(),
        trajectory_svg(world, &exp.runs, &format!("{name}: paths")),
    )];
    // With several runs the overview is a bundle: each run also gets a picture of its own.
    if exp.runs.len() > 1 {
        for r in &exp.runs {
            let title = format!("{name}: run {}, true path and odometry", r.run);
            let svg = trajectory_svg(world, std::slice::from_ref(r), &title);
            pictures.push((format!("trajectory-run-{:03}.svg", r.run), svg));
        }
    }
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
        let svg = matches_svg(world, &exp.runs, rec, &exp.report.evaluation, &title);
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

    fn loop_small() -> World {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/loop-small.toml");
        crate::world::load::load_world(&path).expect("shipped world")
    }

    /// `run()` moved into `world`, as run `k`, with `open` doors open in its one lap.
    fn run_in(world: &World, k: usize, open: &[usize]) -> RunLog {
        let mut r = run();
        r.run = k;
        r.laps[0].open_doors = open.iter().map(|&i| world.doors[i].id.clone()).collect();
        r
    }

    fn doc_texts(svg: &str) -> Vec<String> {
        let doc = roxmltree::Document::parse(svg).expect("valid SVG");
        doc.descendants()
            .filter(|n| n.tag_name().name() == "text")
            .filter_map(|n| n.text().map(str::to_string))
            .collect()
    }

    /// Regression (issue 27): run pictures drew every door closed ("0 open") when the laps had
    /// doors open, and marked only the robot's home. Now a door open in some lap is drawn open,
    /// the subtitle and notes say which lap had which, and each run's start is marked.
    #[test]
    fn pictures_draw_the_laps_doors_and_each_runs_start() {
        let world = loop_small();
        let runs = [run_in(&world, 0, &[2]), run_in(&world, 1, &[])];
        let svg = trajectory_svg(&world, &runs, "t");
        let doc = roxmltree::Document::parse(&svg).expect("valid SVG");
        let open: Vec<&str> = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some("door open"))
            .filter_map(|n| n.attribute("id"))
            .collect();
        assert_eq!(open, [format!("door-{}", world.doors[2].id)]);
        let texts = doc_texts(&svg);
        assert!(
            texts.iter().any(|t| t.contains("1 open in some lap")),
            "{texts:?}"
        );
        let lap0 = format!("run 0 lap 0 (all-closed): open {}", world.doors[2].id);
        assert!(texts.contains(&lap0), "{texts:?}");
        assert!(texts.contains(&"run 1 lap 0 (all-closed): every door closed".to_string()));
        let starts = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some("run-start"))
            .count();
        assert_eq!(starts, 2, "one start mark per run");
        // One colour per run: the two true paths differ in colour.
        let colours: std::collections::HashSet<&str> = doc
            .descendants()
            .filter(|n| n.attribute("class") == Some("path"))
            .filter_map(|n| n.attribute("stroke"))
            .collect();
        assert_eq!(colours.len(), 2, "{colours:?}");

        // Laps with the same doors: the plain subtitle, no lap notes.
        let same = [run_in(&world, 0, &[2]), run_in(&world, 1, &[2])];
        let texts = doc_texts(&trajectory_svg(&world, &same, "t"));
        assert!(
            texts.iter().any(|t| t.contains("doors (1 open)")),
            "{texts:?}"
        );
        assert!(!texts.iter().any(|t| t.starts_with("run 0 lap")));
    }

    /// The matches picture's legend has a row only for what it draws, with counts that say
    /// what they count, and the wrong-pair lines are dashed in a colour of their own.
    #[test]
    fn matches_legend_rows_only_for_what_is_drawn() {
        use crate::eval::{GroundTruth, Recognition};
        let world = loop_small();
        let runs = [run_in(&world, 0, &[])];
        let truth = std::sync::Arc::new(GroundTruth::from_runs(&runs));
        let rec = Recognition::new("none", Vec::new(), Vec::new(), 1, truth);
        let spec = EvaluationSpec {
            tp_radius_m: 0.5,
            ..EvaluationSpec::default()
        };
        let texts = doc_texts(&matches_svg(&world, &runs, &rec, &spec, "t"));
        for absent in [
            "most pairs wrong",
            "most pairs correct",
            "revisit missed",
            "dashed lines",
        ] {
            assert!(
                !texts.iter().any(|t| t.contains(absent)),
                "{absent}: {texts:?}"
            );
        }
        assert!(texts.contains(&"pairs: 0 correct, 0 wrong".to_string()));
        assert_eq!(plural(1), "");
        assert_eq!(plural(2), "s");
    }

    /// The picture judges revisits by the run's whole rule, not by its radius alone: a gap the
    /// report was scored with (`recognize --min-gap-m`) decides what it draws as missed.
    #[test]
    fn matches_picture_follows_the_reports_rule() {
        let world = loop_small();
        let runs = [run_in(&world, 0, &[])];
        // Two laps of a 40 m circle, no match: what has a revisit depends on the gap.
        let (obs, truth) = crate::eval::metrics::tests::circle(2, 40.0);
        let rec = crate::eval::metrics::tests::recognition(&obs, &truth, Vec::new());
        let missed = |min_gap_m: f64| {
            let spec = EvaluationSpec {
                min_gap_m,
                ..EvaluationSpec::default()
            };
            let drawn = doc_texts(&matches_svg(&world, &runs, &rec, &spec, "t"))
                .into_iter()
                .find(|t| t.starts_with("revisit missed"));
            let revisits = crate::eval::evaluate(&rec, &spec).main.revisits;
            (drawn, revisits)
        };
        let (near, far) = (missed(20.0), missed(50.0));
        assert!(near.1 > far.1 && far.1 > 0, "{near:?} {far:?}");
        for (drawn, revisits) in [near, far] {
            assert_eq!(
                drawn,
                Some(format!("revisit missed ({revisits} observations)"))
            );
        }
    }

    /// The notes say how many of the true revisits turned down were recognized later all the
    /// same, beside the look-alikes turned down.
    #[test]
    fn turned_down_notes_count_the_revisits_recognized_later() {
        let status = crate::eval::observation_status::ObservationStatus {
            kinds: Vec::new(),
            positions: Vec::new(),
            lap_slots: Vec::new(),
            revisits: Vec::new(),
            pair_counts: Vec::new(),
            correct_pairs: 3,
            wrong_pairs: Vec::new(),
        };
        let turned_down = RejectedScores {
            sampled: 5,
            correct: 2,
            correct_recognized: 1,
            ..Default::default()
        };
        let notes = pair_notes(&status, Some(&turned_down));
        assert!(
            notes.contains(
                &"verification turned down 2 true revisits (1 recognized later all the same, 1 \
                  lost) and 3 look-alikes (of 5 candidates sampled)"
                    .to_string()
            ),
            "{notes:?}"
        );
        assert_eq!(
            pair_notes(&status, None).len(),
            1,
            "no sentence without candidates"
        );
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
            query_index: 0,
            query: at(q),
            past: at(p),
            direction: Direction::Same,
            check: reason.index(),
            oldest: None,
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
