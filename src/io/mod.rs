//! Reading and writing files the program exchanges with other tools: CARMEN logs, atomic output
//! files, MobileSim maps.

pub mod atomic;
pub mod carmen;
pub mod matches_csv;
pub mod mobilesim;
pub mod real_log;
