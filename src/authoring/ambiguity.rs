//! The ambiguity map: where on a route the recognizer will confuse places, found before any run.
//!
//! The simulated robot drives the route twice with no noise at all (exact laser, exact odometry,
//! no wander, no people), and the recognizer, with its own words and thresholds, matches the
//! drive against itself. Matching the second lap against the first finds every n-gram of words
//! that occurs at two places of the route in either order. A matched word pair whose two words
//! lie more than `tp_radius_m` apart (their middle observations' true positions) is a confusion:
//! both words' stretches of the route are ambiguous, and each is the other's partner. Stretches
//! are merged where they overlap; stretches that are partners, directly or through others, form a
//! group (one colour and number in the picture).

use crate::geom::Vec2;
use crate::recognizer::{Match, Recognizer, RecognizerConfig, Word};
use crate::sim::Frame;
use crate::sim::robot::RouteTracker;
use crate::world::{DoorStates, Route, World};
use serde::Serialize;

/// Route resolution of the stretches, metres.
pub const BIN_M: f64 = 0.1;

/// Why an ambiguity map could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AmbiguityError {
    #[error("world '{world}' has no route '{route}'; {hint}")]
    UnknownRoute {
        world: String,
        route: String,
        hint: String,
    },
    #[error("the noise-free drive failed: {0}")]
    Sim(#[from] crate::sim::SimError),
    #[error("{0}")]
    Recognizer(#[from] crate::recognizer::RecognizerError),
}

/// One ambiguous stretch of the route.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AmbiguousStretch {
    /// 1-based, in route order from the first waypoint.
    pub number: usize,
    /// 1-based group of stretches that look alike to the recognizer.
    pub group: usize,
    /// Start, metres along the route from its first waypoint.
    pub from_m: f64,
    /// End, metres along the route; less than `from_m` when the stretch passes the first
    /// waypoint.
    pub to_m: f64,
    pub length_m: f64,
    /// Numbers of the stretches whose words match this one's.
    pub partners: Vec<usize>,
}

/// Every ambiguous stretch of a route.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AmbiguityReport {
    pub world: String,
    pub route: String,
    pub route_length_m: f64,
    /// Level configuration searched (1 = level-0 words only).
    pub levels: usize,
    /// Minimum n-gram size per level configuration.
    pub min_ngram: Vec<usize>,
    /// Words farther apart than this are different places, metres.
    pub tp_radius_m: f64,
    /// Matched word pairs at different places.
    pub confused_word_pairs: usize,
    /// Share of the route inside an ambiguous stretch, 0..1.
    pub ambiguous_share: f64,
    pub groups: usize,
    pub stretches: Vec<AmbiguousStretch>,
}

impl AmbiguityReport {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".into())
    }
}

/// The noise-free drive: frames of two laps and each frame's position along the route.
pub struct Drive {
    pub frames: Vec<Frame>,
    pub route_m: Vec<f64>,
}

/// A scenario of one run of two laps over `route` with every noise and wander off.
fn noise_free_scenario(
    world: &World,
    route: &Route,
    doors: &DoorStates,
    cfg: &RecognizerConfig,
) -> crate::spec::scenario::Scenario {
    use crate::sim::{laser, odometry, pedestrians, robot};
    use crate::spec::scenario::{DoorChoice, DoorPlan, RunPlan, Scenario};
    Scenario {
        name: format!("{}-ambiguity", world.name),
        description: None,
        path: Default::default(),
        world_path: Default::default(),
        world: world.clone(),
        route: route.clone(),
        seed: 0,
        runs: vec![RunPlan {
            start_waypoint: 0,
            laps: 2,
            doors: DoorPlan::Fixed(DoorChoice {
                name: "given".into(),
                states: doors.clone(),
            }),
        }],
        door_configs: Default::default(),
        pedestrians: pedestrians::PedestrianConfig::default(),
        laser: laser::LaserConfig {
            range_noise_m: 0.0,
            angle_error_rad: 0.0,
            ..laser::LaserConfig::default()
        },
        odometry: odometry::OdometryConfig {
            model: odometry::OdometryModel::Proportional {
                translation_ratio: 0.0,
                rotation_ratio: 0.0,
            },
            ..odometry::OdometryConfig::default()
        },
        robot: robot::RobotConfig::default(),
        recognizer: cfg.clone(),
        evaluation: Default::default(),
        expect: Default::default(),
    }
}

/// Drives `route` twice without noise.
pub fn drive(
    world: &World,
    route: &Route,
    doors: &DoorStates,
    cfg: &RecognizerConfig,
) -> Result<Drive, AmbiguityError> {
    let scn = noise_free_scenario(world, route, doors, cfg);
    let runs = crate::sim::simulate(&scn, None, &|| {})?;
    let frames: Vec<Frame> = runs
        .into_iter()
        .flat_map(|r| r.laps)
        .flat_map(|l| l.frames)
        .collect();
    let mut tracker = RouteTracker::new(route, 0);
    let length = tracker.length_m();
    let route_m = frames
        .iter()
        .map(|f| {
            tracker.update(f.truth.0.position());
            tracker.arc_m().rem_euclid(length)
        })
        .collect();
    Ok(Drive { frames, route_m })
}

/// A word's stretch of the route (start, end, metres along it) and its middle true position.
fn word_place(rec: &Recognizer, drive: &Drive, w: &Word) -> (f64, f64, Vec2) {
    let obs = rec.observations();
    let frame = |i: usize| obs[i].input_index.min(drive.frames.len() - 1);
    let r = w.obs_range();
    let (first, last) = (frame(r.start), frame(r.end - 1));
    let mid = frame(r.start + w.size / 2);
    let at = drive.frames[mid].truth.0.position();
    (drive.route_m[first], drive.route_m[last], at)
}

/// Pairs of route stretches the recognizer confused: ((from, to), (from, to)).
type Confusion = ((f64, f64), (f64, f64));

fn confusions(rec: &Recognizer, drive: &Drive, matches: &[Match], radius_m: f64) -> Vec<Confusion> {
    let words = rec.words();
    let mut out = Vec::new();
    for m in matches {
        for (c, p) in &m.word_pairs {
            let (Some(cw), Some(pw)) = (words.get(*c), words.get(*p)) else {
                continue;
            };
            let (c0, c1, ca) = word_place(rec, drive, cw);
            let (p0, p1, pa) = word_place(rec, drive, pw);
            if (ca - pa).norm() > radius_m {
                out.push(((c0, c1), (p0, p1)));
            }
        }
    }
    out
}

/// Route bins covered by the stretch from `a` to `b` (forward, wrapping at the route's end).
fn bins(a: f64, b: f64, n: usize) -> impl Iterator<Item = usize> {
    let i0 = ((a / BIN_M) as usize).min(n - 1);
    let i1 = ((b / BIN_M) as usize).min(n - 1);
    let count = (i1 + n - i0) % n + 1;
    (0..count).map(move |k| (i0 + k) % n)
}

/// Maximal runs of marked bins on the loop, as (first bin, bin count), in route order.
fn runs_of(marked: &[bool]) -> Vec<(usize, usize)> {
    let n = marked.len();
    let Some(start) = (0..n).find(|&i| !marked[i]) else {
        return vec![(0, n)];
    };
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        let i = (start + k) % n;
        if marked[i] {
            let len = (k..n).take_while(|&j| marked[(start + j) % n]).count();
            out.push((i, len));
            k += len;
        } else {
            k += 1;
        }
    }
    out.sort();
    out
}

/// Union-find root.
fn root(parent: &mut [usize], i: usize) -> usize {
    let mut r = i;
    while parent[r] != r {
        r = parent[r];
    }
    parent[i] = r;
    r
}

/// Merged stretches with their partners and groups.
fn stretches(conf: &[Confusion], length_m: f64) -> Vec<AmbiguousStretch> {
    let n = ((length_m / BIN_M).ceil() as usize).max(1);
    let mut marked = vec![false; n];
    for ((a, b), (c, d)) in conf {
        bins(*a, *b, n)
            .chain(bins(*c, *d, n))
            .for_each(|i| marked[i] = true);
    }
    let runs = runs_of(&marked);
    let mut owner = vec![usize::MAX; n];
    for (s, &(first, len)) in runs.iter().enumerate() {
        (0..len).for_each(|k| owner[(first + k) % n] = s);
    }
    let mut partners = vec![std::collections::BTreeSet::new(); runs.len()];
    let mut parent: Vec<usize> = (0..runs.len()).collect();
    for ((a, _), (c, _)) in conf {
        let (x, y) = (
            owner[bins(*a, *a, n).next().unwrap_or(0)],
            owner[bins(*c, *c, n).next().unwrap_or(0)],
        );
        if x == usize::MAX || y == usize::MAX {
            continue;
        }
        // A stretch whose words repeat within it is its own partner.
        partners[x].insert(y + 1);
        if x != y {
            partners[y].insert(x + 1);
            let (rx, ry) = (root(&mut parent, x), root(&mut parent, y));
            parent[rx.max(ry)] = rx.min(ry);
        }
    }
    let mut group_of = std::collections::BTreeMap::new();
    runs.iter()
        .enumerate()
        .map(|(s, &(first, len))| {
            let r = root(&mut parent, s);
            let next = group_of.len() + 1;
            let group = *group_of.entry(r).or_insert(next);
            let from_m = first as f64 * BIN_M;
            AmbiguousStretch {
                number: s + 1,
                group,
                from_m,
                to_m: ((first + len) as f64 * BIN_M)
                    .min(n as f64 * BIN_M)
                    .rem_euclid(length_m),
                length_m: (len as f64 * BIN_M).min(length_m),
                partners: partners[s].iter().copied().collect(),
            }
        })
        .collect()
}

/// Drives `route` of `world` without noise and finds every stretch whose words also occur
/// elsewhere on it, at the recognizer settings `cfg` (all its level configurations) and with
/// the doors in `doors`. Returns the report and the drive (for the picture).
pub fn ambiguity(
    world: &World,
    route_id: &str,
    doors: &DoorStates,
    cfg: &RecognizerConfig,
    tp_radius_m: f64,
) -> Result<(AmbiguityReport, Drive), AmbiguityError> {
    let route = world
        .route(route_id)
        .ok_or_else(|| AmbiguityError::UnknownRoute {
            world: world.name.clone(),
            route: route_id.to_string(),
            hint: crate::spec::suggest::hint(
                route_id,
                world.routes.iter().map(|r| r.id.as_str()),
                "route ids",
            ),
        })?;
    let drive = drive(world, route, doors, cfg)?;
    let mut rec = Recognizer::new(cfg.clone())?;
    let mut matches = Vec::new();
    for f in &drive.frames {
        matches.extend(rec.push(f.odom, &f.scan));
    }
    matches.extend(rec.finish());
    let conf = confusions(&rec, &drive, &matches, tp_radius_m);
    let length_m = route.length_m();
    let list = stretches(&conf, length_m);
    let covered: f64 = list.iter().map(|s| s.length_m).sum();
    let report = AmbiguityReport {
        world: world.name.clone(),
        route: route.id.clone(),
        route_length_m: length_m,
        levels: cfg.levels,
        min_ngram: cfg.min_ngram.iter().copied().take(cfg.levels).collect(),
        tp_radius_m,
        confused_word_pairs: conf.len(),
        ambiguous_share: (covered / length_m).min(1.0),
        groups: list.iter().map(|s| s.group).max().unwrap_or(0),
        stretches: list,
    };
    Ok((report, drive))
}

/// Distinct colours for groups of look-alike stretches (Tableau 10 without grey).
pub const GROUP_COLORS: [&str; 9] = [
    "#d62728", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22",
    "#17becf",
];

/// Points of the route from `from_m` to `to_m` (forward, wrapping), every 0.25 m.
fn route_points(route: &Route, from_m: f64, length_m: f64) -> Vec<Vec2> {
    let tracker = RouteTracker::new(route, 0);
    let steps = ((length_m / 0.25).ceil() as usize).max(1);
    (0..=steps)
        .map(|k| {
            tracker
                .point_at(from_m + length_m * k as f64 / steps as f64)
                .0
        })
        .collect()
}

/// The world with the route's ambiguous stretches drawn as thick bands, one colour and number
/// per group of stretches that look alike, and a numbered list of the stretches under it.
pub fn ambiguity_svg(world: &World, doors: &DoorStates, report: &AmbiguityReport) -> String {
    use crate::report::world_render::{
        BandOverlay, LegendEntry, MarkOverlay, RenderOptions, render_world_svg,
    };
    let Some(route) = world.route(&report.route) else {
        return render_world_svg(world, &RenderOptions::default());
    };
    let color = |g: usize| GROUP_COLORS[(g - 1) % GROUP_COLORS.len()].to_string();
    let mut opts = RenderOptions {
        doors: doors.clone(),
        title: Some(title(report)),
        show_areas: false,
        show_door_labels: false,
        ..RenderOptions::default()
    };
    for s in &report.stretches {
        let pts = route_points(route, s.from_m, s.length_m);
        opts.marks.push(MarkOverlay {
            at: pts[pts.len() / 2],
            text: s.group.to_string(),
            color: color(s.group),
            class: "ambiguous".into(),
        });
        opts.bands.push(BandOverlay {
            points: pts,
            color: color(s.group),
            width_px: 9.0,
        });
    }
    for g in 1..=report.groups {
        let members: Vec<&AmbiguousStretch> =
            report.stretches.iter().filter(|s| s.group == g).collect();
        opts.legend.push(LegendEntry {
            label: format!("{g}: {} stretches look alike", members.len()),
            color: color(g),
            dashed: false,
        });
    }
    opts.notes = notes(report);
    render_world_svg(world, &opts)
}

fn title(report: &AmbiguityReport) -> String {
    if report.stretches.is_empty() {
        return format!(
            "{}: route '{}' has no ambiguous stretch",
            report.world, report.route
        );
    }
    format!(
        "{}: route '{}', {:.0} % ambiguous ({} groups of look-alike stretches)",
        report.world,
        report.route,
        100.0 * report.ambiguous_share,
        report.groups
    )
}

/// Most stretches listed under the picture.
const MAX_NOTES: usize = 12;

fn notes(report: &AmbiguityReport) -> Vec<String> {
    let mut out: Vec<String> = report
        .stretches
        .iter()
        .take(MAX_NOTES)
        .map(|s| {
            let partners: Vec<String> = s.partners.iter().map(|p| format!("#{p}")).collect();
            format!(
                "group {}: stretch #{} at {:.1}-{:.1} m along the route ({:.1} m) looks like {}",
                s.group,
                s.number,
                s.from_m,
                s.to_m,
                s.length_m,
                partners.join(", ")
            )
        })
        .collect();
    if report.stretches.len() > MAX_NOTES {
        out.push(format!(
            "... and {} more stretches (see --json)",
            report.stretches.len() - MAX_NOTES
        ));
    }
    if report.stretches.is_empty() {
        out.push(format!(
            "no n-gram of words occurs at two places (levels {}, n-gram sizes {:?})",
            report.levels, report.min_ngram
        ));
    }
    out
}

impl AmbiguityReport {
    /// A few lines for people: the share of the route that is ambiguous and each stretch.
    pub fn summary(&self) -> String {
        let mut out = format!(
            "{}: route '{}' ({:.0} m): {} ambiguous stretch(es) in {} group(s), {:.0} % of the route\n",
            self.world,
            self.route,
            self.route_length_m,
            self.stretches.len(),
            self.groups,
            100.0 * self.ambiguous_share
        );
        for s in &self.stretches {
            let partners: Vec<String> = s.partners.iter().map(|p| format!("#{p}")).collect();
            out.push_str(&format!(
                "  #{} (group {}): {:.1}-{:.1} m, looks like {}\n",
                s.number,
                s.group,
                s.from_m,
                s.to_m,
                partners.join(", ")
            ));
        }
        out
    }
}

/// The report and picture `placewords world ambiguity` writes: default recognizer settings
/// (all three level configurations), pairs farther apart than 1 m are different places.
pub fn ambiguity_picture(
    world: &World,
    route_id: &str,
    doors: &DoorStates,
) -> Result<(AmbiguityReport, String), AmbiguityError> {
    let cfg = RecognizerConfig::default();
    let tp_radius_m = crate::spec::evaluation::EvaluationSpec::default().tp_radius_m;
    let (report, _) = ambiguity(world, route_id, doors, &cfg, tp_radius_m)?;
    let svg = ambiguity_svg(world, doors, &report);
    Ok((report, svg))
}
