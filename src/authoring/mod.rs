//! Aids for people who author worlds: see before any run where the recognizer will see the same
//! density, where it will confuse places, and what is wrong with a world that does not load.
//!
//! Sits above the world, the simulator, the recognizer and `experiment`: it drives the simulated
//! robot and builds the recognizer's words, but changes neither; it runs whole scenarios only to
//! hold its ambiguity map against the recognizer's real confusions (`prediction`).

pub mod ambiguity;
pub mod density;
pub mod generate;
pub mod import;
pub mod mobilesim;
pub mod prediction;
pub mod problems;
pub mod route;
pub mod slip;

pub use ambiguity::{AmbiguityReport, AmbiguousStretch, ambiguity, ambiguity_svg};
pub use density::{DensityMap, density_map, density_svg};
