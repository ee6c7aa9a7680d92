//! The scenario file format (TOML, `format_version = 1`) and its validation.
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
//! [evaluation]                          # crate::spec::evaluation::EvaluationSpec
//! [expect]                              # crate::spec::evaluation::ExpectSpec
//! ```
//!
//! At most one of `doors`, `doors_cycle`, `doors_random` per run; none means all closed.
//! Every problem is reported as `file:line:col: what is wrong; what to try`.

use crate::geom::Vec2;
use crate::recognizer::RecognizerConfig;
use crate::sim::laser::{LaserConfig, LaserPreset};
use crate::sim::odometry::{OdometryConfig, OdometryModel};
use crate::sim::pedestrians::{PedestrianConfig, WalkSource};
use crate::sim::robot::RobotConfig;
use crate::spec::SpecError;
use crate::spec::diag::{Diagnostic, line_col};
use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use crate::spec::seeds::SeedRange;
use crate::world::{DoorStates, Route, World};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

type S<T> = Spanned<T>;

/// A whole scenario file, as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    pub format_version: S<i64>,
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    /// World file, relative to the scenario file.
    pub world: S<String>,
    /// Route id in the world.
    pub route: S<String>,
    pub seed: S<i64>,
    /// Seeds `check` runs by default, e.g. "1..20" (both ends included).
    #[serde(default)]
    pub seeds: Option<S<String>>,
    pub runs: S<Vec<RunSpec>>,
    #[serde(default)]
    pub door_configs: BTreeMap<String, S<Vec<S<String>>>>,
    #[serde(default)]
    pub pedestrians: Option<PedestriansSpec>,
    #[serde(default)]
    pub laser: LaserSpec,
    #[serde(default)]
    pub odometry: OdometrySpec,
    #[serde(default)]
    pub robot: RobotSpec,
    #[serde(default)]
    pub recognizer: toml::Table,
    #[serde(default)]
    pub evaluation: EvaluationSpec,
    #[serde(default)]
    pub expect: ExpectSpec,
}

/// One `[[runs]]` entry.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    #[serde(default)]
    pub start_waypoint: Option<S<i64>>,
    pub laps: S<i64>,
    #[serde(default)]
    pub doors: Option<S<String>>,
    #[serde(default)]
    pub doors_cycle: Option<S<Vec<S<String>>>>,
    #[serde(default)]
    pub doors_random: Option<S<DoorsRandomSpec>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DoorsRandomSpec {
    pub open_probability: S<f64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PedestriansSpec {
    pub count: S<i64>,
    #[serde(default)]
    pub areas: Vec<S<String>>,
    #[serde(default)]
    pub paths_m: Vec<S<Vec<[f64; 2]>>>,
    #[serde(default)]
    pub speed_min_m_s: Option<S<f64>>,
    #[serde(default)]
    pub speed_max_m_s: Option<S<f64>>,
    #[serde(default)]
    pub radius_m: Option<S<f64>>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserSpec {
    #[serde(default)]
    pub preset: Option<S<String>>,
    #[serde(default)]
    pub max_range_m: Option<S<f64>>,
    #[serde(default)]
    pub range_noise_m: Option<S<f64>>,
    #[serde(default)]
    pub angle_error_deg: Option<S<f64>>,
    #[serde(default)]
    pub rate_hz: Option<S<f64>>,
    #[serde(default)]
    pub mount_x_m: Option<S<f64>>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometrySpec {
    #[serde(default)]
    pub model: Option<S<String>>,
    #[serde(default)]
    pub translation_error_ratio: Option<S<f64>>,
    #[serde(default)]
    pub rotation_error_ratio: Option<S<f64>>,
    #[serde(default)]
    pub alpha1: Option<S<f64>>,
    #[serde(default)]
    pub alpha2: Option<S<f64>>,
    #[serde(default)]
    pub alpha3: Option<S<f64>>,
    #[serde(default)]
    pub alpha4: Option<S<f64>>,
    #[serde(default)]
    pub wheel_radius_bias_ratio: Option<S<f64>>,
    #[serde(default)]
    pub wheel_radius_mismatch_ratio: Option<S<f64>>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    #[serde(default)]
    pub cruise_speed_m_s: Option<S<f64>>,
    #[serde(default)]
    pub max_speed_m_s: Option<S<f64>>,
    #[serde(default)]
    pub max_turn_rate_deg_s: Option<S<f64>>,
    #[serde(default)]
    pub accel_m_s2: Option<S<f64>>,
    #[serde(default)]
    pub turn_accel_deg_s2: Option<S<f64>>,
    #[serde(default)]
    pub radius_m: Option<S<f64>>,
    #[serde(default)]
    pub axle_track_m: Option<S<f64>>,
    #[serde(default)]
    pub lookahead_m: Option<S<f64>>,
    #[serde(default)]
    pub path_wander_m: Option<S<f64>>,
    #[serde(default)]
    pub stop_distance_m: Option<S<f64>>,
    #[serde(default)]
    pub slow_distance_m: Option<S<f64>>,
    #[serde(default)]
    pub blocked_timeout_s: Option<S<f64>>,
    #[serde(default)]
    pub step_s: Option<S<f64>>,
}

/// A named set of door states.
#[derive(Clone, Debug, PartialEq)]
pub struct DoorChoice {
    /// "all-closed", "all-open" or a `[door_configs]` name.
    pub name: String,
    pub states: DoorStates,
}

/// How a run's doors are set each lap.
#[derive(Clone, Debug, PartialEq)]
pub enum DoorPlan {
    Fixed(DoorChoice),
    /// Lap `k` uses entry `k mod len`.
    Cycle(Vec<DoorChoice>),
    /// Each door open with this probability, drawn per lap.
    Random {
        open_probability: f64,
    },
}

/// One validated run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunPlan {
    pub start_waypoint: usize,
    pub laps: usize,
    pub doors: DoorPlan,
}

/// A validated scenario with its world loaded.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub name: String,
    pub description: Option<String>,
    /// The scenario file (as given).
    pub path: PathBuf,
    /// The world file, resolved against the scenario's folder.
    pub world_path: PathBuf,
    pub world: World,
    pub route: Route,
    pub seed: u64,
    /// The seeds `check` runs by default (`seeds = "1..20"`); `None`: only `seed`.
    pub seeds: Option<SeedRange>,
    pub runs: Vec<RunPlan>,
    pub door_configs: BTreeMap<String, DoorStates>,
    pub pedestrians: PedestrianConfig,
    pub laser: LaserConfig,
    pub odometry: OdometryConfig,
    pub robot: RobotConfig,
    /// Recognizer settings: the `[recognizer]` table over the defaults.
    pub recognizer: RecognizerConfig,
    pub evaluation: EvaluationSpec,
    pub expect: ExpectSpec,
}

/// Reads and validates a scenario file and the world it names.
pub fn load_scenario(path: &Path) -> Result<Scenario, SpecError> {
    let src = std::fs::read_to_string(path).map_err(|e| SpecError::io(path, e))?;
    parse_scenario(&src, path, &|p: &Path| crate::spec::world::load_world(p))
}

/// Parses and validates a scenario's text. `path` names the file in messages and anchors the
/// world path; `load_world` loads the world (tests pass a closure that parses a string).
pub fn parse_scenario(
    src: &str,
    path: &Path,
    load_world: &dyn Fn(&Path) -> Result<World, SpecError>,
) -> Result<Scenario, SpecError> {
    let file = path.display().to_string();
    let spec: ScenarioSpec = match toml::from_str(src) {
        Ok(s) => s,
        Err(e) => {
            let (line, col) = e.span().map(|s| line_col(src, s.start)).unwrap_or((1, 1));
            return Err(SpecError::Invalid(vec![Diagnostic {
                path: file,
                line,
                col,
                message: serde_message(e.message()),
            }]));
        }
    };
    let mut v = Validator {
        src,
        file: &file,
        diags: Vec::new(),
    };
    if *spec.format_version.get_ref() != 1 {
        v.err(
            spec.format_version.span(),
            format!(
                "format_version {} is not supported; use format_version = 1",
                spec.format_version.get_ref()
            ),
        );
    }
    let world_rel = PathBuf::from(spec.world.get_ref());
    let world_path = match path.parent() {
        Some(dir) if !world_rel.is_absolute() => dir.join(&world_rel),
        _ => world_rel.clone(),
    };
    let world = match load_world(&world_path) {
        Ok(w) => w,
        Err(SpecError::Io { source, .. }) => {
            v.err(
                spec.world.span(),
                format!(
                    "cannot read world file `{}`: {source}; the path is relative to the scenario file",
                    world_path.display()
                ),
            );
            return Err(SpecError::Invalid(v.diags));
        }
        Err(SpecError::Invalid(mut d)) => {
            v.err(
                spec.world.span(),
                format!(
                    "world `{}` is invalid; fix the problems listed below",
                    world_path.display()
                ),
            );
            v.diags.append(&mut d);
            return Err(SpecError::Invalid(v.diags));
        }
    };
    let route = match world.route(spec.route.get_ref()) {
        Some(r) => Some(r.clone()),
        None => {
            let ids: Vec<&str> = world.routes.iter().map(|r| r.id.as_str()).collect();
            v.err(
                spec.route.span(),
                format!(
                    "unknown route `{}`{}",
                    spec.route.get_ref(),
                    hint(spec.route.get_ref(), &ids, "routes")
                ),
            );
            None
        }
    };
    let seed = *spec.seed.get_ref();
    if seed < 0 {
        v.err(
            spec.seed.span(),
            "seed must be 0 or more; pick any non-negative integer".into(),
        );
    }
    let seeds = spec
        .seeds
        .as_ref()
        .and_then(|s| match s.get_ref().parse::<SeedRange>() {
            Ok(r) => Some(r),
            Err(e) => {
                v.err(s.span(), e);
                None
            }
        });

    // Door configurations.
    let door_ids: Vec<&str> = world.doors.iter().map(|d| d.id.as_str()).collect();
    let mut door_configs = BTreeMap::new();
    for (name, ids) in &spec.door_configs {
        if RESERVED.contains(&name.as_str()) {
            v.err(
                ids.span(),
                format!("door configuration name `{name}` is reserved; rename it"),
            );
        }
        let mut st = DoorStates::all_closed(&world);
        for id in ids.get_ref() {
            match world.door_index(id.get_ref()) {
                Some(i) => st.open[i] = true,
                None => v.err(
                    id.span(),
                    format!(
                        "unknown door `{}`{}",
                        id.get_ref(),
                        hint(id.get_ref(), &door_ids, "doors")
                    ),
                ),
            }
        }
        door_configs.insert(name.clone(), st);
    }
    let config_names: Vec<&str> = RESERVED
        .iter()
        .copied()
        .filter(|n| *n != "random")
        .chain(spec.door_configs.keys().map(String::as_str))
        .collect();
    let choice = |v: &mut Validator, name: &S<String>| -> Option<DoorChoice> {
        let n = name.get_ref().as_str();
        let states = match n {
            "all-closed" => Some(DoorStates::all_closed(&world)),
            "all-open" => Some(DoorStates::all_open(&world)),
            _ => door_configs.get(n).cloned(),
        };
        match states {
            Some(states) => Some(DoorChoice {
                name: n.to_string(),
                states,
            }),
            None => {
                let what = if world.door_index(n).is_some() {
                    format!(
                        "`{n}` is a door, not a door configuration; name a set of open doors in \
                         [door_configs], e.g. only-{n} = [\"{n}\"], and use its name"
                    )
                } else {
                    format!(
                        "unknown door configuration `{n}`{}",
                        hint(n, &config_names, "configurations")
                    )
                };
                v.err(name.span(), what);
                None
            }
        }
    };

    // Runs.
    let mut runs = Vec::new();
    if spec.runs.get_ref().is_empty() {
        v.err(
            spec.runs.span(),
            "no runs; add a [[runs]] entry with laps = 1 or more".into(),
        );
    }
    for r in spec.runs.get_ref() {
        let laps = *r.laps.get_ref();
        if laps < 1 {
            v.err(
                r.laps.span(),
                format!("laps = {laps}; a run needs 1 lap or more"),
            );
        }
        let start = r.start_waypoint.as_ref().map(|s| *s.get_ref()).unwrap_or(0);
        if let (Some(s), Some(route)) = (&r.start_waypoint, &route)
            && (start < 0 || start as usize >= route.waypoints.len())
        {
            v.err(
                s.span(),
                format!(
                    "start_waypoint {start} is not a waypoint of route `{}`; use 0 to {}",
                    route.id,
                    route.waypoints.len().saturating_sub(1)
                ),
            );
        }
        let given = [
            r.doors.is_some(),
            r.doors_cycle.is_some(),
            r.doors_random.is_some(),
        ]
        .iter()
        .filter(|b| **b)
        .count();
        if given > 1 {
            v.err(
                r.laps.span(),
                "this run sets more than one of doors, doors_cycle and doors_random; keep one"
                    .into(),
            );
        }
        let doors = if let Some(d) = &r.doors {
            choice(&mut v, d).map(DoorPlan::Fixed)
        } else if let Some(c) = &r.doors_cycle {
            if c.get_ref().is_empty() {
                v.err(
                    c.span(),
                    "doors_cycle is empty; list at least one configuration".into(),
                );
            }
            let list: Vec<_> = c
                .get_ref()
                .iter()
                .filter_map(|n| choice(&mut v, n))
                .collect();
            Some(DoorPlan::Cycle(list))
        } else if let Some(rd) = &r.doors_random {
            let p = &rd.get_ref().open_probability;
            if !(0.0..=1.0).contains(p.get_ref()) {
                v.err(
                    p.span(),
                    format!("open_probability {} is outside 0..1", p.get_ref()),
                );
            }
            Some(DoorPlan::Random {
                open_probability: *p.get_ref(),
            })
        } else {
            Some(DoorPlan::Fixed(DoorChoice {
                name: "all-closed".into(),
                states: DoorStates::all_closed(&world),
            }))
        };
        if let Some(doors) = doors {
            runs.push(RunPlan {
                start_waypoint: start.max(0) as usize,
                laps: laps.max(0) as usize,
                doors,
            });
        }
    }

    // Pedestrians.
    let mut pedestrians = PedestrianConfig::default();
    if let Some(p) = &spec.pedestrians {
        let count = *p.count.get_ref();
        if count < 0 {
            v.err(p.count.span(), "count must be 0 or more".into());
        }
        pedestrians.count = count.max(0) as usize;
        let area_ids: Vec<&str> = world.areas.iter().map(|a| a.id.as_str()).collect();
        for a in &p.areas {
            match world.areas.iter().find(|w| w.id == *a.get_ref()) {
                Some(area) => pedestrians.sources.push(WalkSource::Area(area.clone())),
                None => v.err(
                    a.span(),
                    format!(
                        "unknown area `{}`{}",
                        a.get_ref(),
                        hint(a.get_ref(), &area_ids, "areas")
                    ),
                ),
            }
        }
        for path in &p.paths_m {
            let pts: Vec<Vec2> = path
                .get_ref()
                .iter()
                .map(|q| Vec2::new(q[0], q[1]))
                .collect();
            if pts.len() < 2 || pts.iter().any(|q| !q.x.is_finite() || !q.y.is_finite()) {
                v.err(
                    path.span(),
                    "a path needs at least two finite points [x, y]".into(),
                );
            } else {
                pedestrians.sources.push(WalkSource::Path(pts));
            }
        }
        if count > 0 && p.areas.is_empty() && p.paths_m.is_empty() {
            v.err(
                p.count.span(),
                "pedestrians need somewhere to walk; add areas = [..] or paths_m = [..]".into(),
            );
        }
        pedestrians.speed_min_m_s = v.positive("speed_min_m_s", &p.speed_min_m_s, 0.5);
        pedestrians.speed_max_m_s = v.positive("speed_max_m_s", &p.speed_max_m_s, 1.2);
        pedestrians.radius_m = v.positive("radius_m", &p.radius_m, 0.2);
        if pedestrians.speed_max_m_s < pedestrians.speed_min_m_s
            && let Some(s) = &p.speed_max_m_s
        {
            v.err(
                s.span(),
                "speed_max_m_s is below speed_min_m_s; swap them".into(),
            );
        }
    }

    // Laser.
    let l = &spec.laser;
    let preset = match &l.preset {
        None => LaserPreset::Lms200,
        Some(p) => LaserPreset::from_name(p.get_ref()).unwrap_or_else(|| {
            v.err(
                p.span(),
                format!(
                    "unknown laser preset `{}`{}",
                    p.get_ref(),
                    hint(p.get_ref(), &LaserPreset::NAMES, "presets")
                ),
            );
            LaserPreset::Lms200
        }),
    };
    let mut laser = LaserConfig::preset(preset);
    laser.max_range_m = v.positive("max_range_m", &l.max_range_m, laser.max_range_m);
    laser.range_noise_m = v.non_negative("range_noise_m", &l.range_noise_m, laser.range_noise_m);
    laser.angle_error_rad = v
        .non_negative(
            "angle_error_deg",
            &l.angle_error_deg,
            laser.angle_error_rad.to_degrees(),
        )
        .to_radians();
    laser.rate_hz = v.positive("rate_hz", &l.rate_hz, laser.rate_hz);
    laser.mount_x_m = v.finite("mount_x_m", &l.mount_x_m, laser.mount_x_m);

    // Odometry.
    let o = &spec.odometry;
    let model_name = o
        .model
        .as_ref()
        .map(|m| m.get_ref().as_str())
        .unwrap_or("proportional");
    let alphas = [&o.alpha1, &o.alpha2, &o.alpha3, &o.alpha4];
    let model = match model_name {
        "thrun" => {
            for (k, t) in [
                ("translation_error_ratio", &o.translation_error_ratio),
                ("rotation_error_ratio", &o.rotation_error_ratio),
            ] {
                if let Some(t) = t {
                    v.err(
                        t.span(),
                        format!(
                            "{k} applies to model = \"proportional\"; remove it or change the model"
                        ),
                    );
                }
            }
            let d = [0.01, 0.01, 0.01, 0.01];
            let mut a = [0.0; 4];
            for i in 0..4 {
                a[i] = v.non_negative(ALPHA_NAMES[i], alphas[i], d[i]);
            }
            OdometryModel::Thrun { alpha: a }
        }
        other => {
            if other != "proportional"
                && let Some(m) = &o.model
            {
                v.err(
                    m.span(),
                    format!(
                        "unknown odometry model `{other}`{}",
                        hint(other, &["proportional", "thrun"], "models")
                    ),
                );
            }
            for (i, a) in alphas.iter().enumerate() {
                if let Some(a) = a {
                    v.err(a.span(), format!("alpha{} applies to model = \"thrun\"; remove it or set model = \"thrun\"", i + 1));
                }
            }
            OdometryModel::Proportional {
                translation_ratio: v.non_negative(
                    "translation_error_ratio",
                    &o.translation_error_ratio,
                    0.0075,
                ),
                rotation_ratio: v.non_negative(
                    "rotation_error_ratio",
                    &o.rotation_error_ratio,
                    0.0075,
                ),
            }
        }
    };
    let odometry = OdometryConfig {
        model,
        wheel_radius_bias_ratio: v.finite(
            "wheel_radius_bias_ratio",
            &o.wheel_radius_bias_ratio,
            0.0,
        ),
        wheel_radius_mismatch_ratio: v.finite(
            "wheel_radius_mismatch_ratio",
            &o.wheel_radius_mismatch_ratio,
            0.0,
        ),
    };

    // Robot.
    let r = &spec.robot;
    let d = RobotConfig::default();
    let robot = RobotConfig {
        radius_m: v.positive("radius_m", &r.radius_m, d.radius_m),
        axle_track_m: v.positive("axle_track_m", &r.axle_track_m, d.axle_track_m),
        cruise_speed_m_s: v.positive("cruise_speed_m_s", &r.cruise_speed_m_s, d.cruise_speed_m_s),
        max_speed_m_s: v.positive("max_speed_m_s", &r.max_speed_m_s, d.max_speed_m_s),
        max_turn_rate_rad_s: v
            .positive(
                "max_turn_rate_deg_s",
                &r.max_turn_rate_deg_s,
                d.max_turn_rate_rad_s.to_degrees(),
            )
            .to_radians(),
        accel_m_s2: v.positive("accel_m_s2", &r.accel_m_s2, d.accel_m_s2),
        turn_accel_rad_s2: v
            .positive(
                "turn_accel_deg_s2",
                &r.turn_accel_deg_s2,
                d.turn_accel_rad_s2.to_degrees(),
            )
            .to_radians(),
        lookahead_m: v.positive("lookahead_m", &r.lookahead_m, d.lookahead_m),
        stop_distance_m: v.non_negative("stop_distance_m", &r.stop_distance_m, d.stop_distance_m),
        slow_distance_m: v.non_negative("slow_distance_m", &r.slow_distance_m, d.slow_distance_m),
        blocked_timeout_s: v.positive(
            "blocked_timeout_s",
            &r.blocked_timeout_s,
            d.blocked_timeout_s,
        ),
        step_s: v.positive("step_s", &r.step_s, d.step_s),
        path_wander_m: v.non_negative("path_wander_m", &r.path_wander_m, d.path_wander_m),
    };
    if robot.path_wander_m > 0.5
        && let Some(w) = &r.path_wander_m
    {
        v.err(
            w.span(),
            "path_wander_m above 0.5 m takes the robot off 2 m corridors; use 0.1-0.3".into(),
        );
    }
    if robot.cruise_speed_m_s > robot.max_speed_m_s
        && let Some(c) = &r.cruise_speed_m_s
    {
        v.err(
            c.span(),
            format!(
                "cruise_speed_m_s exceeds max_speed_m_s ({}); lower it",
                robot.max_speed_m_s
            ),
        );
    }
    if let Some(s) = &r.step_s
        && *s.get_ref() > 0.5
    {
        v.err(
            s.span(),
            "step_s above 0.5 s is too coarse; use 0.05".into(),
        );
    }

    // Evaluation sanity.
    let ev = &spec.evaluation;
    if !(ev.tp_radius_m > 0.0 && ev.min_gap_m >= 0.0 && ev.heading_tolerance_deg > 0.0) {
        v.err(
            find_key(src, "[evaluation]"),
            "tp_radius_m and heading_tolerance_deg must be positive and min_gap_m 0 or more".into(),
        );
    }
    for l in &spec.expect.levels {
        if !(1..=3).contains(&l.levels) {
            v.err(
                find_key(src, "[[expect.levels]]"),
                format!("levels = {}; use 1, 2 or 3", l.levels),
            );
        }
        for p in [l.min_precision, l.min_recall].into_iter().flatten() {
            if !(0.0..=1.0).contains(&p) {
                v.err(
                    find_key(src, "[[expect.levels]]"),
                    format!("threshold {p} is outside 0..1"),
                );
            }
        }
    }

    if let Some(q) = spec.expect.quantile
        && !(0.0..1.0).contains(&q)
    {
        v.err(
            find_key(src, "quantile"),
            format!("quantile = {q} is outside 0..1; use 0.1 for the 10th percentile"),
        );
    }

    // Recognizer settings: the table over the defaults; each problem at its key.
    let recognizer = recognizer_settings(&spec.recognizer, src, &mut v);

    if !v.diags.is_empty() {
        return Err(SpecError::Invalid(v.diags));
    }
    let name = spec.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".into())
    });
    Ok(Scenario {
        name,
        description: spec.description.clone(),
        path: path.to_path_buf(),
        world_path,
        world,
        route: route.expect("checked above"),
        seed: seed as u64,
        seeds,
        runs,
        door_configs,
        pedestrians,
        laser,
        odometry,
        robot,
        recognizer,
        evaluation: spec.evaluation.clone(),
        expect: spec.expect.clone(),
    })
}

const ALPHA_NAMES: [&str; 4] = ["alpha1", "alpha2", "alpha3", "alpha4"];

const RESERVED: [&str; 3] = ["all-closed", "all-open", "random"];

struct Validator<'a> {
    src: &'a str,
    file: &'a str,
    diags: Vec<Diagnostic>,
}

impl Validator<'_> {
    fn err(&mut self, span: Range<usize>, message: String) {
        let (line, col) = line_col(self.src, span.start);
        self.diags.push(Diagnostic {
            path: self.file.to_string(),
            line,
            col,
            message,
        });
    }

    fn check(
        &mut self,
        key: &str,
        x: &Option<S<f64>>,
        default: f64,
        ok: fn(f64) -> bool,
        what: &str,
    ) -> f64 {
        match x {
            None => default,
            Some(s) => {
                let val = *s.get_ref();
                if ok(val) {
                    val
                } else {
                    self.err(
                        s.span(),
                        format!(
                            "{key} = {val} is out of range; use a {what} number (default {default})"
                        ),
                    );
                    default
                }
            }
        }
    }

    fn positive(&mut self, key: &str, x: &Option<S<f64>>, default: f64) -> f64 {
        self.check(key, x, default, |v| v.is_finite() && v > 0.0, "positive")
    }

    fn non_negative(&mut self, key: &str, x: &Option<S<f64>>, default: f64) -> f64 {
        self.check(
            key,
            x,
            default,
            |v| v.is_finite() && v >= 0.0,
            "non-negative",
        )
    }

    fn finite(&mut self, key: &str, x: &Option<S<f64>>, default: f64) -> f64 {
        self.check(key, x, default, f64::is_finite, "finite")
    }
}

/// Byte offset of a table header, for problems found after deserializing (start of file if
/// absent).
/// The `[recognizer]` table as settings; unknown keys (with "did you mean") and bad values are
/// reported at the key's line.
fn recognizer_settings(table: &toml::Table, src: &str, v: &mut Validator) -> RecognizerConfig {
    let section = src.find("[recognizer]").unwrap_or(0);
    let key_at = |key: &str| -> Range<usize> {
        let at = src[section..]
            .find(&format!("\n{key}"))
            .map(|i| section + i + 1)
            .unwrap_or(section);
        at..at
    };
    let known: Vec<String> = match toml::Table::try_from(RecognizerConfig::default()) {
        Ok(t) => t.keys().cloned().collect(),
        Err(_) => Vec::new(),
    };
    let known_refs: Vec<&str> = known.iter().map(String::as_str).collect();
    let mut unknown = false;
    for key in table.keys() {
        if !known.contains(key) {
            unknown = true;
            v.err(
                key_at(key),
                format!(
                    "unknown key `{key}` in [recognizer]{}",
                    hint(key, &known_refs, "keys")
                ),
            );
        }
    }
    if unknown {
        return RecognizerConfig::default();
    }
    match table.clone().try_into::<RecognizerConfig>() {
        Ok(cfg) => {
            for p in cfg.problems() {
                v.err(
                    key_at(p.field),
                    format!("[recognizer] {}: {}", p.field, p.problem),
                );
            }
            cfg
        }
        Err(e) => {
            v.err(
                key_at("[recognizer]"),
                format!("[recognizer]: {}", serde_message(e.message())),
            );
            RecognizerConfig::default()
        }
    }
}

fn find_key(src: &str, header: &str) -> Range<usize> {
    let at = src.find(header).unwrap_or(0);
    at..at
}

/// "; did you mean `x`?" for the closest name, or "; known `what`: a, b, c".
pub fn hint(name: &str, known: &[&str], what: &str) -> String {
    let best = known
        .iter()
        .map(|k| (strsim::jaro_winkler(name, k), *k))
        .filter(|(s, _)| *s > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0));
    match best {
        Some((_, k)) => format!("; did you mean `{k}`?"),
        None if known.is_empty() => format!("; there are no {what}"),
        None => format!("; known {what}: {}", known.join(", ")),
    }
}

/// Serde's message, lowercase, with a "did you mean" for unknown fields.
fn serde_message(msg: &str) -> String {
    let msg = msg.trim();
    if let Some(rest) = msg.strip_prefix("unknown field `")
        && let Some((field, tail)) = rest.split_once('`')
    {
        let expected: Vec<&str> = tail.split('`').skip(1).step_by(2).collect();
        return format!(
            "unknown field `{field}`{}",
            hint(field, &expected, "fields")
        );
    }
    if let Some(rest) = msg.strip_prefix("unknown variant `")
        && let Some((v, tail)) = rest.split_once('`')
    {
        let expected: Vec<&str> = tail.split('`').skip(1).step_by(2).collect();
        return format!("unknown value `{v}`{}", hint(v, &expected, "values"));
    }
    let mut m = msg.replace('\n', " ");
    if let Some(f) = m.get(0..1) {
        m = f.to_lowercase() + &m[1..];
    }
    if m.starts_with("missing field") {
        m.push_str("; add it");
    }
    m
}
