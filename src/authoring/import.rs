//! `world import`: a MobileSim map as a world file that `world check` accepts, or the reason it
//! cannot be one.
//!
//! [`crate::io::mobilesim`] reads the map, [`crate::authoring::mobilesim`] repairs what it can
//! (a segment drawn twice kept once, a home heading brought into -180..180:
//! [`crate::authoring::mobilesim::repair_map`]) and generates a route
//! ([`crate::authoring::route`]); here the world file it gives is checked as `world check` checks it (the
//! same checks and test drive, [`crate::sim::test_drive::check_world_text`]) before anything
//! is written, so an import never writes a world that `world check` then rejects.

use crate::authoring::mobilesim::{self, MapError};
use crate::authoring::route::RouteOptions;
use crate::spec::SpecError;
use crate::spec::diag::{Diagnostic, Severity};
use crate::spec::world::WorldSpec;

/// A map turned into a world file.
#[derive(Clone, Debug)]
pub struct ImportedWorld {
    pub spec: WorldSpec,
    /// The world file's text.
    pub text: String,
    /// What the import repaired, warnings at the map's lines.
    pub repairs: Vec<Diagnostic>,
}

/// Why a map gives no world file.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The map does not read, or no route could be made ([`MapError::NoRoute`] may carry the
    /// world without its route).
    #[error(transparent)]
    Map(#[from] MapError),
    /// The world the map gives fails `world check`: its problems (their lines are those of the
    /// text that was not written, so each is said of the map as a whole, line 1).
    #[error("{}", .problems.iter().map(|d| format!(
        "{map}:1:1: error: the world this map gives fails `world check`, so it is not written: {}",
        d.message)).collect::<Vec<_>>().join("\n"))]
    Refused {
        map: String,
        problems: Vec<Diagnostic>,
    },
    #[error("cannot serialise the world: {0}")]
    Serialise(#[from] toml::ser::Error),
}

/// Imports the map text `src` (`map_name` in messages) as a world file to be written at
/// `out_name`, checked as `world check` would check that file.
pub fn import_map(src: &str, map_name: &str, out_name: &str) -> Result<ImportedWorld, ImportError> {
    let imported = mobilesim::import_mobilesim_repaired(src, map_name, &RouteOptions::default())?;
    let text = mobilesim::world_to_toml(&imported.spec, map_name)?;
    match crate::sim::test_drive::check_world_text(&text, out_name) {
        Ok(_) => Ok(ImportedWorld {
            spec: imported.spec,
            text,
            repairs: imported.repairs,
        }),
        Err(e) => {
            let problems = match e {
                SpecError::Invalid(d) => d
                    .into_iter()
                    .filter(|d| d.severity == Severity::Error)
                    .collect(),
                SpecError::Io { path, source } => vec![Diagnostic::error(
                    &path.display().to_string(),
                    (1, 1),
                    source.to_string(),
                )],
            };
            Err(ImportError::Refused {
                map: map_name.to_string(),
                problems,
            })
        }
    }
}
