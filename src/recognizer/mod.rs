//! The place recognizer of the paper: local grid, density Ψ, density classes, words, multi-level
//! words, incremental n-gram matching and fine alignment. It takes odometry poses and scans and
//! never sees ground truth.

pub mod types;

pub use types::{AlignedPair, Match, ObsId, Observation, WordRef};
