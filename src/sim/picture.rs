//! An SVG picture of a simulated run: the world (walls, and doors as they were in the first
//! lap), the true path, and the odometry path drawn from the same start so that its drift shows.
//!
//! Kept minimal and dependency-free; the `report` module may take it over.

use crate::geom::Pose2;
use crate::sim::RunLog;
use crate::world::{DoorStates, World};
use std::fmt::Write as _;

/// The SVG text for `run` in `world`.
pub fn run_svg(world: &World, run: &RunLog) -> String {
    let (lo, hi) = world.bounds();
    let margin = 1.0;
    let (w, h) = (hi.x - lo.x + 2.0 * margin, hi.y - lo.y + 2.0 * margin);
    let scale = 900.0 / w.max(h).max(1e-6);
    // World (x, y) to picture coordinates (y down).
    let px = |x: f64| (x - lo.x + margin) * scale;
    let py = |y: f64| (hi.y + margin - y) * scale;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" viewBox="0 0 {:.1} {:.1}">"#,
        w * scale,
        h * scale,
        w * scale,
        h * scale
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        "<title>{} run {}: true path (blue), odometry (red)</title>",
        world.name, run.run
    );
    for wall in &world.walls {
        for seg in wall.segments() {
            let _ = writeln!(
                s,
                r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#333" stroke-width="{:.2}" stroke-linecap="square"/>"##,
                px(seg.a.x),
                py(seg.a.y),
                px(seg.b.x),
                py(seg.b.y),
                (wall.thickness_m * scale).max(1.0)
            );
        }
    }
    let open: Vec<bool> = world
        .doors
        .iter()
        .map(|d| {
            run.laps
                .first()
                .is_some_and(|l| l.open_doors.contains(&d.id))
        })
        .collect();
    let states = DoorStates { open };
    for (i, d) in world.doors.iter().enumerate() {
        let p = d.panel(states.is_open(i));
        let _ = writeln!(
            s,
            r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#b8860b" stroke-width="{:.2}"/>"##,
            px(p.a.x),
            py(p.a.y),
            px(p.b.x),
            py(p.b.y),
            (d.thickness_m * scale).max(1.5)
        );
    }
    let frames: Vec<_> = run.frames().collect();
    if let Some(first) = frames.first() {
        let truth: Vec<Pose2> = frames.iter().map(|f| f.truth.0).collect();
        // Odometry re-anchored at the first true pose: truth₀ ⊕ (odom₀⁻¹ ⊕ odomᵢ).
        let anchor = first.truth.0;
        let o0 = first.odom.0;
        let odom: Vec<Pose2> = frames
            .iter()
            .map(|f| anchor.compose(&o0.between(&f.odom.0)))
            .collect();
        for (poses, colour) in [(&odom, "#d62728"), (&truth, "#1f77b4")] {
            let _ = write!(
                s,
                r#"<polyline fill="none" stroke="{colour}" stroke-width="1.2" points=""#
            );
            for p in poses.iter() {
                let _ = write!(s, "{:.1},{:.1} ", px(p.x), py(p.y));
            }
            let _ = writeln!(s, r#""/>"#);
        }
    }
    s.push_str("</svg>\n");
    s
}
