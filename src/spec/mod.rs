//! Files people write: the structures of world and scenario files, reading them from a string
//! with one reader (`read`), and located diagnostics (`file:line:col: error: what is wrong;
//! what to try`). Nothing here knows the models built from the files: the world's geometric
//! checks live in `world`, the scenario's cross-checks against its world in `experiment`.

pub mod diag;
pub mod evaluation;
pub(crate) mod read;
pub mod scenario;
pub mod seeds;
pub mod subjects;
pub mod suggest;
pub mod world;

pub use diag::{Diagnostic, Diags, SpecError};
