//! A checked scenario: the file read by `spec::scenario`, checked against its world and built
//! into the simulator's plan and the recognizer's, evaluation's and gate's settings. Every
//! problem is reported at once, each at its value. The format (all keys, units, defaults,
//! limits) is `docs/scenario-format.md`.
//!
//! ```toml
//! format_version = 1
//! name = "smoke"                        # optional; default: the file stem
//! world = "../worlds/loop-small.toml"   # relative to this file
//! route = "lap"
//! seed = 42                             # the seed of `run` (and of `check` without `seeds`)
//! seeds = "1..20"                       # optional: the seeds `check` runs (both ends included)
//!
//! [door_configs]                        # named sets of open doors
//! south-open = ["d-south"]
//!
//! [[runs]]
//! start_waypoint = 0                    # default 0
//! direction = "forward"                 # default; "reverse" drives the waypoints backwards
//! laps = 2
//! doors = "all-closed"                  # "all-closed", "all-open" or a [door_configs] name
//! # doors_cycle = ["all-closed", "south-open"]    # lap k uses entry k mod len
//! # doors_random = { open_probability = 0.3 }    # each door open with this probability, per lap
//!
//! [pedestrians]                         # optional
//! count = 2
//! areas = ["corridor-south"]            # world area ids, and/or:
//! paths_m = [[[1.0, 1.0], [5.0, 1.0]]]
//! speed_min_m_s = 0.5                   # default 0.5
//! speed_max_m_s = 1.2                   # default 1.2
//! radius_m = 0.2                        # default 0.2
//!
//! [laser]                               # preset "lms200" (default) or "lms200-mm", then overrides:
//! preset = "lms200"                     # max_range_m, range_noise_m, angle_error_deg, rate_hz, mount_x_m
//!
//! [odometry]                            # model "proportional" (default) or "thrun"
//! model = "proportional"                # translation_error_ratio, rotation_error_ratio (0.0075)
//! # model = "thrun"                     # alpha1..alpha4
//! # wheel_radius_bias_ratio = 0.0, wheel_radius_mismatch_ratio = 0.0
//!
//! [robot]                               # cruise_speed_m_s, max_speed_m_s, max_turn_rate_deg_s,
//!                                       # accel_m_s2, turn_accel_deg_s2, radius_m, axle_track_m,
//!                                       # lookahead_m, path_wander_m, stop_distance_m, slow_distance_m,
//!                                       # blocked_timeout_s, step_s
//! [recognizer]                          # any table, for the recognizer
//! [scan_context]                        # the Scan Context baseline: observation_spacing_m, rings,
//!                                       # sectors, max_radius_m, history_m, cell_m, candidates,
//!                                       # max_distance, min_overlap_ratio (ScanContextConfig)
//! [evaluation]                          # crate::spec::evaluation::EvaluationSpec
//! [[subjects]]                          # recognizers in other processes: name, exec, timeout_s, args
//! [expect]                              # crate::spec::evaluation::ExpectSpec
//! ```
//!
//! At most one of `doors`, `doors_cycle`, `doors_random` per run; none means all closed.

use crate::baseline::scan_context::ScanContextConfig;
use crate::external::ExternalSpec;
use crate::geom::Vec2;
use crate::recognizer::RecognizerConfig;
use crate::sim::laser::{LaserConfig, LaserPreset};
use crate::sim::odometry::{DEFAULT_THRUN_ALPHA, OdometryConfig, OdometryModel, ProportionalError};
use crate::sim::pedestrians::{PedestrianConfig, WalkSource};
use crate::sim::plan::{DoorChoice, DoorPlan, RunPlan, SimPlan};
use crate::sim::robot::RobotConfig;
use crate::sim::variation::LapVariationConfig;
use crate::spec::diag::{Diagnostic, Diags, echo, fmt_number, read_text};
use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use crate::spec::scenario::{DoorsSpec, PedestriansSpec, RunSpec, ScenarioSpec, Settings};
use crate::spec::seeds::SeedRange;
use crate::spec::subjects::SubjectSpec;
use crate::spec::suggest::hint;
use crate::spec::{SpecError, scenario::read_scenario};
use crate::world::{DoorStates, Route, World, WorldCheck};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

type S<T> = Spanned<T>;

/// A checked scenario: what to simulate, and how to recognize, evaluate and gate it.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// The simulation: world, route, seed, runs and models (its `name` is the scenario's).
    pub sim: SimPlan,
    pub description: Option<String>,
    /// The seeds `check` runs by default (`seeds = "1..20"`); `None`: only `sim.seed`.
    pub seeds: Option<SeedRange>,
    /// Recognizer settings: the `[recognizer]` table over the defaults.
    pub recognizer: RecognizerConfig,
    /// The Scan Context baseline's settings: the `[scan_context]` table over the defaults.
    pub scan_context: ScanContextConfig,
    /// The `[[subjects]]`: recognizers in other processes, each run in the scenario file's
    /// folder (so a relative path in its command resolves there).
    pub subjects: Vec<ExternalSpec>,
    pub evaluation: EvaluationSpec,
    pub expect: ExpectSpec,
}

/// Loads a world file checked for a robot (tests pass a closure that parses a string).
pub type WorldLoader<'a> = &'a dyn Fn(&Path, &WorldCheck) -> Result<World, SpecError>;

/// What a command will do with a scenario, for its work budget (`work_budget`): the lap count
/// that replaces every run's, and how many back-end passes read the observations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Workload {
    /// `--laps`: laps per run, replacing the file's. Default `None` (the file's).
    pub laps: Option<usize>,
    /// Back-end passes over the observations: one per level configuration run (`check`,
    /// `run`, `table`), one per grid point and score curve (`sweep`). Default 1.
    pub passes: usize,
    /// Whether the Scan Context baseline runs (it holds a descriptor per observation of its
    /// own). Default false.
    pub scan_context: bool,
}

impl Default for Workload {
    fn default() -> Self {
        Workload {
            laps: None,
            passes: 1,
            scan_context: false,
        }
    }
}

/// Reads and checks a scenario file and the world it names.
pub fn load_scenario(path: &Path) -> Result<Scenario, SpecError> {
    load_scenario_for(path, &Workload::default())
}

/// [`load_scenario`] for a command that does `work` with it: the work budget counts its laps
/// and passes, and refuses the file (at the key that sets the work) beyond its limits.
pub fn load_scenario_for(path: &Path, work: &Workload) -> Result<Scenario, SpecError> {
    let src = read_text(path)?;
    parse_scenario_for(&src, path, &crate::world::load_world_for, work)
}

/// `scenario check` of a file: [`load_scenario`], then a test drive of its route as its runs
/// drive it, for its robot and laser (`sim::test_drive`); a route the robot cannot drive is
/// refused at the waypoint's place in the world file.
pub fn check_scenario(path: &Path) -> Result<Scenario, SpecError> {
    let s = load_scenario(path)?;
    let sim = &s.sim;
    let route = sim.world.routes.iter().position(|r| r.id == sim.route.id);
    let problems = crate::sim::test_drive::plan_problems(sim, route.unwrap_or(0));
    if problems.is_empty() {
        return Ok(s);
    }
    let src = read_text(&sim.world_path)?;
    let check = WorldCheck {
        robot_radius_m: sim.robot.radius_m,
    };
    let shown = sim.world_path.display().to_string();
    crate::world::parse_world_spec_checked(&src, &shown, &check, Some(&|_| problems.clone()))?;
    Ok(s)
}

/// Parses and checks a scenario's text. `path` names the file in messages and anchors the world
/// path. Every problem of the file is reported, then those of its world.
pub fn parse_scenario(
    src: &str,
    path: &Path,
    load_world: WorldLoader,
) -> Result<Scenario, SpecError> {
    parse_scenario_for(src, path, load_world, &Workload::default())
}

/// [`parse_scenario`] for a command that does `work` with it ([`load_scenario_for`]).
pub fn parse_scenario_for(
    src: &str,
    path: &Path,
    load_world: WorldLoader,
    work: &Workload,
) -> Result<Scenario, SpecError> {
    let file = path.display().to_string();
    let mut d = Diags::new(src, &file);
    let mut world_problems = Vec::new();
    let built = read_scenario(src, &mut d).and_then(|spec| {
        let models = Models::build(&spec, &mut d);
        let scan_context = scan_context(&spec.scan_context, &mut d);
        let subjects = subjects(&spec.subjects, path, &mut d);
        let world_path = resolve(path, spec.world.get_ref());
        let check = WorldCheck {
            robot_radius_m: models.robot.radius_m,
        };
        let world = load_for(
            &spec,
            &world_path,
            &check,
            load_world,
            &mut d,
            &mut world_problems,
        )?;
        let work = (work, scan_context.observation_spacing_m);
        let sim = plan(&spec, world, models, (path, world_path), work, &mut d)?;
        Some((spec, sim, scan_context, subjects))
    });
    let mut diags = d.into_sorted();
    diags.append(&mut world_problems);
    match built {
        Some((spec, sim, scan_context, subjects)) if diags.is_empty() => Ok(Scenario {
            recognizer: sim.1,
            scan_context,
            subjects,
            sim: sim.0,
            description: spec.description,
            seeds: spec.seeds.map(|s| s.into_inner()),
            evaluation: spec.evaluation,
            expect: spec.expect,
        }),
        _ if diags.is_empty() => Err(SpecError::Invalid(vec![Diagnostic::error(
            &file,
            (1, 1),
            "the file could not be read as a scenario; check it against scenarios/smoke.toml",
        )])),
        _ => Err(SpecError::Invalid(diags)),
    }
}

/// The world path, relative to the scenario's folder unless absolute.
/// The `[[subjects]]` entries as runnable specs: the command with its arguments quoted, run in
/// the folder of the scenario file at `path`.
fn subjects(specs: &[SubjectSpec], path: &Path, d: &mut Diags) -> Vec<ExternalSpec> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut out = Vec::new();
    for s in specs {
        let args: Vec<String> = s.args.iter().map(|a| a.get_ref().clone()).collect();
        let command = match ExternalSpec::command_with_args(s.exec.get_ref(), &args) {
            Ok(c) => c,
            Err(why) => {
                let at = s
                    .args
                    .first()
                    .map_or(s.exec.span().start, |a| a.span().start);
                d.at(at, format!("{why}; remove the NUL character"));
                continue;
            }
        };
        let mut spec = ExternalSpec::new(s.name.get_ref(), &command);
        if let Some(t) = &s.timeout_s {
            spec.timeout_s = *t.get_ref();
        }
        spec.dir = Some(dir.clone());
        spec.declared_in = Some(path.display().to_string());
        out.push(spec);
    }
    out
}

fn resolve(scenario: &Path, world: &str) -> PathBuf {
    let rel = PathBuf::from(world);
    match scenario.parent() {
        Some(dir) if !rel.is_absolute() => dir.join(rel),
        _ => rel,
    }
}

/// The world, checked for this scenario's robot, so a larger robot is refused here rather than
/// found "blocked" halfway through a run. The world's own problems go to `extra`.
fn load_for(
    spec: &ScenarioSpec,
    world_path: &Path,
    check: &WorldCheck,
    load_world: WorldLoader,
    d: &mut Diags,
    extra: &mut Vec<Diagnostic>,
) -> Option<World> {
    let at = spec.world.span().start;
    let shown = echo(&world_path.display().to_string());
    match load_world(world_path, check) {
        Ok(w) => Some(w),
        Err(SpecError::Io { source, .. }) => {
            d.at(at, format!(
                "cannot read world file `{shown}`: {source}; the path is relative to the scenario file"));
            None
        }
        Err(SpecError::Invalid(mut problems)) => {
            let robot = if *check == WorldCheck::default() {
                String::new()
            } else {
                format!(
                    " for this scenario's robot (radius_m = {})",
                    check.robot_radius_m
                )
            };
            d.at(
                at,
                format!("world `{shown}` is invalid{robot}; fix the problems listed below"),
            );
            extra.append(&mut problems);
            None
        }
    }
}

/// The settings that need no world: laser, odometry, robot, recognizer.
struct Models {
    laser: LaserConfig,
    odometry: OdometryConfig,
    robot: RobotConfig,
    recognizer: RecognizerConfig,
}

impl Models {
    fn build(spec: &ScenarioSpec, d: &mut Diags) -> Models {
        Models {
            laser: laser(&spec.laser, d),
            odometry: odometry(&spec.odometry, d),
            robot: robot(&spec.robot, d),
            recognizer: super::recognizer_settings::recognizer(&spec.recognizer, d),
        }
    }
}

/// What a number must be.
#[derive(Clone, Copy)]
enum Rule {
    Positive,
    NonNegative,
    Finite,
}

/// The number given for `key`, or `default` (the model's own) when absent or out of range.
fn value(d: &mut Diags, s: &Settings, key: &str, default: f64, rule: Rule) -> f64 {
    let Some(x) = s.get(key) else {
        return default;
    };
    let v = *x.get_ref();
    let (ok, what) = match rule {
        Rule::Positive => (v > 0.0, "positive"),
        Rule::NonNegative => (v >= 0.0, "non-negative"),
        Rule::Finite => (true, "finite"),
    };
    if ok && v.is_finite() {
        return v;
    }
    d.at(
        x.span().start,
        format!(
            "{key} = {} is out of range; use a {what} number (default {default})",
            fmt_number(v)
        ),
    );
    default
}

/// A name out of `known`, or an error with a "did you mean".
fn named<'a>(d: &mut Diags, name: &S<String>, known: &[&'a str], what: &str) -> Option<&'a str> {
    let n = name.get_ref().as_str();
    let found = known.iter().find(|k| **k == n).copied();
    if found.is_none() {
        let h = hint(n, known.iter().copied(), &format!("{what}s"));
        d.at(
            name.span().start,
            format!("unknown {what} `{}`; {h}", echo(n)),
        );
    }
    found
}

fn laser(s: &Settings, d: &mut Diags) -> LaserConfig {
    let preset = s
        .name
        .as_ref()
        .and_then(|p| named(d, p, &LaserPreset::NAMES, "laser preset"))
        .and_then(LaserPreset::from_name)
        .unwrap_or(LaserPreset::Lms200);
    let mut l = LaserConfig::preset(preset);
    l.max_range_m = value(d, s, "max_range_m", l.max_range_m, Rule::Positive);
    l.range_noise_m = value(d, s, "range_noise_m", l.range_noise_m, Rule::NonNegative);
    let angle_deg = l.angle_error_rad.to_degrees();
    l.angle_error_rad = value(d, s, "angle_error_deg", angle_deg, Rule::NonNegative).to_radians();
    l.rate_hz = value(d, s, "rate_hz", l.rate_hz, Rule::Positive);
    l.mount_x_m = value(d, s, "mount_x_m", l.mount_x_m, Rule::Finite);
    l
}

const ALPHA_NAMES: [&str; 4] = ["alpha1", "alpha2", "alpha3", "alpha4"];
const RATIO_NAMES: [&str; 2] = ["translation_error_ratio", "rotation_error_ratio"];

fn odometry(s: &Settings, d: &mut Diags) -> OdometryConfig {
    let mut o = OdometryConfig::default();
    let thrun = match &s.name {
        Some(m) => named(d, m, &["proportional", "thrun"], "odometry model") == Some("thrun"),
        None => false,
    };
    other_model_keys(s, thrun, d);
    o.model = match (thrun, o.model) {
        (true, _) => {
            let mut alpha = DEFAULT_THRUN_ALPHA;
            for (a, key) in alpha.iter_mut().zip(ALPHA_NAMES) {
                *a = value(d, s, key, *a, Rule::NonNegative);
            }
            OdometryModel::Thrun { alpha }
        }
        (
            false,
            OdometryModel::Proportional {
                translation_ratio,
                rotation_ratio,
            },
        ) => OdometryModel::Proportional {
            translation_ratio: value(d, s, RATIO_NAMES[0], translation_ratio, Rule::NonNegative),
            rotation_ratio: value(d, s, RATIO_NAMES[1], rotation_ratio, Rule::NonNegative),
        },
        (false, model) => model,
    };
    o.proportional = proportional_error(s, d);
    let bias = o.wheel_radius_bias_ratio;
    o.wheel_radius_bias_ratio = value(d, s, "wheel_radius_bias_ratio", bias, Rule::Finite);
    let mismatch = o.wheel_radius_mismatch_ratio;
    o.wheel_radius_mismatch_ratio =
        value(d, s, "wheel_radius_mismatch_ratio", mismatch, Rule::Finite);
    o
}

/// `[odometry] proportional_error`: "each-update" (MobileSim, default) or "random-walk".
fn proportional_error(s: &Settings, d: &mut Diags) -> ProportionalError {
    let Some(w) = s.word("proportional_error") else {
        return ProportionalError::default();
    };
    match named(d, w, &["each-update", "random-walk"], "proportional_error") {
        Some("random-walk") => ProportionalError::RandomWalk,
        _ => ProportionalError::EachUpdate,
    }
}

/// A ratio in `[0, max]`, or an error and the default.
fn bounded(d: &mut Diags, s: &Settings, key: &str, default: f64, max: f64) -> f64 {
    let v = value(d, s, key, default, Rule::NonNegative);
    match s.get(key) {
        Some(x) if v > max => {
            d.at(
                x.span().start,
                format!("{key} = {} is above {max}; use 0-{max}", fmt_number(v)),
            );
            default
        }
        _ => v,
    }
}

/// The lap variation keys of `[robot]` (see [`crate::sim::variation`]); off unless given.
fn lap_variation(s: &Settings, d: &mut Diags) -> LapVariationConfig {
    use Rule::NonNegative;
    let v = s
        .word("lap_variation")
        .and_then(|w| named(d, w, &LapVariationConfig::PRESETS, "lap_variation preset"))
        .and_then(LapVariationConfig::preset)
        .unwrap_or_default();
    LapVariationConfig {
        lane_offset_ratio: bounded(d, s, "lane_offset_ratio", v.lane_offset_ratio, 1.0),
        lane_margin_m: value(d, s, "lane_margin_m", v.lane_margin_m, NonNegative),
        lap_speed_spread_ratio: bounded(
            d,
            s,
            "lap_speed_spread_ratio",
            v.lap_speed_spread_ratio,
            0.9,
        ),
        speed_wave_ratio: bounded(d, s, "speed_wave_ratio", v.speed_wave_ratio, 0.9),
        stop_spacing_m: value(d, s, "stop_spacing_m", v.stop_spacing_m, NonNegative),
        stop_duration_s: value(d, s, "stop_duration_s", v.stop_duration_s, NonNegative),
        spin_spacing_m: value(d, s, "spin_spacing_m", v.spin_spacing_m, NonNegative),
        spin_angle_rad: bounded(d, s, "spin_angle_deg", v.spin_angle_rad.to_degrees(), 720.0)
            .to_radians(),
        spin_angle_min_rad: deg(d, s, "spin_angle_min_deg", v.spin_angle_min_rad, 360.0),
        corner_spin_ratio: bounded(d, s, "corner_spin_ratio", v.corner_spin_ratio, 1.0),
        weave_heading_rad: deg(d, s, "weave_heading_deg", v.weave_heading_rad, 60.0),
        weave_wavelength_min_m: value(
            d,
            s,
            "weave_wavelength_min_m",
            v.weave_wavelength_min_m,
            NonNegative,
        ),
        weave_wavelength_max_m: value(
            d,
            s,
            "weave_wavelength_max_m",
            v.weave_wavelength_max_m,
            NonNegative,
        ),
        weave_envelope_ratio: bounded(d, s, "weave_envelope_ratio", v.weave_envelope_ratio, 1.0),
    }
}

/// An angle key in degrees within `[0, max_deg]`, returned in radians.
fn deg(d: &mut Diags, s: &Settings, key: &str, default_rad: f64, max_deg: f64) -> f64 {
    bounded(d, s, key, default_rad.to_degrees(), max_deg).to_radians()
}

fn robot(s: &Settings, d: &mut Diags) -> RobotConfig {
    use Rule::*;
    let mut r = RobotConfig::default();
    r.radius_m = value(d, s, "radius_m", r.radius_m, Positive);
    r.axle_track_m = value(d, s, "axle_track_m", r.axle_track_m, Positive);
    r.cruise_speed_m_s = value(d, s, "cruise_speed_m_s", r.cruise_speed_m_s, Positive);
    r.max_speed_m_s = value(d, s, "max_speed_m_s", r.max_speed_m_s, Positive);
    let turn_deg = r.max_turn_rate_rad_s.to_degrees();
    r.max_turn_rate_rad_s = value(d, s, "max_turn_rate_deg_s", turn_deg, Positive).to_radians();
    r.accel_m_s2 = value(d, s, "accel_m_s2", r.accel_m_s2, Positive);
    let turn_accel_deg = r.turn_accel_rad_s2.to_degrees();
    r.turn_accel_rad_s2 = value(d, s, "turn_accel_deg_s2", turn_accel_deg, Positive).to_radians();
    r.lookahead_m = value(d, s, "lookahead_m", r.lookahead_m, Positive);
    r.stop_distance_m = value(d, s, "stop_distance_m", r.stop_distance_m, NonNegative);
    r.slow_distance_m = value(d, s, "slow_distance_m", r.slow_distance_m, NonNegative);
    // Their ranges were checked while reading (the limits that keep a run finite).
    r.blocked_timeout_s = value(d, s, "blocked_timeout_s", r.blocked_timeout_s, Finite);
    r.step_s = value(d, s, "step_s", r.step_s, Finite);
    r.path_wander_m = value(d, s, "path_wander_m", r.path_wander_m, NonNegative);
    r.variation = lap_variation(s, d);
    robot_cross_checks(s, &r, d);
    r
}

fn robot_cross_checks(s: &Settings, r: &RobotConfig, d: &mut Diags) {
    if let Some(w) = s.get("path_wander_m").filter(|_| r.path_wander_m > 0.5) {
        d.at(
            w.span().start,
            "path_wander_m above 0.5 m takes the robot off 2 m corridors; use 0.1-0.3".into(),
        );
    }
    if let Some(c) = s
        .get("cruise_speed_m_s")
        .filter(|_| r.cruise_speed_m_s > r.max_speed_m_s)
    {
        d.at(
            c.span().start,
            format!(
                "cruise_speed_m_s exceeds max_speed_m_s ({}); lower it",
                r.max_speed_m_s
            ),
        );
    }
    let v = &r.variation;
    if let Some(w) = ["weave_wavelength_min_m", "weave_wavelength_max_m"]
        .iter()
        .find_map(|k| s.get(k))
        .filter(|_| v.weave_wavelength_min_m > v.weave_wavelength_max_m)
    {
        d.at(
            w.span().start,
            format!(
                "weave_wavelength_min_m ({}) exceeds weave_wavelength_max_m ({}); swap them",
                fmt_number(v.weave_wavelength_min_m),
                fmt_number(v.weave_wavelength_max_m)
            ),
        );
    }
}

/// The `[scan_context]` numbers over [`ScanContextConfig::default`]; each problem at its value.
fn scan_context(s: &Settings, d: &mut Diags) -> ScanContextConfig {
    let mut c = ScanContextConfig::default();
    let number = |key: &str, default: f64| s.get(key).map_or(default, |x| *x.get_ref());
    let mut whole = |key: &str, default: usize| -> usize {
        let Some(x) = s.get(key) else { return default };
        let v = *x.get_ref();
        if v.fract() != 0.0 || v < 0.0 || !v.is_finite() {
            d.at(
                x.span().start,
                format!(
                    "{key} = {} in [scan_context] is not a whole number; use one (default \
                     {default})",
                    fmt_number(v)
                ),
            );
            return default;
        }
        v as usize
    };
    c.rings = whole("rings", c.rings);
    c.sectors = whole("sectors", c.sectors);
    c.candidates = whole("candidates", c.candidates);
    c.observation_spacing_m = number("observation_spacing_m", c.observation_spacing_m);
    c.max_radius_m = number("max_radius_m", c.max_radius_m);
    c.history_m = number("history_m", c.history_m);
    c.cell_m = number("cell_m", c.cell_m);
    c.max_distance = number("max_distance", c.max_distance);
    c.min_overlap_ratio = number("min_overlap_ratio", c.min_overlap_ratio);
    for p in c.problems() {
        if let Some(x) = s.get(p.key) {
            d.at(
                x.span().start,
                format!(
                    "{} = {} in [scan_context] is out of range; {}",
                    p.key,
                    fmt_number(*x.get_ref()),
                    p.message
                ),
            );
        }
    }
    c
}

/// The simulation plan and recognizer settings: everything checked against the world.
fn plan(
    spec: &ScenarioSpec,
    world: World,
    models: Models,
    (path, world_path): (&Path, PathBuf),
    work: (&Workload, f64),
    d: &mut Diags,
) -> Option<(SimPlan, RecognizerConfig)> {
    let route = route(spec, &world, d);
    let door_configs = door_configs(spec, &world, d);
    let doors = Doors {
        world: &world,
        configs: &door_configs,
    };
    let runs: Vec<RunPlan> = spec
        .runs
        .iter()
        .filter_map(|r| run(r, route.as_ref(), &doors, d))
        .collect();
    let pedestrians = pedestrians(spec.pedestrians.as_ref(), &world, d);
    let name = spec.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".into())
    });
    let sim = SimPlan {
        name,
        path: path.to_path_buf(),
        world_path,
        route: route?,
        seed: *spec.seed.get_ref(),
        runs,
        door_configs,
        pedestrians,
        laser: models.laser,
        odometry: models.odometry,
        robot: models.robot,
        world,
    };
    work_budget(spec, &sim, &models.recognizer, work.0, d);
    if work.0.scan_context {
        scan_context_budget(spec, &sim, work, d);
    }
    Some((sim, models.recognizer))
}

/// Most simulation steps one scenario may take (about ten minutes at 100,000 steps a second).
pub const MAX_SIM_STEPS: f64 = 5e7;
/// Most observations one scenario may make (each holds a local-grid summary until evaluated).
pub const MAX_OBSERVATIONS: f64 = 1e7;
/// Most candidate pairs one command may weigh, over all its back-end passes (about twelve
/// minutes of CPU; see [`candidate_pairs`]): `check` of the smoke scenario driven 1000 laps a
/// run with every candidate (`max_candidates = 0`, two level configurations: 1.9e9) took 682
/// CPU s and 1.05 GB at most (BENCHMARKS.md, 2026-12-05), so the documented 1000-lap limit
/// runs there.
pub const MAX_CANDIDATE_PAIRS: f64 = 2e9;

/// Candidate pairs of one back-end pass over `laps` laps (all runs drive one route) of
/// `per_lap` observations each: every observation of lap i is weighed against its place in the
/// min(i, k) most recent earlier laps, every earlier one when k = 0 (`[recognizer.matcher]
/// max_candidates`). With k = 0 this grows with the laps squared, with k > 0 linearly: the
/// back end's memo, chains and matches, and the evaluation's pairs, grow the same way.
pub fn candidate_pairs(per_lap: f64, laps: usize, k: usize) -> f64 {
    let l = laps as f64;
    let earlier = if k == 0 || k >= laps {
        l * (l - 1.0) / 2.0
    } else {
        let k = k as f64;
        k * (k - 1.0) / 2.0 + (l - k) * k
    };
    per_lap * earlier
}

/// The work the validated numbers imply, estimated before any run, for `work` (laps replaced
/// by `--laps`, the command's back-end passes): simulation steps (travel at the slowest
/// cruise speed a lap may draw, plus its stops, over `step_s`), observations (travel over
/// `observation_spacing_m`) and candidate pairs ([`candidate_pairs`]). Beyond
/// [`MAX_SIM_STEPS`], [`MAX_OBSERVATIONS`] or [`MAX_CANDIDATE_PAIRS`] the file is refused at
/// the key that sets the work, with a value that fits.
fn work_budget(
    spec: &ScenarioSpec,
    sim: &SimPlan,
    rec: &RecognizerConfig,
    work: &Workload,
    d: &mut Diags,
) {
    if d.has_errors() {
        // An estimate from numbers already refused would only repeat them.
        return;
    }
    let laps: usize = sim
        .runs
        .iter()
        .map(|run| work.laps.unwrap_or(run.laps))
        .sum();
    let laps_at = spec.runs.first().map_or(0, |run| run.laps.span().start);
    let what = Drive {
        laps,
        lap_m: sim.route.length_m(),
        flag: work.laps,
    };
    step_budget(spec, sim, &what, laps_at, d);
    let observations = what.travel_m() / rec.front_end.observation_spacing_m;
    if observations > MAX_OBSERVATIONS {
        let key = spec
            .recognizer
            .iter()
            .find(|e| e.is("front_end", "observation_spacing_m"));
        let at = key.map_or(laps_at, |e| e.key.span().start);
        let fits = what.travel_m() / MAX_OBSERVATIONS;
        d.at(
            at,
            format!(
                "{what} at observation_spacing_m = {} make about {observations:.1e} \
                 observations, more than {} held in memory; use observation_spacing_m = {} or \
                 more, or fewer laps",
                fmt_number(rec.front_end.observation_spacing_m),
                fmt_number(MAX_OBSERVATIONS),
                fmt_number((fits * 1000.0).ceil() / 1000.0)
            ),
        );
    }
    if !d.has_errors() {
        // Counted from the observations: only once they fit is the count worth a message.
        let per_lap = observations / laps.max(1) as f64;
        candidate_budget(spec, &what, per_lap, rec, work, laps_at, d);
    }
}

/// Most observations the Scan Context baseline may make in one command: each keeps its
/// descriptor (about 4 kB with its ring key and matches; 395 MB over 96,000 observations of
/// `table`) for the rest of the run, and its candidate search grows faster than the laps.
pub const MAX_SCAN_CONTEXT_OBSERVATIONS: f64 = 2.5e5;

/// The Scan Context part of the budget, for a command that runs it: its observations (travel
/// over `[scan_context] observation_spacing_m`, the spacing given with `work`) at most
/// [`MAX_SCAN_CONTEXT_OBSERVATIONS`], refused at that key (or the first run's laps).
fn scan_context_budget(
    spec: &ScenarioSpec,
    sim: &SimPlan,
    (work, spacing_m): (&Workload, f64),
    d: &mut Diags,
) {
    if d.has_errors() || spacing_m.is_nan() || spacing_m <= 0.0 {
        return;
    }
    let what = Drive {
        laps: sim
            .runs
            .iter()
            .map(|run| work.laps.unwrap_or(run.laps))
            .sum(),
        lap_m: sim.route.length_m(),
        flag: work.laps,
    };
    let observations = what.travel_m() / spacing_m;
    if observations <= MAX_SCAN_CONTEXT_OBSERVATIONS {
        return;
    }
    let laps_at = spec.runs.first().map_or(0, |run| run.laps.span().start);
    let at = (spec.scan_context.get("observation_spacing_m")).map_or(laps_at, |s| s.span().start);
    let fits = what.travel_m() / MAX_SCAN_CONTEXT_OBSERVATIONS;
    d.at(
        at,
        format!(
            "{what} at [scan_context] observation_spacing_m = {} make about {observations:.1e} \
             Scan Context observations, more than {} (each holds its descriptor); use \
             observation_spacing_m = {} or more in [scan_context], leave the baseline out \
             (--no-scan-context), or drive fewer laps",
            fmt_number(spacing_m),
            fmt_number(MAX_SCAN_CONTEXT_OBSERVATIONS),
            fmt_number((fits * 1000.0).ceil() / 1000.0)
        ),
    );
}

/// The laps a command drives, for the budget's messages.
struct Drive {
    laps: usize,
    lap_m: f64,
    /// `--laps`, when it replaced the file's.
    flag: Option<usize>,
}

impl Drive {
    fn travel_m(&self) -> f64 {
        self.laps as f64 * self.lap_m
    }
}

impl std::fmt::Display for Drive {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = if self.laps == 1 { "" } else { "s" };
        write!(f, "{} lap{s} of {:.0} m", self.laps, self.lap_m)?;
        match self.flag {
            Some(n) => write!(f, " (--laps {n} per run)"),
            None => Ok(()),
        }
    }
}

/// The simulation steps of [`work_budget`].
fn step_budget(spec: &ScenarioSpec, sim: &SimPlan, what: &Drive, laps_at: usize, d: &mut Diags) {
    let r = &sim.robot;
    let v = &r.variation;
    let travel_m = what.travel_m();
    // The slowest lap's cruise speed; the speed wave averages out along a lap.
    let slowest_m_s = r.cruise_speed_m_s * (1.0 - v.lap_speed_spread_ratio);
    let stops_s = if v.stop_spacing_m > 0.0 {
        travel_m / v.stop_spacing_m * v.stop_duration_s
    } else {
        0.0
    };
    let seconds = travel_m / slowest_m_s.max(1e-9) + stops_s;
    let steps = seconds / r.step_s;
    if steps > MAX_SIM_STEPS {
        let at = spec.robot.get("step_s").map_or(laps_at, |s| s.span().start);
        let fits = seconds / MAX_SIM_STEPS;
        d.at(
            at,
            format!(
                "{what} at step_s = {} take about {steps:.1e} simulation steps, more than {} \
                 (about ten minutes); use step_s = {} or more, or fewer laps",
                fmt_number(r.step_s),
                fmt_number(MAX_SIM_STEPS),
                fmt_number((fits * 1000.0).ceil() / 1000.0)
            ),
        );
    }
}

/// The candidate pairs of [`work_budget`]: refused at `max_candidates` (or the first run's
/// laps when the file does not set it) with the largest value that fits, or the laps that fit
/// when even one candidate per word is too many.
fn candidate_budget(
    spec: &ScenarioSpec,
    what: &Drive,
    per_lap: f64,
    rec: &RecognizerConfig,
    work: &Workload,
    laps_at: usize,
    d: &mut Diags,
) {
    let k = rec.matcher.max_candidates;
    let passes = work.passes.max(1) as f64;
    let total = |laps: usize, k: usize| passes * candidate_pairs(per_lap, laps, k);
    let pairs = total(what.laps, k);
    if pairs <= MAX_CANDIDATE_PAIRS {
        return;
    }
    // The largest value in 1..=hi that fits, by bisection (the pairs grow with both).
    let largest = |hi: usize, fits: &dyn Fn(usize) -> bool| {
        let (mut lo, mut hi) = (0, hi);
        while lo < hi {
            let mid = lo + (hi - lo).div_ceil(2);
            if fits(mid) { lo = mid } else { hi = mid - 1 }
        }
        lo
    };
    let k_fits = largest(what.laps, &|k| total(what.laps, k) <= MAX_CANDIDATE_PAIRS);
    let laps_fit = largest(what.laps, &|l| total(l, k) <= MAX_CANDIDATE_PAIRS);
    let key = spec
        .recognizer
        .iter()
        .find(|e| e.is("matcher", "max_candidates"));
    let at = key.map_or(laps_at, |e| e.key.span().start);
    let against = match k {
        0 => "every earlier lap".to_string(),
        k => format!("its {k} most recent look-alikes"),
    };
    let runs = spec.runs.len().max(1);
    let fewer = match what.flag {
        Some(_) => format!(
            "at most {laps_fit} laps in all (--laps {})",
            laps_fit / runs
        ),
        None => format!("at most {laps_fit} laps in all"),
    };
    let fix = match k_fits {
        0 => format!("drive {fewer}"),
        k_fits => format!(
            "set [recognizer.matcher] max_candidates = {k_fits} or less (it is {k}), or drive \
             {fewer}"
        ),
    };
    d.at(
        at,
        format!(
            "{what}, each observation weighed against {against}, over {} back-end pass{}, make \
             about {pairs:.1e} candidate pairs, more than {} (about twelve minutes of work); {fix}",
            work.passes.max(1),
            if work.passes > 1 { "es" } else { "" },
            fmt_number(MAX_CANDIDATE_PAIRS),
        ),
    );
}

fn route(spec: &ScenarioSpec, world: &World, d: &mut Diags) -> Option<Route> {
    let id = spec.route.get_ref();
    let found = world.route(id).cloned();
    if found.is_none() {
        let h = hint(id, world.routes.iter().map(|r| r.id.as_str()), "routes");
        d.at(
            spec.route.span().start,
            format!("unknown route `{}`; {h}", echo(id)),
        );
    }
    found
}

/// Door configuration names a file may not define.
const RESERVED: [&str; 3] = ["all-closed", "all-open", "random"];

fn door_configs(spec: &ScenarioSpec, world: &World, d: &mut Diags) -> BTreeMap<String, DoorStates> {
    let mut out = BTreeMap::new();
    for (name, ids) in &spec.door_configs {
        if RESERVED.contains(&name.get_ref().as_str()) {
            d.at(
                name.span().start,
                format!(
                    "door configuration name `{}` is reserved; rename it",
                    name.get_ref()
                ),
            );
        }
        let mut st = DoorStates::all_closed(world);
        for id in ids {
            match world.door_index(id.get_ref()) {
                Some(i) => st.open[i] = true,
                None => {
                    let h = hint(
                        id.get_ref(),
                        world.doors.iter().map(|x| x.id.as_str()),
                        "doors",
                    );
                    d.at(
                        id.span().start,
                        format!("unknown door `{}`; {h}", echo(id.get_ref())),
                    );
                }
            }
        }
        out.insert(name.get_ref().clone(), st);
    }
    out
}

/// What a run's door names are looked up in.
struct Doors<'a> {
    world: &'a World,
    configs: &'a BTreeMap<String, DoorStates>,
}

impl Doors<'_> {
    fn choice(&self, name: &S<String>, d: &mut Diags) -> Option<DoorChoice> {
        let n = name.get_ref().as_str();
        let states = match n {
            "all-closed" => Some(DoorStates::all_closed(self.world)),
            "all-open" => Some(DoorStates::all_open(self.world)),
            _ => self.configs.get(n).cloned(),
        };
        if let Some(states) = states {
            return Some(DoorChoice {
                name: n.to_string(),
                states,
            });
        }
        let what = if self.world.door_index(n).is_some() {
            format!(
                "`{n}` is a door, not a door configuration; name a set of open doors in \
                 [door_configs], e.g. only-{n} = [\"{n}\"], and use its name"
            )
        } else {
            let names = RESERVED[..2]
                .iter()
                .copied()
                .chain(self.configs.keys().map(String::as_str));
            format!(
                "unknown door configuration `{}`; {}",
                echo(n),
                hint(n, names, "configurations")
            )
        };
        d.at(name.span().start, what);
        None
    }
}

fn run(r: &RunSpec, route: Option<&Route>, doors: &Doors, d: &mut Diags) -> Option<RunPlan> {
    let start = r.start_waypoint.as_ref().map(|s| *s.get_ref()).unwrap_or(0);
    if let (Some(s), Some(route)) = (&r.start_waypoint, route) {
        let n = route.waypoints.len();
        if start < 0 || start as usize >= n {
            d.at(s.span().start, format!(
                "start_waypoint {start} is not a waypoint of route `{}`; use 0 (the first) to {} \
                 (the last); waypoints are counted from 0 everywhere",
                route.id, n.saturating_sub(1)));
        }
    }
    let plan = match &r.doors {
        None => DoorPlan::Fixed(DoorChoice {
            name: "all-closed".into(),
            states: DoorStates::all_closed(doors.world),
        }),
        Some(DoorsSpec::Fixed(name)) => DoorPlan::Fixed(doors.choice(name, d)?),
        Some(DoorsSpec::Cycle(list)) => {
            if list.get_ref().is_empty() {
                d.at(
                    list.span().start,
                    "doors_cycle is empty; list at least one configuration".into(),
                );
            }
            DoorPlan::Cycle(
                list.get_ref()
                    .iter()
                    .filter_map(|n| doors.choice(n, d))
                    .collect(),
            )
        }
        Some(DoorsSpec::Random(p)) => DoorPlan::Random {
            open_probability: *p.get_ref(),
        },
    };
    Some(RunPlan {
        start_waypoint: start.max(0) as usize,
        reverse: r.reverse,
        laps: *r.laps.get_ref(),
        doors: plan,
    })
}

fn pedestrians(p: Option<&PedestriansSpec>, world: &World, d: &mut Diags) -> PedestrianConfig {
    let mut cfg = PedestrianConfig::default();
    let Some(p) = p else {
        return cfg;
    };
    cfg.count = *p.count.get_ref();
    for a in &p.areas {
        match world.areas.iter().find(|w| w.id == *a.get_ref()) {
            Some(area) => cfg.sources.push(WalkSource::Area(area.clone())),
            None => {
                let h = hint(
                    a.get_ref(),
                    world.areas.iter().map(|x| x.id.as_str()),
                    "areas",
                );
                d.at(
                    a.span().start,
                    format!("unknown area `{}`; {h}", echo(a.get_ref())),
                );
            }
        }
    }
    for path in &p.paths_m {
        let pts = path
            .get_ref()
            .iter()
            .map(|q| Vec2::new(q[0], q[1]))
            .collect();
        cfg.sources.push(WalkSource::Path(pts));
    }
    if cfg.count > 0 && p.areas.is_empty() && p.paths_m.is_empty() {
        d.at(
            p.count.span().start,
            "pedestrians need somewhere to walk; add areas = [..] or paths_m = [..]".into(),
        );
    }
    walker_settings(&p.settings, &mut cfg, d);
    cfg
}

/// Speeds and size of the people, over [`PedestrianConfig::default`].
fn walker_settings(s: &Settings, cfg: &mut PedestrianConfig, d: &mut Diags) {
    cfg.speed_min_m_s = value(d, s, "speed_min_m_s", cfg.speed_min_m_s, Rule::Positive);
    cfg.speed_max_m_s = value(d, s, "speed_max_m_s", cfg.speed_max_m_s, Rule::Positive);
    cfg.radius_m = value(d, s, "radius_m", cfg.radius_m, Rule::Positive);
    if let Some(x) = s
        .get("speed_max_m_s")
        .filter(|_| cfg.speed_max_m_s < cfg.speed_min_m_s)
    {
        d.at(
            x.span().start,
            "speed_max_m_s is below speed_min_m_s; swap them".into(),
        );
    }
}

/// Keys of the other odometry model are a mistake, not silently ignored.
fn other_model_keys(s: &Settings, thrun: bool, d: &mut Diags) {
    let (other, fix) = if thrun {
        (
            &RATIO_NAMES[..],
            "proportional\"; remove it or change the model",
        )
    } else {
        (
            &ALPHA_NAMES[..],
            "thrun\"; remove it or set model = \"thrun\"",
        )
    };
    for key in other {
        if let Some(x) = s.get(key) {
            d.at(x.span().start, format!("{key} applies to model = \"{fix}"));
        }
    }
}
