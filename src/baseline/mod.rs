//! Baselines the recognizer is compared with (ICP).

pub mod icp;

pub use icp::{IcpConfig, IcpRecognizer};
