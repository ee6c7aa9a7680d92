//! The scenario file format (TOML, `format_version = 1`): the structures of the file as
//! written, each value with its span so later checks can point at it, read with the one reader
//! (`crate::spec::read`). The checks against the world and the models built from these live
//! one layer up, in `experiment::scenario`.
//!
//! The reference, with every key, its unit, default and limits, is `docs/scenario-format.md`;
//! the key tables below are what the reader accepts (a test holds the two together).

use crate::spec::diag::{Diags, echo, fmt_number};
use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use crate::spec::read::{
    Val, get, integer, missing, number, parse_int, plain, points, string, strings, table,
    table_array, type_name, unknown_keys,
};
use crate::spec::seeds::SeedRange;
use crate::spec::world::MAX_ABS_COORD_M;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

type S<T> = Spanned<T>;

/// Most laps one run may drive: a run keeps every lap in memory until it is evaluated.
pub const MAX_LAPS: usize = 1_000;
/// Most people walking at once: every person is stepped and cast against every scan.
pub const MAX_PEDESTRIANS: usize = 200;
/// Smallest simulation step, seconds: a lap takes (lap time / step) steps.
pub const MIN_STEP_S: f64 = 0.001;
/// Largest simulation step, seconds: coarser steps make the robot jump through the world.
pub const MAX_STEP_S: f64 = 0.5;
/// Longest the robot may wait for a blocked route before the run fails, seconds.
pub const MAX_BLOCKED_TIMEOUT_S: f64 = 600.0;

/// How large one number of a model table may be: what keeps the simulator's arithmetic finite
/// (a uniform draw of ±1e308 overflows) and a lap's work bounded (stops every nanometre). The
/// sign and finiteness are the model's own rule (`experiment::scenario`); this is the size.
#[derive(Clone, Copy, Debug)]
pub struct NumberLimit {
    /// The table, without brackets: `laser`, `odometry`, `robot`, `pedestrians`.
    pub table: &'static str,
    pub key: &'static str,
    /// Largest magnitude accepted.
    pub max: f64,
    /// Smallest magnitude accepted besides 0 (0: no such bound).
    pub min_nonzero: f64,
    /// 0 turns the feature off (said in the message).
    pub off_at_zero: bool,
    /// Unit as the docs write it.
    pub unit: &'static str,
    /// A value that fits, for the message.
    pub typical: &'static str,
}

const fn lim(
    table: &'static str,
    key: &'static str,
    (min_nonzero, max): (f64, f64),
    unit: &'static str,
    typical: &'static str,
) -> NumberLimit {
    NumberLimit {
        table,
        key,
        max,
        min_nonzero,
        off_at_zero: false,
        unit,
        typical,
    }
}

/// [`lim`] of a feature 0 turns off.
const fn off(
    table: &'static str,
    key: &'static str,
    range: (f64, f64),
    unit: &'static str,
    typical: &'static str,
) -> NumberLimit {
    NumberLimit {
        off_at_zero: true,
        ..lim(table, key, range, unit, typical)
    }
}

/// Every size limit of a model number; `docs/scenario-format.md` shows each beside its key (a
/// test holds the two together).
pub const NUMBER_LIMITS: &[NumberLimit] = &[
    lim("laser", "max_range_m", (0.0, 1000.0), "m", "32.767"),
    lim("laser", "range_noise_m", (0.0, 1.0), "m", "0.005"),
    lim("laser", "angle_error_deg", (0.0, 10.0), "deg", "0.04"),
    lim("laser", "rate_hz", (0.1, 100.0), "Hz", "10"),
    lim("laser", "mount_x_m", (0.0, 1.0), "m", "0.021"),
    lim(
        "odometry",
        "translation_error_ratio",
        (0.0, 1.0),
        "",
        "0.0075",
    ),
    lim("odometry", "rotation_error_ratio", (0.0, 1.0), "", "0.0075"),
    lim("odometry", "alpha1", (0.0, 1.0), "", "0.01"),
    lim("odometry", "alpha2", (0.0, 1.0), "", "0.01"),
    lim("odometry", "alpha3", (0.0, 1.0), "", "0.01"),
    lim("odometry", "alpha4", (0.0, 1.0), "", "0.01"),
    lim(
        "odometry",
        "wheel_radius_bias_ratio",
        (0.0, 0.5),
        "",
        "0.01",
    ),
    lim(
        "odometry",
        "wheel_radius_mismatch_ratio",
        (0.0, 0.5),
        "",
        "0.01",
    ),
    lim("robot", "radius_m", (0.0, 2.0), "m", "0.25"),
    lim("robot", "axle_track_m", (0.0, 4.0), "m", "0.357"),
    lim("robot", "cruise_speed_m_s", (0.05, 5.0), "m/s", "0.4"),
    lim("robot", "max_speed_m_s", (0.05, 5.0), "m/s", "1.0"),
    lim(
        "robot",
        "max_turn_rate_deg_s",
        (1.0, 1000.0),
        "deg/s",
        "100",
    ),
    lim("robot", "accel_m_s2", (0.01, 100.0), "m/s²", "0.3"),
    lim(
        "robot",
        "turn_accel_deg_s2",
        (1.0, 10000.0),
        "deg/s²",
        "100",
    ),
    lim("robot", "lookahead_m", (0.05, 10.0), "m", "0.8"),
    lim("robot", "stop_distance_m", (0.0, 10.0), "m", "0.6"),
    lim("robot", "slow_distance_m", (0.0, 20.0), "m", "1.2"),
    lim("robot", "lane_margin_m", (0.0, 5.0), "m", "0.25"),
    off("robot", "stop_spacing_m", (1.0, 1e6), "m", "10"),
    lim("robot", "stop_duration_s", (0.0, 60.0), "s", "4"),
    off("robot", "spin_spacing_m", (1.0, 1e6), "m", "50"),
    lim("robot", "weave_wavelength_min_m", (0.2, 50.0), "m", "0.5"),
    lim("robot", "weave_wavelength_max_m", (0.2, 50.0), "m", "5"),
    lim("pedestrians", "speed_min_m_s", (0.0, 5.0), "m/s", "0.5"),
    lim("pedestrians", "speed_max_m_s", (0.0, 5.0), "m/s", "1.2"),
    lim("pedestrians", "radius_m", (0.01, 1.0), "m", "0.2"),
];

/// The limit of `key` in `[table]`, if it has one.
pub fn number_limit(table: &str, key: &str) -> Option<&'static NumberLimit> {
    NUMBER_LIMITS
        .iter()
        .find(|l| l.table == table && l.key == key)
}

/// Reports each number of `[table]` whose size is beyond its [`NumberLimit`].
fn check_number_limits(table: &str, s: &Settings, d: &mut Diags) {
    for (key, v) in &s.numbers {
        let (Some(l), x) = (number_limit(table, key), *v.get_ref()) else {
            continue;
        };
        let a = x.abs();
        // Non-finite values and signs are the model's checks; one message per value.
        if !a.is_finite() || (a <= l.max && (a == 0.0 || a >= l.min_nonzero)) {
            continue;
        }
        let what = beyond_words(l, x);
        d.at(
            v.span().start,
            format!(
                "{key} = {} in [{table}] is {what} the simulator takes; use {}",
                fmt_number(x),
                l.typical
            ),
        );
    }
}

/// How `x` is beyond limit `l`, as "more than 5 m, the most" (followed by "the simulator takes").
fn beyond_words(l: &NumberLimit, x: f64) -> String {
    let unit = if l.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", l.unit)
    };
    if x > l.max {
        format!("more than {}{unit}, the most", fmt_number(l.max))
    } else if x < -l.max {
        format!("less than -{}{unit}, the least", fmt_number(l.max))
    } else {
        let off = if l.off_at_zero {
            " (0 turns it off)"
        } else {
            ""
        };
        format!(
            "less than {}{unit}{off}, the finest",
            fmt_number(l.min_nonzero)
        )
    }
}

/// Keys of the top level.
pub const TOP_KEYS: &[&str] = &[
    "format_version",
    "name",
    "description",
    "world",
    "route",
    "seed",
    "seeds",
    "runs",
    "door_configs",
    "pedestrians",
    "laser",
    "odometry",
    "robot",
    "recognizer",
    "scan_context",
    "subjects",
    "evaluation",
    "expect",
];

/// Keys of `[scan_context]` (the Scan Context baseline, `baseline::scan_context`).
pub const SCAN_CONTEXT_KEYS: &[&str] = &[
    "observation_spacing_m",
    "rings",
    "sectors",
    "max_radius_m",
    "history_m",
    "cell_m",
    "candidates",
    "max_distance",
    "min_overlap_ratio",
];
/// Keys of a `[[runs]]` entry.
pub const RUN_KEYS: &[&str] = &[
    "start_waypoint",
    "direction",
    "laps",
    "doors",
    "doors_cycle",
    "doors_random",
];
/// Keys of a run's `doors_random` table.
pub const DOORS_RANDOM_KEYS: &[&str] = &["open_probability"];
/// Keys of `[pedestrians]`.
pub const PEDESTRIAN_KEYS: &[&str] = &[
    "count",
    "areas",
    "paths_m",
    "speed_min_m_s",
    "speed_max_m_s",
    "radius_m",
];
/// Keys of `[laser]`.
pub const LASER_KEYS: &[&str] = &[
    "preset",
    "max_range_m",
    "range_noise_m",
    "angle_error_deg",
    "rate_hz",
    "mount_x_m",
];
/// Keys of `[odometry]`.
pub const ODOMETRY_KEYS: &[&str] = &[
    "model",
    "translation_error_ratio",
    "rotation_error_ratio",
    "alpha1",
    "alpha2",
    "alpha3",
    "alpha4",
    "wheel_radius_bias_ratio",
    "wheel_radius_mismatch_ratio",
    "proportional_error",
];
/// Keys of `[robot]`.
pub const ROBOT_KEYS: &[&str] = &[
    "cruise_speed_m_s",
    "max_speed_m_s",
    "max_turn_rate_deg_s",
    "accel_m_s2",
    "turn_accel_deg_s2",
    "radius_m",
    "axle_track_m",
    "lookahead_m",
    "path_wander_m",
    "stop_distance_m",
    "slow_distance_m",
    "blocked_timeout_s",
    "step_s",
    "lane_offset_ratio",
    "lane_margin_m",
    "lap_speed_spread_ratio",
    "speed_wave_ratio",
    "stop_spacing_m",
    "stop_duration_s",
    "spin_spacing_m",
    "spin_angle_deg",
    "spin_angle_min_deg",
    "corner_spin_ratio",
    "lap_variation",
    "weave_heading_deg",
    "weave_wavelength_min_m",
    "weave_wavelength_max_m",
    "weave_envelope_ratio",
];
/// Keys of the recognizer's settings that the harness sets itself, never a file's
/// `[recognizer]` table: `levels` (each level configuration is run; `--levels` and
/// `[[expect.subjects]]` (`subject = "words-N"`) choose). A file that sets one is refused.
pub const RECOGNIZER_HARNESS_KEYS: &[&str] = &["levels"];
/// Keys whose value is a word rather than a number (besides a table's `model`/`preset`).
pub const WORD_KEYS: &[&str] = &["proportional_error", "lap_variation"];

/// A whole scenario file, as written.
#[derive(Clone, Debug)]
pub struct ScenarioSpec {
    pub name: Option<String>,
    pub description: Option<String>,
    /// World file, relative to the scenario file.
    pub world: S<String>,
    /// Route id in the world.
    pub route: S<String>,
    pub seed: S<u64>,
    /// `seeds = "1..20"`: the seeds `check` runs (both ends included); `None`: only `seed`.
    pub seeds: Option<S<SeedRange>>,
    pub runs: Vec<RunSpec>,
    /// `[door_configs]`: name and the door ids it opens, in file order.
    pub door_configs: Vec<(S<String>, Vec<S<String>>)>,
    pub pedestrians: Option<PedestriansSpec>,
    pub laser: Settings,
    pub odometry: Settings,
    pub robot: Settings,
    /// `[recognizer]` and its subtables: each key with its value; the recognizer's model knows
    /// the keys.
    pub recognizer: Vec<RecognizerEntry>,
    /// `[scan_context]`: the Scan Context baseline's numbers ([`SCAN_CONTEXT_KEYS`]).
    pub scan_context: Settings,
    /// `[[subjects]]`: recognizers in other processes the scenario runs
    /// (`spec::subjects`).
    pub subjects: Vec<crate::spec::subjects::SubjectSpec>,
    pub evaluation: EvaluationSpec,
    pub expect: ExpectSpec,
}

/// One `[[runs]]` entry.
#[derive(Clone, Debug)]
pub struct RunSpec {
    /// Where the entry starts.
    pub at: usize,
    /// Index into the route's waypoints, 0 for the first. Default 0.
    pub start_waypoint: Option<S<i64>>,
    /// Drive the route's waypoints in reverse order (`direction = "reverse"`). Default false
    /// (`"forward"`).
    pub reverse: bool,
    pub laps: S<usize>,
    /// How the doors are set; `None`: all closed.
    pub doors: Option<DoorsSpec>,
}

/// A run's door setting: exactly one of `doors`, `doors_cycle`, `doors_random`.
#[derive(Clone, Debug)]
pub enum DoorsSpec {
    Fixed(S<String>),
    Cycle(S<Vec<S<String>>>),
    /// `open_probability`.
    Random(S<f64>),
}

/// `[pedestrians]`.
#[derive(Clone, Debug)]
pub struct PedestriansSpec {
    pub count: S<usize>,
    pub areas: Vec<S<String>>,
    pub paths_m: Vec<S<Vec<[f64; 2]>>>,
    /// `speed_min_m_s`, `speed_max_m_s`, `radius_m`.
    pub settings: Settings,
}

/// A table of model settings: an optional name (`preset`, `model`) and numbers by key.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    pub name: Option<S<String>>,
    pub numbers: Vec<(&'static str, S<f64>)>,
    /// Word-valued keys ([`WORD_KEYS`]).
    pub words: Vec<(&'static str, S<String>)>,
}

impl Settings {
    /// The number given for `key`, if any.
    pub fn get(&self, key: &str) -> Option<&S<f64>> {
        self.numbers.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }

    /// The word given for `key`, if any.
    pub fn word(&self, key: &str) -> Option<&S<String>> {
        self.words.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }
}

/// Reads a scenario file's text, reporting every syntax, key, type and limit problem to `d`.
/// `None` when a required part could not be read.
pub fn read_scenario(src: &str, d: &mut Diags) -> Option<ScenarioSpec> {
    let doc = crate::spec::read::parse_document(src, d)?;
    let top = doc.get_ref();
    unknown_keys(top, TOP_KEYS, "the scenario file", d);
    // Every part is read before any is required, so one problem never hides the next.
    let head = read_head(top, d);
    let seeds = read_seeds(top, d);
    let runs = read_runs(top, d);
    let door_configs = read_door_configs(top, d);
    let pedestrians = read_pedestrians(top, d);
    let laser = read_settings(top, "laser", LASER_KEYS, "preset", d);
    let odometry = read_settings(top, "odometry", ODOMETRY_KEYS, "model", d);
    let robot = read_settings(top, "robot", ROBOT_KEYS, "", d);
    check_robot_limits(&robot, d);
    for (table, s) in [
        ("laser", &laser),
        ("odometry", &odometry),
        ("robot", &robot),
    ] {
        check_number_limits(table, s, d);
    }
    if let Some(p) = &pedestrians {
        check_number_limits("pedestrians", &p.settings, d);
    }
    let recognizer = read_recognizer(top, d);
    let scan_context = read_settings(top, "scan_context", SCAN_CONTEXT_KEYS, "", d);
    let subjects = crate::spec::subjects::read_subjects(top, d);
    let evaluation = crate::spec::evaluation::read_evaluation(top, d);
    let declared: Vec<&str> = subjects.iter().map(|s| s.name.get_ref().as_str()).collect();
    let expect = crate::spec::evaluation::read_expect(top, &declared, d);
    let (name, description, world, route, seed) = head?;
    Some(ScenarioSpec {
        name,
        description,
        world,
        route,
        seed,
        seeds,
        runs: runs?,
        door_configs,
        pedestrians,
        laser,
        odometry,
        robot,
        recognizer,
        scan_context,
        subjects,
        evaluation,
        expect,
    })
}

/// `name`, `description`, `world`, `route`, `seed`.
type Head = (Option<String>, Option<String>, S<String>, S<String>, S<u64>);

/// Reports a missing or unsupported `format_version` (only 1 is read).
fn check_format_version(top: &DeTable<'_>, ctx: &str, d: &mut Diags) {
    match get(top, "format_version") {
        None => missing(
            top,
            "format_version",
            TOP_KEYS,
            0,
            "missing key `format_version`; add `format_version = 1` as the first line".into(),
            d,
        ),
        Some((_, v)) => match integer(v, "format_version", ctx, d) {
            Some(1) | None => {}
            Some(n) => d.at(
                v.span().start,
                format!("format_version {n} is not supported; use format_version = 1"),
            ),
        },
    }
}

/// `format_version`, then the [`Head`].
fn read_head(top: &DeTable<'_>, d: &mut Diags) -> Option<Head> {
    let ctx = "the scenario file";
    check_format_version(top, ctx, d);
    let name = get(top, "name").and_then(|(_, v)| string(v, "name", ctx, d));
    let description = get(top, "description").and_then(|(_, v)| string(v, "description", ctx, d));
    let world = required_string(top, "world", "the world file, relative to this file", d);
    let route = required_string(top, "route", "a route id of the world", d);
    let seed = match get(top, "seed") {
        None => {
            missing(
                top,
                "seed",
                TOP_KEYS,
                0,
                "missing key `seed`; add `seed = 1`".into(),
                d,
            );
            None
        }
        Some((_, v)) => seed(v, d),
    };
    Some((name, description, world?, route?, seed?))
}

/// `seeds = "A..B"` (both ends included) or `seeds = "N"`.
fn read_seeds(top: &DeTable<'_>, d: &mut Diags) -> Option<S<SeedRange>> {
    let (_, v) = get(top, "seeds")?;
    let text = string(v, "seeds", "the scenario file", d)?;
    match text.parse::<SeedRange>() {
        Ok(r) => Some(Spanned::new(v.span(), r)),
        Err(e) => {
            d.at(v.span().start, e);
            None
        }
    }
}

fn seed(v: &Val<'_>, d: &mut Diags) -> Option<S<u64>> {
    let n = integer(v, "seed", "the scenario file", d)?;
    if n < 0 {
        d.at(
            v.span().start,
            "seed must be 0 or more; pick any non-negative integer".into(),
        );
    }
    // A negative seed is reported; the stand-in keeps the rest checked against the world.
    Some(Spanned::new(v.span(), n.max(0) as u64))
}

fn required_string(top: &DeTable<'_>, key: &str, what: &str, d: &mut Diags) -> Option<S<String>> {
    let Some((_, v)) = get(top, key) else {
        let msg = format!("missing key `{key}`; add `{key} = \"...\"` ({what})");
        missing(top, key, TOP_KEYS, 0, msg, d);
        return None;
    };
    string(v, key, "the scenario file", d).map(|s| Spanned::new(v.span(), s))
}

/// `[[runs]]`: at least one.
fn read_runs(top: &DeTable<'_>, d: &mut Diags) -> Option<Vec<RunSpec>> {
    let Some((kat, _)) = get(top, "runs") else {
        let msg = "no runs; add a [[runs]] entry with laps = 1 or more".to_string();
        missing(top, "runs", TOP_KEYS, 0, msg, d);
        return None;
    };
    let tables = table_array(top, "runs", d);
    if tables.is_empty() {
        d.at(
            kat,
            "no runs; add a [[runs]] entry with laps = 1 or more".into(),
        );
        return None;
    }
    // A run with a problem is left out; the problem is reported, so the file still fails.
    let runs = tables.into_iter().enumerate();
    Some(
        runs.filter_map(|(i, (at, t))| read_run(t, at, i, d))
            .collect(),
    )
}

fn read_run(t: &DeTable<'_>, at: usize, i: usize, d: &mut Diags) -> Option<RunSpec> {
    let ctx = format!("run #{i}");
    unknown_keys(t, RUN_KEYS, &ctx, d);
    let laps = match get(t, "laps") {
        None => {
            let msg = format!("missing key `laps` in {ctx}; add `laps = 1` or more");
            missing(t, "laps", RUN_KEYS, at, msg, d);
            None
        }
        Some((_, v)) => laps(v, &ctx, d),
    };
    let start_waypoint = get(t, "start_waypoint").and_then(|(_, v)| {
        integer(v, "start_waypoint", &ctx, d).map(|n| Spanned::new(v.span(), n))
    });
    let reverse = match get(t, "direction") {
        None => Some(false),
        Some((_, v)) => run_direction(v, &ctx, d),
    };
    let doors = read_run_doors(t, at, &ctx, d);
    Some(RunSpec {
        at,
        start_waypoint,
        reverse: reverse?,
        laps: laps?,
        doors: doors?,
    })
}

/// `direction = "forward" | "reverse"`: whether the run drives the route backwards.
fn run_direction(v: &Val<'_>, ctx: &str, d: &mut Diags) -> Option<bool> {
    match string(v, "direction", ctx, d)?.as_str() {
        "forward" => Some(false),
        "reverse" => Some(true),
        other => {
            d.at(
                v.span().start,
                format!(
                    "`direction` in {ctx} is \"{other}\"; write \"forward\" (the route's \
                     waypoint order, the default) or \"reverse\""
                ),
            );
            None
        }
    }
}

/// A lap count within 1..=[`MAX_LAPS`]; the one rule for files and for `--laps`.
pub fn check_laps(n: i64) -> Result<usize, String> {
    if n as u64 > MAX_LAPS as u64 && n >= 1 {
        Err(format!(
            "laps = {n} is more than {MAX_LAPS}, the most one run may drive (every lap is kept \
             in memory until evaluated); split the laps over several [[runs]]"
        ))
    } else {
        check_streamed_laps(n)
    }
}

/// Most laps per run `simulate --laps` accepts: it writes each lap as it is made, so memory is
/// no limit, but a million laps of the smallest world is about 1.8 TB of logs and days of work.
pub const MAX_STREAMED_LAPS: usize = 1_000_000;

/// A lap count within 1..=[`MAX_STREAMED_LAPS`], for `simulate --laps` (which holds no lap
/// after writing it).
pub fn check_streamed_laps(n: i64) -> Result<usize, String> {
    if n < 1 {
        Err(format!("laps = {n}; a run needs 1 lap or more"))
    } else if n as u64 > MAX_STREAMED_LAPS as u64 {
        Err(format!(
            "laps = {n} is more than {MAX_STREAMED_LAPS}, the most `simulate` writes per run \
             (about 1.8 MB of log per lap of loop-small)"
        ))
    } else {
        Ok(n as usize)
    }
}

fn laps(v: &Val<'_>, ctx: &str, d: &mut Diags) -> Option<S<usize>> {
    let at = v.span().start;
    let n = match v.get_ref() {
        // A whole number too large for i64 is still a lap count, just far too many.
        DeValue::Integer(i) => parse_int(i.as_str(), i.radix()).unwrap_or(i64::MAX),
        _ => integer(v, "laps", ctx, d)?,
    };
    match check_laps(n) {
        Ok(n) => Some(Spanned::new(v.span(), n)),
        Err(msg) => {
            // Reported; a stand-in keeps the rest of the file checked against its world.
            d.at(at, msg);
            Some(Spanned::new(v.span(), 1))
        }
    }
}

/// `Some(None)`: no door key (all closed); `None`: a problem was reported.
fn read_run_doors(
    t: &DeTable<'_>,
    at: usize,
    ctx: &str,
    d: &mut Diags,
) -> Option<Option<DoorsSpec>> {
    let given: Vec<&str> = ["doors", "doors_cycle", "doors_random"]
        .into_iter()
        .filter(|k| get(t, k).is_some())
        .collect();
    if given.len() > 1 {
        let at = get(t, given[1]).map(|(k, _)| k).unwrap_or(at);
        d.at(
            at,
            "this run sets more than one of doors, doors_cycle and doors_random; keep one".into(),
        );
        return None;
    }
    let Some(&key) = given.first() else {
        return Some(None);
    };
    let (_, v) = get(t, key)?;
    let doors = match key {
        "doors" => DoorsSpec::Fixed(Spanned::new(v.span(), string(v, key, ctx, d)?)),
        "doors_cycle" => DoorsSpec::Cycle(Spanned::new(v.span(), strings(v, key, ctx, d)?)),
        _ => DoorsSpec::Random(open_probability(v, ctx, d)?),
    };
    Some(Some(doors))
}

fn open_probability(v: &Val<'_>, ctx: &str, d: &mut Diags) -> Option<S<f64>> {
    let DeValue::Table(t) = v.get_ref() else {
        d.at(v.span().start, format!(
            "`doors_random` in {ctx} must be a table, found {}; write `doors_random = {{ open_probability = 0.3 }}`",
            type_name(v.get_ref())));
        return None;
    };
    unknown_keys(t, DOORS_RANDOM_KEYS, "doors_random", d);
    let Some((_, p)) = get(t, "open_probability") else {
        d.at(
            v.span().start,
            "missing key `open_probability` in doors_random; add `open_probability = 0.3`".into(),
        );
        return None;
    };
    let x = number(p, "open_probability", "doors_random", d)?;
    if !(0.0..=1.0).contains(&x) {
        d.at(
            p.span().start,
            format!("open_probability {} is outside 0..1", fmt_number(x)),
        );
        return None;
    }
    Some(Spanned::new(p.span(), x))
}

/// `[door_configs]`: name = [door ids].
fn read_door_configs(top: &DeTable<'_>, d: &mut Diags) -> Vec<(S<String>, Vec<S<String>>)> {
    let Some((_, t)) = table(top, "door_configs", d) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (k, v) in t.iter() {
        let name = k.get_ref().to_string();
        if let Some(ids) = strings(v, &name, "[door_configs]", d) {
            out.push((Spanned::new(k.span(), name), ids));
        }
    }
    out
}

fn read_pedestrians(top: &DeTable<'_>, d: &mut Diags) -> Option<PedestriansSpec> {
    let (at, t) = table(top, "pedestrians", d)?;
    let ctx = "[pedestrians]";
    unknown_keys(t, PEDESTRIAN_KEYS, ctx, d);
    let count = read_count(t, at, d);
    let areas = get(t, "areas")
        .and_then(|(_, v)| strings(v, "areas", ctx, d))
        .unwrap_or_default();
    let paths_m = get(t, "paths_m")
        .map(|(_, v)| walk_paths(v, d))
        .unwrap_or_default();
    let settings = settings_of(t, &PEDESTRIAN_KEYS[3..], "", ctx, d);
    Some(PedestriansSpec {
        count: count?,
        areas,
        paths_m,
        settings,
    })
}

/// The required `count` of `[pedestrians]` (the table at `at`).
fn read_count(t: &DeTable<'_>, at: usize, d: &mut Diags) -> Option<S<usize>> {
    match get(t, "count") {
        None => {
            missing(
                t,
                "count",
                PEDESTRIAN_KEYS,
                at,
                "missing key `count` in [pedestrians]; add `count = 1`".into(),
                d,
            );
            None
        }
        Some((_, v)) => pedestrian_count(v, d),
    }
}

fn pedestrian_count(v: &Val<'_>, d: &mut Diags) -> Option<S<usize>> {
    let at = v.span().start;
    let n = match v.get_ref() {
        DeValue::Integer(i) => parse_int(i.as_str(), i.radix()).unwrap_or(i64::MAX),
        _ => integer(v, "count", "[pedestrians]", d)?,
    };
    if n < 0 {
        d.at(at, "count must be 0 or more".into());
        return None;
    }
    if n as u64 > MAX_PEDESTRIANS as u64 {
        d.at(
            at,
            format!(
                "count = {n} is more than {MAX_PEDESTRIANS}, the most people a scenario may hold \
             (each is simulated every step); use fewer"
            ),
        );
        return None;
    }
    Some(Spanned::new(v.span(), n as usize))
}

fn walk_paths(v: &Val<'_>, d: &mut Diags) -> Vec<S<Vec<[f64; 2]>>> {
    let DeValue::Array(a) = v.get_ref() else {
        d.at(v.span().start, format!(
            "`paths_m` in [pedestrians] must be a list of paths, found {}; write e.g. `[[[1.0, 1.0], [5.0, 1.0]]]`",
            type_name(v.get_ref())));
        return Vec::new();
    };
    let mut out = Vec::new();
    for p in a.iter() {
        out.extend(walk_path(p, d));
    }
    out
}

/// One path of `paths_m`, reported when it has fewer than two points or a point far out;
/// `None` when it is not kept.
fn walk_path(p: &Val<'_>, d: &mut Diags) -> Option<S<Vec<[f64; 2]>>> {
    let mut spans = Vec::new();
    let pts = points(p, "paths_m", "[pedestrians]", d, &mut spans)?;
    let far = pts
        .iter()
        .zip(&spans[spans.len() - pts.len()..])
        .find(|(q, _)| q[0].abs() > MAX_ABS_COORD_M || q[1].abs() > MAX_ABS_COORD_M);
    if pts.len() < 2 {
        d.at(
            p.span().start,
            "a path needs at least two finite points [x, y]".into(),
        );
        return None;
    }
    if let Some((q, &at)) = far {
        d.at(
            at,
            format!(
                "the walking point [{}, {}] is more than {:.0} km from the origin; paths \
                 are metres in the world's frame: use points inside the world",
                fmt_number(q[0]),
                fmt_number(q[1]),
                MAX_ABS_COORD_M / 1000.0
            ),
        );
        // Kept, so the file does not also read as having nowhere to walk.
    }
    Some(Spanned::new(p.span(), pts))
}

/// A model table (`[laser]`, `[odometry]`, `[robot]`); absent means all defaults.
fn read_settings(
    top: &DeTable<'_>,
    key: &str,
    known: &'static [&'static str],
    name_key: &str,
    d: &mut Diags,
) -> Settings {
    match table(top, key, d) {
        None => Settings::default(),
        Some((_, t)) => {
            let ctx = format!("[{key}]");
            unknown_keys(t, known, &ctx, d);
            settings_of(t, known, name_key, &ctx, d)
        }
    }
}

fn settings_of(
    t: &DeTable<'_>,
    known: &'static [&'static str],
    name_key: &str,
    ctx: &str,
    d: &mut Diags,
) -> Settings {
    let mut out = Settings::default();
    for &key in known {
        let Some((_, v)) = get(t, key) else { continue };
        if key == name_key {
            out.name = string(v, key, ctx, d).map(|s| Spanned::new(v.span(), s));
        } else if WORD_KEYS.contains(&key) {
            if let Some(w) = string(v, key, ctx, d) {
                out.words.push((key, Spanned::new(v.span(), w)));
            }
        } else if let Some(x) = number(v, key, ctx, d) {
            out.numbers.push((key, Spanned::new(v.span(), x)));
        }
    }
    out
}

/// The limits that keep a run finite: the step and the blocked timeout.
fn check_robot_limits(robot: &Settings, d: &mut Diags) {
    if let Some(s) = robot.get("step_s")
        && !(MIN_STEP_S..=MAX_STEP_S).contains(s.get_ref())
    {
        d.at(s.span().start, format!(
            "step_s = {} is outside {MIN_STEP_S}..{MAX_STEP_S} s (a lap takes lap time / step_s \
             steps); use 0.05", fmt_number(*s.get_ref())));
    }
    if let Some(s) = robot.get("blocked_timeout_s")
        && !(*s.get_ref() > 0.0 && *s.get_ref() <= MAX_BLOCKED_TIMEOUT_S)
    {
        d.at(
            s.span().start,
            format!(
                "blocked_timeout_s = {} is outside (0, {MAX_BLOCKED_TIMEOUT_S}] s; a robot blocked \
             longer is stuck: use 10",
                fmt_number(*s.get_ref())
            ),
        );
    }
}

/// A recognizer settings file (`recognize --config`): a `[recognizer]` table, read as a
/// scenario's, and nothing else (any other key would be silently unused). `None` when the
/// text is not TOML.
pub fn read_recognizer_file(src: &str, d: &mut Diags) -> Option<Vec<RecognizerEntry>> {
    let doc = crate::spec::read::parse_document(src, d)?;
    let top = doc.get_ref();
    unknown_keys(
        top,
        &["recognizer"],
        "a recognizer settings file (it holds a [recognizer] table only)",
        d,
    );
    if get(top, "recognizer").is_none() {
        d.at(
            0,
            "no [recognizer] table; put the settings under [recognizer]".to_string(),
        );
    }
    Some(read_recognizer(top, d))
}

/// One key of `[recognizer]` or of one of its subtables, as written.
#[derive(Clone, Debug)]
pub struct RecognizerEntry {
    /// The subtable (`grid` for `[recognizer.grid]`); `None` for a key of `[recognizer]` itself.
    pub section: Option<S<String>>,
    pub key: S<String>,
    pub value: toml::Value,
}

impl RecognizerEntry {
    /// Whether this is `key` of subtable `section` (`""`: of `[recognizer]` itself).
    pub fn is(&self, section: &str, key: &str) -> bool {
        self.key.get_ref() == key
            && self.section.as_ref().map_or("", |s| s.get_ref().as_str()) == section
    }
}

/// `[recognizer]` and its subtables as plain keys and values, a subtable's keys one by one;
/// the recognizer's model checks them.
fn read_recognizer(top: &DeTable<'_>, d: &mut Diags) -> Vec<RecognizerEntry> {
    let Some((_, t)) = table(top, "recognizer", d) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (k, v) in t.iter() {
        let key = Spanned::new(k.span(), k.get_ref().to_string());
        match v.get_ref() {
            DeValue::Table(sub) => {
                for (k2, v2) in sub.iter() {
                    let entry = recognizer_entry(Some(key.clone()), k2, v2, d);
                    out.extend(entry);
                }
            }
            _ => out.extend(recognizer_entry(None, k, v, d)),
        }
    }
    out
}

/// One key and its plain value; `None` (reported) when the value is out of range.
fn recognizer_entry(
    section: Option<S<String>>,
    k: &Spanned<std::borrow::Cow<'_, str>>,
    v: &Spanned<DeValue<'_>>,
    d: &mut Diags,
) -> Option<RecognizerEntry> {
    let Some(value) = plain(v.get_ref()) else {
        let table = section
            .as_ref()
            .map_or(String::new(), |s| format!(".{}", s.get_ref()));
        d.at(
            v.span().start,
            format!(
                "`{}` in [recognizer{table}] is out of range",
                echo(k.get_ref())
            ),
        );
        return None;
    };
    Some(RecognizerEntry {
        section,
        key: Spanned::new(k.span(), k.get_ref().to_string()),
        value,
    })
}

/// The line (1-based) of the scenario text's `[expect]` table, or of its first `[expect.…]` /
/// `[[expect.…]]` header when it has no plain one; `None` without either. CI annotations point
/// there.
pub fn expect_line(src: &str) -> Option<usize> {
    let header = |l: &str| {
        let l = l.trim_start().trim_start_matches('[').trim_start();
        l.starts_with("expect]") || l.starts_with("expect.")
    };
    let lines: Vec<&str> = src.lines().collect();
    let plain = lines
        .iter()
        .position(|l| l.trim_start().starts_with("[expect]"));
    plain
        .or_else(|| {
            lines
                .iter()
                .position(|l| l.trim_start().starts_with('[') && header(l))
        })
        .map(|i| i + 1)
}

#[cfg(test)]
mod expect_line_tests {
    use super::expect_line;

    #[test]
    fn finds_the_expect_table_or_its_first_sub_table() {
        assert_eq!(
            expect_line("seed = 1\n\n[expect]\nquantile = 0.1\n"),
            Some(3)
        );
        assert_eq!(
            expect_line("a = 1\n[[expect.levels]]\nlevels = 3\n"),
            Some(2)
        );
        assert_eq!(expect_line("a = 1\n[expectation]\n"), None);
        assert_eq!(expect_line("# [expect]\n"), None);
    }
}
