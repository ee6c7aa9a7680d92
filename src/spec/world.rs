//! The world file format (TOML, `format_version = 1`): walls, doors, routes, home pose, areas.
//!
//! These structs describe the file only; [`crate::world::World`] is the validated model built
//! from them. Units are in every physical key; angles are degrees here and radians in the model.

use serde::{Deserialize, Serialize};

/// A whole world file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Must be 1.
    pub format_version: i64,
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    pub robot_home: HomeSpec,
    #[serde(default)]
    pub walls: Vec<WallSpec>,
    #[serde(default)]
    pub doors: Vec<DoorSpec>,
    #[serde(default)]
    pub routes: Vec<RouteSpec>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub areas: Vec<AreaSpec>,
}

/// The robot's home pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomeSpec {
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub heading_deg: f64,
}

/// A wall: a polyline of at least two points with a thickness.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    pub id: String,
    /// Vertices, metres.
    pub points_m: Vec<[f64; 2]>,
    /// Whether the polyline closes back to its first point. Default false.
    #[serde(default, skip_serializing_if = "is_false")]
    pub closed: bool,
    /// Full thickness, metres, centred on the polyline. Default 0.1.
    #[serde(default = "default_wall_thickness_m")]
    pub thickness_m: f64,
}

/// A hinged door panel. Closed, it spans a gap in a wall; open, it swings into its room.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DoorSpec {
    pub id: String,
    /// Hinge point, metres.
    pub hinge_m: [f64; 2],
    /// Panel length from hinge to tip, metres.
    pub width_m: f64,
    /// Direction hinge→tip when closed, degrees counter-clockwise from +x.
    pub closed_heading_deg: f64,
    /// Direction hinge→tip when open, degrees.
    pub open_heading_deg: f64,
    /// Panel thickness, metres. Default 0.04.
    #[serde(default = "default_door_thickness_m")]
    pub thickness_m: f64,
}

/// A closed loop of waypoints the robot drives, in order; the last leg returns to the first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteSpec {
    pub id: String,
    pub waypoints_m: Vec<[f64; 2]>,
}

/// An axis-aligned rectangle where people may walk (back and forth along its longer side).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaSpec {
    pub id: String,
    pub min_m: [f64; 2],
    pub max_m: [f64; 2],
}

pub fn default_wall_thickness_m() -> f64 {
    0.1
}

pub fn default_door_thickness_m() -> f64 {
    0.04
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// Parses and validates a world file's text; `path` only names the file in messages.
///
/// Minimal version: syntax and unknown keys (first error only). The foundation issue extends
/// this with every check of DESIGN.md §3 and all problems at once.
pub fn parse_world(src: &str, path: &str) -> Result<crate::world::World, crate::spec::SpecError> {
    use crate::spec::diag::{Diagnostic, line_col};
    match toml::from_str::<WorldSpec>(src) {
        Ok(spec) => Ok(crate::world::World::from_spec(&spec)),
        Err(e) => {
            let (line, col) = e.span().map(|s| line_col(src, s.start)).unwrap_or((1, 1));
            Err(crate::spec::SpecError::Invalid(vec![Diagnostic {
                path: path.to_string(),
                line,
                col,
                message: e.message().trim().to_string(),
            }]))
        }
    }
}

/// Reads and validates a world file.
pub fn load_world(path: &std::path::Path) -> Result<crate::world::World, crate::spec::SpecError> {
    let src = std::fs::read_to_string(path).map_err(|e| crate::spec::SpecError::io(path, e))?;
    parse_world(&src, &path.display().to_string())
}
