//! The ambiguity map: where on a route the recognizer will confuse places, found before any run.
//!
//! The simulated robot drives the route twice with no noise at all (exact laser, exact odometry,
//! no wander, no people), and the recognizer, with its own words and thresholds, matches the
//! drive against itself. Matching the second lap against the first finds every n-gram of words
//! that occurs at two places of the route in either order. A matched word pair whose two words
//! lie more than `tp_radius_m` apart (their middle observations' true positions) is a confusion:
//! both words' stretches of the route are ambiguous, and each is the other's partner. Stretches
//! confused with each other along consecutive words are merged into one pair of stretches (one
//! colour and number in the picture). Only same-direction matches count (the route is driven one
//! way; the recognizer's `reverse` setting is turned off here).

use crate::geom::Vec2;
use crate::recognizer::{Recognizer, RecognizerConfig, Word, WordMatch as Match};
use crate::sim::Frame;
use crate::sim::plan::{DoorChoice, SimPlan};
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
    /// From 0, in route order from the first waypoint (waypoint 0).
    pub number: usize,
    /// The pair of stretches that look alike to the recognizer, counted from 0 (numbered by the
    /// first stretch's start), as the picture's markers and the summary number them.
    pub pair: usize,
    /// Start, metres along the route from its first waypoint.
    pub from_m: f64,
    /// End, metres along the route; less than `from_m` when the stretch passes the first
    /// waypoint.
    pub to_m: f64,
    pub length_m: f64,
    /// Number of the stretch whose words match this one's.
    pub partners: Vec<usize>,
    /// Why the recognizer confuses it.
    pub cause: Cause,
    /// How strongly: the confused word pairs joined into this pair of stretches.
    pub score: f64,
}

/// Why a stretch is flagged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Cause {
    /// Its words occur at another place under the same doors.
    LookAlike,
    /// Its words under one door set are another place's under another door set.
    DoorChange,
    /// Its words match the same stretch shifted along the route by more than the radius (the
    /// two stretches overlap): a slip along a corridor found by the words themselves.
    Shift,
}

impl Cause {
    /// The cause in words, as the picture and the summary print it.
    pub fn as_str(self) -> &'static str {
        match self {
            Cause::LookAlike => "look-alike",
            Cause::DoorChange => "door change",
            Cause::Shift => "shift",
        }
    }
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
    /// The door sets driven (one noise-free run of two laps each, matched against each other).
    pub door_sets: Vec<String>,
    /// Matched word pairs at different places.
    pub confused_word_pairs: usize,
    /// Share of the route inside an ambiguous stretch, 0..1.
    pub ambiguous_share: f64,
    /// Pairs of look-alike stretches.
    pub pairs: usize,
    pub stretches: Vec<AmbiguousStretch>,
    /// Stretches where the alignment can slide along the route by more than `tp_radius_m`.
    pub slips: Vec<super::slip::SlipStretch>,
    /// Share of the route inside a slip, 0..1.
    pub slip_share: f64,
    /// Share of the route flagged for any cause (look-alike, door change, slip), 0..1.
    pub flagged_share: f64,
}

impl AmbiguityReport {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".into())
    }
}

/// The noise-free drive: frames of two laps per door set and each frame's position along the
/// route.
pub struct Drive {
    pub frames: Vec<Frame>,
    pub route_m: Vec<f64>,
    /// Per frame: the index of the door set it was driven under (into `door_sets`).
    pub door_set_of_frame: Vec<usize>,
    /// Per frame: its lap within its run (0 or 1).
    pub lap_of_frame: Vec<usize>,
    /// The door sets driven, one run of two laps each, in order.
    pub door_sets: Vec<DoorChoice>,
    /// Length of the route, metres.
    pub loop_m: f64,
}

/// What a noise-free drive takes besides the world and route: the door sets (one run of two
/// laps each) and the robot (its lanes and speeds change the words; its noise does not exist
/// here). The world-only map drives one door set with the default robot.
#[derive(Clone, Debug)]
pub struct DriveSettings {
    pub door_sets: Vec<DoorChoice>,
    pub robot: crate::sim::robot::RobotConfig,
    /// Seed of the robot's lap variation (lanes, speeds).
    pub seed: u64,
}

impl DriveSettings {
    /// One door set, the default robot, seed 0.
    pub fn doors(doors: &DoorStates) -> DriveSettings {
        DriveSettings {
            door_sets: vec![DoorChoice {
                name: "given".into(),
                states: doors.clone(),
            }],
            robot: crate::sim::robot::RobotConfig::default(),
            seed: 0,
        }
    }
}

/// A simulation of one run of two laps over `route` per door set, with every noise off.
fn noise_free_plan(world: &World, route: &Route, settings: &DriveSettings) -> SimPlan {
    use crate::sim::plan::{DoorPlan, RunPlan};
    let first = settings.door_sets.first().cloned().unwrap_or(DoorChoice {
        name: "all-closed".into(),
        states: DoorStates::all_closed(world),
    });
    let base = SimPlan::one_run(format!("{}-ambiguity", world.name), world, route, 2, first);
    let runs = settings
        .door_sets
        .iter()
        .map(|d| RunPlan {
            doors: DoorPlan::Fixed(d.clone()),
            ..base.runs[0].clone()
        })
        .collect();
    SimPlan {
        laser: exact_laser(),
        odometry: exact_odometry(),
        robot: settings.robot.clone(),
        seed: settings.seed,
        runs,
        ..base
    }
}

/// The default laser without range noise or angle error.
fn exact_laser() -> crate::sim::laser::LaserConfig {
    crate::sim::laser::LaserConfig {
        range_noise_m: 0.0,
        angle_error_rad: 0.0,
        ..crate::sim::laser::LaserConfig::default()
    }
}

/// The default odometry without drift.
fn exact_odometry() -> crate::sim::odometry::OdometryConfig {
    use crate::sim::odometry::{OdometryConfig, OdometryModel};
    OdometryConfig {
        model: OdometryModel::Proportional {
            translation_ratio: 0.0,
            rotation_ratio: 0.0,
        },
        ..OdometryConfig::default()
    }
}

/// Drives `route` twice without noise under each door set of `settings`.
pub fn drive(
    world: &World,
    route: &Route,
    settings: &DriveSettings,
) -> Result<Drive, AmbiguityError> {
    let scn = noise_free_plan(world, route, settings);
    let runs = crate::sim::simulate(&scn, None, &|| {})?;
    let mut drive = Drive {
        frames: Vec::new(),
        route_m: Vec::new(),
        door_set_of_frame: Vec::new(),
        lap_of_frame: Vec::new(),
        door_sets: settings.door_sets.clone(),
        loop_m: RouteTracker::new(route, 0).length_m(),
    };
    for (k, run) in runs.into_iter().enumerate() {
        drive.add_run(k, run, route);
    }
    Ok(drive)
}

impl Drive {
    /// Appends the frames of `run` (with door set `k`), each with where it is along `route`.
    fn add_run(&mut self, k: usize, run: crate::sim::RunLog, route: &Route) {
        // A tracker per run: each run starts again at waypoint 0.
        let mut tracker = RouteTracker::new(route, 0);
        for lap in run.laps {
            for f in lap.frames {
                tracker.update(f.truth.0.position());
                self.route_m.push(tracker.arc_m().rem_euclid(self.loop_m));
                self.door_set_of_frame.push(k);
                self.lap_of_frame.push(lap.lap);
                self.frames.push(f);
            }
        }
    }

    /// Whether the middles of stretches `c` and `p` (route metres, start and end) lie within
    /// `radius_m` of each other along the loop.
    fn near_along_route(&self, c: (f64, f64), p: (f64, f64), radius_m: f64) -> bool {
        let mid = |a: f64, b: f64| a + (b - a).rem_euclid(self.loop_m) / 2.0;
        let along = (mid(c.0, c.1) - mid(p.0, p.1)).rem_euclid(self.loop_m);
        along.min(self.loop_m - along) <= radius_m
    }

    /// The door set of the frame of word `w`'s first observation.
    fn door_set_of_word(&self, rec: &Recognizer, w: &Word) -> usize {
        let f = rec.observations()[w.obs_range().start]
            .frame_id
            .min(self.frames.len() - 1);
        self.door_set_of_frame[f]
    }
}

/// A word's stretch of the route (start, end, metres along it) and its middle true position.
fn word_place(rec: &Recognizer, drive: &Drive, w: &Word) -> (f64, f64, Vec2) {
    let obs = rec.observations();
    let frame = |i: usize| obs[i].frame_id.min(drive.frames.len() - 1);
    let r = w.obs_range();
    let (first, last) = (frame(r.start), frame(r.end - 1));
    let mid = frame(r.start + w.size / 2);
    let at = drive.frames[mid].truth.0.position();
    (drive.route_m[first], drive.route_m[last], at)
}

/// Pairs of route stretches the recognizer confused: ((from, to), (from, to)).
type Confusion = ((f64, f64), (f64, f64));

/// A confusion, and whether its two words were driven under different door sets.
#[derive(Clone, Copy, Debug)]
struct Confused {
    places: Confusion,
    door_change: bool,
}

fn confusions(rec: &Recognizer, drive: &Drive, matches: &[Match], radius_m: f64) -> Vec<Confused> {
    let words = rec.words();
    let door_set = |w: &Word| drive.door_set_of_word(rec, w);
    let mut out = Vec::new();
    for m in matches {
        for (c, p) in &m.word_pairs {
            let (Some(cw), Some(pw)) = (words.get(*c), words.get(*p)) else {
                continue;
            };
            let (c0, c1, ca) = word_place(rec, drive, cw);
            let (p0, p1, pa) = word_place(rec, drive, pw);
            // Words at the same place of the route, one lap apart, are the same place even
            // when their alignment is off.
            if drive.near_along_route((c0, c1), (p0, p1), radius_m) {
                continue;
            }
            if wrong_pair(rec, drive, m, cw, pw, radius_m).unwrap_or((ca - pa).norm() > radius_m) {
                out.push(Confused {
                    places: ((c0, c1), (p0, p1)),
                    door_change: door_set(cw) != door_set(pw),
                });
            }
        }
    }
    out
}

/// Whether most aligned observation pairs of the word pair (`c`, `p`) lie farther apart than
/// `radius_m` (as evaluation scores pairs); `None` when the match holds none of them.
fn wrong_pair(
    rec: &Recognizer,
    drive: &Drive,
    m: &Match,
    c: &Word,
    p: &Word,
    radius_m: f64,
) -> Option<bool> {
    let obs = rec.observations();
    let at = |i: usize| {
        let f = obs[i].frame_id.min(drive.frames.len() - 1);
        drive.frames[f].truth.0.position()
    };
    let (cr, pr) = (c.obs_range(), p.obs_range());
    let (mut wrong, mut all) = (0, 0);
    for (q, pa) in m
        .pairs()
        .filter(|(q, pa)| cr.contains(q) && pr.contains(pa))
    {
        all += 1;
        wrong += usize::from((at(q) - at(pa)).norm() > radius_m);
    }
    (all > 0).then_some(2 * wrong > all)
}

/// A stretch of the loop: start and length, metres along the route.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Arc {
    start: f64,
    len: f64,
}

/// Stretches closer than this along the route are merged, metres.
const MERGE_GAP_M: f64 = 1.0;

impl Arc {
    fn new(from: f64, to: f64, loop_m: f64) -> Arc {
        Arc {
            start: from.rem_euclid(loop_m),
            len: (to - from).rem_euclid(loop_m),
        }
    }

    /// Whether the two stretches overlap or come within `MERGE_GAP_M`.
    fn touches(&self, o: &Arc, loop_m: f64) -> bool {
        let d = (o.start - self.start).rem_euclid(loop_m);
        d <= self.len + MERGE_GAP_M || loop_m - d <= o.len + MERGE_GAP_M
    }

    /// The shorter stretch covering both (they touch).
    fn union(&self, o: &Arc, loop_m: f64) -> Arc {
        let d = (o.start - self.start).rem_euclid(loop_m);
        let from_self = self.len.max(d + o.len);
        let from_other = o.len.max(loop_m - d + self.len);
        if from_self <= from_other {
            Arc {
                start: self.start,
                len: from_self.min(loop_m),
            }
        } else {
            Arc {
                start: o.start,
                len: from_other.min(loop_m),
            }
        }
    }
}

/// Confusions as pairs of stretches.
fn arcs(conf: &[Confusion], loop_m: f64) -> Vec<(Arc, Arc)> {
    let mut out: Vec<(Arc, Arc)> = conf
        .iter()
        .map(|((a, b), (c, d))| (Arc::new(*a, *b, loop_m), Arc::new(*c, *d, loop_m)))
        .collect();
    out.sort_by(|p, q| {
        p.0.start
            .total_cmp(&q.0.start)
            .then(p.1.start.total_cmp(&q.1.start))
    });
    out
}

/// `q` merged into `p` if their stretches touch side by side, in either order.
fn merge(p: &(Arc, Arc), q: &(Arc, Arc), loop_m: f64) -> Option<(Arc, Arc)> {
    if p.0.touches(&q.0, loop_m) && p.1.touches(&q.1, loop_m) {
        Some((p.0.union(&q.0, loop_m), p.1.union(&q.1, loop_m)))
    } else if p.0.touches(&q.1, loop_m) && p.1.touches(&q.0, loop_m) {
        Some((p.0.union(&q.1, loop_m), p.1.union(&q.0, loop_m)))
    } else {
        None
    }
}

/// Confused word pairs merged into pairs of stretches: two confusions join when their
/// stretches touch side by side (consecutive words of one n-gram do, and a confusion found in
/// both orders joins itself), until no two pairs touch. Each pair's earlier stretch comes first.
fn merged_pairs(conf: &[Confusion], loop_m: f64) -> Vec<(Arc, Arc)> {
    let mut pairs: Vec<(Arc, Arc)> = Vec::new();
    for c in arcs(conf, loop_m) {
        match pairs.iter().position(|p| merge(p, &c, loop_m).is_some()) {
            Some(i) => pairs[i] = merge(&pairs[i], &c, loop_m).unwrap_or(pairs[i]),
            None => pairs.push(c),
        }
    }
    let mut changed = true;
    while changed {
        changed = false;
        'outer: for i in 0..pairs.len() {
            for j in i + 1..pairs.len() {
                if let Some(m) = merge(&pairs[i], &pairs[j], loop_m) {
                    pairs[i] = m;
                    pairs.remove(j);
                    changed = true;
                    break 'outer;
                }
            }
        }
    }
    let mut out: Vec<(Arc, Arc)> = pairs
        .into_iter()
        .map(|(a, b)| if a.start <= b.start { (a, b) } else { (b, a) })
        .collect();
    out.sort_by(|p, q| p.0.start.total_cmp(&q.0.start));
    out
}

/// The numbered stretches, from 0: pair k gives stretches 2k and 2k + 1, each the other's
/// partner; each with its cause and score (the confused word pairs merged into it).
fn stretches(conf: &[Confused], loop_m: f64) -> Vec<AmbiguousStretch> {
    let places: Vec<Confusion> = conf.iter().map(|c| c.places).collect();
    merged_pairs(&places, loop_m)
        .iter()
        .enumerate()
        .flat_map(|(k, pair)| {
            let (na, nb) = (2 * k, 2 * k + 1);
            let inside: Vec<&Confused> = conf
                .iter()
                .filter(|c| merge(pair, &arcs(&[c.places], loop_m)[0], loop_m).is_some())
                .collect();
            let (a, b) = pair;
            let cause = cause_of(pair, &inside, loop_m);
            let score = inside.len() as f64;
            [
                stretch(a, (na, k, nb), cause, score, loop_m),
                stretch(b, (nb, k, na), cause, score, loop_m),
            ]
        })
        .collect()
}

/// Stretch `arc` (of a loop `loop_m` long), numbered `number`, half of pair `pair` with
/// stretch `partner`.
fn stretch(
    arc: &Arc,
    (number, pair, partner): (usize, usize, usize),
    cause: Cause,
    score: f64,
    loop_m: f64,
) -> AmbiguousStretch {
    AmbiguousStretch {
        number,
        pair,
        from_m: round_dm(arc.start),
        to_m: round_dm((arc.start + arc.len).rem_euclid(loop_m)),
        length_m: round_dm(arc.len),
        partners: vec![partner],
        cause,
        score,
    }
}

/// Why the stretches of `pair` look alike: they overlap (a shift), every confusion `inside`
/// them came with a door change, or they look alike.
fn cause_of((a, b): &(Arc, Arc), inside: &[&Confused], loop_m: f64) -> Cause {
    if a.touches(b, loop_m) {
        Cause::Shift
    } else if inside.iter().all(|c| c.door_change) && !inside.is_empty() {
        Cause::DoorChange
    } else {
        Cause::LookAlike
    }
}

/// Rounded to 0.1 m (the route positions are no more precise).
fn round_dm(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
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
    ambiguity_with(
        world,
        route_id,
        &DriveSettings::doors(doors),
        cfg,
        tp_radius_m,
    )
}

/// [`ambiguity`] over every door set of `settings` (one noise-free run of two laps each, all
/// matched against each other, as a scenario's laps under different doors are) with its
/// robot, plus the stretches where the alignment can slip along the route
/// ([`super::slip`]).
pub fn ambiguity_with(
    world: &World,
    route_id: &str,
    settings: &DriveSettings,
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
    let drive = drive(world, route, settings)?;
    // The route is driven one way: a stretch that looks like another only when read backwards
    // would confuse a robot driving it in reverse, which this map is not about.
    let mut one_way = cfg.clone();
    one_way.matcher.reverse = false;
    let mut rec = Recognizer::new(one_way)?;
    let mut matches = Vec::new();
    for (i, f) in drive.frames.iter().enumerate() {
        if i == 0 || drive.door_set_of_frame[i] != drive.door_set_of_frame[i - 1] {
            matches.extend(rec.start_run());
        }
        matches.extend(rec.push_frame(i, f.odom, &f.scan));
    }
    matches.extend(rec.finish());
    let conf = confusions(&rec, &drive, &matches, tp_radius_m);
    let length_m = route.length_m();
    let list = stretches(&conf, length_m);
    let share = covered_share(&list, length_m);
    let slips = super::slip::slips(&drive, cfg, tp_radius_m)?;
    let flagged_share = flagged(&list, &slips, length_m)
        .iter()
        .filter(|f| **f)
        .count() as f64
        / bins(length_m) as f64;
    let report = AmbiguityReport {
        world: world.name.clone(),
        route: route.id.clone(),
        route_length_m: length_m,
        levels: cfg.levels,
        min_ngram: crate::recognizer::thresholds(cfg),
        tp_radius_m,
        door_sets: settings.door_sets.iter().map(|d| d.name.clone()).collect(),
        confused_word_pairs: conf.len(),
        ambiguous_share: share,
        pairs: list.iter().map(|s| s.pair + 1).max().unwrap_or(0),
        stretches: list,
        slip_share: super::slip::share(&slips, length_m),
        slips,
        flagged_share,
    };
    Ok((report, drive))
}

/// Number of 0.1 m bins of a loop.
fn bins(loop_m: f64) -> usize {
    ((loop_m / BIN_M).ceil() as usize).max(1)
}

/// Marks the bins of `[from_m, from_m + length_m)` (wrapping) in `marked`.
pub(crate) fn mark(marked: &mut [bool], from_m: f64, length_m: f64) {
    let n = marked.len();
    let first = (from_m / BIN_M) as usize;
    let count = (length_m / BIN_M).round() as usize;
    (0..count.min(n)).for_each(|k| marked[(first + k) % n] = true);
}

/// Per 0.1 m bin of the loop: inside a look-alike stretch or a slip.
pub fn flagged(
    stretches: &[AmbiguousStretch],
    slips: &[super::slip::SlipStretch],
    loop_m: f64,
) -> Vec<bool> {
    let mut marked = vec![false; bins(loop_m)];
    for s in stretches {
        mark(&mut marked, s.from_m, s.length_m);
    }
    for s in slips {
        mark(&mut marked, s.from_m, s.length_m);
    }
    marked
}

/// Share of the loop inside at least one stretch (0.1 m resolution).
fn covered_share(list: &[AmbiguousStretch], loop_m: f64) -> f64 {
    let marked = flagged(list, &[], loop_m);
    marked.iter().filter(|m| **m).count() as f64 / marked.len() as f64
}

/// Colour of the slip bands.
pub const SLIP_COLOR: &str = "#8c8c8c";

/// Distinct colours for pairs of look-alike stretches (Tableau 10 without grey).
pub const PAIR_COLORS: [&str; 9] = [
    "#d62728", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#bcbd22",
    "#17becf",
];

/// Points of the route from `from_m` over `length_m` (forward, wrapping), every 0.25 m.
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
/// per pair of look-alike stretches joined by a thin line, and a list of the pairs under it.
pub fn ambiguity_svg(world: &World, doors: &DoorStates, report: &AmbiguityReport) -> String {
    use crate::report::world_render::{
        BandOverlay, MarkOverlay, RenderOptions, SegmentOverlay, render_world_svg,
    };
    let mut opts = RenderOptions {
        doors: doors.clone(),
        title: Some(title(report)),
        show_areas: false,
        show_door_labels: false,
        ..RenderOptions::default()
    };
    let Some(route) = world.route(&report.route) else {
        return render_world_svg(world, &opts);
    };
    let color = |k: usize| PAIR_COLORS[k % PAIR_COLORS.len()].to_string();
    let mut middles = std::collections::BTreeMap::<usize, Vec<Vec2>>::new();
    for s in &report.stretches {
        let pts = route_points(route, s.from_m, s.length_m);
        let mid = pts[pts.len() / 2];
        middles.entry(s.pair).or_default().push(mid);
        opts.marks.push(MarkOverlay {
            at: mid,
            text: s.pair.to_string(),
            color: color(s.pair),
            class: "ambiguous".into(),
        });
        opts.bands.push(BandOverlay {
            points: pts,
            color: color(s.pair),
            width_px: 10.0,
        });
    }
    for (k, m) in &middles {
        if let [a, b] = m.as_slice() {
            opts.segments.push(SegmentOverlay {
                color: color(*k),
                a: *a,
                b: *b,
                dashed: false,
            });
        }
    }
    // Slips under the look-alike bands: translucent grey, as wide as their uncertainty.
    for s in &report.slips {
        opts.bands.insert(
            0,
            BandOverlay {
                points: route_points(route, s.from_m, s.length_m),
                color: SLIP_COLOR.into(),
                width_px: 6.0 + 4.0 * s.uncertainty_m,
            },
        );
        let pts = route_points(route, s.from_m, s.length_m);
        opts.marks.push(MarkOverlay {
            at: pts[pts.len() / 2],
            text: format!("s{} ±{:.1} m", s.number, s.uncertainty_m),
            color: SLIP_COLOR.into(),
            class: "slip".into(),
        });
    }
    if !report.stretches.is_empty() {
        opts.legend.push(crate::report::world_render::LegendEntry {
            label: "look-alike stretches (same number: same words)".into(),
            color: PAIR_COLORS[0].into(),
            dashed: false,
        });
    }
    if !report.slips.is_empty() {
        opts.legend.push(crate::report::world_render::LegendEntry {
            label: "slips: the alignment can slide along the route (band width: uncertainty)"
                .into(),
            color: SLIP_COLOR.into(),
            dashed: false,
        });
    }
    opts.notes = notes(report);
    render_world_svg(world, &opts)
}

fn title(report: &AmbiguityReport) -> String {
    if !report.slips.is_empty() {
        return format!(
            "{}: route '{}': {} pair(s) of places look alike, {} slip(s); {:.0} % of the route \
             flagged",
            report.world,
            report.route,
            report.pairs,
            report.slips.len(),
            100.0 * report.flagged_share
        );
    }
    if report.stretches.is_empty() {
        return format!(
            "{}: route '{}': no two places look alike to the recognizer",
            report.world, report.route
        );
    }
    format!(
        "{}: route '{}': {} pair(s) of places look alike, {:.0} % of the route",
        report.world,
        report.route,
        report.pairs,
        100.0 * report.ambiguous_share
    )
}

/// Most pairs listed under the picture.
const MAX_NOTES: usize = 12;

/// One line per pair: where its two stretches are.
fn pair_lines(report: &AmbiguityReport) -> Vec<String> {
    report
        .stretches
        .chunks(2)
        .map(|c| {
            let at = |s: &AmbiguousStretch| format!("{:.1}-{:.1} m", s.from_m, s.to_m);
            let other = c.get(1).map(at).unwrap_or_default();
            let cause = match c[0].cause {
                Cause::LookAlike => "",
                Cause::DoorChange => " under other doors",
                Cause::Shift => ", shifted along itself",
            };
            format!(
                "{}: {} ({:.1} m) looks like {}{cause} (metres along the route from waypoint 0)",
                c[0].pair,
                at(&c[0]),
                c[0].length_m,
                other
            )
        })
        .collect()
}

/// One line per slip: where, how far the alignment can slide.
fn slip_lines(report: &AmbiguityReport) -> Vec<String> {
    report
        .slips
        .iter()
        .map(|s| {
            format!(
                "s{}: {:.1}-{:.1} m ({:.1} m): the alignment can slide by up to {:.1} m ({})",
                s.number, s.from_m, s.to_m, s.length_m, s.uncertainty_m, s.door_set
            )
        })
        .collect()
}

fn notes(report: &AmbiguityReport) -> Vec<String> {
    let mut lines = pair_lines(report);
    lines.extend(slip_lines(report));
    let mut out: Vec<String> = lines.iter().take(MAX_NOTES).cloned().collect();
    if lines.len() > MAX_NOTES {
        out.push(format!(
            "... and {} more (see --json)",
            lines.len() - MAX_NOTES
        ));
    }
    if lines.is_empty() {
        out.push(format!(
            "in a noise-free drive with these doors no n-gram of words occurs at two places \
             ({} level configuration(s), n-gram sizes {:?}); noise, doors and people can still \
             cause wrong matches",
            report.levels, report.min_ngram
        ));
    }
    out
}

impl AmbiguityReport {
    /// A few lines for people: the share of the route that is ambiguous and each pair.
    pub fn summary(&self) -> String {
        let mut out = format!(
            "{}: route '{}' ({:.0} m): {} pair(s) of look-alike stretches, {:.0} % of the route\n",
            self.world,
            self.route,
            self.route_length_m,
            self.pairs,
            100.0 * self.ambiguous_share
        );
        for line in pair_lines(self) {
            out.push_str(&format!("  {line}\n"));
        }
        if !self.slips.is_empty() || self.door_sets.len() > 1 {
            out.push_str(&format!(
                "{} slip(s), {:.0} % of the route; flagged in all: {:.0} % (door sets: {})\n",
                self.slips.len(),
                100.0 * self.slip_share,
                100.0 * self.flagged_share,
                self.door_sets.join(", ")
            ));
        }
        for line in slip_lines(self) {
            out.push_str(&format!("  {line}\n"));
        }
        out
    }
}
/// The report and picture `placewords world ambiguity` writes: default recognizer settings,
/// searching `levels` level configurations (default all three); words farther apart than the
/// default true-positive radius (1 m) are different places.
pub fn ambiguity_picture(
    world: &World,
    route_id: &str,
    doors: &DoorStates,
    levels: Option<usize>,
) -> Result<(AmbiguityReport, String), AmbiguityError> {
    let mut cfg = RecognizerConfig::default();
    cfg.levels = levels.unwrap_or(cfg.levels);
    let tp_radius_m = crate::spec::evaluation::EvaluationSpec::default().tp_radius_m;
    let (report, _) = ambiguity(world, route_id, doors, &cfg, tp_radius_m)?;
    let svg = ambiguity_svg(world, doors, &report);
    Ok((report, svg))
}
