//! Reading and writing files the program exchanges with other tools: CARMEN logs, ROS 2 bags
//! (MCAP), atomic output files, MobileSim maps, and the lap file of the lap cache
//! ([`lap_file`]).

pub mod atomic;
pub mod carmen;
pub mod lap_file;
pub mod matches_csv;
pub mod mobilesim;
pub mod real_log;
pub mod ros2;
