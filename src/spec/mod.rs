//! Files people write: the serde structures of world and scenario files, parsing from a string,
//! and validation with located errors (`file:line:col: what is wrong; what to try`).

pub mod diag;
pub mod evaluation;
pub mod scenario;
pub mod seeds;
pub mod suggest;
pub mod validate;
pub mod world;

pub use diag::{Diagnostic, SpecError};
