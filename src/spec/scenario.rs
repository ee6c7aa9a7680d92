//! The scenario file format (TOML, `format_version = 1`): the structures of the file as
//! written, with the span of every value so later checks can point at it. The checks against the
//! world and the models built from these live in `experiment::scenario`.
//!
//! The full reference, with every key, its unit, default and limits, is
//! `docs/scenario-format.md`.

use crate::spec::evaluation::{EvaluationSpec, ExpectSpec};
use serde::Deserialize;
use std::collections::BTreeMap;
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
