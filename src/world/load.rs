//! Loading a world file: read it with `spec`, check it here, build the model.

use crate::spec::diag::{Diagnostic, Diags, SpecError};
use crate::spec::world::{WorldSpec, read_world};
use crate::world::World;
use crate::world::validate::{self, WorldCheck};
use std::path::Path;

/// Reads and checks a world file's text into its file structures; `path` only names the file in
/// messages. Every problem is reported, in file order.
pub fn parse_world_spec(src: &str, path: &str, check: &WorldCheck) -> Result<WorldSpec, SpecError> {
    parse_world_spec_warned(src, path, check).map(|(spec, _)| spec)
}

/// A problem a check above this layer (the simulator's test drive of a route) found at a route
/// waypoint; reported at the waypoint's place in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct RouteProblem {
    /// Index of the route in the file (from 0).
    pub route: usize,
    /// Index of the waypoint in the route as the file lists it (from 0).
    pub waypoint: usize,
    /// `what is wrong; what to try`.
    pub message: String,
}

/// Checks of a valid world that need more than the world itself (a simulated drive): run only
/// when every check here passed.
pub type RouteCheck<'a> = &'a dyn Fn(&World) -> Vec<RouteProblem>;

/// Like [`parse_world_spec`], with the warnings of a world that has no error.
pub fn parse_world_spec_warned(
    src: &str,
    path: &str,
    check: &WorldCheck,
) -> Result<(WorldSpec, Vec<Diagnostic>), SpecError> {
    parse_world_spec_checked(src, path, check, None)
}

/// Like `parse_world_spec_warned`; when the world has no error, `more` checks its routes too
/// and each problem it finds is reported at its waypoint (`file:line:col`).
pub fn parse_world_spec_checked(
    src: &str,
    path: &str,
    check: &WorldCheck,
    more: Option<RouteCheck>,
) -> Result<(WorldSpec, Vec<Diagnostic>), SpecError> {
    let mut d = Diags::new(src, path);
    let spec = read_world(src, &mut d).map(|(spec, loc)| {
        validate::validate(&spec, &loc, check, &mut d);
        if more.is_some() && d.has_errors() {
            let at = loc.routes.first().map_or(loc.walls_key, |l| l.table);
            d.note(
                at,
                "the routes were not test-driven: the robot drives a world only once it has no errors; fix them and check again".into(),
            );
        } else if let Some(more) = more {
            for p in more(&World::from_spec(&spec)) {
                let at = loc.routes.get(p.route).map_or(0, |l| {
                    l.waypoints
                        .get(p.waypoint)
                        .copied()
                        .unwrap_or(l.waypoints_key)
                });
                d.at(at, p.message);
            }
        }
        spec
    });
    let has_errors = d.has_errors();
    match (spec, d.into_sorted()) {
        (Some(spec), warnings) if !has_errors => Ok((spec, warnings)),
        (_, mut diags) => {
            if diags.is_empty() {
                // Defensive: a failed read always reports why; never return an empty error.
                diags.push(Diagnostic::error(
                    path,
                    (1, 1),
                    "the file could not be read as a world; check it against worlds/loop-small.toml",
                ));
            }
            Err(SpecError::Invalid(diags))
        }
    }
}

/// Parses and checks a world file's text for the default robot; `path` only names the file.
pub fn parse_world(src: &str, path: &str) -> Result<World, SpecError> {
    parse_world_for(src, path, &WorldCheck::default())
}

/// Parses and checks a world file's text for the robot in `check`.
pub fn parse_world_for(src: &str, path: &str, check: &WorldCheck) -> Result<World, SpecError> {
    parse_world_spec(src, path, check).map(|spec| World::from_spec(&spec))
}

/// Reads and checks a world file for the default robot.
pub fn load_world(path: &Path) -> Result<World, SpecError> {
    load_world_for(path, &WorldCheck::default())
}

/// Reads and checks a world file for the default robot; also returns its warnings (problems
/// that leave the world usable), for `world check`.
pub fn check_world(path: &Path) -> Result<(World, Vec<Diagnostic>), SpecError> {
    let src = crate::spec::diag::read_text(path)?;
    parse_world_spec_warned(&src, &path.display().to_string(), &WorldCheck::default())
        .map(|(spec, warnings)| (World::from_spec(&spec), warnings))
}

/// [`check_world`], and when the world has no error, `more` on its routes (see
/// [`parse_world_spec_checked`]).
pub fn check_world_with(
    path: &Path,
    more: RouteCheck,
) -> Result<(World, Vec<Diagnostic>), SpecError> {
    let src = crate::spec::diag::read_text(path)?;
    parse_world_spec_checked(
        &src,
        &path.display().to_string(),
        &WorldCheck::default(),
        Some(more),
    )
    .map(|(spec, warnings)| (World::from_spec(&spec), warnings))
}

/// Reads and checks a world file for the robot in `check`.
pub fn load_world_for(path: &Path, check: &WorldCheck) -> Result<World, SpecError> {
    let src = crate::spec::diag::read_text(path)?;
    parse_world_for(&src, &path.display().to_string(), check)
}

/// What could be read of a world file even when it is invalid, for pictures of what is wrong:
/// its structures and the offsets of its values (`None` when the text is not TOML), and every
/// problem, in file order.
pub fn read_world_lenient(
    src: &str,
    path: &str,
) -> (
    Option<(WorldSpec, crate::spec::world::WorldLoc)>,
    Vec<Diagnostic>,
) {
    let mut d = Diags::new(src, path);
    let read = read_world(src, &mut d);
    if let Some((spec, loc)) = &read {
        validate::validate(spec, loc, &WorldCheck::default(), &mut d);
    }
    (read, d.into_sorted())
}
