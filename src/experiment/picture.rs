//! Pictures of an experiment: the world with the true and odometry paths, and with the matched
//! pairs of a recognition drawn between their true positions, green when correct, red when not.

use crate::eval::Recognition;
use crate::eval::metrics::scored_pairs;
use crate::log::RunLog;
use crate::report::world_render::{
    LegendEntry, PathOverlay, RenderOptions, SegmentOverlay, render_world_svg,
};
use crate::world::World;

/// Most segments drawn for matched pairs; beyond it every k-th pair is drawn (a picture of
/// 80,000 lines is neither readable nor small).
pub const MAX_PAIR_SEGMENTS: usize = 4000;

const TRUE_COLOR: &str = "#1f77b4";
const ODOM_COLOR: &str = "#ff7f0e";
const CORRECT_COLOR: &str = "#2ca02c";
const WRONG_COLOR: &str = "#d62728";

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

/// The world with each run's true path and odometry path.
pub fn trajectory_svg(world: &World, runs: &[RunLog], title: &str) -> String {
    let mut opts = plain(world, title.to_string());
    opts.paths = true_paths(runs, "true path");
    opts.paths
        .extend(runs.iter().enumerate().map(|(i, r)| PathOverlay {
            label: if i == 0 {
                "odometry".into()
            } else {
                String::new()
            },
            color: ODOM_COLOR.into(),
            points: r.frames().map(|f| f.odom.0.position()).collect(),
            dashed: true,
        }));
    render_world_svg(world, &opts)
}

/// The world with the true path and every matched pair of `rec` between its true positions.
pub fn matches_svg(
    world: &World,
    runs: &[RunLog],
    rec: &Recognition,
    radius_m: f64,
    title: &str,
) -> String {
    let pairs = scored_pairs(rec, radius_m);
    let step = pairs.len().div_ceil(MAX_PAIR_SEGMENTS).max(1);
    let correct = pairs.iter().filter(|p| p.correct).count();
    let mut opts = plain(world, title.to_string());
    opts.paths = true_paths(runs, "true path");
    // Wrong pairs last, so they are drawn on top.
    let mut segs: Vec<(bool, SegmentOverlay)> = pairs
        .iter()
        .step_by(step)
        .map(|p| {
            (
                p.correct,
                SegmentOverlay {
                    color: if p.correct {
                        CORRECT_COLOR
                    } else {
                        WRONG_COLOR
                    }
                    .into(),
                    a: p.query_truth.0.position(),
                    b: p.past_truth.0.position(),
                },
            )
        })
        .collect();
    segs.sort_by_key(|(ok, _)| !*ok);
    opts.segments = segs.into_iter().map(|(_, s)| s).collect();
    let note = if step > 1 {
        format!(" (every {step}th drawn)")
    } else {
        String::new()
    };
    opts.legend = vec![
        LegendEntry {
            label: format!("correct pair ({correct}){note}"),
            color: CORRECT_COLOR.into(),
            dashed: false,
        },
        LegendEntry {
            label: format!("wrong pair ({})", pairs.len() - correct),
            color: WRONG_COLOR.into(),
            dashed: false,
        },
    ];
    render_world_svg(world, &opts)
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
