//! A world generator for stress tests and examples: a corridor loop (a rectangle with corners
//! cut away, so 4, 6, 8, 10 or 12 corridors), offices outside the loop each with one door that
//! swings into it, niches in the courtyard wall at random places so that stretches of corridor
//! differ, a walking area along each corridor, and a lap route along the corridors' centre
//! lines.
//!
//! Options: `double_loaded` puts offices on both sides of every corridor (inside the loop too,
//! their doors in the courtyard wall, which then has no niches), as in a hospital ward or an
//! office floor; `look_alike` makes the corridors look alike on purpose (every office the same
//! width with its door at the same place, no niches), the recognizer's hardest case. Asking for
//! more offices than fit is refused with the number that fits.
//!
//! Deterministic per seed: every draw comes from one ChaCha stream keyed by the seed
//! ([`crate::sim::rng::stream`] with [`Purpose::WorldGenerator`]).

use crate::geom::Vec2;
use crate::sim::rng::{Purpose, SimRng, stream};
use crate::spec::world::{AreaSpec, DoorSpec, HomeSpec, RouteSpec, WallSpec, WorldSpec};
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
    /// Offices on both sides of every corridor. Default false (outside the loop only).
    pub double_loaded: bool,
    /// Every office [`LOOK_ALIKE_ROOM_M`] wide with its door at the same place, and no niches:
    /// stretches of corridor that look alike. Default false.
    pub look_alike: bool,
}

/// Office width along the corridor with `look_alike`, metres.
pub const LOOK_ALIKE_ROOM_M: f64 = 4.0;
/// Where the door's gap starts in a look-alike office, metres from the office's start.
const LOOK_ALIKE_DOOR_AT_M: f64 = 0.5;

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions {
            seed: 1,
            size_m: (40.0, 30.0),
            doors: 12,
            corridors: 4,
            double_loaded: false,
            look_alike: false,
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
        "--doors {asked}: only {fit} offices fit along the corridors of this floor{more}; ask for fewer doors or a larger --size-m"
    )]
    Doors {
        asked: usize,
        fit: usize,
        /// What would fit more (`, {n} with --double-loaded`), or empty.
        more: String,
    },
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
        out.extend(cut_corner(
            rng,
            *c,
            inward[k],
            (x1 - x0, y1 - y0),
            k % 2 == 0,
        ));
    }
    out.iter()
        .map(|p| Vec2::new(round_cm(p.x), round_cm(p.y)))
        .collect()
}

/// The three points that replace corner `c` by a notch 20-30 % of the loop's `size` deep in
/// each direction, going `inward` (signs along x and y); counter-clockwise: arriving along the
/// previous edge and leaving along the next (`even`: the notch's y side comes first).
fn cut_corner(
    rng: &mut SimRng,
    c: Vec2,
    (sx, sy): (f64, f64),
    size: (f64, f64),
    even: bool,
) -> [Vec2; 3] {
    let cx = rng.random_range(0.2..0.3) * size.0;
    let cy = rng.random_range(0.2..0.3) * size.1;
    let a = c + Vec2::new(0.0, sy * cy);
    let m = c + Vec2::new(sx * cx, sy * cy);
    let b = c + Vec2::new(sx * cx, 0.0);
    if even { [a, m, b] } else { [b, m, a] }
}

/// One office slot: corridor edge, start and end along it (metres from the edge's start), and
/// side (1 outside the loop, -1 inside).
#[derive(Clone, Copy, Debug)]
struct Slot {
    edge: usize,
    from: f64,
    to: f64,
    side: f64,
}

/// Office slots along every edge on `side`, clear of the corners: 3.5-5 m wide, or all
/// [`LOOK_ALIKE_ROOM_M`] with `look_alike`.
fn slots(rng: &mut SimRng, loop_pts: &[Vec2], side: f64, look_alike: bool) -> Vec<Slot> {
    let n = loop_pts.len();
    let mut out = Vec::new();
    for e in 0..n {
        let len = (loop_pts[(e + 1) % n] - loop_pts[e]).norm();
        let mut at = ROOM_END_MARGIN_M;
        loop {
            let w = if look_alike {
                LOOK_ALIKE_ROOM_M
            } else {
                round_cm(rng.random_range(3.5..5.0))
            };
            if at + w > len - ROOM_END_MARGIN_M {
                break;
            }
            out.push(Slot {
                edge: e,
                from: at,
                to: at + w,
                side,
            });
            at += w;
        }
    }
    out
}

/// The office of `slot` as a rectangle (min, max corners), grown by `grow_m`.
fn room_box(loop_pts: &[Vec2], slot: &Slot, grow_m: f64) -> (Vec2, Vec2) {
    let (a, d, out) = edge_frame(loop_pts, slot.edge);
    let o = out * slot.side;
    let (front, back) = (CORRIDOR_M / 2.0, CORRIDOR_M / 2.0 + ROOM_DEPTH_M);
    let c = [a + d * slot.from + o * front, a + d * slot.to + o * back];
    let lo = Vec2::new(c[0].x.min(c[1].x), c[0].y.min(c[1].y));
    let hi = Vec2::new(c[0].x.max(c[1].x), c[0].y.max(c[1].y));
    let g = Vec2::new(grow_m, grow_m);
    (lo - g, hi + g)
}

/// Inside slots whose office would come within 0.3 m of another corridor (in a small or
/// notched courtyard) or of an inside office of another edge are left out.
fn inside_slots_that_fit(loop_pts: &[Vec2], inner: Vec<Slot>) -> Vec<Slot> {
    let n = loop_pts.len();
    let mut kept: Vec<Slot> = Vec::new();
    let overlaps = |(alo, ahi): (Vec2, Vec2), (blo, bhi): (Vec2, Vec2)| {
        alo.x < bhi.x && blo.x < ahi.x && alo.y < bhi.y && blo.y < ahi.y
    };
    for s in inner {
        let grown = room_box(loop_pts, &s, 0.3);
        let hits_corridor = (0..n).filter(|&e| e != s.edge).any(|e| {
            let (a, b) = (loop_pts[e], loop_pts[(e + 1) % n]);
            let band = CORRIDOR_M / 2.0;
            let lo = Vec2::new(a.x.min(b.x) - band, a.y.min(b.y) - band);
            let hi = Vec2::new(a.x.max(b.x) + band, a.y.max(b.y) + band);
            overlaps(grown, (lo, hi))
        });
        let hits_room = kept
            .iter()
            .filter(|k| k.edge != s.edge)
            .any(|k| overlaps(grown, room_box(loop_pts, k, 0.0)));
        if !hits_corridor && !hits_room {
            kept.push(s);
        }
    }
    kept
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
    look_alike: bool,
) -> (WallSpec, DoorSpec, f64) {
    let (a, d, out) = edge_frame(loop_pts, slot.edge);
    let out = out * slot.side;
    let at = |t: f64, o: f64| pt(a + d * t + out * o);
    let (front, back) = (CORRIDOR_M / 2.0, CORRIDOR_M / 2.0 + ROOM_DEPTH_M);
    let mut points = vec![at(slot.from, front), at(slot.from, back), at(slot.to, back)];
    if !shares_right {
        points.push(at(slot.to, front));
    }
    let g0 = if look_alike {
        slot.from + LOOK_ALIKE_DOOR_AT_M
    } else {
        round_cm(rng.random_range(slot.from + 0.3..slot.to - DOOR_M - 0.3))
    };
    let wall = WallSpec {
        id: format!("office-{:02}", index + 1),
        points_m: points,
        closed: false,
        thickness_m: crate::spec::world::default_wall_thickness_m(),
    };
    (wall, office_door(index, at(g0, front), d, out), g0)
}

/// The door of office `index`, hinged at `hinge_m`, closed along the corridor (`along`) and
/// open into the office (`into`).
fn office_door(index: usize, hinge_m: [f64; 2], along: Vec2, into: Vec2) -> DoorSpec {
    let heading = |v: Vec2| round_cm(v.y.atan2(v.x).to_degrees());
    DoorSpec {
        id: format!("d-{:02}", index + 1),
        hinge_m,
        width_m: DOOR_M,
        closed_heading_deg: heading(along),
        open_heading_deg: heading(into),
        thickness_m: crate::spec::world::default_door_thickness_m(),
    }
}

/// A corridor wall on `side` (1: the outer wall, -1: the courtyard wall), cut at the door
/// gaps `(edge, from)` (sorted): one closed wall without doors, else one open polyline from
/// each gap's end to the next gap's start. Walls are named `{name}-{k}` (`{name}` alone when
/// closed).
fn corridor_wall(loop_pts: &[Vec2], gaps: &[(usize, f64)], side: f64, name: &str) -> Vec<WallSpec> {
    let outer = offset(loop_pts, -side * CORRIDOR_M / 2.0);
    let n = outer.len();
    let wall = |k: usize, points_m: Vec<[f64; 2]>, closed: bool| {
        corridor_wall_spec(name, k, side, points_m, closed)
    };
    if gaps.is_empty() {
        return vec![wall(1, outer.iter().map(|p| pt(*p)).collect(), true)];
    }
    let on = |e: usize, t: f64| {
        let (a, d, o) = edge_frame(loop_pts, e);
        pt(a + d * t + o * (side * CORRIDOR_M / 2.0))
    };
    let mut walls = Vec::new();
    for (k, &(e, g)) in gaps.iter().enumerate() {
        let (e2, g2) = gaps[(k + 1) % gaps.len()];
        let mut points = vec![on(e, g + DOOR_M)];
        let steps = corners_between((e, g), (e2, g2), n, gaps.len());
        points.extend((1..=steps).map(|j| pt(outer[(e + j) % n])));
        points.push(on(e2, g2));
        walls.push(wall(k + 1, points, false));
    }
    walls
}

/// Wall `k` of the corridor side `name`: a closed wall on the negative `side` is named `name`
/// alone, the others `name-k`.
fn corridor_wall_spec(
    name: &str,
    k: usize,
    side: f64,
    points_m: Vec<[f64; 2]>,
    closed: bool,
) -> WallSpec {
    WallSpec {
        id: if closed && side < 0.0 {
            name.to_string()
        } else {
            format!("{name}-{k}")
        },
        points_m,
        closed,
        thickness_m: crate::spec::world::default_wall_thickness_m(),
    }
}

/// How many of the `n` loop corners a wall from the gap at `(edge, along)` to the next of the
/// `gaps` gaps, at `to`, passes: none when the next is ahead on the same edge.
fn corners_between((e, g): (usize, f64), (e2, g2): (usize, f64), n: usize, gaps: usize) -> usize {
    let ahead_on_edge = e2 == e && g2 > g && gaps > 1;
    match (e2 + n - e) % n {
        _ if ahead_on_edge => 0,
        0 => n,
        s => s,
    }
}

/// The floor's size `(w, h)`, metres, when `opts` ask for a floor that can be generated.
fn check_options(opts: &GenerateOptions) -> Result<(f64, f64), GenerateError> {
    let (w, h) = opts.size_m;
    if !((4..=12).contains(&opts.corridors) && opts.corridors.is_multiple_of(2)) {
        return Err(GenerateError::Corridors(opts.corridors));
    }
    if !((24.0..=2000.0).contains(&w) && (24.0..=2000.0).contains(&h)) {
        return Err(GenerateError::Size(w, h));
    }
    Ok((w, h))
}

/// The generated world's description: what it was generated from.
fn description(opts: &GenerateOptions) -> String {
    let (w, h) = opts.size_m;
    format!(
        "generated: seed {}, {} x {} m, {} doors, {} corridors{}{}",
        opts.seed,
        w,
        h,
        opts.doors,
        opts.corridors,
        if opts.double_loaded {
            ", double-loaded"
        } else {
            ""
        },
        if opts.look_alike { ", look-alike" } else { "" }
    )
}

/// Generates a floor (see the module docs) as file structures.
pub fn generate_spec(opts: &GenerateOptions) -> Result<WorldSpec, GenerateError> {
    let (w, h) = check_options(opts)?;
    let mut rng = stream(opts.seed, 0, 0, Purpose::WorldGenerator);
    let loop_pts = centre_loop(&mut rng, w, h, (opts.corridors - 4) / 2);
    let mut all = slots(&mut rng, &loop_pts, 1.0, opts.look_alike);
    let outside = all.len();
    // The inside slots are drawn from a copy of the stream when not used, so a single-loaded
    // floor is the one earlier versions generated from the same seed.
    let inner = if opts.double_loaded {
        slots(&mut rng, &loop_pts, -1.0, opts.look_alike)
    } else {
        slots(&mut rng.clone(), &loop_pts, -1.0, opts.look_alike)
    };
    let inner = inside_slots_that_fit(&loop_pts, inner);
    if opts.double_loaded {
        all.extend(inner.iter().copied());
    }
    if all.len() < opts.doors {
        let more = if opts.double_loaded {
            String::new()
        } else {
            format!(", {} with --double-loaded", outside + inner.len())
        };
        return Err(GenerateError::Doors {
            asked: opts.doors,
            fit: all.len(),
            more,
        });
    }
    // Which slots get an office: a seeded shuffle, then back in loop order.
    let mut order: Vec<usize> = (0..all.len()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut chosen: Vec<usize> = order[..opts.doors].to_vec();
    chosen.sort_unstable();
    let plain_courtyard = opts.double_loaded || opts.look_alike;
    let mut walls = Vec::new();
    if !plain_courtyard {
        walls.push(WallSpec {
            id: "courtyard".into(),
            points_m: courtyard_wall(&mut rng, &loop_pts),
            closed: true,
            thickness_m: crate::spec::world::default_wall_thickness_m(),
        });
    }
    let (mut doors, mut gaps, mut inner_gaps) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &i) in chosen.iter().enumerate() {
        let shares = chosen.get(k + 1).is_some_and(|&j| {
            j == i + 1 && all[j].edge == all[i].edge && all[j].side == all[i].side
        });
        let (wall, door, g0) = office(&mut rng, &loop_pts, all[i], shares, k, opts.look_alike);
        walls.push(wall);
        doors.push(door);
        if all[i].side > 0.0 {
            gaps.push((all[i].edge, g0));
        } else {
            inner_gaps.push((all[i].edge, g0));
        }
    }
    if plain_courtyard {
        walls.extend(corridor_wall(&loop_pts, &inner_gaps, -1.0, "courtyard"));
    }
    walls.extend(corridor_wall(&loop_pts, &gaps, 1.0, "corridor"));
    let (a, d, _) = edge_frame(&loop_pts, 0);
    let home = a + d * 1.0;
    Ok(WorldSpec {
        format_version: 1,
        name: format!("generated-{}", opts.seed),
        description: Some(description(opts)),
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
        areas: walking_areas(&loop_pts),
    })
}

/// Where people walk: along the centre of each corridor at least 6 m long, 1.2 m across,
/// keeping 2 m from the corners.
fn walking_areas(loop_pts: &[Vec2]) -> Vec<AreaSpec> {
    let n = loop_pts.len();
    (0..n)
        .filter_map(|e| {
            let (a, d, out) = edge_frame(loop_pts, e);
            let len = (loop_pts[(e + 1) % n] - a).norm();
            if len < 6.0 {
                return None;
            }
            let (p, q) = (a + d * 2.0 + out * 0.6, a + d * (len - 2.0) - out * 0.6);
            Some(AreaSpec {
                id: format!("walk-{e}"),
                min_m: pt(Vec2::new(p.x.min(q.x), p.y.min(q.y))),
                max_m: pt(Vec2::new(p.x.max(q.x), p.y.max(q.y))),
            })
        })
        .collect()
}

/// Generates a floor as the text of a world file, checked by the world file checks.
pub fn generate_toml(opts: &GenerateOptions) -> Result<String, GenerateError> {
    let spec = generate_spec(opts)?;
    let body = toml::to_string(&spec).map_err(|e| GenerateError::Invalid(e.to_string()))?;
    let text = format!("{}{body}", header_comment(opts));
    crate::world::load::parse_world_spec(
        &text,
        "generated world",
        &crate::world::validate::WorldCheck::default(),
    )
    .map_err(|e| GenerateError::Invalid(e.to_string()))?;
    Ok(text)
}

/// The comment atop a generated world: the command that makes it again and what it holds.
fn header_comment(opts: &GenerateOptions) -> String {
    format!(
        "# A generated floor: placewords world generate --seed {} --size-m {},{} --doors {} --corridors {}{}{}\n\
         # A corridor loop (route \"lap\" along its centre line), offices {} with one door\n\
         # each (swinging into the office), {}; people walk in the areas \"walk-N\".\n",
        opts.seed,
        opts.size_m.0,
        opts.size_m.1,
        opts.doors,
        opts.corridors,
        if opts.double_loaded {
            " --double-loaded"
        } else {
            ""
        },
        if opts.look_alike { " --look-alike" } else { "" },
        if opts.double_loaded {
            "on both sides of it"
        } else {
            "outside it"
        },
        if opts.double_loaded || opts.look_alike {
            "no niches"
        } else {
            "niches in the courtyard wall"
        }
    )
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
