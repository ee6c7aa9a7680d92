//! A world generator for stress tests and examples: a corridor loop (a rectangle with corners
//! cut away, so 4, 6, 8, 10 or 12 corridors), offices outside the loop each with one door that
//! swings into it, niches in the courtyard wall at random places so that stretches of corridor
//! differ, and a lap route along the corridors' centre lines.
//!
//! Deterministic per seed: every draw comes from one ChaCha stream keyed by the seed
//! ([`crate::sim::rng::stream`] with [`Purpose::WorldGenerator`]).

use crate::geom::Vec2;
use crate::sim::rng::{Purpose, SimRng, stream};
use crate::spec::world::{DoorSpec, HomeSpec, RouteSpec, WallSpec, WorldSpec};
use rand::RngExt;

/// Corridor width, metres.
pub const CORRIDOR_M: f64 = 2.0;
/// Office depth behind the corridor wall, metres.
pub const ROOM_DEPTH_M: f64 = 3.0;
/// Door panel width, metres.
pub const DOOR_M: f64 = 0.9;
/// Offices keep this far from the ends of their corridor's centre line, metres.
const ROOM_END_MARGIN_M: f64 = CORRIDOR_M / 2.0 + ROOM_DEPTH_M + 0.5;
/// Margin between the offices and the floor's edge, metres.
const EDGE_M: f64 = CORRIDOR_M / 2.0 + ROOM_DEPTH_M + 0.2;

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct GenerateOptions {
    pub seed: u64,
    /// Floor size (x, y), metres. Default 40 × 30.
    pub size_m: (f64, f64),
    /// Number of offices, each with one door. Default 12.
    pub doors: usize,
    /// Corridors of the loop: 4, 6, 8, 10 or 12. Default 4.
    pub corridors: usize,
}

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions {
            seed: 1,
            size_m: (40.0, 30.0),
            doors: 12,
            corridors: 4,
        }
    }
}

/// Why a floor could not be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    #[error(
        "--corridors {0}: the loop is a rectangle with corners cut away, so it has 4, 6, 8, 10 or 12 corridors"
    )]
    Corridors(usize),
    #[error("--size-m {0}x{1}: the floor must be between 24 m and 2000 m on each side")]
    Size(f64, f64),
    #[error(
        "--doors {asked}: only {fit} offices fit along the corridors of this floor; ask for fewer doors or a larger --size-m"
    )]
    Doors { asked: usize, fit: usize },
    #[error(
        "the generated floor does not pass the checks (a generator bug, please report it with the seed):\n{0}"
    )]
    Invalid(String),
}

fn round_cm(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// The corridor loop's centre line, counter-clockwise: a rectangle with `cuts` corners cut away.
fn centre_loop(rng: &mut SimRng, w: f64, h: f64, cuts: usize) -> Vec<Vec2> {
    let (x0, y0, x1, y1) = (EDGE_M, EDGE_M, w - EDGE_M, h - EDGE_M);
    let corners = [
        Vec2::new(x0, y0),
        Vec2::new(x1, y0),
        Vec2::new(x1, y1),
        Vec2::new(x0, y1),
    ];
    // Inward directions from each corner along x and y.
    let inward = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)];
    let mut out = Vec::new();
    for (k, c) in corners.iter().enumerate() {
        if k >= cuts {
            out.push(*c);
            continue;
        }
        let cx = rng.random_range(0.2..0.3) * (x1 - x0);
        let cy = rng.random_range(0.2..0.3) * (y1 - y0);
        let (sx, sy) = inward[k];
        let a = *c + Vec2::new(0.0, sy * cy);
        let m = *c + Vec2::new(sx * cx, sy * cy);
        let b = *c + Vec2::new(sx * cx, 0.0);
        // Counter-clockwise: arrive along the previous edge, leave along the next.
        if k % 2 == 0 {
            out.extend([a, m, b]);
        } else {
            out.extend([b, m, a]);
        }
    }
    out.iter()
        .map(|p| Vec2::new(round_cm(p.x), round_cm(p.y)))
        .collect()
}

/// One office slot: corridor edge, start and end along it (metres from the edge's start).
#[derive(Clone, Copy, Debug)]
struct Slot {
    edge: usize,
    from: f64,
    to: f64,
}

/// Office slots of 3.5-5 m along every edge, clear of the corners.
fn slots(rng: &mut SimRng, loop_pts: &[Vec2]) -> Vec<Slot> {
    let n = loop_pts.len();
    let mut out = Vec::new();
    for e in 0..n {
        let len = (loop_pts[(e + 1) % n] - loop_pts[e]).norm();
        let mut at = ROOM_END_MARGIN_M;
        loop {
            let w = round_cm(rng.random_range(3.5..5.0));
            if at + w > len - ROOM_END_MARGIN_M {
                break;
            }
            out.push(Slot {
                edge: e,
                from: at,
                to: at + w,
            });
            at += w;
        }
    }
    out
}

/// A frame along edge `e`: its start, unit direction and outward (right-hand) normal.
fn edge_frame(loop_pts: &[Vec2], e: usize) -> (Vec2, Vec2, Vec2) {
    let n = loop_pts.len();
    let (a, b) = (loop_pts[e], loop_pts[(e + 1) % n]);
    let d = (b - a) / (b - a).norm();
    (a, d, Vec2::new(d.y, -d.x))
}

fn pt(p: Vec2) -> [f64; 2] {
    [round_cm(p.x), round_cm(p.y)]
}

/// Offsets a counter-clockwise rectilinear loop by `d` to the left (inward for d > 0).
fn offset(loop_pts: &[Vec2], d: f64) -> Vec<Vec2> {
    let n = loop_pts.len();
    (0..n)
        .map(|i| {
            let (_, din, _) = edge_frame(loop_pts, (i + n - 1) % n);
            let (_, dout, _) = edge_frame(loop_pts, i);
            let (nin, nout) = (Vec2::new(-din.y, din.x), Vec2::new(-dout.y, dout.x));
            // Rectilinear corners: the two offsets add.
            loop_pts[i] + (nin + nout) * d
        })
        .collect()
}

/// The courtyard wall: the loop offset inward, with a niche on about two edges in three.
fn courtyard_wall(rng: &mut SimRng, loop_pts: &[Vec2]) -> Vec<[f64; 2]> {
    let inner = offset(loop_pts, CORRIDOR_M / 2.0);
    let n = inner.len();
    let mut out = Vec::new();
    for e in 0..n {
        out.push(pt(inner[e]));
        let (a, b) = (inner[e], inner[(e + 1) % n]);
        let len = (b - a).norm();
        let width = rng.random_range(1.0..2.5);
        let depth = rng.random_range(0.5..1.2);
        let wanted = rng.random_bool(0.7);
        if !wanted || len < width + 5.0 {
            continue;
        }
        let d = (b - a) / len;
        let left = Vec2::new(-d.y, d.x);
        let t0 = rng.random_range(2.5..len - 2.5 - width);
        let p0 = a + d * t0;
        let p1 = p0 + d * width;
        out.extend([p0, p0 + left * depth, p1 + left * depth, p1].map(pt));
    }
    out
}

/// An office at `slot` with its door: the office walls (back and left side; the right side
/// too unless the next office shares it) and the door spec. The door's gap is cut from the
/// corridor wall by the caller.
fn office(
    rng: &mut SimRng,
    loop_pts: &[Vec2],
    slot: Slot,
    shares_right: bool,
    index: usize,
) -> (WallSpec, DoorSpec, f64) {
    let (a, d, out) = edge_frame(loop_pts, slot.edge);
    let at = |t: f64, o: f64| pt(a + d * t + out * o);
    let (front, back) = (CORRIDOR_M / 2.0, CORRIDOR_M / 2.0 + ROOM_DEPTH_M);
    let mut points = vec![at(slot.from, front), at(slot.from, back), at(slot.to, back)];
    if !shares_right {
        points.push(at(slot.to, front));
    }
    let g0 = round_cm(rng.random_range(slot.from + 0.3..slot.to - DOOR_M - 0.3));
    let heading = |v: Vec2| round_cm(v.y.atan2(v.x).to_degrees());
    let wall = WallSpec {
        id: format!("office-{:02}", index + 1),
        points_m: points,
        closed: false,
        thickness_m: crate::spec::world::default_wall_thickness_m(),
    };
    let door = DoorSpec {
        id: format!("d-{:02}", index + 1),
        hinge_m: at(g0, front),
        width_m: DOOR_M,
        closed_heading_deg: heading(d),
        open_heading_deg: heading(out),
        thickness_m: crate::spec::world::default_door_thickness_m(),
    };
    (wall, door, g0)
}

/// The corridor's outer wall, cut at the door gaps `(edge, from)` (sorted): one closed wall
/// without doors, else one open polyline from each gap's end to the next gap's start.
fn corridor_wall(loop_pts: &[Vec2], gaps: &[(usize, f64)]) -> Vec<WallSpec> {
    let outer = offset(loop_pts, -CORRIDOR_M / 2.0);
    let n = outer.len();
    let wall = |k: usize, points_m: Vec<[f64; 2]>, closed: bool| WallSpec {
        id: format!("corridor-{k}"),
        points_m,
        closed,
        thickness_m: crate::spec::world::default_wall_thickness_m(),
    };
    if gaps.is_empty() {
        return vec![wall(1, outer.iter().map(|p| pt(*p)).collect(), true)];
    }
    let on = |e: usize, t: f64| {
        let (a, d, o) = edge_frame(loop_pts, e);
        pt(a + d * t + o * (CORRIDOR_M / 2.0))
    };
    let mut walls = Vec::new();
    for (k, &(e, g)) in gaps.iter().enumerate() {
        let (e2, g2) = gaps[(k + 1) % gaps.len()];
        let mut points = vec![on(e, g + DOOR_M)];
        let ahead_on_edge = e2 == e && g2 > g && gaps.len() > 1;
        let steps = match (e2 + n - e) % n {
            _ if ahead_on_edge => 0,
            0 => n,
            s => s,
        };
        points.extend((1..=steps).map(|j| pt(outer[(e + j) % n])));
        points.push(on(e2, g2));
        walls.push(wall(k + 1, points, false));
    }
    walls
}

/// Generates a floor (see the module docs) as file structures.
pub fn generate_spec(opts: &GenerateOptions) -> Result<WorldSpec, GenerateError> {
    let (w, h) = opts.size_m;
    if !((4..=12).contains(&opts.corridors) && opts.corridors.is_multiple_of(2)) {
        return Err(GenerateError::Corridors(opts.corridors));
    }
    if !((24.0..=2000.0).contains(&w) && (24.0..=2000.0).contains(&h)) {
        return Err(GenerateError::Size(w, h));
    }
    let mut rng = stream(opts.seed, 0, 0, Purpose::WorldGenerator);
    let loop_pts = centre_loop(&mut rng, w, h, (opts.corridors - 4) / 2);
    let all = slots(&mut rng, &loop_pts);
    if all.len() < opts.doors {
        return Err(GenerateError::Doors {
            asked: opts.doors,
            fit: all.len(),
        });
    }
    // Which slots get an office: a seeded shuffle, then back in loop order.
    let mut order: Vec<usize> = (0..all.len()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut chosen: Vec<usize> = order[..opts.doors].to_vec();
    chosen.sort_unstable();
    let mut walls = vec![WallSpec {
        id: "courtyard".into(),
        points_m: courtyard_wall(&mut rng, &loop_pts),
        closed: true,
        thickness_m: crate::spec::world::default_wall_thickness_m(),
    }];
    let (mut doors, mut gaps) = (Vec::new(), Vec::new());
    for (k, &i) in chosen.iter().enumerate() {
        let shares = chosen
            .get(k + 1)
            .is_some_and(|&j| j == i + 1 && all[j].edge == all[i].edge);
        let (wall, door, g0) = office(&mut rng, &loop_pts, all[i], shares, k);
        walls.push(wall);
        doors.push(door);
        gaps.push((all[i].edge, g0));
    }
    walls.extend(corridor_wall(&loop_pts, &gaps));
    let (a, d, _) = edge_frame(&loop_pts, 0);
    let home = a + d * 1.0;
    Ok(WorldSpec {
        format_version: 1,
        name: format!("generated-{}", opts.seed),
        description: Some(format!(
            "generated: seed {}, {} x {} m, {} doors, {} corridors",
            opts.seed, w, h, opts.doors, opts.corridors
        )),
        robot_home: HomeSpec {
            x_m: round_cm(home.x),
            y_m: round_cm(home.y),
            heading_deg: round_cm(d.y.atan2(d.x).to_degrees()),
        },
        walls,
        doors,
        routes: vec![RouteSpec {
            id: "lap".into(),
            waypoints_m: loop_pts.iter().map(|p| pt(*p)).collect(),
        }],
        areas: Vec::new(),
    })
}

/// Generates a floor as the text of a world file, checked by the world file checks.
pub fn generate_toml(opts: &GenerateOptions) -> Result<String, GenerateError> {
    let spec = generate_spec(opts)?;
    let body = toml::to_string(&spec).map_err(|e| GenerateError::Invalid(e.to_string()))?;
    let text = format!(
        "# A generated floor: placewords world generate --seed {} --size-m {},{} --doors {} --corridors {}\n\
         # A corridor loop (route \"lap\" along its centre line), offices outside it with one door\n\
         # each (swinging into the office), niches in the courtyard wall.\n{body}",
        opts.seed, opts.size_m.0, opts.size_m.1, opts.doors, opts.corridors
    );
    crate::world::load::parse_world_spec(
        &text,
        "generated world",
        &crate::world::validate::WorldCheck::default(),
    )
    .map_err(|e| GenerateError::Invalid(e.to_string()))?;
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_floor_and_another_seed_another() {
        let a = generate_toml(&GenerateOptions::default()).unwrap();
        assert_eq!(a, generate_toml(&GenerateOptions::default()).unwrap());
        let b = generate_toml(&GenerateOptions {
            seed: 2,
            ..GenerateOptions::default()
        })
        .unwrap();
        assert_ne!(a, b);
    }

    #[test]
    fn impossible_requests_are_refused() {
        let o = GenerateOptions::default();
        let odd = GenerateOptions {
            corridors: 5,
            ..o.clone()
        };
        assert_eq!(generate_spec(&odd), Err(GenerateError::Corridors(5)));
        let many = GenerateOptions { doors: 500, ..o };
        assert!(matches!(
            generate_spec(&many),
            Err(GenerateError::Doors { .. })
        ));
    }
}
